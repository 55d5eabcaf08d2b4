"""The suite's problems, one module each (each registers itself; see :mod:`moreau.suite.problem`).

The rocking block (Housner's ratio) is pending: its scene lands on branch
``tangential-impact``; its module goes here as ``rocking_block.py`` and
replaces the entry of :data:`moreau.suite.problem.PENDING`.
"""
