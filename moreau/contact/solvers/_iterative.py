"""An iterative solver of FCLib's per-contact layout as a registered contact-problem solver.

Shared by ``nsgs`` and ``apgd``: the problem (no equality rows; :func:`solve`
refuses them for these methods by name, ``"mlcp"`` with ``inner="nsgs"``
eliminates them first) goes to FCLib's layout by
:func:`~moreau.contact.to_fclib` (the impact law folded into ``q``, an exact
change of variables), the solver runs there, and its impulses come back by
:func:`~moreau.contact.from_fclib`.

Status and residual: the solver's own stopping measure, the natural map of
the De Saxcé complementarity ``||F(r)||_2 / (1 + ||q||_2)``
(:mod:`moreau.contact._sparse`), recomputed with compensated sums on the
impulses returned, is the solution's ``residual``, in the units of ``tol``:
``"solved"`` when it is ``<= tol``; otherwise ``"max-iter"`` when the budget
ran out, ``"failed"`` when the iterates stopped being finite. A solve that
did not converge keeps its best impulses and says so; it is never reported
solved.
"""

import numpy as np

from ..fclib_layout import from_fclib, to_fclib
from ..problem import FAILED, MAX_ITER, SOLVED, ContactSolution

__all__ = ["DEFAULT_TOL", "local_problem", "solution_of", "solve_local"]

#: the tolerance on the natural-map residual when the caller gives none (the FCLib solvers' own)
DEFAULT_TOL = 1e-8

_NO_EQ = np.zeros(0)


def local_problem(problem):
    """``(W, q, mu)`` of ``problem`` in FCLib's layout (``W`` dense; the solvers convert to CSR)."""
    lp = to_fclib(problem)
    return lp.W, lp.q, lp.mu


def solution_of(problem, result, budget):
    """The :class:`~moreau.contact.ContactSolution` of an :class:`~moreau.contact._sparse.IterativeResult`.

    ``budget`` is the iteration limit the solver ran with (it tells a budget
    spent from a breakdown).
    """
    p = from_fclib(problem, result.r)
    pN = np.array(result.r[0::2])
    pT = np.array(result.r[1::2])
    pT[problem.mu == 0.0] = 0.0
    if result.converged:
        status = SOLVED
    elif result.iterations >= budget:
        status = MAX_ITER
    else:
        status = FAILED
    return ContactSolution(p, _NO_EQ, pN, pT, status, result.residual, result.solver,
                           result.iterations, result.message, (result.solver,), None)


def solve_local(problem, solver, budget_option, budget, tol, **options):
    """``problem`` solved by ``solver(W, q, mu, tol=..., **options)`` in FCLib's layout.

    ``budget`` is the iteration limit given to the solver as its keyword
    ``budget_option`` (see :func:`solution_of`); ``tol`` ``None`` is
    :data:`DEFAULT_TOL`.
    """
    W, q, mu = local_problem(problem)
    res = solver(W, q, mu, tol=DEFAULT_TOL if tol is None else tol, **{budget_option: budget},
                 **options)
    return solution_of(problem, res, budget)
