"""The benchmark suite (``moreau suite``) and animations of runs (``moreau animate``).

:mod:`moreau.suite.problem`
    the problems: a registered scene with its reference, headline
    quantities and tolerance, one module each under
    :mod:`moreau.suite.problems`;
:mod:`moreau.suite.run`
    every registered scheme on every problem, cell by cell, kept as it goes;
:mod:`moreau.suite.report`
    the table, the figures and the page;
:mod:`moreau.suite.animate`
    an animation of a ``moreau run`` output from the scene's shapes.
"""
