"""The pieces every compiled step rule shares, spliced into the driver where a step rule calls them.

Each function is a :func:`moreau.integrators._driver.spliced` helper: at a
call in a step rule its body replaces the call (no call, no argument
passing), so that a step rule built from them runs the arithmetic it would
run written out, in the same order, to the bit. The contact rows a model
writes are ``G[i] = (g, wN, wT, WN[0:n], WT[0:n])`` (:mod:`moreau.compiled`);
``ia`` lists the active contacts and ``fa`` the frictional ones among them,
the normal rows first, then the tangential ones.

The sequences several schemes share are here: the step's start and active
set (:func:`start_contacts`), the contact problem's assembly
(:func:`dense_delassus`, :func:`sparse_delassus`, :func:`restitution_shift`),
its solution (:func:`solve_one`, :func:`one_row_impulse`,
:func:`lemke_solve`) and the update (:func:`add_impulse`, :func:`slip_rows`,
:func:`record_contacts`). A part written with ``spliced(step_returns=True)``
may end the step with a status, as the step rule itself would.
"""

import math

import numpy as np
from numba import njit

from ._contact_step import (LCP_HANDBACK, PAINLEVE, S_DIRECT, S_LCP, S_PEN, _classify, _one_contact, _residual,
                            _stop_at)
from ._driver import spliced

__all__ = ["invert", "mass_inverse", "gaps_at", "index_set", "gather_rows", "affine_rows",
           "times_ht", "rows_times", "contact_block", "solve_one", "add_impulse", "slip_rows",
           "all_finite", "record_contacts", "gap_block", "start_contacts", "sparse_delassus",
           "restitution_shift", "lemke_solve", "move_by", "move_back", "held_gaps",
           "dense_delassus", "one_row_impulse", "COND_MAX"]

#: a matrix whose 1-norm condition number reaches this is singular to working precision
COND_MAX = 1e14


@njit(cache=True)
def _invert_small(A, out, n):
    """``out = A^-1`` for ``n <= 3`` in closed form; False when ``A`` is singular.

    Singular means to working precision: a 1-norm condition number of 1e14 or
    more, or a non-finite entry. Loop-free and call-free on purpose: LLVM
    inlines it into the loops and prunes the arrays' reference counts only
    around straight-line code.
    """
    ok = True
    na = 0.0
    ni = 0.0
    if n == 1:
        a = A[0, 0]
        ok = math.isfinite(a)
        out[0, 0] = 1.0 / a
        na = abs(a)
        ni = abs(out[0, 0])
    elif n == 2:
        a = A[0, 0]
        b = A[0, 1]
        c = A[1, 0]
        d = A[1, 1]
        ok = math.isfinite(a) and math.isfinite(b) and math.isfinite(c) and math.isfinite(d)
        det = a * d - b * c
        out[0, 0] = d / det
        out[0, 1] = -b / det
        out[1, 0] = -c / det
        out[1, 1] = a / det
        na = max(abs(a) + abs(c), abs(b) + abs(d))
        ni = max(abs(out[0, 0]) + abs(out[1, 0]), abs(out[0, 1]) + abs(out[1, 1]))
    else:
        a00 = A[0, 0]
        a01 = A[0, 1]
        a02 = A[0, 2]
        a10 = A[1, 0]
        a11 = A[1, 1]
        a12 = A[1, 2]
        a20 = A[2, 0]
        a21 = A[2, 1]
        a22 = A[2, 2]
        ok = (math.isfinite(a00) and math.isfinite(a01) and math.isfinite(a02)
              and math.isfinite(a10) and math.isfinite(a11) and math.isfinite(a12)
              and math.isfinite(a20) and math.isfinite(a21) and math.isfinite(a22))
        # adjugate over the determinant
        c00 = a11 * a22 - a12 * a21
        c01 = a02 * a21 - a01 * a22
        c02 = a01 * a12 - a02 * a11
        c10 = a12 * a20 - a10 * a22
        c11 = a00 * a22 - a02 * a20
        c12 = a02 * a10 - a00 * a12
        c20 = a10 * a21 - a11 * a20
        c21 = a01 * a20 - a00 * a21
        c22 = a00 * a11 - a01 * a10
        det = a00 * c00 + a01 * c10 + a02 * c20
        out[0, 0] = c00 / det
        out[0, 1] = c01 / det
        out[0, 2] = c02 / det
        out[1, 0] = c10 / det
        out[1, 1] = c11 / det
        out[1, 2] = c12 / det
        out[2, 0] = c20 / det
        out[2, 1] = c21 / det
        out[2, 2] = c22 / det
        na = max(abs(a00) + abs(a10) + abs(a20),
                 max(abs(a01) + abs(a11) + abs(a21), abs(a02) + abs(a12) + abs(a22)))
        ni = max(abs(out[0, 0]) + abs(out[1, 0]) + abs(out[2, 0]),
                 max(abs(out[0, 1]) + abs(out[1, 1]) + abs(out[2, 1]),
                     abs(out[0, 2]) + abs(out[1, 2]) + abs(out[2, 2])))
    # the arrays' last use, on the path where all branches have merged
    touched = A.size + out.size
    # `na * ni < COND_MAX` is False for nan too
    return ok and na * ni < COND_MAX and touched > 0


@njit(cache=True, error_model="numpy")
def _invert_gj(A, out, work, n):
    """``out = A^-1`` by Gauss-Jordan with partial pivoting (any ``n``); False when singular."""
    for i in range(n):
        for j in range(n):
            if not math.isfinite(A[i, j]):
                return False
    for i in range(n):
        for j in range(n):
            work[i, j] = A[i, j]
            out[i, j] = 1.0 if i == j else 0.0
    for c in range(n):
        piv = c
        best = abs(work[c, c])
        for r in range(c + 1, n):
            if abs(work[r, c]) > best:
                best = abs(work[r, c])
                piv = r
        if best == 0.0:
            return False
        if piv != c:
            for j in range(n):
                tmp = work[c, j]
                work[c, j] = work[piv, j]
                work[piv, j] = tmp
                tmp = out[c, j]
                out[c, j] = out[piv, j]
                out[piv, j] = tmp
        inv = 1.0 / work[c, c]
        for j in range(n):
            work[c, j] *= inv
            out[c, j] *= inv
        for r in range(n):
            if r != c:
                fct = work[r, c]
                if fct != 0.0:
                    for j in range(n):
                        work[r, j] -= fct * work[c, j]
                        out[r, j] -= fct * out[c, j]
    na = 0.0
    ni = 0.0
    for j in range(n):
        sa = 0.0
        si = 0.0
        for i in range(n):
            sa += abs(A[i, j])
            si += abs(out[i, j])
        na = max(na, sa)
        ni = max(ni, si)
    return na * ni < COND_MAX





@spliced
def invert(A, Ai, wk, n):
    """``Ai = A^-1`` in closed form (``n <= 3``) or by Gauss–Jordan; False when singular."""
    if n <= 3:
        ok = _invert_small(A, Ai, n)
    else:
        ok = _invert_gj(A, Ai, wk, n)
    return ok


@spliced(step_returns=True)
def mass_inverse(mass_fn, par, q, M, Mi, wk, n, fail):
    """``M = M(q)`` and ``Mi = M^-1``; a singular ``M`` ends the step with the status ``fail``."""
    mass_fn(par, q, M)
    ok = invert(M, Mi, wk, n)
    if not ok:
        return fail


@spliced
def gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q, t, G):
    """The gaps at ``(q, t)`` into ``G[:, 0]``: the model's own function where it has one."""
    if HAS_GAPS:
        gaps_fn(par, q, t, G)
    else:
        contacts_fn(par, q, t, G, True, False)


@spliced
def index_set(active, mu, nc, ia, fa):
    """``(na, nfa)``: the contacts flagged ``active`` into ``ia``, the frictional ones into ``fa``."""
    # int64, not the literal 0: numba types a call by its first-seen argument types, and
    # a literal would compile the contact solves a second time for it
    na = np.int64(0)
    nfa = 0
    for i in range(nc):
        if active[i]:
            ia[na] = i
            na += 1
            if mu[i] > 0.0:
                fa[nfa] = i
                nfa += 1
    return na, nfa


@spliced
def gather_rows(G, ia, fa, na, nfa, n, H, w):
    """The rows ``H`` and the rheonomic terms ``w`` of the active contacts: normal, then tangential."""
    for r in range(na):
        i = ia[r]
        for j in range(n):
            H[r, j] = G[i, 3 + j]
        w[r] = G[i, 1]
    for r in range(nfa):
        i = fa[r]
        for j in range(n):
            H[na + r, j] = G[i, 3 + n + j]
        w[na + r] = G[i, 2]


@spliced
def affine_rows(H, w, u, U, m, n):
    """``U = w + H u`` over ``m`` rows (the local velocities of ``u``)."""
    for r in range(m):
        acc = w[r]
        for j in range(n):
            acc += H[r, j] * u[j]
        U[r] = acc


@spliced
def times_ht(A, H, X, m, n):
    """``X = A H^T`` for the ``m`` rows of ``H`` (``M^-1 H^T``: the directions of the impulses)."""
    for c in range(m):
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += A[i, j] * H[c, j]
            X[i, c] = acc


@spliced
def rows_times(H, X, W, m, n):
    """``W = H X`` over ``m`` rows and columns (the Delassus matrix from ``X = M^-1 H^T``)."""
    for r in range(m):
        for c in range(m):
            acc = 0.0
            for j in range(n):
                acc += H[r, j] * X[j, c]
            W[r, c] = acc


@spliced
def contact_block(G, i, Ai, AiHT, u, n, fr):
    """One contact's Delassus block and local velocities from its two rows alone.

    ``AiHT`` gets ``A^-1`` times the contact's normal and tangential rows;
    returns ``(Wnn, Wnt, Wtn, Wtt, uN, uT)`` at the velocity ``u`` (the
    tangential ones zero where ``fr`` is false). Loops over ``n`` alone, so
    that with the sizes known at compile time it is straight-line code.
    """
    for j in range(n):
        acc = 0.0
        acc2 = 0.0
        for l in range(n):
            acc += Ai[j, l] * G[i, 3 + l]
            acc2 += Ai[j, l] * G[i, 3 + n + l]
        AiHT[j, 0] = acc
        AiHT[j, 1] = acc2
    Wnn = 0.0
    uN = G[i, 1]
    for j in range(n):
        Wnn += G[i, 3 + j] * AiHT[j, 0]
        uN += G[i, 3 + j] * u[j]
    Wnt = 0.0
    Wtn = 0.0
    Wtt = 0.0
    uT = G[i, 2]
    if fr:
        for j in range(n):
            Wnt += G[i, 3 + j] * AiHT[j, 1]
            Wtn += G[i, 3 + n + j] * AiHT[j, 0]
            Wtt += G[i, 3 + n + j] * AiHT[j, 1]
            uT += G[i, 3 + n + j] * u[j]
    return Wnn, Wnt, Wtn, Wtt, uN, uT


@spliced
def solve_one(Wnn, Wnt, Wtn, Wtt, uN, uT, fr, mu, e, vpre, lcp_ctl, stats, count):
    """One active contact in closed form: ``(pn, pt, ok, res)``.

    ``ok`` is false where the sliding piece has no solution, or where
    ``painleve="stop"`` stops there (the caller hands the step back); ``res``
    is the answer's residual. ``count`` says whether the solve enters the
    statistics.
    """
    if count:
        stats[S_LCP] += 1.0
        stats[S_DIRECT] += 1.0
    if fr:
        pn, pt, ok = _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vpre)
        ok = ok and not _stop_at(lcp_ctl, Wnn, Wnt, mu, uN, uT, e, vpre)
        res = _residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vpre, pn, pt)
    else:
        pn, pt, ok = _one_contact(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, e, vpre)
        res = _residual(Wnn, 0.0, 0.0, 0.0, uN, 0.0, 0.0, e, vpre, pn, 0.0)
    return pn, pt, ok, res


@spliced
def add_impulse(X, p, u, out, m, n):
    """``out = u + X p`` (``X = M^-1 H^T``: the velocity ``u`` moved by the impulses ``p``;
    ``out`` may be ``u``)."""
    for i in range(n):
        acc = u[i]
        for c in range(m):
            acc += X[i, c] * p[c]
        out[i] = acc


@spliced
def slip_rows(W, U, p, fa, na, nfa, m, slip):
    """The slip velocity ``U_T + W_T p`` of each frictional active contact after the impulses."""
    for r in range(nfa):
        acc = U[na + r]
        for c in range(m):
            acc += W[na + r, c] * p[c]
        slip[fa[r]] = acc


@spliced
def move_by(X, d, q, m, n):
    """``q += X d`` over ``m`` columns (a position projection's step along ``X = A^-1 WN^T``)."""
    for i in range(n):
        acc = 0.0
        for c in range(m):
            acc += X[i, c] * d[c]
        q[i] += acc


@spliced
def held_gaps(G, held, nh, gx):
    """``gx`` = the gaps (``G[:, 0]``) of the ``nh`` contacts listed in ``held``; returns the
    largest in magnitude (a position projection's residual)."""
    gm = 0.0
    for r in range(nh):
        gx[r] = G[held[r], 0]
        gm = max(gm, abs(gx[r]))
    return gm


@spliced
def move_back(X, d, q, m, n):
    """``q -= X d`` over ``m`` columns; returns the largest ``|X d|`` (a Newton step onto the
    gaps or the velocities along ``X = A^-1 WN^T``, and its size)."""
    dmax = 0.0
    for i in range(n):
        acc = 0.0
        for c in range(m):
            acc += X[i, c] * d[c]
        q[i] -= acc
        dmax = max(dmax, abs(acc))
    return dmax


@spliced
def all_finite(a, b, n):
    """Whether the ``n`` first entries of ``a`` and ``b`` are finite (a step's state)."""
    finite = True
    for i in range(n):
        if not (math.isfinite(a[i]) and math.isfinite(b[i])):
            finite = False
    return finite


@spliced
def record_contacts(G, nc, pN, pT, mu, reg, stats):
    """At the step's end: the largest penetration (``G[:, 0]``, the gaps) and each contact's regime."""
    for i in range(nc):
        if -G[i, 0] > stats[S_PEN]:
            stats[S_PEN] = -G[i, 0]
        reg[i] = _classify(pN[i], pT[i], mu[i])


@spliced
def gap_block(G, sel, s, Ai, X, S, n):
    """``X = A^-1 WN^T`` and ``S = WN X`` for the normal rows of the ``s`` contacts listed in ``sel``
    (a position projection's Gauss–Newton step)."""
    for c in range(s):
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Ai[i, j] * G[sel[c], 3 + j]
            X[i, c] = acc
    for r in range(s):
        for c in range(s):
            acc = 0.0
            for j in range(n):
                acc += G[sel[r], 3 + j] * X[j, c]
            S[r, c] = acc


@spliced
def start_contacts(G0, v, closed, hk, nc, n, vN0, active, pN, pT, slip):
    """The step's start: impulses and slips zeroed, the normal velocities ``vN0`` at ``v`` and the
    active set (a gap that closes within half a step at ``vN0``, or a contact closed before)."""
    for i in range(nc):
        pN[i] = 0.0
        pT[i] = 0.0
        slip[i] = 0.0
        acc = G0[i, 1]
        for j in range(n):
            acc += G0[i, 3 + j] * v[j]
        vN0[i] = acc
        active[i] = (G0[i, 0] + 0.5 * hk * acc <= 0.0) or closed[i]


@spliced
def sparse_delassus(G, ia, fa, na, nfa, n, Ai, u, H, hnz, hcnt, w, AiHT, U, W):
    """The contact problem of the active rows: ``H``, ``AiHT = A^-1 H^T``, ``U = w + H u`` and
    ``W = H AiHT``, summed over each row's nonzero columns only.

    Contact rows touch few coordinates (two balls of a chain): over them alone
    the assembly costs ``m nnz`` instead of ``m n^2`` (100 balls: 10x fewer
    operations a step). The skipped terms are exact zeros, so the sums are the same.
    """
    m = na + nfa
    gather_rows(G, ia, fa, na, nfa, n, H, w)
    for c in range(m):
        cnt = 0
        for j in range(n):
            if H[c, j] != 0.0:
                hnz[c, cnt] = j
                cnt += 1
        hcnt[c] = cnt
    for c in range(m):
        for i in range(n):
            acc = 0.0
            for t in range(hcnt[c]):
                j = hnz[c, t]
                acc += Ai[i, j] * H[c, j]
            AiHT[i, c] = acc
    for r in range(m):
        acc = w[r]
        for t in range(hcnt[r]):
            j = hnz[r, t]
            acc += H[r, j] * u[j]
        U[r] = acc
        for c in range(m):
            acc = 0.0
            for t in range(hcnt[r]):
                j = hnz[r, t]
                acc += H[r, j] * AiHT[j, c]
            W[r, c] = acc


@spliced
def restitution_shift(U, na, ia, e, vN0):
    """Newton's restitution on the normal rows ``U[:na]``: each aims at ``-e`` times its
    approach speed ``vN0`` (Signorini's law on the shifted velocity)."""
    for r in range(na):
        i = ia[r]
        if e[i] > 0.0:
            U[r] += e[i] * min(vN0[i], 0.0)


@spliced(step_returns=True)
def lemke_solve(lcp_step, W, U, na, ia, mu, p, pN, pT, L, base, trow, Ml, ql, dl, zl, wl, rayl,
                work, iwork, lay, lcp_ctl, Ab, xb, idx, pcol, warm_ok):
    """The friction LCP of the active rows by ``lcp_step`` (:func:`._contact_step._lcp_step`):
    ``(pivots, residual, warm)``; where Lemke fails the step is handed back (:data:`LCP_HANDBACK`)."""
    lst, piv, res, warm = lcp_step(W, U, na, ia, mu, p, pN, pT, L, base, trow, Ml, ql, dl, zl, wl,
                                   rayl, work, iwork, lay, lcp_ctl, Ab, xb, idx, pcol, warm_ok)
    if lst != 0:
        return LCP_HANDBACK
    return piv, res, warm


@spliced
def dense_delassus(G, ia, fa, na, nfa, n, Ai, u, H, w, AiHT, U, W):
    """The contact problem of the active rows, dense: ``H``, ``AiHT = A^-1 H^T``, ``U = w + H u``
    and ``W = H AiHT``."""
    m = na + nfa
    gather_rows(G, ia, fa, na, nfa, n, H, w)
    times_ht(Ai, H, AiHT, m, n)
    affine_rows(H, w, u, U, m, n)
    rows_times(H, AiHT, W, m, n)


@spliced(step_returns=True)
def one_row_impulse(W, U, i, fr, mu, ei, vpre, p, pN, pT, lcp_ctl, stats):
    """Contact ``i``, the only active one, in closed form (:func:`solve_one`) on the Delassus
    block ``W`` and velocities ``U``: impulses into ``p`` (stacked) and ``pN``, ``pT``; returns
    the residual. No solution stops the step (:data:`PAINLEVE`)."""
    pn, pt, ok, res = solve_one(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U[0], U[1], fr, mu[i], ei,
                                vpre, lcp_ctl, stats, True)
    if not ok:
        return PAINLEVE
    p[0] = pn
    if fr:
        p[1] = pt
    pN[i] = pn
    pT[i] = pt
    return res
