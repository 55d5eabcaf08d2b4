"""The model layer: how mechanical systems are described (:mod:`moreau.model.planar`)."""
