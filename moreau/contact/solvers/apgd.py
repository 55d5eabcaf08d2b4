"""Accelerated projected gradient (APGD) for the 2D frictional contact problem in FCLib's form.

Nesterov's accelerated projected gradient with adaptive restart, as Mazhar,
Heyn, Negrut and Tasora (2015) use it for contact (Chrono's APGD), on the
map ``G(r) = W r + q + s(r)`` whose natural map is the problem's residual:
``s(r)`` adds ``mu |u_T|`` to each normal entry (De Saxcé's shift), so a fixed
point ``r = P_K(r - G(r) / L)`` is a Coulomb solution, not the solution of
the convex relaxation that plain APGD on ``1/2 r.W r + q.r`` would give
(where a sliding contact separates at ``mu |u_T|``). The shift is updated at
every step (the fixed-point-on-``s`` scheme of Acary, Cadoux, Lemaréchal and
Malick 2011, interleaved with the gradient steps); with ``mu = 0`` or no
slip it vanishes and the method is plain APGD, with its ``O(1/k^2)`` rate on
the convex problem. With slip it is a heuristic: the status says so when it
does not converge.

Step ``1 / L`` with ``L`` the largest eigenvalue of ``W``, estimated by the
power method and capped by Gershgorin's bound (an upper bound). Restart
(O'Donoghue and Candès 2015): the momentum is dropped whenever the step goes
against the gradient, ``G(y).(x_{k+1} - x_k) > 0``.

The stop is certified as in :mod:`moreau.contact.solvers.nsgs`: the
natural-map residual of the iterate every ``check_every`` steps, the
least-residual iterate returned with its residual recomputed (compensated
sums), ``"not converged"`` past the budget.
"""

import math

import numpy as np
from numba import njit

from moreau import _jit_cache
from moreau._validate import finite_scalar, positive_int
from moreau.contact import _sparse
from moreau.contact._sparse import check_problem, project_cone, record_check, velocities
from moreau.errors import InputError

from ..registry import register_solver
from . import _iterative

#: numba's cache pickles the module's name with the machine code; a copy of this file imported
#: under another name (pytest's doctest collection imports a module outside a regular package
#: by its bare file name) would write entries that the package cannot load, so only the
#: package's own import caches
_CACHE = __name__.startswith("moreau.")

__all__ = ["solve_apgd", "lipschitz_bound", "solve"]


@njit(cache=_CACHE)
def _power(indptr, indices, data, iters, seed_vec):
    x = seed_vec.copy()
    y = np.empty_like(x)
    zero = np.zeros_like(x)
    lam = 0.0
    for _ in range(iters):
        nrm = math.sqrt(np.dot(x, x))
        if nrm == 0.0:
            return 0.0
        x /= nrm
        velocities(indptr, indices, data, zero, x, y)
        lam = np.dot(x, y)
        x[:] = y
    return lam


def lipschitz_bound(W, iters=30):
    """``L`` for the gradient step: ``min(1.1 x power-method estimate, Gershgorin)`` of ``W``.

    Examples
    --------
    >>> import scipy.sparse as sps
    >>> from moreau.contact.solvers.apgd import lipschitz_bound
    >>> round(lipschitz_bound(sps.csr_array([[2.0, 1.0], [1.0, 2.0]])), 6)
    3.0
    """
    gersh = float(np.max(abs(W) @ np.ones(W.shape[0])))
    rng = np.random.default_rng(12345)
    est = _power(W.indptr, W.indices, W.data, iters, rng.random(W.shape[0]) + 0.5)
    return min(gersh, 1.1 * est) if est > 0.0 else gersh


@njit(cache=_CACHE)
def _apgd(indptr, indices, data, q, mu, x, max_iter, check_every, tol_abs, hist_it, hist_res,
          best_r, L):
    nc = mu.shape[0]
    n = q.shape[0]
    y = x.copy()
    x_new = np.empty_like(x)
    g = np.empty_like(x)
    u = np.empty_like(x)
    nh, best, stop = record_check(indptr, indices, data, q, x, u, mu, 0, max_iter, check_every,
                                  hist_it, hist_res, 0, math.inf, best_r, tol_abs)
    it = 0
    theta = 1.0
    step = 1.0 / L
    while not stop and it < max_iter:
        velocities(indptr, indices, data, q, y, g)
        for i in range(nc):
            g[2 * i] += mu[i] * abs(g[2 * i + 1])
        along = 0.0
        for i in range(nc):
            a = 2 * i
            pn, pt = project_cone(mu[i], y[a] - step * g[a], y[a + 1] - step * g[a + 1])
            x_new[a] = pn
            x_new[a + 1] = pt
            along += g[a] * (pn - x[a]) + g[a + 1] * (pt - x[a + 1])
        if along > 0.0:
            theta = 1.0
            y[:] = x_new
        else:
            theta_new = 0.5 * (1.0 + math.sqrt(1.0 + 4.0 * theta * theta))
            beta = (theta - 1.0) / theta_new
            for k in range(n):
                y[k] = x_new[k] + beta * (x_new[k] - x[k])
            theta = theta_new
        x[:] = x_new
        it += 1
        nh, best, stop = record_check(indptr, indices, data, q, x, u, mu, it, max_iter,
                                      check_every, hist_it, hist_res, nh, best, best_r, tol_abs)
    return it, nh


_jit_cache.bind_cache_to_sources([_power, _apgd], [__file__, _sparse.__file__])


def solve_apgd(W, q, mu, *, r0=None, tol=1e-8, max_iter=100_000, check_every=10, L=None):
    """Solve the 2D frictional contact problem ``(W, q, mu)`` by APGD with restart.

    Parameters
    ----------
    W, q, mu
        As for :func:`moreau.contact.solvers.nsgs.solve_nsgs`.
    r0 : array_like, shape (2 nc,), optional
        Warm start, projected onto the cones first; zero by default.
    tol : float
        Tolerance on ``residual = ||F(r)|| / (1 + ||q||)``, in ``[1e-15, 1)``.
    max_iter : int
        Budget of gradient steps (each one product with ``W``).
    check_every : int
        Steps between two full residual evaluations.
    L : float, optional
        Upper bound on ``W``'s largest eigenvalue; :func:`lipschitz_bound` by
        default.

    Returns
    -------
    IterativeResult

    Examples
    --------
    The block of :func:`~moreau.contact.solvers.nsgs.solve_nsgs`'s example: APGD
    converges to NSGS's impulses.

    >>> import numpy as np
    >>> from moreau.contact.solvers.nsgs import solve_nsgs
    >>> W = np.array([[2.0, 0.5, 1.0, 0.5], [0.5, 2.0, 0.5, 1.0],
    ...               [1.0, 0.5, 2.0, 0.5], [0.5, 1.0, 0.5, 2.0]])
    >>> q, mu = [-1.0, 0.2, -1.0, 0.2], [0.3, 0.3]
    >>> res = solve_apgd(W, q, mu, tol=1e-10)
    >>> res.status, res.residual <= 1e-10, bool(np.allclose(res.r, solve_nsgs(W, q, mu).r))
    ('converged', True, True)
    """
    W, q, mu = check_problem(W, q, mu)
    tol = _sparse.checked_tolerance(tol)
    max_iter = positive_int("max_iter", max_iter)
    check_every = positive_int("check_every", check_every)
    if L is None:
        L = lipschitz_bound(W)
    else:
        L = finite_scalar("L", L)
        if L <= 0.0:
            raise InputError(f"`L` must be > 0, got {L!r}")
    if L <= 0.0:
        # W = 0: the impulses change no velocity; start from zero and report
        L = 1.0
    return _sparse.CheckRecord.run(_apgd, W, q, mu, r0, tol, max_iter, check_every, "apgd",
                                   float(L))


def solve(problem, *, max_iter=None, tol=None, check_every=10, L=None):
    """``"apgd"``: a :class:`~moreau.contact.ContactProblem` by :func:`solve_apgd` in FCLib's layout.

    Parameters
    ----------
    problem, tol
        As for ``"nsgs"`` (:func:`moreau.contact.solvers.nsgs.solve`).
    max_iter : int, optional
        The budget of gradient steps, 100 000 by default.
    check_every, L
        As for :func:`solve_apgd`.

    Returns
    -------
    ContactSolution
        As for ``"nsgs"``.

    Examples
    --------
    The problem of ``"nsgs"``'s example, solved to the same impulses:

    >>> from moreau.contact import ContactProblem, solve as solve_contact
    >>> problem = ContactProblem(np.eye(2), [-1.0, 1.0], [0.5])
    >>> [np.round(solve_contact(problem, m, tol=1e-12).p, 9).tolist() for m in ("apgd", "nsgs")]
    [[1.0, -0.5], [1.0, -0.5]]
    """
    return _iterative.solve_local(problem, solve_apgd, "max_iter",
                                  100_000 if max_iter is None else max_iter, tol,
                                  check_every=check_every, L=L)


register_solver("apgd", solve,
                summary="accelerated projected gradient with restart, FCLib layout, W in CSR")
