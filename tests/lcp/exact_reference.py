"""A textbook Lemke in exact rational arithmetic: the reference of the degenerate-family tests.

Written apart from :mod:`moreau.lcp._exact` (which pivots on an integer
tableau): here the basis inverse ``B^-1`` of the system ``w - M z - d z0 =
q`` is kept explicitly in :class:`fractions.Fraction`, each entering column
is ``B^-1 A_e`` afresh, and the ratio test is the lexicographic one of Cottle,
Pang and Stone (1992, Sec. 4.9): among the rows at the minimum ratio, the
lexicographic minimum of ``(b_i, (B^-1)_i) / a_i``; ``z0`` leaves as soon as
it is among the tied rows. Covering vector ``d = 1``. Variables: ``w_j -> j``,
``z_j -> n + j``, ``z0 -> 2 n``.
"""

from fractions import Fraction


def _column(M, n, v):
    # column of variable v in A = [I, -M, -1]
    if v < n:
        return [Fraction(int(i == v)) for i in range(n)]
    if v < 2 * n:
        return [-Fraction(float(M[i][v - n])) for i in range(n)]
    return [Fraction(-1)] * n


def reference_lemke(M, q, max_iter=10**5, trace=None):
    """Run exact Lemke; returns ``(status, basis, pivots, z, max_ties)``.

    ``status`` is "solved", "ray" or "max_iter"; ``basis`` the frozenset of
    basic variables at the end; ``max_ties`` the largest number of rows tied
    at the minimum ratio at any step after the first. ``trace`` (a list)
    receives every step after the first as ``(rows, entering, leaving, b)``:
    the basic variable of each row before the step, the variables entering
    and leaving (None on the ray) and the right-hand side after it (on the
    ray, before), row by row.
    """
    n = len(q)
    qf = [Fraction(float(v)) for v in q]
    if min(qf, default=0) >= 0:
        return "solved", frozenset(range(n)), 0, [Fraction(0)] * n, 0
    Binv = [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    b = list(qf)
    rows = list(range(n))
    z0 = 2 * n
    # first pivot: z0 enters at the smallest q_i (ties: the larger index, the
    # lexicographic minimum of (q_i, e_i) with B^-1 = I)
    r = min(range(n), key=lambda i: (qf[i], -i))
    a = [Fraction(-1)] * n
    pivots = 0
    entering = z0
    max_ties = 0
    while True:
        before = list(rows)
        # pivot on (r, entering) with column a = B^-1 A_e
        p = a[r]
        Binv[r] = [x / p for x in Binv[r]]
        b[r] = b[r] / p
        for i in range(n):
            if i != r and a[i] != 0:
                f = a[i]
                Binv[i] = [x - f * y for x, y in zip(Binv[i], Binv[r])]
                b[i] = b[i] - f * b[r]
        leaving = rows[r]
        rows[r] = entering
        pivots += 1
        if trace is not None and entering != z0:
            trace.append((before, entering, leaving, list(b)))
        if leaving == z0:
            z = [Fraction(0)] * n
            for i, v in enumerate(rows):
                if n <= v < 2 * n:
                    z[v - n] = b[i]
            return "solved", frozenset(rows), pivots, z, max_ties
        if pivots >= max_iter:
            return "max_iter", frozenset(rows), pivots, None, max_ties
        entering = leaving + n if leaving < n else leaving - n
        col = _column(M, n, entering)
        a = [sum(Binv[i][k] * col[k] for k in range(n) if col[k]) for i in range(n)]
        cand = [i for i in range(n) if a[i] > 0]
        if not cand:
            if trace is not None:
                trace.append((list(rows), entering, None, list(b)))
            return "ray", frozenset(rows), pivots, None, max_ties
        theta = min(b[i] / a[i] for i in cand)
        tied = [i for i in cand if b[i] / a[i] == theta]
        max_ties = max(max_ties, len(tied))
        zrow = [i for i in tied if rows[i] == z0]
        if zrow:
            r = zrow[0]
        else:
            r = min(tied, key=lambda i: [x / a[i] for x in Binv[i]])
