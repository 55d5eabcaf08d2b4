"""The certified violation of a candidate LCP solution, compiled: one implementation for every caller.

:func:`residual` computes ``w = M z + q`` from the data and the violation
that :func:`moreau.lcp.lcp_violation` reports, at its worst over the rounding
of ``w``: a point whose complementarity rests on cancellation below
rounding is not certified. Lemke's kernel, the compiled time stepper and the
Python :func:`lcp_violation` all call it, so that "solved" means one thing.
"""

import numpy as np
from numba import njit

__all__ = ["residual", "lcp_violation", "farkas_float", "two_prod"]

_EPS = float(np.finfo(float).eps)
# a row's violation below 1e-9 times this (in units of max|q|) needs no
# second, more precise summation
_CERT_SLACK = 1e-3


@njit(cache=True, inline="always")
def two_prod(a, b):
    """``(p, e)`` with ``a b = p + e`` exactly, ``p = fl(a b)`` (compiled; no overflow or
    underflow in the products).

    Dekker's split (no fused multiply-add in numba's portable code); Ogita,
    Rump & Oishi 2005, TwoProduct. Every operation of the error term is
    exact, so it equals the rounding error of ``p``.

    Examples
    --------
    >>> p, e = two_prod(1.0 + 2.0**-30, 1.0 + 2.0**-30)
    >>> p == 1.0 + 2.0**-29, e == 2.0**-60
    (True, True)
    """
    p = a * b
    c = 134217729.0 * a
    ah = c - (c - a)
    al = a - ah
    c = 134217729.0 * b
    bh = c - (c - b)
    bl = b - bh
    return p, al * bl - (((p - ah * bh) - al * bh) - ah * bl)


@njit(cache=True, _nrt=False)
def _dot2_row(M, q, z, i, n):
    # q_i + sum_j M_ij z_j in twice the working precision (Dot2): returns the
    # value and a bound on its error, 2 eps |value| + ((n + 2) eps)^2 sum |terms|
    s = q[i]
    c = 0.0
    mag = abs(q[i])
    for j in range(n):
        zj = z[j]
        if zj != 0.0:
            p, ep = two_prod(M[i, j], zj)
            t = s + p
            bb = t - s
            es = (s - (t - bb)) + (p - bb)
            s = t
            c += ep + es
            mag += abs(p)
    v = s + c
    g = (n + 2) * _EPS
    return v, 2.0 * _EPS * abs(v) + g * g * mag


@njit(cache=True, _nrt=False)
def residual(M, q, z, w, mmax, qmax):
    # w = M z + q from the data, and the violation of lcp_violation:
    # max |min(mmax z_i, w_i)| / qmax, scaled by the data only, at its worst
    # over the rounding of w. The computed w_i is within
    # r_i = (n + 2) eps (sum_j |M_ij z_j| + |q_i|) of the exact one (the
    # standard bound gamma_n, a factor 2 to spare). Where that bound is too
    # wide to certify, the row is summed again in twice the working precision
    # (Dot2), whose bound is about eps |w_i|: only a point whose
    # complementarity truly rests on cancellation below rounding fails.
    n = q.shape[0]
    ms = mmax if mmax > 0.0 else 1.0
    qs = qmax if qmax > 0.0 else 1.0
    lim = qs * _CERT_SLACK
    gam = (n + 2) * _EPS
    num = 0.0
    for i in range(n):
        acc = q[i]
        mag = abs(q[i])
        for j in range(n):
            zj = z[j]
            if zj != 0.0:
                p = M[i, j] * zj
                acc += p
                mag += abs(p)
        r = gam * mag
        a = ms * z[i]
        m = max(abs(min(a, acc - r)), abs(min(a, acc + r)))
        if not m <= lim * 1e-9 and r > 0.0:
            v, r2 = _dot2_row(M, q, z, i, n)
            if abs(v) < np.inf and r2 < r:
                acc = v
                m = max(abs(min(a, v - r2)), abs(min(a, v + r2)))
        w[i] = acc
        if m > num:
            num = m
    if not np.isfinite(num):
        return np.inf
    return num / qs


@njit(cache=True, inline="always")
def _two_sum(a, b):
    # a + b = s + e exactly (Knuth's TwoSum)
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@njit(cache=True, _nrt=False)
def _grow(e, m, b):
    # Shewchuk's Grow-Expansion with zero elimination: e[:m], a nonoverlapping
    # expansion in increasing magnitude, becomes one of its sum plus b, in place
    # (component k is written after component i >= k is read); returns its length
    k = 0
    for i in range(m):
        b, h = _two_sum(b, e[i])
        if h != 0.0:
            e[k] = h
            k += 1
    if b != 0.0:
        e[k] = b
        k += 1
    return k


@njit(cache=True)
def _dot_sign(M, q, y, j):
    # the exact sign (-1, 0, 1) of sum_i c_i y_i with c = q (j < 0) or column j
    # of M: each product split exactly into two floats (TwoProduct), all summed
    # exactly into a nonoverlapping expansion (Shewchuk 1997), whose sign is
    # that of its largest component. 2 where a product lies outside
    # [2^-960, 2^1000] (underflow would make the split inexact)
    n = q.shape[0]
    e = np.empty(2 * n + 1)
    m = np.int64(0)  # not a literal: it would compile _grow a second time
    for i in range(n):
        c = q[i] if j < 0 else M[i, j]
        p = c * y[i]
        if p == 0.0 and (c == 0.0 or y[i] == 0.0):
            continue
        a = abs(p)
        if not (a < 2.0**1000 and a > 2.0**-960):
            return 2
        p, err = two_prod(c, y[i])
        m = _grow(e, m, err)
        m = _grow(e, m, p)
    if m == 0:
        return 0
    return 1 if e[m - 1] > 0.0 else -1


@njit(cache=True)
def farkas_float(M, q, y):
    # y >= 0, M^T y <= 0, q.y < 0 decided in floating point with a rigorous
    # bound on each sum's rounding, and where a sum lies within its bound of
    # zero, by its exact sign (_dot_sign): 1 holds, -1 fails, 0 undecided
    # (products over- or underflowing; the exact rational check of
    # moreau.lcp.certify.farkas_holds then settles it)
    n = q.shape[0]
    gam = (n + 2) * _EPS
    pos = False
    for i in range(n):
        if not (y[i] >= 0.0 and y[i] < np.inf):
            return -1
        pos = pos or y[i] > 0.0
    if not pos:
        return -1
    qy = 0.0
    qb = 0.0
    for i in range(n):
        p = q[i] * y[i]
        qy += p
        qb += abs(p)
    qb *= gam
    if not (abs(qy) < np.inf and qb < np.inf):
        return 0
    if qy - qb >= 0.0:
        return -1
    sure = True
    if not qy + qb < 0.0:
        sg = _dot_sign(M, q, y, np.int64(-1))
        if sg == 2:
            sure = False
        elif sg >= 0:
            return -1
    for j in range(n):
        g = 0.0
        gb = 0.0
        for i in range(n):
            if y[i] != 0.0:
                p = M[i, j] * y[i]
                g += p
                gb += abs(p)
        gb *= gam
        if not (abs(g) < np.inf and gb < np.inf):
            return 0
        if g - gb > 0.0:
            return -1
        if not g + gb <= 0.0:
            sg = _dot_sign(M, q, y, j)
            if sg == 2:
                sure = False
            elif sg > 0:
                return -1
    return 1 if sure else 0


def lcp_arrays(M, q, z):
    """``M``, ``q`` and a candidate ``z`` as C-ordered float arrays (the compiled checks' layout)."""
    return (np.ascontiguousarray(M, dtype=float), np.ascontiguousarray(q, dtype=float),
            np.ascontiguousarray(z, dtype=float))


def lcp_violation(M, q, z, w=None):
    """How far ``z`` is from solving ``LCP(M, q)``, in units fixed by the data alone.

    This is the number every method's success is certified with: a result
    counts as solved only when ``lcp_violation(M, q, z) <= tol``.

    Parameters
    ----------
    M : array_like, shape (n, n)
    q : array_like, shape (n,)
    z : array_like, shape (n,)
    w : array_like, shape (n,), optional
        Ignored: ``w = M z + q`` is always recomputed from the data, with a
        bound on its rounding (kept so that older calls still work).

    Returns
    -------
    float
        ``max_i |min(m z_i, w_i)| / s`` with ``s = max|q|`` and ``m =
        max|M|`` (each replaced by 1 when it is 0), at its worst over the
        rounding error of ``w``; ``inf`` when ``z`` or ``w`` is not finite.

    Notes
    -----
    With ``tol_w = tol s`` and ``tol_z = tol s / m``, ``lcp_violation <=
    tol`` holds exactly when, for every ``w`` within the rounding bound of
    the computed ``M z + q``,

    * ``z >= -tol_z``,
    * ``w >= -tol_w``, and
    * for every ``i``, ``z_i <= tol_z`` or ``w_i <= tol_w``
      (``|min(z_i / tol_z, w_i / tol_w)| <= 1``: complementarity).

    The rounding bound is ``(n + 2) eps sum_j |M_ij z_j| + |q_i|``; where it
    is too wide to decide, the row is summed again in twice the working
    precision (Ogita, Rump and Oishi's Dot2, bound about ``eps |w_i|``).
    ``s`` is the scale of ``w`` and ``s / m`` the natural scale of ``z``, so
    both tolerances are absolute and follow the data: the measure is
    invariant under ``(M, q) -> (a M, b q)`` (whose solutions are ``(b / a)
    z``) and never grows with the candidate ``z``. A point with ``w_i = -1``
    fails by ``1 / max|q|`` however large ``z`` is.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    >>> q = np.array([-1.0, -1.0])
    >>> round(float(lcp_violation(M, q, np.array([2e9, 2e9]))), 12)  # w = (-1, -1)
    1.0
    >>> float(lcp_violation(np.eye(2), q, np.array([1.0, 1.0]))) < 1e-14   # the rounding bound
    True
    >>> M = np.array([[5.137024881800956e10, -1.1909459371103899e11],
    ...               [-1.1909459371103899e11, 2.7610382619414026e11]])
    >>> q = np.array([-0.7412042577027442, -1.4156959890769878])
    >>> float(lcp_violation(M, q, np.array([61896.45733205, 26698.41102792]))) > 0.1
    True
    """
    M, q, z = lcp_arrays(M, q, z)
    if z.size == 0:
        return 0.0
    if not (np.all(np.isfinite(z)) and np.all(np.isfinite(M)) and np.all(np.isfinite(q))):
        return np.inf
    w = np.empty_like(z)
    return float(residual(M, q, z, w, float(np.max(np.abs(M))), float(np.max(np.abs(q)))))
