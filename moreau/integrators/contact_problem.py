"""The contact problem of one time step, shared by the time-stepping schemes.

Every velocity- or impulse-level scheme of this package ends a step with the
same problem on its active contacts: local velocities ``U = U_free + W p``
(``W`` the Delassus matrix over the stacked normal and tangential rows),
Newton's impact law ``0 <= U_N + e min(vN_pre, 0) _|_ p_N >= 0`` and 2D
Coulomb friction. The schemes differ only in what they put into ``W``,
``U_free``, ``e`` and ``vN_pre``. :func:`solve_contact_problem` solves it:
one active contact by exact enumeration
(:func:`one_contact_impulse`), several by the
friction LCP (:func:`moreau.lcp.friction.build_friction_lcp`) through
:func:`moreau.lcp.solve_lcp`: Lemke, then the QP fallback with
``lcp_method="auto"``. A problem that is not solved raises
:class:`~moreau.errors.LCPError`; no false solution is returned.
"""

import numpy as np

from ..errors import LCPError, PainleveError
from ..lcp import lcp_residual, solve_lcp
from ..lcp.friction import build_friction_lcp, friction_impulses
from . import _mj_kernels as _kernels

__all__ = ["solve_contact_problem", "new_contact_counters", "one_contact_impulse",
           "one_contact_residual"]


def new_contact_counters():
    """The statistics :func:`solve_contact_problem` updates, all zero."""
    return {"lcp_solves": 0, "direct_solves": 0, "pivots": 0, "fallbacks": 0,
            "max_residual": 0.0}


def solve_contact_problem(W, U_free, mu, e, vN_pre, *, lcp_method="auto", counters=None,
                          lemke_max_iter=None, t=None):
    """Impulses of the active contacts of one step.

    Parameters
    ----------
    W : ndarray, shape (na + nf, na + nf)
        Delassus matrix over the rows ``[N of every active contact; T of the
        active frictional ones]``, the tangential rows in the order of the
        frictional contacts among the active ones.
    U_free : ndarray, shape (na + nf,)
        Local velocities without contact impulses.
    mu, e, vN_pre : ndarray, shape (na,)
        Friction and restitution coefficients and pre-step normal velocities
        of the active contacts.
    lcp_method : {"auto", "lemke", "qp"}
        ``"auto"`` solves one contact in closed form; ``"lemke"`` and
        ``"qp"`` force that solver on the assembled LCP.
    counters : dict, optional
        Updated in place (keys of :func:`new_contact_counters`).
    lemke_max_iter : int, optional
        Pivot limit of Lemke's method.
    t : float, optional
        Time of the step, for the error message.

    Returns
    -------
    p : ndarray, shape (na + nf,)
        The impulses, stacked like the rows of ``W``.
    pN, pT : ndarray, shape (na,)
        Normal and tangential impulse of each active contact (``pT = 0`` on
        a frictionless one).

    Raises
    ------
    LCPError
        The contact problem has no certified solution.
    PainleveError
        One contact violates the discrete Painlevé condition.

    Examples
    --------
    A unit mass sliding at speed 1 onto the ground at approach speed 1, ``mu = 0.5``:

    >>> p, pN, pT = solve_contact_problem(np.eye(2), np.array([-1.0, 1.0]), np.array([0.5]),
    ...                                   np.zeros(1), np.zeros(1))
    >>> pN, pT
    (array([1.]), array([-0.5]))
    """
    c = counters if counters is not None else new_contact_counters()
    mu = np.asarray(mu, dtype=float)
    e = np.asarray(e, dtype=float)
    vN_pre = np.asarray(vN_pre, dtype=float)
    na = mu.size
    c["lcp_solves"] += 1
    if na == 1 and lcp_method == "auto":
        c["direct_solves"] += 1
        if mu[0] > 0.0:
            pn, pt = one_contact_impulse(W, U_free, mu[0], e[0], vN_pre[0])
            res = one_contact_residual(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U_free[0], U_free[1],
                                       mu[0], e[0], vN_pre[0], pn, pt)
            p = np.array([pn, pt])
        else:
            pn, pt = one_contact_impulse(W[:1, :1], U_free[:1], 0.0, e[0], vN_pre[0])
            res = one_contact_residual(W[0, 0], 0.0, 0.0, 0.0, U_free[0], 0.0, 0.0, e[0],
                                       vN_pre[0], pn, 0.0)
            p = np.array([pn])
        c["max_residual"] = max(c["max_residual"], float(res))
        return p, np.array([pn]), np.array([pt])
    Ml, ql, layout = build_friction_lcp(W, U_free, mu, e, vN_pre)
    r = solve_lcp(Ml, ql, method=lcp_method, friction=layout, max_iter=lemke_max_iter)
    if r.method == "lemke":
        c["pivots"] += int(r.pivots)
    if r.fallback_used:
        c["fallbacks"] += 1
    if not r.success:
        where = f" at t = {t!r}" if t is not None else ""
        raise LCPError(f"contact problem{where} not solved: {r.message}")
    pN, pT = friction_impulses(r.z, layout)
    c["max_residual"] = max(c["max_residual"], float(lcp_residual(Ml, ql, r.z)))
    return friction_impulses(r.z, layout, stacked=True), np.asarray(pN), np.asarray(pT)


def one_contact_impulse(W, u_free, mu, e=0.0, vN_pre=0.0):
    """Exact solution of the one-contact velocity-level Coulomb problem.

    Solves the same problem as the friction LCP of
    :func:`moreau.lcp.friction.build_friction_lcp` for a single contact by
    enumerating its cases: no impulse, stick, positive slip, negative slip.

    Parameters
    ----------
    W : array_like, shape (2, 2) or (1, 1)
        Delassus matrix over the rows ``(N, T)``; ``(1, 1)`` when ``mu = 0``.
    u_free : array_like, shape (2,) or (1,)
        Free normal and tangential velocity at the end of the step.
    mu : float
        Friction coefficient, ``>= 0``.
    e : float
        Newton restitution coefficient.
    vN_pre : float
        Normal velocity before the step; the impact law uses ``min(vN_pre, 0)``.

    Returns
    -------
    pN, pT : float
        Normal and tangential impulse (``pT = 0`` when ``mu = 0``).

    Raises
    ------
    PainleveError
        The contact must act (``u_N < -e min(vN_pre, 0)``), the discrete
        Painlevé condition ``W_NN - mu |W_NT| > 0`` fails, and either the
        free slip ``u_T`` runs along the branch whose normal velocity does not
        grow with ``pN`` (the paradox: only an impulsive jam could solve it) or
        the problem has no solution or several. Where the condition fails but
        the contact slides the harmless way and the solution is unique, it is
        returned.
    FloatingPointError
        The contact must act and ``W_NN`` is not positive and finite, or the
        data are not finite: a diverged state or a mass matrix that is no
        longer positive definite, named as such and not as a Painlevé case.

    Notes
    -----
    For fixed ``pN`` the tangential problem has one solution ``pT(pN)``
    (``W_TT > 0``); the normal velocity ``b + W_NN pN + W_NT pT(pN)`` then
    grows with ``pN`` in stick (slope ``W_NN - W_NT W_TN / W_TT > 0``) and in
    slip (slope ``W_NN -/+ mu W_NT``, positive under the Painlevé condition),
    so exactly one case applies and the result is unique. Cases are tested in
    the order stick, positive slip, negative slip; where two hold (on a case
    boundary) they give the same impulse. When the condition fails, all three
    cases are tried. With ``u_N >= -e min(vN_pre, 0)`` the answer is "no
    impulse" even if a paradoxical slip branch offers a second solution.

    Examples
    --------
    Unit mass sliding at speed 1 onto the ground at approach speed 1, ``mu = 0.5``:

    >>> one_contact_impulse([[1.0, 0.0], [0.0, 1.0]], [-1.0, 1.0], 0.5)
    (1.0, -0.5)
    """
    W = np.asarray(W, dtype=float)
    u = np.asarray(u_free, dtype=float).reshape(-1)
    mu, e, vN_pre = float(mu), float(e), float(vN_pre)
    if not (np.all(np.isfinite(W)) and np.all(np.isfinite(u))):
        raise FloatingPointError(_broken_delassus(float(W[0, 0])))
    if mu > 0.0:
        pN, pT = _one_contact(*(float(x) for x in (W[0, 0], W[0, 1], W[1, 0], W[1, 1], u[0], u[1])),
                              mu, e, vN_pre)
        return pN, pT
    return _one_contact_frictionless(float(W[0, 0]), float(u[0]), e, vN_pre), 0.0


def _one_contact_frictionless(Wnn, uN, e, vN_pre):
    b = uN + e * min(vN_pre, 0.0)
    if b >= 0.0:
        return 0.0
    if not Wnn > 0.0:
        raise FloatingPointError(_broken_delassus(Wnn))
    return -b / Wnn


def _broken_delassus(Wnn):
    # W_NN = w_N M^-1 w_N^T > 0 for every positive definite M and nonzero contact row:
    # anything else is the state or the mass matrix breaking down, not a paradox
    return (f"the contact's Delassus entry W_NN = {Wnn!r} is not positive and finite: the "
            f"mass matrix has lost positive definiteness or the state has diverged (a step "
            f"`h` too large for the stiffest force, or a zero contact row); this is not a "
            f"Painlevé case, which needs W_NN > 0")


def _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre):
    # the compiled case analysis itself, so that the fast and the generic path
    # agree to rounding; here only the failure gets its explanation
    pN, pT, ok = _kernels._one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre)
    if ok:
        return pN, pT
    if not Wnn > 0.0:
        # (non-finite data never get here: one_contact_impulse refuses them first)
        raise FloatingPointError(_broken_delassus(Wnn))
    if (uT > 0.0 and Wnn - mu * Wnt <= 0.0) or (uT < 0.0 and Wnn + mu * Wnt <= 0.0):
        # one slip branch has a non-increasing normal velocity and the step would
        # slide along it: the only way out is an impulsive jam whose size does not
        # vanish with h, so the continuous problem is paradoxical
        raise PainleveError(
            f"discrete Painlevé condition W_NN - mu |W_NT| > 0 violated "
            f"(W_NN = {Wnn:.6g}, W_NT = {Wnt:.6g}, mu = {mu:.6g}) with the contact sliding "
            f"the paradoxical way: no sliding solution exists")
    raise PainleveError(
        f"discrete Painlevé condition W_NN - mu |W_NT| > 0 violated "
        f"(W_NN = {Wnn:.6g}, W_NT = {Wnt:.6g}, mu = {mu:.6g}) and the contact problem has "
        f"no unique solution")


def one_contact_residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    """Scaled residual of ``(pN, pT)`` in the one-contact friction LCP.

    The same number :func:`moreau.lcp.lcp_residual` gives for the LCP of
    :func:`~moreau.lcp.friction.build_friction_lcp` at the point
    ``z = (pN, max(pT, 0), max(-pT, 0), |u_T|)``, computed without building it.
    """
    return _kernels._residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT)
