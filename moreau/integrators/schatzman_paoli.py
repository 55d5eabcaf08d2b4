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
The step is written in velocity form so that the state is a position and a
velocity like every other scheme's. Let ``a_k = M^-1 h(q_k, w_k, t_k)``
(``M = M(q_k)``; ``w_k`` is the velocity the forces see, below), ``V_k`` the
*Verlet velocity* that carries the recursion, and ``u+ = V_k + (h/2) a_k``,
``u- = V_k - (h/2) a_k``. Without contact the positions one step ahead and
behind are ``q_k + h u+`` and ``q_{k-1} = q_k - h u-``. With impulses
``p = P / h`` and the node's velocity jump ``dv_k = M^-1 H^T p``::

    q_{k+1} = q_k + h (u+ + dv_k)

Linearising the gap of contact ``i`` about ``(q_k, t_k)``, with the time of
``z`` being ``t_z = (t_{k+1} + e t_{k-1}) / (1 + e)``::

    g_i(z, t_z) ~ g_i + WN_i (z - q_k) + wN_i (t_z - t_k),
    z - q_k = h (u+ + dv_k - e u-) / (1 + e),   t_z - t_k = h (1 - e) / (1 + e)

and multiplying by ``(1 + e) / h > 0`` gives the normal condition as a
velocity-level complementarity::

    0 <= U_N = (1 + e) g_i / h + (WN_i u+ + wN_i) - e (WN_i u- + wN_i) + WN_i dv_k  _|_  p_N >= 0

that is, Newton's law between the velocities after (``u+``) and before
(``u-``) the step plus the gap itself: a closed contact is held at
``g(z) = 0`` to the linearisation, with no drift. Coulomb's law acts on the
slip velocity over the step, ``U_T = WT (q_{k+1} - q_k) / h + wT``. Both
rows share the Delassus matrix ``W = H M^-1 H^T``, so the step's problem is
the one of :func:`moreau.integrators.contact_problem.solve_contact_problem`
with ``e = 0`` in its own law (the restitution is already in ``U_free``).
The Jacobians and the rheonomic terms are taken at ``(q_k, t_k + h/2)``.

The step's velocity ``u_k = (q_{k+1} - q_k) / h = u+ + dv_k`` and the
closing half step ``V_{k+1} = u_k + (h/2) a_{k+1}`` give
``u_k - u_{k-1} = h a_k + dv_k``, that is::

    q_{k+1} - 2 q_k + q_{k-1} = h^2 M^-1 (h_k + r_k),   r_k = H^T p_k / h

the two-step scheme above: the impulse of the step that leaves node ``k``
is the reaction *at* node ``k``. A run started at ``(q_0, v_0)`` takes
``V_0 = v_0``; on a contact closed at rest this puts the virtual previous
position ``h^2/2`` into the obstacle, which the first step lifts off by
``e h^2/2`` (the offset then decays by ``-e`` every step: 2.5e-5,
-1.25e-5, ... with ``h = 0.01``, ``e = 0.5``).

Velocities: recorded, and seen by the forces
---------------------------------------------
The positions are the scheme; a velocity is an approximation read off
them. The one the scheme records at node ``k`` (and hands back as the
state) is the central difference::

    v_k = (q_{k+1} - q_{k-1}) / 2h = (u_{k-1} + u_k) / 2 = V_k + dv_k / 2

with the node's *own* impulse. It is second order where the motion is
smooth, and exactly 0 on a contact at rest (``q`` constant). On a node with
an impact it is the mean of the velocities of the steps that arrive and
leave, so it lies between them, and its kinetic energy is at most the
larger of theirs. The node's impulse is solved at the end of the step that
reaches the node (one contact problem per node); the run's last node is
solved with the nominal step for its velocity only. A run restarted from a
recorded state takes ``V_0 = v_k``, which is the run's own ``V_k`` where
the node carries no impulse and differs by ``dv_k / 2`` where it does (on a
contact at rest, the start offset described above). The sample of
node ``k + 1`` carries the forces of the step that reaches it, ``p_k / h``,
like every scheme's sample.

The forces must be evaluated before the node's impulse is known, so they
cannot see ``v_k`` itself (it would make the step implicit in the forces).
They see the explicit predictor::

    w_{k+1} = u_k + (h/2) a_k + dv_k / 2 = v_k + h (a_k + dv_k / h)

an Euler step of the node's central velocity with its whole acceleration,
forces and contact reaction (``w_0 = v_0``). It is ``v(t_{k+1}) + O(h^2)``
where the motion is smooth, contact phases included (0 on a contact at
rest), so that the scheme stays second order there with velocity-dependent
forces (measured slope 2.00 on a ball with a linear damper in flight). At
the node after an impact it exceeds the departing velocity ``u_k`` by half
the impact's jump ``dv_k``: the forces see a velocity off by ``O(1)`` over
one step, which moves the solution by ``O(h)``, the order of the scheme
through an impact anyway (the damped ball converges with order 1 through
its impacts; the tests measure both). For forces that do not depend on the velocity none of
this touches the positions: they are the two-step recursion above.

*Index set.* Contact ``i`` enters the step's problem when its free ``U_N``
is ``<= 0`` (the mean position ``z`` would leave ``K``) or when it carried
a normal impulse in the step before.

Like every explicit scheme, the step must resolve the fastest smooth
oscillation (``h omega < 2``); a run that blows up stops with a status.
"""

import dataclasses

import numpy as np

from ._blocks import EXPLICIT_BLOWUP
from ._sp_kernels import sp_loop
from .base import register_integrator
from .contact_problem import new_contact_counters, slip_signs, solve_contact_problem
from .moreau_jean import classify_impulse
from .time_stepping import FixedStepOptions, TimeStepping, next_time

__all__ = ["SchatzmanPaoli"]


@register_integrator("schatzman-paoli")
class SchatzmanPaoli(TimeStepping):
    """Schatzman–Paoli time stepping (see the module docstring).

    Parameters
    ----------
    lemke_max_iter : int, optional
        Pivot limit of Lemke's method.
    scene, t0, q0, v0, t_bound, options, h, lcp_method, save_every, fast, max_steps, painleve
        As for every fixed-step scheme: :class:`~moreau.integrators.time_stepping.FixedStepOptions`.

    Notes
    -----
    The recorded velocity is the central difference
    ``(q_{k+1} - q_{k-1}) / 2h`` of the positions (the module docstring
    derives it and the velocity the forces see). Recorded forces are the
    impulse / step of the step that ends at the sample; the slip velocity is
    the one the contact problem enforced; the gap is ``g(q_{k+1}, t_{k+1})``.
    The statistics are those of Moreau–Jean's generic step.

    Examples
    --------
    A unit point mass dropped from height 1 under gravity 1 onto the ground
    (``e = 1``) is back at height 1, to first order in ``h`` (an impact within a step), at ``t = 2 sqrt(2)``:

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.model.examples import Drop
    >>> res = simulate(Drop(), (0.0, 2 * np.sqrt(2)), [1.0], [0.0], "schatzman-paoli", h=1e-3)
    >>> bool(abs(res.q[-1, 0] - 1.0) < 2e-3)
    True
    """

    #: an explicit (central-difference) step: a stop names its stability bound where exceeded
    explicit_step = True

    compare_settings = ("steps_per_period", (50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000),
                        (100, 300, 1000), {})

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class Options(FixedStepOptions):
        """Options of :class:`SchatzmanPaoli` (those of every fixed-step scheme,
        :class:`~moreau.integrators.time_stepping.FixedStepOptions`, and its own)."""
        lemke_max_iter: int | None = None

        def smooth_order(self):
            return 2        # Stormer-Verlet in smooth phases

    def _setup_scheme(self):
        # the Verlet velocity that carries the two-step recursion, the velocity the forces
        # see at the current node, and that node's solved contact problem where the
        # generic step has it (see the module docstring)
        self._v_verlet = self.v.copy()
        self._v_force = self.v.copy()
        self._node = None

    def _step_impl(self):
        if self._fast:
            self._node = None       # the compiled loop keeps its node solutions to itself
            return self._fast_block()
        return self._generic_step()

    def _fast_block(self):
        q, v, vv, vf = self.q.copy(), self.v.copy(), self._v_verlet.copy(), self._v_force.copy()
        closed = self._closed.copy()
        status = self._run_block(sp_loop, (q, v, (), (vv, vf, closed)), (self._lcp_ctl,))
        self.q, self.v, self._v_verlet, self._v_force, self._closed = q, v, vv, vf, closed
        self._after_block(status, numerical=EXPLICIT_BLOWUP)

    def _solve_node(self, t, q, vv, a, M, closed, g, h, count):
        """The contact impulse of the node ``(t, q)`` for the step ``h`` that leaves it.

        Returns ``(u_plus, dv_contact, pN, pT, slip)``: the Verlet velocity
        ``vv + (h/2) a``, the velocity jump ``M^-1 H^T p`` of the node's
        impulse, the impulses and the slip velocities. ``count`` says whether
        the solve enters the statistics (not when a node is solved again).
        """
        sc = self.scene
        nc = sc.ncontacts
        u_plus = vv + 0.5 * h * a
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        slip = np.zeros(nc)
        dv_contact = 0.0
        if nc:
            WN, wN, WT, wT = (np.asarray(x, dtype=float)
                              for x in sc.contact_jacobians(q, t + 0.5 * h))
            u_minus = vv - 0.5 * h * a
            e = self.e_c
            UN_free = (1.0 + e) * g / h + (WN @ u_plus + wN) - e * (WN @ u_minus + wN)
            active = (UN_free <= 0.0) | closed
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
                    lcp_method=self.lcp_method,
                    counters=self.counters if count else new_contact_counters(),
                    lemke_max_iter=self.lemke_max_iter, t=t,
                    # a node solved again must not record its tangential impact twice
                    slip_before=slip_signs(self._prev_reg[ia]) if count else None,
                    painleve=self.painleve, warm=self._lcp_warm("impulse"),
                    warm_key=tuple(ia.tolist()))
                pN[ia], pT[ia] = pn, pt
                dv_contact = MinvHT @ p
                slip[fa] = (U_free + W @ p)[ia.size:]
        return u_plus, dv_contact, pN, pT, slip

    def _generic_step(self):
        sc = self.scene
        nc = sc.ncontacts
        t0, q = self.t, self.q
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)
        node = self._node
        if node is None:
            # the run's first node, or a node the compiled loop solved (taken again here)
            M = np.asarray(sc.mass(q), dtype=float)
            a = np.linalg.solve(M, np.asarray(sc.forces(q, self._v_force, t0), dtype=float))
            g = np.asarray(sc.gaps(q, t0), dtype=float) if nc else np.zeros(0)
            node = (a, M, g) + self._solve_node(t0, q, self._v_verlet, a, M, self._closed, g, h,
                                                self._pending_initial)
        a, M, g0, u_plus, dv_contact, pN, pT, slip = node
        v_half = u_plus + dv_contact
        q1 = q + h * v_half
        # what the forces see at the next node (module docstring): an explicit predictor
        v_force = v_half + 0.5 * h * a + 0.5 * dv_contact
        M1 = np.asarray(sc.mass(q1), dtype=float)
        a1 = np.linalg.solve(M1, np.asarray(sc.forces(q1, v_force, t1), dtype=float))
        vv1 = v_half + 0.5 * h * a1
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(vv1))):
            self.counters["steps"] -= 1     # the base class counts this failed step
            self._fail(-5, EXPLICIT_BLOWUP.format(t=t0, h=h))
            return
        gap = self._end_gaps(q1, t1, nc)
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)])
        self._prev_reg = regime
        fN, fT = pN / h, pT / h
        if self._pending_initial:
            self._record(t0, q, self.v, regime, fN, fT, slip, g0)
            self._pending_initial = False
        # the next node's impulse completes its velocity; the run's last node is solved
        # with the nominal step, for its velocity only
        h1 = self.h if t1 >= self.t_bound else next_time(self.t0, self._k + 1, self.h,
                                                          self.t_bound)[1]
        closed1 = pN > 0.0
        node1 = (a1, M1, gap) + self._solve_node(t1, q1, vv1, a1, M1, closed1, gap, h1, True)
        v1 = vv1 + 0.5 * node1[4]
        self._k += 1
        self.t, self.q, self.v, self._v_verlet, self._v_force = t1, q1, v1, vv1, v_force
        self._closed, self._node = closed1, node1
        if self._k % self.save_every == 0 or t1 >= self.t_bound:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)
