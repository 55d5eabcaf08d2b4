"""The compiled Schatzman–Paoli step rule, spliced into the compiled driver.

The same step as :class:`moreau.integrators.schatzman_paoli.SchatzmanPaoli`
(see its module docstring for the derivation), on the functions of a
:class:`moreau.compiled.CompiledModel`, with the contact problem of
:mod:`moreau.integrators._contact_step` (the one-contact enumeration, Lemke
for several contacts; no warm start), run by
:mod:`moreau.integrators._driver`.

A node's contact impulse completes the node's velocity
``v = vv + M^-1 H^T p / 2``, so the step from node ``k`` to ``k + 1``
solves node ``k + 1`` one step ahead of the state the driver commits (with
the driver's ``hn``, the step that will leave it). The node's solution stays
in the step rule's workspace for the next step of the call; the call's first
node is solved again at its first step (the statistics count it only on a
run's first call). On :data:`LCP_HANDBACK` or :data:`PAINLEVE` the state is
the last node whose impulse was solved; the caller takes the step from it in
Python.
"""

import math

import numpy as np
from numba import njit

from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, OK, PAINLEVE, S_LCP,  # noqa: F401
                          S_PIVOTS, S_RES, SINGULAR, _lcp_size, _lcp_step, _lcp_step_unused,
                          lcp_buffers)
from ._mj_kernels import SHARED_INDIRECT  # noqa: F401  (read by moreau.integrators._loops)
from ._driver import loop_template, spliced
from ._step_parts import (add_impulse, affine_rows, contact_block, gaps_at, gather_rows, index_set,
                          mass_inverse, record_contacts, rows_times, slip_rows, solve_one, times_ht)

__all__ = ["sp_loop"]


# spliced, as Moreau–Jean's: the buffers' shapes stay visible to LLVM
@spliced
def step_workspace(n, nc, opts, lcp_ctl):
    """The buffers of :func:`step_rule`, allocated once a call of the loop (one tuple)."""
    ncm = max(nc, 1)
    mrows = 2 * ncm
    return (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.zeros((n, 1 + 2 * n)),
            np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.zeros(n), np.empty(n),
            np.empty(n), np.zeros((ncm, 3 + 2 * n)), np.zeros(ncm), np.zeros(ncm), np.zeros(ncm),
            np.zeros(ncm), np.zeros(ncm, dtype=np.bool_), np.zeros(ncm, dtype=np.int64),
            np.zeros(ncm, dtype=np.int64), np.zeros((mrows, n)), np.zeros((n, mrows)),
            np.zeros((mrows, mrows)), np.zeros(mrows), np.zeros(mrows), np.zeros(mrows),
            np.zeros(ncm, dtype=np.bool_), np.zeros(ncm, dtype=np.int64),
            np.zeros(ncm, dtype=np.int64), lcp_buffers(ncm))


@njit(inline="always", error_model="numpy")
def step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS, HAS_JAC,
              HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats, k, k0, tk, t1, hk,
              hn, record_initial, q, v, out):
    """One Schatzman–Paoli step from node ``k`` to node ``k + 1``, whose impulse it then solves.

    ``opts`` is empty; ``memo`` is ``(vv, vf, closed)``: the Verlet velocity
    that carries the recursion, the velocity the forces see at the node and
    the index set its contact problem starts from, updated after a step
    taken. The recorded impulses are node ``k``'s (those of the step), the
    velocity ``v1`` is node ``k + 1``'s central one, completed by its own
    impulse (see :mod:`moreau.integrators.schatzman_paoli`).
    """
    n = NDOF
    nc = NCONTACTS
    const_mass = CONST_MASS
    q1, v1, pN, pT, slip, reg, G0, Gq = out
    vv, vf, closed = memo
    (M, Mi, wk, D, acc, up, um, vh, dvc, vv1, vf1, G1, UN, pNn, pTn, slipn, cl, ia, fa, H, MiHT,
     Wd, Uf, p, w, act, base, trow, lw) = ws
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lw
    force_lemke = lcp_ctl[0] != 0
    ...  # the steps (moreau.integrators._driver.loop_template)
    # node k's impulse was solved by the step before in this call, except at its first step
    solved = k > k0
    while True:
        if solved:
            # -- the step from node k to k + 1: positions, the next node's forces and gaps
            for i in range(n):
                vh[i] = up[i] + dvc[i]
                q1[i] = q[i] + hk * vh[i]
                # what the forces see at the next node (see the scheme's module docstring)
                vf1[i] = vh[i] + 0.5 * hk * acc[i] + 0.5 * dvc[i]
            if not const_mass:
                mass_inverse(mass_fn, par, q1, M, Mi, wk, n, SINGULAR)
            forces_fn(par, q1, vf1, t1, D, False)
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
                return NUMERICAL
            if nc > 0:
                gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, Gq)
                for i in range(nc):
                    pN[i] = pNn[i]
                    pT[i] = pTn[i]
                    slip[i] = slipn[i]
                    cl[i] = pNn[i] > 0.0
                record_contacts(Gq, nc, pN, pT, mu, reg, stats)
            # the node ahead: its time, the step that leaves it, its gaps
            tn = t1
            hm = hn
            Gn = Gq
        else:
            # the call's first node: its mass, forces and gaps
            mass_inverse(mass_fn, par, q, M, Mi, wk, n, SINGULAR)
            forces_fn(par, q, vf, tk, D, False)
            for i in range(n):
                a_i = 0.0
                for j in range(n):
                    a_i += Mi[i, j] * D[j, 0]
                acc[i] = a_i
                q1[i] = q[i]
                vv1[i] = vv[i]
            if nc > 0:
                gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q, tk, G0)
            for i in range(nc):
                cl[i] = closed[i]
            tn = tk
            hm = hk
            Gn = G0
        # a node solved again at a call's start is counted once, by the call that reached it
        count = solved or record_initial
        # -- the node's contact impulse (position q1, Verlet velocity vv1, acceleration acc)
        for i in range(n):
            up[i] = vv1[i] + 0.5 * hm * acc[i]
            um[i] = vv1[i] - 0.5 * hm * acc[i]
            dvc[i] = 0.0
        for i in range(nc):
            pNn[i] = 0.0
            pTn[i] = 0.0
            slipn[i] = 0.0
        if nc > 0:
            contacts_fn(par, q1, tn + 0.5 * hm, G1, False, True)
            for i in range(nc):
                sp = G1[i, 1]
                sm = G1[i, 1]
                for j in range(n):
                    sp += G1[i, 3 + j] * up[j]
                    sm += G1[i, 3 + j] * um[j]
                UN[i] = (1.0 + e[i]) * Gn[i, 0] / hm + sp - e[i] * sm
                act[i] = UN[i] <= 0.0 or cl[i]
        na, nfa = index_set(act, mu, nc, ia, fa)
        if na == 1 and not force_lemke:
            # the restitution is in UN already: the contact's own law has e = 0
            i = ia[0]
            fr = nfa == 1
            Wnn, Wnt, Wtn, Wtt, uN, uT = contact_block(G1, i, Mi, MiHT, up, n, fr)
            pn, pt, ok, res = solve_one(Wnn, Wnt, Wtn, Wtt, UN[i], uT, fr, mu[i], 0.0, 0.0,
                                        lcp_ctl, stats, count)
            if not ok:
                return PAINLEVE
            if fr:
                slipn[i] = uT + Wtn * pn + Wtt * pt
            pNn[i] = pn
            pTn[i] = pt
            if res > stats[S_RES]:
                stats[S_RES] = res
            for j in range(n):
                dvc[j] = MiHT[j, 0] * pn + MiHT[j, 1] * pt
        elif na > 0:
            m = na + nfa
            gather_rows(G1, ia, fa, na, nfa, n, H, w)
            affine_rows(H, w, up, Uf, m, n)
            for r in range(na):
                Uf[r] = UN[ia[r]]
            times_ht(Mi, H, MiHT, m, n)
            rows_times(H, MiHT, Wd, m, n)
            L = _lcp_size(na, ia, mu, base, trow)
            # np.False_: a literal False would compile the LCP step a second time
            lst, piv, res, warm = lcp_step(Wd, Uf, na, ia, mu, p, pNn, pTn, L, base, trow,
                                           Ml, ql, dl, zl, wl, rayl, work, iwork, lay,
                                           lcp_ctl, Ab, xb, idx, pcol, np.False_)
            if lst != 0:
                return LCP_HANDBACK
            if count:
                stats[S_PIVOTS] += piv
                stats[S_LCP] += 1.0
            if res > stats[S_RES]:
                stats[S_RES] = res
            add_impulse(MiHT, p, dvc, dvc, m, n)
            slip_rows(Wd, Uf, p, fa, na, nfa, m, slipn)
        if solved:
            break
        solved = True
    # node k + 1 solved: its central velocity, and what the next call starts from
    for j in range(n):
        v1[j] = vv1[j] + 0.5 * dvc[j]
        vv[j] = vv1[j]
        vf[j] = vf1[j]
    for i in range(nc):
        closed[i] = cl[i]
    return OK


sp_loop = loop_template("sp_loop", globals(), "Schatzman–Paoli")
