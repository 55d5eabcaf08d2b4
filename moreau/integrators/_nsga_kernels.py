"""The compiled nonsmooth generalized-α loop: a template compiled once per model.

The same step as :class:`moreau.integrators.nonsmooth_generalized_alpha.NonsmoothGeneralizedAlpha`
(see its module docstring), on the functions of a
:class:`moreau.compiled.CompiledModel`: the smooth generalized-α Newton
iteration on the model's forces and Jacobians with the closed contacts'
smooth forces solved inside each iteration, the velocity-level impulse
problem (both with the contact problem of :mod:`moreau.integrators._mj_kernels`:
the one-contact enumeration, Lemke for several) and the position correction
(closed form for one contact; for several, the held contacts' equalities
eliminated by a Schur complement and a frictionless LCP by Lemke for the rest).
Like :func:`moreau.integrators._mj_kernels.mj_loop` it is a template that
:func:`moreau.integrators._loops.runner_for` compiles in the model's namespace.
"""

import numpy as np
from numba import njit

from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, OK, PAINLEVE, S_LCP,  # noqa: F401
                          S_PIVOTS, S_RES, SINGULAR, _lcp_size, _lcp_step, _lcp_step_unused,
                          lcp_buffers, record_sample)
from ._mj_kernels import grid_step  # noqa: F401
from ._driver import loop_template, spliced
from ._step_parts import (add_impulse, all_finite, dense_delassus, gap_block, gaps_at, gather_rows,
                          index_set, invert, lemke_solve, mass_inverse, move_by, one_row_impulse,
                          record_contacts, restitution_shift, rows_times, slip_rows, times_ht)
from ._mj_kernels import SHARED_INDIRECT  # noqa: F401  (read by moreau.integrators._loops)

__all__ = ["nsga_loop", "CONVERGENCE"]

#: status: the smooth Newton iteration did not converge (the state is the start of the step)
CONVERGENCE = -8
NEWTON_RTOL = 1e-12
NEWTON_MAXITER = 25
POSITION_TOL = 1e-14
CONTACT_TOL = 1e-12
POSITION_MAXITER = 8


# spliced, as Moreau–Jean's: allocated in the loop's own function
@spliced
def step_workspace(n, nc, opts, lcp_ctl):
    """The buffers of :func:`step_rule`, allocated once a call of the loop (one tuple)."""
    M = np.zeros((n, n))
    Mi = np.empty((n, n))
    J = np.empty((n, n))
    Ji = np.empty((n, n))
    wk = np.empty((n, n))
    D = np.zeros((n, 1 + 2 * n))
    x = np.empty(n)
    r = np.empty(n)
    a1 = np.empty(n)
    qs = np.empty(n)
    vs = np.empty(n)
    ncm = max(nc, 1)
    mrows = 2 * ncm
    Gs = np.zeros((ncm, 3 + 2 * n))
    vN0 = np.zeros(ncm)
    pNi = np.zeros(ncm)
    pTi = np.zeros(ncm)
    ia = np.zeros(ncm, dtype=np.int64)
    fa = np.zeros(ncm, dtype=np.int64)
    H = np.zeros((mrows, n))
    w = np.zeros(mrows)
    MiHT = np.zeros((n, mrows))
    Wd = np.zeros((mrows, mrows))
    Uf = np.zeros(mrows)
    p = np.zeros(mrows)
    base = np.zeros(ncm, dtype=np.int64)
    trow = np.zeros(ncm, dtype=np.int64)
    lw = lcp_buffers(ncm)
    Lmax = 4 * ncm
    # the position correction's frictionless LCP: its own buffers and layout memory
    mu0 = np.zeros(ncm)
    Ml2 = np.zeros((Lmax, Lmax))
    lay2 = np.zeros(1 + ncm, dtype=np.int64)
    lay2[0] = -1
    Wn = np.zeros((mrows, mrows))
    gn = np.zeros(mrows)
    nu = np.zeros(mrows)
    nuN = np.zeros(ncm)
    nuT = np.zeros(ncm)
    X = np.zeros((n, ncm))
    # the smooth stage: the closed contacts' forces, their Delassus matrix over J^-1
    ib = np.zeros(ncm, dtype=np.int64)
    fb = np.zeros(ncm, dtype=np.int64)
    lamN = np.zeros(ncm)
    lamT = np.zeros(ncm)
    lam = np.zeros(mrows)
    dx0 = np.zeros(n)
    JiHT = np.zeros((n, mrows))
    Ml3 = np.zeros((Lmax, Lmax))
    lay3 = np.zeros(1 + ncm, dtype=np.int64)
    lay3[0] = -1
    # the mixed position correction: equality rows (held contacts) eliminated
    eqr = np.zeros(ncm, dtype=np.int64)
    unr = np.zeros(ncm, dtype=np.int64)
    iu = np.zeros(ncm, dtype=np.int64)
    Wee = np.zeros((ncm, ncm))
    Weei = np.zeros((ncm, ncm))
    wke = np.zeros((ncm, ncm))
    Ws = np.zeros((mrows, mrows))
    gs2 = np.zeros(mrows)
    nuu = np.zeros(mrows)
    tmpe = np.zeros(ncm)
    return (M, Mi, J, Ji, wk, D, x, r, a1, qs, vs, Gs, vN0, pNi, pTi, ia, fa, H, w, MiHT, Wd, Uf, p,
            base, trow, lw, mu0, Ml2, lay2, Wn, gn, nu, nuN, nuT, X, ib, fb, lamN, lamT,
            lam, dx0, JiHT, Ml3, lay3, eqr, unr, iu, Wee, Weei, wke, Ws, gs2, nuu, tmpe,
            np.zeros(ncm, dtype=np.bool_))


@spliced(step_returns=True)
def smooth_stage(mass_fn, forces_fn, contacts_fn, lcp_step, par, q, v, a, acc, t1, hk, am, af,
                 gamma, beta, cfac, n, nc, has_jac, force_lemke, closed, mu, ib, fb, x, a1, qs,
                 vs, M, D, J, Ji, wk, r, dx0, Gs, H, w, JiHT, Wd, Uf, lam, lamN, lamT, slip, base,
                 trow, Ml3, ql, dl, zl, wl, rayl, work, iwork, lay3, Ab, xb, idx, pcol, lcp_ctl,
                 stats):
    """The smooth step: Newton on the acceleration ``x = acc_{n+1}``, the contacts held in the
    step before (``closed``) carrying smooth forces ``lamN``, ``lamT`` solved in each iteration.

    Hands the step to Python where it does not converge (:data:`CONVERGENCE`),
    and on a singular Jacobian, a one-contact law without solution or Lemke's failure.
    """
    kv = hk * gamma * cfac
    for i in range(nc):
        lamN[i] = 0.0
        lamT[i] = 0.0
        slip[i] = 0.0
    nb, nfb = index_set(closed, mu, nc, ib, fb)
    mb = nb + nfb
    for i in range(n):
        x[i] = acc[i]
    converged = False
    for _ in range(NEWTON_MAXITER):
        for i in range(n):
            a1[i] = cfac * x[i] + (af * acc[i] - am * a[i]) / (1.0 - am)
            qs[i] = q[i] + hk * v[i] + hk * hk * ((0.5 - beta) * a[i] + beta * a1[i])
            vs[i] = v[i] + hk * ((1.0 - gamma) * a[i] + gamma * a1[i])
        mass_fn(par, qs, M)  # noqa: F821
        forces_fn(par, qs, vs, t1, D, True)  # noqa: F821
        for i in range(n):
            acc_r = -D[i, 0]
            for j in range(n):
                acc_r += M[i, j] * x[j]
                jj = M[i, j]
                if has_jac:
                    jj -= cfac * (hk * hk * beta * D[i, 1 + j] + hk * gamma * D[i, 1 + n + j])
                J[i, j] = jj
            r[i] = acc_r
        ok = invert(J, Ji, wk, n)
        if not ok:
            return SINGULAR
        for i in range(n):
            dx = 0.0
            for j in range(n):
                dx -= Ji[i, j] * r[j]
            dx0[i] = dx
        if nb > 0:
            # the contact velocities at v*(x + dx) are affine in the smooth forces:
            # U = U_free + kv H J^-1 H^T lam
            contacts_fn(par, qs, t1, Gs, False, True)  # noqa: F821
            gather_rows(Gs, ib, fb, nb, nfb, n, H, w)
            times_ht(Ji, H, JiHT, mb, n)
            rows_times(H, JiHT, Wd, mb, n)
            for rr in range(mb):
                acc_v = w[rr]
                for j in range(n):
                    acc_v += H[rr, j] * (vs[j] + kv * dx0[j])
                Uf[rr] = acc_v
                for c in range(mb):
                    Wd[rr, c] = kv * Wd[rr, c]
            if nb == 1 and not force_lemke:
                res = one_row_impulse(Wd, Uf, ib[0], nfb == 1, mu, 0.0, 0.0, lam, lamN, lamT,
                                      lcp_ctl, stats)
            else:
                L = _lcp_size(nb, ib, mu, base, trow)
                # np.False_: a literal False would compile the LCP step a second time
                piv, res, warm = lemke_solve(lcp_step, Wd, Uf, nb, ib, mu, lam, lamN, lamT, L, base,
                                             trow, Ml3, ql, dl, zl, wl, rayl, work, iwork, lay3,
                                             lcp_ctl, Ab, xb, idx, pcol, np.False_)
                stats[S_PIVOTS] += piv
                stats[S_LCP] += 1.0
            add_impulse(JiHT, lam, dx0, dx0, mb, n)
            # the slip at v*: the impulse stage replaces it where it runs
            slip_rows(Wd, Uf, lam, fb, nb, nfb, mb, slip)
        dmax = 0.0
        xmax = 0.0
        for i in range(n):
            x[i] += dx0[i]
            dmax = max(dmax, abs(dx0[i]))
            xmax = max(xmax, abs(x[i]))
        if dmax <= NEWTON_RTOL * max(1.0, xmax):
            converged = True
            break
    if not converged:
        return CONVERGENCE


@spliced(step_returns=True)
def impulse_stage(mass_fn, contacts_fn, lcp_step, par, q, v, qs, vs, tk, t1, n, nc, na, nfa, ia,
                  fa, mu, e, force_lemke, lamN, G0, Gs, vN0, M, Mi, wk, H, w, MiHT, Uf, Wd, p, pNi,
                  pTi, v1, slip, base, trow, Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb,
                  idx, pcol, lcp_ctl, stats):
    """The velocity-level impulse of the active contacts at the predicted state ``(qs, vs)``
    (Newton's restitution on the velocities before the step), into ``v1``; returns whether
    ``Mi`` holds ``M(qs)^-1``."""
    # a contact carrying a smooth normal force meets its law at v* already: the
    # impulse problem is solved only when an active contact carries none
    need = False
    for rr in range(na):
        if not lamN[ia[rr]] > 0.0:
            need = True
    have_mi = False
    if need:
        contacts_fn(par, q, tk, G0, False, False)  # noqa: F821
        for i in range(nc):
            acc_v = G0[i, 1]
            for j in range(n):
                acc_v += G0[i, 3 + j] * v[j]
            vN0[i] = acc_v
        mass_inverse(mass_fn, par, qs, M, Mi, wk, n, SINGULAR)  # noqa: F821
        have_mi = True
        contacts_fn(par, qs, t1, Gs, True, True)  # noqa: F821
        m = na + nfa
        dense_delassus(Gs, ia, fa, na, nfa, n, Mi, vs, H, w, MiHT, Uf, Wd)
        if na == 1 and not force_lemke:
            res = one_row_impulse(Wd, Uf, ia[0], nfa == 1, mu, e[ia[0]], vN0[ia[0]], p, pNi, pTi,
                                  lcp_ctl, stats)
        else:
            restitution_shift(Uf, na, ia, e, vN0)
            L = _lcp_size(na, ia, mu, base, trow)
            piv, res, warm = lemke_solve(lcp_step, Wd, Uf, na, ia, mu, p, pNi, pTi, L, base, trow,
                                         Ml, ql, dl, zl, wl, rayl, work, iwork, lay, lcp_ctl, Ab, xb,
                                         idx, pcol, np.False_)
            stats[S_PIVOTS] += piv
            stats[S_LCP] += 1.0
            for rr in range(na):
                if e[ia[rr]] > 0.0:
                    Uf[rr] -= e[ia[rr]] * min(vN0[ia[rr]], 0.0)
        if res > stats[S_RES]:
            stats[S_RES] = res
        add_impulse(MiHT, p, vs, v1, m, n)
        slip_rows(Wd, Uf, p, fa, na, nfa, m, slip)
    return have_mi


@spliced(step_returns=True)
def correct_positions(mass_fn, gaps_fn, contacts_fn, lcp_step, HAS_GAPS, par, qs, q1, t1, n, na, ia,
                      lamN, have_mi0, M, Mi, wk, Gq, X, Wn, gn, eqr, unr, iu, nu, mu0, nuN, nuT,
                      Wee, Weei, wke, Ws, gs2, nuu, tmpe, base, trow, Ml2, ql, dl, zl, wl, rayl,
                      work, iwork, lay2, Ab, xb, idx, pcol, lcp_ctl):
    """The position correction of ``q1``: Gauss–Newton with complementarity on the active
    contacts' gaps, the held ones (``lamN > 0``) as equalities eliminated by a Schur
    complement, a frictionless LCP by Lemke for the rest."""
    # Gauss-Newton with complementarity on the active contacts' gaps
    have_mi = have_mi0
    for _ in range(POSITION_MAXITER):
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, Gq)
        # done when no gap is negative and every held contact's gap is zero
        gmin = 0.0
        gheld = 0.0
        for rr in range(na):
            gmin = min(gmin, Gq[ia[rr], 0])
            if lamN[ia[rr]] > 0.0:
                gheld = max(gheld, abs(Gq[ia[rr], 0]))
        if gmin >= -POSITION_TOL and gheld <= POSITION_TOL:
            break
        if not have_mi:
            mass_inverse(mass_fn, par, qs, M, Mi, wk, n, SINGULAR)  # noqa: F821
            have_mi = True
        if n > 0:
            contacts_fn(par, q1, t1, Gq, True, False)  # noqa: F821
        gap_block(Gq, ia, na, Mi, X, Wn, n)
        for c in range(na):
            gn[c] = Gq[ia[c], 0]
        ne = np.int64(0)  # not a literal: see _driver.drive
        nun = np.int64(0)  # not a literal: see _mj_kernels.mj_loop
        for rr in range(na):
            if lamN[ia[rr]] > 0.0:
                eqr[ne] = rr
                ne += 1
            else:
                unr[nun] = rr
                iu[nun] = ia[rr]
                nun += 1
        if na == 1:
            if ne == 1:
                nu[0] = -gn[0] / Wn[0, 0]
            else:
                nu[0] = max(0.0, -gn[0] / Wn[0, 0])
        elif ne == 0:
            L2 = _lcp_size(na, ia, mu0, base, trow)
            lst, piv, res, warm = lcp_step(Wn, gn, na, ia, mu0, nu, nuN, nuT, L2,
                                            base, trow, Ml2, ql, dl, zl, wl, rayl,
                                            work, iwork, lay2, lcp_ctl, Ab, xb, idx,
                                            pcol, np.False_)
            if lst != 0:
                return LCP_HANDBACK
        else:
            # g = 0 on the held rows (nu of either sign): their nu eliminated
            for a_ in range(ne):
                for b_ in range(ne):
                    Wee[a_, b_] = Wn[eqr[a_], eqr[b_]]
            ok = invert(Wee, Weei, wke, ne)
            if not ok:
                return SINGULAR
            if nun > 0:
                for a_ in range(nun):
                    ra = unr[a_]
                    for b_ in range(ne):
                        acc_v = 0.0
                        for c_ in range(ne):
                            acc_v += Wn[ra, eqr[c_]] * Weei[c_, b_]
                        tmpe[b_] = acc_v
                    acc_v = gn[ra]
                    for b_ in range(ne):
                        acc_v -= tmpe[b_] * gn[eqr[b_]]
                    gs2[a_] = acc_v
                    for c in range(nun):
                        acc_v = Wn[ra, unr[c]]
                        for b_ in range(ne):
                            acc_v -= tmpe[b_] * Wn[eqr[b_], unr[c]]
                        Ws[a_, c] = acc_v
                L2 = _lcp_size(nun, iu, mu0, base, trow)
                lst, piv, res, warm = lcp_step(Ws, gs2, nun, iu, mu0, nuu, nuN, nuT,
                                                L2, base, trow, Ml2, ql, dl, zl, wl,
                                                rayl, work, iwork, lay2, lcp_ctl, Ab,
                                                xb, idx, pcol, np.False_)
                if lst != 0:
                    return LCP_HANDBACK
                for a_ in range(nun):
                    nu[unr[a_]] = nuu[a_]
            for a_ in range(ne):
                acc_v = gn[eqr[a_]]
                for c in range(nun):
                    acc_v += Wn[eqr[a_], unr[c]] * nuu[c]
                tmpe[a_] = acc_v
            for a_ in range(ne):
                acc_v = 0.0
                for b_ in range(ne):
                    acc_v -= Weei[a_, b_] * tmpe[b_]
                nu[eqr[a_]] = acc_v
        move_by(X, nu, q1, na, n)


@njit(inline="always", error_model="numpy")
def step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS, HAS_JAC,
              HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats, k, k0, tk, t1, hk,
              hn, record_initial, q, v, out):
    """One nonsmooth generalized-α step from ``(q, v)`` at ``tk`` (see :mod:`._driver`).

    ``opts`` is ``(coef, position_level)`` with ``coef = (alpha_m, alpha_f,
    gamma, beta)``; ``memo`` is ``(a, acc, closed)``: the algorithmic and the
    smooth acceleration and the contacts held in the step before, updated
    after a step taken. The recorded forces are the step's whole percussions
    (smooth force over the step plus the impulse). Statuses as the driver's,
    plus :data:`CONVERGENCE` (the smooth Newton iteration did not converge;
    the caller takes the step in Python).
    """
    n = NDOF
    nc = NCONTACTS
    has_jac = HAS_JAC
    coef, position_level = opts
    a, acc, closed = memo
    q1, v1, pN, pT, slip, reg, G0, Gq = out
    (M, Mi, J, Ji, wk, D, x, r, a1, qs, vs, Gs, vN0, pNi, pTi, ia, fa, H, w, MiHT, Wd, Uf, p, base,
     trow, lw, mu0, Ml2, lay2, Wn, gn, nu, nuN, nuT, X, ib, fb, lamN, lamT, lam, dx0, JiHT,
     Ml3, lay3, eqr, unr, iu, Wee, Weei, wke, Ws, gs2, nuu, tmpe, act) = ws
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lw
    am = coef[0]
    af = coef[1]
    gamma = coef[2]
    beta = coef[3]
    cfac = (1.0 - af) / (1.0 - am)
    force_lemke = lcp_ctl[0] != 0
    ...  # the steps (moreau.integrators._driver.loop_template)
    # -- the smooth step: Newton on acc_{n+1}, with the smooth forces of the closed contacts
    smooth_stage(mass_fn, forces_fn, contacts_fn, lcp_step, par, q, v, a, acc, t1, hk, am, af,
                 gamma, beta, cfac, n, nc, has_jac, force_lemke, closed, mu, ib, fb, x, a1, qs, vs,
                 M, D, J, Ji, wk, r, dx0, Gs, H, w, JiHT, Wd, Uf, lam, lamN, lamT, slip, base,
                 trow, Ml3, ql, dl, zl, wl, rayl, work, iwork, lay3, Ab, xb, idx, pcol, lcp_ctl,
                 stats)
    for i in range(n):
        a1[i] = cfac * x[i] + (af * acc[i] - am * a[i]) / (1.0 - am)
        qs[i] = q[i] + hk * v[i] + hk * hk * ((0.5 - beta) * a[i] + beta * a1[i])
        vs[i] = v[i] + hk * ((1.0 - gamma) * a[i] + gamma * a1[i])
        v1[i] = vs[i]
        q1[i] = qs[i]
    # -- contacts at the predicted position
    if nc > 0:
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, qs, t1, Gs)
    for i in range(nc):
        pNi[i] = 0.0
        pTi[i] = 0.0
        act[i] = Gs[i, 0] <= CONTACT_TOL or closed[i]
    na, nfa = index_set(act, mu, nc, ia, fa)
    if na > 0:
        have_mi = impulse_stage(mass_fn, contacts_fn, lcp_step, par, q, v, qs, vs, tk, t1, n, nc,
                                na, nfa, ia, fa, mu, e, force_lemke, lamN, G0, Gs, vN0, M, Mi,
                                wk, H, w, MiHT, Uf, Wd, p, pNi, pTi, v1, slip, base, trow, Ml,
                                ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol,
                                lcp_ctl, stats)
        if position_level:
            correct_positions(mass_fn, gaps_fn, contacts_fn, lcp_step, HAS_GAPS, par, qs, q1, t1,
                              n, na, ia, lamN, have_mi, M, Mi, wk, Gq, X, Wn, gn, eqr, unr, iu,
                              nu, mu0, nuN, nuT, Wee, Weei, wke, Ws, gs2, nuu, tmpe, base, trow,
                              Ml2, ql, dl, zl, wl, rayl, work, iwork, lay2, Ab, xb, idx, pcol,
                              lcp_ctl)
    if not all_finite(q1, v1, n):
        return NUMERICAL
    if nc > 0:
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, Gq)
        for i in range(nc):
            # the step's whole percussion: smooth force over the step plus the impulse
            pN[i] = hk * lamN[i] + pNi[i]
            pT[i] = hk * lamT[i] + pTi[i]
        record_contacts(Gq, nc, pN, pT, mu, reg, stats)
    if k == k0 and nc > 0:
        # the gaps at the call's first state, which the driver records there
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q, tk, G0)
    for i in range(nc):
        closed[i] = pNi[i] > 0.0 or lamN[i] > 0.0
    for j in range(n):
        a[j] = a1[j]
        acc[j] = x[j]
    return OK


nsga_loop = loop_template("nsga_loop", globals(), "nonsmooth generalized-alpha")
