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
(each of them exceeds 2^49). Single numerators need fewer primes than
products of two; the further primes are taken only when a product is not
decided otherwise.

The float filter
----------------
Most signs need no residues: ``X ~ G^-1`` in floating point with
``alpha >= ||I - X G||_inf`` (its rounding counted) bounds ``||G^-1 - X||``
by ``alpha ||X|| / (1 - alpha)`` (Neumann series), and ``x~ = X c_R`` is off
``G^-1 c_R`` by at most ``||X|| ||c_R - G x~|| / (1 - alpha)``. A sign is read
from floating point where the value stands above that bound; exact zeros and
ties (rounding noise in floating point) always go to the residues.

The exact point
---------------
:func:`exact_point` gives the point of a complementary basis correctly
rounded, as :func:`moreau.lcp._exact.basis_point` does with Python's
integers: ``z_J = N / det`` (Cramer) is compared, by the sign of an integer,
with the midpoints between the floats around a guess. Before that, one step
of refinement of the guess in double-double arithmetic with a rigorous error
bound settles every component that is neither zero nor near a midpoint.
"""

import math

import numpy as np
from numba import njit

from .. import _jit_cache
from . import _certified
from ._certified import two_prod

__all__ = ["modular_step", "exact_point", "primes", "STEP_PIVOT", "STEP_RAY", "STEP_REFUSED",
           "STEP_TOO_BIG"]

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
# the relative rounding of a computed error bound (a sum of non-negative terms)
# stays below this factor's excess for sums of fewer than 10^5 terms
_SAFE = 1.0 + 1e-10


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


@njit(cache=True)
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


@njit(cache=True)
def _addmod(a, b, p):
    r = a + b
    return r - p if r >= p else r


@njit(cache=True)
def _submod(a, b, p):
    r = a - b
    return r + p if r < 0 else r


@njit(cache=True)
def _invmod(a, p):
    # a^-1 mod p (a != 0 mod p), extended Euclid
    r0, r1 = p, a
    s0, s1 = np.int64(0), np.int64(1)
    while r1 != 0:
        # the quotient from a floating-point division (both below 2^50, so
        # it is off by at most one), corrected: cheaper than an integer division
        t = np.int64(float(r0) / float(r1))
        r = r0 - t * r1
        if r < 0:
            t -= 1
            r += r1
        elif r >= r1:
            t += 1
            r -= r1
        r0, r1 = r1, r
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
def _sign(res, m, P, Pinv, W, half):
    # the sign of the integer v (|v| < prod P[:m] / 2) whose residues are res[:m]:
    # zero when they all are; else positive exactly when u = v mod prod P lies
    # below half of it, decided on the mixed-radix digits of u (Garner),
    # compared from the top with those of (prod P[:m] - 1) / 2 (half). W[i, j]
    # for j < i holds p_j mod p_i, W[i, i] the inverse of p_0 ... p_(i-1) mod
    # p_i, and the row W[-1] takes the digits
    nz = False
    for t in range(m):
        if res[t] != 0:
            nz = True
            break
    if not nz:
        return 0
    digits = W[W.shape[0] - 1]
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
    for i in range(m - 1, -1, -1):
        if digits[i] != half[i]:
            return 1 if digits[i] < half[i] else -1
    return 1


@njit(cache=True)
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
def _prime_powers(P_all, pi, pow2, smax):
    # the prime P_all[pi] and its reciprocal; pow2[s] = 2^s mod it for s <= smax
    p = P_all[pi]
    pinv = 1.0 / p
    pow2[0] = 1
    for s in range(1, smax + 1):
        pow2[s] = _addmod(pow2[s - 1], pow2[s - 1], p)
    return p, pinv


@njit(cache=True)
def _first_nonzero(A, col, k):
    # the first row from col to k - 1 whose entry in column col is nonzero, -1 if none
    for a in range(col, k):
        if A[a, col] != 0:
            return a
    return -1


@njit(cache=True)
def _swap_rows(A, i, j):
    for b in range(A.shape[1]):
        tmp = A[i, b]
        A[i, b] = A[j, b]
        A[j, b] = tmp


@njit(cache=True)
def _radix_row(W, P, used, p, pinv):
    # row `used` of the mixed-radix table: the earlier primes mod p, and in the
    # diagonal the inverse of their product mod p
    acc = np.int64(1)
    for j in range(used):
        W[used, j] = _reduce(P[j], p, pinv)
        acc = _mulmod(acc, W[used, j], p, pinv)
    W[used, used] = _invmod(acc, p)


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
    k = np.int64(0)  # not a literal: it would type (and compile) the calls on k twice
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
    # single numerators (signs, zero tests) are below 2^need1, products of two
    # (cross-multiplied ratios, entries of B^-1 against the entering column)
    # below 2^need: m1 primes serve the first, m the second, taken only when a
    # product is not decided otherwise
    need1 = logP + max(loga, logq) + 2.0
    need = 2.0 * logP + loga + logq + 3.0
    NP = P_all.shape[0]
    m1 = int(need1 / 49.0) + 1
    m = int(need / 49.0) + 1
    # primes dividing a nonzero det G: at most log2(P) / 49 of them
    maxbad = int(max(logP, 0.0) / 49.0) + 1
    if m + maxbad > NP or m * n * (k + 2) > _MAX_WORDS:
        return STEP_TOO_BIG, -1
    # -- residues, prime by prime (_add_primes)
    P = np.empty(m, dtype=np.int64)
    Pinv = np.empty(m)
    dm = np.empty(m, dtype=np.int64)
    adj = np.empty((m, k, k), dtype=np.int64)
    Zc = np.empty((m, k + 2, n), dtype=np.int64)
    Na = np.empty((m, n), dtype=np.int64)
    Nb = np.empty((m, n), dtype=np.int64)
    W = np.zeros((m + 3, m), dtype=np.int64)
    work = np.empty((k, 2 * k + 2), dtype=np.int64)
    pow2 = np.empty(smax + 1, dtype=np.int64)
    # state[0]: primes in use, state[1]: the next one of the table
    state = np.zeros(2, dtype=np.int64)
    if not _add_primes(m1, maxbad, state, P_all, P, Pinv, dm, adj, Zc, Na, Nb, W, work, pow2,
                       mant, ex, R, zrow, basis, entering, e_w, K, k, n, smax):
        return STEP_REFUSED, -1
    res = np.empty(m, dtype=np.int64)
    res2 = np.empty(m, dtype=np.int64)
    # W[m + 1]: digits of half the product of the first m1 primes; W[m]: of all m
    _half(P, m1, W[m + 1])
    h1 = W[m + 1]
    for t in range(m1):
        res[t] = dm[t]
    sd = _sign(res, m1, P, Pinv, W, h1)
    # -- the float filter: the same quantities in floating point with a
    # rigorous bound on their error (_float_filter); a sign is read from the
    # float value only where that stands above its bound
    fa = np.empty(n)
    ea = np.empty(n)
    fb = np.empty(n)
    eb = np.empty(n)
    X = np.empty((k, k))
    einv = _float_filter(C, R, zrow, basis, entering, e_w, k, n, fa, ea, fb, eb, X)
    # -- the basis must be feasible and lexicographically positive
    sb = np.empty(n, dtype=np.int64)
    sa = np.empty(n, dtype=np.int64)
    for i in range(n):
        if abs(fb[i]) > eb[i]:
            sb[i] = 1 if fb[i] > 0.0 else -1
        else:
            for t in range(m1):
                res[t] = Nb[t, i]
            sb[i] = sd * _sign(res, m1, P, Pinv, W, h1)
        if sb[i] < 0:
            return STEP_REFUSED, -1
        if sb[i] == 0:
            # the first nonzero entry of row i of B^-1, column by column
            first = 0
            j = basis[i] if zrow[i] < 0 else n
            for t in range(k):
                if R[t] > j:
                    break
                s = _entry_sign(Zc, adj, P, Pinv, W, h1, m1, k, zrow[i], basis[i], t, res, C, X,
                                einv, sd)
                if s != 0:
                    first = s
                    break
            if first == 0 and j < n:
                first = 1  # det G / (det G 2^K) at column j
            if first <= 0:
                return STEP_REFUSED, -1
        if abs(fa[i]) > ea[i]:
            sa[i] = 1 if fa[i] > 0.0 else -1
        else:
            for t in range(m1):
                res[t] = Na[t, i]
            sa[i] = sd * _sign(res, m1, P, Pinv, W, h1)
    full = False
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
        # the sign of b_i a_r0 - b_r0 a_i (a_i, a_r0 > 0)
        if sb[i] == 0 or sb[r0] == 0:
            s = sb[i] - sb[r0]
        else:
            v = fb[i] * fa[r0] - fb[r0] * fa[i]
            e = (abs(fb[i]) * ea[r0] + eb[i] * abs(fa[r0]) + eb[i] * ea[r0]
                 + abs(fb[r0]) * ea[i] + eb[r0] * abs(fa[i]) + eb[r0] * ea[i])
            e = (e + 4.5e-16 * (abs(fb[i] * fa[r0]) + abs(fb[r0] * fa[i]))) * _SAFE
            if abs(v) > e:
                s = 1 if v > 0.0 else -1
            else:
                if not full:
                    if not _add_primes(m, maxbad, state, P_all, P, Pinv, dm, adj, Zc, Na, Nb, W,
                                       work, pow2, mant, ex, R, zrow, basis, entering, e_w, K, k,
                                       n, smax):
                        return STEP_REFUSED, -1
                    _half(P, m, W[m])
                    full = True
                for u in range(m):
                    p = P[u]
                    pinv = Pinv[u]
                    res[u] = _submod(_mulmod(Nb[u, i], Na[u, r0], p, pinv),
                                     _mulmod(Nb[u, r0], Na[u, i], p, pinv), p)
                s = _sign(res, m, P, Pinv, W, W[m])
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
            # (B^-1)_i / a_i against (B^-1)_r / a_r, column by column: the sign
            # of E_i A_r - E_r A_i, E the numerators of the entries of column
            # col and A those of a (both A of the sign of det G)
            ji = basis[i] if zrow[i] < 0 else -1
            jr = basis[r] if zrow[r] < 0 else -1
            for col in range(n):
                tc = rpos[col]
                if tc < 0 and col != ji and col != jr:
                    continue
                if tc >= 0:
                    si = _entry_sign(Zc, adj, P, Pinv, W, h1, m1, k, zrow[i], basis[i], tc, res,
                                     C, X, einv, sd)
                    sr = _entry_sign(Zc, adj, P, Pinv, W, h1, m1, k, zrow[r], basis[r], tc, res,
                                     C, X, einv, sd)
                else:
                    # det G / (det G 2^K) > 0 in the row's own w column
                    si = 1 if col == ji else 0
                    sr = 1 if col == jr else 0
                if si == 0 and sr == 0:
                    continue
                if si == 0 or sr == 0:
                    # one entry zero: the sign of the other's term decides
                    s = -sr if si == 0 else si
                else:
                    if not full:
                        if not _add_primes(m, maxbad, state, P_all, P, Pinv, dm, adj, Zc, Na, Nb,
                                           W, work, pow2, mant, ex, R, zrow, basis, entering,
                                           e_w, K, k, n, smax):
                            return STEP_REFUSED, -1
                        _half(P, m, W[m])
                        full = True
                    if tc >= 0:
                        _entry_residues(Zc, adj, P, Pinv, m, k, zrow[i], basis[i], tc, res)
                        _entry_residues(Zc, adj, P, Pinv, m, k, zrow[r], basis[r], tc, res2)
                    else:
                        for u in range(m):
                            res[u] = dm[u] if col == ji else 0
                            res2[u] = dm[u] if col == jr else 0
                    for u in range(m):
                        p = P[u]
                        pinv = Pinv[u]
                        res[u] = _submod(_mulmod(res[u], Na[u, r], p, pinv),
                                         _mulmod(res2[u], Na[u, i], p, pinv), p)
                    s = _sign(res, m, P, Pinv, W, W[m])
                if s != 0:
                    if s < 0:
                        r = i
                    break
    # -- the right-hand side after the step: zero or positive, row by row.
    # With b_r = 0 the step changes no right-hand side but row r's (0)
    for i in range(n):
        if i == r or sb[r] == 0:
            flags[i] = 0.0 if sb[i] == 0 else np.nan
            continue
        if not full:
            if not _add_primes(m, maxbad, state, P_all, P, Pinv, dm, adj, Zc, Na, Nb, W, work,
                               pow2, mant, ex, R, zrow, basis, entering, e_w, K, k, n, smax):
                return STEP_REFUSED, -1
            _half(P, m, W[m])
            full = True
        zero = True
        for u in range(m):
            p = P[u]
            pinv = Pinv[u]
            if _mulmod(Nb[u, i], Na[u, r], p, pinv) != _mulmod(Na[u, i], Nb[u, r], p, pinv):
                zero = False
                break
        flags[i] = 0.0 if zero else np.nan
    return STEP_PIVOT, basis[r]


@njit(cache=True)
def _half(P, m, out):
    # the mixed-radix digits of (prod P[:m] - 1) / 2, halved from the top digit
    rem = np.int64(0)
    for i in range(m - 1, -1, -1):
        x = rem * P[i] + (P[i] - 1)
        out[i] = x // 2
        rem = x % 2


@njit(cache=True)
def _add_primes(target, maxbad, state, P_all, P, Pinv, dm, adj, Zc, Na, Nb, W, work, pow2, mant,
                ex, R, zrow, basis, entering, e_w, K, k, n, smax):
    # Residues for primes state[0] .. target - 1 (the data Zc, det G, adj G,
    # the numerators Na of the entering column and Nb of q in every row), from
    # the table entry state[1] on, skipping primes that divide det G, and the
    # mixed-radix rows of W (see _sign). False when more primes divide det G
    # than a nonzero one allows (it is zero: a singular basis) or the table ends.
    G = work[:, :2 * k]
    ya = work[:, 2 * k]
    yb = work[:, 2 * k + 1]
    used = state[0]
    pi = state[1]
    NP = P_all.shape[0]
    while used < target:
        if pi >= NP:
            return False
        p, pinv = _prime_powers(P_all, pi, pow2, smax)
        pi += 1
        Zu = Zc[used]
        for c in range(k + 2):
            for a in range(n):
                Zu[c, a] = _to_residue(mant[c, a], ex[c, a], p, pinv, pow2)
        if e_w:
            Zu[k, entering] = pow2[K]
        # [G | I] -> [I | G^-1] by Gauss-Jordan mod p, det along
        for a in range(k):
            for b in range(k):
                G[a, b] = Zu[b, R[a]]
                G[a, k + b] = 1 if a == b else 0
        det = np.int64(1)
        ok = True
        for col in range(k):
            piv = _first_nonzero(G, col, k)
            if piv < 0:
                ok = False
                break
            if piv != col:
                _swap_rows(G, col, piv)
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
            # this prime divides det G
            maxbad -= 1
            if maxbad < 0:
                return False
            continue
        P[used] = p
        Pinv[used] = pinv
        dm[used] = det
        for a in range(k):
            acc_a = np.int64(0)
            acc_b = np.int64(0)
            for b in range(k):
                g = _mulmod(det, G[a, k + b], p, pinv)
                adj[used, a, b] = g
                acc_a = _addmod(acc_a, _mulmod(g, Zu[k, R[b]], p, pinv), p)
                acc_b = _addmod(acc_b, _mulmod(g, Zu[k + 1, R[b]], p, pinv), p)
            ya[a] = acc_a
            yb[a] = acc_b
        # Z rows: adj c_R; the row of w_j: det c_j - B[j, Z] adj c_R
        for i in range(n):
            zi = zrow[i]
            if zi >= 0:
                Na[used, i] = ya[zi]
                Nb[used, i] = yb[zi]
            else:
                j = basis[i]
                acc_a = _mulmod(det, Zu[k, j], p, pinv)
                acc_b = _mulmod(det, Zu[k + 1, j], p, pinv)
                for c in range(k):
                    g = Zu[c, j]
                    if g != 0:
                        acc_a = _submod(acc_a, _mulmod(g, ya[c], p, pinv), p)
                        acc_b = _submod(acc_b, _mulmod(g, yb[c], p, pinv), p)
                Na[used, i] = acc_a
                Nb[used, i] = acc_b
        # mixed radix: p_j mod p, the inverse of the product of the earlier primes
        _radix_row(W, P, used, p, pinv)
        used += 1
    state[0] = used
    state[1] = pi
    return True


@njit(cache=True)
def _entry_residues(Zc, adj, P, Pinv, m, k, zi, v, t, res):
    # residues of the numerator of (B^-1)_(i, R[t]) for the row i holding z
    # variable zi (adj[zi, t]) or w_v (-B[v, Z] adj[:, t])
    for u in range(m):
        if zi >= 0:
            res[u] = adj[u, zi, t]
        else:
            p = P[u]
            pinv = Pinv[u]
            acc = np.int64(0)
            for c in range(k):
                g = Zc[u, c, v]
                if g != 0:
                    acc = _addmod(acc, _mulmod(g, adj[u, c, t], p, pinv), p)
            res[u] = _submod(0, acc, p)


@njit(cache=True)
def _entry_sign(Zc, adj, P, Pinv, W, half, m, k, zi, v, t, res, C, X, einv, sd):
    # the sign of the entry (B^-1)_(i, R[t]) (see _entry_residues): 0 when its
    # numerator is zero, else that of the float value where the filter decides
    # it, else sd (the sign of det G) times that of its numerator
    _entry_residues(Zc, adj, P, Pinv, m, k, zi, v, t, res)
    nz = False
    for u in range(m):
        if res[u] != 0:
            nz = True
            break
    if not nz:
        return 0
    if einv < np.inf:
        if zi >= 0:
            x = X[zi, t]
            e = einv
        else:
            # -(B[v, Z] G^-1)[:, t], B[v, Z] = C[:k, v]
            x = 0.0
            e = 0.0
            for c in range(k):
                x -= C[c, v] * X[c, t]
                e += abs(C[c, v]) * (einv + 2.3e-16 * (k + 2) * abs(X[c, t]))
        if abs(x) > e * _SAFE:
            return 1 if x > 0.0 else -1
    return sd * _sign(res, m, P, Pinv, W, half)


@njit(cache=True)
def _approx_inverse(G, X, k, gk):
    # X ~ G^-1 by Gauss-Jordan with partial pivoting, and (alpha, ||X||_inf),
    # each times _SAFE: alpha >= ||I - X G||_inf counting the rounding of X G
    # (gk = gamma_(k+2)), so that ||G^-1 - X||_inf <= alpha ||X||_inf / (1 -
    # alpha) where alpha < 1 (Neumann series). alpha is inf where a pivot is
    # zero or X is not finite.
    A = np.empty((k, 2 * k))
    for a in range(k):
        for b in range(k):
            A[a, b] = G[a, b]
            A[a, k + b] = 1.0 if a == b else 0.0
    for col in range(k):
        piv = col
        big = 0.0
        for a in range(col, k):
            if abs(A[a, col]) > big:
                big = abs(A[a, col])
                piv = a
        if not big > 0.0:
            return np.inf, np.inf
        if piv != col:
            _swap_rows(A, col, piv)
        inv = 1.0 / A[col, col]
        for b in range(2 * k):
            A[col, b] *= inv
        for a in range(k):
            f = A[a, col]
            if a != col and f != 0.0:
                for b in range(2 * k):
                    A[a, b] -= f * A[col, b]
    for a in range(k):
        for b in range(k):
            X[a, b] = A[a, k + b]
            if not abs(X[a, b]) < np.inf:
                return np.inf, np.inf
    alpha = 0.0
    nX = 0.0
    for a in range(k):
        row = 0.0
        xrow = 0.0
        for b in range(k):
            acc = 1.0 if a == b else 0.0
            mag = 0.0
            for c in range(k):
                g = G[c, b]
                acc -= X[a, c] * g
                mag += abs(X[a, c] * g)
            row += abs(acc) + gk * (mag + 1.0)
            xrow += abs(X[a, b])
        alpha = max(alpha, row)
        nX = max(nX, xrow)
    # every bound is a sum of non-negative terms, computed with a relative
    # error below gamma_n: _SAFE covers that for any n below 10^5
    return alpha * _SAFE, nX * _SAFE


@njit(cache=True)
def _float_filter(C, R, zrow, basis, entering, e_w, k, n, fa, ea, fb, eb, X):
    # The entering column a = B^-1 A_e and b = B^-1 q in floating point (fa,
    # fb), each entry with a rigorous bound on its error (ea, eb; inf where
    # none holds), and X ~ G^-1 with the bound of its entries' error (returned;
    # inf where none holds). X by Gauss-Jordan; with E = I - X G and
    # alpha >= ||E||_inf counting the rounding of X G, ||G^-1||_inf <=
    # ||X||_inf / (1 - alpha) and ||G^-1 - X||_inf <= alpha ||X||_inf / (1 - alpha)
    # (Neumann series). For x~ ~ G^-1 c_R, x - x~ = G^-1 r with r = c_R - G x~,
    # computed with its own rounding bound. A w row's entry c_j - B[j, Z] x
    # adds its own rounding. u = 2^-53; gamma_j = j u / (1 - j u) < 1.01 j u.
    u = 2.0**-53
    gk = 1.01 * (k + 2) * u
    for i in range(n):
        ea[i] = np.inf
        eb[i] = np.inf
        fa[i] = 0.0
        fb[i] = 0.0
    G = np.empty((k, k))
    for a in range(k):
        for b in range(k):
            G[a, b] = C[b, R[a]]
    alpha, nX = _approx_inverse(G, X, k, gk)
    if not alpha < 0.5:
        return np.inf
    einv = alpha * nX / (1.0 - alpha) * _SAFE
    x = np.empty(k)
    for which in range(2):
        cr = k + 1 if which == 1 else k
        # x~ = X c_R
        for a in range(k):
            acc = 0.0
            for b in range(k):
                cb = (1.0 if R[b] == entering else 0.0) if (which == 0 and e_w) else C[cr, R[b]]
                acc += X[a, b] * cb
            x[a] = acc
        # r = c_R - G x~ with its rounding; the bound of x - x~ in every entry
        rmax = 0.0
        for a in range(k):
            ca = (1.0 if R[a] == entering else 0.0) if (which == 0 and e_w) else C[cr, R[a]]
            acc = ca
            mag = abs(ca)
            for c in range(k):
                g = C[c, R[a]]
                acc -= g * x[c]
                mag += abs(g * x[c])
            rmax = max(rmax, abs(acc) + gk * mag)
        ez = nX * rmax / (1.0 - alpha) * _SAFE
        out = fa if which == 0 else fb
        err = ea if which == 0 else eb
        for i in range(n):
            zi = zrow[i]
            if zi >= 0:
                out[i] = x[zi]
                err[i] = ez
            else:
                j = basis[i]
                cj = (1.0 if j == entering else 0.0) if (which == 0 and e_w) else C[cr, j]
                acc = cj
                mag = abs(cj)
                gs = 0.0
                for c in range(k):
                    g = C[c, j]
                    acc -= g * x[c]
                    mag += abs(g * x[c])
                    gs += abs(g)
                out[i] = acc
                err[i] = (gs * ez + gk * mag) * _SAFE
            if not abs(out[i]) < np.inf or not err[i] < np.inf:
                err[i] = np.inf
    return einv


@njit(cache=True)
def _powmod2(e, p, pinv):
    # 2^e mod p, e >= 0
    r = np.int64(1)
    b = np.int64(2)
    while e > 0:
        if e & 1:
            r = _mulmod(r, b, p, pinv)
        b = _mulmod(b, b, p, pinv)
        e >>= 1
    return r


# the correct rounding of a component walks at most this many ulps from the guess
_MAX_WALK = 64


@njit(cache=True)
def exact_point(M, q, J, P_all, z, use_filter=True):
    """The point of a complementary basis, exactly, correctly rounded (compiled).

    The result of :func:`moreau.lcp._exact.basis_point` (``M_JJ z_J = -q_J``,
    ``z = 0`` off ``J``, each entry the float nearest the exact rational,
    ties to even), computed by residues: ``z_j = N_j / det M_JJ`` with Cramer's
    numerators ``N_j``, and the float nearest it found from the guess in ``z``
    by comparing ``N_j / det`` with the midpoints between neighbouring floats,
    each comparison the sign of an integer (see the module's text).

    Parameters
    ----------
    M, q : ndarray
        The data (read exactly).
    J : int64[:]
        The basic ``z`` variables.
    P_all : int64[:]
        The moduli (:func:`primes`).
    z : float64[:], shape (n,)
        A guess of the point on entry (within a few ulps: the floating-point
        path's); the exact point, correctly rounded, on success.
    use_filter : bool
        First try the float filter (one refinement step with a rigorous error
        bound, decisive unless a component is zero or near a midpoint); the
        residues are computed only where it cannot decide.

    Returns
    -------
    bool
        False (``z`` then untouched) where this cannot decide: ``M_JJ``
        singular, a point outside the range of floats, a guess too far off,
        more moduli than the table holds.

    Examples
    --------
    >>> import numpy as np
    >>> z = np.full(2, 1 / 3 - 2e-16)   # a guess a few ulps off
    >>> exact_point(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -1.0]),
    ...             np.array([0, 1]), primes(), z, True)
    True
    >>> z.tolist()
    [0.3333333333333333, 0.3333333333333333]
    """
    n = q.shape[0]
    k = J.shape[0]
    if k == 0:
        for j in range(n):
            z[j] = 0.0
        return True
    if use_filter and _point_filter(M, q, J, z):
        return True
    # integer data: the columns of M_JJ, then -q_J, times one 2^K
    mant = np.empty((k + 1, k), dtype=np.int64)
    ex = np.empty((k + 1, k), dtype=np.int64)
    emin = 0
    for c in range(k + 1):
        for a in range(k):
            v = M[J[a], J[c]] if c < k else -q[J[a]]
            fm, fe = math.frexp(v)
            mant[c, a] = np.int64(fm * 2.0**53)
            ex[c, a] = fe - 53
            if fm != 0.0 and fe - 53 < emin:
                emin = fe - 53
    K = -emin
    smax = np.int64(0)  # not a literal (see modular_step's k)
    logP = 0.0
    for c in range(k + 1):
        amax = 0.0
        acc = 0.0
        for a in range(k):
            if mant[c, a] != 0:
                ex[c, a] += K
                smax = max(smax, ex[c, a])
            else:
                ex[c, a] = 0
            v = M[J[a], J[c]] if c < k else q[J[a]]
            amax = max(amax, abs(v))
        if amax == 0.0:
            if c < k:
                return False  # a zero column: M_JJ singular
            continue
        for a in range(k):
            v = M[J[a], J[c]] if c < k else q[J[a]]
            acc += (v / amax) ** 2
        logP += max(K + math.log2(amax) + 0.5 * math.log2(acc) + 1e-6, 0.0)
    # |N_j|, |det| <= 2^logP (Hadamard); a comparison of |N| 2^-F with |det| T
    # (F < 0) or of |N| with |det| T 2^F (F >= 0), T < 2^55, for the midpoints
    # T 2^F of floats near the guess: below 2^(logP + max(|F|, 55) + 1)... +1
    # the exponents F of the midpoints within a few ulps of the guesses: the
    # largest -F below zero and F above
    fneg = 0
    fpos = 0
    for a in range(k):
        y = abs(z[J[a]])
        if not y < np.inf:
            return False
        fc = math.frexp(y)[1] - 54 if y > 0.0 else -1076
        fneg = max(fneg, 4 - fc)
        fpos = max(fpos, fc + 4)
    bits = logP + 3.0 + max(55.0, float(fneg), fpos + 55.0)
    m = int(bits / 49.0) + 1
    # the largest |F| for which each kind of comparison stays inside half the
    # moduli's product
    capneg = 49.0 * m - logP - 3.0
    cappos = 49.0 * m - logP - 58.0
    maxbad = int(logP / 49.0) + 1
    if m + maxbad > P_all.shape[0]:
        return False
    P = np.empty(m, dtype=np.int64)
    Pinv = np.empty(m)
    dm = np.empty(m, dtype=np.int64)
    N = np.empty((m, k), dtype=np.int64)
    A = np.empty((k, k + 1), dtype=np.int64)
    W = np.zeros((m + 2, m), dtype=np.int64)
    pow2 = np.empty(smax + 1, dtype=np.int64)
    used = np.int64(0)  # not literals (see modular_step's k)
    bad = 0
    pi = np.int64(0)
    # the rows the elimination swaps in, as for the first prime: the same for
    # every prime means that each entry tested for zero was zero exactly when
    # it was zero modulo all of them (a nonzero minor is below their product),
    # i.e. the swaps are those of the exact elimination (_exact.basis_point's,
    # whose determinant gives an exact zero its sign)
    seq = np.empty(k, dtype=np.int64)
    inv_d = np.empty(k + 1, dtype=np.int64)
    swaps = 0
    while used < m:
        if pi >= P_all.shape[0]:
            return False
        p, pinv = _prime_powers(P_all, pi, pow2, smax)
        pi += 1
        for c in range(k + 1):
            for a in range(k):
                A[a, c] = _to_residue(mant[c, a], ex[c, a], p, pinv, pow2)
        nsw = 0
        # Gaussian elimination mod p without divisions (a row below the pivot
        # becomes piv row - f pivot row: det gains the factor piv), then back
        # substitution with the inverses of the diagonal and of those factors
        # taken at once (one modular inverse a prime): x = A^-1 c, N = det x
        det = np.int64(1)
        mult = np.int64(1)
        ok = True
        for col in range(k):
            piv = _first_nonzero(A, col, k)
            if piv < 0:
                ok = False
                break
            if used == 0:
                seq[col] = piv
            elif seq[col] != piv:
                return False
            if piv != col:
                _swap_rows(A, col, piv)
                det = _submod(0, det, p)
                nsw += 1
            pv = A[col, col]
            for a in range(col + 1, k):
                f = A[a, col]
                if f != 0:
                    mult = _mulmod(mult, pv, p, pinv)
                    for b in range(col + 1, k + 1):
                        A[a, b] = _submod(_mulmod(pv, A[a, b], p, pinv),
                                          _mulmod(f, A[col, b], p, pinv), p)
        if not ok:
            if used > 0:
                return False  # the first prime's pivots were not the exact ones
            bad += 1
            if bad > maxbad:
                return False  # det M_JJ = 0
            continue
        swaps = nsw
        # inverses of U_00 .. U_(k-1)(k-1) and of mult, by one inversion
        acc = np.int64(1)
        for a in range(k):
            inv_d[a] = acc
            acc = _mulmod(acc, A[a, a], p, pinv)
            det = _mulmod(det, A[a, a], p, pinv)
        inv_d[k] = acc
        acc = _mulmod(acc, mult, p, pinv)
        inv = _invmod(acc, p)
        inv_mult = _mulmod(inv, inv_d[k], p, pinv)
        inv = _mulmod(inv, mult, p, pinv)
        for a in range(k - 1, -1, -1):
            t = _mulmod(inv, inv_d[a], p, pinv)
            inv = _mulmod(inv, A[a, a], p, pinv)
            inv_d[a] = t
        det = _mulmod(det, inv_mult, p, pinv)
        for a in range(k - 1, -1, -1):
            acc = A[a, k]
            for b in range(a + 1, k):
                acc = _submod(acc, _mulmod(A[a, b], A[b, k], p, pinv), p)
            A[a, k] = _mulmod(acc, inv_d[a], p, pinv)
        P[used] = p
        Pinv[used] = pinv
        dm[used] = det
        for a in range(k):
            N[used, a] = _mulmod(det, A[a, k], p, pinv)
        _radix_row(W, P, used, p, pinv)
        used += 1
    half = W[m]
    _half(P, m, half)
    res = np.empty(m, dtype=np.int64)
    for t in range(m):
        res[t] = dm[t]
    sd = _sign(res, m, P, Pinv, W, half)
    out = np.empty(k)
    pw = np.empty(m, dtype=np.int64)
    fcache = np.array([np.int64(1) << 40])
    for a in range(k):
        for t in range(m):
            res[t] = N[t, a]
        sn = _sign(res, m, P, Pinv, W, half)
        if sn == 0:
            # 0 / det of the row-swapped matrix: a zero of that determinant's sign
            out[a] = 0.0 if sd * (1 - 2 * (swaps % 2)) > 0 else -0.0
            continue
        # |z_j| = |N| / |det|: residues of both magnitudes
        sgn = sn * sd
        y = abs(z[J[a]])
        if not y > 0.0:
            y = 5e-324
        done = False
        # after a step up, the new lower midpoint is the old upper one, which
        # the value lies above (and the converse after a step down)
        known = 0
        for _ in range(_MAX_WALK):
            # y = Y 2^E exactly (Y < 2^53, E >= -1074)
            fm, fe = math.frexp(y)
            E = max(fe - 53, -1074)
            Y = np.int64(math.ldexp(y, -E))
            # the midpoints T 2^F above and below y (below: half the ulp below
            # at the bottom of a binade)
            if known == -1:
                cmp_hi = -1
            else:
                cmp_hi = _cmp_mid(N, dm, a, sn, sd, 2 * Y + 1, E - 1, m, P, Pinv, W, half, res,
                                  capneg, cappos, pw, fcache)
            if cmp_hi == 2:
                return False
            if known == 1 or cmp_hi > 0:
                cmp_lo = 1
            elif Y == (np.int64(1) << 52) and E > -1074:
                cmp_lo = _cmp_mid(N, dm, a, sn, sd, 4 * Y - 1, E - 2, m, P, Pinv, W, half, res,
                                  capneg, cappos, pw, fcache)
            else:
                cmp_lo = _cmp_mid(N, dm, a, sn, sd, 2 * Y - 1, E - 1, m, P, Pinv, W, half, res,
                                  capneg, cappos, pw, fcache)
            if cmp_lo == 2:
                return False
            if cmp_hi > 0 or (cmp_hi == 0 and Y % 2 == 1):
                # above the upper midpoint (or on it with y odd): the next float up
                y = np.nextafter(y, np.inf)
                if not y < np.inf:
                    return False
                if cmp_hi == 0:
                    done = True
                    break
                known = 1
                continue
            if cmp_lo < 0 or (cmp_lo == 0 and Y % 2 == 1):
                y = np.nextafter(y, 0.0)
                if cmp_lo == 0:
                    done = True
                    break
                if not y > 0.0:
                    return False
                known = -1
                continue
            done = True
            break
        if not done:
            return False
        out[a] = y if sgn > 0 else -y
    for j in range(n):
        z[j] = 0.0
    for a in range(k):
        z[J[a]] = out[a]
    return True


@njit(cache=True)
def _cmp_mid(N, dm, a, sn, sd, T, F, m, P, Pinv, W, half, res, capneg, cappos, pw, fcache):
    # the sign of |N_a| / |det| - T 2^F (T > 0): of |N_a| 2^-F - |det| T when F < 0,
    # else of |N_a| - |det| T 2^F; 2 when that integer may exceed the moduli's
    # range. pw holds 2^|F| mod each prime for F = fcache[0] (made afresh for another F)
    if (F < 0 and -F > capneg) or (F >= 0 and F > cappos):
        return 2
    if fcache[0] != F:
        for u in range(m):
            pw[u] = _powmod2(abs(F), P[u], Pinv[u])
        fcache[0] = F
    for u in range(m):
        p = P[u]
        pinv = Pinv[u]
        nu = N[u, a] if sn > 0 else _submod(0, N[u, a], p)
        du = dm[u] if sd > 0 else _submod(0, dm[u], p)
        tu = _mulmod(du, _reduce(T, p, pinv), p, pinv)
        if F < 0:
            nu = _mulmod(nu, pw[u], p, pinv)
        else:
            tu = _mulmod(tu, pw[u], p, pinv)
        res[u] = _submod(nu, tu, p)
    return _sign(res, m, P, Pinv, W, half)


@njit(cache=True)
def _point_filter(M, q, J, z):
    # The float filter of exact_point: one step of refinement of the guess,
    # x~ + X r with the residual r = c - A x~ (A = M_JJ, c = -q_J) summed in
    # double-double from exact products, and a rigorous bound e of the error
    # (|A^-1 r - X r~| <= einv |r| + ||X|| |r - r~| + rounding, einv bounding
    # ||A^-1 - X|| as in _float_filter). Where every component's interval lies
    # strictly between the midpoints around one float, that float is the exact
    # point correctly rounded: z takes it, True. Otherwise (a zero component, a
    # value near a midpoint, data out of the safe range) False, z untouched.
    n = q.shape[0]
    k = J.shape[0]
    u = 2.0**-53
    gk = 1.01 * (k + 2) * u
    G = np.empty((k, k))
    for a in range(k):
        for b in range(k):
            v = M[J[a], J[b]]
            if not abs(v) < 2.0**500 or (v != 0.0 and abs(v) < 2.0**-400):
                return False
            G[a, b] = v
        x = z[J[a]]
        if not abs(x) < 2.0**400 or abs(x) < 2.0**-400 or abs(q[J[a]]) > 2.0**900:
            return False
    # X ~ A^-1 and its bound
    X = np.empty((k, k))
    alpha, nX = _approx_inverse(G, X, k, gk)
    if not alpha < 0.5 or not nX < 2.0**400:
        return False
    einv = alpha * nX / (1.0 - alpha) * _SAFE
    # r = c - A x~ in double-double: exact products, compensated sums
    r = np.empty(k)
    rerr = 0.0
    for a in range(k):
        hi = -q[J[a]]
        lo = 0.0
        tot = abs(hi)
        for b in range(k):
            p, e = two_prod(M[J[a], J[b]], z[J[b]])
            if p != 0.0 and abs(p) < 2.0**-900:
                return False
            tot += abs(p)
            # hi + lo -= p + e (TwoSum on the high parts)
            s_ = hi - p
            bb = s_ - hi
            lo += (hi - (s_ - bb)) + (-p - bb) - e
            hi = s_
        ra = hi + lo
        r[a] = ra
        # the double-double sum's error (lo, of order k u tot, summed 2 k times
        # with rounding) and the rounding of hi + lo
        rerr = max(rerr, 2.0 * (2 * k + 2) ** 2 * u * u * tot + u * abs(ra))
    rmax = 0.0
    for a in range(k):
        rmax = max(rmax, abs(r[a]))
    # delta = X r~ and the bound of its error against A^-1 r
    err = (einv * (rmax + rerr) + nX * rerr) * _SAFE
    out = np.empty(k)
    for a in range(k):
        dl = 0.0
        mag = 0.0
        for b in range(k):
            t = X[a, b] * r[b]
            dl += t
            mag += abs(t)
        e = (err + gk * mag) * _SAFE
        x0 = z[J[a]]
        y = x0 + dl
        if y == 0.0 or not abs(y - x0) <= 0.5 * abs(x0):
            return False
        # the exact value lies within e of x0 + dl = y + d
        d = (x0 - y) + dl
        ay = abs(y)
        up = np.nextafter(ay, np.inf) - ay
        down = ay - np.nextafter(ay, 0.0)
        if y < 0.0:
            up, down = down, up
        # d's own rounding (x0 - y is exact: Sterbenz) and that of the sums below
        slack = (e + 4.0 * u * abs(d)) * 1.01
        if not (d + slack < 0.5 * up and d - slack > -0.5 * down):
            return False
        out[a] = y
    for j in range(n):
        z[j] = 0.0
    for a in range(k):
        z[J[a]] = out[a]
    return True


# _point_filter inlines _certified.two_prod: the on-disk cache follows that file too
_jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    (__file__, _certified.__file__))
