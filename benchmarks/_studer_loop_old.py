"""The compiled loop of Studer's step-size adjustment and extrapolation: a template per model.

The same macro step as
:meth:`moreau.integrators.studer_extrapolation.StuderExtrapolation._generic_step`
(see that module's docstring for the method), on the functions of a
:class:`moreau.compiled.CompiledModel`: the Moreau midpoint base steps, the
sequences of ``1 .. K`` base steps, the Aitken–Neville table in smooth
phases, step halving and the switch location elsewhere, the projection of
the accepted state onto the closed contacts. Every contact problem goes
through :func:`moreau.integrators._tdg_kernels._stage_problem` (the rows
that measure the velocity are those of the step's end, the impulse acts
along the midpoint's). Like the other loops it is a template:
:func:`moreau.integrators._loops.runner_for` compiles it in a namespace that
holds the model's functions and sizes as frozen globals.
"""

import math

import numpy as np

from moreau.integrators._mj_kernels import (OK, S_PEN, SINGULAR, _classify, _invert_gj, _invert_small, lcp_buffers,
                          record_sample)
from moreau.integrators._step_parts import gap_block, held_gaps, move_back
from moreau.integrators._tdg_kernels import _solve_small, _stage_problem

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


def studer_loop(par, mu, e, t_bound, tol, K, h_min, budget, nmax, th, q, v, closed, last_reg,
                acc, record_initial, lcp_ctl, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT,
                rec_slip, rec_gap, rec_kind, rec_a0, rec_a1, stats, cnt):
    """Run up to ``nmax`` accepted macro steps of a compiled model in one call.

    ``th = [t, h, has_acc]`` (time, next macro step, whether ``acc`` holds the
    last step's acceleration), ``q``, ``v``, ``closed`` (contacts carrying a
    force), ``last_reg`` (regimes the last step ended in) and ``acc`` are the
    state, updated in place. ``budget`` bounds the macro steps tried. One
    sample is recorded per accepted step (and the start with
    ``record_initial``), with the data of the step's dense output in
    ``rec_kind, rec_a0, rec_a1`` (:data:`DENSE_SMOOTH`: the accelerations at
    the step's ends extrapolated as the state is; :data:`DENSE_SWITCH`: those
    of the two-step sequence; :data:`DENSE_IMPACT`: the last smooth
    acceleration in both; -1 on the start's sample). Returns
    ``(status, accepted, samples)``. On
    ``LCP_HANDBACK`` or ``PAINLEVE`` (:mod:`moreau.integrators._mj_kernels`) the
    state is the start of the macro step that failed; the caller takes that
    step in Python.
    """
    n = NDOF  # noqa: F821  (the model's namespace)
    nc = NCONTACTS  # noqa: F821
    const_mass = CONST_MASS  # noqa: F821
    force_lemke = lcp_ctl[0] != 0
    n2 = 2 * n
    # a row of the table: q, v and the accelerations at the start and the end (dense output)
    n4 = 4 * n
    ncm = max(nc, 1)
    mrows = 2 * ncm
    M = np.zeros((n, n))
    Mi = np.empty((n, n))
    Mp = np.empty((n, n))
    wk = np.empty((n, n))
    D = np.zeros((n, 1 + 2 * n))
    Gm = np.zeros((ncm, 3 + 2 * n))
    Ge = np.zeros((ncm, 3 + 2 * n))
    G1 = np.zeros((ncm, 3 + 2 * n))
    qm = np.empty(n)
    qe = np.empty(n)
    qs = np.empty(n)
    vs = np.empty(n)
    vf = np.empty(n)
    q1 = np.empty(n)
    v1 = np.empty(n)
    y = np.empty(n2)
    Y = np.zeros((K, n4))
    R = np.zeros((K, n4))
    Rn = np.zeros((K, n4))
    a0 = np.zeros(n)
    a1 = np.zeros(n)
    sq_smooth = np.zeros(K, dtype=np.bool_)
    sq_missed = np.zeros(K, dtype=np.bool_)
    sq_closing = np.zeros(K, dtype=np.bool_)
    sq_closed = np.zeros((K, ncm), dtype=np.bool_)
    sq_pN = np.zeros((K, ncm))
    sq_pT = np.zeros((K, ncm))
    sq_slip = np.zeros((K, ncm))
    sq_reg = np.zeros((K, ncm), dtype=np.int64)
    cl = np.zeros(ncm, dtype=np.bool_)
    act = np.zeros(ncm, dtype=np.bool_)
    reg = np.zeros(ncm, dtype=np.int64)
    reg0 = np.zeros(ncm, dtype=np.int64)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    sl = np.zeros(ncm)
    ia = np.zeros(ncm, dtype=np.int64)
    fa = np.zeros(ncm, dtype=np.int64)
    held = np.zeros(ncm, dtype=np.int64)
    ea = np.zeros(ncm)
    vpre = np.zeros(ncm)
    Hm = np.zeros((mrows, n))
    He = np.zeros((mrows, n))
    we = np.zeros(mrows)
    Dir = np.zeros((n, mrows))
    Wd = np.zeros((mrows, mrows))
    Uf = np.zeros(mrows)
    U = np.zeros(mrows)
    p = np.zeros(mrows)
    S = np.zeros((ncm, ncm))
    gx = np.zeros(ncm)
    MW = np.zeros((n, ncm))
    base = np.zeros(ncm, dtype=np.int64)
    trow = np.zeros(ncm, dtype=np.int64)
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lcp_buffers(ncm)
    lw = (Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol)

    t = th[0]
    h = th[1]
    has_acc = th[2] != 0.0
    have_Mi = False
    nrec = 0
    nacc = 0
    kind = DENSE_SWITCH
    status = OK
    while nacc < nmax and status == OK:
        # -- one macro step: tried until its error estimate allows ---------------------
        accepted = False
        while True:
            cnt[0] += 1
            if cnt[0] > budget:
                status = TOO_MANY
                break
            H = min(h, t_bound - t)
            last = t + H >= t_bound - 1e-12 * max(1.0, abs(t_bound))
            smooth = False
            reject_missed = False
            jdone = 0
            for j in range(1, K + 1):
                # -- sequence j: j base steps of H / j -----------------------------
                hb = H / j
                for k in range(n):
                    qs[k] = q[k]
                    vs[k] = v[k]
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
                    for k in range(n):
                        qm[k] = qs[k] + 0.5 * hb * vs[k]
                    if not (const_mass and have_Mi):
                        mass_fn(par, qm, M)  # noqa: F821
                        ok = _invert_small(M, Mi, n) if n <= 3 else _invert_gj(M, Mi, wk, n)
                        if not ok:
                            status = SINGULAR
                            break
                        have_Mi = True
                    forces_fn(par, qm, vs, tm, D, False)  # noqa: F821
                    for k in range(n):
                        a = 0.0
                        for l in range(n):
                            a += Mi[k, l] * D[l, 0]
                        vf[k] = vs[k] + hb * a
                        v1[k] = vf[k]
                    na = np.int64(0)  # not a literal: see _mj_kernels.mj_loop
                    nfa = 0
                    for c in range(nc):
                        pN[c] = 0.0
                        pT[c] = 0.0
                        sl[c] = 0.0
                        act[c] = False
                    if nc > 0:
                        if HAS_GAPS:  # noqa: F821
                            gaps_fn(par, qm, tm, Gm)  # noqa: F821
                        else:
                            contacts_fn(par, qm, tm, Gm, True, False)  # noqa: F821
                        for c in range(nc):
                            # a contact that carried a force stays in the index set
                            # while it does, whatever its midpoint gap
                            if cl[c] or Gm[c, 0] <= 0.0:
                                act[c] = True
                                ia[na] = c
                                na += 1
                                if mu[c] > 0.0:
                                    fa[nfa] = c
                                    nfa += 1
                    if na > 0:
                        m = na + nfa
                        contacts_fn(par, qm, tm, Gm, False, True)  # noqa: F821
                        for k in range(n):
                            qe[k] = qs[k] + hb * vs[k]
                        contacts_fn(par, qe, tb + hb, Ge, False, True)  # noqa: F821
                        for r in range(na):
                            c = ia[r]
                            a = Gm[c, 1]
                            for k in range(n):
                                a += Gm[c, 3 + k] * vs[k]
                                Hm[r, k] = Gm[c, 3 + k]
                                He[r, k] = Ge[c, 3 + k]
                            vpre[r] = a
                            we[r] = Ge[c, 1]
                            ea[r] = 0.0 if cl[c] else e[c]
                        for r in range(nfa):
                            c = fa[r]
                            for k in range(n):
                                Hm[na + r, k] = Gm[c, 3 + n + k]
                                He[na + r, k] = Ge[c, 3 + n + k]
                            we[na + r] = Ge[c, 2]
                        for cc in range(m):
                            for k in range(n):
                                a = 0.0
                                for l in range(n):
                                    a += Mi[k, l] * Hm[cc, l]
                                Dir[k, cc] = a
                        st = _stage_problem(He, we, Dir, vf, ea, vpre, n, na, nfa, ia, mu,
                                            force_lemke, p, pN, pT, U, Wd, Uf, base, trow, lw,
                                            lcp_ctl, stats)
                        if st != OK:
                            status = st
                            break
                        for k in range(n):
                            a = vf[k]
                            for cc in range(m):
                                a += Dir[k, cc] * p[cc]
                            v1[k] = a
                        for r in range(nfa):
                            sl[fa[r]] = U[na + r]
                    # the mean accelerations of the first and the last base step: at
                    # the ends of the macro step to O(hb), and extrapolated with the state
                    if ib == 0:
                        for k in range(n):
                            Y[j - 1, n2 + k] = (v1[k] - vs[k]) / hb
                    if ib == j - 1:
                        for k in range(n):
                            Y[j - 1, n2 + n + k] = (v1[k] - vs[k]) / hb
                    for k in range(n):
                        qs[k] = qm[k] + 0.5 * hb * v1[k]
                        vs[k] = v1[k]
                    if not const_mass:
                        have_Mi = False
                    switch = False
                    miss = False
                    if na < nc:
                        # only a contact open at the midpoint can be crossed unseen
                        if HAS_GAPS:  # noqa: F821
                            gaps_fn(par, qs, tb + hb, G1)  # noqa: F821
                        else:
                            contacts_fn(par, qs, tb + hb, G1, True, False)  # noqa: F821
                        for c in range(nc):
                            if G1[c, 0] < 0.0 and not act[c]:
                                miss = True
                    for c in range(nc):
                        if pN[c] > 0.0 and not cl[c]:
                            switch = True
                        reg[c] = _classify(pN[c], pT[c], mu[c])
                        cl[c] = pN[c] > 0.0
                        sq_pN[j - 1, c] += pN[c]
                        sq_pT[j - 1, c] += pT[c]
                    if ib == 0:
                        for c in range(nc):
                            reg0[c] = reg[c]
                    same = True
                    for c in range(nc):
                        if reg[c] != reg0[c]:
                            same = False
                    s_missed = s_missed or miss
                    s_closing = s_closing or switch
                    s_smooth = s_smooth and not switch and not miss and same
                if status != OK:
                    break
                for k in range(n):
                    Y[j - 1, k] = qs[k]
                    Y[j - 1, n + k] = vs[k]
                sq_smooth[j - 1] = s_smooth
                sq_missed[j - 1] = s_missed
                sq_closing[j - 1] = s_closing
                for c in range(nc):
                    sq_closed[j - 1, c] = cl[c]
                    sq_slip[j - 1, c] = sl[c]
                    sq_reg[j - 1, c] = reg[c]
                jdone = j
                # -- after the sequence: go on, or decide ---------------------------
                same_last = True
                for c in range(nc):
                    if reg[c] != last_reg[c]:
                        same_last = False
                if j == 1:
                    smooth = s_smooth and same_last
                    continue
                if j == 2:
                    if (sq_missed[0] or sq_missed[1]) and H > h_min:
                        reject_missed = True
                        break
                smooth = smooth and s_smooth and same_last
                if not smooth:
                    break
            if status != OK:
                break
            if reject_missed:
                # an impact crossed unseen: shrink until a midpoint lands in the contact
                cnt[2] += 1
                h = max(h_min, 0.25 * H)
                continue
            smooth = smooth and jdone == K
            if smooth:
                # Aitken-Neville on n_j = j, for an error expansion in every power of h
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
                for k in range(n):
                    a0[k] = R[K - 1, n2 + k]
                    a1[k] = R[K - 1, n2 + n + k]
                kind = DENSE_SMOOTH
                order = K
                ir = K - 1
            else:
                err = 0.0
                for d in range(n2):
                    y[d] = Y[1, d]
                    err = max(err, abs(y[d] - Y[0, d]) / (tol * (1.0 + abs(y[d]))))
                order = 1
                ir = 1
                if sq_closing[1]:
                    # an impulse somewhere in the step: the dense output joins the smooth
                    # motions before and after it (the last step's acceleration in both)
                    kind = DENSE_IMPACT
                    for k in range(n):
                        a0[k] = acc[k] if has_acc else 0.0
                        a1[k] = a0[k]
                else:
                    kind = DENSE_SWITCH
                    for k in range(n):
                        a0[k] = Y[1, n2 + k]
                        a1[k] = Y[1, n2 + n + k]
                if has_acc and not (sq_closing[0] or sq_closing[1]):
                    changed = False
                    for c in range(nc):
                        if sq_reg[0, c] != last_reg[c]:
                            changed = True
                    if changed:
                        # a switch in the first base step of every sequence: located by
                        # the jump of the acceleration (an error |da| H on the velocities)
                        e_sw = 0.0
                        for k in range(n):
                            da = abs((Y[0, n + k] - v[k]) / H - acc[k])
                            e_sw = max(e_sw, da * H / (tol * (1.0 + abs(y[n + k]))))
                        if e_sw > err:
                            err = e_sw
                            order = 0
            if err <= 1.0 or H <= h_min:
                if err > 1.0:
                    cnt[4] += 1
                accepted = True
                break
            cnt[2] += 1
            h = max(h_min, H * max(0.1, 0.9 * err ** (-1.0 / (order + 1))))
        if not accepted:
            break
        # -- the accepted macro step ------------------------------------------------
        if smooth:
            cnt[3] += 1
        fac = 4.0 if err == 0.0 else min(4.0, max(0.1, 0.9 * err ** (-1.0 / (order + 1))))
        h_next = h if last else max(h_min, H * fac)
        t1 = t_bound if last else t + H
        finite = math.isfinite(err)
        for k in range(n):
            q1[k] = y[k]
            v1[k] = y[n + k]
            if not (math.isfinite(q1[k]) and math.isfinite(v1[k])):
                finite = False
        if not finite:
            status = NOT_FINITE
            break
        h = h_next
        nh = 0
        for c in range(nc):
            if sq_closed[ir, c]:
                held[nh] = c
                nh += 1
        if nh > 0:
            # positions onto g = 0 and velocities onto WN v + wN = 0, in the metric of M
            if const_mass and have_Mi:
                for k in range(n):
                    for l in range(n):
                        Mp[k, l] = Mi[k, l]
            else:
                mass_fn(par, q1, M)  # noqa: F821
                ok = _invert_small(M, Mp, n) if n <= 3 else _invert_gj(M, Mp, wk, n)
                if not ok:
                    status = SINGULAR
                    break
            for it in range(4):
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, q1, t1, G1)  # noqa: F821
                else:
                    contacts_fn(par, q1, t1, G1, True, False)  # noqa: F821
                gm = held_gaps(G1, held, nh, gx)
                if gm == 0.0:
                    break
                contacts_fn(par, q1, t1, G1, False, True)  # noqa: F821
                gap_block(G1, held, nh, Mp, MW, S, n)
                if not _solve_small(S, gx, nh):
                    break
                dmax = move_back(MW, gx, q1, nh, n)
                qmax = 1.0
                for k in range(n):
                    qmax = max(qmax, abs(q1[k]))
                if dmax <= 4e-16 * qmax:
                    break
            if not const_mass:
                mass_fn(par, q1, M)  # noqa: F821
                ok = _invert_small(M, Mp, n) if n <= 3 else _invert_gj(M, Mp, wk, n)
                if not ok:
                    status = SINGULAR
                    break
            contacts_fn(par, q1, t1, G1, False, True)  # noqa: F821
            gap_block(G1, held, nh, Mp, MW, S, n)
            for r in range(nh):
                a = G1[held[r], 1]
                for k in range(n):
                    a += G1[held[r], 3 + k] * v1[k]
                gx[r] = a
            if _solve_small(S, gx, nh):
                move_back(MW, gx, v1, nh, n)
        if nc > 0:
            if HAS_GAPS:  # noqa: F821
                gaps_fn(par, q1, t1, G1)  # noqa: F821
            else:
                contacts_fn(par, q1, t1, G1, True, False)  # noqa: F821
            for c in range(nc):
                if -G1[c, 0] > stats[S_PEN]:
                    stats[S_PEN] = -G1[c, 0]
        # the step's regime and forces, recorded at its end and, as every time-stepping
        # scheme records its start (no step has ended there), at the start of the first
        for c in range(nc):
            pN[c] = sq_pN[ir, c]
            pT[c] = sq_pT[ir, c]
            sl[c] = sq_slip[ir, c]
            reg[c] = sq_reg[ir, c]
        if record_initial:
            if nc > 0:
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, q, t, Gm)  # noqa: F821
                else:
                    contacts_fn(par, q, t, Gm, True, False)  # noqa: F821
            record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                          t, q, v, reg, pN, pT, H, sl, Gm, n, nc)
            rec_kind[nrec] = -1
            for k in range(n):
                rec_a0[nrec, k] = 0.0
                rec_a1[nrec, k] = 0.0
            nrec += 1
            record_initial = False
        record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                      t1, q1, v1, reg, pN, pT, H, sl, G1, n, nc)
        rec_kind[nrec] = kind
        for k in range(n):
            rec_a0[nrec, k] = a0[k]
            rec_a1[nrec, k] = a1[k]
        nrec += 1
        has_acc = not sq_closing[ir]
        for k in range(n):
            acc[k] = (v1[k] - v[k]) / H
            q[k] = q1[k]
            v[k] = v1[k]
        for c in range(nc):
            closed[c] = sq_closed[ir, c]
            last_reg[c] = sq_reg[ir, c]
        t = t1
        nacc += 1
        if last:
            break
    th[0] = t
    th[1] = h
    th[2] = 1.0 if has_acc else 0.0
    return status, nacc, nrec
