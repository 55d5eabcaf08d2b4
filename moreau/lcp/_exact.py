"""Lemke's method in exact arithmetic: the path the floating-point kernel hands over to.

Every float is a dyadic rational, so the data ``(M, q, d)`` times one power of
two ``2^K`` are integers, and ``LCP(2^K M, 2^K q)`` with covering ``2^K d``
has the same solutions and, for the lexicographic rule, the same pivots: the
tableau of a basis only changes its rows by positive factors and its ``B^-1``
part by one common factor, neither of which changes a ratio or a
lexicographic order.

The tableau ``[I, -M, -d | q]`` is kept in integer-preserving (Edmonds,
"fraction-free") form: integers ``T`` and a denominator ``D > 0`` with the
current tableau ``B^-1 [A | q] = T / D``. A pivot on ``(r, s)`` maps ``T_ij``
to ``(T_ij T_rs - T_is T_rj) / D`` for ``i != r``, an exact division (the
entries are subdeterminants of the integer data), and sets ``D = T_rs``;
nothing is rounded and the integers grow only to the size of the largest
subdeterminant.

The ratio test is the lexicographic one of the kernel (Cottle, Pang and
Stone, *The Linear Complementarity Problem*, 1992, Sec. 4.9): among the rows
tied at the minimum ratio ``b_i / a_i``, the lexicographic minimum of
``(b_i, (B^-1)_i) / a_i``, with ``z0`` leaving at once when it is among them.
From a lexicographically positive basis (every row of ``[b, B^-1]`` has a
positive first nonzero entry) this rule keeps the basis lexicographically
positive and makes ``(b, B^-1)`` of the ``z0`` row strictly decrease, so no
basis repeats and the path ends, on a solution or a secondary ray.

Variables are numbered as in the kernel: ``w_j -> j``, ``z_j -> n + j``,
``z0 -> 2 n``.
"""

from fractions import Fraction

import numpy as np

__all__ = ["exact_lemke", "integer_data"]

SOLVED = 0
RAY = 1
MAX_ITER = 2


def integer_data(*arrays):
    """The arrays times one power of two ``2^K`` as Python integers (lists), and ``K``.

    Every finite float ``m 2^e`` (``m`` an odd integer) is an integer times
    ``2^K`` for ``K = -min(e)``; the conversion is exact.
    """
    emin = 0
    for a in arrays:
        a = np.asarray(a, dtype=float)
        nz = a[a != 0.0]
        if nz.size:
            mant, ex = np.frexp(nz)
            # a float m 2^e with |m| in [0.5, 1) has 53 bits: m 2^53 is an integer
            emin = min(emin, int(ex.min()) - 53)
    K = -emin
    out = []
    for a in arrays:
        a = np.asarray(a, dtype=float)
        flat = [_to_int(float(v), K) for v in a.reshape(-1)]
        if a.ndim == 2:
            m = a.shape[1]
            out.append([flat[i * m:(i + 1) * m] for i in range(a.shape[0])])
        else:
            out.append(flat)
    return out, K


def _to_int(x, K):
    num, den = x.as_integer_ratio()
    # den is a power of two dividing 2^K
    return num * ((1 << K) // den)


def _tableau(Mi, qi, di):
    # [I, -M, -d | q]: rows of Python ints, the right-hand side last
    n = len(qi)
    T = []
    for i in range(n):
        row = [0] * (2 * n + 2)
        row[i] = 1
        for j in range(n):
            row[n + j] = -Mi[i][j]
        row[2 * n] = -di[i]
        row[2 * n + 1] = qi[i]
        T.append(row)
    return T


def _pivot(T, D, r, s):
    # integer-preserving Gauss-Jordan step on (r, s); returns the new D (> 0)
    Tr = T[r]
    p = Tr[s]
    for i in range(len(T)):
        if i == r:
            continue
        Ti = T[i]
        f = Ti[s]
        if f == 0:
            # T_ij p / D: still exact (D divides p T_ij for the new denominator p)
            T[i] = [(x * p) // D for x in Ti]
        else:
            T[i] = [(x * p - f * y) // D for x, y in zip(Ti, Tr)]
    if p < 0:
        for i in range(len(T)):
            T[i] = [-x for x in T[i]]
        p = -p
    return p


def _lex_less(T, n, i, k, s):
    # row i's (b_i, B^-1_i) / a_i lexicographically below row k's? (a_i, a_k > 0;
    # the common denominator D cancels; B^-1 is the w block, columns 0..n-1)
    ai = T[i][s]
    ak = T[k][s]
    for j in [2 * n + 1] + list(range(n)):
        xi = T[i][j] * ak
        xk = T[k][j] * ai
        if xi != xk:
            return xi < xk
    return False  # proportional rows: B singular, cannot happen


def lex_positive(T, n):
    """Whether every row of ``[b, B^-1]`` has a positive first nonzero entry (``D > 0``)."""
    for row in T:
        for j in [2 * n + 1] + list(range(n)):
            if row[j] != 0:
                if row[j] < 0:
                    return False
                break
        else:
            return False
    return True


def _from_basis(Mi, qi, di, basis):
    # the tableau of a given basis, by integer pivots from the all-w basis
    n = len(qi)
    T = _tableau(Mi, qi, di)
    D = 1
    rows = list(range(n))  # basic variable of each row
    for v in basis:
        if v < n:
            continue
        r = next((i for i in range(n) if rows[i] < n and rows[i] not in basis and T[i][v] != 0),
                 None)
        if r is None:
            return None, None, None
        D = _pivot(T, D, r, v)
        rows[r] = v
    return T, D, rows


def exact_lemke(M, q, d=None, *, basis=None, entering=None, max_iter=10**6, pivots=0, trace=None):
    """Lexicographic Lemke in exact integer arithmetic on the caller's floats.

    Parameters
    ----------
    M, q : ndarray
        The data (floats, read exactly).
    d : ndarray, optional
        Covering vector (ones by default).
    basis, entering : sequence of int and int, optional
        Resume from this basis (the basic variable of every row, ``z0``
        among them) with ``entering`` to enter next; used when it is
        lexicographically positive, else the path starts afresh.
    max_iter : int
        Pivot limit (counting ``pivots`` already made).
    pivots : int
        Pivots made before the hand-over (counted in the result).
    trace : list, optional
        Receives ``(entering, leaving)`` of every pivot after the first.

    Returns
    -------
    status : int
        0 solved, 1 secondary ray, 2 pivot limit.
    z : list of Fraction
        The terminal point (on a ray, the point where the ray starts).
    ray : list of Fraction or None
        ``(dz, dz0)`` on a secondary ray.
    pivots : int
    resumed : bool
        Whether the given basis was used.

    Examples
    --------
    >>> import numpy as np
    >>> st, z, ray, piv, _ = exact_lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -1.0]))
    >>> st, [str(v) for v in z], piv
    (0, ['1/3', '1/3'], 3)
    """
    n = len(q)
    if d is None:
        d = np.ones(n)
    (Mi, qi, di), _ = integer_data(M, q, d)
    z0 = 2 * n
    if min(qi) >= 0:
        return SOLVED, [Fraction(0)] * n, None, 0, False
    resumed = False
    T = None
    if basis is not None and entering is not None and z0 in basis:
        T, D, rows = _from_basis(Mi, qi, di, list(basis))
        if T is not None and lex_positive(T, n) and all(row[2 * n + 1] >= 0 for row in T):
            resumed = True
        else:
            T = None
    if T is None:
        pivots = 0
        T = _tableau(Mi, qi, di)
        D = 1
        rows = list(range(n))
        # z0 enters at the lexicographic minimum of (q_i, e_i) / d_i: the
        # smallest q_i / d_i, ties to the larger index
        r = 0
        for i in range(1, n):
            # q_i / d_i <= q_r / d_r, cross-multiplied (d > 0)
            if qi[i] * di[r] <= qi[r] * di[i]:
                r = i
        D = _pivot(T, D, r, z0)
        leaving = rows[r]
        rows[r] = z0
        pivots = 1
        entering = leaving + n
    while pivots < max_iter:
        s = entering
        best = -1
        for i in range(n):
            a = T[i][s]
            if a <= 0:
                continue
            if best < 0:
                best = i
                continue
            # b_i / a_i against b_best / a_best
            lhs = T[i][2 * n + 1] * T[best][s]
            rhs = T[best][2 * n + 1] * a
            if lhs < rhs:
                best = i
            elif lhs == rhs:
                if rows[i] == z0 or (rows[best] != z0 and _lex_less(T, n, i, best, s)):
                    best = i
        if best < 0:
            zf = _point(T, D, rows, n)
            ray = [Fraction(0)] * (n + 1)
            for i in range(n):
                v = rows[i]
                if n <= v < 2 * n:
                    ray[v - n] = Fraction(-T[i][s], D)
                elif v == z0:
                    ray[n] = Fraction(-T[i][s], D)
            if n <= s < 2 * n:
                ray[s - n] = Fraction(1)
            return RAY, zf, ray, pivots, resumed
        # z0 among the tied rows leaves at once (checked above through the tie rule)
        r = best
        if trace is not None:
            trace.append((s, rows[r]))
        D = _pivot(T, D, r, s)
        pivots += 1
        leaving = rows[r]
        rows[r] = s
        if leaving == z0:
            return SOLVED, _point(T, D, rows, n), None, pivots, resumed
        entering = leaving + n if leaving < n else leaving - n
    return MAX_ITER, _point(T, D, rows, n), None, pivots, resumed


def _point(T, D, rows, n):
    z = [Fraction(0)] * n
    for i in range(n):
        v = rows[i]
        if n <= v < 2 * n:
            z[v - n] = Fraction(T[i][2 * n + 1], D)
    return z
