"""Nonsmooth Gauss–Seidel (NSGS) for the 2D frictional contact problem in FCLib's form.

One sweep visits the contacts in order; contact ``i`` is solved exactly with
the others' impulses held (:func:`moreau.contact._sparse.local_solve`: the
local 2D Coulomb problem has closed-form cases), and its impulse replaces the
old one at once (Gauss–Seidel), optionally over-relaxed and projected back
onto the cone (``omega``; Jourdan, Alart and Jean 1998 describe the method,
Acary, Brémond and Huber 2018 compare it on FCLib). ``W`` stays in CSR: a
sweep costs the nonzeros of ``W``, linear in the contacts for a granular
problem.

The stop is certified: every ``check_every`` sweeps the natural-map
residual of the current impulses is computed in full; the solve stops when
it falls to ``tol``, or at the budget ``max_sweeps``. The result carries the
residual recomputed (compensated sums) on the impulses it returns, and says
``"not converged"`` when that exceeds ``tol``.
"""

import math

import numpy as np
from numba import njit

from moreau import _jit_cache
from moreau._validate import finite_scalar, positive_int
from moreau.contact import _sparse
from moreau.contact._sparse import check_problem, local_solve, project_cone, record_check
from moreau.errors import InputError

from ..registry import register_solver
from . import _iterative

#: numba's cache pickles the module's name with the machine code; a copy of this file imported
#: under another name (pytest's doctest collection imports a module outside a regular package
#: by its bare file name) would write entries that the package cannot load, so only the
#: package's own import caches
_CACHE = __name__.startswith("moreau.")

__all__ = ["solve_nsgs", "solve"]


@njit(cache=_CACHE)
def _nsgs(indptr, indices, data, q, mu, r, max_sweeps, check_every, tol_abs, hist_it, hist_res,
          best_r, blocks, omega):
    nc = mu.shape[0]
    u = np.empty_like(q)
    nh, best, stop = record_check(indptr, indices, data, q, r, u, mu, 0, max_sweeps, check_every,
                                  hist_it, hist_res, 0, math.inf, best_r, tol_abs)
    sweeps = 0
    while not stop and sweeps < max_sweeps:
        for i in range(nc):
            a = 2 * i
            Wnn = blocks[i, 0, 0]
            Wnt = blocks[i, 0, 1]
            Wtn = blocks[i, 1, 0]
            Wtt = blocks[i, 1, 1]
            bn = q[a]
            for k in range(indptr[a], indptr[a + 1]):
                bn += data[k] * r[indices[k]]
            bt = q[a + 1]
            for k in range(indptr[a + 1], indptr[a + 2]):
                bt += data[k] * r[indices[k]]
            rn = r[a]
            rt = r[a + 1]
            bn -= Wnn * rn + Wnt * rt
            bt -= Wtn * rn + Wtt * rt
            if Wnn <= 0.0:
                # a contact between bodies that cannot move: no impulse changes anything
                continue
            sn, st = local_solve(Wnn, Wnt, Wtn, Wtt, bn, bt, mu[i])
            if omega != 1.0:
                sn, st = project_cone(mu[i], rn + omega * (sn - rn), rt + omega * (st - rt))
            r[a] = sn
            r[a + 1] = st
        sweeps += 1
        nh, best, stop = record_check(indptr, indices, data, q, r, u, mu, sweeps, max_sweeps,
                                      check_every, hist_it, hist_res, nh, best, best_r, tol_abs)
    return sweeps, nh


_jit_cache.bind_cache_to_sources([_nsgs], [__file__, _sparse.__file__])


def solve_nsgs(W, q, mu, *, r0=None, tol=1e-8, max_sweeps=10_000, omega=1.0, check_every=4):
    """Solve the 2D frictional contact problem ``(W, q, mu)`` by NSGS.

    Parameters
    ----------
    W : sparse matrix or array_like, shape (2 nc, 2 nc)
        Delassus operator, rows ``[N_i, T_i]`` interleaved per contact.
    q : array_like, shape (2 nc,)
        Free velocity (the impact law folded into its normal entries).
    mu : array_like, shape (nc,)
        Friction coefficients, ``>= 0``.
    r0 : array_like, shape (2 nc,), optional
        Warm start (for instance the last step's impulses); projected onto
        the cones first. Zero by default.
    tol : float
        Tolerance on ``residual = ||F(r)|| / (1 + ||q||)``, in ``[1e-15, 1)``.
    max_sweeps : int
        The budget.
    omega : float
        Relaxation in ``(0, 2)``; 1 is plain Gauss–Seidel.
    check_every : int
        Sweeps between two full residual evaluations (each costs about one
        sweep).

    Returns
    -------
    IterativeResult
        The impulses with the least residual seen (the last ones, when the
        solve converged), their certified residual and status.

    Examples
    --------
    Two contacts of a block on the ground, pushed down and sideways:

    >>> import numpy as np
    >>> from moreau.contact.solvers.nsgs import solve_nsgs
    >>> W = np.array([[2.0, 0.5, 1.0, 0.5], [0.5, 2.0, 0.5, 1.0],
    ...               [1.0, 0.5, 2.0, 0.5], [0.5, 1.0, 0.5, 2.0]])
    >>> res = solve_nsgs(W, [-1.0, 0.2, -1.0, 0.2], [0.3, 0.3], tol=1e-12)
    >>> res.status, res.residual <= 1e-12
    ('converged', True)
    >>> res = solve_nsgs(W, [-1.0, 0.2, -1.0, 0.2], [0.3, 0.3], tol=1e-14, max_sweeps=2,
    ...                  check_every=1)
    >>> res.status
    'not converged'
    """
    W, q, mu = check_problem(W, q, mu)
    tol = _sparse.checked_tolerance(tol)
    max_sweeps = positive_int("max_sweeps", max_sweeps)
    check_every = positive_int("check_every", check_every)
    omega = finite_scalar("omega", omega)
    if not 0.0 < omega < 2.0:
        raise InputError(f"`omega` must lie in (0, 2), got {omega!r}")
    blocks = _sparse.diagonal_blocks(W.indptr, W.indices, W.data, mu.shape[0], 2)
    return _sparse.CheckRecord.run(_nsgs, W, q, mu, r0, tol, max_sweeps, check_every, "nsgs",
                                   blocks, omega)


def solve(problem, *, max_iter=None, tol=None, omega=1.0, check_every=4):
    """``"nsgs"``: a :class:`~moreau.contact.ContactProblem` by :func:`solve_nsgs` in FCLib's layout.

    Parameters
    ----------
    problem : ContactProblem
        Without equality rows.
    max_iter : int, optional
        The budget of sweeps (``max_sweeps``), 10 000 by default.
    tol : float, optional
        Tolerance on the natural-map residual (:mod:`._iterative`), 1e-8 by
        default.
    omega, check_every
        As for :func:`solve_nsgs`.

    Returns
    -------
    ContactSolution
        ``residual``: the natural map recomputed on the impulses returned;
        ``status`` ``"solved"`` only when it is ``<= tol``.

    Examples
    --------
    >>> from moreau.contact import ContactProblem, solve as solve_contact
    >>> sol = solve_contact(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]), "nsgs")
    >>> sol.status, sol.method, sol.p.tolist()
    ('solved', 'nsgs', [1.0, -0.5])
    """
    return _iterative.solve_local(problem, solve_nsgs, "max_sweeps",
                                  10_000 if max_iter is None else max_iter, tol,
                                  omega=omega, check_every=check_every)


register_solver("nsgs", solve,
                summary="nonsmooth Gauss-Seidel over contacts, FCLib layout, W in CSR")
