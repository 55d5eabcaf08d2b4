"""Siconos's Moreau–Jean step replayed on a scene of ours: where the two schemes part, to the bit.

``benchmarks/siconos_peer.py`` runs Siconos's ``MoreauJeanOSI`` on the
friction drive (a ``LagrangianDS`` with a ``LagrangianRheonomousR``, C plugins
written apart from the scene); our Moreau–Jean's final state differs from it
by 4e-4 of the rotor displacement after 20 000 steps. This module shows that
the difference is where each scheme linearises its step, and nothing else.

Both are the theta-method (here ``theta = 1``) on ``M dv = F dt + H^T dp``
with the contact law on the velocity ``U = H v + w`` of the step's end. They
differ in the point of the linearisation:

* moreau (``moreau.integrators.moreau_jean``) linearises at the start
  ``q_k``: ``v_free = v_k + W^-1 [h F(t_k+1, q_k, v_k) + h^2 K v_k]`` with
  ``W = M - h C - h^2 K`` (``K = dF/dq``, ``C = dF/dv`` at ``q_k``) and the
  contact rows ``H, w`` at ``(q_k, t_k+1)``;
* Siconos starts its Newton loop from the predictor ``q0 = q_k + h v_k``
  (``MoreauJeanOSI::computeInitialNewtonState``, "we start the Newton loop
  q = q0 + h v0") and stops after one iteration when the residual is below
  its tolerance: ``v_free = v_k + W^-1 h F(t_k+1, q0, v_k)`` with ``W``,
  ``H`` and ``w`` at ``(q0, t_k+1)``.

``F(q0) = F(q_k) + h K v_k + O(h^2)``, so the two free velocities agree to
``O(h^3)``; the rows' point moves the contact normal by ``O(h)``, and with
it the impulse's direction, which is most of the difference. Each is first
order; they part by ``O(h)`` over a fixed time.

:func:`replay` runs either linearisation through the scene's own functions
(``mass``, ``forces``, ``force_jacobians``, ``contact_jacobians``, ``gaps``)
and moreau's contact solve, with moreau's index set. At the start point it
is moreau's generic step (``tests/test_siconos_replica.py``: the same final
state to 1e-13); at the predictor it is Siconos's step, and lands on
Siconos's final state (``bench_moreau_jean.py`` prints both: 6.8e-14 of the
rotor displacement against 4.4e-4, at 185 and 2000 Hz).
"""

import numpy as np

from moreau.integrators.contact_problem import solve_contact_problem


def replay(scene, q0, v0, h, steps, at="start"):
    """``steps`` Moreau–Jean steps (``theta = 1``) of ``scene`` linearised ``at`` ``"start"`` or ``"predictor"``.

    Returns the final ``(q, v)``. The index set is moreau's (a contact is
    active when ``g + h/2 vN <= 0`` at the step's start, or when it carried
    an impulse in the step before); every active contact's rows go into one
    contact problem.

    Examples
    --------
    >>> import math
    >>> from moreau.scenes import FrictionDrive
    >>> sc = FrictionDrive(frequency=2000.0)
    >>> q, v = replay(sc, *sc.initial_state(), 2 * math.pi / 1000, 10, at="predictor")
    >>> q.shape
    (2,)
    """
    if at not in ("start", "predictor"):
        raise ValueError(f"`at` must be 'start' or 'predictor', got {at!r}")
    q, v = np.array(q0, dtype=float), np.array(v0, dtype=float)
    mu = np.asarray(scene.mu, dtype=float)
    e = np.asarray(scene.restitution, dtype=float)
    trow = np.full(mu.size, -1)
    trow[scene.frictional_index] = np.arange(len(scene.frictional_index))
    closed = np.zeros(mu.size, dtype=bool)
    for k in range(steps):
        t0, t1 = k * h, (k + 1) * h
        qp = q + h * v if at == "predictor" else q
        M = np.asarray(scene.mass(qp), dtype=float)
        f = np.asarray(scene.forces(qp, v, t1), dtype=float)
        K, C = (np.asarray(a, dtype=float) for a in scene.force_jacobians(qp, v, t1))
        rhs = h * f if at == "predictor" else h * f + h * h * (K @ v)
        Winv = np.linalg.inv(M - h * C - h * h * K)
        v_free = v + Winv @ rhs
        WN0, wN0, _, _ = (np.asarray(a, dtype=float) for a in scene.contact_jacobians(q, t0))
        vN0 = WN0 @ v + wN0
        active = (np.asarray(scene.gaps(q, t0), dtype=float) + 0.5 * h * vN0 <= 0.0) | closed
        ia = np.flatnonzero(active)
        pN = np.zeros(mu.size)
        v1 = v_free
        if ia.size:
            WN, wN, WT, wT = (np.asarray(a, dtype=float) for a in scene.contact_jacobians(qp, t1))
            tr = trow[ia][trow[ia] >= 0]
            H = np.vstack([WN[ia], WT[tr]])
            w = np.concatenate([wN[ia], wT[tr]])
            W = H @ Winv @ H.T
            p, pN[ia], _ = solve_contact_problem(W, H @ v_free + w, mu[ia], e[ia], vN0[ia])
            v1 = v_free + Winv @ H.T @ p
        q = q + h * v1
        v = v1
        closed = pN > 0.0
    return q, v
