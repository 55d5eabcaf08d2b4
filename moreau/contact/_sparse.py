"""Block-sparse 2D frictional contact problems in FCLib's local form, and their residual.

The problem (FCLib's local problem, spacedim 2; Acary, Brémond and Huber
2018): given ``W`` (``n x n``, ``n = 2 nc``, rows interleaved per contact
``[N_0, T_0, N_1, T_1, ...]``), ``q`` and one friction coefficient per
contact, find ``r`` and ``u = W r + q`` with, for every contact ``i``,

    ``K_i = {(r_N, r_T): |r_T| <= mu_i r_N}``,
    ``u_hat_i = (u_N + mu_i |u_T|, u_T)``,
    ``K_i* ∋ u_hat_i  ⊥  r_i ∈ K_i``   (De Saxcé's modified complementarity).

In the plane this is Coulomb's law exactly: take-off (``r = 0``, ``u_N >= 0``),
stick (``u = 0``, ``r`` in the cone) or slip (``u_N = 0``, ``r`` on the
cone's edge opposite to ``u_T``). The impact law is folded into ``q`` by the
caller (``q_N + e min(vN_pre, 0)``).

The residual every solver here reports is the natural map on the caller's
data, ``F(r) = r - P_K(r - u_hat(r))`` (``P_K`` the Euclidean projection onto
the product of cones), which is zero exactly at a solution:

    ``residual_abs = ||F(r)||_2``,  ``residual = residual_abs / (1 + ||q||_2)``.

It is computed after the last sweep from ``r`` alone, with ``u = W r + q``
accumulated by compensated (twice-working-precision) dot products, so the
number reported is the residual of the impulses returned, exact to a few
units of rounding of the size of ``r`` and ``u`` (``tests/contact`` checks it
against exact rational arithmetic: a residual of 1e-8 with impulses of size
1 is exact to about seven digits).

``W = H M^-1 H^T`` is kept in compressed sparse rows (scipy's CSR arrays): a
contact couples only with the contacts that share a body, so a row holds
``2 (1 + neighbours)`` entries. :func:`delassus` builds it with ``M^-1``
applied body by body.
"""

import math

import numpy as np
import scipy.sparse as sps
from numba import njit

from moreau import _jit_cache
from moreau._validate import finite_array, finite_scalar
from moreau.errors import InputError
from moreau.lcp import _certified
from moreau.lcp._certified import two_prod

#: numba's cache pickles the module's name with the machine code; a copy of this file imported
#: under another name (pytest's doctest collection imports a module outside a regular package
#: by its bare file name) would write entries that the package cannot load, so only the
#: package's own import caches
_CACHE = __name__.startswith("moreau.")

__all__ = ["IterativeResult", "check_problem", "project_cone", "start_impulses", "local_solve",
           "natural_map",
           "problem_residual", "delassus", "disk_jacobian", "chain_impact_problem",
           "stacked_disks_problem", "DENSE_CROSSOVER"]

#: contacts up to which the dense path (``W`` dense, the friction LCP, Lemke) is as fast as
#: the sparse one: ``benchmarks/bench_contact_solvers.py --crossover`` timed the two equal
#: between 16 and 32 contacts on short frictional chains (two runs; ``W`` positive definite,
#: Lemke's best case) and NSGS (CSR, to 1e-10) 3x faster at 64, 10x at 128; on hyperstatic
#: stacks Lemke took 0.9 s at 18 contacts. :func:`delassus` returns CSR at any size; a
#: caller picking Lemke up to this size densifies
DENSE_CROSSOVER = 32


class IterativeResult:
    """What an iterative contact solver returns.

    Attributes
    ----------
    r, u : ndarray, shape (2 nc,)
        Impulses and the velocities ``W r + q`` they give (interleaved
        ``[N, T]`` per contact).
    residual : float
        ``||F(r)||_2 / (1 + ||q||_2)``, the natural map recomputed on the
        returned ``r`` (never NaN; ``inf`` only if no finite iterate existed).
    residual_abs : float
        ``||F(r)||_2``.
    converged : bool
        ``residual <= tol``.
    status : str
        ``"converged"`` or ``"not converged"``.
    iterations : int
        Sweeps (NSGS) or gradient steps (APGD) done.
    tol : float
        The tolerance asked for.
    solver : str
    history : ndarray
        ``(iteration, residual)`` rows at each check, in order.
    """

    __slots__ = ("r", "u", "residual", "residual_abs", "converged", "status", "iterations",
                 "tol", "solver", "history")

    def __init__(self, r, u, residual, residual_abs, iterations, tol, solver, history):
        self.r = r
        self.u = u
        self.residual = float(residual)
        self.residual_abs = float(residual_abs)
        self.iterations = int(iterations)
        self.tol = float(tol)
        self.converged = bool(self.residual <= self.tol)
        self.status = "converged" if self.converged else "not converged"
        self.solver = solver
        self.history = history

    @property
    def message(self):
        """One line: status, residual against tolerance, iterations."""
        rel = "<=" if self.converged else ">"
        return (f"{self.solver}: {self.status}, residual {self.residual:.3e} {rel} tol "
                f"{self.tol:.1e} after {self.iterations} iterations")

    def __repr__(self):
        return f"IterativeResult({self.message})"


# -- input ---------------------------------------------------------------------------------------

def csr_delassus(W, rows, rule):
    """``W`` as a finite square CSR array of ``rows`` rows a contact, or an ``InputError``.

    ``rule`` names the row count in the message (the callers' wording).
    """
    if sps.issparse(W):
        W = sps.csr_array(W, dtype=float)
        W.sum_duplicates()
        if not np.all(np.isfinite(W.data)):
            raise InputError("`W` must contain only finite values (no NaN or inf)")
    else:
        W = sps.csr_array(finite_array("W", W, ndim=2))
    n = W.shape[0]
    if W.shape != (n, n) or n % rows or n == 0:
        raise InputError(f"`W` must be square with {rule}, got shape {W.shape}")
    return W


def check_problem(W, q, mu):
    """Validate FCLib-form data; return ``(W as CSR float64, q, mu)``.

    Raises
    ------
    InputError
        ``W`` not square ``2 nc x 2 nc``, ``q`` or ``mu`` of the wrong length,
        non-finite values, ``mu < 0``.

    Examples
    --------
    >>> W, q, mu = check_problem([[1.0, 0.0], [0.0, 1.0]], [-1.0, 0.0], [0.3])
    >>> W.shape, q.tolist(), mu.tolist()
    ((2, 2), [-1.0, 0.0], [0.3])
    >>> check_problem([[1.0, 0.0], [0.0, 1.0]], [-1.0, 0.0], [0.3, 0.1])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `mu` must have one entry per contact (1), got shape (2,)
    """
    W = csr_delassus(W, 2, "an even number (2 per contact) of rows")
    n = W.shape[0]
    q = finite_array("q", q, shape=(n,))
    mu = finite_array("mu", mu, ndim=1)
    if mu.shape != (n // 2,):
        raise InputError(f"`mu` must have one entry per contact ({n // 2}), got shape {mu.shape}")
    if np.any(mu < 0.0):
        raise InputError("`mu` must be >= 0 for every contact")
    W.indices = W.indices.astype(np.int64, copy=False)
    W.indptr = W.indptr.astype(np.int64, copy=False)
    return W, q, mu


@njit(cache=_CACHE)
def diagonal_blocks(indptr, indices, data, nc, d):
    """The ``d x d`` diagonal blocks of a CSR matrix, shape ``(nc, d, d)``.

    ``d`` is 2 for the plane's contacts ``[N, T]``, 3 with a rolling row. The CSR
    must hold one entry a column in a row (duplicates summed, as
    :func:`check_problem` leaves it): each entry is copied, not added. One pass
    over the nonzeros; scipy's three diagonals cost 2 ms at 12 000 contacts.
    """
    # no doctest: the doctest run imports this file outside the package, uncached, and would
    # compile the loop (a second) at every run; the NSGS tests cover it
    blocks = np.zeros((nc, d, d))
    for i in range(nc):
        for row in range(d):
            a = d * i + row
            for k in range(indptr[a], indptr[a + 1]):
                c = indices[k] - d * i
                if 0 <= c < d:
                    blocks[i, row, c] = data[k]
    return blocks


# -- the cone, the local problem, the residual ---------------------------------------------------

@njit(cache=_CACHE)
def project_cone(mu, rn, rt):
    """Euclidean projection of ``(rn, rt)`` onto ``{|r_T| <= mu r_N}``.

    Inside: itself. In the polar cone (``mu |rt| <= -rn``): the apex.
    Otherwise onto the edge ``t (1, mu s)``, ``s = sign(rt)``, at
    ``t = (rn + mu |rt|) / (1 + mu^2)``.

    Examples
    --------
    >>> from moreau.contact._sparse import project_cone
    >>> project_cone(0.5, 1.0, 2.0)
    (1.6, 0.8)
    >>> project_cone(0.5, -1.0, 0.1)
    (0.0, 0.0)
    >>> project_cone(0.0, -1.0, 0.0)
    (0.0, 0.0)
    """
    a = abs(rt)
    # (rn >= 0: with mu = 0 the test a <= mu rn alone holds at rt = 0 for any rn, 0 <= -0.0)
    if a <= mu * rn and rn >= 0.0:
        return rn, rt
    if mu * a <= -rn:
        return 0.0, 0.0
    t = (rn + mu * a) / (1.0 + mu * mu)
    return t, math.copysign(mu * t, rt)


@njit(cache=_CACHE)
def _project_start(r, mu):
    # compiled: a Python loop over the contacts cost about 0.8 us a contact (one dispatch of
    # project_cone each), 10 ms at 12 000 contacts, more than ten sweeps of a warm-started step
    for i in range(mu.shape[0]):
        r[2 * i], r[2 * i + 1] = project_cone(mu[i], r[2 * i], r[2 * i + 1])


def start_impulses(r0, q, mu):
    """An iterative solver's first impulses: ``r0`` (checked, copied) or zero, on the cones.

    Examples
    --------
    >>> q, mu = np.array([-1.0, 0.0]), np.array([0.5])
    >>> start_impulses([1.0, 2.0], q, mu).tolist()
    [1.6, 0.8]
    >>> start_impulses(None, q, mu).tolist()
    [0.0, 0.0]
    """
    r = np.zeros_like(q) if r0 is None else finite_array("r0", r0, shape=q.shape).copy()
    _project_start(r, mu)
    return r


@njit(cache=_CACHE)
def _local_residual_sq(Wnn, Wnt, Wtn, Wtt, bn, bt, mu, rn, rt):
    un = Wnn * rn + Wnt * rt + bn
    ut = Wtn * rn + Wtt * rt + bt
    pn, pt = project_cone(mu, rn - (un + mu * abs(ut)), rt - ut)
    return (rn - pn) ** 2 + (rt - pt) ** 2


@njit(cache=_CACHE)
def local_solve(Wnn, Wnt, Wtn, Wtt, bn, bt, mu):
    """Exact solution of one 2D contact: ``u = [[Wnn, Wnt], [Wtn, Wtt]] r + b``, Coulomb.

    Tries take-off, stick, slip one way, slip the other, in this order, and
    returns the first that holds (Coulomb's law in the plane has no other
    cases); when rounding makes every test fail by a hair (a contact on the
    stick/slip boundary), the candidate with the least local residual.

    Examples
    --------
    A unit block pushed into the ground at speed 1 while sliding at 1, ``mu = 0.5``:

    >>> from moreau.contact._sparse import local_solve
    >>> local_solve(1.0, 0.0, 0.0, 1.0, -1.0, 1.0, 0.5)
    (1.0, -0.5)
    """
    if bn >= 0.0:
        return 0.0, 0.0
    det = Wnn * Wtt - Wnt * Wtn
    sn = 0.0
    st = 0.0
    stick_ok = False
    if det > 1e-14 * abs(Wnn * Wtt) and det > 0.0:
        sn = (-bn * Wtt + bt * Wnt) / det
        st = (-bt * Wnn + bn * Wtn) / det
        stick_ok = True
        if sn >= 0.0 and abs(st) <= mu * sn:
            return sn, st
    best_n = 0.0
    best_t = 0.0
    best = _local_residual_sq(Wnn, Wnt, Wtn, Wtt, bn, bt, mu, 0.0, 0.0)
    if stick_ok:
        pn, pt = project_cone(mu, sn, st)
        res = _local_residual_sq(Wnn, Wnt, Wtn, Wtt, bn, bt, mu, pn, pt)
        if res < best:
            best, best_n, best_t = res, pn, pt
    for k in range(2):
        s = 1.0 if k == 0 else -1.0
        den = Wnn - mu * s * Wnt
        if den > 0.0:
            rn = -bn / den
            ut = (Wtn - mu * s * Wtt) * rn + bt
            if s * ut >= 0.0:
                return rn, -mu * s * rn
            res = _local_residual_sq(Wnn, Wnt, Wtn, Wtt, bn, bt, mu, rn, -mu * s * rn)
            if res < best:
                best, best_n, best_t = res, rn, -mu * s * rn
    return best_n, best_t


@njit(cache=_CACHE, inline="always")
def _two_sum(a, b):
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@njit(cache=_CACHE)
def velocities_compensated(indptr, indices, data, q, r, u):
    """``u = W r + q`` row by row with compensated sums (Ogita, Rump, Oishi 2005, Dot2)."""
    n = q.shape[0]
    for i in range(n):
        s = q[i]
        c = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            p, ep = two_prod(data[k], r[indices[k]])
            s, es = _two_sum(s, p)
            c += ep + es
        u[i] = s + c


@njit(cache=_CACHE)
def velocities(indptr, indices, data, q, r, u):
    """``u = W r + q`` (plain float sums, for the solvers' inner checks)."""
    n = q.shape[0]
    for i in range(n):
        s = q[i]
        for k in range(indptr[i], indptr[i + 1]):
            s += data[k] * r[indices[k]]
        u[i] = s


@njit(cache=_CACHE)
def natural_map(r, u, mu):
    """``||F(r)||_2^2`` of the natural map, given ``u = W r + q``; ``inf`` if not finite."""
    nc = mu.shape[0]
    s = 0.0
    for i in range(nc):
        rn = r[2 * i]
        rt = r[2 * i + 1]
        un = u[2 * i]
        ut = u[2 * i + 1]
        pn, pt = project_cone(mu[i], rn - (un + mu[i] * abs(ut)), rt - ut)
        s += (rn - pn) ** 2 + (rt - pt) ** 2
    if not math.isfinite(s):
        return math.inf
    return s


@njit(cache=_CACHE, inline="always")
def record_check(indptr, indices, data, q, r, u, mu, it, budget, check_every, hist_it, hist_res,
                 nh, best, best_r, tol_abs):
    """An iterative solver's check after iteration ``it`` of ``budget``, when due (at the
    start, every ``check_every`` iterations and at the budget): the true residual of ``r``
    recorded, the best iterate kept; returns ``(nh, best, stop)``, ``stop`` where the
    residual meets ``tol_abs`` or is no longer finite."""
    if it % check_every != 0 and it != budget:
        return nh, best, False
    velocities(indptr, indices, data, q, r, u)
    res = math.sqrt(natural_map(r, u, mu))
    hist_it[nh] = it
    hist_res[nh] = res
    # the first iterate is kept whatever its residual (a NaN one stops the solver there)
    if nh == 0 or res < best:
        best = res
        best_r[:] = r
    return nh + 1, best, (not math.isfinite(res)) or res <= tol_abs


_jit_cache.bind_cache_to_sources(
    [project_cone, _project_start, _local_residual_sq, local_solve, _two_sum, velocities_compensated,
     velocities, natural_map, record_check, diagonal_blocks], [__file__, _certified.__file__])


def problem_residual(W, q, mu, r):
    """The certified residual of impulses ``r``: ``(residual, residual_abs, u)``.

    Parameters
    ----------
    W, q, mu : FCLib-form data (checked by :func:`check_problem`).
    r : array_like, shape (2 nc,)

    Returns
    -------
    residual : float
        ``||F(r)||_2 / (1 + ||q||_2)``.
    residual_abs : float
        ``||F(r)||_2``.
    u : ndarray
        ``W r + q``.

    Examples
    --------
    >>> from moreau.contact._sparse import problem_residual
    >>> res, res_abs, u = problem_residual([[1.0, 0.0], [0.0, 1.0]], [-1.0, 1.0], [0.5], [1.0, -0.5])
    >>> res, u.tolist()
    (0.0, [0.0, 0.5])
    """
    W, q, mu = check_problem(W, q, mu)
    r = finite_array("r", r, shape=q.shape)
    return _residual_checked(W, q, mu, r)


def _residual_checked(W, q, mu, r):
    u = np.empty_like(q)
    velocities_compensated(W.indptr, W.indices, W.data, q, r, u)
    res_abs = math.sqrt(natural_map(r, u, mu))
    return res_abs / (1.0 + float(np.linalg.norm(q))), res_abs, u


def checked_tolerance(tol):
    """``tol`` of an iterative solver, a finite number in ``[1e-15, 1)``."""
    tol = finite_scalar("tol", tol)
    if not 1e-15 <= tol < 1.0:
        raise InputError(f"`tol` must lie in [1e-15, 1), got {tol!r}")
    return tol


class CheckRecord:
    """The history buffers an iterative solver's :func:`record_check` fills, and its result.

    One entry per check, every ``check_every`` of ``budget`` iterations, and
    two more (the start and the last iteration). The residuals are recorded
    absolute and returned relative to ``scale = 1 + ||q||``, the units of ``tol``.
    """

    def __init__(self, q, budget, check_every):
        self.scale = 1.0 + float(np.linalg.norm(q))
        n = budget // check_every + 2
        self.iterations = np.zeros(n, dtype=np.int64)
        self.residuals = np.zeros(n)

    @classmethod
    def run(cls, kernel, W, q, mu, r0, tol, budget, check_every, solver, *extra):
        """``kernel`` from ``r0`` (:func:`start_impulses`) and its :meth:`result`.

        ``kernel(indptr, indices, data, q, mu, r, budget, check_every, tol_abs, hist_it,
        hist_res, best_r, *extra)`` fills the history by :func:`record_check` and returns
        its iterations and checks.
        """
        r = start_impulses(r0, q, mu)
        checks = cls(q, budget, check_every)
        best_r = np.empty_like(r)
        it, nh = kernel(W.indptr, W.indices, W.data, q, mu, r, budget, check_every,
                        tol * checks.scale, checks.iterations, checks.residuals, best_r, *extra)
        return checks.result(W, q, mu, best_r, it, nh, tol, solver)

    def result(self, W, q, mu, best_r, iterations, n_checks, tol, solver):
        """The :class:`IterativeResult` of ``best_r``, its residual recomputed (compensated sums)."""
        res, res_abs, u = _residual_checked(W, q, mu, best_r)
        history = np.column_stack([self.iterations[:n_checks],
                                   self.residuals[:n_checks] / self.scale])
        return IterativeResult(best_r, u, res, res_abs, iterations, tol, solver, history)


# -- building W = H M^-1 H^T ---------------------------------------------------------------------

def delassus(H, inv_mass):
    """``W = H M^-1 H^T`` in CSR, ``M^-1`` applied body by body.

    Parameters
    ----------
    H : sparse or array_like, shape (2 nc, k nb)
        Contact Jacobian, rows interleaved ``[N_i, T_i]``, columns ``k``
        per body.
    inv_mass : array_like, shape (nb, k, k) or (nb, k)
        Each body's inverse mass matrix (or its diagonal).

    Returns
    -------
    scipy.sparse.csr_array

    Examples
    --------
    Two unit point masses on a line (``k = 1``) and one contact between them:

    >>> W = delassus([[-1.0, 1.0], [0.0, 0.0]], [[1.0], [1.0]])
    >>> W.toarray().tolist()
    [[2.0, 0.0], [0.0, 0.0]]
    """
    H = sps.csr_array(H, dtype=float)
    Mi = np.asarray(inv_mass, dtype=float)
    if Mi.ndim == 2:
        nb, k = Mi.shape
        Minv = sps.diags_array(Mi.ravel()).tocsr()
    elif Mi.ndim == 3 and Mi.shape[1] == Mi.shape[2]:
        nb, k = Mi.shape[:2]
        Minv = sps.block_diag(list(Mi), format="csr")
    else:
        raise InputError(f"`inv_mass` must have shape (nb, k, k) or (nb, k), got {Mi.shape}")
    if H.shape[1] != nb * k:
        raise InputError(f"`H` must have {nb * k} columns ({nb} bodies x {k}), got {H.shape[1]}")
    W = sps.csr_array(H @ Minv @ H.T)
    W.sum_duplicates()
    W.sort_indices()
    return W


def disk_jacobian(contacts, centres, n_bodies):
    """The 2D contact Jacobian of rigid bodies ``(x, y, theta)``, as CSR.

    Parameters
    ----------
    contacts : sequence of (a, b, point, normal)
        Body ``a`` (or ``-1`` for the fixed ground) and body ``b``, the contact
        point and the unit normal pointing from ``a`` to ``b``.
    centres : array_like, shape (nb, 2)
    n_bodies : int

    Returns
    -------
    scipy.sparse.csr_array, shape (2 nc, 3 nb)
        Row ``2 i``: ``u_N = n . (v_b(p) - v_a(p))``; row ``2 i + 1``: the same
        along ``t = (-n_y, n_x)``, where ``v(p) = v + omega e_z x (p - c)``.

    Examples
    --------
    >>> H = disk_jacobian([(-1, 0, (0.0, 0.0), (0.0, 1.0))], [[0.0, 1.0]], 1)
    >>> H.toarray().tolist()
    [[0.0, 1.0, 0.0], [-1.0, 0.0, -1.0]]
    """
    centres = np.asarray(centres, dtype=float)
    rows, cols, vals = [], [], []
    for i, (a, b, p, nrm) in enumerate(contacts):
        n = np.asarray(nrm, dtype=float)
        t = np.array([-n[1], n[0]])
        p = np.asarray(p, dtype=float)
        for body, sign in ((a, -1.0), (b, 1.0)):
            if body < 0:
                continue
            d = p - centres[body]
            for row, e in ((2 * i, n), (2 * i + 1, t)):
                # e . (omega e_z x d) = omega (e_y d_x - e_x d_y)
                rows += [row] * 3
                cols += [3 * body, 3 * body + 1, 3 * body + 2]
                vals += [sign * e[0], sign * e[1], sign * (e[1] * d[0] - e[0] * d[1])]
    H = sps.coo_array((vals, (rows, cols)), shape=(2 * len(contacts), 3 * n_bodies))
    return sps.csr_array(H)


def chain_impact_problem(n_balls, e=0.0, mu=0.0, mass=1.0, radius=1.0):
    """The simultaneous impact of a struck chain of equal disks, and its exact solution.

    ``n_balls`` disks of mass ``mass`` touch in a row along ``x``; the first
    moves at speed 1 into the others, at rest. With Newton's law at every
    contact (restitution ``e``) the ``n_balls - 1`` contacts solve one
    problem, and its solution is the block result (derived in the notes):
    balls ``1 .. N-1`` leave together at ``w = (1 + e) / N``, the striker at
    ``w - e``, every contact keeps pressing, and the normal impulse of
    contact ``i`` (balls ``i``, ``i + 1``) is ``(N - 1 - i) w m``.

    Returns
    -------
    W : scipy.sparse.csr_array, shape (2 (N-1), 2 (N-1))
    q : ndarray
        Free contact velocities, the impact law folded in:
        ``q_N0 = -(1 + e)``, every other entry 0.
    mu : ndarray
    r_exact : ndarray
        The exact impulses (``r_T = 0``).

    Notes
    -----
    Guess every contact pressing: then ``u_N0 = e`` (the striker separates at
    ``e`` times its approach, Newton) and ``u_Ni = 0`` for ``i >= 1``: balls
    ``1 .. N-1`` share one speed ``w`` and the striker has ``w - e``.
    Momentum, ``(w - e) + (N - 1) w = 1``, gives ``w = (1 + e) / N``. Ball
    ``j >= 1`` receives ``P_{j-1} - P_j`` (``P_{N-1} = 0``), so
    ``P_{j-1} = (N - j) w m``, all positive: the guess holds, and ``W_NN``
    (tridiagonal ``(-1, 2, -1) / m``) is positive definite, so it is the
    solution. The tangential rows (transverse velocity with the spin) see no
    impulse: ``u_T = 0`` too, so the result holds for any ``mu``.

    Examples
    --------
    >>> W, q, mu, r = chain_impact_problem(3, e=1.0)
    >>> r[0::2].tolist()
    [1.3333333333333333, 0.6666666666666666]
    """
    N = int(n_balls)
    if N < 2:
        raise InputError(f"`n_balls` must be >= 2, got {n_balls!r}")
    centres = np.column_stack([2.0 * radius * np.arange(N), np.zeros(N)])
    contacts = [(i, i + 1, (centres[i, 0] + radius, 0.0), (1.0, 0.0)) for i in range(N - 1)]
    H = disk_jacobian(contacts, centres, N)
    inertia = 0.5 * mass * radius ** 2
    W = delassus(H, np.tile([1.0 / mass, 1.0 / mass, 1.0 / inertia], (N, 1)))
    q = np.zeros(2 * (N - 1))
    q[0] = -(1.0 + e)
    w = (1.0 + e) / N
    r = np.zeros_like(q)
    r[0::2] = (N - 1 - np.arange(N - 1)) * w * mass
    return W, q, np.full(N - 1, float(mu)), r


def stacked_disks_problem(rows, cols, mu=0.5, h=1e-2, g=9.81, seed=0, jitter=0.1):
    """A granular step: a square packing of unit disks on the ground under gravity.

    ``rows x cols`` disks of radius 1 and mass 1 touch their neighbours left,
    right and below (the bottom row touches the ground): ``rows (2 cols - 1)``
    contacts. The free velocity is one step of gravity, ``-g h``, plus a
    random velocity ``jitter g h`` per disk (seeded), so some contacts stick,
    some slip and some open.

    Returns
    -------
    W, q, mu : FCLib-form data (``W`` CSR)

    Examples
    --------
    >>> W, q, mu = stacked_disks_problem(2, 3)
    >>> W.shape, mu.shape
    ((20, 20), (10,))
    """
    rng = np.random.default_rng(seed)
    nb = rows * cols
    idx = np.arange(nb).reshape(rows, cols)
    centres = np.column_stack([2.0 * (idx % cols).ravel(), 1.0 + 2.0 * (idx // cols).ravel()])
    contacts = []
    for j in range(rows):
        for k in range(cols):
            b = idx[j, k]
            below = -1 if j == 0 else idx[j - 1, k]
            contacts.append((below, b, centres[b] - (0.0, 1.0), (0.0, 1.0)))
            if k + 1 < cols:
                contacts.append((b, idx[j, k + 1], centres[b] + (1.0, 0.0), (1.0, 0.0)))
    H = disk_jacobian(contacts, centres, nb)
    W = delassus(H, np.tile([1.0, 1.0, 2.0], (nb, 1)))
    v = np.zeros(3 * nb)
    v[1::3] = -g * h
    v += jitter * g * h * rng.standard_normal(3 * nb)
    q = H @ v
    return W, q, np.full(len(contacts), float(mu))
