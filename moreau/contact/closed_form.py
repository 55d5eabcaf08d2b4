"""The contact problem's exact solutions: one contact in closed form, a few by their pieces.

One active contact is solved by exact enumeration of its cases
(:func:`one_contact_impulse`: open, stick, slip either way), with the
tangential impact (:func:`tangential_impact`) where the discrete Painlevé
condition fails; up to :data:`MAX_PIECES_CONTACTS` contacts by enumerating
every contact's piece (:func:`friction_pieces`), the certified rescue of a
float Lemke that ends on a ray. The rows are those of
:mod:`moreau.contact.problem` without equality rows: ``[N of every contact;
T of the frictional ones]``.
"""

from itertools import product

import numpy as np
from scipy.optimize import linprog

from ..errors import PainleveError
from ..lcp import lcp_violation
from ..lcp.lemke import DEFAULT_TOL
from ..lcp.friction import build_friction_lcp
from . import _one_contact as _kernels

__all__ = ["one_contact_impulse", "one_contact_residual", "tangential_impact",
           "friction_pieces", "friction_point", "MAX_PIECES_CONTACTS"]


def tangential_impact(W, U_free, mu, e, vN_pre, slip_before):
    """Whether a one-contact step is a tangential impact (dynamic jamming).

    The contact slid the way ``slip_before`` (``+1`` positive slip, ``-1``
    negative, ``0`` not sliding) at the end of the step before, it presses
    (``b = u_N + e min(vN_pre, 0) < 0``) and its sliding piece that way has a
    normal velocity that does not grow with the normal impulse,
    ``W_NN - mu s W_NT <= 0``: sliding on has no solution, and the step's
    unique answer (:func:`one_contact_impulse`) is the stick, whose impulse
    does not vanish with the step (Génot and Brogliato 1999's tangential
    impact, Stewart 1998's impulsive resolution of Painlevé's paradox).

    Parameters
    ----------
    W : array_like, shape (2, 2)
    U_free : array_like, shape (2,)
    mu, e, vN_pre, slip_before : float

    Examples
    --------
    A rod's tip sliding the paradoxical way (``W_NN = 1.6``, ``W_NT = 1.2``, ``mu = 10``):

    >>> W = [[1.6, 1.2], [1.2, 1.4]]
    >>> tangential_impact(W, [-1e-3, 0.5], 10.0, 0.0, 0.0, 1.0)
    True
    >>> tangential_impact(W, [-1e-3, 0.5], 10.0, 0.0, 0.0, 0.0)   # it was not sliding
    False
    """
    W = np.asarray(W, dtype=float)
    U = np.asarray(U_free, dtype=float).reshape(-1)
    return bool(_kernels._jam(float(W[0, 0]), float(W[0, 1]), float(mu), float(U[0]), float(e),
                              float(vN_pre), float(slip_before)))

#: most active contacts whose pieces :func:`friction_pieces` enumerates (4^4 = 256 pieces)
MAX_PIECES_CONTACTS = 4


def friction_pieces(W, U_free, mu, e, vN_pre, Ml=None, ql=None, layout=None):
    """A certified solution of the contact problem by enumerating each contact's piece.

    Each contact is open, sticking, sliding positively or negatively (open or
    closed without friction). A choice of pieces fixes ``m`` linear
    equations on the stacked impulse ``p`` (an open contact's impulses zero,
    a closed one's normal velocity zero, a sticking one's slip zero, a
    sliding one's ``p_T = -/+ mu p_N``) and inequalities (the other side of
    each complementarity, the cone). Where the equations are regular the
    piece is one solve; where they are singular (redundant contacts: a block
    flat on two sticking corners) a point of the affine solution set that
    meets the inequalities is found by a linear program (HiGHS) and
    projected back onto the equations. A candidate is kept only when it
    passes the check every LCP solution passes
    (:func:`moreau.lcp.lcp_violation` on the friction LCP of
    :func:`~moreau.lcp.friction.build_friction_lcp`, at Lemke's tolerance).

    Returns the LCP vector ``z`` (``layout``'s order), or None where no piece
    gives a certified solution.

    Examples
    --------
    Two sticking corners of a block at rest (4 rows on 3 dof, ``W`` singular):

    >>> J = np.array([[0, 1, -0.5], [0, 1, 0.5], [1, 0, 1.0], [1, 0, 1.0]])
    >>> W = J @ np.diag([1.0, 1.0, 3.0 / 1.25]) @ J.T
    >>> z = friction_pieces(W, np.array([-0.1, -0.1, 0.0, 0.0]), np.array([1.0, 1.0]),
    ...                     np.zeros(2), np.zeros(2))
    >>> Ml, ql, layout = build_friction_lcp(W, [-0.1, -0.1, 0.0, 0.0], [1.0, 1.0], 0.0)
    >>> bool(lcp_violation(Ml, ql, z) <= DEFAULT_TOL)
    True
    """
    W = np.asarray(W, dtype=float)
    U = np.asarray(U_free, dtype=float)
    mu = np.asarray(mu, dtype=float)
    e = np.asarray(e, dtype=float)
    vN_pre = np.asarray(vN_pre, dtype=float)
    if Ml is None:
        Ml, ql, layout = build_friction_lcp(W, U, mu, e, vN_pre)
    na = mu.size
    m = W.shape[0]
    b = U.copy()
    b[:na] += e * np.minimum(vN_pre, 0.0)
    trow = np.full(na, -1)
    trow[mu > 0.0] = na + np.arange(int(np.sum(mu > 0.0)))
    choices = [("S", "P", "N", "O") if trow[i] >= 0 else ("C", "O") for i in range(na)]
    scale = max(float(np.max(np.abs(W))), 1.0)
    for combo in product(*choices):
        E = np.zeros((m, m))
        f = np.zeros(m)
        G, g = [], []           # G p <= g
        for i, mode in enumerate(combo):
            n_, t_ = i, trow[i]
            if mode == "O":
                E[n_, n_] = 1.0
                G.append(-W[n_])
                g.append(b[n_])                      # vN = b + W p >= 0
                if t_ >= 0:
                    E[t_, t_] = 1.0
                continue
            E[n_] = W[n_]
            f[n_] = -b[n_]
            row = np.zeros(m)
            row[n_] = -1.0
            G.append(row)
            g.append(0.0)                            # pN >= 0
            if t_ < 0:
                continue
            if mode == "S":
                E[t_] = W[t_]
                f[t_] = -b[t_]
                for sgn in (1.0, -1.0):              # sgn pT - mu pN <= 0
                    row = np.zeros(m)
                    row[t_] = sgn
                    row[n_] = -mu[i]
                    G.append(row)
                    g.append(0.0)
            else:
                s = 1.0 if mode == "P" else -1.0     # slip +: pT = -mu pN, vT >= 0
                E[t_, t_] = 1.0
                E[t_, n_] = s * mu[i]
                G.append(-s * W[t_])
                g.append(s * b[t_])
        G, g = np.array(G), np.array(g)
        p = _piece_point(E, f, G, g, scale)
        if p is None:
            continue
        z = friction_point(layout, p, (b + W @ p)[na:])
        if lcp_violation(Ml, ql, z) <= DEFAULT_TOL:
            return z
    return None


def friction_point(layout, p, vT):
    """The friction LCP's variables ``z`` of the stacked impulse ``p`` (rows ``[N; T]``).

    ``p_T+ = max(p_T, 0)``, ``p_T- = max(-p_T, 0)`` and ``beta = |v_T|``, with
    ``vT`` the tangential velocities of the frictional contacts; ``layout``
    from :func:`~moreau.lcp.friction.build_friction_lcp`.

    Examples
    --------
    >>> from moreau.lcp.friction import FrictionLayout
    >>> friction_point(FrictionLayout([0.5, 0.0], [0.0, 0.0]), np.array([2.0, 1.0, -0.5]),
    ...                np.array([0.25])).tolist()
    [2.0, 0.0, 0.5, 0.25, 1.0]
    """
    na = layout.n_contacts
    z = np.zeros(layout.size)
    z[layout.normal] = p[:na]
    fr = layout.frictional
    pT = p[na:]
    z[layout.tplus[fr]] = np.maximum(pT, 0.0)
    z[layout.tminus[fr]] = np.maximum(-pT, 0.0)
    z[layout.beta[fr]] = np.abs(vT)
    return z


def _piece_point(E, f, G, g, scale):
    # a point with E p = f and G p <= g (to rounding), or None
    try:
        cond = np.linalg.cond(E)
    except np.linalg.LinAlgError:
        cond = np.inf
    if np.isfinite(cond) and cond < 1e10:
        p = np.linalg.solve(E, f)
        tol = 1e-9 * (scale * float(np.max(np.abs(p), initial=0.0)) + float(np.max(np.abs(f), initial=0.0)) + 1e-300)
        return p if np.all(G @ p <= g + tol) else None
    res = linprog(np.zeros(E.shape[1]), A_ub=G, b_ub=g, A_eq=E, b_eq=f,
                  bounds=[(None, None)] * E.shape[1], method="highs")
    if res.status != 0:
        return None
    p = res.x
    # back onto the equations exactly (the inequalities had slack or are checked next)
    p = p + np.linalg.lstsq(E, f - E @ p, rcond=1e-12)[0]
    return p


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
        Painlevé condition ``W_NN - mu |W_NT| > 0`` fails and ``W`` is
        singular, so that the problem has no solution or several. With ``W``
        positive definite there is always exactly one answer, the
        tangential impact included (Notes).
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
    boundary) they give the same impulse. With ``u_N >= -e min(vN_pre, 0)``
    the answer is "no impulse" even if a paradoxical slip branch offers a
    second solution.

    When the condition fails, the problem still has exactly one solution for
    ``b = u_N + e min(vN_pre, 0) < 0`` and ``W`` positive definite. Take
    ``pN`` as the parameter: ``pT(pN)`` is the clamp of ``-(u_T + W_TN pN) /
    W_TT`` to ``[-mu pN, mu pN]``, so ``pN -> v_N(pN)`` is continuous and
    piecewise linear, from ``v_N(0) = b < 0``, in at most three pieces: a
    slip against the free slip ``u_T`` (slope ``W_NN - mu sign(u_T) W_NT``,
    the only one that may fall), stick (slope ``det W / W_TT > 0``) and,
    only where ``|W_NT| > mu W_TT``, a slip beyond it (slope ``W_NN - mu
    |W_NT| > 0``, since then ``W_NN > W_NT^2 / W_TT > mu |W_NT|``). The last
    piece is unbounded with a positive slope, so ``v_N`` has exactly one
    root. Where the first piece falls (the free slip runs the paradoxical
    way) the root lies on the stick piece: the tangential impact, whose
    impulse ``-W^-1 (b, u_T)`` does not vanish with the step
    (:func:`tangential_impact`). The friction LCP of one contact is the
    same problem: its matrix is copositive (``z^T M z = p^T W p + mu beta
    pN``) and ``z >= 0, M z >= 0, z^T M z = 0`` forces ``p = 0``, so
    ``z^T q = 0``: the condition under which Lemke's method (covering vector
    ``d > 0``) cannot end on a secondary ray of a copositive LCP (Cottle,
    Pang and Stone 1992, Sec. 4.4; Anitescu and Potra 1997): a ray
    ``(z*, z0*) + lambda (z_h, 0)`` has ``z_h >= 0, M z_h >= 0, z_h^T M z_h
    = 0`` and ``z_h^T q = -z_h^T M z* - z0* d^T z_h < 0``, the first term
    being ``>= 0`` by copositivity.

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
    # a positive definite W always gives one answer (see _one_contact._one_contact_cases):
    # only a singular one (normal and tangential rows dependent) gets here
    raise PainleveError(
        f"discrete Painlevé condition W_NN - mu |W_NT| > 0 violated "
        f"(W_NN = {Wnn:.6g}, W_NT = {Wnt:.6g}, mu = {mu:.6g}) on a singular Delassus matrix "
        f"(W_NN W_TT - W_NT W_TN = {Wnn * Wtt - Wnt * Wtn:.6g}): the contact problem has no "
        f"unique solution")


def one_contact_residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    """Scaled residual of ``(pN, pT)`` in the one-contact friction LCP.

    The same number :func:`moreau.lcp.lcp_residual` gives for the LCP of
    :func:`~moreau.lcp.friction.build_friction_lcp` at the point
    ``z = (pN, max(pT, 0), max(-pT, 0), |u_T|)``, computed without building it.
    """
    return _kernels._residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT)
