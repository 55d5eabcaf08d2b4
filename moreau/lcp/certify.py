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

import numpy as np

__all__ = ["copositive_plus_class", "farkas_vector", "infeasibility_from_ray", "FARKAS_TOL", "RAY_FARKAS_TOL"]

#: a Farkas vector from a source that alone proves nothing (a ray of an
#: uncertified M) must hold to this relative accuracy: no feasible point
#: then lies within ``||z||_1 < (max|q| / max|M|) / FARKAS_TOL``
FARKAS_TOL = 1e-10
#: accuracy asked of the Farkas vector of a ray when M is certified
#: copositive-plus: the theorem is the proof, the check only guards against
#: a ray that rounding produced
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


def farkas_vector(M, q, y, tol=FARKAS_TOL):
    """Check a candidate Farkas vector for the infeasibility of ``LCP(M, q)``.

    Parameters
    ----------
    M : ndarray, shape (n, n)
    q : ndarray, shape (n,)
    y : ndarray, shape (n,)
        Candidate, any positive scale.
    tol : float
        Relative accuracy asked of ``M^T y <= 0`` (see Returns).

    Returns
    -------
    ndarray or None
        ``y`` scaled to ``max(y) = 1`` (entries below ``-tol`` reject it,
        smaller negative ones are set to 0) when ``q.y < 0`` and
        ``max(M^T y) <= tol * max|M| * |q.y| / max|q|``; None otherwise.
        The bound means that no ``z >= 0`` with ``||z||_1 < (max|q| /
        max|M|) / tol`` is feasible; with ``max(M^T y) <= 0`` exactly, none
        at all.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    >>> farkas_vector(M, np.array([-1.0, -1.0]), np.array([3.0, 3.0])).tolist()
    [1.0, 1.0]
    >>> farkas_vector(M, np.array([-1.0, 2.0]), np.array([1.0, 1.0])) is None
    True
    """
    y = np.asarray(y, dtype=float)
    if y.size == 0 or not np.all(np.isfinite(y)):
        return None
    top = float(np.max(y))
    if not top > 0.0:
        return None
    y = y / top
    if np.min(y) < -tol:
        return None
    y = np.maximum(y, 0.0)
    qy = float(q @ y)
    if not qy < 0.0:
        return None
    mmax = float(np.max(np.abs(M)))
    qmax = float(np.max(np.abs(q)))
    g = float(np.max(M.T @ y))
    if g > tol * mmax * (-qy) / qmax:
        return None
    return y


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
    Proven when ``M`` is certified copositive-plus (Lemke's theorem; the
    ray's Farkas vector must then hold to :data:`RAY_FARKAS_TOL`, a guard
    against a ray made by rounding), or, for any ``M``, when ``ray[:n]`` is
    a Farkas vector to :data:`FARKAS_TOL`.

    Examples
    --------
    >>> import numpy as np
    >>> y, why = infeasibility_from_ray(np.array([[-1.0]]), np.array([-1.0]), np.array([1.0, 0.0]))
    >>> y.tolist(), why.startswith("Farkas")
    ([1.0], True)
    """
    n = len(q)
    dz = np.asarray(ray, dtype=float)[:n]
    cls = copositive_plus_class(M)
    if cls is not None:
        y = farkas_vector(M, q, dz, RAY_FARKAS_TOL)
        if y is not None:
            return y, (f"Lemke ended on a secondary ray and M is copositive-plus ({cls}), which proves "
                       f"the LCP infeasible (Lemke's theorem); `certificate` holds the Farkas vector "
                       f"y = dz: y >= 0, M^T y <= 0, q.y = {float(q @ y):.3g} < 0.")
        return None, (f"M is copositive-plus ({cls}), yet the ray's Farkas vector does not check out: "
                      f"the ray is likely an artefact of rounding.")
    y = farkas_vector(M, q, dz, FARKAS_TOL)
    if y is not None:
        return y, (f"Farkas certificate from the ray (M is of no certified class): y = dz has y >= 0, "
                   f"M^T y <= 0, q.y = {float(q @ y):.3g} < 0, so no z >= 0 has M z + q >= 0.")
    return None, "M is not certified copositive-plus and the ray gives no Farkas vector: this proves nothing."
