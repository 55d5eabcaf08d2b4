"""Compiled Moreau–Jean step loop for two-dof scenes with one contact (the friction drive).

This is the fast path of :mod:`moreau.integrators.moreau_jean`: the same
scheme, the same index set, the same one-contact enumeration, the same
regime classification and the same projection, written with scalars so that
a whole run is one ``numba`` call that allocates nothing per step. The model
is read from the buffer layout of :mod:`moreau.scenes._friction_drive_jit`.

Every branch mirrors the generic Python code; the two agree to rounding
(tested to ``1e-12``). If you change one, change the other.
"""

import math

import numpy as np
from numba import njit

from ..scenes._friction_drive_jit import (
    C00, C01, C10, C11, F0, F1, GAP, K00, K01, K10, K11, M00, M01, M10, M11, NOUT,
    P_E, P_MU, WN0, WN1, WNR, WT0, WT1, WTR, fd_eval, fd_gap,
)

__all__ = ["mj_run_fd", "new_stats", "STAT_NAMES", "OK", "PAINLEVE", "NUMERICAL"]

# status codes (those of SimulationResult where they overlap)
OK = 0
PAINLEVE = -1
NUMERICAL = -5

#: layout of the statistics vector
STAT_NAMES = ("lcp_solves", "direct_solves", "pivots", "fallbacks", "max_residual",
              "max_penetration", "projection_iterations")
S_LCP, S_DIRECT, S_PIVOTS, S_FALLBACKS, S_RES, S_PEN, S_PROJ = range(7)

# shared with moreau_jean.py (kept as literals so that numba freezes them)
SLIP_RTOL = 1e-10
PROJECTION_TOL = 1e-14
PROJECTION_MAXITER = 8


def new_stats():
    return np.zeros(len(STAT_NAMES))


@njit(cache=True, inline="always")
def _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre):
    # returns (pN, pT, ok); ok = False when the discrete Painlevé condition
    # fails and the problem has no solution or several (see moreau_jean.py)
    b = uN + e * min(vN_pre, 0.0)
    if b >= 0.0:
        return 0.0, 0.0, True
    if mu > 0.0:
        det = Wnn * Wtt - Wnt * Wtn
        if Wnn - mu * abs(Wnt) > 0.0:
            if det > 0.0:
                pN = (Wnt * uT - Wtt * b) / det
                pT = (Wtn * b - Wnn * uT) / det
                if pN >= 0.0 and abs(pT) <= mu * pN:
                    return pN, pT, True
            pN = -b / (Wnn - mu * Wnt)
            if uT + (Wtn - mu * Wtt) * pN >= 0.0:
                return pN, -mu * pN, True
            pN = -b / (Wnn + mu * Wnt)
            return pN, mu * pN, True
        if (uT > 0.0 and Wnn - mu * Wnt <= 0.0) or (uT < 0.0 and Wnn + mu * Wnt <= 0.0):
            return 0.0, 0.0, False
        nfound = 0
        fN = 0.0
        fT = 0.0
        ok = True
        for case in range(3):
            valid = False
            pN = 0.0
            pT = 0.0
            if case == 0:
                if det != 0.0:
                    pN = (Wnt * uT - Wtt * b) / det
                    pT = (Wtn * b - Wnn * uT) / det
                    valid = pN >= 0.0 and abs(pT) <= mu * pN
            elif case == 1:
                den = Wnn - mu * Wnt
                if den != 0.0:
                    pN = -b / den
                    pT = -mu * pN
                    valid = pN >= 0.0 and uT + (Wtn - mu * Wtt) * pN >= 0.0
            else:
                den = Wnn + mu * Wnt
                if den != 0.0:
                    pN = -b / den
                    pT = mu * pN
                    valid = pN >= 0.0 and uT + (Wtn + mu * Wtt) * pN <= 0.0
            if valid:
                if nfound == 0:
                    fN = pN
                    fT = pT
                elif (abs(pN - fN) > 1e-9 * (1.0 + abs(fN))
                      or abs(pT - fT) > 1e-9 * (1.0 + abs(fT))):
                    ok = False
                nfound += 1
        if nfound == 0:
            ok = False
        return fN, fT, ok
    if not Wnn > 0.0:
        return 0.0, 0.0, False
    return -b / Wnn, 0.0, True


@njit(cache=True, inline="always")
def _residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    b = uN + e * min(vN_pre, 0.0)
    vN = b + Wnn * pN + Wnt * pT
    if not mu > 0.0:
        return abs(min(pN, vN)) / (1.0 + abs(b) + abs(Wnn) * abs(pN))
    vT = uT + Wtn * pN + Wtt * pT
    tp = max(pT, 0.0)
    tm = max(-pT, 0.0)
    beta = abs(vT)
    num = max(max(abs(min(pN, vN)), abs(min(tp, vT + beta))),
              max(abs(min(tm, beta - vT)), abs(min(beta, mu * pN - tp - tm))))
    mmax = max(max(abs(Wnn), abs(Wnt)), max(max(abs(Wtn), abs(Wtt)), max(mu, 1.0)))
    scale = 1.0 + max(abs(b), abs(uT)) + mmax * max(max(pN, tp), max(tm, beta))
    return num / scale


@njit(cache=True, inline="always")
def _classify(pN, pT, mu):
    if not pN > 0.0:
        return 0
    if mu > 0.0:
        bound = mu * pN * (1.0 - SLIP_RTOL)
        if pT <= -bound:
            return 1
        if pT >= bound:
            return 2
    return 3


@njit(cache=True, inline="always")
def _store(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, i,
           t, q0, q1, v0, v1, reg, fN, fT, slip, gap):
    rec_t[i] = t
    rec_q[i, 0] = q0
    rec_q[i, 1] = q1
    rec_v[i, 0] = v0
    rec_v[i, 1] = v1
    rec_reg[i] = reg
    rec_fN[i] = fN
    rec_fT[i] = fT
    rec_slip[i] = slip
    rec_gap[i] = gap


@njit(cache=True)
def mj_run_fd(par, t0, h, t_bound, k0, nmax, q, v, theta, projection, closed, save_every,
              record_initial, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
              stats):
    """Run up to ``nmax`` Moreau–Jean steps of the friction drive in one compiled call.

    Parameters
    ----------
    par : float64[:]
        From :func:`moreau.scenes._friction_drive_jit.pack_params`.
    t0, h, t_bound : float
        Grid ``t0 + k h``; the step that reaches ``t_bound`` is cut there.
    k0 : int
        Index of the first step (``t_k0 = t0 + k0 h``).
    nmax : int
        Most steps to take in this call.
    q, v : float64[2]
        State at ``t_k0``; overwritten with the final state.
    theta : float
    projection : bool
    closed : bool
        Whether the contact carried a normal impulse in the step before ``k0``.
    save_every : int
        Record after every ``save_every``-th step (counted from ``t0``) and after the last.
    record_initial : bool
        Also record the state at ``t_k0`` (with the first step's regime and forces).
    rec_* : arrays
        Sample buffers (``rec_q``, ``rec_v`` of shape (n, 2)); must be long
        enough for the samples of this call.
    stats : float64[:]
        Accumulated statistics, layout :data:`STAT_NAMES`.

    Returns
    -------
    status : int
        ``OK``, ``PAINLEVE`` or ``NUMERICAL`` (the state is the last good one).
    k : int
        Index of the next step (steps taken: ``k - k0``).
    nrec : int
        Samples written.
    closed : bool
        Contact flag after the last step.
    """
    b0 = np.empty(NOUT)
    b1 = np.empty(NOUT)
    mu = par[P_MU]
    e = par[P_E]
    th = theta
    nrec = 0
    k = k0
    q0_ = q[0]
    q1_ = q[1]
    v0_ = v[0]
    v1_ = v[1]
    status = OK
    while k - k0 < nmax:
        tk = t0 + k * h
        t1 = t0 + (k + 1) * h
        hk = h
        last = False
        if t1 >= t_bound - 1e-9 * h:
            t1 = t_bound
            hk = t_bound - tk
            last = True
        if tk >= t_bound:
            break
        fd_eval(q0_, v0_, tk, par, b0)
        fd_eval(q0_, v0_, t1, par, b1)
        b0_gap = b0[GAP]
        # free velocity: W_hat dv = h [theta f1 + (1 - theta) f0] + h^2 theta K v
        f0 = b1[F0]
        f1 = b1[F1]
        if th != 1.0:
            f0 = th * f0 + (1.0 - th) * b0[F0]
            f1 = th * f1 + (1.0 - th) * b0[F1]
        a = hk * th
        a2 = hk * hk * th
        r0 = hk * f0 + a2 * (b1[K00] * v0_ + b1[K01] * v1_)
        r1 = hk * f1 + a2 * (b1[K10] * v0_ + b1[K11] * v1_)
        a2 = a2 * th
        w00 = b1[M00] - a * b1[C00] - a2 * b1[K00]
        w01 = b1[M01] - a * b1[C01] - a2 * b1[K01]
        w10 = b1[M10] - a * b1[C10] - a2 * b1[K10]
        w11 = b1[M11] - a * b1[C11] - a2 * b1[K11]
        det = w00 * w11 - w01 * w10
        i00 = w11 / det
        i01 = -w01 / det
        i10 = -w10 / det
        i11 = w00 / det
        n1 = max(abs(w00) + abs(w10), abs(w01) + abs(w11))
        ni = max(abs(i00) + abs(i10), abs(i01) + abs(i11))
        if not (n1 * ni < 1e14):
            status = NUMERICAL
            break
        vf0 = v0_ + (i00 * r0 + i01 * r1)
        vf1 = v1_ + (i10 * r0 + i11 * r1)

        # index set: predicted gap, or closed in the previous step
        vN0 = b0[WN0] * v0_ + b0[WN1] * v1_ + b0[WNR]
        active = (b0_gap + 0.5 * hk * vN0 <= 0.0) or closed
        pN = 0.0
        pT = 0.0
        slip = 0.0
        nv0 = vf0
        nv1 = vf1
        if active:
            # W_hat^-1 H^T columns and the Delassus entries
            an0 = i00 * b1[WN0] + i01 * b1[WN1]
            an1 = i10 * b1[WN0] + i11 * b1[WN1]
            Wnn = b1[WN0] * an0 + b1[WN1] * an1
            uN = b1[WN0] * vf0 + b1[WN1] * vf1 + b1[WNR]
            if mu > 0.0:
                at0 = i00 * b1[WT0] + i01 * b1[WT1]
                at1 = i10 * b1[WT0] + i11 * b1[WT1]
                Wnt = b1[WN0] * at0 + b1[WN1] * at1
                Wtn = b1[WT0] * an0 + b1[WT1] * an1
                Wtt = b1[WT0] * at0 + b1[WT1] * at1
                uT = b1[WT0] * vf0 + b1[WT1] * vf1 + b1[WTR]
            else:
                at0 = 0.0
                at1 = 0.0
                Wnt = 0.0
                Wtn = 0.0
                Wtt = 0.0
                uT = 0.0
            pN, pT, ok = _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN0)
            if not ok:
                status = PAINLEVE
                break
            stats[S_LCP] += 1.0
            stats[S_DIRECT] += 1.0
            res = _residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN0, pN, pT)
            if res > stats[S_RES]:
                stats[S_RES] = res
            nv0 = vf0 + (an0 * pN + at0 * pT)
            nv1 = vf1 + (an1 * pN + at1 * pT)
            if mu > 0.0:
                slip = uT + (Wtn * pN + Wtt * pT)

        nq0 = q0_ + hk * (th * nv0 + (1.0 - th) * v0_)
        nq1 = q1_ + hk * (th * nv1 + (1.0 - th) * v1_)
        is_closed = pN > 0.0
        if projection:
            sel = is_closed
            for _ in range(PROJECTION_MAXITER):
                fd_eval(nq0, nv0, t1, par, b0)
                g = b0[GAP]
                if g < 0.0:
                    sel = True
                if (not sel) or abs(g) <= PROJECTION_TOL:
                    break
                # q += M^-1 WN^T d with (WN M^-1 WN^T) d = -g
                dm = b0[M00] * b0[M11] - b0[M01] * b0[M10]
                m0 = (b0[M11] * b0[WN0] - b0[M01] * b0[WN1]) / dm
                m1 = (-b0[M10] * b0[WN0] + b0[M00] * b0[WN1]) / dm
                d = -g / (b0[WN0] * m0 + b0[WN1] * m1)
                nq0 = nq0 + m0 * d
                nq1 = nq1 + m1 * d
                stats[S_PROJ] += 1.0
        if not (math.isfinite(nq0) and math.isfinite(nq1) and math.isfinite(nv0)
                and math.isfinite(nv1)):
            status = NUMERICAL
            break
        gap = fd_gap(nq0, t1, par)
        if -gap > stats[S_PEN]:
            stats[S_PEN] = -gap
        reg = _classify(pN, pT, mu)
        if record_initial:
            _store(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                   tk, q0_, q1_, v0_, v1_, reg, pN / hk, pT / hk, slip, b0_gap)
            nrec += 1
            record_initial = False
        closed = is_closed
        q0_ = nq0
        q1_ = nq1
        v0_ = nv0
        v1_ = nv1
        k += 1
        if k % save_every == 0 or last:
            _store(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                   t1, q0_, q1_, v0_, v1_, reg, pN / hk, pT / hk, slip, gap)
            nrec += 1
        if last:
            break
    q[0] = q0_
    q[1] = q1_
    v[0] = v0_
    v[1] = v1_
    return status, k, nrec, closed
