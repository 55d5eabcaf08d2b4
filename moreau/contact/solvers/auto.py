"""``"auto"``: what the schemes use. One contact in closed form; up to
:data:`~moreau.contact._sparse.DENSE_CROSSOVER` (32) contacts by Lemke with the
QP fallback (:func:`moreau.lcp.solve_lcp`'s ``"auto"``); more by ``"nsgs"``,
and by the dense LCP where NSGS does not converge within its budget;
equality rows by ``"mlcp"`` (which solves the reduced problem the same way).

The crossover is the one measured for :mod:`moreau.contact._sparse`:
``benchmarks/bench_contact_solvers.py --crossover`` timed dense Lemke on the
friction LCP and NSGS on CSR equal between 16 and 32 contacts on short
frictional chains, NSGS 3x faster at 64 and 10x at 128, and Lemke took 0.9 s
on an 18-contact hyperstatic stack. Every scheme's problem is far below it,
so their results do not depend on NSGS, except the generic step of a
long chain (the ball chain at N > 33), whose pressed chain is NSGS's worst
case: there NSGS either certifies its answer or hands the step to Lemke.
"""

from .._sparse import DENSE_CROSSOVER
from ..problem import SOLVED
from ..registry import register_solver
from . import closed_form, mlcp, nsgs
from ._friction_lcp import solve_friction_lcp

__all__ = ["solve"]


def solve(problem, *, max_iter=None, tol=None):
    """Solve ``problem`` by the fitting method.

    ``max_iter`` and ``tol`` go to the method chosen: Lemke's pivot limit and
    violation bound, or NSGS's sweeps and natural-map tolerance (1e-8 by
    default) above the crossover, where a solve that does not converge goes to
    the dense LCP (``path`` names both).

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.contact import ContactProblem
    >>> solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5])).method
    'closed-form'
    >>> solve(ContactProblem(np.eye(2), [-1.0, -1.0], [0.0, 0.0])).method
    'lemke'
    >>> solve(ContactProblem(np.eye(40), -np.ones(40), np.zeros(40))).method
    'nsgs'
    """
    if problem.n_eq:
        return mlcp.solve(problem, max_iter=max_iter, tol=tol)
    if problem.mu.size == 1:
        return closed_form.solve(problem)
    if problem.mu.size > DENSE_CROSSOVER:
        sol = nsgs.solve(problem, max_iter=max_iter, tol=tol)
        if sol.status == SOLVED:
            return sol
        # NSGS's worst case (a long pressed chain needs about N^2 sweeps) is no reason to
        # fail a step: the dense LCP decides, at its cost, and the path says so
        dense = solve_friction_lcp(problem, "auto", None, None)
        return dense._replace(path=tuple(sol.path) + tuple(dense.path))
    return solve_friction_lcp(problem, "auto", max_iter, tol)


register_solver("auto", solve, equality_rows=True,
                summary="closed form for one contact, Lemke then QP up to 32 contacts, NSGS "
                        "above; mlcp with equality rows")
