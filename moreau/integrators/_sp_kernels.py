"""The compiled Schatzman–Paoli loop: a template compiled once per model.

The same step as :class:`moreau.integrators.schatzman_paoli.SchatzmanPaoli`
(see its module docstring for the derivation), on the functions of a
:class:`moreau.compiled.CompiledModel`, with the contact problem of
:mod:`moreau.integrators._mj_kernels` (the one-contact enumeration, Lemke
for several contacts; no warm start). Like
:func:`moreau.integrators._mj_kernels.mj_loop` it is a template:
:func:`moreau.integrators._loops.runner_for` compiles it in a namespace that
holds the model's functions and sizes as frozen globals.
"""

import math

import numpy as np

from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, OK, PAINLEVE, S_DIRECT, S_LCP, S_PEN,  # noqa: F401
                          S_PIVOTS, S_RES, SINGULAR, _classify, _invert_gj, _invert_small,
                          _lcp_size, _lcp_step, _lcp_step_unused, _one_contact, _residual, _stop_at,
                          lcp_buffers, record_sample)
from ._mj_kernels import SHARED_INDIRECT  # noqa: F401  (read by moreau.integrators._loops)

__all__ = ["sp_loop"]


def sp_loop(par, mu, e, t0, h, t_bound, k0, nmax, q, v, vv, closed, save_every, record_initial,
            lcp_ctl, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, stats):
    """Run up to ``nmax`` Schatzman–Paoli steps of a compiled model in one call.

    Arguments, statuses and outputs as :func:`moreau.integrators._mj_kernels.mj_loop`
    (no ``theta``, no projection), plus ``vv`` (float64[n]), the Verlet
    velocity that carries the recursion, overwritten like ``q`` and ``v``.
    On :data:`LCP_HANDBACK` or :data:`PAINLEVE` the state is the start of the
    step that failed; the caller takes that step in Python.
    """
    n = NDOF  # noqa: F821  (the model's namespace)
    nc = NCONTACTS  # noqa: F821
    const_mass = CONST_MASS  # noqa: F821
    force_lemke = lcp_ctl[0] != 0
    M = np.zeros((n, n))
    Mi = np.empty((n, n))
    wk = np.empty((n, n))
    D = np.zeros((n, 1 + 2 * n))
    a = np.empty(n)
    up = np.empty(n)
    um = np.empty(n)
    vh = np.empty(n)
    dvc = np.zeros(n)
    q1 = np.empty(n)
    ncm = max(nc, 1)
    mrows = 2 * ncm
    G0 = np.zeros((ncm, 3 + 2 * n))
    G1 = np.zeros((ncm, 3 + 2 * n))
    Gq = np.zeros((ncm, 3 + 2 * n))
    UN = np.zeros(ncm)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    reg = np.zeros(ncm, dtype=np.int64)
    ia = np.zeros(ncm, dtype=np.int64)
    fa = np.zeros(ncm, dtype=np.int64)
    H = np.zeros((mrows, n))
    MiHT = np.zeros((n, mrows))
    Wd = np.zeros((mrows, mrows))
    Uf = np.zeros(mrows)
    p = np.zeros(mrows)
    base = np.zeros(ncm, dtype=np.int64)
    trow = np.zeros(ncm, dtype=np.int64)
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lcp_buffers(ncm)

    have_Mi = False
    nrec = 0
    k = k0
    status = OK
    to_save = save_every - k0 % save_every
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
        if not (const_mass and have_Mi):
            mass_fn(par, q, M)  # noqa: F821
            if n <= 3:
                ok = _invert_small(M, Mi, n)
            else:
                ok = _invert_gj(M, Mi, wk, n)
            if not ok:
                status = SINGULAR
                break
            have_Mi = True
        forces_fn(par, q, v, tk, D, False)  # noqa: F821
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Mi[i, j] * D[j, 0]
            a[i] = acc
            up[i] = vv[i] + 0.5 * hk * acc
            um[i] = vv[i] - 0.5 * hk * acc
            vh[i] = up[i]
            dvc[i] = 0.0
        na = np.int64(0)  # not a literal: see _mj_kernels.mj_loop
        nfa = 0
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
        if nc > 0:
            if k == k0:
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, q, tk, G0)  # noqa: F821
                else:
                    contacts_fn(par, q, tk, G0, True, False)  # noqa: F821
            contacts_fn(par, q, tk + 0.5 * hk, G1, False, True)  # noqa: F821
            for i in range(nc):
                sp = G1[i, 1]
                sm = G1[i, 1]
                for j in range(n):
                    sp += G1[i, 3 + j] * up[j]
                    sm += G1[i, 3 + j] * um[j]
                UN[i] = (1.0 + e[i]) * G0[i, 0] / hk + sp - e[i] * sm
                if UN[i] <= 0.0 or closed[i]:
                    ia[na] = i
                    na += 1
                    if mu[i] > 0.0:
                        fa[nfa] = i
                        nfa += 1
        if na == 1 and not force_lemke:
            i = ia[0]
            for j in range(n):
                acc = 0.0
                acc2 = 0.0
                for l in range(n):
                    acc += Mi[j, l] * G1[i, 3 + l]
                    acc2 += Mi[j, l] * G1[i, 3 + n + l]
                MiHT[j, 0] = acc
                MiHT[j, 1] = acc2
            Wnn = 0.0
            for j in range(n):
                Wnn += G1[i, 3 + j] * MiHT[j, 0]
            uN = UN[i]
            stats[S_LCP] += 1.0
            stats[S_DIRECT] += 1.0
            if nfa == 1:
                Wnt = 0.0
                Wtn = 0.0
                Wtt = 0.0
                uT = G1[i, 2]
                for j in range(n):
                    Wnt += G1[i, 3 + j] * MiHT[j, 1]
                    Wtn += G1[i, 3 + n + j] * MiHT[j, 0]
                    Wtt += G1[i, 3 + n + j] * MiHT[j, 1]
                    uT += G1[i, 3 + n + j] * up[j]
                pn, pt, ok = _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu[i], 0.0, 0.0)
                if not ok or _stop_at(lcp_ctl, Wnn, Wnt, mu[i], uN, uT, 0.0, 0.0):
                    status = PAINLEVE
                    break
                res = _residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu[i], 0.0, 0.0, pn, pt)
                slip[i] = uT + Wtn * pn + Wtt * pt
            else:
                pn, pt, ok = _one_contact(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, 0.0, 0.0)
                if not ok:
                    status = PAINLEVE
                    break
                res = _residual(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, 0.0, 0.0, pn, 0.0)
            pN[i] = pn
            pT[i] = pt
            if res > stats[S_RES]:
                stats[S_RES] = res
            for j in range(n):
                dvc[j] = MiHT[j, 0] * pn + MiHT[j, 1] * pt
        elif na > 0:
            m = na + nfa
            for r in range(na):
                i = ia[r]
                for j in range(n):
                    H[r, j] = G1[i, 3 + j]
                Uf[r] = UN[i]
            for r in range(nfa):
                i = fa[r]
                acc = G1[i, 2]
                for j in range(n):
                    H[na + r, j] = G1[i, 3 + n + j]
                    acc += G1[i, 3 + n + j] * up[j]
                Uf[na + r] = acc
            for c in range(m):
                for i in range(n):
                    acc = 0.0
                    for j in range(n):
                        acc += Mi[i, j] * H[c, j]
                    MiHT[i, c] = acc
            for r in range(m):
                for c in range(m):
                    acc = 0.0
                    for j in range(n):
                        acc += H[r, j] * MiHT[j, c]
                    Wd[r, c] = acc
            L = _lcp_size(na, ia, mu, base, trow)
            lst, piv, res, warm = _lcp_step(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow,
                                            Ml, ql, dl, zl, wl, rayl, work, iwork, lay,
                                            lcp_ctl, Ab, xb, idx, pcol, False)
            if lst != 0:
                status = LCP_HANDBACK
                break
            stats[S_PIVOTS] += piv
            stats[S_LCP] += 1.0
            if res > stats[S_RES]:
                stats[S_RES] = res
            for i in range(n):
                acc = 0.0
                for c in range(m):
                    acc += MiHT[i, c] * p[c]
                dvc[i] = acc
            for r in range(nfa):
                tr = na + r
                acc = Uf[tr]
                for c in range(m):
                    acc += Wd[tr, c] * p[c]
                slip[fa[r]] = acc
        for i in range(n):
            vh[i] = up[i] + dvc[i]
            q1[i] = q[i] + hk * vh[i]
        # the Verlet closing half step at the new position
        if not const_mass:
            mass_fn(par, q1, M)  # noqa: F821
            if n <= 3:
                ok = _invert_small(M, Mi, n)
            else:
                ok = _invert_gj(M, Mi, wk, n)
            if not ok:
                status = SINGULAR
                break
        forces_fn(par, q1, vh, t1, D, False)  # noqa: F821
        finite = True
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Mi[i, j] * D[j, 0]
            a[i] = vh[i] + 0.5 * hk * acc
            if not (math.isfinite(q1[i]) and math.isfinite(a[i])):
                finite = False
        if not finite:
            status = NUMERICAL
            break
        if not const_mass:
            # M(q_k+1) stands for the next step's M(q_k): recomputed there
            have_Mi = False
        if nc > 0:
            if HAS_GAPS:  # noqa: F821
                gaps_fn(par, q1, t1, Gq)  # noqa: F821
            else:
                contacts_fn(par, q1, t1, Gq, True, False)  # noqa: F821
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
            closed[i] = pN[i] > 0.0
            G0[i, 0] = Gq[i, 0]
        for j in range(n):
            q[j] = q1[j]
            vv[j] = a[j]
            v[j] = a[j] + 0.5 * dvc[j]
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
    return status, k, nrec
