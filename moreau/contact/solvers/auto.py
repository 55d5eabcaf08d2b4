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

Above the crossover NSGS runs within :func:`auto_budget` sweeps (``200 +
10 nc``, at most 10 000) unless the caller gives ``max_iter``: the first
:data:`PLAIN_SWEEPS` (100) plain (a problem they solve gets the answer it
got before), the rest over-relaxed, ``omega =`` :data:`AUTO_OMEGA` (1.5),
from where the plain sweeps left. Measured
(``benchmarks/bench_contact_solvers.py``'s problems, sweeps to 1e-8):
the pressed chain of 34, 100, 300 contacts took 1656, 12 740, > 20 000
sweeps at ``omega = 1`` and 540, 4228, > 20 000 at 1.5; square stacks of
75, 190 and 1180 disks (``mu`` 0.1 and 0.5) 320/1224, 2544/4120,
> 20 000/13 772 at 1 and 104/608, 712/1184, 12 664/9064 at 1.5, while 1.7
and 1.9 failed on every stack with ``mu = 0.5``. The budget is a few times
what the stacks need and bounds what a step that NSGS cannot finish costs
before the dense LCP takes it: the pressed chain's step (99 contacts)
cost 123 ms with 10 000 plain sweeps before Lemke (0.5 ms), 40 ms with
this budget (199 contacts: 524 ms, 236 ms; shared machine, one run).
"""

from ...errors import PainleveError
from .._sparse import DENSE_CROSSOVER
from ..problem import SOLVED
from ..registry import register_solver
from . import _iterative, closed_form, mlcp, nsgs
from ._friction_lcp import solve_friction_lcp

__all__ = ["solve", "auto_budget", "AUTO_OMEGA"]

#: plain NSGS sweeps above the crossover before the over-relaxed ones
PLAIN_SWEEPS = 100
#: NSGS's over-relaxation above the crossover (module docstring: 1.5 never slower than 1 on
#: the measured problems, 1.7 and more failed on frictional stacks)
AUTO_OMEGA = 1.5


def auto_budget(n_contacts):
    """NSGS's sweeps above the crossover before the dense LCP takes the step: ``200 + 10 nc``, at most 10 000.

    Examples
    --------
    >>> auto_budget(100), auto_budget(5000)
    (1200, 10000)
    """
    return min(10_000, 200 + 10 * int(n_contacts))


def solve(problem, *, max_iter=None, tol=None):
    """Solve ``problem`` by the fitting method.

    ``max_iter`` and ``tol`` go to the method chosen: Lemke's pivot limit and
    violation bound, or NSGS's sweeps (:func:`auto_budget` by default) and
    natural-map tolerance (1e-8 by default) above the crossover, where a solve
    that does not converge goes to the dense LCP (``path`` names both).

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
        try:
            sol = closed_form.solve(problem, tol=tol)
        except PainleveError as exc:
            # a singular Delassus matrix (normal and tangential rates tied: a one-dof
            # mechanism): the case formulas cannot pick among the impulses that give its
            # unique velocities; the LCP can, and where it finds none the problem has none
            dense = solve_friction_lcp(problem, "auto", max_iter, tol)
            if dense.status != SOLVED:
                raise exc
            return dense._replace(path=("closed-form",) + tuple(dense.path))
        if sol.status == SOLVED:
            return sol
        # a Delassus matrix singular to rounding: the case formulas lost their digits, and
        # Lemke with the QP fallback decides on the same data
        dense = solve_friction_lcp(problem, "auto", max_iter, tol)
        return dense._replace(path=tuple(sol.path) + tuple(dense.path))
    if problem.mu.size > DENSE_CROSSOVER:
        budget = auto_budget(problem.mu.size) if max_iter is None else max_iter
        sol = _staged_nsgs(problem, budget, tol)
        if sol.status == SOLVED:
            return sol
        # NSGS's worst case (a long pressed chain needs about N^2 sweeps) is no reason to
        # fail a step: the dense LCP decides, at its cost, and the path says so
        dense = solve_friction_lcp(problem, "auto", None, None)
        return dense._replace(path=tuple(sol.path) + tuple(dense.path))
    return solve_friction_lcp(problem, "auto", max_iter, tol)


def _staged_nsgs(problem, budget, tol):
    W, q, mu = _iterative.local_problem(problem)
    tol = _iterative.DEFAULT_TOL if tol is None else tol
    first = min(budget, PLAIN_SWEEPS)
    res = nsgs.solve_nsgs(W, q, mu, tol=tol, max_sweeps=first)
    if not res.converged and budget > first:
        more = nsgs.solve_nsgs(W, q, mu, r0=res.r, tol=tol, max_sweeps=budget - first,
                               omega=AUTO_OMEGA)
        done = first + more.iterations
        if more.residual <= res.residual:
            res = more
        res.iterations = done
    return _iterative.solution_of(problem, res, budget)


register_solver("auto", solve, equality_rows=True,
                summary="closed form for one contact, Lemke then QP up to 32 contacts, NSGS "
                        "above; mlcp with equality rows")
