"""``"auto"``: what the schemes use. One contact in closed form; several by Lemke with
the QP fallback (:func:`moreau.lcp.solve_lcp`'s ``"auto"``); equality rows by ``"mlcp"``."""

from ..registry import register_solver
from . import closed_form, mlcp
from ._friction_lcp import solve_friction_lcp

__all__ = ["solve"]


def solve(problem, *, max_iter=None, tol=None):
    """Solve ``problem`` by the fitting method.

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.contact import ContactProblem
    >>> solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5])).method
    'closed-form'
    >>> solve(ContactProblem(np.eye(2), [-1.0, -1.0], [0.0, 0.0])).method
    'lemke'
    """
    if problem.n_eq:
        return mlcp.solve(problem, max_iter=max_iter, tol=tol)
    if problem.mu.size == 1:
        return closed_form.solve(problem)
    return solve_friction_lcp(problem, "auto", max_iter, tol)


register_solver("auto", solve, equality_rows=True,
                summary="closed form for one contact, else Lemke then QP; mlcp with equality rows")
