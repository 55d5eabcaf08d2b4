"""Deciding small LCPs that Lemke's method leaves open: a Farkas vector from an LP, and enumeration.

Lemke's method can end on a secondary ray of an LCP that has a solution
(outside the copositive-plus class, e.g. bimatrix games) or that has none
without a certificate from the ray. Two further tools settle such cases,
both ending in checks made exactly on the caller's data:

:func:`lp_farkas`
    Solves, with HiGHS (:func:`scipy.optimize.linprog`), the LP ``min q.y``
    over ``M^T y <= 0``, ``0 <= y <= 1``: the dual of the feasibility
    problem ``{z >= 0, M z + q >= 0}``. A negative optimum gives a candidate
    Farkas vector; it, its versions with rounding noise removed and its
    rational reconstruction are checked exactly
    (:func:`moreau.lcp.certify.farkas_holds`).
:func:`enumerate_pieces`
    Visits the ``2^n`` complementary pieces ``P_J = {z : z_J >= 0, z_{J^c}
    = 0, (M z + q)_J = 0, (M z + q)_{J^c} >= 0}``, whose union is the
    solution set. A first pass in floating point (one linear solve a piece,
    least squares where ``M_JJ`` is singular) returns the first candidate
    that passes :func:`moreau.lcp.lcp_violation`. If none does, a second
    pass shows every piece empty in exact arithmetic: where ``M_JJ`` is
    regular (its determinant by integer Bareiss elimination on the data
    times a power of two), the unique rational solution of ``M_JJ z_J =
    -q_J`` violates a sign; where it is singular, a Farkas certificate
    ``(u, v)``, ``v >= 0``, with ``M_JJ^T u + M_{J^c J}^T v <= 0`` and
    ``q_J.u + q_{J^c}.v < 0``, from an LP, is checked in rationals. Only
    when every piece is shown empty is the answer "no solution"; a piece
    neither emptied nor solved is reported as undecided.
"""

from fractions import Fraction
import math

import numpy as np
from scipy.optimize import linprog

from ._certified import lcp_violation
from ._exact import integer_data
from .certify import farkas_holds, farkas_vector

__all__ = ["lp_farkas", "enumerate_pieces", "ENUMERATE_MAX_N"]

#: largest size enumerated by default (2^12 = 4096 pieces)
ENUMERATE_MAX_N = 12


def _linprog(*args, **kwargs):
    return linprog(*args, method="highs", **kwargs)


def _rational_images(y, max_den=10**6):
    # the rational vector the float approximates (small denominators), times
    # the common denominator: integers, exact as floats when small
    fr = [Fraction(float(v)).limit_denominator(max_den) for v in y]
    den = 1
    for f in fr:
        den = den * f.denominator // math.gcd(den, f.denominator)
    ints = [int(f * den) for f in fr]
    if max(abs(v) for v in ints) < 2**53:
        yield np.array(ints, dtype=float)


def lp_farkas(M, q):
    """A Farkas vector of ``LCP(M, q)`` from the dual of its feasibility LP, checked exactly, or None.

    Parameters
    ----------
    M : ndarray, shape (n, n)
    q : ndarray, shape (n,)

    Returns
    -------
    ndarray or None
        ``y`` with ``y >= 0``, ``M^T y <= 0`` and ``q.y < 0`` holding exactly
        on the given floats (:func:`moreau.lcp.certify.farkas_holds`); None
        when the LP finds none or no version of its answer checks out.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[-1.0, 1.0], [1.0, -1.0]])
    >>> lp_farkas(M, np.array([-1.0, -1.0])).tolist()
    [1.0, 1.0]
    >>> lp_farkas(np.eye(2), np.array([-1.0, -1.0])) is None
    True
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    n = len(q)
    if n == 0 or np.min(q) >= 0.0:
        return None
    # HiGHS's tolerances are absolute: solve on data of unit size (a positive
    # scaling of M or q changes no Farkas vector), check on the caller's
    sm = float(np.max(np.abs(M))) or 1.0
    res = _linprog(q / float(np.max(np.abs(q))), A_ub=M.T / sm, b_ub=np.zeros(n),
                   bounds=[(0.0, 1.0)] * n)
    if res.status != 0 or not res.fun < 0.0:
        return None
    y = np.maximum(np.asarray(res.x, dtype=float), 0.0)
    if not np.max(y) > 0.0:
        return None
    for cand in _rational_images(y / np.max(y)):
        if farkas_holds(M, q, cand):
            return cand / np.max(cand)
    return farkas_vector(M, q, y)


def _bareiss(A, b):
    # integer A (m x m lists), b (m): (det, x) with A x = det b... i.e. the
    # solution is x / det; det = 0 when A is singular (x then None). Fraction
    # free: every intermediate is an integer (a minor of [A | b]).
    m = len(A)
    R = [list(A[i]) + [b[i]] for i in range(m)]
    sign = 1
    prev = 1
    for k in range(m):
        p = next((i for i in range(k, m) if R[i][k] != 0), None)
        if p is None:
            return 0, None
        if p != k:
            R[k], R[p] = R[p], R[k]
            sign = -sign
        pk = R[k][k]
        for i in range(k + 1, m):
            Ri = R[i]
            f = Ri[k]
            Ri[k] = 0
            for j in range(k + 1, m + 1):
                Ri[j] = (Ri[j] * pk - f * R[k][j]) // prev
        prev = pk
    det = R[m - 1][m - 1] if m else 1
    # back substitution in rationals: x_i = num_i / det
    x = [Fraction(0)] * m
    for i in range(m - 1, -1, -1):
        acc = Fraction(R[i][m])
        for j in range(i + 1, m):
            acc -= R[i][j] * x[j]
        x[i] = acc / R[i][i]
    return sign * det, x


def _piece_certificate(M, q, J, Jc):
    # a Farkas certificate (u, v) that piece J is empty, checked exactly, or None
    nJ = len(J)
    A = np.hstack([M[np.ix_(J, J)].T, M[np.ix_(Jc, J)].T]) if nJ else np.zeros((0, len(Jc)))
    c = np.concatenate([q[J], q[Jc]])
    bounds = [(-1.0, 1.0)] * nJ + [(0.0, 1.0)] * len(Jc)
    # unit-size data for HiGHS's absolute tolerances (the certificate is checked exactly)
    sa = float(np.max(np.abs(A))) if A.size else 1.0
    sc = float(np.max(np.abs(c))) if c.size else 1.0
    res = _linprog(c / (sc or 1.0), A_ub=A / (sa or 1.0) if nJ else None,
                   b_ub=np.zeros(nJ) if nJ else None, bounds=bounds)
    if res.status != 0 or not res.fun < 0.0:
        return False
    x = np.asarray(res.x, dtype=float)
    x = x / np.max(np.abs(x))
    for cand in [x] + list(_rational_images(x)):
        u = [Fraction(float(v)) for v in cand[:nJ]]
        v = [Fraction(float(max(t, 0.0))) for t in cand[nJ:]]
        qf = sum(Fraction(float(q[i])) * u[a] for a, i in enumerate(J)) + \
            sum(Fraction(float(q[i])) * v[a] for a, i in enumerate(Jc))
        if qf >= 0:
            continue
        ok = True
        for j in J:
            g = sum(Fraction(float(M[i, j])) * u[a] for a, i in enumerate(J) if u[a]) + \
                sum(Fraction(float(M[i, j])) * v[a] for a, i in enumerate(Jc) if v[a])
            if g > 0:
                ok = False
                break
        if ok:
            return True
    return False


def _piece_point(M, q, J, Jc, n):
    # a point of the singular piece J from an LP, or None
    nJ = len(J)
    res = _linprog(np.zeros(nJ), A_ub=-M[np.ix_(Jc, J)] if len(Jc) else None,
                   b_ub=q[Jc] if len(Jc) else None, A_eq=M[np.ix_(J, J)], b_eq=-q[J],
                   bounds=[(0.0, None)] * nJ)
    if res.status != 0:
        return None
    z = np.zeros(n)
    z[J] = np.maximum(res.x, 0.0)
    return z


def enumerate_pieces(M, q, tol=1e-9):
    """Decide ``LCP(M, q)`` by visiting its ``2^n`` complementary pieces.

    Parameters
    ----------
    M : ndarray, shape (n, n)
    q : ndarray, shape (n,)
    tol : float
        Bound on :func:`moreau.lcp.lcp_violation` for a candidate to count
        as a solution.

    Returns
    -------
    outcome : str
        ``"solved"``, ``"none"`` (every piece shown empty exactly: no
        solution exists) or ``"undecided"``.
    z : ndarray or None
        The solution (``"solved"``).
    counts : dict
        ``pieces``, ``regular`` and ``singular`` (pieces shown empty each
        way) and ``undecided``, and the piece ``J`` of a solution.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[0.0, 2.0], [3.0, 0.0]])      # a bimatrix game
    >>> out, z, _ = enumerate_pieces(M, np.array([-1.0, -1.0]))
    >>> out, z.tolist()
    ('solved', [0.3333333333333333, 0.5])
    >>> enumerate_pieces(np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, 2.0]))[0]
    'solved'
    >>> enumerate_pieces(np.array([[-1.0]]), np.array([-1.0]))[0]
    'none'
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    n = len(q)
    counts = {"pieces": 2**n, "regular": 0, "singular": 0, "undecided": 0}
    idx = np.arange(n)
    pieces = []
    for mask in range(2**n):
        J = idx[[(mask >> i) & 1 == 1 for i in range(n)]]
        pieces.append((J, np.setdiff1d(idx, J)))
    # pass 1, floating point: the first candidate that checks out on the data
    for J, Jc in pieces:
        z = np.zeros(n)
        if len(J):
            A = M[np.ix_(J, J)]
            try:
                zJ = np.linalg.solve(A, -q[J])
            except np.linalg.LinAlgError:
                zJ = np.linalg.lstsq(A, -q[J], rcond=None)[0]
            if not np.all(np.isfinite(zJ)):
                continue
            z[J] = np.maximum(zJ, 0.0)
        if lcp_violation(M, q, z) <= tol:
            counts["J"] = J.tolist()
            return "solved", z, counts
    # pass 2, exact: every piece empty, or a solution the floats missed
    (Mi, qi), _ = integer_data(M, q)
    for J, Jc in pieces:
        Jl = J.tolist()
        det, x = _bareiss([[Mi[i][j] for j in Jl] for i in Jl], [-qi[i] for i in Jl])
        if det != 0 or not Jl:
            # the unique point of the piece's equations: inside the piece?
            zJ = x if Jl else []
            if all(v >= 0 for v in zJ) and all(
                    qi[i] + sum(Mi[i][j] * zJ[a] for a, j in enumerate(Jl)) >= 0 for i in Jc):
                z = np.zeros(n)
                try:
                    z[J] = [float(v) for v in zJ]
                except OverflowError:
                    counts["undecided"] += 1  # a solution outside the range of doubles
                    continue
                if lcp_violation(M, q, z) <= tol:
                    counts["J"] = Jl
                    return "solved", z, counts
                counts["undecided"] += 1  # a solution exists, but not one floats can hold to tol
                continue
            counts["regular"] += 1
            continue
        if _piece_certificate(M, q, J, Jc):
            counts["singular"] += 1
            continue
        z = _piece_point(M, q, J, Jc, n)
        if z is not None and lcp_violation(M, q, z) <= tol:
            counts["J"] = Jl
            return "solved", z, counts
        counts["undecided"] += 1
    return ("none" if counts["undecided"] == 0 else "undecided"), None, counts
