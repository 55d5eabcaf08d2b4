"""``"closed-form"``: one contact, by the exact case analysis of
:func:`moreau.contact.closed_form.one_contact_impulse`."""

import numpy as np

from ...lcp.lemke import DEFAULT_TOL
from ..closed_form import one_contact_impulse, one_contact_residual
from ..problem import FAILED, SOLVED, ContactSolution
from ..registry import register_solver

__all__ = ["solve"]

_NO_EQ = np.zeros(0)


def solve(problem, *, max_iter=None, tol=None):
    """Impulse of a one-contact problem: open, stick, positive or negative slip.

    Exact where ``W`` is positive definite (a unique answer, the tangential
    impact included). The answer's residual on the caller's data is checked
    against ``tol`` (Lemke's :data:`~moreau.lcp.lemke.DEFAULT_TOL` by
    default): where ``W`` is singular to rounding (a contact whose normal and
    tangential rates the system ties together) the case formulas can lose
    every digit, and the status is then ``"failed"`` with the residual, for
    ``"auto"`` to hand the problem to Lemke. ``max_iter`` does not apply.

    Raises
    ------
    PainleveError
        A singular Delassus matrix without a unique answer.
    FloatingPointError
        ``W_NN`` not positive and finite where the contact must act.

    Examples
    --------
    >>> from moreau.contact import ContactProblem
    >>> sol = solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]))
    >>> sol.p.tolist(), sol.method
    ([1.0, -0.5], 'closed-form')
    """
    W, U, mu, e, vN = problem.W, problem.u_free, problem.mu, problem.e, problem.vN_pre
    if mu[0] > 0.0:
        pn, pt = one_contact_impulse(W, U, mu[0], e[0], vN[0])
        res = one_contact_residual(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U[0], U[1],
                                   mu[0], e[0], vN[0], pn, pt)
        p = np.array([pn, pt])
    else:
        pn, pt = one_contact_impulse(W[:1, :1], U[:1], 0.0, e[0], vN[0])
        res = one_contact_residual(W[0, 0], 0.0, 0.0, 0.0, U[0], 0.0, 0.0, e[0], vN[0], pn, 0.0)
        p = np.array([pn])
    tol = DEFAULT_TOL if tol is None else tol
    if not res <= tol:
        return ContactSolution(p, _NO_EQ, np.array([pn]), np.array([pt]), FAILED, float(res),
                               "closed-form", 0,
                               f"the closed form's residual {res:.3g} exceeds tol = {tol:.3g} "
                               f"(a Delassus matrix singular to rounding)", ("closed-form",))
    return ContactSolution(p, _NO_EQ, np.array([pn]), np.array([pt]), SOLVED, float(res),
                           "closed-form", 0, "Solved in closed form.", ("closed-form",))


register_solver("closed-form", solve, max_contacts=1,
                summary="one contact, exact case analysis (open, stick, slip either way)")
