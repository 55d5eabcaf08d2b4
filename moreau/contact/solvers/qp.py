"""``"qp"``: the friction LCP by the QP method of :mod:`moreau.lcp.qp` (a Tresca
fixed point on OSQP), the fallback of ``"auto"``."""

from ..registry import register_solver
from ._friction_lcp import solve_friction_lcp

__all__ = ["solve"]


def solve(problem, *, max_iter=None, tol=None):
    """The friction LCP of ``problem`` by the QP method (``max_iter`` fixed-point iterations).

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.contact import ContactProblem
    >>> sol = solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]))
    >>> sol.status, sol.method, np.round(sol.p, 6).tolist()
    ('solved', 'qp', [1.0, -0.5])
    """
    return solve_friction_lcp(problem, "qp", max_iter, tol)


register_solver("qp", solve, summary="dense friction LCP, QP (Tresca fixed point, OSQP)")
