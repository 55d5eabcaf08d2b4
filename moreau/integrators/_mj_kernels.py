"""Compiled Moreau–Jean step loop for any scene with a compiled model.

This is the fast path of :mod:`moreau.integrators.moreau_jean`: the same
scheme, the same time grid, index set, contact problem, regime
classification and projection, run as one ``numba`` call over a block of
steps that allocates nothing per step. The scene's model comes as the
functions of its :class:`moreau.compiled.CompiledModel`; the loop itself
knows no scene, and :mod:`moreau.integrators._loops` compiles it once per
model, on first use.

The contact problem of a step is solved as the generic path solves it:

* no active contact: nothing is solved;
* one active contact: the closed-form case analysis :func:`_one_contact`
  (stick, positive slip, negative slip; one row when ``mu = 0``);
* several: the velocity-level friction LCP of
  :func:`moreau.lcp.friction.build_friction_lcp`, assembled here over the
  active contacts only (one variable per frictionless contact, four per
  frictional one, no restitution term where ``e = 0``), solved by the
  compiled :func:`moreau.lcp.lemke.lemke_core`. When Lemke fails the loop
  stops *before* that step with status :data:`LCP_HANDBACK`; the caller takes
  the step in Python (QP fallback) and calls the loop again.
* warm start (``lcp_method="auto"``), two levels, both certified as Lemke's
  answer would be (:func:`moreau.lcp.lcp_violation` at Lemke's tolerance,
  every inequality clear of its bound) and refused otherwise:

  - from the second step of a call on, :func:`_regime_solve` solves the step
    in the regimes of the step before (open, slipping either way, sticking)
    on the Delassus matrix itself: the normal impulses of the loaded
    contacts and the tangential ones of the sticking contacts, 2 x 2 for two
    sliding contacts instead of the 8 x 8 LCP;
  - on the first step of a call, the support of the last LCP solved with the
    same active contacts (:func:`_warm_solve`: the principal subsystem
    ``M_BB z_B = -q_B``, ``z = 0`` off it).

  Where the LCP's solution is unique the answer is then Lemke's to rounding.
  Between contact events nothing changes, so most multi-contact steps skip
  pivoting (``stats["warm_starts"]``); where a regime changes within the
  step (or within the margin of changing), Lemke runs from scratch.

The generic Python step (``MoreauJean(..., fast=False)``) is kept as the
reference; the tests hold the two to ``1e-12`` on every scene (the forces of
sticking contacts to the velocities' difference over ``h``, see
``tests/integrators/_agreement.py``).
"""

import math

import numpy as np
from numba import njit
from numba.core import types as _nbt

from .. import _jit_cache
from ..lcp import _certified
from ..lcp import certify as _certify
from ..lcp import lemke as _lemke
from ..lcp.lemke import DEFAULT_TOL, eliminate, lemke_core, lemke_workspace

__all__ = ["mj_loop", "grid_step", "no_gaps", "new_stats", "new_lcp_control", "STAT_NAMES", "OK", "PAINLEVE", "NUMERICAL",
           "SINGULAR", "LCP_HANDBACK"]

# status codes (those of SimulationResult where they overlap)
OK = 0
PAINLEVE = -1
NUMERICAL = -5
#: the iteration matrix was singular (reported as status -5 with its own message)
SINGULAR = -6
#: Lemke failed on this step: take it in Python, then resume
LCP_HANDBACK = 7

#: layout of the statistics vector
STAT_NAMES = ("lcp_solves", "direct_solves", "pivots", "fallbacks", "max_residual",
              "max_penetration", "projection_iterations", "warm_starts")
S_LCP, S_DIRECT, S_PIVOTS, S_FALLBACKS, S_RES, S_PEN, S_PROJ, S_WARM = range(8)

# shared with moreau_jean.py (kept as literals so that numba freezes them)
SLIP_RTOL = 1e-10
PROJECTION_TOL = 1e-14
PROJECTION_MAXITER = 8
COND_MAX = 1e14

# warm start of the contact LCP (see _lcp_step): a solution on the previous
# step's support is accepted only when every pivot of its subsystem's
# elimination exceeds this times its column's largest entry (a singular
# M_BB, e.g. two sticking contacts on fewer degrees of freedom, gives pivots
# at rounding level), and then under the violation bound a Lemke solution
# must meet (DEFAULT_TOL). A tighter bound was tried: Lemke's own answers
# on a resting box violate by 1e-11 (it snaps a tangential impulse of
# rounding size to zero), and the warm start must accept those too.
WARM_PIVOT_RTOL = 1e-8
# ... and only when it is clear of a change of support: every z_j on it and
# every w_j of a normal row (and of the cone row of a loaded contact) off it
# above this times its natural scale (max|q| / max|M| for z, max|q| for w).
# Near such a tie (a slip that ends within the step, a contact about to
# lift off) two solutions lie within rounding of each other; Lemke decides
# there, as the generic step does.
WARM_MARGIN = 1e-8


def new_stats():
    return np.zeros(len(STAT_NAMES))


@njit(inline="always")
def grid_step(t0, k, h, t_bound):
    """``(t_k, t_{k+1}, step, last)`` of the fixed-step grid ``t0 + k h``, the last step cut at
    ``t_bound``: the compiled loops' twin of :func:`moreau.integrators.moreau_jean.next_time`."""
    tk = t0 + k * h
    t1 = t0 + (k + 1) * h
    if t1 >= t_bound - 1e-9 * h:
        return tk, t_bound, t_bound - tk, True
    return tk, t1, h, False


@njit(cache=True)
def _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre):
    # returns (pN, pT, ok); ok = False only where W is not positive definite and
    # the problem has no solution or several (see contact_problem.one_contact_impulse:
    # with W_NN W_TT > W_NT^2 and the contact pressing, the solution is unique and
    # may be the tangential impact, a stick that the sliding piece cannot give)
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
        return _one_contact_cases(Wnn, Wnt, Wtn, Wtt, uT, mu, b, det)
    if not Wnn > 0.0:
        return 0.0, 0.0, False
    return -b / Wnn, 0.0, True


@njit(cache=True)
def _one_contact_cases(Wnn, Wnt, Wtn, Wtt, uT, mu, b, det):
    # _one_contact where Wnn - mu |Wnt| <= 0 (the discrete Painlevé condition fails):
    # every case that holds, which must agree. With b < 0 and det > 0 exactly one
    # holds: along pN the normal velocity falls only on the first slip piece (the
    # paradoxical one, from b < 0, so no root there) and rises on the stick piece
    # after it, whose slope det / Wtt > 0 never ends (a slip piece beyond it would
    # need |Wnt| > mu Wtt, hence Wnn > Wnt^2 / Wtt > mu |Wnt|). Where the free slip
    # runs the paradoxical way the answer is therefore the stick: the tangential
    # impact. A call of its own, so that the common cases are small where a loop
    # inlines them (SPECIALISED)
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


@njit(cache=True)
def _jam(Wnn, Wnt, mu, uN, e, vN_pre, s):
    # a tangential impact: the contact slid the way s (+1: positive slip, -1: negative)
    # in the step before, it presses (b < 0), and its sliding piece that way has a
    # non-increasing normal velocity (W_NN - mu s W_NT <= 0): sliding on has no
    # solution, and the step's answer is the impulsive stick
    b = uN + e * min(vN_pre, 0.0)
    return s != 0.0 and mu > 0.0 and b < 0.0 and Wnn - mu * s * Wnt <= 0.0


@njit(cache=True)
def _residual_parts(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    # the violation of the one-contact problem's conditions and its scale: the
    # residual is their quotient (_residual)
    b = uN + e * min(vN_pre, 0.0)
    vN = b + Wnn * pN + Wnt * pT
    if not mu > 0.0:
        return abs(min(pN, vN)), 1.0 + abs(b) + abs(Wnn) * abs(pN)
    vT = uT + Wtn * pN + Wtt * pT
    tp = max(pT, 0.0)
    tm = max(-pT, 0.0)
    beta = abs(vT)
    num = max(max(abs(min(pN, vN)), abs(min(tp, vT + beta))),
              max(abs(min(tm, beta - vT)), abs(min(beta, mu * pN - tp - tm))))
    mmax = max(max(abs(Wnn), abs(Wnt)), max(max(abs(Wtn), abs(Wtt)), max(mu, 1.0)))
    scale = 1.0 + max(abs(b), abs(uT)) + mmax * max(max(pN, tp), max(tm, beta))
    return num, scale


@njit(cache=True)
def _residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    num, scale = _residual_parts(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT)
    return num / scale


#: the frictional one-contact solve and its residual, as the loops call them; a model's
#: own loop inlines them instead (SPECIALISED)
_one_contact_fr = _one_contact
_residual_parts_fr = _residual_parts

#: globals that a model's own loop (moreau.integrators._loops._build) binds otherwise than
#: the shared loop. Inlined (numba IR), the frictional one-contact solve and its residual
#: make a friction-drive step 7-8 % faster: as calls, the loop kept its live values on the
#: stack across them. The shared loop keeps the calls: inlined there they lengthened its
#: compile, which every first use pays (a model's own loop takes about 1.4 s longer to
#: compile, about 12 %). LLVM inlines the frictionless calls, whose zeros fold, by itself.
SPECIALISED = {
    "_one_contact_fr": njit(cache=True, inline="always")(_one_contact.py_func),
    "_residual_parts_fr": njit(cache=True, inline="always")(_residual_parts.py_func),
}


@njit(cache=True)
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


@njit(cache=True)
def lcp_buffers(ncm):
    """The buffers of one loop's contact LCPs for up to ``ncm`` contacts (see :func:`_lcp_step`).

    Returns ``(Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol)``; ``lay``
    starts with ``-1`` (no layout assembled yet).
    """
    Lmax = 4 * ncm
    work, iwork = lemke_workspace(Lmax)
    lay = np.zeros(1 + ncm, dtype=np.int64)
    lay[0] = -1
    return (np.zeros((Lmax, Lmax)), np.zeros(Lmax), np.ones(Lmax), np.zeros(Lmax),
            np.zeros(Lmax), np.zeros(Lmax + 1), work, iwork, lay, np.zeros((Lmax, Lmax)),
            np.zeros(Lmax), np.zeros(Lmax, dtype=np.int64), np.zeros(4 * ncm, dtype=np.int64))


@njit(cache=True)
def record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec, t, q, v,
                  reg, pN, pT, h, slip, G, n, nc):
    """Write sample ``nrec`` of a compiled loop: time, state, and per contact the regime, the
    forces (impulse / step), the slip velocity and the gap (column 0 of ``G``)."""
    rec_t[nrec] = t
    for j in range(n):
        rec_q[nrec, j] = q[j]
        rec_v[nrec, j] = v[j]
    for i in range(nc):
        rec_reg[nrec, i] = reg[i]
        rec_fN[nrec, i] = pN[i] / h
        rec_fT[nrec, i] = pT[i] / h
        rec_slip[nrec, i] = slip[i]
        rec_gap[nrec, i] = G[i, 0]


@njit(cache=True)
def _invert_small(A, out, n):
    """``out = A^-1`` for ``n <= 3`` in closed form; False when ``A`` is singular.

    Singular means to working precision: a 1-norm condition number of 1e14 or
    more, or a non-finite entry. Loop-free and call-free on purpose: LLVM
    inlines it into the loops and prunes the arrays' reference counts only
    around straight-line code.
    """
    ok = True
    na = 0.0
    ni = 0.0
    if n == 1:
        a = A[0, 0]
        ok = math.isfinite(a)
        out[0, 0] = 1.0 / a
        na = abs(a)
        ni = abs(out[0, 0])
    elif n == 2:
        a = A[0, 0]
        b = A[0, 1]
        c = A[1, 0]
        d = A[1, 1]
        ok = math.isfinite(a) and math.isfinite(b) and math.isfinite(c) and math.isfinite(d)
        det = a * d - b * c
        out[0, 0] = d / det
        out[0, 1] = -b / det
        out[1, 0] = -c / det
        out[1, 1] = a / det
        na = max(abs(a) + abs(c), abs(b) + abs(d))
        ni = max(abs(out[0, 0]) + abs(out[1, 0]), abs(out[0, 1]) + abs(out[1, 1]))
    else:
        a00 = A[0, 0]
        a01 = A[0, 1]
        a02 = A[0, 2]
        a10 = A[1, 0]
        a11 = A[1, 1]
        a12 = A[1, 2]
        a20 = A[2, 0]
        a21 = A[2, 1]
        a22 = A[2, 2]
        ok = (math.isfinite(a00) and math.isfinite(a01) and math.isfinite(a02)
              and math.isfinite(a10) and math.isfinite(a11) and math.isfinite(a12)
              and math.isfinite(a20) and math.isfinite(a21) and math.isfinite(a22))
        # adjugate over the determinant
        c00 = a11 * a22 - a12 * a21
        c01 = a02 * a21 - a01 * a22
        c02 = a01 * a12 - a02 * a11
        c10 = a12 * a20 - a10 * a22
        c11 = a00 * a22 - a02 * a20
        c12 = a02 * a10 - a00 * a12
        c20 = a10 * a21 - a11 * a20
        c21 = a01 * a20 - a00 * a21
        c22 = a00 * a11 - a01 * a10
        det = a00 * c00 + a01 * c10 + a02 * c20
        out[0, 0] = c00 / det
        out[0, 1] = c01 / det
        out[0, 2] = c02 / det
        out[1, 0] = c10 / det
        out[1, 1] = c11 / det
        out[1, 2] = c12 / det
        out[2, 0] = c20 / det
        out[2, 1] = c21 / det
        out[2, 2] = c22 / det
        na = max(abs(a00) + abs(a10) + abs(a20),
                 max(abs(a01) + abs(a11) + abs(a21), abs(a02) + abs(a12) + abs(a22)))
        ni = max(abs(out[0, 0]) + abs(out[1, 0]) + abs(out[2, 0]),
                 max(abs(out[0, 1]) + abs(out[1, 1]) + abs(out[2, 1]),
                     abs(out[0, 2]) + abs(out[1, 2]) + abs(out[2, 2])))
    # the arrays' last use, on the path where all branches have merged
    touched = A.size + out.size
    # `na * ni < COND_MAX` is False for nan too
    return ok and na * ni < COND_MAX and touched > 0


@njit(cache=True, error_model="numpy")
def _invert_gj(A, out, work, n):
    """``out = A^-1`` by Gauss-Jordan with partial pivoting (any ``n``); False when singular."""
    for i in range(n):
        for j in range(n):
            if not math.isfinite(A[i, j]):
                return False
    for i in range(n):
        for j in range(n):
            work[i, j] = A[i, j]
            out[i, j] = 1.0 if i == j else 0.0
    for c in range(n):
        piv = c
        best = abs(work[c, c])
        for r in range(c + 1, n):
            if abs(work[r, c]) > best:
                best = abs(work[r, c])
                piv = r
        if best == 0.0:
            return False
        if piv != c:
            for j in range(n):
                tmp = work[c, j]
                work[c, j] = work[piv, j]
                work[piv, j] = tmp
                tmp = out[c, j]
                out[c, j] = out[piv, j]
                out[piv, j] = tmp
        inv = 1.0 / work[c, c]
        for j in range(n):
            work[c, j] *= inv
            out[c, j] *= inv
        for r in range(n):
            if r != c:
                fct = work[r, c]
                if fct != 0.0:
                    for j in range(n):
                        work[r, j] -= fct * work[c, j]
                        out[r, j] -= fct * out[c, j]
    na = 0.0
    ni = 0.0
    for j in range(n):
        sa = 0.0
        si = 0.0
        for i in range(n):
            sa += abs(A[i, j])
            si += abs(out[i, j])
        na = max(na, sa)
        ni = max(ni, si)
    return na * ni < COND_MAX


@njit(cache=True)
def _lcp_size(na, ia, mu, base, trow):
    # LCP layout of the active contacts: start of each contact's block, its
    # tangential row in the stacked W (-1 if frictionless); returns the size
    L = 0
    nf = 0
    for r in range(na):
        base[r] = L
        if mu[ia[r]] > 0.0:
            trow[r] = na + nf
            nf += 1
            L += 4
        else:
            trow[r] = -1
            L += 1
    return L


# layout of the contact-problem control array (new_lcp_control)
CTL_FORCE, CTL_WARM, CTL_MAXIT, CTL_L, CTL_NA, CTL_IA = range(6)


def new_lcp_control(nc, force_lemke=False, warm_start=True, max_iter=0):
    """Options and warm-start memory of the loop's contact problems, one int64 array.

    Layout: ``[force_lemke, warm_start, max_iter, L, na, ia (max(nc, 1)
    slots), support flags (4 max(nc, 1) slots), regimes (max(nc, 1)
    slots), painleve_stop]``. The first three are the options (see
    :func:`mj_run`), the last one another (hand every one-contact step whose
    free slip runs into a Painlevé configuration to the generic step, which
    stops there: ``painleve="stop"``, :func:`set_painleve_stop`); then
    the warm start's memory, the last contact LCP solved in the loop (``L =
    -1``: none), and the regime of each contact in the last step taken
    (:func:`prev_regimes`: a tangential impact is a step that stops a
    slip), which the caller keeps from one call of :func:`mj_run` to the
    next. (One array rather than separate arguments: the loop already takes
    the thirty arguments beyond which CPython passes a call's arguments as a
    tuple, which numba cannot inline.)
    """
    ncm = max(nc, 1)
    ctl = np.zeros(CTL_IA + 6 * ncm + 1, dtype=np.int64)
    ctl[CTL_FORCE] = bool(force_lemke)
    ctl[CTL_WARM] = bool(warm_start)
    ctl[CTL_MAXIT] = int(max_iter)
    ctl[CTL_L] = -1
    return ctl


def set_painleve_stop(ctl, nc, stop):
    """Set the ``painleve_stop`` option of ``ctl`` (:func:`new_lcp_control`), its last entry."""
    ctl[CTL_IA + 6 * max(nc, 1)] = bool(stop)


@njit(cache=True)
def _stop_at(ctl, Wnn, Wnt, mu, uN, uT, e, vN_pre):
    # painleve="stop" (the last entry of ctl): the pressed contact's free slip, of any size,
    # runs into a sliding piece without solution; the generic step stops there
    return (ctl[ctl.shape[0] - 1] != 0 and uT != 0.0
            and _jam(Wnn, Wnt, mu, uN, e, vN_pre, math.copysign(1.0, uT)))


def prev_regimes(ctl, nc):
    """The view of ``ctl`` (:func:`new_lcp_control`) holding each contact's regime in the last step."""
    ncm = max(nc, 1)
    return ctl[CTL_IA + 5 * ncm:CTL_IA + 5 * ncm + nc]


@njit(cache=True)
def _slip_sign(regime):
    # +1 for positive slip, -1 for negative, 0 otherwise (Regime codes)
    if regime == 1:
        return 1.0
    if regime == 2:
        return -1.0
    return 0.0


@njit(cache=True)
def _warm_solve(Ml, qv, L, memo, off, A, x, idx, zl, wl, mmax, qmax, na, base, trow, pcol):
    """Solve ``LCP(Ml, qv)`` on the remembered support; the violation, or inf if refused.

    With ``B`` the remembered support (flags ``memo[off:off + L]``), solves
    ``M_BB z_B = -q_B`` by Gaussian elimination with partial pivoting, sets
    ``z_N = 0`` and returns Lemke's own measure of the result
    (:func:`moreau.lcp.lemke._residual`, which also writes ``w = M z + q``
    into ``wl``). A pivot below :data:`WARM_PIVOT_RTOL` times the largest
    entry of its column of ``M_BB`` refuses the subsystem as ill conditioned
    (a singular one included), and so is a solution near a change of
    support (see :data:`WARM_MARGIN`); the caller then runs Lemke.
    """
    s = 0
    for j in range(L):
        if memo[off + j] != 0:
            idx[s] = j
            s += 1
    for a in range(s):
        x[a] = -qv[idx[a]]
        for c in range(s):
            A[a, c] = Ml[idx[a], idx[c]]
    for j in range(L):
        zl[j] = 0.0
    if eliminate(A, x, s, WARM_PIVOT_RTOL, 0.0, pcol, zl, idx) < s:
        return np.inf
    res = _lemke._residual(Ml, qv, zl, wl, mmax, qmax)
    dw = WARM_MARGIN * (qmax if qmax > 0.0 else 1.0)
    dz = dw / (mmax if mmax > 0.0 else 1.0)
    for a in range(s):
        if not zl[idx[a]] > dz:
            return np.inf
    for r in range(na):
        j = base[r]
        loaded = memo[off + j] != 0
        if not loaded and not wl[j] > dw:
            return np.inf
        # the cone row mu pN - pT+ - pT- of an unloaded contact is 0 by nature;
        # the tangential rows vT +- beta of a sticking one too
        if loaded and trow[r] >= 0 and memo[off + j + 3] == 0 and not wl[j + 3] > dw:
            return np.inf
    return res


# inlined into the loop (numba IR), unlike the other helpers: it runs on nearly every
# step of a two-contact scene, and as a call with fifteen array arguments it cost the
# bidirectional drive a fifth of its speed (2.1e6 -> 2.6e6 steps/s inlined, sliding box
# 2.7e6 -> 3.7e6, same process); the loops that include it are compiled once each now
@njit(cache=True, inline="always")
def _regime_solve(Wd, Uf, na, ia, trow, mu, reg, p, pN, pT, A, x, uidx, vel, pcol):
    """Solve the active contacts' problem in the regimes of the step before; the violation, or inf.

    Each active contact keeps its last regime (``reg``, as :func:`_classify`:
    0 open, 1 and 2 slipping with ``p_T = -/+ mu p_N``, 3 sticking, or loaded
    without friction). The unknowns are the normal impulses of the loaded
    contacts and the tangential ones of the sticking contacts; the equations
    are their zero normal and (sticking) tangential velocities, on the
    Delassus matrix ``Wd`` itself: 2 x 2 for two sliding contacts, against
    the 8 x 8 friction LCP of the same step.

    Where sticking contacts are statically indeterminate (the box resting on
    two corners: four impulse rows on three degrees of freedom, its two
    tangential rows equal), the elimination finds a column without a pivot
    (below :data:`WARM_PIVOT_RTOL` times the column's scale) and sets that
    impulse to zero: a vertex of the solution set, as Lemke's basic
    solutions are. An inconsistent system fails the velocity check below.

    The answer is accepted only as a solution of the friction LCP it stands
    for: every inequality of the regimes holds clear of its bound
    (:data:`WARM_MARGIN`, so that near a change of regime Lemke decides, as
    in the generic step) and the violation of the LCP, measured as
    :func:`moreau.lcp.lemke._residual` measures Lemke's (the LCP's ``max|q|``
    and ``max|M|``), is at most ``DEFAULT_TOL``. Writes ``p``, ``pN``, ``pT``
    only when accepted. Returns the violation when accepted, ``inf`` when
    refused.
    """
    m = na
    for r in range(na):
        if trow[r] >= 0:
            m += 1
    # scales of the LCP this stands for: q = (b, +-uT, 0), M's entries Wd, +-1, mu
    qmax = 0.0
    mmax = 1.0
    for r in range(m):
        if r < na and trow[r] >= 0:
            mmax = max(mmax, mu[ia[r]])
        qmax = max(qmax, abs(Uf[r]))
        for c in range(m):
            mmax = max(mmax, abs(Wd[r, c]))
    qs = qmax if qmax > 0.0 else 1.0
    dw = WARM_MARGIN * qs
    dz = dw / mmax
    s = 0
    for r in range(na):
        g = reg[ia[r]]
        if g != 0:
            uidx[s] = r
            s += 1
            if g == 3 and trow[r] >= 0:
                uidx[s] = trow[r]
                s += 1
    for a in range(s):
        row = uidx[a]
        x[a] = -Uf[row]
        for c in range(s):
            col = uidx[c]
            val = Wd[row, col]
            if col < na:
                g = reg[ia[col]]
                tc = trow[col]
                if tc >= 0 and (g == 1 or g == 2):
                    # a sliding contact's tangential impulse rides on its normal one
                    val += (2.0 * g - 3.0) * mu[ia[col]] * Wd[row, tc]
            A[a, c] = val
    # vel takes the impulses: the pivoted ones, zero for a column without a pivot
    for r in range(m):
        vel[r] = 0.0
    eliminate(A, x, s, WARM_PIVOT_RTOL, 0.0, pcol, vel, uidx)
    for r in range(na):
        tr = trow[r]
        g = reg[ia[r]]
        if tr >= 0 and (g == 1 or g == 2):
            vel[tr] = (2.0 * g - 3.0) * mu[ia[r]] * vel[r]
    # x takes the contact velocities; then the regimes' inequalities
    num = 0.0
    for r in range(m):
        acc = Uf[r]
        for c in range(m):
            acc += Wd[r, c] * vel[c]
        x[r] = acc
    for r in range(na):
        i = ia[r]
        tr = trow[r]
        g = reg[i]
        if g == 0:
            if not x[r] > dw:
                return np.inf
            continue
        if not vel[r] > dz:
            return np.inf
        num = max(num, abs(x[r]))
        if tr >= 0:
            if g == 3:
                if not mu[i] * vel[r] - abs(vel[tr]) > dz:
                    return np.inf
                num = max(num, abs(x[tr]))
            elif g == 1:
                if not x[tr] > dw:
                    return np.inf
            elif not x[tr] < -dw:
                return np.inf
    res = num / qs
    if not res <= DEFAULT_TOL:
        return np.inf
    for r in range(m):
        p[r] = vel[r]
    for r in range(na):
        i = ia[r]
        pN[i] = vel[r]
        pT[i] = vel[trow[r]] if trow[r] >= 0 else 0.0
    return res


@njit(cache=True)
def _lcp_step(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow, Ml, ql, dl, zl, wl, rayl,
              work, iwork, lay, ctl, Ab, xb, idx, pcol, use_memory):
    """Assemble the friction LCP of the active contacts and solve it (warm start, else Lemke).

    The layout is that of :func:`moreau.lcp.friction.build_friction_lcp` over
    the active contacts (``ia[:na]``): one variable per frictionless contact,
    ``(p_N, p_T+, p_T-, beta)`` per frictional one, ``M = S^T W S`` plus the
    cone rows; ``Uf`` holds the free contact velocities, the restitution
    target already in its normal rows. The buffers
    are at least the size ``L`` of :func:`_lcp_size`; their leading ``L``
    entries are used. ``lay`` (``[na, ia...]``) holds the layout ``Ml`` was
    last assembled in: with the same layout the matrix's zero pattern is the
    same and only its nonzero entries are rewritten.

    With the warm start on (``ctl``, see :func:`new_lcp_control`) and
    ``use_memory`` (the caller's regime solve has not just been refused: its
    regimes, hence the remembered support, are out of date), and when
    the last LCP in its memory had the same active contacts, that solution's
    support ``B = {j : z_j > 0}`` is tried first (:func:`_warm_solve`); the
    result is accepted only when it passes the check a Lemke solution must
    pass (violation at most ``DEFAULT_TOL``).
    Otherwise Lemke runs, with the pivot limit of ``ctl`` (``<= 0``: the
    default). After a success the memory takes the new support.

    Writes the stacked impulses ``p`` and the per-contact ``pN``, ``pT``.
    Returns ``(status, pivots, residual, warm_used)``, status and residual
    as Lemke's (:func:`moreau.lcp.lemke.lemke_core`).
    """
    same = lay[0] == na
    if same:
        for r in range(na):
            if lay[1 + r] != ia[r]:
                same = False
    if not same:
        # a new layout: clear the block; with the old one every entry that is
        # not rewritten below is still zero
        for r in range(L):
            for c in range(L):
                Ml[r, c] = 0.0
        lay[0] = na
        for r in range(na):
            lay[1 + r] = ia[r]
    for r in range(na):
        i = ia[r]
        br = base[r]
        tr = trow[r]
        ql[br] = Uf[r]
        if tr >= 0:
            ql[br + 1] = Uf[tr]
            ql[br + 2] = -Uf[tr]
            ql[br + 3] = 0.0
        for c in range(na):
            bc = base[c]
            tc = trow[c]
            Ml[br, bc] = Wd[r, c]
            if tc >= 0:
                Ml[br, bc + 1] = Wd[r, tc]
                Ml[br, bc + 2] = -Wd[r, tc]
            if tr >= 0:
                Ml[br + 1, bc] = Wd[tr, c]
                Ml[br + 2, bc] = -Wd[tr, c]
                if tc >= 0:
                    Ml[br + 1, bc + 1] = Wd[tr, tc]
                    Ml[br + 1, bc + 2] = -Wd[tr, tc]
                    Ml[br + 2, bc + 1] = -Wd[tr, tc]
                    Ml[br + 2, bc + 2] = Wd[tr, tc]
        if tr >= 0:
            Ml[br + 1, br + 3] = 1.0
            Ml[br + 2, br + 3] = 1.0
            Ml[br + 3, br] = mu[i]
            Ml[br + 3, br + 1] = -1.0
            Ml[br + 3, br + 2] = -1.0
    qv = ql[:L]
    off = CTL_IA + ia.shape[0]
    warm = ctl[CTL_WARM] != 0 and use_memory
    status = -1
    pivots = 0
    res = np.inf
    used = False
    if warm and ctl[CTL_L] == L and ctl[CTL_NA] == na:
        same = True
        for r in range(na):
            if ctl[CTL_IA + r] != ia[r]:
                same = False
        qmin = 0.0
        qmax = 0.0
        for r in range(L):
            qmin = min(qmin, qv[r])
            qmax = max(qmax, abs(qv[r]))
        # q >= 0: Lemke returns z = 0 without a pivot, nothing to gain
        if same and qmin < 0.0:
            mmax = 0.0
            for r in range(L):
                for c in range(L):
                    mmax = max(mmax, abs(Ml[r, c]))
            res = _warm_solve(Ml, qv, L, ctl, off, Ab, xb, idx, zl, wl, mmax, qmax, na, base,
                              trow, pcol)
            if res <= DEFAULT_TOL:
                status = 0
                used = True
    if not used:
        max_iter = ctl[CTL_MAXIT]
        if max_iter <= 0:
            max_iter = 1000 if L <= 20 else 50 * L
        # lemke_core takes the size from q; M, d and the outputs may be larger
        status, pivots, res = lemke_core(Ml, qv, dl, zl, wl, rayl, work, iwork, max_iter,
                                         DEFAULT_TOL)
    if status == 0:
        for r in range(na):
            i = ia[r]
            br = base[r]
            p[r] = zl[br]
            pN[i] = zl[br]
            if trow[r] >= 0:
                pt = zl[br + 1] - zl[br + 2]
                p[trow[r]] = pt
                pT[i] = pt
        if warm:
            ctl[CTL_L] = L
            ctl[CTL_NA] = na
            for r in range(na):
                ctl[CTL_IA + r] = ia[r]
            for j in range(L):
                ctl[off + j] = 1 if zl[j] > 0.0 else 0
            for r in range(na):
                br = base[r]
                if (trow[r] >= 0 and ctl[off + br + 1] != 0 and ctl[off + br + 2] != 0
                        and ctl[off + br + 3] == 0):
                    # stick with both p_T+ and p_T- > 0 (beta = 0): their columns
                    # are opposite on the rows of B, so M_BB is singular; keep
                    # the one that carries the net tangential impulse
                    if zl[br + 1] >= zl[br + 2]:
                        ctl[off + br + 2] = 0
                    else:
                        ctl[off + br + 1] = 0
    return status, pivots, res, used


_A1 = _nbt.float64[::1]
_A2 = _nbt.float64[:, ::1]
_I1 = _nbt.int64[::1]
_INT = _nbt.int64
#: the numba signature of :func:`_lcp_step`, for the shared loop, which calls it
#: through a pointer (:data:`SHARED_INDIRECT`)
LCP_STEP_SIGNATURE = _nbt.Tuple((_INT, _INT, _nbt.float64, _nbt.boolean))(
    _A2, _A1, _INT, _I1, _A1, _A1, _A1, _A1, _INT, _I1, _I1, _A2, _A1, _A1, _A1, _A1, _A1, _A2,
    _I1, _I1, _I1, _A2, _A1, _I1, _I1, _nbt.boolean)


@njit(cache=True)
def _lcp_step_unused(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow, Ml, ql, dl, zl, wl, rayl,
                     work, iwork, lay, ctl, Ab, xb, idx, pcol, use_memory):
    # stands in for _lcp_step where no contact LCP can arise (one contact, Lemke not
    # forced): a run of a single-contact scene then compiles neither Lemke nor the
    # LCP's assembly (about 11 of a first call's 28 s). Were it reached, its status
    # hands the step to the generic step, which solves it: slower, never wrong
    return np.int64(1), np.int64(0), np.inf, False


def lcp_needed(ncontacts, lcp_ctl):
    """Whether a Moreau–Jean run of ``ncontacts`` contacts with ``lcp_ctl`` can reach the LCP solve.

    With one contact the step is solved in closed form unless Lemke is
    forced (``mj_loop``: ``na == 1 and not force_lemke``).
    """
    return ncontacts >= 2 or bool(lcp_ctl[CTL_FORCE])


#: kernels the shared Moreau–Jean loop takes as arguments instead of linking them in
#: (:func:`moreau.integrators._loops.shared_core`): name -> (signature, stand-in where
#: :func:`lcp_needed` says it cannot be called, the name of the loop's argument
#: that decides)
SHARED_INDIRECT = {"_lcp_step": (LCP_STEP_SIGNATURE, "_lcp_step_unused", lcp_needed, "lcp_ctl")}


def mj_loop(par, mu, e, t0, h, t_bound, k0, nmax, q, v, theta, projection, closed, save_every,
            record_initial, lcp_ctl, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip,
            rec_gap, stats):
    """Run up to ``nmax`` Moreau–Jean steps of a compiled model in one call.

    A template, not called as it stands: :func:`moreau.integrators._loops.runner_for`
    compiles it once per model, in a namespace that adds the model to this
    module's globals: its functions ``mass_fn``, ``forces_fn``,
    ``contacts_fn`` and ``gaps_fn`` (:class:`moreau.compiled.CompiledModel`),
    and the constants ``NDOF``, ``NCONTACTS``, ``CONST_MASS`` (``M``
    independent of ``q``), ``HAS_JAC`` (``dh/dq`` or ``dh/dv`` nonzero) and
    ``HAS_GAPS`` (the model has ``gaps``). Numba
    freezes globals, so the compiler drops the branches the model does not
    take and unrolls the small-matrix loops; passing the functions as
    arguments instead would make them run-time values, which numba can
    neither inline nor cache.

    Parameters
    ----------
    par : float64[:]
        The model's parameters.
    mu, e : float64[:]
        Friction and restitution of each contact.
    t0, h, t_bound : float
        Grid ``t0 + k h``; the step that reaches ``t_bound`` is cut there.
    k0 : int
        Index of the first step (``t_k0 = t0 + k0 h``).
    nmax : int
        Most steps to take in this call.
    q, v : float64[n]
        State at ``t_k0``; overwritten with the final state.
    theta : float
    projection : bool
    closed : bool[nc]
        Contacts that carried a normal impulse in the step before ``k0``; updated.
    save_every : int
        Record after every ``save_every``-th step (counted from ``t0``) and after the last.
    record_initial : bool
        Also record the state at ``t_k0`` (with the first step's regime and forces).
    lcp_ctl : int64[:]
        From :func:`new_lcp_control`: ``force_lemke`` (solve a single active
        contact by Lemke too, ``lcp_method="lemke"``), ``warm_start`` (try
        the last contact LCP's support before Lemke, see :func:`_lcp_step`),
        ``max_iter`` (Lemke's pivot limit; ``<= 0``: the default, 1000, or
        ``50 L`` above ``L = 20``), then the warm start's memory, read and
        updated; the caller keeps the array from one call to the next.
    rec_* : arrays
        Sample buffers, ``rec_q``/``rec_v`` of shape (ns, n), the contact
        ones (ns, nc); long enough for this call's samples.
    stats : float64[:]
        Accumulated statistics, layout :data:`STAT_NAMES`.

    Returns
    -------
    status : int
        :data:`OK`, :data:`PAINLEVE`, :data:`NUMERICAL`, :data:`SINGULAR`
        (state: the last good one) or :data:`LCP_HANDBACK` (state: the start
        of the step Lemke could not solve).
    k : int
        Index of the next step (steps taken: ``k - k0``).
    nrec : int
        Samples written.
    """
    n = NDOF  # noqa: F821  (the model's namespace, see above)
    nc = NCONTACTS  # noqa: F821
    const_mass = CONST_MASS  # noqa: F821
    has_jac = HAS_JAC  # noqa: F821
    force_lemke = lcp_ctl[CTL_FORCE] != 0
    warm_on = lcp_ctl[CTL_WARM] != 0 and not force_lemke
    rvel = np.zeros(2 * max(nc, 1))
    th = theta
    M = np.zeros((n, n))
    Wh = np.empty((n, n))
    Wi = np.empty((n, n))
    wk = np.empty((n, n))
    # model outputs, packed (see moreau.compiled): D = [h | K | C]
    D = np.zeros((n, 1 + 2 * n))
    D0 = np.zeros((n, 1 + 2 * n))
    rhs = np.empty(n)
    vf = np.empty(n)
    v1 = np.empty(n)
    q1 = np.empty(n)
    ncm = max(nc, 1)
    mrows = 2 * ncm
    # contact rows (g, wN, wT, WN, WT): at (q_k, t_k), at (q_k, t_k+1), at (q_k+1, t_k+1)
    G0 = np.zeros((ncm, 3 + 2 * n))
    G1 = np.zeros((ncm, 3 + 2 * n))
    Gq = np.zeros((ncm, 3 + 2 * n))
    vN0 = np.zeros(ncm)
    active = np.zeros(ncm, dtype=np.bool_)
    cnew = np.zeros(ncm, dtype=np.bool_)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    reg = np.zeros(ncm, dtype=np.int64)
    ia = np.zeros(ncm, dtype=np.int64)
    fa = np.zeros(ncm, dtype=np.int64)
    H = np.zeros((mrows, n))
    # the columns where each row of H is nonzero: contact rows touch few
    # coordinates (two balls of a chain), and the Delassus assembly over them
    # alone costs m nnz instead of m n^2 (N = 100 balls: 10x fewer operations
    # per step); the skipped terms are exact zeros, so the sums are the same
    hnz = np.zeros((mrows, n), dtype=np.int64)
    hcnt = np.zeros(mrows, dtype=np.int64)
    w = np.zeros(mrows)
    WiHT = np.zeros((n, mrows))
    Wd = np.zeros((mrows, mrows))
    Uf = np.zeros(mrows)
    p = np.zeros(mrows)
    # projection buffers
    Mi = np.empty((n, n))
    sel = np.zeros(ncm, dtype=np.bool_)
    X = np.zeros((n, ncm))
    S = np.zeros((ncm, ncm))
    rs = np.zeros(ncm)
    ident = np.arange(ncm)
    dd = np.zeros(ncm)
    base = np.zeros(ncm, dtype=np.int64)
    trow = np.zeros(ncm, dtype=np.int64)
    # LCP buffers at the largest size (four variables per contact), allocated
    # once: arrays reassigned inside the loop would be reference-counted on
    # every step, contact or not; _lcp_step uses their leading L x L block
    # the LCP buffers; `lay` holds the layout Ml holds (na, ia...), Ab .. pcol the warm
    # start's subsystem
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lcp_buffers(ncm)

    # the regime of each contact in the step before (a tangential impact stops a slip)
    roff = CTL_IA + 5 * ncm
    for i in range(nc):
        reg[i] = lcp_ctl[roff + i]
    constant_W = const_mass and not has_jac
    have_Wi = False
    have_Mi = False
    nrec = 0
    k = k0
    status = OK
    # steps left until the next sample (k % save_every == 0 after the step): a
    # countdown, because an integer division per step costs as much as a sine
    to_save = save_every - k0 % save_every
    while k - k0 < nmax:
        tk, t1, hk, last = grid_step(t0, k, h, t_bound)
        if tk >= t_bound:
            break
        # -- free velocity: W_hat dv = h [theta f1 + (1 - theta) f0] + h^2 theta K v
        # the gaps at (q_k, t_k) were computed at the end of the step before
        if not (const_mass and k > k0):
            mass_fn(par, q, M)
        # the model is evaluated in the order of its times: t_k (where the step before
        # ended), then t_k+1, so that a model which keeps its last transcendentals
        # (the friction drive's sines and cosines of the phase) finds them still current
        if nc > 0:
            contacts_fn(par, q, tk, G0, k == k0, False)
        if th != 1.0:
            forces_fn(par, q, v, tk, D0, False)
        forces_fn(par, q, v, t1, D, has_jac)
        if th != 1.0:
            for i in range(n):
                D[i, 0] = th * D[i, 0] + (1.0 - th) * D0[i, 0]
        a = hk * th
        a2 = hk * hk * th
        if has_jac:
            for i in range(n):
                acc = 0.0
                for j in range(n):
                    acc += D[i, 1 + j] * v[j]
                rhs[i] = hk * D[i, 0] + a2 * acc
            a2 = a2 * th
            for i in range(n):
                for j in range(n):
                    Wh[i, j] = M[i, j] - a * D[i, 1 + n + j] - a2 * D[i, 1 + j]
        else:
            for i in range(n):
                rhs[i] = hk * D[i, 0]
                for j in range(n):
                    Wh[i, j] = M[i, j]
        if not (constant_W and have_Wi):
            if n <= 3:
                ok = _invert_small(Wh, Wi, n)
            else:
                ok = _invert_gj(Wh, Wi, wk, n)
            if not ok:
                status = SINGULAR
                break
            have_Wi = True
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Wi[i, j] * rhs[j]
            vf[i] = v[i] + acc
            v1[i] = vf[i]

        # -- contacts
        # int64, not the literal 0: numba types a call by its first-seen argument types, and
        # a literal would compile the contact solves a second time for it
        na = np.int64(0)
        nfa = 0
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
        if nc > 0:
            for i in range(nc):
                acc = G0[i, 1]
                for j in range(n):
                    acc += G0[i, 3 + j] * v[j]
                vN0[i] = acc
                active[i] = (G0[i, 0] + 0.5 * hk * acc <= 0.0) or closed[i]
                if active[i]:
                    ia[na] = i
                    na += 1
                    if mu[i] > 0.0:
                        fa[nfa] = i
                        nfa += 1
        if na > 0:
            contacts_fn(par, q, t1, G1, False, True)
        if na == 1 and not force_lemke:
            # one contact: the closed-form case analysis on the 2x2 (1x1) Delassus
            # matrix, built from the contact's two rows only; loops over n alone, so
            # that with the sizes known at compile time it is straight-line code
            i = ia[0]
            fr = nfa == 1
            for j in range(n):
                acc = 0.0
                acc2 = 0.0
                for l in range(n):
                    acc += Wi[j, l] * G1[i, 3 + l]
                    acc2 += Wi[j, l] * G1[i, 3 + n + l]
                WiHT[j, 0] = acc
                WiHT[j, 1] = acc2
            Wnn = 0.0
            uN = G1[i, 1]
            for j in range(n):
                Wnn += G1[i, 3 + j] * WiHT[j, 0]
                uN += G1[i, 3 + j] * vf[j]
            stats[S_LCP] += 1.0
            stats[S_DIRECT] += 1.0
            if fr:
                Wnt = 0.0
                Wtn = 0.0
                Wtt = 0.0
                uT = G1[i, 2]
                for j in range(n):
                    Wnt += G1[i, 3 + j] * WiHT[j, 1]
                    Wtn += G1[i, 3 + n + j] * WiHT[j, 0]
                    Wtt += G1[i, 3 + n + j] * WiHT[j, 1]
                    uT += G1[i, 3 + n + j] * vf[j]
                pn, pt, ok = _one_contact_fr(Wnn, Wnt, Wtn, Wtt, uN, uT, mu[i], e[i], vN0[i])
                # a tangential impact is taken by the generic step, which records it (or
                # stops there with painleve="stop"); it is rare, the test is not
                if not ok or (reg[i] != 0 and reg[i] != 3
                              and _jam(Wnn, Wnt, mu[i], uN, e[i], vN0[i], _slip_sign(reg[i]))) \
                        or _stop_at(lcp_ctl, Wnn, Wnt, mu[i], uN, uT, e[i], vN0[i]):
                    status = PAINLEVE
                    break
                rnum, rscale = _residual_parts_fr(Wnn, Wnt, Wtn, Wtt, uN, uT, mu[i], e[i],
                                                  vN0[i], pn, pt)
                slip[i] = uT + Wtn * pn + Wtt * pt
            else:
                pn, pt, ok = _one_contact(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, e[i], vN0[i])
                if not ok:
                    status = PAINLEVE
                    break
                rnum, rscale = _residual_parts(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, e[i], vN0[i],
                                               pn, 0.0)
            pN[i] = pn
            pT[i] = pt
            # stats[S_RES] = max(stats[S_RES], rnum / rscale), dividing only where the
            # quotient can exceed it: fl(rnum / rscale) > r implies rnum > r rscale exactly,
            # hence rnum >= fl(r rscale) for the double rnum, so the test skips no update.
            # On most steps the largest residual stands and the division is skipped
            # (2 % of a friction-drive step)
            if rnum >= stats[S_RES] * rscale:
                res = rnum / rscale
                if res > stats[S_RES]:
                    stats[S_RES] = res
            for j in range(n):
                v1[j] = vf[j] + WiHT[j, 0] * pn + WiHT[j, 1] * pt
        elif na > 0:
            m = na + nfa
            for r in range(na):
                i = ia[r]
                for j in range(n):
                    H[r, j] = G1[i, 3 + j]
                w[r] = G1[i, 1]
            for r in range(nfa):
                i = fa[r]
                for j in range(n):
                    H[na + r, j] = G1[i, 3 + n + j]
                w[na + r] = G1[i, 2]
            for c in range(m):
                cnt = 0
                for j in range(n):
                    if H[c, j] != 0.0:
                        hnz[c, cnt] = j
                        cnt += 1
                hcnt[c] = cnt
            for c in range(m):
                for i in range(n):
                    acc = 0.0
                    for t in range(hcnt[c]):
                        j = hnz[c, t]
                        acc += Wi[i, j] * H[c, j]
                    WiHT[i, c] = acc
            for r in range(m):
                acc = w[r]
                for t in range(hcnt[r]):
                    j = hnz[r, t]
                    acc += H[r, j] * vf[j]
                Uf[r] = acc
                for c in range(m):
                    acc = 0.0
                    for t in range(hcnt[r]):
                        j = hnz[r, t]
                        acc += H[r, j] * WiHT[j, c]
                    Wd[r, c] = acc
            # Newton's restitution: the normal rows aim at -e times the approach speed
            for r in range(na):
                i = ia[r]
                if e[i] > 0.0:
                    Uf[r] += e[i] * min(vN0[i], 0.0)
            L = _lcp_size(na, ia, mu, base, trow)
            res = np.inf
            # the regimes of the step before (known from the second step of a call on)
            regimes = warm_on and k > k0
            if regimes:
                res = _regime_solve(Wd, Uf, na, ia, trow, mu, reg, p, pN, pT, Ab, xb, idx, rvel,
                                    pcol)
            if 0.0 <= res <= DEFAULT_TOL:
                stats[S_LCP] += 1.0
                stats[S_WARM] += 1.0
            else:
                # refused: a regime changes in this step (or lies within the
                # margin of changing) and Lemke decides, from scratch, since the
                # remembered support is that of the old regimes. On the first
                # step of a call the regimes are unknown: the support may serve
                lst, piv, res, warm = _lcp_step(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow,
                                                Ml, ql, dl, zl, wl, rayl, work, iwork, lay,
                                                lcp_ctl, Ab, xb, idx, pcol, not regimes)
                if lst != 0:
                    status = LCP_HANDBACK
                    break
                if na == 1 and nfa == 1 and (
                        (reg[ia[0]] != 0 and reg[ia[0]] != 3
                         and _jam(Wd[0, 0], Wd[0, 1], mu[ia[0]], Uf[0], e[ia[0]], vN0[ia[0]],
                                  _slip_sign(reg[ia[0]])))
                        or _stop_at(lcp_ctl, Wd[0, 0], Wd[0, 1], mu[ia[0]], Uf[0], Uf[1],
                                    e[ia[0]], vN0[ia[0]])):
                    # one contact by Lemke (lcp_method="lemke"): a tangential impact, as above
                    status = PAINLEVE
                    break
                stats[S_PIVOTS] += piv
                stats[S_LCP] += 1.0
                if warm:
                    stats[S_WARM] += 1.0
            if res > stats[S_RES]:
                stats[S_RES] = res
            for i in range(n):
                acc = vf[i]
                for c in range(m):
                    acc += WiHT[i, c] * p[c]
                v1[i] = acc
            for r in range(nfa):
                tr = na + r
                acc = Uf[tr]
                for c in range(m):
                    acc += Wd[tr, c] * p[c]
                slip[fa[r]] = acc

        for i in range(n):
            q1[i] = q[i] + hk * (th * v1[i] + (1.0 - th) * v[i])
        for i in range(nc):
            cnew[i] = pN[i] > 0.0
        gaps_current = False
        if projection and nc > 0:
            if not const_mass:
                mass_fn(par, q1, M)
            for i in range(nc):
                sel[i] = cnew[i]
            # M^-1 of a constant mass matrix is kept from the last projection
            pinv = const_mass and have_Mi
            for _ in range(PROJECTION_MAXITER):
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, q1, t1, Gq)
                else:
                    contacts_fn(par, q1, t1, Gq, True, False)
                gaps_current = True
                anysel = False
                gmax = 0.0
                for i in range(nc):
                    if Gq[i, 0] < 0.0:
                        sel[i] = True
                    if sel[i]:
                        anysel = True
                        gmax = max(gmax, abs(Gq[i, 0]))
                if (not anysel) or gmax <= PROJECTION_TOL:
                    break
                if not pinv:
                    if n <= 3:
                        ok = _invert_small(M, Mi, n)
                    else:
                        ok = _invert_gj(M, Mi, wk, n)
                    if not ok:
                        status = NUMERICAL
                        break
                    pinv = True
                    have_Mi = True
                contacts_fn(par, q1, t1, Gq, False, False)
                s = 0
                for i in range(nc):
                    if sel[i]:
                        ia[s] = i
                        s += 1
                # X = M^-1 WN_sel^T, S = WN_sel X, S d = -g_sel, q += X d
                if s == 1:
                    # one contact (the common case): a scalar division, no solver call
                    i0 = ia[0]
                    sc = 0.0
                    for i in range(n):
                        acc = 0.0
                        for j in range(n):
                            acc += Mi[i, j] * Gq[i0, 3 + j]
                        X[i, 0] = acc
                        sc += Gq[i0, 3 + i] * acc
                    d0 = -Gq[i0, 0] / sc
                    for i in range(n):
                        q1[i] += X[i, 0] * d0
                else:
                    for c in range(s):
                        for i in range(n):
                            acc = 0.0
                            for j in range(n):
                                acc += Mi[i, j] * Gq[ia[c], 3 + j]
                            X[i, c] = acc
                        rs[c] = -Gq[ia[c], 0]
                    for r in range(s):
                        for c in range(s):
                            acc = 0.0
                            for j in range(n):
                                acc += Gq[ia[r], 3 + j] * X[j, c]
                            S[r, c] = acc
                    # S is regular where the selected gaps are independent; an
                    # exactly singular one is a numerical failure, as before
                    if eliminate(S, rs, s, 0.0, 0.0, pcol, dd, ident) < s:
                        status = NUMERICAL
                        break
                    for i in range(n):
                        acc = 0.0
                        for c in range(s):
                            acc += X[i, c] * dd[c]
                        q1[i] += acc
                gaps_current = False
                stats[S_PROJ] += 1.0
            if status != OK:
                break
        finite = True
        for i in range(n):
            if not (math.isfinite(q1[i]) and math.isfinite(v1[i])):
                finite = False
        if not finite:
            status = NUMERICAL
            break
        if nc > 0:
            if not gaps_current:
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, q1, t1, Gq)
                else:
                    contacts_fn(par, q1, t1, Gq, True, False)
            for i in range(nc):
                if -Gq[i, 0] > stats[S_PEN]:
                    stats[S_PEN] = -Gq[i, 0]
                reg[i] = _classify(pN[i], pT[i], mu[i])
        if record_initial:
            record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                          tk, q, v, reg, pN, pT, hk, slip, G0, n, nc)
            nrec += 1
            record_initial = False
        for i in range(nc):
            closed[i] = cnew[i]
            G0[i, 0] = Gq[i, 0]
        for j in range(n):
            q[j] = q1[j]
            v[j] = v1[j]
        k += 1
        to_save -= 1
        if to_save == 0:
            to_save = save_every
        if to_save == save_every or last:
            record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                          t1, q, v, reg, pN, pT, hk, slip, Gq, n, nc)
            nrec += 1
        if last:
            break
    for i in range(nc):
        lcp_ctl[roff + i] = reg[i]
    return status, k, nrec


# error_model="numpy": a division by zero gives inf/nan, which the loop's own
# tests turn into SINGULAR or NUMERICAL, instead of a raise branch after every
# division, whose clean-up path kept numba from pruning reference counts.
@njit(cache=True)
def no_gaps(par, q, t, G):
    """Stands in for a model without a ``gaps`` function (never called: ``HAS_GAPS`` is False)."""
    G[0, 0] = math.nan


#: every source whose compiled code ends up in this module's functions and in
#: the runners built on mj_loop (Lemke is linked in; globals are frozen in)
KERNEL_SOURCES = (__file__, _lemke.__file__, _certify.__file__, _certified.__file__)

# numba checks a cached kernel against this file only: tie it to all of them so
# that editing Lemke cannot leave stale machine code in use
CACHE_MODE = _jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    KERNEL_SOURCES)
