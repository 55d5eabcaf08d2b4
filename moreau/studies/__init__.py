"""Studies of particular scenes: the paper's own (``paper``) and the two-rod drive's (``bidirectional``).

The generic machinery (steady states, the sweep engine, comparison) lives in
:mod:`moreau.analysis`; what is specific to one scene or to the paper lives here.
"""
