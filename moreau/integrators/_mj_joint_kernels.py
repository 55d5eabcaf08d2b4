"""Compiled Moreau–Jean steps of a scene with joints: the step's mixed LCP in the loop.

The fast path of :meth:`moreau.integrators.moreau_jean.MoreauJean._joint_step`
for scenes that give their joint rows as a compiled function
(``scene.compiled_joints()``, the planar builder's scenes): the same step,
the same time grid, index set, rows and elimination, run as one ``numba``
call over a block of steps. Per step:

* the free velocity ``v_free = v + W_hat^-1 h f`` of the θ-method (with the
  forces' Jacobians where the model has them), ``W_hat^-1`` by LAPACK as on
  the generic path;
* the rows ``H = [WE; WN; WT]``: the joints' Jacobian at the predicted
  θ-point or end point, the active contact's rows at ``(q_k, t_k+1)``, the
  Delassus matrix ``W = H W_hat^-1 H^T`` and ``U_free = H v_free + w``; the
  joint rows' target with the Baumgarte term ``-(alpha / h) gE(q_k, t_k)``
  where ``alpha > 0``;
* the equality rows eliminated as :mod:`moreau.contact.solvers.mlcp` does:
  the block ``A`` checked by its singular values (:data:`RANK_RTOL`), the
  Schur complement ``W_S = B - D A^-1 C``, ``u_S = b - D A^-1 a``, the
  contact by the closed form of :mod:`moreau.contact._one_contact` (the
  function the generic path calls), ``p_E = -A^-1 (a + C p_C)`` with one
  step of iterative refinement; the answer is checked on the whole mixed
  LCP by the violation of :func:`moreau.lcp.mlcp.mlcp_violation` at Lemke's
  tolerance.

A step the loop does not take returns :data:`LCP_HANDBACK` before it: more
than one active contact (the generic step runs Lemke), a case the closed
form leaves to the generic step (a tangential impact, a Painlevé case), a
rank-deficient equality block (the generic step names the rows), or a
failed check. The caller takes that step in Python and calls the loop again.
"""

import math
import threading

import numpy as np
import numba
from numba import njit
from numba.core import types as nbtypes

from .. import _jit_cache
from ..contact import _one_contact as _one_contact_module
from ..lcp.lemke import DEFAULT_TOL
from ..lcp.mlcp import RANK_RTOL
from ._contact_step import LCP_HANDBACK, NUMERICAL, OK, SINGULAR, _classify
from . import _driver
from ._driver import grid_step, record_sample

__all__ = ["run_joint_block", "J_STAT_NAMES"]

_one_contact = _one_contact_module._one_contact

#: the loop's statistics: contact problems solved, the largest mixed-LCP residual
#: (:func:`moreau.lcp.mlcp.mlcp_residual`), the largest penetration and joint residual
J_STAT_NAMES = ("lcp_solves", "max_residual", "max_penetration", "max_drift")
_EPS = float(np.finfo(float).eps)
#: the generic step's bound on the 1-norm condition number of ``W_hat`` (moreau_jean._inverse)
COND_MAX = 1e14


@njit(cache=True)
def _mlcp_check(W, Uf, target, k, pE, pn, pt, mu, e, vN0, fr):
    """``(violation, residual)`` of the step's mixed LCP at its answer (mlcp_violation, mlcp_residual).

    The friction MLCP of one contact on the caller's data: variables
    ``x = (p_E, pN[, t+, t-, beta])``, matrix ``[[A, C S], [S^T D, S^T B S +
    friction rows]]``, ``q = (u_E - target, u_N + e min(vN0, 0)[, u_T, -u_T, 0])``;
    the equality rows alone (``x = p_E``, ``M = A``) where ``pn < 0`` (no contact).
    """
    L = 0 if pn < 0.0 else 4 if fr else 1
    m = k + L
    Mm = np.zeros((m, m))
    qm = np.zeros(m)
    x = np.zeros(m)
    # S: the contact variables' columns in the stacked rows (N, then T)
    S = np.zeros((2, max(L, 1)))
    S[0, 0] = 1.0
    if fr:
        S[1, 1] = 1.0
        S[1, 2] = -1.0
    nr = 2 if fr else 1
    for i in range(k):
        for j in range(k):
            Mm[i, j] = W[i, j]
        for c in range(L):
            acc = 0.0
            for r in range(nr):
                acc += W[i, k + r] * S[r, c]
            Mm[i, k + c] = acc
            acc = 0.0
            for r in range(nr):
                acc += S[r, c] * W[k + r, i]
            Mm[k + c, i] = acc
        qm[i] = Uf[i] - target[i]
        x[i] = pE[i]
    for a in range(L):
        for b in range(L):
            acc = 0.0
            for r in range(nr):
                for s in range(nr):
                    acc += S[r, a] * W[k + r, k + s] * S[s, b]
            Mm[k + a, k + b] = acc
    if L > 0:
        qm[k] = Uf[k] + e * min(vN0, 0.0)
        x[k] = pn
    if L > 1:
        qm[k + 1] = Uf[k + 1]
        qm[k + 2] = -Uf[k + 1]
        Mm[k + 1, k + 3] = 1.0
        Mm[k + 2, k + 3] = 1.0
        Mm[k + 3, k] = mu
        Mm[k + 3, k + 1] = -1.0
        Mm[k + 3, k + 2] = -1.0
        vT = Uf[k + 1] + W[k + 1, k] * pn + W[k + 1, k + 1] * pt
        for j in range(k):
            vT += W[k + 1, j] * pE[j]
        x[k + 1] = max(pt, 0.0)
        x[k + 2] = max(-pt, 0.0)
        x[k + 3] = abs(vT)
    mmax = 0.0
    qmax = 0.0
    xmax = 0.0
    for i in range(m):
        qmax = max(qmax, abs(qm[i]))
        xmax = max(xmax, abs(x[i]))
        for j in range(m):
            mmax = max(mmax, abs(Mm[i, j]))
    worst = 0.0
    num = 0.0
    ms = mmax if mmax > 0.0 else 1.0
    for i in range(m):
        w = qm[i]
        r = abs(qm[i])
        for j in range(m):
            w += Mm[i, j] * x[j]
            r += abs(Mm[i, j]) * abs(x[j])
        r *= (m + 2) * _EPS
        if i < k:
            worst = max(worst, abs(w) + r)
            num = max(num, abs(w))
        else:
            a = ms * x[i]
            worst = max(worst, abs(min(a, w - r)), abs(min(a, w + r)))
            num = max(num, abs(min(x[i], w)))
    qs = qmax if qmax > 0.0 else 1.0
    viol = worst / qs
    if not math.isfinite(viol):
        viol = np.inf
    return viol, num / (1.0 + qmax + mmax * xmax)


#: ``k cond_1(A)`` below which the SVD's rank test cannot fail (see :func:`_regular`)
SURE_REGULAR = 1e10


@njit(cache=True)
def _norm1(A, k):
    out = 0.0
    for j in range(k):
        c = 0.0
        for i in range(k):
            c += abs(A[i, j])
        out = max(out, c)
    return out


@njit(cache=True)
def _regular(A, k):
    """Whether the equality block ``A`` has full rank by its singular values (as equality_block).

    The SVD (most of a step's time at six rows) is taken only where a cheaper
    bound leaves the answer open: ``cond_2(A) <= k cond_1(A)`` (``||B||_2 <=
    sqrt(k) ||B||_1`` for ``A`` and ``A^-1``), so below :data:`SURE_REGULAR`
    the smallest singular value is above ``1e-10`` times the largest, far above
    :data:`RANK_RTOL` and the SVD's rounding: the SVD would say full rank.
    """
    if k == 0:
        return True
    for i in range(k):
        for j in range(k):
            if not math.isfinite(A[i, j]):
                return False
    Ac = np.ascontiguousarray(A)
    try:
        c = k * _norm1(Ac, k) * _norm1(np.linalg.inv(Ac), k)
        if math.isfinite(c) and c < SURE_REGULAR:
            return True
    except Exception:  # noqa: BLE001  (an exactly singular A: the SVD decides)
        pass
    s = np.linalg.svd(Ac)[1]
    return s[0] > 0.0 and s[k - 1] > RANK_RTOL * s[0]


@njit(inline="always")
def _solve_vector(A, b):
    """``np.linalg.solve(A, b)`` of a contiguous vector ``b``, taken as a one-column matrix.

    The same LAPACK call on the same numbers as the vector form, so the same
    bits; numba then compiles one form of ``solve`` for the loop, not two
    (the vector form's argument checks and messages alone cost 2-3 CPU s).
    """
    return np.ascontiguousarray(np.linalg.solve(A, b.reshape((b.shape[0], 1)))[:, 0])


@njit(cache=True)
def _refined(A, rhs):
    """``A^-1 rhs`` with one step of iterative refinement (moreau.lcp.mlcp.free_part)."""
    u = _solve_vector(A, rhs)
    return u + _solve_vector(A, rhs - A @ u)


@njit(cache=True, error_model="numpy")
def mj_joint_loop(mass_fn, forces_fn, contacts_fn, joints_fn, n, nc, nj, has_jac,
                  par, mu, e, t0, h, t_bound, k0, nmax, q, v, theta, theta_rows, alpha, closed,
                  reg,
                  save_every, record_initial, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT,
                  rec_slip, rec_gap, stats):
    """Up to ``nmax`` Moreau–Jean steps of a scene with joints (module docstring).

    Returns ``(status, k, nrec)`` as the fixed-step driver does
    (:func:`moreau.integrators._driver.drive`); ``closed`` (the contacts
    that carried a normal impulse) and ``reg`` (the regimes of the last
    step) are updated; ``stats`` accumulates :data:`J_STAT_NAMES`.
    """
    ncm = max(nc, 1)
    w2 = 3 + 2 * n
    M = np.zeros((n, n))
    D = np.zeros((n, 1 + 2 * n))
    D0 = np.zeros((n, 1 + 2 * n))
    G0 = np.zeros((ncm, w2))
    G1 = np.zeros((ncm, w2))
    Gq = np.zeros((ncm, w2))
    GE = np.zeros((max(nj, 1), w2))
    GEq = np.zeros((max(nj, 1), w2))
    GEk = np.zeros((max(nj, 1), w2))
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    vN0 = np.zeros(ncm)
    cnew = np.zeros(ncm, dtype=np.bool_)
    nrec = np.int64(0)  # not a literal: see _driver.drive
    k = k0
    status = OK
    while k - k0 < nmax:
        tk, t1, hk, last = grid_step(t0, k, h, t_bound)
        if tk >= t_bound:
            break
        # -- free velocity: W_hat dv = h [theta f1 + (1 - theta) f0] + h^2 theta K v
        mass_fn(par, q, M)
        forces_fn(par, q, v, t1, D, has_jac)
        f = D[:, 0].copy()
        if theta != 1.0:
            forces_fn(par, q, v, tk, D0, False)
            f = theta * f + (1.0 - theta) * D0[:, 0]
        K = np.ascontiguousarray(D[:, 1:1 + n])
        C = np.ascontiguousarray(D[:, 1 + n:])
        rhs = hk * f + (hk * hk * theta) * (K @ v)
        Wh = M - (hk * theta) * C - (hk * hk * theta * theta) * K
        finite = True
        for i in range(n):
            for j in range(n):
                if not math.isfinite(Wh[i, j]):
                    finite = False
        if not finite:
            status = SINGULAR
            break
        try:
            Wi = np.linalg.inv(Wh)
        except Exception:  # noqa: BLE001  (exactly singular: the generic step's failure too)
            status = SINGULAR
            break
        cond = _norm1(Wh, n) * _norm1(Wi, n)
        if not (math.isfinite(cond) and cond < COND_MAX):
            status = SINGULAR
            break
        vf = v + Wi @ rhs

        # -- the index set: gaps and normal velocities at (q_k, t_k)
        na = 0
        ic = -1
        if nc > 0:
            contacts_fn(par, q, tk, G0, True, True)
            # WN v + wN summed as numpy sums the generic step's product (its dot of a row:
            # numba's matrix-vector product rounds differently)
            for i in range(nc):
                vN0[i] = np.dot(np.ascontiguousarray(G0[i, 3:3 + n]), v) + G0[i, 1]
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
            if (G0[i, 0] + 0.5 * hk * vN0[i] <= 0.0) or closed[i]:
                na += 1
                ic = i
        if na > 1:
            status = LCP_HANDBACK
            break
        fr = na == 1 and mu[ic] > 0.0

        # -- the rows [E; N; T]: joints at the theta-point or end point, the contact at t_k+1
        th = theta if theta_rows else 1.0
        q_th = q + (th * hk) * v
        t_th = t1 if th == 1.0 else tk + th * hk
        joints_fn(par, q_th, t_th, GE, True)
        m = nj + na + (1 if fr else 0)
        H = np.zeros((m, n))
        wr = np.zeros(m)
        for r in range(nj):
            for j in range(n):
                H[r, j] = GE[r, 3 + j]
            wr[r] = GE[r, 1]
        target = np.zeros(nj)
        if theta != 1.0 and theta_rows:
            # theta (WE v_k+1 + wE) + (1 - theta) (WE v_k + wE) = 0, on v_k+1
            for r in range(nj):
                acc = wr[r]
                for j in range(n):
                    acc += H[r, j] * v[j]
                target[r] = ((theta - 1.0) / theta) * acc
        if alpha > 0.0:
            # Baumgarte: less (alpha / h) gE(q_k, t_k), over theta on the theta-weighted rows
            joints_fn(par, q, tk, GEk, True)
            div = theta if (theta_rows and theta != 1.0) else 1.0
            for r in range(nj):
                target[r] = target[r] - ((alpha / hk) * GEk[r, 0]) / div
        if na == 1:
            contacts_fn(par, q, t1, G1, True, True)
            for j in range(n):
                H[nj, j] = G1[ic, 3 + j]
            wr[nj] = G1[ic, 1]
            if fr:
                for j in range(n):
                    H[nj + 1, j] = G1[ic, 3 + n + j]
                wr[nj + 1] = G1[ic, 2]
        WiHT = Wi @ H.T
        W = H @ WiHT
        Uf = H @ vf + wr

        # -- the mixed LCP: the equality rows eliminated (moreau.contact.solvers.mlcp)
        A = np.ascontiguousarray(W[:nj, :nj])
        a = Uf[:nj] - target
        if not _regular(A, nj):
            status = LCP_HANDBACK
            break
        p = np.zeros(m)
        pn = 0.0
        pt = 0.0
        if na == 0:
            pE = _refined(A, -a)
        else:
            Cc = np.ascontiguousarray(W[:nj, nj:])
            Dd = np.ascontiguousarray(W[nj:, :nj])
            AiC = np.linalg.solve(A, Cc)
            Aia = _solve_vector(A, a)
            WS = W[nj:, nj:] - Dd @ AiC
            uS = Uf[nj:] - Dd @ Aia
            if fr:
                pn, pt, ok = _one_contact(WS[0, 0], WS[0, 1], WS[1, 0], WS[1, 1], uS[0], uS[1],
                                          mu[ic], e[ic], vN0[ic])
            else:
                pn, pt, ok = _one_contact(WS[0, 0], 0.0, 0.0, 0.0, uS[0], 0.0, 0.0, e[ic],
                                          vN0[ic])
                pt = 0.0
            if not ok:
                status = LCP_HANDBACK
                break
            pC = np.zeros(m - nj)
            pC[0] = pn
            if fr:
                pC[1] = pt
            pE = _refined(A, -(a + Cc @ pC))
            p[nj] = pn
            if fr:
                p[nj + 1] = pt
        for r in range(nj):
            p[r] = pE[r]
        # the answer checked on the whole problem as the generic step checks it (a failure
        # is its to report)
        if na == 1:
            viol, res = _mlcp_check(W, Uf, target, nj, pE, pn, pt, mu[ic], e[ic], vN0[ic], fr)
        else:
            # np.False_, not False: a literal argument compiles a second _mlcp_check
            viol, res = _mlcp_check(W, Uf, target, nj, pE, -1.0, 0.0, 0.0, 0.0, 0.0, np.False_)
        if not viol <= DEFAULT_TOL:
            status = LCP_HANDBACK
            break
        if na == 1:
            pN[ic] = pn
            pT[ic] = pt
            stats[0] += 1.0
            if res > stats[1]:
                stats[1] = res
            if fr:
                U = Uf + W @ p
                slip[ic] = U[nj + 1]
        v1 = vf + WiHT @ p
        q1 = q + hk * (theta * v1 + (1.0 - theta) * v)
        ok = True
        for j in range(n):
            if not (math.isfinite(q1[j]) and math.isfinite(v1[j])):
                ok = False
        if not ok:
            status = NUMERICAL
            break
        # -- the end of the step: gaps, joint residuals, regimes
        if nc > 0:
            contacts_fn(par, q1, t1, Gq, True, False)
        for i in range(nc):
            if -Gq[i, 0] > stats[2]:
                stats[2] = -Gq[i, 0]
        joints_fn(par, q1, t1, GEq, True)
        for r in range(nj):
            if abs(GEq[r, 0]) > stats[3]:
                stats[3] = abs(GEq[r, 0])
        for i in range(nc):
            reg[i] = _classify(pN[i], pT[i], mu[i])
            cnew[i] = pN[i] > 0.0
        if record_initial:
            nrec = record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                                 nrec, tk, q, v, reg, pN, pT, hk, slip, G0, nc)
            record_initial = False
        for i in range(nc):
            closed[i] = cnew[i]
        for j in range(n):
            q[j] = q1[j]
            v[j] = v1[j]
        k += 1
        if k % save_every == 0 or last:
            nrec = record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                                 nrec, t1, q, v, reg, pN, pT, hk, slip, Gq, nc)
        if last:
            break
    return status, k, nrec


_F1 = nbtypes.float64[::1]
_F2 = nbtypes.float64[:, ::1]
_B = nbtypes.boolean
#: the model's functions as the loop calls them (moreau.compiled, and the planar builder's
#: ``joints(par, q, t, G, need_gap)``)
_FUNCTION_TYPES = (
    nbtypes.FunctionType(nbtypes.void(_F1, _F1, _F2)),
    nbtypes.FunctionType(nbtypes.void(_F1, _F1, _F1, nbtypes.float64, _F2, _B)),
    nbtypes.FunctionType(nbtypes.void(_F1, _F1, nbtypes.float64, _F2, _B, _B)),
    nbtypes.FunctionType(nbtypes.void(_F1, _F1, nbtypes.float64, _F2, _B)),
)
_COMPILED = set()
_LOCK = threading.Lock()


def run_joint_block(mass, forces, contacts, joints, *args):
    """Call :func:`mj_joint_loop` with the model's functions as first-class functions.

    One compile (numba's disk cache keeps it) serves every model: the
    functions are passed by pointer, not compiled into the loop.
    """
    sig = _FUNCTION_TYPES + tuple(numba.typeof(a) for a in args)
    with _LOCK:
        if sig not in _COMPILED:
            mj_joint_loop.disable_compile(False)
            # processes that reach it together compile it once (_jit_cache.compile_lock)
            with _jit_cache.compile_lock(mj_joint_loop):
                mj_joint_loop.compile(sig)
            _COMPILED.add(sig)
        # compiling only on the explicit signature: a call converts the model's
        # dispatchers to its function pointers instead of compiling a loop for each model
        mj_joint_loop.disable_compile(True)
    return mj_joint_loop(mass, forces, contacts, joints, *args)


#: every source whose machine code is in the loop
KERNEL_SOURCES = (__file__, _one_contact_module.__file__, _driver.__file__)
_jit_cache.bind_cache_to_sources([mj_joint_loop, _mlcp_check, _regular, _norm1, _refined],
                                 KERNEL_SOURCES)
