"""The compiled time-discontinuous Galerkin loop: a template compiled once per model.

The same step as :class:`moreau.integrators.time_discontinuous_galerkin.TimeDiscontinuousGalerkin`
(see its module docstring for the derivation), on the functions of a
:class:`moreau.compiled.CompiledModel`. Every contact problem of a step (the
impulse at its left end and one per stage) goes through
:func:`_stage_problem`: the one-contact enumeration, or the friction LCP and
Lemke's method for several contacts (no warm start). Like
:func:`moreau.integrators._mj_kernels.mj_loop` the loop is a template:
:func:`moreau.integrators._loops.runner_for` compiles it in a namespace that
holds the model's functions and sizes as frozen globals.
"""

import math

import numpy as np
from numba import njit

from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, OK, PAINLEVE, S_DIRECT, S_LCP, S_PEN,  # noqa: F401
                          S_PIVOTS, S_PROJ, S_RES, SINGULAR, _classify, _invert_gj,
                          _invert_small, _lcp_size, _lcp_step, _one_contact, _residual, _stop_at,
                          grid_step, lcp_buffers, record_sample)

__all__ = ["tdg_loop"]


# inlined: a call would pass (and reference-count) its thirty arrays on every
# solve, which cost about 1 us a call, 50 times the solve of one contact
@njit(inline="always")
def _stage_problem(Hm, wm, Dir, vfree, e, vpre, n, na, nfa, ia, mu, force_lemke, p, pN, pT,
                   U, Wd, Uf, base, trow, lw, lcp_ctl, stats):
    """Impulse ``p`` along ``Dir`` (``M^-1 H^T``) making ``Hm v + wm`` obey Newton–Coulomb.

    ``e`` and ``vpre`` (per row of ``ia``) give Newton's law
    ``U_N + e min(vpre, 0) >= 0``; zero ``e`` is the velocity-level Signorini
    law of a stage. ``lw`` holds the buffers of Lemke's method
    (``Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol``, those of
    :func:`moreau.integrators._mj_kernels._lcp_step`). Writes ``p`` (stacked rows), ``pN``, ``pT`` (by contact)
    and ``U`` (the local velocities after the impulse). Returns a status of
    :mod:`moreau.integrators._mj_kernels`.
    """
    m = na + nfa
    need = False
    for r in range(m):
        acc = wm[r]
        for j in range(n):
            acc += Hm[r, j] * vfree[j]
        U[r] = acc
        p[r] = 0.0
    for r in range(na):
        i = ia[r]
        pN[i] = 0.0
        pT[i] = 0.0
        if U[r] + e[r] * min(vpre[r], 0.0) < 0.0:
            need = True
    if not need:
        # no contact needs to push: a zero normal impulse bounds the friction to zero
        return OK
    for r in range(m):
        for c in range(m):
            acc = 0.0
            for j in range(n):
                acc += Hm[r, j] * Dir[j, c]
            Wd[r, c] = acc
    stats[S_LCP] += 1.0
    if na == 1 and not force_lemke:
        stats[S_DIRECT] += 1.0
        i = ia[0]
        if nfa == 1:
            pn, pt, ok = _one_contact(Wd[0, 0], Wd[0, 1], Wd[1, 0], Wd[1, 1], U[0], U[1], mu[i],
                                      e[0], vpre[0])
            if not ok or _stop_at(lcp_ctl, Wd[0, 0], Wd[0, 1], mu[i], U[0], U[1], e[0], vpre[0]):
                return PAINLEVE
            res = _residual(Wd[0, 0], Wd[0, 1], Wd[1, 0], Wd[1, 1], U[0], U[1], mu[i], e[0],
                            vpre[0], pn, pt)
            p[1] = pt
        else:
            pn, pt, ok = _one_contact(Wd[0, 0], 0.0, 0.0, 0.0, U[0], 0.0, 0.0, e[0], vpre[0])
            if not ok:
                return PAINLEVE
            res = _residual(Wd[0, 0], 0.0, 0.0, 0.0, U[0], 0.0, 0.0, e[0], vpre[0], pn, 0.0)
        p[0] = pn
        pN[i] = pn
        pT[i] = pt
    else:
        for r in range(m):
            Uf[r] = U[r]
        for r in range(na):
            # Newton's law is Signorini's on the shifted free velocity
            Uf[r] += e[r] * min(vpre[r], 0.0)
        L = _lcp_size(na, ia, mu, base, trow)
        Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lw
        lst, piv, res, warm = _lcp_step(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow,
                                        Ml, ql, dl, zl, wl, rayl, work, iwork, lay,
                                        lcp_ctl, Ab, xb, idx, pcol, False)
        if lst != 0:
            return LCP_HANDBACK
        stats[S_PIVOTS] += piv
    if res > stats[S_RES]:
        stats[S_RES] = res
    for r in range(m):
        acc = U[r]
        for c in range(m):
            acc += Wd[r, c] * p[c]
        U[r] = acc
    return OK


@njit(cache=True)
def _solve_small(S, x, m):
    """Solve ``S y = x`` in place (``x`` becomes ``y``) by elimination with partial pivoting."""
    for c in range(m):
        piv = c
        for r in range(c + 1, m):
            if abs(S[r, c]) > abs(S[piv, c]):
                piv = r
        if S[piv, c] == 0.0:
            return False
        if piv != c:
            for j in range(m):
                S[c, j], S[piv, j] = S[piv, j], S[c, j]
            x[c], x[piv] = x[piv], x[c]
        for r in range(c + 1, m):
            f = S[r, c] / S[c, c]
            for j in range(c, m):
                S[r, j] -= f * S[c, j]
            x[r] -= f * x[c]
    for c in range(m - 1, -1, -1):
        acc = x[c]
        for j in range(c + 1, m):
            acc -= S[c, j] * x[j]
        x[c] = acc / S[c, c]
    return True


def tdg_loop(par, mu, e, t0, h, t_bound, k0, nmax, q, v, closed, save_every, record_initial,
             cs, a_st, b_st, projection, lcp_ctl, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT,
             rec_slip, rec_gap, stats):
    """Run up to ``nmax`` time-discontinuous Galerkin steps of a compiled model in one call.

    Arguments, statuses and outputs as :func:`moreau.integrators._mj_kernels.mj_loop`
    (no ``theta``), plus the tableau (``cs`` nodes, ``a_st`` stage matrix,
    ``b_st`` weights) and ``projection`` (bool). On :data:`LCP_HANDBACK` or
    :data:`PAINLEVE` the state is the start of the step that failed; the
    caller takes that step in Python.
    """
    n = NDOF  # noqa: F821  (the model's namespace)
    nc = NCONTACTS  # noqa: F821
    const_mass = CONST_MASS  # noqa: F821
    force_lemke = lcp_ctl[0] != 0
    s = cs.shape[0]
    M = np.zeros((n, n))
    Mi = np.empty((n, n))
    Mi0 = np.empty((n, n))
    wk = np.empty((n, n))
    D = np.zeros((n, 1 + 2 * n))
    Qs = np.zeros((s, n))
    Vs = np.zeros((s, n))
    As = np.zeros((s, n))
    ncm = max(nc, 1)
    mrows = 2 * ncm
    Dirs = np.zeros((s, n, mrows))
    Lam = np.zeros((s, mrows))
    v0 = np.empty(n)
    vi = np.empty(n)
    qi = np.empty(n)
    G0 = np.zeros((ncm, 3 + 2 * n))
    Gi = np.zeros((ncm, 3 + 2 * n))
    vN0 = np.zeros(ncm)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    sN = np.zeros(ncm)
    sT = np.zeros(ncm)
    slip = np.zeros(ncm)
    reg = np.zeros(ncm, dtype=np.int64)
    ia = np.zeros(ncm, dtype=np.int64)
    fa = np.zeros(ncm, dtype=np.int64)
    held = np.zeros(ncm, dtype=np.int64)
    ez = np.zeros(ncm)
    ea = np.zeros(ncm)
    H = np.zeros((mrows, n))
    w = np.zeros(mrows)
    Wd = np.zeros((mrows, mrows))
    Uf = np.zeros(mrows)
    U = np.zeros(mrows)
    p = np.zeros(mrows)
    Ptot = np.zeros(mrows)
    S = np.zeros((ncm, ncm))
    gx = np.zeros(ncm)
    MW = np.zeros((n, ncm))
    base = np.zeros(ncm, dtype=np.int64)
    trow = np.zeros(ncm, dtype=np.int64)
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lcp_buffers(ncm)
    lw = (Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol)

    have_Mi = False
    nrec = 0
    k = k0
    status = OK
    to_save = save_every - k0 % save_every
    while k - k0 < nmax:
        tk, t1, hk, last = grid_step(t0, k, h, t_bound)
        if tk >= t_bound:
            break
        if not (const_mass and have_Mi):
            mass_fn(par, q, M)  # noqa: F821
            ok = _invert_small(M, Mi0, n) if n <= 3 else _invert_gj(M, Mi0, wk, n)
            if not ok:
                status = SINGULAR
                break
            have_Mi = True
        for j in range(n):
            v0[j] = v[j]
        na = np.int64(0)  # not a literal: see _mj_kernels.mj_loop
        nfa = 0
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
        if nc > 0:
            contacts_fn(par, q, tk, G0, False, True)  # noqa: F821
            if HAS_GAPS:  # noqa: F821
                gaps_fn(par, q, tk, G0)  # noqa: F821
            else:
                contacts_fn(par, q, tk, G0, True, False)  # noqa: F821
            for i in range(nc):
                acc = G0[i, 1]
                for j in range(n):
                    acc += G0[i, 3 + j] * v[j]
                vN0[i] = acc
                if G0[i, 0] + 0.5 * hk * acc <= 0.0 or closed[i]:
                    ia[na] = i
                    na += 1
                    if mu[i] > 0.0:
                        fa[nfa] = i
                        nfa += 1
        m = na + nfa
        if na > 0:
            # the impulsive part at t_n+: Newton's law on the pre-step velocities
            for r in range(na):
                i = ia[r]
                for j in range(n):
                    H[r, j] = G0[i, 3 + j]
                w[r] = G0[i, 1]
                ea[r] = e[i]
                ez[r] = vN0[i]
            for r in range(nfa):
                i = fa[r]
                for j in range(n):
                    H[na + r, j] = G0[i, 3 + n + j]
                w[na + r] = G0[i, 2]
            for c in range(m):
                for i in range(n):
                    acc = 0.0
                    for j in range(n):
                        acc += Mi0[i, j] * H[c, j]
                    Dirs[0, i, c] = acc
            st = _stage_problem(H, w, Dirs[0], v0, ea, ez, n, na, nfa, ia, mu, force_lemke, p,
                                sN, sT, U, Wd, Uf, base, trow, lw, lcp_ctl, stats)
            if st != OK:
                status = st
                break
            for c in range(m):
                Ptot[c] = p[c]
                for i in range(n):
                    v0[i] += Dirs[0, i, c] * p[c]
            for r in range(na):
                ea[r] = 0.0
                ez[r] = 0.0
        # the non-impulsive part: half-explicit Runge-Kutta on the Lobatto nodes
        forces_fn(par, q, v0, tk, D, False)  # noqa: F821
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Mi0[i, j] * D[j, 0]
            As[0, i] = acc
            Qs[0, i] = q[i]
            Vs[0, i] = v0[i]
        failed = False
        for st_i in range(1, s + 1):
            fin = st_i == s
            ti = t1 if fin else tk + cs[st_i] * hk
            for j in range(n):
                accq = q[j]
                accv = v0[j]
                for l in range(st_i):
                    cf = b_st[l] if fin else a_st[st_i, l]
                    accq += hk * cf * Vs[l, j]
                    accv += hk * cf * As[l, j]
                    if na > 0 and l < st_i - 1:
                        for c in range(m):
                            accv += hk * cf * Dirs[l, j, c] * Lam[l, c]
                qi[j] = accq
                vi[j] = accv
            if na > 0:
                contacts_fn(par, qi, ti, Gi, False, True)  # noqa: F821
                for r in range(na):
                    i = ia[r]
                    for j in range(n):
                        H[r, j] = Gi[i, 3 + j]
                    w[r] = Gi[i, 1]
                for r in range(nfa):
                    i = fa[r]
                    for j in range(n):
                        H[na + r, j] = Gi[i, 3 + n + j]
                    w[na + r] = Gi[i, 2]
                # the force of stage st_i - 1 is fixed by the constraint at stage st_i
                kc = hk * (b_st[st_i - 1] if fin else a_st[st_i, st_i - 1])
                st = _stage_problem(H, w, Dirs[st_i - 1], vi, ea, ez, n, na, nfa, ia, mu,
                                    force_lemke, p, sN, sT, U, Wd, Uf, base, trow, lw, lcp_ctl,
                                    stats)
                if st != OK:
                    status = st
                    failed = True
                    break
                for c in range(m):
                    Lam[st_i - 1, c] = p[c] / kc
                    for j in range(n):
                        vi[j] += Dirs[st_i - 1, j, c] * p[c]
                if fin:
                    for r in range(nfa):
                        slip[fa[r]] = U[na + r]
            if fin:
                break
            if not const_mass:
                mass_fn(par, qi, M)  # noqa: F821
                ok = _invert_small(M, Mi, n) if n <= 3 else _invert_gj(M, Mi, wk, n)
                if not ok:
                    status = SINGULAR
                    failed = True
                    break
            else:
                for i in range(n):
                    for j in range(n):
                        Mi[i, j] = Mi0[i, j]
            forces_fn(par, qi, vi, ti, D, False)  # noqa: F821
            for i in range(n):
                acc = 0.0
                for j in range(n):
                    acc += Mi[i, j] * D[j, 0]
                As[st_i, i] = acc
                Qs[st_i, i] = qi[i]
                Vs[st_i, i] = vi[i]
            if na > 0:
                for c in range(m):
                    for i in range(n):
                        acc = 0.0
                        for j in range(n):
                            acc += Mi[i, j] * H[c, j]
                        Dirs[st_i, i, c] = acc
        if failed:
            break
        finite = True
        for i in range(n):
            if not (math.isfinite(qi[i]) and math.isfinite(vi[i])):
                finite = False
        if not finite:
            status = NUMERICAL
            break
        nh = 0
        if na > 0:
            for c in range(m):
                acc = Ptot[c]
                for l in range(s):
                    acc += hk * b_st[l] * Lam[l, c]
                Ptot[c] = acc
            for r in range(na):
                pN[ia[r]] = Ptot[r]
                if Lam[s - 1, r] > 0.0:
                    held[nh] = ia[r]
                    nh += 1
            for r in range(nfa):
                pT[fa[r]] = Ptot[na + r]
        if projection and nh > 0:
            # Newton steps onto g = 0 for the held contacts, in the metric of M(q_{n+1})
            # (a constant mass matrix is inverted once, in Mi0)
            if const_mass:
                for i in range(n):
                    for j in range(n):
                        Mi[i, j] = Mi0[i, j]
            else:
                mass_fn(par, qi, M)  # noqa: F821
                ok = _invert_small(M, Mi, n) if n <= 3 else _invert_gj(M, Mi, wk, n)
                if not ok:
                    status = SINGULAR
                    break
            qmax = 1.0
            for j in range(n):
                qmax = max(qmax, abs(qi[j]))
            for it in range(4):
                contacts_fn(par, qi, t1, Gi, False, True)  # noqa: F821
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, qi, t1, Gi)  # noqa: F821
                else:
                    contacts_fn(par, qi, t1, Gi, True, False)  # noqa: F821
                gm = 0.0
                for r in range(nh):
                    gx[r] = Gi[held[r], 0]
                    gm = max(gm, abs(gx[r]))
                if gm == 0.0:
                    break
                for c in range(nh):
                    for i in range(n):
                        acc = 0.0
                        for j in range(n):
                            acc += Mi[i, j] * Gi[held[c], 3 + j]
                        MW[i, c] = acc
                for r in range(nh):
                    for c in range(nh):
                        acc = 0.0
                        for j in range(n):
                            acc += Gi[held[r], 3 + j] * MW[j, c]
                        S[r, c] = acc
                if not _solve_small(S, gx, nh):
                    break
                dmax = 0.0
                for j in range(n):
                    acc = 0.0
                    for c in range(nh):
                        acc += MW[j, c] * gx[c]
                    qi[j] -= acc
                    dmax = max(dmax, abs(acc))
                stats[S_PROJ] += 1.0
                if dmax <= 4e-16 * qmax:
                    break
        if not const_mass:
            have_Mi = False
        if nc > 0:
            if HAS_GAPS:  # noqa: F821
                gaps_fn(par, qi, t1, Gi)  # noqa: F821
            else:
                contacts_fn(par, qi, t1, Gi, True, False)  # noqa: F821
            for i in range(nc):
                if -Gi[i, 0] > stats[S_PEN]:
                    stats[S_PEN] = -Gi[i, 0]
                reg[i] = _classify(pN[i], pT[i], mu[i])
        if record_initial:
            # the first step's regime and forces, as every time-stepping scheme records its
            # start (no step has ended there)
            record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                          tk, q, v, reg, pN, pT, hk, slip, G0, n, nc)
            nrec += 1
            record_initial = False
        for i in range(nc):
            closed[i] = pN[i] > 0.0
        for j in range(n):
            q[j] = qi[j]
            v[j] = vi[j]
        k += 1
        to_save -= 1
        if to_save == 0:
            to_save = save_every
        if to_save == save_every or last:
            record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec,
                          t1, q, v, reg, pN, pT, hk, slip, Gi, n, nc)
            nrec += 1
        if last:
            break
    return status, k, nrec
