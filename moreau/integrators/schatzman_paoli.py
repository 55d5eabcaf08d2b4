r"""Schatzman–Paoli: a position-level scheme with the impact law in the discretisation.

The scheme (Paoli & Schatzman, SIAM J. Numer. Anal. 40, 2002)
-------------------------------------------------------------
The central-difference (Störmer–Verlet) scheme for ``M q'' = h + r``, with
the contact reaction ``r`` in the normal cone of the admissible set ``K`` at
a *weighted mean of the positions before and after the step*::

    M (q_{k+1} - 2 q_k + q_{k-1}) = h^2 h_k + H^T P
    z_k = (q_{k+1} + e q_{k-1}) / (1 + e)  in K,   P in -N_K(z_k)

With ``e = 0`` the new position itself is admissible (a plastic impact);
with ``e = 1`` the mean of the old and the new position is, which reflects
the motion elastically (Paoli and Schatzman prove convergence to the
solution with Newton's law of coefficient ``e``). In smooth phases it is the
Störmer–Verlet scheme: second order, symplectic, explicit in the forces.

Derivation of the step used here
--------------------------------
The step is written in velocity form so that the state is ``(q_k, v_k)``
like every other scheme's. With ``a_k = M^-1 h(q_k, v_k, t_k)`` (``M = M(q_k)``)
and the Verlet velocities ``u+ = v_k + (h/2) a_k`` and ``u- = v_k - (h/2) a_k``,
the positions one step ahead and behind without contact are
``q_k + h u+`` and ``q_{k-1} = q_k - h u-`` (exact for Verlet: its central
velocity is ``v_k = (q_{k+1} - q_{k-1}) / 2h``). With impulses ``p = P / h``::

    q_{k+1} = q_k + h (u+ + M^-1 H^T p)

Linearising the gap of contact ``i`` about ``(q_k, t_k)``, with the time of
``z`` being ``t_z = (t_{k+1} + e t_{k-1}) / (1 + e)``::

    g_i(z, t_z) ~ g_i + WN_i (z - q_k) + wN_i (t_z - t_k),
    z - q_k = h (u+ + M^-1 H^T p - e u-) / (1 + e),   t_z - t_k = h (1 - e) / (1 + e)

and multiplying by ``(1 + e) / h > 0`` gives the normal condition as a
velocity-level complementarity::

    0 <= U_N = (1 + e) g_i / h + (WN_i u+ + wN_i) - e (WN_i u- + wN_i) + WN_i M^-1 H^T p  _|_  p_N >= 0

that is, Newton's law between the velocities after (``u+``) and before
(``u-``) the step plus the gap itself: a closed contact is held at
``g(z) = 0`` to the linearisation, with no drift. Coulomb's law acts on the
slip velocity over the step, ``U_T = WT (q_{k+1} - q_k) / h + wT``. Both
rows share the Delassus matrix ``W = H M^-1 H^T``, so the step's problem is
the one of :func:`moreau.integrators.contact_problem.solve_contact_problem`
with ``e = 0`` in its own law (the restitution is already in ``U_free``).
The Jacobians and the rheonomic terms are taken at ``(q_k, t_k + h/2)``.

The Verlet velocity ``v_{k+1} = (q_{k+1} - q_k) / h + (h/2) M^-1 h(q_{k+1},
(q_{k+1} - q_k)/h, t_{k+1})`` carries the recursion from one step to the
next: for forces that do not depend on the velocity the scheme is then
exactly the two-step recursion above, and with velocity-dependent forces it
stays second order in smooth phases. It lacks the contact reaction of the
step's second half, so a resting contact would report ``-(h/2) g``; the
velocity the integrator reports (and records) adds half the step's velocity
jump, ``M^-1 H^T p / 2``: zero on a resting contact, and second order in a
sliding one. A run started at ``(q_0, v_0)`` takes the Verlet velocity to be
``v_0``; on a contact closed at rest this puts the virtual previous position
``h^2/2`` into the obstacle, which the first step lifts off by ``e h^2/2``
(the offset then decays by ``-e`` every step: 2.5e-5, -1.25e-5, ... with
``h = 0.01``, ``e = 0.5``).

*Index set.* Contact ``i`` enters the step's problem when its free ``U_N``
is ``<= 0`` (the mean position ``z`` would leave ``K``) or when it carried
a normal impulse in the step before.

Like every explicit scheme, the step must resolve the fastest smooth
oscillation (``h omega < 2``); a run that blows up stops with a status.
"""

import numpy as np

from .._validate import positive_int
from ._blocks import EXPLICIT_BLOWUP, CompiledRecording
from ._sp_kernels import sp_loop
from .base import Integrator, register_integrator
from ._mj_kernels import set_painleve_stop
from .contact_problem import (new_contact_counters, painleve_option, slip_signs, sliding_regimes,
                              solve_contact_problem)
from .moreau_jean import (MAX_STEPS, check_lcp_options, check_scene_contacts, check_step,
                          check_work, classify_impulse, compiled_model_of, next_time)

__all__ = ["SchatzmanPaoli"]


@register_integrator("schatzman-paoli")
class SchatzmanPaoli(CompiledRecording, Integrator):
    """Schatzman–Paoli time stepping (see the module docstring).

    Parameters
    ----------
    scene : Scene
    t0, q0, v0, t_bound
        See :class:`~moreau.integrators.base.Integrator`.
    h : float
        Time step (dimensionless), > 0; the last step is shortened to end on ``t_bound``.
    lcp_method : {"auto", "lemke", "qp"}
        Solver of the contact problem (:func:`~moreau.integrators.contact_problem.solve_contact_problem`).
    lemke_max_iter : int, optional
        Pivot limit of Lemke's method.
    save_every : int
        Record one sample every ``save_every`` steps (and the last one).
    fast : {"auto", True, False}
        Run the compiled loop (:mod:`moreau.integrators._sp_kernels`, the same
        step, equal to rounding) on a scene with a ``compiled_model()``;
        ``"auto"`` does so unless ``lcp_method="qp"``. A step whose contact
        problem Lemke cannot solve is taken by the generic step (QP fallback).
    max_steps : int
        Bound on the number of steps of the run.
    painleve : {"impulse", "stop"}
        At a one-contact step whose sliding piece has no solution (the discrete Painlevé
        condition fails the way the contact slides): take the step's unique answer, the
        impulsive stick (default; the tangential impact, counted in
        ``stats["tangential_impacts"]`` on the generic step), or stop with status ``-1``
        wherever the pressed contact's free slip, of any size, runs that way
        (:func:`~moreau.integrators.contact_problem.solve_contact_problem`).

    Notes
    -----
    Recorded forces are impulse / step; the slip velocity is the one the
    contact problem enforced; the gap is ``g(q_{k+1}, t_{k+1})``. The
    statistics are those of Moreau–Jean's generic step.

    Examples
    --------
    A unit point mass dropped from height 1 under gravity 1 onto the ground
    (``e = 1``) is back at height 1, to first order in ``h`` (an impact within a step), at ``t = 2 sqrt(2)``:

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.scenes.base import Scene
    >>> class Drop(Scene):
    ...     ndof, mu, restitution = 1, np.array([0.0]), np.array([1.0])
    ...     def mass(self, q): return np.eye(1)
    ...     def forces(self, q, v, t): return np.array([-1.0])
    ...     def gaps(self, q, t): return np.array([q[0]])
    ...     def contact_jacobians(self, q, t):
    ...         return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)
    >>> res = simulate(Drop(), (0.0, 2 * np.sqrt(2)), [1.0], [0.0], "schatzman-paoli", h=1e-3)
    >>> bool(abs(res.q[-1, 0] - 1.0) < 2e-3)
    True
    """

    compare_settings = ("steps_per_period", (50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000),
                        (100, 300, 1000), {})

    def __init__(self, scene, t0, q0, v0, t_bound, h=None, lcp_method="auto",
                 lemke_max_iter=None, save_every=1, fast="auto", max_steps=MAX_STEPS,
                 painleve="impulse"):
        super().__init__(scene, t0, q0, v0, t_bound)
        self.h = check_step("schatzman-paoli", h)
        self.lcp_method, self.lemke_max_iter = check_lcp_options(lcp_method, lemke_max_iter)
        self.save_every = positive_int("save_every", save_every)
        check_work(scene, self.t0, self.t_bound, self.h, self.save_every,
                   positive_int("max_steps", max_steps))
        self.mu_c, self.e_c = check_scene_contacts(scene)
        nc = scene.ncontacts
        self._trow = np.full(nc, -1, dtype=int)
        self._trow[scene.frictional_index] = np.arange(len(scene.frictional_index))
        self._closed = np.zeros(nc, dtype=bool)
        self._k = 0
        self.counters = {"steps": 0, **new_contact_counters(), "max_penetration": 0.0}
        self._pending_initial = True
        # the Verlet velocity that carries the two-step recursion (see the module docstring)
        self._v_verlet = self.v.copy()
        self.painleve, fast = painleve_option(painleve, fast)
        self._prev_reg = sliding_regimes(scene, self.q, self.v, self.t0)
        self._choose_compiled(fast, compiled_model_of(scene), lcp_method, lemke_max_iter)
        if self._fast:
            set_painleve_stop(self._lcp_ctl, scene.ncontacts, self.painleve == "stop")

    def _step_impl(self):
        if self._fast:
            return self._fast_block()
        return self._generic_step()

    def _fast_block(self):
        q, v, vv, closed = self.q.copy(), self.v.copy(), self._v_verlet.copy(), self._closed.copy()
        status = self._run_block(sp_loop, (q, v, vv, closed), (self._lcp_ctl,))
        self.q, self.v, self._v_verlet, self._closed = q, v, vv, closed
        self._after_block(status, numerical=EXPLICIT_BLOWUP)

    def _generic_step(self):
        sc = self.scene
        t0, q, v = self.t, self.q, self.v
        vv = self._v_verlet
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)
        M = np.asarray(sc.mass(q), dtype=float)
        a = np.linalg.solve(M, np.asarray(sc.forces(q, v, t0), dtype=float))
        u_plus = vv + 0.5 * h * a
        nc = sc.ncontacts
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        slip = np.zeros(nc)
        v_half = u_plus
        dv_contact = 0.0
        if nc:
            g = np.asarray(sc.gaps(q, t0), dtype=float)
            WN, wN, WT, wT = (np.asarray(x, dtype=float)
                              for x in sc.contact_jacobians(q, t0 + 0.5 * h))
            u_minus = vv - 0.5 * h * a
            e = self.e_c
            UN_free = (1.0 + e) * g / h + (WN @ u_plus + wN) - e * (WN @ u_minus + wN)
            active = (UN_free <= 0.0) | self._closed
            if active.any():
                ia = np.flatnonzero(active)
                fa = ia[self._trow[ia] >= 0]
                tr = self._trow[fa]
                H = np.vstack([WN[ia], WT[tr]])
                MinvHT = np.linalg.solve(M, H.T)
                W = H @ MinvHT
                U_free = np.concatenate([UN_free[ia], WT[tr] @ u_plus + wT[tr]])
                p, pn, pt = solve_contact_problem(
                    W, U_free, self.mu_c[ia], np.zeros(ia.size), np.zeros(ia.size),
                    lcp_method=self.lcp_method, counters=self.counters,
                    lemke_max_iter=self.lemke_max_iter, t=t0,
                    slip_before=slip_signs(self._prev_reg[ia]), painleve=self.painleve)
                pN[ia], pT[ia] = pn, pt
                dv_contact = MinvHT @ p
                v_half = u_plus + dv_contact
                slip[fa] = (U_free + W @ p)[ia.size:]
        q1 = q + h * v_half
        M1 = np.asarray(sc.mass(q1), dtype=float)
        vv1 = v_half + 0.5 * h * np.linalg.solve(M1, np.asarray(sc.forces(q1, v_half, t1),
                                                                 dtype=float))
        v1 = vv1 + 0.5 * dv_contact
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            self.counters["steps"] -= 1     # the base class counts this failed step
            self._fail(-5, EXPLICIT_BLOWUP.format(t=t0, h=h))
            return
        gap = np.asarray(sc.gaps(q1, t1), dtype=float) if nc else np.zeros(0)
        if nc:
            self.counters["max_penetration"] = max(self.counters["max_penetration"],
                                                   float(np.max(-gap, initial=0.0)))
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)])
        self._prev_reg = regime
        self._closed = pN > 0.0
        self._k += 1
        fN, fT = pN / h, pT / h
        if self._pending_initial:
            g0 = np.asarray(sc.gaps(q, t0), dtype=float) if nc else gap
            self._record(t0, q, v, regime, fN, fT, slip, g0)
            self._pending_initial = False
        self.t, self.q, self.v, self._v_verlet = t1, q1, v1, vv1
        if self._k % self.save_every == 0 or t1 >= self.t_bound:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)
