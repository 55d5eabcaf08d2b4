"""``"lemke"``: the dense friction LCP by Lemke's method (:mod:`moreau.lcp.lemke`),
then the enumeration of the pieces where it ends on a ray."""

from ..registry import register_solver
from ._friction_lcp import solve_friction_lcp

__all__ = ["solve"]


def solve(problem, *, max_iter=None, tol=None):
    """The friction LCP of ``problem`` by Lemke (pivot limit ``max_iter``).

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.contact import ContactProblem
    >>> sol = solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]))
    >>> np.round(sol.p, 12).tolist(), sol.method, sol.status
    ([1.0, -0.5], 'lemke', 'solved')
    """
    return solve_friction_lcp(problem, "lemke", max_iter, tol)


register_solver("lemke", solve, summary="dense friction LCP, Lemke's method")
