r"""The 2D frictional contact problem with rolling resistance, and NSGS for it.

Each contact ``i`` has three rows, interleaved ``[N_i, T_i, R_i]``: the
normal and tangential relative velocities of FCLib's 2D problem
(:mod:`moreau.contact._sparse`) and the relative angular velocity ``u_R``
of the two bodies (``omega_b - omega_a``; against a fixed wall,
``omega_b``), with the impulses ``r = (r_N, r_T, r_R)``: ``r_R`` is the
impulse of a couple, ``+r_R`` on body ``b`` and ``-r_R`` on ``a`` (row
``R`` of the Jacobian, transposed). Given ``W`` (``3 nc x 3 nc``), ``q`` and
per contact a friction coefficient ``mu`` and a rolling-resistance length
``mu_r``, find ``r`` and ``u = W r + q`` with

    ``K_i = {r : |r_T| <= mu_i r_N,  |r_R| <= mu_r,i r_N}``,
    ``u_hat_i = (u_N + mu_i |u_T| + mu_r,i |u_R|,  u_T,  u_R)``,
    ``K_i* ∋ u_hat_i  ⊥  r_i ∈ K_i``.

Why this is the law (derived here): ``K_i*`` (the dual cone) is ``{u :
u_N >= mu |u_T| + mu_r |u_R|}`` (the least of ``u . r`` over ``K`` at
``r_N = 1`` is ``u_N - mu |u_T| - mu_r |u_R|``), so ``u_hat in K*`` is
``u_N >= 0``; and ``r . u_hat = r_N u_N + (mu r_N |u_T| + r_T u_T) +
(mu_r r_N |u_R| + r_R u_R)``, three terms each ``>= 0`` on ``K``, so the
complementarity makes each zero: Signorini, Coulomb (``r_T`` opposes a
slip ``u_T != 0`` at ``mu r_N``) and the same law for the rolling couple,
``|M| <= mu_r N`` with ``M`` opposing a relative rolling ``u_R != 0``. The
couple does no work in a rigid motion of the pair (``u_R = 0`` where both
turn alike) and dissipates ``mu_r r_N |u_R|`` otherwise. ``mu_r`` is a
length, the lever arm of the normal force (Coulomb's coefficient of rolling
friction); with ``mu_r = 0`` the rows ``R`` carry nothing and the problem
is FCLib's 2D one. The same cone in three dimensions is Siconos's rolling
friction contact problem (V. Acary, F. Bourrier and B. Viano, *Variational
approach for nonsmooth elasto-plastic dynamics with contact and impacts*,
2023; F. Bourrier and V. Acary, *Predictive capabilities of 2D and 3D block
propagation models integrating block shape assessed from field
experiments*, Rock Mech. Rock Eng. 2022); in granular packings of disks,
F. A. Estrada, E. Azéma, F. Radjai, A. Taboada, *Identification of rolling
resistance as a shape parameter in sheared granular media*, Phys. Rev. E 84
(2011) 011306.

The residual is the natural map ``F(r) = r - P_K(r - u_hat(r))`` as in
:mod:`moreau.contact._sparse`, with :func:`project_rolling_cone` (derived
in its docstring), ``residual = ||F||_2 / (1 + ||q||_2)``, recomputed with
compensated sums on the impulses returned.
"""

import math

import numpy as np
import scipy.sparse as sps
from numba import njit

from moreau import _jit_cache
from moreau._validate import finite_array, finite_scalar, positive_int
from moreau.contact import _sparse
from moreau.contact._sparse import IterativeResult, velocities, velocities_compensated
from moreau.errors import InputError

_CACHE = __name__.startswith("moreau.")

__all__ = ["project_rolling_cone", "local_solve_rolling", "solve_nsgs_rolling",
           "rolling_residual", "check_rolling_problem"]


@njit(cache=_CACHE)
def project_rolling_cone(mu, mu_r, rn, rt, rr):
    """Euclidean projection of ``(rn, rt, rr)`` onto ``{|r_T| <= mu r_N, |r_R| <= mu_r r_N}``.

    At a fixed ``r_N = s >= 0`` the nearest point clips ``rt`` to ``[-mu s,
    mu s]`` and ``rr`` to ``[-mu_r s, mu_r s]``; the squared distance left,
    ``f(s) = (s - rn)^2 + (|rt| - mu s)_+^2 + (|rr| - mu_r s)_+^2``, is
    convex with the nondecreasing slope ``f'/2 = s - rn - mu (|rt| - mu
    s)_+ - mu_r (|rr| - mu_r s)_+``, piecewise linear between the breaks
    ``|rt| / mu`` and ``|rr| / mu_r``. ``s = 0`` where the slope at 0 is
    ``>= 0``; otherwise the slope's zero, on the first piece whose right end
    has a slope ``>= 0``: ``s = (rn + sum mu_k |x_k|) / (1 + sum mu_k^2)``
    over the components still clipped there.

    Examples
    --------
    >>> from moreau.contact.rolling import project_rolling_cone
    >>> project_rolling_cone(0.5, 0.1, 1.0, 0.2, 0.05)
    (1.0, 0.2, 0.05)
    >>> project_rolling_cone(0.5, 0.0, 1.0, 2.0, 3.0)
    (1.6, 0.8, 0.0)
    >>> project_rolling_cone(0.5, 0.1, -1.0, 0.1, 0.0)
    (0.0, 0.0, 0.0)
    """
    at = abs(rt)
    ar = abs(rr)
    # the slope at 0
    if -rn - mu * at - mu_r * ar >= 0.0:
        return 0.0, 0.0, 0.0
    bt = at / mu if mu > 0.0 else math.inf
    br = ar / mu_r if mu_r > 0.0 else math.inf
    lo = min(bt, br)
    hi = max(bt, br)
    s = 0.0
    found = False
    for k in range(3):
        right = lo if k == 0 else (hi if k == 1 else math.inf)
        if k < 2 and not math.isfinite(right):
            continue
        num = rn
        den = 1.0
        # clipped on this piece: the components whose break lies at or beyond its right end
        if mu > 0.0 and bt >= right:
            num += mu * at
            den += mu * mu
        if mu_r > 0.0 and br >= right:
            num += mu_r * ar
            den += mu_r * mu_r
        if k == 2:
            s = num / den
            found = True
            break
        slope = right - rn - mu * max(at - mu * right, 0.0) - mu_r * max(ar - mu_r * right, 0.0)
        if slope >= 0.0:
            s = num / den
            found = True
            break
    if not found or s < 0.0:
        s = max(s, 0.0)
    pt = min(max(rt, -mu * s), mu * s)
    pr = min(max(rr, -mu_r * s), mu_r * s)
    return s, pt, pr


@njit(cache=_CACHE)
def _local_residual_sq(B, b, mu, mu_r, x0, x1, x2):
    u0 = B[0, 0] * x0 + B[0, 1] * x1 + B[0, 2] * x2 + b[0]
    u1 = B[1, 0] * x0 + B[1, 1] * x1 + B[1, 2] * x2 + b[1]
    u2 = B[2, 0] * x0 + B[2, 1] * x1 + B[2, 2] * x2 + b[2]
    p0, p1, p2 = project_rolling_cone(mu, mu_r, x0 - (u0 + mu * abs(u1) + mu_r * abs(u2)),
                                      x1 - u1, x2 - u2)
    return (x0 - p0) ** 2 + (x1 - p1) ** 2 + (x2 - p2) ** 2


@njit(cache=_CACHE)
def _solve3(A, c, x):
    # Gaussian elimination with partial pivoting on copies; False where a pivot vanishes
    M = A.copy()
    y = c.copy()
    scale = 0.0
    for i in range(3):
        for j in range(3):
            scale = max(scale, abs(M[i, j]))
    if scale == 0.0:
        return False
    for col in range(3):
        piv = col
        for i in range(col + 1, 3):
            if abs(M[i, col]) > abs(M[piv, col]):
                piv = i
        if abs(M[piv, col]) <= 1e-13 * scale:
            return False
        if piv != col:
            for j in range(3):
                M[col, j], M[piv, j] = M[piv, j], M[col, j]
            y[col], y[piv] = y[piv], y[col]
        for i in range(col + 1, 3):
            f = M[i, col] / M[col, col]
            for j in range(col, 3):
                M[i, j] -= f * M[col, j]
            y[i] -= f * y[col]
    for i in range(2, -1, -1):
        s = y[i]
        for j in range(i + 1, 3):
            s -= M[i, j] * x[j]
        x[i] = s / M[i, i]
    return True


@njit(cache=_CACHE, inline="always")
def _piece_row(A, c, B, b, row, stick, slope):
    # row ``row`` of a piece's linear system: sticking, the row's velocity vanishes
    # (B[row] x = -b[row]); slipping, the impulse rides the cone's face,
    # x[row] + slope x[0] = 0 (slope = mu times the slip's sign)
    if stick:
        for j in range(3):
            A[row, j] = B[row, j]
        c[row] = -b[row]
    else:
        for j in range(3):
            A[row, j] = 0.0
        A[row, 0] = slope
        A[row, row] = 1.0
        c[row] = 0.0


@njit(cache=_CACHE)
def local_solve_rolling(B, b, mu, mu_r):
    """Exact solution of one contact ``u = B r + b`` (``3 x 3``) with friction and rolling resistance.

    Take-off where ``b_N >= 0``; otherwise the first of the nine pieces
    (the tangential row sticking or slipping either way, times the rolling
    row sticking or rolling either way: stick-stick first) whose linear
    system has a solution that meets its piece's inequalities. When
    rounding makes every test fail by a hair, the candidate (projected onto
    the cone) with the least local residual.

    Examples
    --------
    A disk of unit mass and radius on a floor (its ``B``), rolling at speed 1
    without slip (``u_T = 0``, ``u_R = -1``), its weight's impulse 1 in the
    step, ``mu = 0.5``, ``mu_r = 0.3``: it keeps rolling, the couple at
    ``mu_r r_N`` against the roll, the friction ``0.2`` holding the slip at zero:

    >>> import numpy as np
    >>> from moreau.contact.rolling import local_solve_rolling
    >>> B = np.array([[1.0, 0.0, 0.0], [0.0, 3.0, -2.0], [0.0, -2.0, 2.0]])
    >>> [round(v, 12) for v in local_solve_rolling(B, np.array([-1.0, 0.0, -1.0]), 0.5, 0.3)]
    [1.0, 0.2, 0.3]
    """
    if b[0] >= 0.0:
        return 0.0, 0.0, 0.0
    A = np.empty((3, 3))
    c = np.empty(3)
    x = np.zeros(3)
    best = _local_residual_sq(B, b, mu, mu_r, 0.0, 0.0, 0.0)
    bx0 = 0.0
    bx1 = 0.0
    bx2 = 0.0
    for piece in range(9):
        kt = piece % 3      # 0 stick, 1 slip with u_T > 0, 2 slip with u_T < 0
        kr = piece // 3     # the same for the rolling row
        st = 1.0 if kt == 1 else -1.0
        sr = 1.0 if kr == 1 else -1.0
        _piece_row(A, c, B, b, 0, True, 0.0)
        _piece_row(A, c, B, b, 1, kt == 0, mu * st)
        _piece_row(A, c, B, b, 2, kr == 0, mu_r * sr)
        if not _solve3(A, c, x):
            continue
        ok = x[0] >= 0.0
        if ok and kt == 0:
            ok = abs(x[1]) <= mu * x[0]
        if ok and kr == 0:
            ok = abs(x[2]) <= mu_r * x[0]
        if ok and kt != 0:
            ok = st * (B[1, 0] * x[0] + B[1, 1] * x[1] + B[1, 2] * x[2] + b[1]) >= 0.0
        if ok and kr != 0:
            ok = sr * (B[2, 0] * x[0] + B[2, 1] * x[1] + B[2, 2] * x[2] + b[2]) >= 0.0
        if ok:
            return x[0], x[1], x[2]
        p0, p1, p2 = project_rolling_cone(mu, mu_r, x[0], x[1], x[2])
        res = _local_residual_sq(B, b, mu, mu_r, p0, p1, p2)
        if res < best:
            best, bx0, bx1, bx2 = res, p0, p1, p2
    return bx0, bx1, bx2


@njit(cache=_CACHE)
def _natural_map(r, u, mu, mu_r):
    s = 0.0
    for i in range(mu.shape[0]):
        a = 3 * i
        un = u[a] + mu[i] * abs(u[a + 1]) + mu_r[i] * abs(u[a + 2])
        p0, p1, p2 = project_rolling_cone(mu[i], mu_r[i], r[a] - un, r[a + 1] - u[a + 1],
                                          r[a + 2] - u[a + 2])
        s += (r[a] - p0) ** 2 + (r[a + 1] - p1) ** 2 + (r[a + 2] - p2) ** 2
    if not math.isfinite(s):
        return math.inf
    return s


@njit(cache=_CACHE)
def _nsgs(indptr, indices, data, blocks, q, mu, mu_r, r, max_sweeps, check_every, tol_abs,
          hist_it, hist_res, best_r):
    nc = mu.shape[0]
    u = np.empty_like(q)
    velocities(indptr, indices, data, q, r, u)
    best = math.sqrt(_natural_map(r, u, mu, mu_r))
    best_r[:] = r
    hist_it[0] = 0
    hist_res[0] = best
    nh = 1
    sweeps = 0
    if best <= tol_abs:
        return sweeps, nh
    b = np.empty(3)
    while sweeps < max_sweeps:
        for i in range(nc):
            a = 3 * i
            if blocks[i, 0, 0] <= 0.0:
                continue
            for row in range(3):
                s = q[a + row]
                for k in range(indptr[a + row], indptr[a + row + 1]):
                    s += data[k] * r[indices[k]]
                for j in range(3):
                    s -= blocks[i, row, j] * r[a + j]
                b[row] = s
            r[a], r[a + 1], r[a + 2] = local_solve_rolling(blocks[i], b, mu[i], mu_r[i])
        sweeps += 1
        if sweeps % check_every == 0 or sweeps == max_sweeps:
            velocities(indptr, indices, data, q, r, u)
            res = math.sqrt(_natural_map(r, u, mu, mu_r))
            hist_it[nh] = sweeps
            hist_res[nh] = res
            nh += 1
            if res < best:
                best = res
                best_r[:] = r
            if not math.isfinite(res) or res <= tol_abs:
                break
    return sweeps, nh


@njit(cache=_CACHE)
def _project_start(r, mu, mu_r):
    for i in range(mu.shape[0]):
        a = 3 * i
        r[a], r[a + 1], r[a + 2] = project_rolling_cone(mu[i], mu_r[i], r[a], r[a + 1], r[a + 2])


_jit_cache.bind_cache_to_sources(
    [project_rolling_cone, _local_residual_sq, _solve3, _piece_row, local_solve_rolling,
     _natural_map, _nsgs, _project_start], [__file__, _sparse.__file__])


def check_rolling_problem(W, q, mu, mu_r):
    """Validate the data of the problem with rolling; return ``(W as CSR, q, mu, mu_r)``.

    Examples
    --------
    >>> check_rolling_problem(np.eye(3), [-1.0, 0.0, 0.0], [0.5], [-0.1])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `mu_r` must be >= 0 for every contact
    """
    W = _sparse.csr_delassus(W, 3, "a multiple of 3 rows (3 per contact)")
    n = W.shape[0]
    q = finite_array("q", q, shape=(n,))
    mu = finite_array("mu", mu, shape=(n // 3,))
    mu_r = finite_array("mu_r", mu_r, shape=(n // 3,))
    if np.any(mu < 0.0):
        raise InputError("`mu` must be >= 0 for every contact")
    if np.any(mu_r < 0.0):
        raise InputError("`mu_r` must be >= 0 for every contact")
    W.sort_indices()
    W.indices = W.indices.astype(np.int64, copy=False)
    W.indptr = W.indptr.astype(np.int64, copy=False)
    return W, q, mu, mu_r


def _residual(W, q, mu, mu_r, r):
    u = np.empty_like(q)
    velocities_compensated(W.indptr, W.indices, W.data, q, r, u)
    res_abs = math.sqrt(_natural_map(r, u, mu, mu_r))
    return res_abs / (1.0 + float(np.linalg.norm(q))), res_abs, u


def rolling_residual(W, q, mu, mu_r, r):
    """The certified residual of impulses ``r``: ``(residual, residual_abs, u)`` (module docstring).

    Examples
    --------
    A unit disk at rest on a floor under its weight's impulse 1 (the block of
    :func:`local_solve_rolling`):

    >>> B = np.array([[1.0, 0.0, 0.0], [0.0, 3.0, -2.0], [0.0, -2.0, 2.0]])
    >>> res, _, u = rolling_residual(B, [-1.0, 0.0, 0.0], [0.5], [0.1], [1.0, 0.0, 0.0])
    >>> res, u.tolist()
    (0.0, [0.0, 0.0, 0.0])
    """
    W, q, mu, mu_r = check_rolling_problem(W, q, mu, mu_r)
    r = finite_array("r", r, shape=q.shape)
    return _residual(W, q, mu, mu_r, r)


def solve_nsgs_rolling(W, q, mu, mu_r, *, r0=None, tol=1e-8, max_sweeps=10_000, check_every=4):
    """Solve the problem with rolling resistance ``(W, q, mu, mu_r)`` by nonsmooth Gauss–Seidel.

    The sweeps of :func:`moreau.contact.solvers.nsgs.solve_nsgs`, contact by
    contact with :func:`local_solve_rolling`; the same certified stop and
    result.

    Parameters
    ----------
    W : sparse matrix or array_like, shape (3 nc, 3 nc)
        Rows ``[N_i, T_i, R_i]`` interleaved.
    q : array_like, shape (3 nc,)
    mu, mu_r : array_like, shape (nc,)
        Friction coefficients and rolling-resistance lengths, ``>= 0``.
    r0 : array_like, shape (3 nc,), optional
        Warm start, projected onto the cones first.
    tol : float
        On ``||F(r)|| / (1 + ||q||)``, in ``[1e-15, 1)``.
    max_sweeps, check_every : int

    Returns
    -------
    IterativeResult
        Interleaved ``[N, T, R]`` impulses and velocities; ``solver``
        ``"nsgs-rolling"``.

    Examples
    --------
    The rolling disk of :func:`local_solve_rolling`: the step slows its roll
    from 1 to 0.8.

    >>> B = np.array([[1.0, 0.0, 0.0], [0.0, 3.0, -2.0], [0.0, -2.0, 2.0]])
    >>> res = solve_nsgs_rolling(B, [-1.0, 0.0, -1.0], [0.5], [0.3], tol=1e-12)
    >>> res.status, np.round(res.r, 12).tolist(), round(float(res.u[2]), 12)
    ('converged', [1.0, 0.2, 0.3], -0.8)
    """
    W, q, mu, mu_r = check_rolling_problem(W, q, mu, mu_r)
    tol = finite_scalar("tol", tol)
    if not 1e-15 <= tol < 1.0:
        raise InputError(f"`tol` must lie in [1e-15, 1), got {tol!r}")
    max_sweeps = positive_int("max_sweeps", max_sweeps)
    check_every = positive_int("check_every", check_every)
    r = np.zeros_like(q) if r0 is None else finite_array("r0", r0, shape=q.shape).copy()
    _project_start(r, mu, mu_r)
    scale = 1.0 + float(np.linalg.norm(q))
    nh_max = max_sweeps // check_every + 2
    hist_it = np.zeros(nh_max, dtype=np.int64)
    hist_res = np.zeros(nh_max)
    best_r = np.empty_like(r)
    blocks = _sparse.diagonal_blocks(W.indptr, W.indices, W.data, mu.shape[0], 3)
    sweeps, nh = _nsgs(W.indptr, W.indices, W.data, blocks, q, mu, mu_r, r, max_sweeps,
                       check_every, tol * scale, hist_it, hist_res, best_r)
    res, res_abs, u = _residual(W, q, mu, mu_r, best_r)
    history = np.column_stack([hist_it[:nh], hist_res[:nh] / scale])
    return IterativeResult(best_r, u, res, res_abs, sweeps, tol, "nsgs-rolling", history)
