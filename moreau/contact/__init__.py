"""The contact problem of one time step: its data, its solvers (issue 35).

Every scheme ends a step with the same problem on its active rows
(:class:`ContactProblem`: Delassus matrix ``W``, free velocities, ``mu``,
``e``, pre-step normal velocities, and leading equality rows for joints).
:func:`solve` reaches every registered solver by name
(:func:`solver_names`; one module each in :mod:`moreau.contact.solvers`)
and returns a :class:`ContactSolution`. A solver written in FCLib's
per-contact layout reaches a problem through :func:`to_fclib` and
:func:`from_fclib` (:mod:`moreau.contact.fclib_layout`); equality rows are
eliminated first (:func:`moreau.contact.solvers.mlcp.eliminate_equalities`).

Floor: above :mod:`moreau.lcp`, below :mod:`moreau.integrators`.

Examples
--------
A unit point mass on a rod that keeps ``x + y`` constant (equality row
``E = x + y``), moving at ``(1, -2)`` onto a frictionless floor ``y = 0``
(row ``N = y``): the rod and the floor stop it together.

>>> import numpy as np
>>> from moreau.contact import ContactProblem, solve
>>> W = np.array([[2.0, 1.0], [1.0, 1.0]])          # J J^T, J = [[1, 1], [0, 1]]
>>> sol = solve(ContactProblem(W, [-1.0, -2.0], [0.0], n_eq=1))
>>> sol.status, sol.method, sol.p_eq.tolist(), sol.pN.tolist()
('solved', 'mlcp+closed-form', [-1.0], [3.0])
"""

from . import solvers  # noqa: F401  (registers the solvers)
from .fclib_layout import LocalProblem, from_fclib, to_fclib
from .problem import FAILED, MAX_ITER, SOLVED, ContactProblem, ContactSolution
from .registry import SolverEntry, get_solver, register_solver, solve, solver_names

__all__ = ["ContactProblem", "ContactSolution", "solve", "register_solver", "solver_names",
           "get_solver", "SolverEntry", "LocalProblem", "to_fclib", "from_fclib", "SOLVED",
           "MAX_ITER", "FAILED"]
