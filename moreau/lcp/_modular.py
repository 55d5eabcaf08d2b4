"""The exact lexicographic step of Lemke's method in compiled code, by modular arithmetic.

:func:`moreau.lcp._exact.exact_step` decides one step of the lexicographic
path exactly with Python integers. :func:`modular_step` decides the same step
(the same leaving variable, the same refusals) without big integers: every
quantity the ratio test reads is an integer of bounded size, computed modulo
several primes and decoded only as far as its sign.

The data
--------
Every float is ``m 2^e`` with ``m`` an integer below ``2^53``, so the columns
the step reads (those of the basic non-``w`` variables, the entering one,
``q``) times one power of two ``2^K`` are integers; the ``w`` columns become
``2^K e_j``. Scaling the whole system ``[I, -M, -d | q]`` by ``2^K`` changes no
ratio and no lexicographic order (``B^-1`` of the scaled basis is ``2^-K``
times the original: a positive factor).

The numerators
--------------
With ``Z`` the basic non-``w`` variables, ``R`` (ascending) the rows whose
``w`` is not basic (``|R| = |Z| = k``), ``W`` the others and ``G = B[R, Z]``
(``k x k``), the solution ``x = B^-1 c`` of any column ``c`` is
``x_Z = G^-1 c_R`` and ``x_{w_j} = (c_j - B[j, Z] G^-1 c_R) / 2^K``. With
``adj = det(G) G^-1`` the integer numerators are ``N_Z = adj c_R`` (over
``det G``) and ``N_{w_j} = det(G) c_j - B[j, Z] adj c_R`` (over ``det(G) 2^K``),
the latter being ``det [[G, c_R], [B[j, Z], c_j]]`` (Schur's complement). By
Hadamard's inequality each is at most ``P ||c||_2`` in magnitude, ``P`` the
product of the Euclidean norms of the ``Z`` columns over all rows (a
determinant of columns restricted to some rows is bounded by the product of
the restricted norms, which the full norms bound). Every decision of the step
is the sign of ``det G`` times the sign of a numerator, or the sign of a
difference of two products of numerators of the same row denominators
(``b_i a_k - b_k a_i``: the denominators cancel row by row, and the entries
``a_i, a_k > 0`` of the entering column have numerators of one sign),
bounded by ``2 P^2 ||c_1|| ||c_2||``.

Signs from residues
-------------------
Each numerator is computed modulo primes ``p_t`` in ``(2^49, 2^50)``
(products of two residues stay exact through a floating-point quotient
estimate, :func:`_mulmod`), as many as make ``prod p_t`` exceed twice the
bound. A value ``v`` with ``|v| < prod p_t / 2`` is zero when all its
residues are, and otherwise positive exactly when its least non-negative
residue modulo ``prod p_t`` lies below half of it; that residue is compared
in mixed radix (Garner's algorithm, Knuth, *TAOCP* vol. 2, Sec. 4.3.2), with
no number above 2^51. A prime dividing ``det G`` is skipped; ``det G`` is
zero (a singular basis) when more primes divide it than its bound allows
(each of them exceeds 2^49).
"""

import math

import numpy as np
from numba import njit

__all__ = ["modular_step", "primes", "STEP_PIVOT", "STEP_RAY", "STEP_REFUSED", "STEP_TOO_BIG"]

#: outcomes of :func:`modular_step`
STEP_PIVOT = 0
STEP_RAY = 1
#: the basis is singular or not lexicographically positive for the data: no
#: exact step starts from it (``exact_step`` returns None)
STEP_REFUSED = -1
#: the bound needs more primes than the table holds, or more memory than
#: _MAX_WORDS: the step is left to the Python integers
STEP_TOO_BIG = -2

_NPRIMES = 160
# residues kept at once (primes x rows x k), 32 MB
_MAX_WORDS = 1 << 22
_PRIMES = None


def _is_prime(m):
    # deterministic Miller-Rabin: these bases decide every m < 3.3e24
    if m % 2 == 0:
        return m == 2
    d, s = m - 1, 0
    while d % 2 == 0:
        d //= 2
        s += 1
    for a in (2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37):
        x = pow(a, d, m)
        if x in (1, m - 1):
            continue
        for _ in range(s - 1):
            x = x * x % m
            if x == m - 1:
                break
        else:
            return False
    return True


def primes():
    """The moduli: the largest primes below ``2^50``, descending (made once, then cached).

    Examples
    --------
    >>> p = primes()
    >>> bool(2**49 < p[-1] < p[0] < 2**50), len(p)
    (True, 160)
    """
    global _PRIMES
    if _PRIMES is None:
        small = [3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47]
        out = []
        m = (1 << 50) - 1
        while len(out) < _NPRIMES:
            if all(m % s for s in small) and _is_prime(m):
                out.append(m)
            m -= 2
        _PRIMES = np.array(out, dtype=np.int64)
    return _PRIMES


@njit(cache=True, inline="always")
def _mulmod(a, b, p, pinv):
    # a b mod p for 0 <= a, b < p < 2^50: the quotient estimate (a b / p in
    # floating point, relative error below 2^-51) is off by at most one, so
    # a b - t p lies in (-p, 2p); computed in wrapping 64-bit arithmetic it
    # is exact, since it is below 2^63 in magnitude
    t = np.int64(float(a) * float(b) * pinv)
    r = a * b - t * p
    if r < 0:
        r += p
    elif r >= p:
        r -= p
    return r


@njit(cache=True, inline="always")
def _addmod(a, b, p):
    r = a + b
    return r - p if r >= p else r


@njit(cache=True, inline="always")
def _submod(a, b, p):
    r = a - b
    return r + p if r < 0 else r


@njit(cache=True)
def _invmod(a, p):
    # a^-1 mod p (a != 0 mod p), extended Euclid
    r0, r1 = p, a
    s0, s1 = np.int64(0), np.int64(1)
    while r1 != 0:
        t = r0 // r1
        r0, r1 = r1, r0 - t * r1
        s0, s1 = s1, s0 - t * s1
    return s0 % p


@njit(cache=True)
def _log2_norm(x, K):
    # an upper bound of log2 of the Euclidean norm of the integer column 2^K x
    amax = 0.0
    for v in x:
        amax = max(amax, abs(v))
    if amax == 0.0:
        return -np.inf
    acc = 0.0
    for v in x:
        acc += (v / amax) ** 2
    return K + math.log2(amax) + 0.5 * math.log2(acc) + 1e-6


@njit(cache=True)
def _sign(res, m, P, Pinv, W):
    # the sign of the integer v (|v| < prod P[:m] / 2) whose residues are res[:m]:
    # zero when they all are; else positive exactly when u = v mod prod P lies
    # below half of it, decided on the mixed-radix digits of u (Garner),
    # compared from the top with those of (prod P - 1) / 2 (W[m]). W[i, j] for
    # j < i holds p_j mod p_i, W[i, i] the inverse of p_0 ... p_(i-1) mod p_i
    nz = False
    for t in range(m):
        if res[t] != 0:
            nz = True
            break
    if not nz:
        return 0
    digits = W[m + 1]
    for i in range(m):
        p = P[i]
        pinv = Pinv[i]
        x = res[i]
        if i > 0:
            # the digits so far, evaluated mod p by Horner's rule (the primes
            # descend, so an earlier digit is below 2 p: one subtraction reduces it)
            acc = digits[i - 1]
            if acc >= p:
                acc -= p
            for j in range(i - 2, -1, -1):
                dj = digits[j]
                if dj >= p:
                    dj -= p
                acc = _addmod(_mulmod(acc, W[i, j], p, pinv), dj, p)
            x = _mulmod(_submod(x, acc, p), W[i, i], p, pinv)
        digits[i] = x
    half = W[m]
    for i in range(m - 1, -1, -1):
        if digits[i] != half[i]:
            return 1 if digits[i] < half[i] else -1
    return 1


@njit(cache=True, inline="always")
def _reduce(x, p, pinv):
    # x mod p for |x| < 2^62
    r = x - np.int64(float(x) * pinv) * p
    while r < 0:
        r += p
    while r >= p:
        r -= p
    return r


@njit(cache=True)
def _to_residue(mant, sh, p, pinv, pow2):
    # (mant 2^sh) mod p, mant an integer below 2^53 in magnitude
    return _mulmod(_reduce(mant, p, pinv), pow2[sh], p, pinv)


@njit(cache=True)
def modular_step(M, q, d, basis, entering, P_all, flags):
    """One step of the lexicographic Lemke path at ``basis``, decided exactly (compiled).

    The decision of :func:`moreau.lcp._exact.exact_step` on the same
    arguments, made with residues modulo primes (see the module's text).

    Parameters
    ----------
    M, q, d : ndarray
        The data pivoted on (read exactly) and the covering vector.
    basis : int64[:]
        The basic variable of every row (``w_j -> j``, ``z_j -> n + j``,
        ``z0 -> 2 n``; ``z0`` among them).
    entering : int
        The variable to enter.
    P_all : int64[:]
        The moduli (:func:`primes`).
    flags : float64[:], shape (n,)
        Receives, row by row of the basis after the step (the entering
        variable in the leaving one's row; on a ray, of this basis), 0.0
        where its right-hand side is exactly zero and NaN where it is positive.

    Returns
    -------
    outcome : int
        :data:`STEP_PIVOT`, :data:`STEP_RAY`, :data:`STEP_REFUSED` (where
        ``exact_step`` returns None) or :data:`STEP_TOO_BIG`.
    leaving : int
        The variable that leaves on a pivot (``2 n`` when ``z0`` is among
        the tied rows), else -1.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[2.0, 1.0], [1.0, 2.0]])
    >>> flags = np.empty(2)
    >>> modular_step(M, np.array([-1.0, -1.0]), np.ones(2), np.array([0, 4]), 3, primes(), flags)
    (0, 0)
    >>> flags.tolist()   # z_1 = 0 in row 0, z0 = 1 in row 1
    [0.0, nan]
    """
    n = q.shape[0]
    z0 = 2 * n
    # -- the structure of the basis: Z (its non-w variables), R, W
    isw = np.zeros(n, dtype=np.bool_)
    k = 0
    for i in range(n):
        v = basis[i]
        if v < n:
            if isw[v]:
                return STEP_REFUSED, -1
            isw[v] = True
        else:
            k += 1
        if v == entering:
            return STEP_REFUSED, -1
    R = np.empty(k, dtype=np.int64)
    t = 0
    for j in range(n):
        if not isw[j]:
            if t == k:
                return STEP_REFUSED, -1
            R[t] = j
            t += 1
    if t != k:
        return STEP_REFUSED, -1
    # rpos[j]: position of row j in R, -1 for a row of W
    rpos = np.full(n, -1, dtype=np.int64)
    for t in range(k):
        rpos[R[t]] = t
    # zrow[i]: for a row holding a non-w variable, its index in Z
    zrow = np.full(n, -1, dtype=np.int64)
    # the integer data: columns 0..k-1 those of Z, k the entering one (z), k+1 q
    C = np.empty((k + 2, n))
    c = 0
    for i in range(n):
        v = basis[i]
        if v >= n:
            zrow[i] = c
            for a in range(n):
                C[c, a] = -d[a] if v == z0 else -M[a, v - n]
            c += 1
    e_w = entering < n
    for a in range(n):
        C[k, a] = 0.0 if e_w else -M[a, entering - n]
        C[k + 1, a] = q[a]
    mant = np.empty((k + 2, n), dtype=np.int64)
    ex = np.empty((k + 2, n), dtype=np.int64)
    emin = 0
    for c in range(k + 2):
        for a in range(n):
            fm, fe = math.frexp(C[c, a])
            mant[c, a] = np.int64(fm * 2.0**53)
            ex[c, a] = fe - 53
            if fm != 0.0 and fe - 53 < emin:
                emin = fe - 53
    K = -emin
    smax = K
    for c in range(k + 2):
        for a in range(n):
            if mant[c, a] != 0:
                ex[c, a] += K
                smax = max(smax, ex[c, a])
            else:
                ex[c, a] = 0
    # -- the bound: P the product of the Z columns' norms
    logP = 0.0
    for c in range(k):
        lc = _log2_norm(C[c], K)
        if lc == -np.inf:
            # a zero column: B is singular
            return STEP_REFUSED, -1
        logP += max(lc, 0.0)
    loga = float(K) if e_w else max(_log2_norm(C[k], K), 0.0)
    logq = max(_log2_norm(C[k + 1], K), 0.0)
    need = 2.0 * logP + loga + logq + 3.0
    NP = P_all.shape[0]
    m = int(need / 49.0) + 1
    # primes dividing a nonzero det G: at most log2(P) / 49 of them
    maxbad = int(max(logP, 0.0) / 49.0) + 1
    if m + maxbad > NP or m * n * max(k, 1) > _MAX_WORDS:
        return STEP_TOO_BIG, -1
    P = np.empty(m, dtype=np.int64)
    dm = np.empty(m, dtype=np.int64)
    L = np.empty((m, n, max(k, 1)), dtype=np.int64)
    Na = np.empty((m, n), dtype=np.int64)
    Nb = np.empty((m, n), dtype=np.int64)
    pow2 = np.empty(smax + 1, dtype=np.int64)
    G = np.empty((k, 2 * k), dtype=np.int64)
    Zc = np.empty((k + 2, n), dtype=np.int64)
    y = np.empty(k, dtype=np.int64)
    used = 0
    bad = 0
    for pi in range(NP):
        if used == m:
            break
        p = P_all[pi]
        pinv = 1.0 / p
        pow2[0] = 1
        for s in range(1, smax + 1):
            pow2[s] = _addmod(pow2[s - 1], pow2[s - 1], p)
        for c in range(k + 2):
            for a in range(n):
                Zc[c, a] = _to_residue(mant[c, a], ex[c, a], p, pinv, pow2)
        # [G | I] -> [I | G^-1] by Gauss-Jordan mod p, det along
        for a in range(k):
            for b in range(k):
                G[a, b] = Zc[b, R[a]]
                G[a, k + b] = 1 if a == b else 0
        det = np.int64(1)
        ok = True
        for col in range(k):
            piv = -1
            for a in range(col, k):
                if G[a, col] != 0:
                    piv = a
                    break
            if piv < 0:
                ok = False
                break
            if piv != col:
                for b in range(2 * k):
                    tmp = G[col, b]
                    G[col, b] = G[piv, b]
                    G[piv, b] = tmp
                det = _submod(0, det, p)
            det = _mulmod(det, G[col, col], p, pinv)
            inv = _invmod(G[col, col], p)
            for b in range(2 * k):
                G[col, b] = _mulmod(G[col, b], inv, p, pinv)
            for a in range(k):
                f = G[a, col]
                if a != col and f != 0:
                    for b in range(2 * k):
                        G[a, b] = _submod(G[a, b], _mulmod(f, G[col, b], p, pinv), p)
        if not ok:
            bad += 1
            if bad > maxbad:
                # det G = 0: a singular basis
                return STEP_REFUSED, -1
            continue
        P[used] = p
        dm[used] = det
        # adj = det G^-1, in G[:, k:]
        for a in range(k):
            for b in range(k):
                G[a, k + b] = _mulmod(det, G[a, k + b], p, pinv)
        for i in range(n):
            zi = zrow[i]
            if zi >= 0:
                for t in range(k):
                    L[used, i, t] = G[zi, k + t]
            else:
                # the row of w_j: -B[j, Z] adj
                j = basis[i]
                for t in range(k):
                    acc = np.int64(0)
                    for c in range(k):
                        acc = _addmod(acc, _mulmod(Zc[c, j], G[c, k + t], p, pinv), p)
                    L[used, i, t] = _submod(0, acc, p)
        # the numerators of the entering column and of q, row by row
        w2K = pow2[K]
        for i in range(n):
            acc_a = np.int64(0)
            acc_b = np.int64(0)
            for t in range(k):
                lv = L[used, i, t]
                if e_w:
                    if R[t] == entering:
                        acc_a = _addmod(acc_a, _mulmod(lv, w2K, p, pinv), p)
                else:
                    acc_a = _addmod(acc_a, _mulmod(lv, Zc[k, R[t]], p, pinv), p)
                acc_b = _addmod(acc_b, _mulmod(lv, Zc[k + 1, R[t]], p, pinv), p)
            if zrow[i] < 0:
                j = basis[i]
                ca = (w2K if j == entering else 0) if e_w else Zc[k, j]
                acc_a = _addmod(acc_a, _mulmod(det, ca, p, pinv), p)
                acc_b = _addmod(acc_b, _mulmod(det, Zc[k + 1, j], p, pinv), p)
            Na[used, i] = acc_a
            Nb[used, i] = acc_b
        used += 1
    if used < m:
        return STEP_TOO_BIG, -1
    # -- mixed radix (see _sign): p_j mod p_i, the inverses of the prefix
    # products, the digits of half the product, a row for the digits
    Pinv = np.empty(m)
    W = np.zeros((m + 2, m), dtype=np.int64)
    res = np.empty(m, dtype=np.int64)
    for i in range(m):
        p = P[i]
        pinv = 1.0 / p
        Pinv[i] = pinv
        acc = np.int64(1)
        for j in range(i):
            W[i, j] = _reduce(P[j], p, pinv)
            acc = _mulmod(acc, W[i, j], p, pinv)
        W[i, i] = _invmod(acc, p)
    rem = np.int64(0)
    for i in range(m - 1, -1, -1):
        x = rem * P[i] + (P[i] - 1)
        W[m, i] = x // 2
        rem = x % 2
    for t in range(m):
        res[t] = dm[t]
    sd = _sign(res, m, P, Pinv, W)
    # -- the basis must be feasible and lexicographically positive
    sb = np.empty(n, dtype=np.int64)
    sa = np.empty(n, dtype=np.int64)
    for i in range(n):
        for t in range(m):
            res[t] = Nb[t, i]
        sb[i] = sd * _sign(res, m, P, Pinv, W)
        if sb[i] < 0:
            return STEP_REFUSED, -1
        if sb[i] == 0:
            # the first nonzero entry of row i of B^-1, column by column
            first = 0
            j = basis[i] if zrow[i] < 0 else n
            for t in range(k):
                if R[t] > j:
                    break
                for u in range(m):
                    res[u] = L[u, i, t]
                s = _sign(res, m, P, Pinv, W)
                if s != 0:
                    first = sd * s
                    break
            if first == 0 and j < n:
                first = 1  # det G / (det G 2^K) at column j
            if first <= 0:
                return STEP_REFUSED, -1
        for t in range(m):
            res[t] = Na[t, i]
        sa[i] = sd * _sign(res, m, P, Pinv, W)
    # -- the ratio test: rows tied at the least ratio, by cross products
    nbest = 0
    best = np.empty(n, dtype=np.int64)
    for i in range(n):
        if sa[i] <= 0:
            continue
        if nbest == 0:
            best[0] = i
            nbest = 1
            continue
        r0 = best[0]
        for u in range(m):
            p = P[u]
            pinv = Pinv[u]
            res[u] = _submod(_mulmod(Nb[u, i], Na[u, r0], p, pinv),
                             _mulmod(Nb[u, r0], Na[u, i], p, pinv), p)
        s = _sign(res, m, P, Pinv, W)
        if s < 0:
            best[0] = i
            nbest = 1
        elif s == 0:
            best[nbest] = i
            nbest += 1
    if nbest == 0:
        for i in range(n):
            flags[i] = 0.0 if sb[i] == 0 else np.nan
        return STEP_RAY, -1
    r = -1
    for a in range(nbest):
        if basis[best[a]] == z0:
            r = best[a]
            break
    if r < 0:
        r = best[0]
        for a in range(1, nbest):
            i = best[a]
            # (B^-1)_i / a_i against (B^-1)_r / a_r, column by column
            ji = basis[i] if zrow[i] < 0 else -1
            jr = basis[r] if zrow[r] < 0 else -1
            for col in range(n):
                tc = rpos[col]
                if tc < 0 and col != ji and col != jr:
                    continue
                for u in range(m):
                    p = P[u]
                    pinv = Pinv[u]
                    ei = L[u, i, tc] if tc >= 0 else (dm[u] if col == ji else 0)
                    er = L[u, r, tc] if tc >= 0 else (dm[u] if col == jr else 0)
                    res[u] = _submod(_mulmod(ei, Na[u, r], p, pinv),
                                     _mulmod(er, Na[u, i], p, pinv), p)
                s = _sign(res, m, P, Pinv, W)
                if s != 0:
                    if s < 0:
                        r = i
                    break
    # -- the right-hand side after the step: zero or positive, row by row
    for i in range(n):
        if i == r:
            flags[i] = 0.0 if sb[r] == 0 else np.nan
            continue
        zero = True
        for u in range(m):
            p = P[u]
            pinv = Pinv[u]
            if _mulmod(Nb[u, i], Na[u, r], p, pinv) != _mulmod(Na[u, i], Nb[u, r], p, pinv):
                zero = False
                break
        flags[i] = 0.0 if zero else np.nan
    return STEP_PIVOT, basis[r]
