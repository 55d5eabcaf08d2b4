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

from .. import _jit_cache
from ..lcp.lemke import DEFAULT_TOL, eliminate
# the contact step's names, read here by the loop and by the modules that import them from here
from ._contact_step import (  # noqa: F401
    CTL_FORCE, CTL_IA, CTL_WARM, LCP_HANDBACK, LCP_STEP_SIGNATURE, NUMERICAL, OK, PAINLEVE,
    S_DIRECT, S_FALLBACKS, S_LCP, S_PEN, S_PIVOTS, S_PROJ, S_RES, S_WARM, SHARED_INDIRECT,
    SINGULAR, SLIP_RTOL, SPECIALISED, STAT_NAMES, _classify, _jam, _lcp_size, _lcp_step,
    _lcp_step_unused, _one_contact, _one_contact_fr, _regime_solve, _residual, _residual_parts,
    _residual_parts_fr, _slip_sign, _stop_at, borrowed, lcp_buffers, lcp_needed,
    new_lcp_control, new_stats, prev_regimes, set_painleve_stop)
from . import _contact_step, _driver, _step_parts
from ._driver import grid_step, loop_template, record_sample, spliced  # noqa: F401
from ._step_parts import (COND_MAX, _invert_gj, _invert_small, add_impulse, all_finite,  # noqa: F401
                          contact_block, gap_block, gaps_at, gather_rows, index_set, invert,
                          lemke_solve, move_by, record_contacts, restitution_shift, slip_rows,
                          sparse_delassus, start_contacts)

__all__ = ["mj_loop", "grid_step", "no_gaps", "new_stats", "new_lcp_control", "STAT_NAMES", "OK", "PAINLEVE", "NUMERICAL",
           "SINGULAR", "LCP_HANDBACK"]

# shared with moreau_jean.py (kept as literals so that numba freezes them)
PROJECTION_TOL = 1e-14
PROJECTION_MAXITER = 8

#: compile-time switches of the step rule, True in every loop but the lean shared one
#: (SHARED_LEAN), where numba prunes the branches they guard
LCP_REACHABLE = True
PROJECTION_REACHABLE = True

# spliced: allocated in the loop's own function, the buffers' shapes are known to LLVM
# (a model's own loop of a two-contact scene ran 7-9 % slower with them from a call), and
# given to the step rule's names with no tuple between (_driver._spliced_workspace)
@spliced
def step_workspace(n, nc, opts, lcp_ctl):
    """The buffers of :func:`step_rule`, allocated once a call of the loop (one tuple)."""
    ncm = max(nc, 1)
    mrows = 2 * ncm
    lw = lcp_buffers(ncm)
    # the columns where each row of H is nonzero: contact rows touch few
    # coordinates (two balls of a chain), and the Delassus assembly over them
    # alone costs m nnz instead of m n^2 (N = 100 balls: 10x fewer operations
    # per step); the skipped terms are exact zeros, so the sums are the same
    hnz = np.zeros((mrows, n), dtype=np.int64)
    # have_Wi, have_Mi: W_hat^-1 and M^-1 of a constant matrix computed in this call
    flags = np.zeros(2, dtype=np.int64)
    return (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
            # model outputs, packed (see moreau.compiled): D = [h | K | C]
            np.zeros((n, 1 + 2 * n)), np.zeros((n, 1 + 2 * n)), np.empty(n), np.empty(n),
            # contact rows at (q_k, t_k+1)
            np.zeros((ncm, 3 + 2 * n)), np.zeros(ncm), np.zeros(ncm, dtype=np.bool_),
            np.zeros(ncm, dtype=np.bool_), np.zeros(ncm, dtype=np.int64),
            np.zeros(ncm, dtype=np.int64), np.zeros((mrows, n)), hnz,
            np.zeros(mrows, dtype=np.int64), np.zeros(mrows), np.zeros((n, mrows)),
            np.zeros((mrows, mrows)), np.zeros(mrows), np.zeros(mrows),
            # projection buffers
            np.empty((n, n)), np.zeros(ncm, dtype=np.bool_), np.zeros((n, ncm)),
            np.zeros((ncm, ncm)), np.zeros(ncm), np.arange(ncm), np.zeros(ncm),
            np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.int64), np.zeros(2 * ncm),
            flags, lw)


@spliced(step_returns=True)
def free_velocity(mass_fn, forces_fn, contacts_fn, par, q, v, tk, t1, hk, k, k0, th, n, nc,
                  const_mass, has_jac, constant_W, M, D, D0, G0, rhs, Wh, Wi, wk, flags, vf, v1):
    """Moreau–Jean's free velocity ``vf = v + W_hat^-1 (h [theta f1 + (1 - theta) f0]
    + h^2 theta K v)`` (also into ``v1``); the contact rows at ``(q_k, t_k)`` into ``G0``.

    ``W_hat^-1`` of a constant mass matrix without force Jacobians is kept
    (``flags[0]``); a singular ``W_hat`` stops the step (:data:`SINGULAR`).
    """
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
    if not (constant_W and flags[0] != 0):
        ok = invert(Wh, Wi, wk, n)
        if not ok:
            return SINGULAR
        flags[0] = 1
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += Wi[i, j] * rhs[j]
        vf[i] = v[i] + acc
        v1[i] = vf[i]


@spliced(step_returns=True)
def one_contact(G1, ia, nfa, Wi, WiHT, vf, v1, n, mu, e, vN0, reg, lcp_ctl, stats, pN, pT, slip):
    """One active contact (``ia[0]``) in closed form, into ``pN``, ``pT``, ``slip`` and ``v1``.

    The case analysis on the 2x2 (1x1) Delassus matrix, built from the
    contact's two rows only; loops over ``n`` alone, so that with the sizes
    known at compile time it is straight-line code. A tangential impact or no
    solution hands the step to the generic path (:data:`PAINLEVE`).
    """
    i = ia[0]
    fr = nfa == 1
    Wnn, Wnt, Wtn, Wtt, uN, uT = contact_block(G1, i, Wi, WiHT, vf, n, fr)
    stats[S_LCP] += 1.0
    stats[S_DIRECT] += 1.0
    if fr:
        pn, pt, ok = _one_contact_fr(Wnn, Wnt, Wtn, Wtt, uN, uT, mu[i], e[i], vN0[i])
        # a tangential impact is taken by the generic step, which records it (or
        # stops there with painleve="stop"); it is rare, the test is not
        if not ok or (reg[i] != 0 and reg[i] != 3
                      and _jam(Wnn, Wnt, mu[i], uN, e[i], vN0[i], _slip_sign(reg[i]))) \
                or _stop_at(lcp_ctl, Wnn, Wnt, mu[i], uN, uT, e[i], vN0[i]):
            return PAINLEVE
        rnum, rscale = _residual_parts_fr(Wnn, Wnt, Wtn, Wtt, uN, uT, mu[i], e[i],
                                          vN0[i], pn, pt)
        slip[i] = uT + Wtn * pn + Wtt * pt
    else:
        pn, pt, ok = _one_contact(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, e[i], vN0[i])
        if not ok:
            return PAINLEVE
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


@spliced(step_returns=True)
def several_contacts(lcp_step, na, nfa, ia, mu, e, vN0, reg, Wd, Uf, p, pN, pT, base, trow, rvel,
                     Ml, ql, dl, zl, wl, rayl, work, iwork, lay, lcp_ctl, Ab, xb, idx, pcol,
                     warm_on, k, k0, stats):
    """The friction LCP of several active contacts (``Wd``, ``Uf`` assembled): impulses into ``p``,
    ``pN``, ``pT``.

    From the second step of a call on, the regimes of the step before are
    tried first (:func:`_regime_solve`); refused, Lemke decides (from the
    remembered support on a call's first step). Where Lemke fails the step
    is handed back (:data:`LCP_HANDBACK`); a tangential impact of one
    contact solved by Lemke goes to the generic path (:data:`PAINLEVE`).
    """
    L = _lcp_size(na, ia, mu, base, trow)
    res = np.inf
    # the regimes of the step before (known from the second step of a call on)
    regimes = warm_on and k > k0
    if regimes:
        # borrowed views: no reference counting per step (see _contact_step.borrowed)
        res = _regime_solve(borrowed(Wd), borrowed(Uf), na, borrowed(ia), borrowed(trow),
                            borrowed(mu), borrowed(reg), borrowed(p), borrowed(pN), borrowed(pT),
                            borrowed(Ab), borrowed(xb), borrowed(idx), borrowed(rvel),
                            borrowed(pcol))
    if 0.0 <= res <= DEFAULT_TOL:
        stats[S_LCP] += 1.0
        stats[S_WARM] += 1.0
    else:
        # refused: a regime changes in this step (or lies within the
        # margin of changing) and Lemke decides, from scratch, since the
        # remembered support is that of the old regimes. On the first
        # step of a call the regimes are unknown: the support may serve
        piv, res, warm = lemke_solve(lcp_step, Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow,
                                     Ml, ql, dl, zl, wl, rayl, work, iwork, lay, lcp_ctl, Ab, xb,
                                     idx, pcol, not regimes)
        if na == 1 and nfa == 1 and (
                (reg[ia[0]] != 0 and reg[ia[0]] != 3
                 and _jam(Wd[0, 0], Wd[0, 1], mu[ia[0]], Uf[0], e[ia[0]], vN0[ia[0]],
                          _slip_sign(reg[ia[0]])))
                or _stop_at(lcp_ctl, Wd[0, 0], Wd[0, 1], mu[ia[0]], Uf[0], Uf[1],
                            e[ia[0]], vN0[ia[0]])):
            # one contact by Lemke (lcp_method="lemke"): a tangential impact, as in one_contact
            return PAINLEVE
        stats[S_PIVOTS] += piv
        stats[S_LCP] += 1.0
        if warm:
            stats[S_WARM] += 1.0
    if res > stats[S_RES]:
        stats[S_RES] = res


@spliced(step_returns=True)
def project_positions(projection, nc, n, mass_fn, gaps_fn, contacts_fn, HAS_GAPS, const_mass, par,
                      t1, q1, M, Mi, wk, sel, cnew, Gq, ia, X, S, rs, pcol, dd, ident, flags,
                      stats):
    """With ``projection``: Gauss–Newton steps of ``q1`` onto ``g = 0`` for the contacts that
    carried an impulse or whose gap is negative, in the metric of ``M``.

    Returns whether ``Gq`` holds the gaps at ``q1``; a singular ``M`` or
    selected gaps that are not independent stop the step (:data:`NUMERICAL`).
    """
    gaps_current = False
    if projection and nc > 0:
        if not const_mass:
            mass_fn(par, q1, M)
        for i in range(nc):
            sel[i] = cnew[i]
        # M^-1 of a constant mass matrix is kept from the last projection
        pinv = const_mass and flags[1] != 0
        for _ in range(PROJECTION_MAXITER):
            gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, Gq)
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
                ok = invert(M, Mi, wk, n)
                if not ok:
                    return NUMERICAL
                pinv = True
                flags[1] = 1
            contacts_fn(par, q1, t1, Gq, False, False)
            s = 0
            for i in range(nc):
                if sel[i]:
                    ia[s] = i
                    s += 1
            # X = M^-1 WN_sel^T, S = WN_sel X, S d = -g_sel, q += X d
            gap_block(Gq, ia, s, Mi, X, S, n)
            if s == 1:
                # one contact (the common case): a scalar division, no solver call
                d0 = -Gq[ia[0], 0] / S[0, 0]
                for i in range(n):
                    q1[i] += X[i, 0] * d0
            else:
                for c in range(s):
                    rs[c] = -Gq[ia[c], 0]
                # S is regular where the selected gaps are independent; an
                # exactly singular one is a numerical failure, as before
                if eliminate(S, rs, s, 0.0, 0.0, pcol, dd, ident) < s:
                    return NUMERICAL
                move_by(X, dd, q1, s, n)
            gaps_current = False
            stats[S_PROJ] += 1.0
    return gaps_current


@njit(inline="always", error_model="numpy")
def step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS, HAS_JAC,
              HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats, k, k0, tk, t1, hk,
              hn, record_initial, q, v, out):
    """One Moreau–Jean step from ``(q, v)`` at ``tk`` to ``(q1, v1)`` at ``t1`` (see :mod:`._driver`).

    ``opts`` is ``(theta, projection)``, ``memo`` ``(closed,)``: the contacts
    that carried a normal impulse in the step before, updated after a step
    taken. The free velocity solves ``W_hat dv = h [theta f1 + (1 - theta)
    f0] + h^2 theta K v``; a contact is active where its gap, extrapolated
    half a step, closes (or where it was closed); one active contact is
    solved in closed form, several by the friction LCP (:mod:`._contact_step`);
    then the position update and, with ``projection``, the mass-weighted
    projection of the closed gaps.
    """
    n = NDOF
    nc = NCONTACTS
    const_mass = CONST_MASS
    has_jac = HAS_JAC
    th, projection = opts
    q1, v1, pN, pT, slip, reg, G0, Gq = out
    closed = memo[0]
    (M, Wh, Wi, wk, D, D0, rhs, vf, G1, vN0, active, cnew, ia, fa, H, hnz, hcnt, w, WiHT, Wd, Uf,
     p, Mi, sel, X, S, rs, ident, dd, base, trow, rvel, flags, lw) = ws
    # unpacked before the loop (the driver splices this): a tuple unpacked on every step
    # costs a two-contact scene a third of its speed
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lw
    force_lemke = lcp_ctl[CTL_FORCE] != 0
    warm_on = lcp_ctl[CTL_WARM] != 0 and not force_lemke
    constant_W = const_mass and not has_jac
    ...  # the steps (moreau.integrators._driver.loop_template)
    # -- free velocity: W_hat dv = h [theta f1 + (1 - theta) f0] + h^2 theta K v
    free_velocity(mass_fn, forces_fn, contacts_fn, par, q, v, tk, t1, hk, k, k0, th, n, nc,
                  const_mass, has_jac, constant_W, M, D, D0, G0, rhs, Wh, Wi, wk, flags, vf, v1)
    # -- contacts: the active set at (q_k, v_k), the rows at (q_k, t_k+1)
    start_contacts(G0, v, closed, hk, nc, n, vN0, active, pN, pT, slip)
    na, nfa = index_set(active, mu, nc, ia, fa)
    if na > 0:
        contacts_fn(par, q, t1, G1, False, True)
    if na == 1 and not force_lemke:
        one_contact(G1, ia, nfa, Wi, WiHT, vf, v1, n, mu, e, vN0, reg, lcp_ctl, stats, pN, pT,
                    slip)
    elif na > 0:
        if LCP_REACHABLE:
            m = na + nfa
            sparse_delassus(G1, ia, fa, na, nfa, n, Wi, vf, H, hnz, hcnt, w, WiHT, Uf, Wd)
            restitution_shift(Uf, na, ia, e, vN0)
            several_contacts(lcp_step, na, nfa, ia, mu, e, vN0, reg, Wd, Uf, p, pN, pT, base,
                             trow, rvel, Ml, ql, dl, zl, wl, rayl, work, iwork, lay, lcp_ctl, Ab,
                             xb, idx, pcol, warm_on, k, k0, stats)
            add_impulse(WiHT, p, vf, v1, m, n)
            slip_rows(Wd, Uf, p, fa, na, nfa, m, slip)
        else:
            # the lean shared loop, run only where no LCP can arise (SHARED_LEAN): never
            # reached; were it reached, the generic step would take the step
            return LCP_HANDBACK
    # -- update: positions, then the projection
    for i in range(n):
        q1[i] = q[i] + hk * (th * v1[i] + (1.0 - th) * v[i])
    for i in range(nc):
        cnew[i] = pN[i] > 0.0
    if PROJECTION_REACHABLE:
        gaps_current = project_positions(projection, nc, n, mass_fn, gaps_fn, contacts_fn,
                                         HAS_GAPS, const_mass, par, t1, q1, M, Mi, wk, sel, cnew,
                                         Gq, ia, X, S, rs, pcol, dd, ident, flags, stats)
    elif projection:
        # the lean shared loop runs without projection only (SHARED_LEAN): never reached
        return LCP_HANDBACK
    else:
        gaps_current = False
    if not all_finite(q1, v1, n):
        return NUMERICAL
    if nc > 0 and not gaps_current:
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, Gq)
    record_contacts(Gq, nc, pN, pT, mu, reg, stats)
    for i in range(nc):
        closed[i] = cnew[i]
    return OK


mj_loop = loop_template("mj_loop", globals(), "Moreau–Jean")


def lean_enough(nc, lcp_ctl, opts):
    """Whether a run can take the lean shared loop: no contact LCP (:func:`lcp_needed`), no
    projection.

    Examples
    --------
    >>> lean_enough(1, new_lcp_control(1), (1.0, False)), lean_enough(2, new_lcp_control(2),
    ...                                                                (1.0, False))
    (True, False)
    """
    return not lcp_needed(nc, lcp_ctl) and isinstance(opts, tuple) and len(opts) == 2 \
        and not opts[1]


#: the shared loop's lean variant (moreau.integrators._loops.shared_core): the switches it is
#: compiled with, and the test on (the number of contacts, the loop's arguments named) that
#: picks it. A first use of a one-contact scene (the README's friction drive) compiles the
#: loop without the several-contact branch (Delassus assembly, warm start, Lemke's call) and
#: the projection: about a third of the full loop's compile
SHARED_LEAN = ({"LCP_REACHABLE": False, "PROJECTION_REACHABLE": False}, lean_enough,
               ("lcp_ctl", "opts"))


# error_model="numpy": a division by zero gives inf/nan, which the loop's own
# tests turn into SINGULAR or NUMERICAL, instead of a raise branch after every
# division, whose clean-up path kept numba from pruning reference counts.
@njit(cache=True)
def no_gaps(par, q, t, G):
    """Stands in for a model without a ``gaps`` function (never called: ``HAS_GAPS`` is False)."""
    G[0, 0] = math.nan


#: every source whose compiled code ends up in this module's functions and in
#: the runners built on mj_loop (Lemke is linked in; globals are frozen in)
KERNEL_SOURCES = (__file__, _driver.__file__, _step_parts.__file__) + _contact_step.KERNEL_SOURCES

# numba checks a cached kernel against this file only: tie it to all of them so
# that editing Lemke cannot leave stale machine code in use
CACHE_MODE = _jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    KERNEL_SOURCES)
