"""Proofs of infeasibility: matrix classes and Farkas vectors.

``LCP(M, q)`` has no solution as soon as it has no *feasible* point, i.e. no
``z >= 0`` with ``M z + q >= 0``. Farkas' lemma gives a checkable proof of
that: a vector ``y >= 0`` with ``M^T y <= 0`` and ``q.y < 0``, for then every
``z >= 0`` has ``y.(M z + q) = (M^T y).z + q.y < 0``. :func:`farkas_vector`
checks such a vector.

Lemke's theorem (Cottle, Pang and Stone, *The Linear Complementarity
Problem*, 1992, Thm. 4.4.13) says when a secondary ray proves infeasibility:
for copositive-plus ``M`` (``z.M z >= 0`` for ``z >= 0``, and ``z >= 0``,
``z.M z = 0`` imply ``(M + M^T) z = 0``), Lemke's method with a
lexicographic ratio test ends on a secondary ray only if the LCP is
infeasible. The ray then also yields the Farkas vector: with ``(dz, dz0)``
the ray, ``dz0 = 0`` and ``dz >= 0`` has ``M dz >= 0`` and ``dz.M dz = 0``,
hence ``M^T dz = -M dz <= 0``, and ``q.dz < 0``. :func:`copositive_plus_class`
recognises the classes that can be certified cheaply;
:func:`infeasibility_from_ray` puts the two together.
"""

from fractions import Fraction

import numpy as np

from ._certified import farkas_float

__all__ = ["copositive_plus_class", "farkas_vector", "farkas_holds", "infeasibility_from_ray",
           "FARKAS_TOL", "RAY_FARKAS_TOL"]

#: the compiled pre-filter of a ray (:func:`moreau.lcp.lemke` ``_ray_is_farkas``)
#: passes a ray that is a Farkas vector to this relative accuracy; only the
#: exact check (:func:`farkas_holds`) turns it into a proof
FARKAS_TOL = 1e-10
#: kept for callers of the former tolerance-based check; unused
RAY_FARKAS_TOL = 1e-6


def copositive_plus_class(M):
    """Name a copositive-plus class ``M`` certifiably belongs to, or None.

    Two classes are recognised, both cheaply:

    * ``"nonnegative with a positive diagonal"``: then ``z.M z >= sum_i M_ii
      z_i^2 > 0`` for ``z >= 0``, ``z != 0`` (strictly copositive). Exact: no
      tolerance involved.
    * ``"positive semidefinite (monotone)"``: the symmetric part ``S = (M +
      M^T) / 2`` has no eigenvalue below ``-100 n eps max|S| n`` (the
      rounding level of a symmetric eigensolver; an exactly singular ``S``
      computes to eigenvalues of that size). ``z.S z = 0`` with ``S``
      positive semidefinite gives ``S z = 0``.

    Parameters
    ----------
    M : ndarray, shape (n, n)

    Returns
    -------
    str or None

    Examples
    --------
    >>> import numpy as np
    >>> copositive_plus_class(np.array([[1.0, -1.0], [-1.0, 1.0]]))
    'positive semidefinite (monotone)'
    >>> copositive_plus_class(np.array([[1.0, 5.0], [5.0, 1.0]]))
    'nonnegative with a positive diagonal'
    >>> copositive_plus_class(np.array([[0.0, 1.0], [2.0, 0.0]])) is None
    True
    """
    M = np.asarray(M, dtype=float)
    n = M.shape[0]
    if n == 0:
        return "positive semidefinite (monotone)"
    if np.all(M >= 0.0) and np.all(np.diag(M) > 0.0):
        return "nonnegative with a positive diagonal"
    S = 0.5 * (M + M.T)
    smax = float(np.max(np.abs(S)))
    if smax == 0.0:
        return "positive semidefinite (monotone)"
    # a negative diagonal entry rules PSD out without an eigensolver
    if np.min(np.diag(S)) < 0.0:
        return None
    lam = np.linalg.eigvalsh(S)[0]
    if lam >= -100.0 * n * n * np.finfo(float).eps * smax:
        return "positive semidefinite (monotone)"
    return None


def farkas_holds(M, q, y):
    """Whether ``y >= 0``, ``M^T y <= 0`` and ``q.y < 0`` hold *exactly* for the given floats.

    A Farkas vector is a claim that no ``z >= 0`` has ``M z + q >= 0``; a
    tolerance would let rounding make the claim (``diag(1e300, 1e-300)`` has
    a solution of size 1e300, outside any tolerance ball). Every float is a
    rational number, so the check is done on the caller's data exactly:
    first in floating point with a rigorous bound on the rounding of each sum
    (``(n + 2) eps`` times the sum of the magnitudes), which settles nearly
    every case, and where a sum lies within its bound of zero, in
    :class:`fractions.Fraction` arithmetic.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    >>> farkas_holds(M, np.array([-1.0, -1.0]), np.array([1.0, 1.0]))
    True
    >>> farkas_holds(M, np.array([-1.0, -1.0]), np.array([1.0, 1.0 - 2.0**-40]))
    False
    """
    M = np.ascontiguousarray(M, dtype=float)
    q = np.ascontiguousarray(q, dtype=float)
    y = np.ascontiguousarray(y, dtype=float)
    n = q.shape[0]
    if y.shape != (n,) or M.shape != (n, n):
        return False
    verdict = farkas_float(M, q, y)
    if verdict != 0:
        return verdict > 0
    if not np.all(np.isfinite(y)) or np.any(y < 0.0) or not np.any(y > 0.0):
        return False
    return _exact_farkas(M, q, y)


def _exact_farkas(M, q, y):
    yf = [Fraction(float(v)) for v in y]
    support = [i for i, v in enumerate(yf) if v != 0]
    if sum(Fraction(float(q[i])) * yf[i] for i in support) >= 0:
        return False
    for j in range(len(yf)):
        if sum(Fraction(float(M[i, j])) * yf[i] for i in support) > 0:
            return False
    return True


def _candidates(y):
    # the vector as given, and versions with rounding noise removed: entries
    # negligible against the largest set to zero, and the rest snapped to
    # short dyadic fractions, whose products with the data are exact more often
    top = float(np.max(y))
    y = np.maximum(y / top, 0.0)
    yield y
    for cut in (1e-12, 1e-9, 1e-6):
        yield np.where(y < cut, 0.0, y)
    for bits in (40, 26, 20, 12):
        yield np.ldexp(np.round(np.ldexp(y, bits)), -bits)


def _rational_null(B):
    # basis of the null space of the rational matrix B (list of rows), by
    # exact Gauss-Jordan elimination: a list of vectors (empty when trivial)
    rows = [list(r) for r in B]
    m = len(rows[0]) if rows else 0
    piv = []
    r = 0
    for c in range(m):
        k = next((i for i in range(r, len(rows)) if rows[i][c] != 0), None)
        if k is None:
            continue
        rows[r], rows[k] = rows[k], rows[r]
        p = rows[r][c]
        rows[r] = [v / p for v in rows[r]]
        for i in range(len(rows)):
            if i != r and rows[i][c] != 0:
                f = rows[i][c]
                rows[i] = [a - f * b for a, b in zip(rows[i], rows[r])]
        piv.append(c)
        r += 1
        if r == len(rows):
            break
    basis = []
    for f in (c for c in range(m) if c not in piv):
        v = [Fraction(0)] * m
        v[f] = Fraction(1)
        for i, c in enumerate(piv):
            v[c] = -rows[i][f]
        basis.append(v)
    return basis


def _project(basis, y):
    # the exact orthogonal projection of the rational vector y onto span(basis)
    d = len(basis)
    G = [[sum(a * b for a, b in zip(basis[i], basis[j])) for j in range(d)] for i in range(d)]
    rhs = [sum(a * b for a, b in zip(basis[i], y)) for i in range(d)]
    # Gauss-Jordan on the (positive definite) Gram matrix
    A = [G[i] + [rhs[i]] for i in range(d)]
    for c in range(d):
        k = next(i for i in range(c, d) if A[i][c] != 0)
        A[c], A[k] = A[k], A[c]
        p = A[c][c]
        A[c] = [v / p for v in A[c]]
        for i in range(d):
            if i != c and A[i][c] != 0:
                f = A[i][c]
                A[i] = [a - f * b for a, b in zip(A[i], A[c])]
    coef = [A[i][d] for i in range(d)]
    return [sum(coef[i] * basis[i][k] for i in range(d)) for k in range(len(y))]


def _null_farkas(M, q, y, cut=1e-9, max_n=40):
    # For a monotone M a Farkas vector has M^T y = 0 on the nose, which
    # floating point rarely hits: project the candidate exactly (rationals)
    # onto the null space of M^T, on the candidate's support and then on all
    # entries: the exact direction the float candidate approximates, when
    # the stored data have one.
    n = len(q)
    if n > max_n:
        return None
    supports = [[i for i in range(n) if y[i] > cut], list(range(n))]
    for J in supports:
        if not J or (J is supports[1] and len(supports[0]) == n):
            continue
        B = [[Fraction(float(M[i, j])) for i in J] for j in range(n)]
        basis = _rational_null(B)
        if not basis:
            continue
        v = _project(basis, [Fraction(float(y[i])) for i in J])
        if any(a < 0 for a in v) or not any(a > 0 for a in v):
            continue
        if sum(Fraction(float(q[i])) * a for i, a in zip(J, v)) >= 0:
            continue
        top = max(v)
        out = np.zeros(n)
        out[J] = [float(a / top) for a in v]
        return out
    return None


def farkas_vector(M, q, y, tol=None):
    """A Farkas vector for the infeasibility of ``LCP(M, q)`` built from the candidate ``y``, or None.

    Parameters
    ----------
    M : ndarray, shape (n, n)
    q : ndarray, shape (n,)
    y : ndarray, shape (n,)
        Candidate, any positive scale (a Lemke ray, an OSQP certificate).
    tol : float, optional
        Ignored; kept so that older calls still work. The check is exact
        (:func:`farkas_holds`).

    Returns
    -------
    ndarray or None
        A vector with ``max = 1`` for which :func:`farkas_holds` is True: the
        candidate scaled, the candidate with entries below rounding noise
        removed, or the exact solution of ``M^T y = 0`` on the candidate's
        support (rational Gauss–Jordan; a monotone ``M`` has ``M^T y = 0`` for
        every Farkas vector, which floating point rarely hits; the proof is
        then made with that rational vector and the float returned is its
        image). None when no such version checks out: the candidate then
        proves nothing.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    >>> farkas_vector(M, np.array([-1.0, -1.0]), np.array([3.0, 3.0 * (1 + 1e-15)])).tolist()
    [1.0, 1.0]
    >>> farkas_vector(M, np.array([-1.0, 2.0]), np.array([1.0, 1.0])) is None
    True
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    y = np.asarray(y, dtype=float).reshape(-1)
    if y.size == 0 or y.shape != q.shape or not np.all(np.isfinite(y)) or not np.max(y) > 0.0:
        return None
    for cand in _candidates(y):
        if farkas_holds(M, q, cand):
            return cand
    # for a monotone M only (there every Farkas vector has M^T y = 0): proven
    # in rationals (M^T v = 0 on the support by construction, v >= 0, q.v < 0);
    # the float image may miss M^T y <= 0 by an ulp, the proof stands
    if copositive_plus_class(M) != "positive semidefinite (monotone)":
        return None
    return _null_farkas(M, q, np.maximum(y / np.max(y), 0.0))


def infeasibility_from_ray(M, q, ray):
    """Turn the secondary ray Lemke's method ended on into a proof, if it is one.

    Parameters
    ----------
    M : ndarray, shape (n, n)
    q : ndarray, shape (n,)
    ray : ndarray, shape (n + 1,)
        ``(dz, dz0)`` from :func:`moreau.lcp.lemke.solve`.

    Returns
    -------
    y : ndarray or None
        The Farkas vector (``ray[:n]`` scaled) when infeasibility is proven.
    detail : str
        Why it is, or why not.

    Notes
    -----
    Proven only when a Farkas vector built from ``ray[:n]``
    (:func:`farkas_vector`) holds exactly on the given data. For
    copositive-plus ``M``, Lemke's theorem says that it should; the exact
    check is what turns the floating-point ray into a proof.

    Examples
    --------
    >>> import numpy as np
    >>> y, why = infeasibility_from_ray(np.array([[-1.0]]), np.array([-1.0]), np.array([1.0, 0.0]))
    >>> y.tolist(), "checked exactly" in why
    ([1.0], True)
    """
    n = len(q)
    dz = np.asarray(ray, dtype=float)[:n]
    cls = copositive_plus_class(M)
    y = farkas_vector(M, q, dz)
    if y is not None:
        src = (f"M is copositive-plus ({cls}), so Lemke's theorem says the ray means infeasibility"
               if cls is not None else "M is of no certified class")
        return y, (f"Lemke ended on a secondary ray ({src}); `certificate` holds a Farkas "
                   f"vector y built from the ray's dz, with y >= 0, M^T y <= 0 and q.y = "
                   f"{float(q @ y):.3g} < 0 checked exactly on the given data, so no z >= 0 has "
                   f"M z + q >= 0.")
    if cls is not None:
        return None, (f"M is copositive-plus ({cls}), yet no Farkas vector built from the ray "
                      f"checks out exactly on the given data: infeasibility is not proven (the "
                      f"ray may be an artefact of rounding).")
    return None, ("M is not certified copositive-plus and the ray gives no Farkas vector that "
                  "checks out exactly: this proves nothing.")
