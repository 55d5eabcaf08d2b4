"""Contact problems at the velocity level (see :mod:`moreau.contact.cone3d` for the spatial cone)."""
