"""The dense friction LCP of a contact problem without equality rows, solved and read back.

Shared by the ``lemke``, ``qp`` and ``auto`` solvers: the LCP of
:func:`moreau.lcp.friction.build_friction_lcp` solved by
:func:`moreau.lcp.solve_lcp`; where that fails other than at the pivot
limit, with at most :data:`~moreau.contact.closed_form.MAX_PIECES_CONTACTS`
contacts, the enumeration of the contacts' pieces
(:func:`~moreau.contact.closed_form.friction_pieces`), certified the same way.
"""

import numpy as np

from ...lcp import MAX_ITER, lcp_residual, solve_lcp
from ...lcp.friction import build_friction_lcp, friction_impulses
from ..closed_form import MAX_PIECES_CONTACTS, friction_pieces
from ..problem import FAILED, MAX_ITER as MAX_ITER_STATUS, SOLVED, ContactSolution

_NO_EQ = np.zeros(0)


def solve_friction_lcp(problem, lcp_method, max_iter, tol):
    """A :class:`~moreau.contact.ContactSolution` of ``problem`` (``n_eq = 0``) by ``lcp_method``."""
    W, U, mu, e, vN = problem.W, problem.u_free, problem.mu, problem.e, problem.vN_pre
    na = mu.size
    Ml, ql, layout = build_friction_lcp(W, U, mu, e, vN)
    # the warm start (a support) is "auto"'s: Lemke and the QP alone take none
    warm = {"support": problem.warm} if lcp_method == "auto" and problem.warm is not None else {}
    r = solve_lcp(Ml, ql, method=lcp_method, friction=layout, max_iter=max_iter, tol=tol, **warm)
    z = r.z if r.success else None
    path, method = r.path, r.method
    # (a pivot limit the caller set is kept: its failure is the answer)
    if z is None and r.status != MAX_ITER and na <= MAX_PIECES_CONTACTS:
        # a frictional contact problem has a solution (closed_form.one_contact_impulse's
        # Notes: the matrix is copositive, and with W = J M^-1 J^T, no rheonomic term and
        # e = 0 Lemke's condition holds), so a float Lemke that ends on a ray has met
        # rounding on a degenerate problem (redundant contacts, a block flat on two
        # corners): the complete enumeration of the contacts' pieces finds it
        z = friction_pieces(W, U, mu, e, vN, Ml, ql, layout)
        if z is not None:
            path, method = path + ("pieces",), "pieces"
    if z is None:
        tried = (f"; the enumeration of the {4 ** na} pieces of its {na} contacts found none"
                 if na <= MAX_PIECES_CONTACTS and r.status != MAX_ITER else "")
        status = MAX_ITER_STATUS if r.status == MAX_ITER else FAILED
        pN, pT = friction_impulses(r.z, layout)
        return ContactSolution(friction_impulses(r.z, layout, stacked=True), _NO_EQ, pN, pT,
                               status, float(lcp_residual(Ml, ql, r.z)), method, int(r.pivots),
                               f"{r.message}{tried}", path, r)
    pN, pT = friction_impulses(z, layout)
    return ContactSolution(friction_impulses(z, layout, stacked=True), _NO_EQ, np.asarray(pN),
                           np.asarray(pT), SOLVED, float(lcp_residual(Ml, ql, z)), method,
                           int(r.pivots) if method == r.method else 0, r.message, path, r)


def friction_lcp_solver(lcp_method):
    """The solver ``fn(problem, *, max_iter=None, tol=None)`` of the friction LCP by ``lcp_method``.

    Examples
    --------
    >>> from moreau.contact import ContactProblem
    >>> sol = friction_lcp_solver("lemke")(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]))
    >>> np.round(sol.p, 12).tolist(), sol.method, sol.status
    ([1.0, -0.5], 'lemke', 'solved')
    """
    def solve(problem, *, max_iter=None, tol=None):
        return solve_friction_lcp(problem, lcp_method, max_iter, tol)

    solve.__doc__ = (f"The friction LCP of ``problem`` by :func:`moreau.lcp.solve_lcp`'s "
                     f"{lcp_method!r} method, then the pieces where it ends on a ray.")
    return solve
