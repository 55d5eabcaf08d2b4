"""Studer's step-size adjustment and extrapolation as a step rule of the compiled driver.

The same macro step as
:meth:`moreau.integrators.studer_extrapolation.StuderExtrapolation._generic_step`
(see that module's docstring for the method), on the functions of a
:class:`moreau.compiled.CompiledModel`: the Moreau midpoint base steps, the
sequences of ``1 .. K`` base steps, the Aitken–Neville table in smooth
phases, step halving and the switch location elsewhere, the projection of
the accepted state onto the closed contacts. Every contact problem goes
through :func:`moreau.integrators._tdg_kernels._stage_problem` (the rows
that measure the velocity are those of the step's end, the impulse acts
along the midpoint's). :func:`step_rule` takes one accepted macro step; the
driver (:mod:`moreau.integrators._driver`, without its grid:
``ADAPTIVE_STEPS``) owns the loop, the buffers and the recording, and
:func:`moreau.integrators._loops.runner_for` compiles ``studer_loop`` as
every driver's template. Its helpers are :func:`moreau.integrators._driver.spliced`
into it as source, as the step parts it uses are.
"""

import math

import numpy as np
from numba import njit

from ._driver import loop_template, spliced
from ._mj_kernels import OK, S_PEN, SINGULAR, _classify, _lcp_step, lcp_buffers  # noqa: F401
# read by moreau.integrators._loops
from ._mj_kernels import SHARED_INDIRECT, _lcp_step_unused  # noqa: F401
from ._step_parts import (add_impulse, affine_rows, all_finite, gap_block, gaps_at, gather_rows,
                          held_gaps, index_set, mass_inverse, move_back, times_ht)
from ._tdg_kernels import _solve_small, _stage_problem

__all__ = ["studer_loop", "STUDER_COUNTERS", "NOT_FINITE", "TOO_MANY", "DENSE_IMPACT",
           "DENSE_SWITCH", "DENSE_SMOOTH"]

#: status: a non-finite state or error estimate after a macro step
NOT_FINITE = -5
#: status: the run's bound on macro steps is reached
TOO_MANY = -8
#: dense output of a macro step (:mod:`moreau.integrators.studer_extrapolation`): a contact
#: closed in it (an impulse), a switch of the regimes without one, a smooth step
DENSE_IMPACT = 0
DENSE_SWITCH = 1
DENSE_SMOOTH = 2
#: the loop's counters, in the order of its ``cnt`` argument
STUDER_COUNTERS = ("macro_steps", "base_steps", "rejected_steps", "smooth_steps", "forced_steps")


#: the driver (:mod:`moreau.integrators._driver`) has no grid: the step rule sizes its macro steps
ADAPTIVE_STEPS = True


# spliced, as Moreau–Jean's: allocated in the loop's own function
@spliced
def step_workspace(n, nc, opts, lcp_ctl):
    """The buffers of :func:`step_rule`, allocated once a call of the loop (one tuple)."""
    K = opts[1]
    ncm = max(nc, 1)
    mrows = 2 * ncm
    # a row of the table: q, v and the accelerations at the start and the end (dense output)
    n4 = 4 * n
    return (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
            np.zeros((n, 1 + 2 * n)), np.zeros((ncm, 3 + 2 * n)), np.zeros((ncm, 3 + 2 * n)),
            np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(2 * n),
            np.zeros((K, n4)), np.zeros((K, n4)), np.zeros((K, n4)), np.zeros(n), np.zeros(n),
            np.zeros(K, dtype=np.bool_), np.zeros(K, dtype=np.bool_), np.zeros(K, dtype=np.bool_),
            np.zeros((K, ncm), dtype=np.bool_), np.zeros((K, ncm)), np.zeros((K, ncm)),
            np.zeros((K, ncm)), np.zeros((K, ncm), dtype=np.int64), np.zeros(ncm, dtype=np.bool_),
            np.zeros(ncm, dtype=np.bool_), np.zeros(ncm, dtype=np.int64),
            np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.int64),
            np.zeros(ncm, dtype=np.int64), np.zeros(ncm), np.zeros(ncm), np.zeros((mrows, n)),
            np.zeros((mrows, n)), np.zeros(mrows), np.zeros(mrows), np.zeros((n, mrows)),
            np.zeros((mrows, mrows)), np.zeros(mrows), np.zeros(mrows), np.zeros(mrows),
            np.zeros((ncm, ncm)), np.zeros(ncm), np.zeros((n, ncm)),
            np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.int64), lcp_buffers(ncm))


@spliced(step_returns=True)
def midpoint_velocity(forces_fn, contacts_fn, gaps_fn, HAS_GAPS, par, mu, e, qs, vs, qm, tb, tm,
                      hb, n, nc, cl, Mi, D, qe, vf, v1, pN, pT, sl, act, ia, fa, Gm, Ge, Hm, He,
                      wm, we, ea, vpre, Dir, force_lemke, p, U, Wd, Uf, base, trow, lw, lcp_ctl,
                      stats, lcp_step):
    """``v1`` after one Moreau midpoint step of ``hb`` from ``(qs, vs)`` at ``tb`` (``qm`` its
    midpoint, ``Mi`` the inverse mass there); returns how many contacts are active in it."""
    forces_fn(par, qm, vs, tm, D, False)
    for i in range(n):
        a = 0.0
        for j in range(n):
            a += Mi[i, j] * D[j, 0]
        vf[i] = vs[i] + hb * a
        v1[i] = vf[i]
    for c in range(nc):
        pN[c] = 0.0
        pT[c] = 0.0
        sl[c] = 0.0
        act[c] = False
    if nc > 0:
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, qm, tm, Gm)
        for c in range(nc):
            # a contact that carried a force stays in the index set while it does, whatever
            # its midpoint gap
            act[c] = cl[c] or Gm[c, 0] <= 0.0
    na, nfa = index_set(act, mu, nc, ia, fa)
    if na > 0:
        m = na + nfa
        contacts_fn(par, qm, tm, Gm, False, True)
        for i in range(n):
            qe[i] = qs[i] + hb * vs[i]
        contacts_fn(par, qe, tb + hb, Ge, False, True)
        # the impulse acts along the midpoint's rows, the end's rows measure the velocity
        gather_rows(Gm, ia, fa, na, nfa, n, Hm, wm)
        gather_rows(Ge, ia, fa, na, nfa, n, He, we)
        affine_rows(Hm, wm, vs, vpre, na, n)
        for r in range(na):
            ea[r] = 0.0 if cl[ia[r]] else e[ia[r]]
        times_ht(Mi, Hm, Dir, m, n)
        st = _stage_problem(He, we, Dir, vf, ea, vpre, n, na, nfa, ia, mu, force_lemke, p, pN,
                            pT, U, Wd, Uf, base, trow, lw, lcp_ctl, stats, lcp_step)
        if st != OK:
            return st
        add_impulse(Dir, p, vf, v1, m, n)
        for r in range(nfa):
            sl[fa[r]] = U[na + r]
    return na


@spliced(step_returns=True)
def sequence(mass_fn, forces_fn, contacts_fn, gaps_fn, HAS_GAPS, const_mass, have_Mi, par, mu, e,
             q, v, closed, last_reg, t, H, j, n, nc, M, Mi, wk, D, qm, qe, qs, vs, vf, v1, pN, pT,
             sl, reg, reg0, cl, act, ia, fa, Gm, Ge, G1, Hm, He, wm, we, ea, vpre, Dir, force_lemke,
             p, U, Wd, Uf, base, trow, lw, lcp_ctl, stats, cnt, Y, sq_smooth, sq_missed,
             sq_closing, sq_closed, sq_pN, sq_pT, sq_slip, sq_reg, lcp_step):
    """Sequence ``j``: ``j`` Moreau midpoint steps of ``H / j`` from ``(q, v)`` at ``t``, into
    row ``j - 1`` of the table ``Y`` (state, the first and the last step's mean accelerations)
    and of the ``sq_*`` arrays. Returns ``(same_last, have_Mi)``: whether it ends in the regimes
    the step before ended in, and whether ``Mi`` holds the constant mass matrix's inverse."""
    fresh = have_Mi
    hb = H / j
    for i in range(n):
        qs[i] = q[i]
        vs[i] = v[i]
    for c in range(nc):
        cl[c] = closed[c]
        sq_pN[j - 1, c] = 0.0
        sq_pT[j - 1, c] = 0.0
    s_smooth = True
    s_missed = False
    s_closing = False
    for ib in range(j):
        cnt[1] += 1
        tb = t + ib * hb
        tm = tb + 0.5 * hb
        for i in range(n):
            qm[i] = qs[i] + 0.5 * hb * vs[i]
        if not (const_mass and fresh):
            mass_inverse(mass_fn, par, qm, M, Mi, wk, n, SINGULAR)
            fresh = True
        na = midpoint_velocity(forces_fn, contacts_fn, gaps_fn, HAS_GAPS, par, mu, e, qs,
                               vs, qm, tb, tm, hb, n, nc, cl, Mi, D, qe, vf, v1, pN, pT,
                               sl, act, ia, fa, Gm, Ge, Hm, He, wm, we, ea, vpre, Dir,
                               force_lemke, p, U, Wd, Uf, base, trow, lw, lcp_ctl, stats,
                               lcp_step)
        # the mean accelerations of the first and the last base step: at the ends of
        # the macro step to O(hb), and extrapolated with the state
        if ib == 0:
            for i in range(n):
                Y[j - 1, 2 * n + i] = (v1[i] - vs[i]) / hb
        if ib == j - 1:
            for i in range(n):
                Y[j - 1, 3 * n + i] = (v1[i] - vs[i]) / hb
        for i in range(n):
            qs[i] = qm[i] + 0.5 * hb * v1[i]
            vs[i] = v1[i]
        if not const_mass:
            fresh = False
        switch = False
        miss = False
        if na < nc:
            # only a contact open at the midpoint can be crossed unseen
            gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, qs, tb + hb, G1)
            for c in range(nc):
                if G1[c, 0] < 0.0 and not act[c]:
                    miss = True
        same = True
        for c in range(nc):
            if pN[c] > 0.0 and not cl[c]:
                switch = True
            reg[c] = _classify(pN[c], pT[c], mu[c])
            cl[c] = pN[c] > 0.0
            sq_pN[j - 1, c] += pN[c]
            sq_pT[j - 1, c] += pT[c]
            if ib == 0:
                reg0[c] = reg[c]
            if reg[c] != reg0[c]:
                same = False
        s_missed = s_missed or miss
        s_closing = s_closing or switch
        s_smooth = s_smooth and not switch and not miss and same
    for i in range(n):
        Y[j - 1, i] = qs[i]
        Y[j - 1, n + i] = vs[i]
    sq_smooth[j - 1] = s_smooth
    sq_missed[j - 1] = s_missed
    sq_closing[j - 1] = s_closing
    same_last = True
    for c in range(nc):
        sq_closed[j - 1, c] = cl[c]
        sq_slip[j - 1, c] = sl[c]
        sq_reg[j - 1, c] = reg[c]
        if reg[c] != last_reg[c]:
            same_last = False
    return same_last, fresh


@spliced
def extrapolated(Y, R, Rn, y, a0, a1, K, n, tol):
    """The Aitken–Neville table of the ``K`` sequences (``n_j = j``, an error expansion in every
    power of the step) into ``y`` and the ends' accelerations ``a0``, ``a1``; returns the error
    estimate (the last two columns' difference over the tolerance)."""
    n2 = 2 * n
    n4 = 4 * n
    for d in range(n4):
        R[0, d] = Y[0, d]
    for j in range(2, K + 1):
        for d in range(n4):
            Rn[0, d] = Y[j - 1, d]
        for kk in range(2, j + 1):
            ratio = j / (j - kk + 1) - 1.0
            for d in range(n4):
                Rn[kk - 1, d] = Rn[kk - 2, d] + (Rn[kk - 2, d] - R[kk - 2, d]) / ratio
        for kk in range(j):
            for d in range(n4):
                R[kk, d] = Rn[kk, d]
    err = 0.0
    for d in range(n2):
        y[d] = R[K - 1, d]
        err = max(err, abs(y[d] - R[K - 2, d]) / (tol * (1.0 + abs(y[d]))))
    for i in range(n):
        a0[i] = R[K - 1, n2 + i]
        a1[i] = R[K - 1, n2 + n + i]
    return err


@spliced
def switch_error(Y, y, a0, a1, v, acc, has_acc, sq_closing, sq_reg, last_reg, H, n, nc, tol):
    """The two-sequence estimate of a macro step that is not smooth: ``y`` from the two base
    steps, the dense output's kind and accelerations; returns ``(err, order)``."""
    n2 = 2 * n
    err = 0.0
    for d in range(n2):
        y[d] = Y[1, d]
        err = max(err, abs(y[d] - Y[0, d]) / (tol * (1.0 + abs(y[d]))))
    order = 1
    if sq_closing[1]:
        # an impulse somewhere in the step: the dense output joins the smooth motions
        # before and after it (the last step's acceleration in both)
        kind = DENSE_IMPACT
        for i in range(n):
            a0[i] = acc[i] if has_acc else 0.0
            a1[i] = a0[i]
    else:
        kind = DENSE_SWITCH
        for i in range(n):
            a0[i] = Y[1, n2 + i]
            a1[i] = Y[1, n2 + n + i]
    if has_acc and not (sq_closing[0] or sq_closing[1]):
        changed = False
        for c in range(nc):
            if sq_reg[0, c] != last_reg[c]:
                changed = True
        if changed:
            # a switch in the first base step of every sequence: located by the jump of
            # the acceleration (an error |da| H on the velocities)
            e_sw = 0.0
            for i in range(n):
                da = abs((Y[0, n + i] - v[i]) / H - acc[i])
                e_sw = max(e_sw, da * H / (tol * (1.0 + abs(y[n + i]))))
            if e_sw > err:
                err = e_sw
                order = 0
    return err, order, kind


@spliced(step_returns=True)
def project_held(mass_fn, gaps_fn, contacts_fn, HAS_GAPS, const_mass, have_Mi, par, q1, v1, t1,
                 n, nh, held, M, Mi, Mp, wk, G1, gx, MW, S):
    """Positions onto ``g = 0`` and velocities onto ``WN v + wN = 0`` for the ``nh`` contacts in
    ``held``, in the metric of ``M`` (a singular ``M`` stops the step)."""
    if const_mass and have_Mi:
        for i in range(n):
            for j in range(n):
                Mp[i, j] = Mi[i, j]
    else:
        mass_inverse(mass_fn, par, q1, M, Mp, wk, n, SINGULAR)
    for it in range(4):
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, G1)
        gm = held_gaps(G1, held, nh, gx)
        if gm == 0.0:
            break
        contacts_fn(par, q1, t1, G1, False, True)
        gap_block(G1, held, nh, Mp, MW, S, n)
        if not _solve_small(S, gx, nh):
            break
        dmax = move_back(MW, gx, q1, nh, n)
        qmax = 1.0
        for i in range(n):
            qmax = max(qmax, abs(q1[i]))
        if dmax <= 4e-16 * qmax:
            break
    if not const_mass:
        mass_inverse(mass_fn, par, q1, M, Mp, wk, n, SINGULAR)
    contacts_fn(par, q1, t1, G1, False, True)
    gap_block(G1, held, nh, Mp, MW, S, n)
    for r in range(nh):
        a = G1[held[r], 1]
        for i in range(n):
            a += G1[held[r], 3 + i] * v1[i]
        gx[r] = a
    if _solve_small(S, gx, nh):
        move_back(MW, gx, v1, nh, n)


@njit(inline="always", error_model="numpy")
def step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS, HAS_JAC,
              HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats, k, k0, tk, t1, hk,
              hn, record_initial, q, v, out):
    """One accepted macro step of Studer's scheme from ``(q, v)`` at ``tk`` (see :mod:`._driver`).

    ``opts`` is ``(tol, K, h_min, budget)``: the tolerance, the sequences
    ``1 .. K`` of base steps, the smallest macro step and the bound on the
    macro steps tried (counted in ``cnt[0]``). ``memo`` is ``(th, closed,
    last_reg, acc, cnt, rec_kind, rec_a0, rec_a1)``: ``th = [t, h, has_acc]``
    (time, next macro step, whether ``acc`` holds the last step's
    acceleration), the contacts carrying a force, the regimes the last step
    ended in, the counters :data:`STUDER_COUNTERS` and the dense output of
    each recorded sample (:data:`DENSE_SMOOTH`, ...; -1 on the start's). The
    step is tried until its error estimate allows, then projected onto the
    contacts it closes; ``t1``, ``hk`` and ``last`` are set here
    (``ADAPTIVE_STEPS``). ``have_Mi`` (a constant mass matrix inverted in
    this call) and ``nk`` (dense rows written) live through the call.
    """
    n = NDOF
    nc = NCONTACTS
    const_mass = CONST_MASS
    tol, K, h_min, budget = opts
    th, closed, last_reg, acc, cnt, rec_kind, rec_a0, rec_a1 = memo
    q1, v1, pN, pT, sl, reg, G0, G1 = out
    (M, Mi, Mp, wk, D, Gm, Ge, qm, qe, qs, vs, vf, y, Y, R, Rn, a0, a1, sq_smooth, sq_missed,
     sq_closing, sq_closed, sq_pN, sq_pT, sq_slip, sq_reg, cl, act, reg0, ia, fa, held, ea, vpre,
     Hm, He, wm, we, Dir, Wd, Uf, U, p, S, gx, MW, base, trow, lw) = ws
    force_lemke = lcp_ctl[0] != 0
    have_Mi = False
    nk = 0
    ...  # the steps (moreau.integrators._driver.loop_template)
    t = tk
    has_acc = th[2] != 0.0
    while True:
        cnt[0] += 1
        if cnt[0] > budget:
            return TOO_MANY
        H = min(th[1], t_bound - t)
        last = t + H >= t_bound - 1e-12 * max(1.0, abs(t_bound))
        smooth = False
        reject_missed = False
        jdone = 0
        for j in range(1, K + 1):
            same_last, have_Mi = sequence(
                mass_fn, forces_fn, contacts_fn, gaps_fn, HAS_GAPS, const_mass, have_Mi, par, mu,
                e, q, v, closed, last_reg, t, H, j, n, nc, M, Mi, wk, D, qm, qe, qs, vs, vf, v1,
                pN, pT, sl, reg, reg0, cl, act, ia, fa, Gm, Ge, G1, Hm, He, wm, we, ea, vpre, Dir,
                force_lemke, p, U, Wd, Uf, base, trow, lw, lcp_ctl, stats, cnt, Y, sq_smooth,
                sq_missed, sq_closing, sq_closed, sq_pN, sq_pT, sq_slip, sq_reg, lcp_step)
            jdone = j
            # after sequence j: go on, or decide
            if j == 1:
                smooth = sq_smooth[0] and same_last
                continue
            if j == 2 and (sq_missed[0] or sq_missed[1]) and H > h_min:
                reject_missed = True
                break
            smooth = smooth and sq_smooth[j - 1] and same_last
            if not smooth:
                break
        if reject_missed:
            # an impact crossed unseen: shrink until a midpoint lands in the contact
            cnt[2] += 1
            th[1] = max(h_min, 0.25 * H)
            continue
        smooth = smooth and jdone == K
        if smooth:
            err = extrapolated(Y, R, Rn, y, a0, a1, K, n, tol)
            kind = DENSE_SMOOTH
            order = K
            ir = K - 1
        else:
            err, order, kind = switch_error(Y, y, a0, a1, v, acc, has_acc, sq_closing, sq_reg,
                                            last_reg, H, n, nc, tol)
            ir = 1
        if err <= 1.0 or H <= h_min:
            if err > 1.0:
                cnt[4] += 1
            break
        cnt[2] += 1
        th[1] = max(h_min, H * max(0.1, 0.9 * err ** (-1.0 / (order + 1))))
    # -- the accepted macro step ------------------------------------------------------
    if smooth:
        cnt[3] += 1
    fac = 4.0 if err == 0.0 else min(4.0, max(0.1, 0.9 * err ** (-1.0 / (order + 1))))
    h_next = th[1] if last else max(h_min, H * fac)
    t1 = t_bound if last else t + H
    hk = H
    for i in range(n):
        q1[i] = y[i]
        v1[i] = y[n + i]
    if not (math.isfinite(err) and all_finite(q1, v1, n)):
        return NOT_FINITE
    th[1] = h_next
    nh = 0
    for c in range(nc):
        if sq_closed[ir, c]:
            held[nh] = c
            nh += 1
    if nh > 0:
        project_held(mass_fn, gaps_fn, contacts_fn, HAS_GAPS, const_mass, have_Mi, par, q1, v1,
                     t1, n, nh, held, M, Mi, Mp, wk, G1, gx, MW, S)
    if nc > 0:
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, G1)
        for c in range(nc):
            if -G1[c, 0] > stats[S_PEN]:
                stats[S_PEN] = -G1[c, 0]
    # the step's regime and forces, recorded at its end and, as every time-stepping scheme
    # records its start (no step has ended there), at the start of the first
    for c in range(nc):
        pN[c] = sq_pN[ir, c]
        pT[c] = sq_pT[ir, c]
        sl[c] = sq_slip[ir, c]
        reg[c] = sq_reg[ir, c]
        closed[c] = sq_closed[ir, c]
        last_reg[c] = sq_reg[ir, c]
    if record_initial:
        if nc > 0:
            gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q, t, G0)
        rec_kind[nk] = -1
        for i in range(n):
            rec_a0[nk, i] = 0.0
            rec_a1[nk, i] = 0.0
        nk += 1
    rec_kind[nk] = kind
    for i in range(n):
        rec_a0[nk, i] = a0[i]
        rec_a1[nk, i] = a1[i]
        acc[i] = (v1[i] - v[i]) / H
    nk += 1
    th[0] = t1
    th[2] = 0.0 if sq_closing[ir] else 1.0
    return OK


studer_loop = loop_template("studer_loop", globals(), "Studer extrapolation")
