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

import time
from fractions import Fraction

import numpy as np

__all__ = ["exact_lemke", "exact_step", "basis_point", "integer_data"]

SOLVED = 0
RAY = 1
MAX_ITER = 2
#: the deadline given to :func:`exact_lemke` passed before the path's end
BUDGET = 3


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


def _from_basis(Mi, qi, di, basis, deadline=None):
    # the tableau of a given basis, by integer pivots from the all-w basis;
    # rows is BUDGET when the deadline passes first
    n = len(qi)
    T = _tableau(Mi, qi, di)
    D = 1
    rows = list(range(n))  # basic variable of each row
    for v in basis:
        if v < n:
            continue
        if deadline is not None and time.process_time() > deadline:
            return None, None, BUDGET
        r = next((i for i in range(n) if rows[i] < n and rows[i] not in basis and T[i][v] != 0),
                 None)
        if r is None:
            return None, None, None
        D = _pivot(T, D, r, v)
        rows[r] = v
    return T, D, rows


def exact_lemke(M, q, d=None, *, basis=None, entering=None, max_iter=10**6, pivots=0, trace=None,
                deadline=None):
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
    deadline : float, optional
        A ``time.process_time()`` value past which the path stops, checked
        between pivots (status :data:`BUDGET`, ``z`` None).

    Returns
    -------
    status : int
        0 solved, 1 secondary ray, 2 pivot limit, 3 the deadline passed.
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
        T, D, rows = _from_basis(Mi, qi, di, list(basis), deadline)
        if rows == BUDGET:
            return BUDGET, None, None, pivots, True
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
        if deadline is not None and time.process_time() > deadline:
            return BUDGET, None, None, pivots, resumed
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


def _column_ints(F):
    # the rows of the float array F as Python integers times one power of two
    # 2^K, K >= 0 (exact: a float is m 2^e with |m| < 2^53), and K
    mant, ex = np.frexp(F)
    m = (mant * 2.0**53).astype(np.int64)
    nz = m != 0
    e = ex.astype(np.int64) - 53
    K = max(0, -int(e[nz].min())) if nz.any() else 0
    sh = np.where(nz, e + K, 0)
    if sh.size == 0 or int(sh.max()) <= 9:
        # |m| < 2^53 shifted by at most 9 bits stays below 2^62: exact in int64
        # (data of one scale, the usual case), converted to Python integers at once
        return np.left_shift(m, sh).tolist(), K
    # the shifts as one object-array operation: Python integers, no per-entry bytecode
    return np.left_shift(m.astype(object), sh.astype(object)).tolist(), K


def exact_step(M, q, d, basis, entering):
    """The step of the lexicographic path at ``basis``, decided in exact arithmetic.

    Only what the ratio test reads is computed: with ``Z`` the basic
    variables other than the ``w``'s and ``R`` the rows whose ``w`` is not
    basic, ``B^-1`` follows from the ``k x k`` block ``G = A[R, Z]`` (``k =
    |Z|``) by fraction-free Gauss-Jordan, and each needed entry of ``B^-1 [A
    | q]`` costs ``O(k)`` integer operations: ``O(k^3 + n k^2)`` in all,
    against ``O(k n^2)`` for the whole tableau.

    Parameters
    ----------
    M, q, d : ndarray
        The data pivoted on (floats, read exactly) and the covering vector.
    basis : sequence of int
        The basic variable of every row (``w_j -> j``, ``z_j -> n + j``,
        ``z0 -> 2 n``; ``z0`` among them).
    entering : int
        The variable to enter.

    Returns
    -------
    tuple or None
        ``("pivot", leaving, b)`` with the variable the lexicographic rule
        removes (``2 n``, ``z0``, when it is among the tied rows: the path
        ends on a solution), ``("ray", None, b)`` when the entering column
        has no positive entry; ``b`` is the right-hand side ``B^-1 q`` of the
        basis after the step (on a ray, of this one), row by row of
        ``basis`` (the entering variable in the leaving one's row), each
        correctly rounded to a float (exact zeros stay zeros). None when
        the basis is singular or not
        lexicographically positive for the data (a right-hand side below
        zero, or a zero one whose row of ``B^-1`` starts negative): no
        exact step can start from it; None too when a right-hand side after
        the step lies outside the range of floats (the floating path cannot
        go on from there; the exact path can).

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[2.0, 1.0], [1.0, 2.0]])
    >>> kind, leaving, b = exact_step(M, np.array([-1.0, -1.0]), np.ones(2), [0, 4], 3)
    >>> kind, leaving, b   # z0 = 1 in row 1, z_1 enters: w_0 = -z_1 leaves at 0
    ('pivot', 0, [0.0, 1.0])
    """
    n = len(q)
    z0 = 2 * n
    basis = [int(v) for v in basis]
    entering = int(entering)
    Z = [v for v in basis if v >= n]
    wb = {v for v in basis if v < n}
    R = [j for j in range(n) if j not in wb]
    k = len(Z)
    if len(R) != k or len(set(basis)) != n or entering in basis:
        return None
    cols = [(-M[:, v - n] if v < z0 else -d) for v in Z]
    e_w = entering < n
    if not e_w:
        cols.append(-M[:, entering - n])
    cols.append(q)
    ints, K = _column_ints(np.array(cols, dtype=float))
    A = np.array(ints[:k] or np.zeros((0, n), dtype=np.int64), dtype=object).reshape(k, n)
    # fraction-free Gauss-Jordan on [G | I], G = A[R, Z]: G^-1 = Y / D with D > 0
    T = [[ints[c][R[a]] for c in range(k)] + [1 if a == b else 0 for b in range(k)]
         for a in range(k)]
    D = 1
    used = [False] * k
    prow = [0] * k
    for c in range(k):
        r = next((a for a in range(k) if not used[a] and T[a][c] != 0), None)
        if r is None:
            return None
        D = _pivot(T, D, r, c)
        used[r] = True
        prow[c] = r
    Y = np.array([T[prow[c]][k:] for c in range(k)], dtype=object).reshape(k, k)
    # numerators of (B^-1)_{i c} for c in R (the tableau column of w_c over 2^K;
    # the other columns hold D on the row of a basic w_c, 0 elsewhere): -P[j]
    # on the row of a basic w_j, Y[c'] on the row of z variable Z[c']
    P = A.T.dot(Y) if k else np.zeros((n, 0), dtype=object)
    zi = {v: c for c, v in enumerate(Z)}
    Rarr = np.array(R, dtype=np.int64)

    def numer(a):
        # numerators of B^-1 a row by row, over D (Z rows) or D 2^K (w rows): both > 0
        a = np.array(a, dtype=object)
        y = Y.dot(a[Rarr]) if k else a[:0]
        nw = D * a - (y.dot(A) if k else 0)
        return [nw[v] if v < n else y[zi[v]] for v in basis]

    def binv_row(i):
        # the nonzero numerators of row i of B^-1, by column, in column order
        v = basis[i]
        if v < n:
            ent = {R[t]: -P[v, t] for t in range(k)}
            ent[v] = D
        else:
            ent = {R[t]: Y[zi[v], t] for t in range(k)}
        return [ent[c] for c in sorted(ent)], sorted(ent)

    bq = numer(ints[-1])
    for i in range(n):
        if bq[i] > 0:
            continue
        if bq[i] < 0:
            return None
        # the first nonzero of row i of B^-1 (R is sorted): on a w_j row the
        # entries -P[j, t] of the columns R[t] < j, then D > 0 at column j
        v = basis[i]
        if v < n:
            first = next((-P[v, t] for t in range(k) if R[t] < v and P[v, t] != 0), D)
        else:
            first = next((x for x in Y[zi[v]] if x != 0), 0)
        if first <= 0:
            return None
    if e_w:
        # the column of w_c in the integer data: 2^K e_c
        ae = numer([1 << K if j == entering else 0 for j in range(n)])
    else:
        ae = numer(ints[k])
    best = []
    for i in range(n):
        if ae[i] <= 0:
            continue
        if not best:
            best = [i]
            continue
        lhs = bq[i] * ae[best[0]]
        rhs = bq[best[0]] * ae[i]
        if lhs < rhs:
            best = [i]
        elif lhs == rhs:
            best.append(i)
    # the true right-hand side is bq_i / D on a Z row and bq_i / (D 2^K) on a w row
    den = [D if v >= n else D << K for v in basis]
    if not best:
        try:
            return "ray", None, [x / dd for x, dd in zip(bq, den)]
        except OverflowError:
            return None
    z0_rows = [i for i in best if basis[i] == z0]
    if z0_rows:
        r = z0_rows[0]
    else:
        r = best[0]
        for i in best[1:]:
            # (B^-1)_i / a_i against (B^-1)_r / a_r, column by column
            vi, ci = binv_row(i)
            vr, cr = binv_row(r)
            di = dict(zip(ci, vi))
            dr = dict(zip(cr, vr))
            for c in sorted(set(ci) | set(cr)):
                xi = di.get(c, 0) * ae[r]
                xr = dr.get(c, 0) * ae[i]
                if xi != xr:
                    if xi < xr:
                        r = i
                    break
    # the pivot: b_r / a_r in row r, b_i - a_i b_r / a_r in the others (the
    # row denominators cancel in a_i / a_r); a row with a_i = 0 keeps b_i, the
    # same rational with smaller integers (int / int rounds correctly either way)
    br, ar = bq[r], ae[r]
    try:
        b = [br / ar if i == r else ((bq[i] * ar - ae[i] * br) / (ar * den[i]) if ae[i]
                                     else bq[i] / den[i]) for i in range(n)]
    except OverflowError:
        return None
    return "pivot", basis[r], b


def basis_point(M, q, J):
    """The point of the complementary basis whose basic ``z`` are ``J``, exactly, rounded to floats.

    Solves ``M_JJ z_J = -q_J`` in exact arithmetic (Bareiss's fraction-free
    elimination on the data as integers), ``z = 0`` off ``J``; each entry
    correctly rounded. None when ``M_JJ`` is singular or the point lies
    outside the range of floats.

    Examples
    --------
    >>> import numpy as np
    >>> basis_point(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -1.0]), [0, 1])
    [0.3333333333333333, 0.3333333333333333]
    """
    n = len(q)
    k = len(J)
    z = [0.0] * n
    if k == 0:
        return z
    # the columns of M_JJ, then -q_J, as the rows of one array (one gather: an
    # index list per column costs more than the elimination at small k)
    Ji = np.asarray(J, dtype=np.intp)
    cols = np.empty((k + 1, k))
    cols[:k] = M[np.ix_(Ji, Ji)].T
    cols[k] = -q[Ji]
    ints, _ = _column_ints(cols)
    # Bareiss's fraction-free elimination on [M_JJ | -q_J] (every entry stays
    # an integer minor), then back-substitution for X = det z_J, also in integers
    T = [[ints[c][a] for c in range(k + 1)] for a in range(k)]
    prev = 1
    for c in range(k):
        r = next((a for a in range(c, k) if T[a][c] != 0), None)
        if r is None:
            return None
        if r != c:
            T[c], T[r] = T[r], T[c]
        Tc = T[c]
        p = Tc[c]
        for a in range(c + 1, k):
            Ta = T[a]
            f = Ta[c]
            T[a] = [0] * (c + 1) + [(Ta[j] * p - f * Tc[j]) // prev for j in range(c + 1, k + 1)]
        prev = p
    det = T[k - 1][k - 1]
    X = [0] * k
    for c in range(k - 1, -1, -1):
        Tc = T[c]
        X[c] = (det * Tc[k] - sum(Tc[j] * X[j] for j in range(c + 1, k))) // Tc[c]
    try:
        for c, j in enumerate(J):
            z[j] = X[c] / det
    except OverflowError:
        return None
    return z
