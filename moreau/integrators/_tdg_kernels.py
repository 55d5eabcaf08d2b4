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

import numpy as np
from numba import njit

from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, OK, PAINLEVE, S_DIRECT, S_LCP,  # noqa: F401
                          S_PIVOTS, S_PROJ, S_RES, SINGULAR, _lcp_size, _lcp_step, _one_contact,
                          _residual, _stop_at, borrowed, grid_step, lcp_buffers, record_sample)
from ._driver import loop_template, spliced
# read by moreau.integrators._loops
from ._mj_kernels import SHARED_INDIRECT, _lcp_step_unused  # noqa: F401
from ._step_parts import (all_finite, gap_block, gaps_at, gather_rows, held_gaps, index_set,
                          mass_inverse, move_back, record_contacts, start_contacts, times_ht)

__all__ = ["tdg_loop"]


# inlined: a call would pass (and reference-count) its thirty arrays on every
# solve, which cost about 1 us a call, 50 times the solve of one contact. Inlined, it
# still took an atomic reference on each, which LLVM did not prune: its callers pass
# borrowed() views (see _contact_step.borrowed). Its loops are written out: the parts
# of _step_parts inlined by numba inside it made a step of the bouncing ball about 7 %
# slower
@njit(inline="always")
def _stage_problem(Hm, wm, Dir, vfree, e, vpre, n, na, nfa, ia, mu, force_lemke, p, pN, pT,
                   U, Wd, Uf, base, trow, lw, lcp_ctl, stats, lcp_step):
    """Impulse ``p`` along ``Dir`` (``M^-1 H^T``) making ``Hm v + wm`` obey Newton–Coulomb.

    ``e`` and ``vpre`` (per row of ``ia``) give Newton's law
    ``U_N + e min(vpre, 0) >= 0``; zero ``e`` is the velocity-level Signorini
    law of a stage. ``lw`` holds the buffers of Lemke's method
    (``Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol``, those of
    :func:`moreau.integrators._mj_kernels._lcp_step`). Writes ``p`` (stacked rows), ``pN``, ``pT`` (by contact)
    and ``U`` (the local velocities after the impulse). Returns a status of
    :mod:`moreau.integrators._mj_kernels`. ``lcp_step`` is the loop's LCP step: in the
    shared loop a pointer (:data:`SHARED_INDIRECT`), so that Lemke is not linked and
    optimised again inside the loop, and a stand-in where no LCP can arise.
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
        # np.False_: a literal False would compile the LCP step a second time
        lst, piv, res, warm = lcp_step(Wd, Uf, na, ia, mu, p, pN, pT, L, base, trow,
                                        Ml, ql, dl, zl, wl, rayl, work, iwork, lay,
                                        lcp_ctl, Ab, xb, idx, pcol, np.False_)
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


# spliced, as Moreau–Jean's: allocated in the loop's own function
@spliced
def step_workspace(n, nc, opts, lcp_ctl):
    """The buffers of :func:`step_rule`, allocated once a call of the loop (one tuple)."""
    cs = opts[0]
    s = cs.shape[0]
    ncm = max(nc, 1)
    mrows = 2 * ncm
    # have_Mi: the inverse of a constant mass matrix computed in this call
    flags = np.zeros(1, dtype=np.int64)
    return (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
            np.zeros((n, 1 + 2 * n)), np.zeros((s, n)), np.zeros((s, n)), np.zeros((s, n)),
            np.zeros((s, n, mrows)), np.zeros((s, mrows)), np.empty(n), np.zeros(ncm),
            np.zeros(ncm), np.zeros(ncm), np.zeros(ncm, dtype=np.int64),
            np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.int64), np.zeros(ncm),
            np.zeros(ncm), np.zeros((mrows, n)), np.zeros(mrows), np.zeros((mrows, mrows)),
            np.zeros(mrows), np.zeros(mrows), np.zeros(mrows), np.zeros(mrows),
            np.zeros((ncm, ncm)), np.zeros(ncm), np.zeros((n, ncm)),
            np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.int64), flags,
            np.zeros(ncm, dtype=np.bool_), lcp_buffers(ncm))


@spliced(step_returns=True)
def impulse_at_start(G0, ia, fa, na, nfa, m, n, e, mu, vN0, ea, ez, Mi0, H, w, Dirs, v0, p, Ptot,
                     force_lemke, sN, sT, U, Wd, Uf, base, trow, lw, lcp_ctl, stats, lcp_step):
    """The impulsive part at ``t_n+``: Newton's law on the pre-step velocities, into ``v0`` and
    ``Ptot``; ``Dirs[0] = M^-1 H^T`` at the step's start."""
    gather_rows(G0, ia, fa, na, nfa, n, H, w)
    for r in range(na):
        ea[r] = e[ia[r]]
        ez[r] = vN0[ia[r]]
    times_ht(Mi0, H, Dirs[0], m, n)
    # borrowed views: no reference counting per stage (see _contact_step.borrowed)
    st = _stage_problem(borrowed(H), borrowed(w), borrowed(Dirs)[0], borrowed(v0), borrowed(ea),
                        borrowed(ez), n, na, nfa, borrowed(ia), borrowed(mu), force_lemke,
                        borrowed(p), borrowed(sN), borrowed(sT), borrowed(U), borrowed(Wd),
                        borrowed(Uf), borrowed(base), borrowed(trow), borrowed(lw),
                        borrowed(lcp_ctl), borrowed(stats), lcp_step)
    if st != OK:
        return st
    for c in range(m):
        Ptot[c] = p[c]
        for i in range(n):
            v0[i] += Dirs[0, i, c] * p[c]
    for r in range(na):
        ea[r] = 0.0
        ez[r] = 0.0


@spliced
def total_impulses(na, nfa, m, s, hk, ia, fa, b_st, Lam, Ptot, pN, pT, held):
    """The step's impulses: the one at its start plus the stages' forces by their weights, into
    ``pN``, ``pT``; returns how many contacts the last stage holds (listed in ``held``)."""
    nh = np.int64(0)  # not a literal: see _driver.drive
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
    return nh


@spliced(step_returns=True)
def project_held(mass_fn, gaps_fn, contacts_fn, HAS_GAPS, const_mass, par, t1, n, nh, held, qi, M,
                 Mi, Mi0, wk, Gi, gx, MW, S, stats):
    """Newton steps of ``qi`` onto ``g = 0`` for the ``nh`` contacts in ``held``, in the metric of
    ``M(q_{n+1})`` (at most four, down to rounding); a singular ``M`` stops the step."""
    # Newton steps onto g = 0 for the held contacts, in the metric of M(q_{n+1})
    # (a constant mass matrix is inverted once, in Mi0)
    if const_mass:
        for i in range(n):
            for j in range(n):
                Mi[i, j] = Mi0[i, j]
    else:
        mass_inverse(mass_fn, par, qi, M, Mi, wk, n, SINGULAR)  # noqa: F821
    qmax = 1.0
    for j in range(n):
        qmax = max(qmax, abs(qi[j]))
    for it in range(4):
        contacts_fn(par, qi, t1, Gi, False, True)  # noqa: F821
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, qi, t1, Gi)
        gm = held_gaps(Gi, held, nh, gx)
        if gm == 0.0:
            break
        gap_block(Gi, held, nh, Mi, MW, S, n)
        if not _solve_small(S, gx, nh):
            break
        dmax = move_back(MW, gx, qi, nh, n)
        stats[S_PROJ] += 1.0
        if dmax <= 4e-16 * qmax:
            break


@njit(inline="always", error_model="numpy")
def step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS, HAS_JAC,
              HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats, k, k0, tk, t1, hk,
              hn, record_initial, q, v, out):
    """One time-discontinuous Galerkin step from ``(q, v)`` at ``tk`` (see :mod:`._driver`).

    ``opts`` is the tableau and the projection, ``(cs, a_st, b_st,
    projection)`` (``cs`` nodes, ``a_st`` stage matrix, ``b_st`` weights);
    ``memo`` ``(closed,)``, the contacts that carried a normal impulse in the
    step before. The impulse at the step's left end (Newton's law on the
    pre-step velocities), then the half-explicit Runge–Kutta stages on the
    Lobatto nodes, each force fixed by the constraint at the next stage
    (:func:`_stage_problem`); with ``projection``, Newton steps onto
    ``g = 0`` for the contacts still held at the end.
    """
    n = NDOF
    nc = NCONTACTS
    const_mass = CONST_MASS
    cs, a_st, b_st, projection = opts
    closed = memo[0]
    qi, vi, pN, pT, slip, reg, G0, Gi = out
    (M, Mi, Mi0, wk, D, Qs, Vs, As, Dirs, Lam, v0, vN0, sN, sT, ia, fa, held, ez, ea, H, w, Wd,
     Uf, U, p, Ptot, S, gx, MW, base, trow, flags, act, lw) = ws
    force_lemke = lcp_ctl[0] != 0
    s = cs.shape[0]
    ...  # the steps (moreau.integrators._driver.loop_template)
    if not (const_mass and flags[0] != 0):
        mass_inverse(mass_fn, par, q, M, Mi0, wk, n, SINGULAR)  # noqa: F821
        flags[0] = 1
    for j in range(n):
        v0[j] = v[j]
    if nc > 0:
        contacts_fn(par, q, tk, G0, False, True)  # noqa: F821
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q, tk, G0)
    start_contacts(G0, v, closed, hk, nc, n, vN0, act, pN, pT, slip)
    na, nfa = index_set(act, mu, nc, ia, fa)
    m = na + nfa
    if na > 0:
        impulse_at_start(G0, ia, fa, na, nfa, m, n, e, mu, vN0, ea, ez, Mi0, H, w, Dirs, v0, p,
                         Ptot, force_lemke, sN, sT, U, Wd, Uf, base, trow, lw, lcp_ctl, stats,
                         lcp_step)
    # the non-impulsive part: half-explicit Runge-Kutta on the Lobatto nodes
    forces_fn(par, q, v0, tk, D, False)  # noqa: F821
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += Mi0[i, j] * D[j, 0]
        As[0, i] = acc
        Qs[0, i] = q[i]
        Vs[0, i] = v0[i]
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
            gather_rows(Gi, ia, fa, na, nfa, n, H, w)
            # the force of stage st_i - 1 is fixed by the constraint at stage st_i
            kc = hk * (b_st[st_i - 1] if fin else a_st[st_i, st_i - 1])
            st = _stage_problem(borrowed(H), borrowed(w), borrowed(Dirs)[st_i - 1], borrowed(vi),
                                borrowed(ea), borrowed(ez), n, na, nfa, borrowed(ia),
                                borrowed(mu), force_lemke, borrowed(p), borrowed(sN),
                                borrowed(sT), borrowed(U), borrowed(Wd), borrowed(Uf),
                                borrowed(base), borrowed(trow), borrowed(lw),
                                borrowed(lcp_ctl), borrowed(stats), lcp_step)
            if st != OK:
                return st
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
            mass_inverse(mass_fn, par, qi, M, Mi, wk, n, SINGULAR)  # noqa: F821
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
            times_ht(Mi, H, Dirs[st_i], m, n)
    if not all_finite(qi, vi, n):
        return NUMERICAL
    nh = total_impulses(na, nfa, m, s, hk, ia, fa, b_st, Lam, Ptot, pN, pT, held)
    if projection and nh > 0:
        project_held(mass_fn, gaps_fn, contacts_fn, HAS_GAPS, const_mass, par, t1, n, nh, held,
                     qi, M, Mi, Mi0, wk, Gi, gx, MW, S, stats)
    if not const_mass:
        flags[0] = 0
    if nc > 0:
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, qi, t1, Gi)
    record_contacts(Gi, nc, pN, pT, mu, reg, stats)
    for i in range(nc):
        closed[i] = pN[i] > 0.0
    return OK


tdg_loop = loop_template("tdg_loop", globals(), "time-discontinuous Galerkin")
