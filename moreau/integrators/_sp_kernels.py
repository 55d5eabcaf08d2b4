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
from ._mj_kernels import grid_step
from ._mj_kernels import SHARED_INDIRECT  # noqa: F401  (read by moreau.integrators._loops)

__all__ = ["sp_loop"]


def sp_loop(par, mu, e, t0, h, t_bound, k0, nmax, q, v, vv, vf, closed, save_every,
            record_initial, lcp_ctl, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip,
            rec_gap, stats):
    """Run up to ``nmax`` Schatzman–Paoli steps of a compiled model in one call.

    Arguments, statuses and outputs as :func:`moreau.integrators._mj_kernels.mj_loop`
    (no ``theta``, no projection), plus ``vv`` and ``vf`` (float64[n]), the
    Verlet velocity that carries the recursion and the velocity the forces
    see at the current node, overwritten like ``q`` and ``v``; ``closed`` is
    the index set the current node's contact problem starts from.

    Each node's contact impulse is solved once, before the step that leaves
    it, and completes the node's velocity ``v = vv + M^-1 H^T p / 2``; the
    call's first node is solved again (the statistics count it only on a
    run's first call). On :data:`LCP_HANDBACK` or :data:`PAINLEVE` the state
    is the last node whose impulse was solved; the caller takes the step
    from it in Python.
    """
    n = NDOF  # noqa: F821  (the model's namespace)
    nc = NCONTACTS  # noqa: F821
    const_mass = CONST_MASS  # noqa: F821
    force_lemke = lcp_ctl[0] != 0
    M = np.zeros((n, n))
    Mi = np.empty((n, n))
    wk = np.empty((n, n))
    D = np.zeros((n, 1 + 2 * n))
    acc = np.empty(n)
    up = np.empty(n)
    um = np.empty(n)
    vh = np.empty(n)
    dvc = np.zeros(n)
    q1 = np.empty(n)
    vv1 = np.empty(n)
    vf1 = np.empty(n)
    ncm = max(nc, 1)
    mrows = 2 * ncm
    G0 = np.zeros((ncm, 3 + 2 * n))
    G1 = np.zeros((ncm, 3 + 2 * n))
    Gi = np.zeros((ncm, 1))
    UN = np.zeros(ncm)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    pNp = np.zeros(ncm)
    pTp = np.zeros(ncm)
    slipp = np.zeros(ncm)
    cl = np.zeros(ncm, dtype=np.bool_)
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

    nrec = 0
    k = k0              # the last node whose impulse is solved and whose state is committed
    kn = k0             # the node being solved: k, or k + 1 ahead of the commit
    ahead = False
    final = False       # node kn is the end of the run
    hkp = h
    status = OK
    to_save = save_every - k0 % save_every
    while True:
        if final:
            tk = t_bound
            hk = h      # no step leaves the last node: the nominal one completes its velocity
            t1 = t_bound
            last = False
        else:
            tk, t1, hk, last = grid_step(t0, kn, h, t_bound)
        if not ahead:
            # the call's first node: its mass, forces and gaps
            if tk >= t_bound:
                break
            mass_fn(par, q, M)  # noqa: F821
            if n <= 3:
                ok = _invert_small(M, Mi, n)
            else:
                ok = _invert_gj(M, Mi, wk, n)
            if not ok:
                status = SINGULAR
                break
            forces_fn(par, q, vf, tk, D, False)  # noqa: F821
            for i in range(n):
                a_i = 0.0
                for j in range(n):
                    a_i += Mi[i, j] * D[j, 0]
                acc[i] = a_i
                q1[i] = q[i]
                vv1[i] = vv[i]
            if nc > 0:
                if HAS_GAPS:  # noqa: F821
                    gaps_fn(par, q, tk, G0)  # noqa: F821
                else:
                    contacts_fn(par, q, tk, G0, True, False)  # noqa: F821
            for i in range(nc):
                cl[i] = closed[i]
                Gi[i, 0] = G0[i, 0]
        count = ahead or record_initial
        # -- the contact impulse of node kn (position q1, Verlet velocity vv1, acceleration acc)
        for i in range(n):
            up[i] = vv1[i] + 0.5 * hk * acc[i]
            um[i] = vv1[i] - 0.5 * hk * acc[i]
            dvc[i] = 0.0
        na = np.int64(0)  # not a literal: see _mj_kernels.mj_loop
        nfa = 0
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
        if nc > 0:
            contacts_fn(par, q1, tk + 0.5 * hk, G1, False, True)  # noqa: F821
            for i in range(nc):
                sp = G1[i, 1]
                sm = G1[i, 1]
                for j in range(n):
                    sp += G1[i, 3 + j] * up[j]
                    sm += G1[i, 3 + j] * um[j]
                UN[i] = (1.0 + e[i]) * G0[i, 0] / hk + sp - e[i] * sm
                if UN[i] <= 0.0 or cl[i]:
                    ia[na] = i
                    na += 1
                    if mu[i] > 0.0:
                        fa[nfa] = i
                        nfa += 1
        if na == 1 and not force_lemke:
            i = ia[0]
            for j in range(n):
                a_j = 0.0
                a_j2 = 0.0
                for l in range(n):
                    a_j += Mi[j, l] * G1[i, 3 + l]
                    a_j2 += Mi[j, l] * G1[i, 3 + n + l]
                MiHT[j, 0] = a_j
                MiHT[j, 1] = a_j2
            Wnn = 0.0
            for j in range(n):
                Wnn += G1[i, 3 + j] * MiHT[j, 0]
            uN = UN[i]
            if count:
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
                a_i = G1[i, 2]
                for j in range(n):
                    H[na + r, j] = G1[i, 3 + n + j]
                    a_i += G1[i, 3 + n + j] * up[j]
                Uf[na + r] = a_i
            for c in range(m):
                for i in range(n):
                    a_i = 0.0
                    for j in range(n):
                        a_i += Mi[i, j] * H[c, j]
                    MiHT[i, c] = a_i
            for r in range(m):
                for c in range(m):
                    a_i = 0.0
                    for j in range(n):
                        a_i += H[r, j] * MiHT[j, c]
                    Wd[r, c] = a_i
            L = _lcp_size(na, ia, mu, base, trow)
            lst, piv, res, warm = _lcp_step(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow,
                                            Ml, ql, dl, zl, wl, rayl, work, iwork, lay,
                                            lcp_ctl, Ab, xb, idx, pcol, False)
            if lst != 0:
                status = LCP_HANDBACK
                break
            if count:
                stats[S_PIVOTS] += piv
                stats[S_LCP] += 1.0
            if res > stats[S_RES]:
                stats[S_RES] = res
            for i in range(n):
                a_i = 0.0
                for c in range(m):
                    a_i += MiHT[i, c] * p[c]
                dvc[i] = a_i
            for r in range(nfa):
                tr = na + r
                a_i = Uf[tr]
                for c in range(m):
                    a_i += Wd[tr, c] * p[c]
                slip[fa[r]] = a_i
        # -- node kn solved: commit it (a node ahead) and record its sample
        if ahead:
            if record_initial:
                # the run's first sample, once its step is certain to be taken here
                record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                              nrec, t0 + k0 * h, q, v, reg, pNp, pTp, hkp, slipp, Gi, n, nc)
                nrec += 1
                record_initial = False
            for j in range(n):
                q[j] = q1[j]
                vv[j] = vv1[j]
                vf[j] = vf1[j]
                v[j] = vv1[j] + 0.5 * dvc[j]
            for i in range(nc):
                closed[i] = cl[i]
            k = kn
            to_save -= 1
            if to_save == 0:
                to_save = save_every
            if to_save == save_every or final:
                record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                              nrec, tk, q, v, reg, pNp, pTp, hkp, slipp, G0, n, nc)
                nrec += 1
        if final or k - k0 >= nmax:
            break
        # -- the step from node k to k + 1: positions, the next node's forces and gaps
        for i in range(n):
            vh[i] = up[i] + dvc[i]
            q1[i] = q[i] + hk * vh[i]
            # what the forces see at the next node (see the scheme's module docstring)
            vf1[i] = vh[i] + 0.5 * hk * acc[i] + 0.5 * dvc[i]
        if not const_mass:
            mass_fn(par, q1, M)  # noqa: F821
            if n <= 3:
                ok = _invert_small(M, Mi, n)
            else:
                ok = _invert_gj(M, Mi, wk, n)
            if not ok:
                status = SINGULAR
                break
        forces_fn(par, q1, vf1, t1, D, False)  # noqa: F821
        finite = True
        for i in range(n):
            a_i = 0.0
            for j in range(n):
                a_i += Mi[i, j] * D[j, 0]
            acc[i] = a_i
            vv1[i] = vh[i] + 0.5 * hk * a_i
            if not (math.isfinite(q1[i]) and math.isfinite(vv1[i])):
                finite = False
        if not finite:
            status = NUMERICAL
            break
        if nc > 0:
            if HAS_GAPS:  # noqa: F821
                gaps_fn(par, q1, t1, G0)  # noqa: F821
            else:
                contacts_fn(par, q1, t1, G0, True, False)  # noqa: F821
            for i in range(nc):
                if -G0[i, 0] > stats[S_PEN]:
                    stats[S_PEN] = -G0[i, 0]
                reg[i] = _classify(pN[i], pT[i], mu[i])
                pNp[i] = pN[i]
                pTp[i] = pT[i]
                slipp[i] = slip[i]
                cl[i] = pN[i] > 0.0
        hkp = hk
        kn = k + 1
        ahead = True
        final = last
    return status, k, nrec
