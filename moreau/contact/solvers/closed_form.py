"""``"closed-form"``: one contact, by the exact case analysis of
:func:`moreau.contact.closed_form.one_contact_impulse`."""

import numpy as np

from ..closed_form import one_contact_impulse, one_contact_residual
from ..problem import SOLVED, ContactSolution
from ..registry import register_solver

__all__ = ["solve"]

_NO_EQ = np.zeros(0)


def solve(problem, *, max_iter=None, tol=None):
    """Impulse of a one-contact problem: open, stick, positive or negative slip.

    Exact where ``W`` is positive definite (a unique answer, the tangential
    impact included); ``max_iter`` and ``tol`` do not apply.

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
    return ContactSolution(p, _NO_EQ, np.array([pn]), np.array([pt]), SOLVED, float(res),
                           "closed-form", 0, "Solved in closed form.", ("closed-form",))


register_solver("closed-form", solve, max_contacts=1,
                summary="one contact, exact case analysis (open, stick, slip either way)")
