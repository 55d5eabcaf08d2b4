"""The compiled contact step shared by the schemes' loops.

Given the active contacts of a step (their rows ``ia``, the frictional ones
``fa``), the Delassus block ``Wd`` of their normal and tangential rows, the
free local velocities ``Uf``, the friction and restitution coefficients, the
pre-impact normal velocities and the warm-start memory with the options
(:func:`new_lcp_control`), it returns the impulses and a status:

* one active contact: the closed-form case analysis :func:`_one_contact`
  (stick, positive slip, negative slip; one row when ``mu = 0``);
* several: the velocity-level friction LCP of
  :func:`moreau.lcp.friction.build_friction_lcp`, assembled over the active
  contacts only and solved by the compiled :func:`moreau.lcp.lemke.lemke_core`
  (:func:`_lcp_step`), after the two warm starts (:func:`_regime_solve`, the
  regimes of the step before; :func:`_warm_solve`, the support of the last
  LCP); where Lemke fails the status :data:`LCP_HANDBACK` hands the step to
  Python (the QP fallback).

:mod:`moreau.integrators._mj_kernels` documents the warm starts' acceptance.
A scheme's step rule calls these kernels on buffers it has unpacked before its
loop: behind one entry taking the buffers as a tuple, the unpacking on every
step cost the two-contact scenes a third of their speed.
"""

import math

import numpy as np
from numba import njit
from numba.core import types as _nbt
from numba.extending import intrinsic

from .. import _jit_cache
from ..contact import _one_contact as _one_contact_module
from ..lcp import _certified
from ..lcp import certify as _certify
from ..lcp import lemke as _lemke
from ..lcp.lemke import DEFAULT_TOL, eliminate, lemke_core, lemke_workspace

__all__ = ["new_lcp_control", "new_stats", "lcp_buffers", "set_painleve_stop",
           "prev_regimes", "STAT_NAMES", "OK", "PAINLEVE", "NUMERICAL", "SINGULAR", "LCP_HANDBACK"]

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


#: the one-contact closed form, its tangential-impact test and residual: compiled once on
#: the contact floor, where the Python schemes' contact problem calls the same functions
_one_contact = _one_contact_module._one_contact
_one_contact_cases = _one_contact_module._one_contact_cases
_jam = _one_contact_module._jam
_residual_parts = _one_contact_module._residual_parts
_residual = _one_contact_module._residual


def new_stats():
    return np.zeros(len(STAT_NAMES))


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


@intrinsic
def borrowed(typingctx, arr):
    """A view of the array ``arr`` that does not own its data (no memory-info pointer).

    A tuple of arrays (and of such tuples) gives the tuple of their views; a
    number or a boolean is passed through.

    For the arrays a compiled function hands to a function inlined at
    numba's IR level (:func:`_regime_solve`, :func:`_lcp_step_body`), or to a
    model's function (``moreau.integrators._driver._borrow_model_arguments``): numba
    takes a reference on each for the callee's names and drops it at each of
    its exits, an atomic increment and decrement per array and call, which
    LLVM's pruning does not pair across the callee's loops and branches. On a
    view without memory info both are a test of a null pointer. The view must
    not outlive ``arr`` (the caller's buffers, or its own arguments) and must
    not be returned to Python.
    """
    if not _borrowable(arr):
        return None
    ty = _nbt.unliteral(arr)

    def codegen(context, builder, sig, args):
        return _borrow_value(context, builder, ty, args[0])
    return ty(arr), codegen


def _borrowable(ty):
    # an array, a number or a boolean (passed through: a model function's time and
    # flags), or a tuple of them (a loop's buffer groups)
    if isinstance(ty, (_nbt.Array, _nbt.Number, _nbt.Boolean)):
        return True
    return isinstance(ty, _nbt.BaseTuple) and all(_borrowable(t) for t in ty.types)


def _borrow_value(context, builder, ty, value):
    if isinstance(ty, _nbt.Array):
        view = context.make_array(ty)(context, builder, value=value)
        view.meminfo = context.get_constant_null(_nbt.MemInfoPointer(ty.dtype))
        return view._getvalue()
    if not isinstance(ty, _nbt.BaseTuple):
        return value
    for k, t in enumerate(ty.types):
        value = builder.insert_value(
            value, _borrow_value(context, builder, t, builder.extract_value(value, k)), k)
    return value


# inlined into the loop (numba IR), unlike the other helpers: it runs on nearly every
# step of a two-contact scene, and as a call with fifteen array arguments it cost the
# bidirectional drive a fifth of its speed (2.1e6 -> 2.6e6 steps/s inlined, sliding box
# 2.7e6 -> 3.7e6, same process); the loops that include it are compiled once each now.
# Its callers pass its arrays as borrowed() views: inlined, each argument's reference
# count was an atomic increment and decrement per step that LLVM did not prune (a
# quarter of the shared loop's time in the bidirectional drive)
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
    """Assemble the friction LCP of the active contacts and solve it: :func:`_lcp_step_body`.

    Its arrays as :func:`borrowed` views: a reference taken on each of the
    twenty-three and dropped at each exit, through Lemke's branches, was
    dozens of atomic operations per call that LLVM did not prune (a fifth to
    a third of the time of the schemes that solve an LCP at every step).
    """
    return _lcp_step_body(
        borrowed(Wd), borrowed(Uf), na, borrowed(ia), borrowed(mu), borrowed(p), borrowed(pN),
        borrowed(pT), L, borrowed(base), borrowed(trow), borrowed(Ml), borrowed(ql),
        borrowed(dl), borrowed(zl), borrowed(wl), borrowed(rayl), borrowed(work),
        borrowed(iwork), borrowed(lay), borrowed(ctl), borrowed(Ab), borrowed(xb),
        borrowed(idx), borrowed(pcol), use_memory)


@njit(cache=True, inline="always")
def _lcp_step_body(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow, Ml, ql, dl, zl, wl, rayl,
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


#: every source whose compiled code ends up in this module's functions (Lemke is linked in)
KERNEL_SOURCES = (__file__, _one_contact_module.__file__, _lemke.__file__, _certify.__file__,
                  _certified.__file__)

# numba checks a cached kernel against this file only: tie it to all of them so
# that editing Lemke cannot leave stale machine code in use
CACHE_MODE = _jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    KERNEL_SOURCES)
