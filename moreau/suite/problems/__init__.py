"""The suite's problems, one module each (each registers itself; see :mod:`moreau.suite.problem`)."""
