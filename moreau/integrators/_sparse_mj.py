"""Moreau–Jean's step on a sparse, frictionless contact model (long chains: the ball chain).

A scene whose ``sparse_contacts()`` returns ``(inv_mass, forces, jacobian,
gaps)`` rather than None is stepped here by :class:`~moreau.integrators.moreau_jean.MoreauJean`
(``fast="auto"``, ``lcp_method="auto"``, no projection): a diagonal mass
matrix (``inv_mass``, shape ``(ndof,)``), constant forces (``forces``,
shape ``(ndof,)``), frictionless contacts, the normal rows ``WN(q)`` as a
scipy CSR matrix (``jacobian(q)``) and the gaps ``gaps(q)``. Nothing of size
``ndof x ndof`` or ``nc x ndof`` is dense. It is the step of
:mod:`moreau.integrators.moreau_jean` with ``M`` diagonal and ``K = C = 0``:
``v_free = v_k + h M^-1 f``, the same index set (``g + (h/2) gdot <= 0`` or
an impulse in the step before), and the contact problem on the active
contacts, ``W = WN M^-1 WN^T`` (CSR), ``0 <= W p + WN v_free + e min(vN_k, 0)
_|_ p >= 0``.

The LCP is solved by the primal-dual active-set method
(:func:`moreau.lcp.active_set.solve_active_set`), exact to rounding in at
most ``nc + 2`` sparse solves where ``W`` is an M-matrix. A chain's ``W`` is
one: tridiagonal, positive definite, with off-diagonal entries ``-1/m_i <=
0``. On other matrices it may cycle; a solve that has not ended in ``nc + 2``
steps (LCPError), or ends with a natural-map residual ``||min(p, W p + q)||
/ (1 + ||q||)`` above :data:`SPARSE_TOL`, fails the step (status -3), never
passed silently. The residual of the answer used is recorded in
``stats["max_residual"]``, the active-set solves in ``stats["pivots"]``. A
problem with ``q >= 0`` (a chain at rest or coming apart) has the answer
``p = 0``, taken without a solve.
"""

import numpy as np
import scipy.sparse as sps

from ..errors import LCPError
from ..lcp.active_set import solve_active_set
from ..regimes import Regime
from .time_stepping import next_time

#: the natural-map residual, relative to ``1 + ||q||``, a sparse step's LCP must meet (the
#: active-set answer is exact to rounding: the chains measured end near 1e-16)
SPARSE_TOL = 1e-10


def sparse_contacts_of(scene):
    """The scene's sparse frictionless contact model, or None (the dense paths)."""
    hook = getattr(scene, "sparse_contacts", None)
    if hook is None or np.any(np.asarray(scene.mu, dtype=float) != 0.0):
        return None
    return hook()


def sparse_step(integ, model):
    """One Moreau–Jean step of ``integ`` (a MoreauJean) on ``model`` (module docstring)."""
    inv_m, f, jacobian, gaps = model
    theta = integ.theta
    t0, q, v = integ.t, integ.q, integ.v
    t1, h = next_time(integ.t0, integ._k, integ.h, integ.t_bound)
    v_free = v + h * (inv_m * f)
    WN = jacobian(q)
    if not isinstance(WN, sps.csr_array):
        WN = sps.csr_array(WN)
    nc = WN.shape[0]
    g0 = integ._end_gap[2] if integ._end_gap is not None else np.asarray(gaps(q), dtype=float)
    vN0 = WN @ v
    active = (g0 + 0.5 * h * vN0 <= 0.0) | integ._closed
    pN = np.zeros(nc)
    v1 = v_free
    if active.any():
        every = bool(active.all())
        ia = np.flatnonzero(active)
        Ha = WN if every else WN[ia]
        U = Ha @ v_free
        qa = U + integ.e_c[ia] * np.minimum(vN0[ia], 0.0)
        # q >= 0: p = 0 solves it exactly (most steps of a chain: at rest, or moving apart)
        if np.any(qa < 0.0):
            W = sps.csr_array((Ha * inv_m) @ Ha.T)
            p, residual, solves = solve_active_set(W, qa)
            c = integ.counters
            c["lcp_solves"] += 1
            c["pivots"] += solves
            c["max_residual"] = max(c["max_residual"], residual)
            if not residual <= SPARSE_TOL:
                raise LCPError(f"the sparse contact problem at t = {t0!r} ended with residual "
                               f"{residual:.3g} > {SPARSE_TOL:g}")
            pN[ia] = p
            v1 = v_free + inv_m * (Ha.T @ p)
    q1 = q + h * (theta * v1 + (1.0 - theta) * v)
    if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
        integ.counters["steps"] -= 1
        integ._fail(-5, f"non-finite state after the step at t = {t0!r}")
        return
    gap = np.asarray(gaps(q1), dtype=float)
    integ.counters["max_penetration"] = max(integ.counters["max_penetration"],
                                            float(np.max(-gap, initial=0.0)))
    regime = np.where(pN > 0.0, int(Regime.STICK), int(Regime.FLIGHT))
    integ._closed = pN > 0.0
    integ._k += 1
    integ.t, integ.q, integ.v = t1, q1, v1
    integ._end_gap = (q1, t1, gap)
    fN, zero = pN / h, np.zeros(nc)
    if integ._pending_initial:
        integ._record(t0, q, v, regime, fN, zero, zero, g0)
        integ._pending_initial = False
    if integ._k % integ.save_every == 0 or t1 >= integ.t_bound:
        integ._record(t1, q1, v1, regime, fN, zero, zero, gap)
