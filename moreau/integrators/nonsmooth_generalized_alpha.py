r"""The nonsmooth generalized-α scheme: second order in free flight, no drift.

After Chen, Acary, Virlez & Brüls (IJNME 2013), with the position-level
constraint of Brüls, Acary & Cardona (CMAME 2014) and Coulomb friction at
velocity level as in Capobianco, Harsch, Eugster & Leine (IJNME 2021).

The scheme
----------
The velocity is split into a smooth part, integrated by the Chung–Hulbert
generalized-α method, and a jump ``W`` caused by contact impulses; a
position correction ``U`` keeps the gaps admissible. One step from
``(q_n, v_n, a_n, acc_n)`` (``a`` the algorithmic acceleration, ``acc``
the smooth one)::

    (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) acc_{n+1} + alpha_f acc_n
    q*  = q_n + h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
    v*  = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
    M(q*) acc_{n+1} = h(q*, v*, t_{n+1})                    (Newton on acc_{n+1})
    v_{n+1} = v* + M^-1 H^T P                               (velocity jump W)
    q_{n+1} = q* + M^-1 WN^T nu                             (position correction U)

with the coefficients from the spectral radius at infinity ``rho_inf`` in
``[0, 1]``: ``alpha_m = (2 rho - 1) / (rho + 1)``, ``alpha_f = rho / (rho + 1)``,
``gamma = 1/2 + alpha_f - alpha_m``, ``beta = (gamma + 1/2)^2 / 4``
(second order, unconditionally stable for linear problems, ``rho_inf = 1``
is the undamped trapezoidal rule).

*Velocity level.* The contacts whose predicted gap ``g(q*, t_{n+1})`` is
``<= 1e-12`` (or that carried an impulse in the step before) form the step's
contact problem, with Newton's law and 2D Coulomb friction on
``U = H v_{n+1} + w(t_{n+1})``, the pre-step normal velocity
``WN(q_n) v_n + wN(t_n)`` in the restitution term: the problem of
:func:`~moreau.integrators.contact_problem.solve_contact_problem`, Jacobians at
``(q*, t_{n+1})``. The smooth acceleration carries no contact force: a
persistent contact's force enters through the jump, so that phase is first
order, while free flight is second order.

*Position level* (``position_level=True``). The same contacts' gaps are
corrected by ``nu >= 0`` with ``0 <= g(q_{n+1}) _|_ nu >= 0``, linearised at
``q*`` and iterated (Gauss–Newton with complementarity, a frictionless LCP
in ``nu`` on ``WN M^-1 WN^T``, at most 8 times) until every gap is within
``1e-14`` of admissible: no penetration and no drift of a closed contact.
Without it (``False``) the positions are the generalized-α ones, which
penetrate by ``O(h^2)`` per impact and drift in persistent contact.

The velocity jump does not feed back into the smooth acceleration of the
same step (``acc_{n+1}`` uses ``v*``): with velocity-dependent forces that
is an ``O(h)`` error at each impact only.
"""

import numpy as np

from .._validate import in_closed_interval, positive, positive_int
from ..errors import ConvergenceError, InputError, LCPError
from ..lcp import solve_lcp
from ._blocks import CompiledRecording
from ._loops import runner_for
from ._mj_kernels import (LCP_HANDBACK, NUMERICAL, PAINLEVE, SINGULAR, STAT_NAMES,
                          new_lcp_control, new_stats)
from ._nsga_kernels import CONVERGENCE, nsga_loop
from .base import Integrator, register_integrator
from .contact_problem import new_contact_counters, solve_contact_problem
from .moreau_jean import (FAST_BLOCK, LCP_METHODS, MAX_STEPS, check_scene_contacts, check_work,
                          classify_impulse, compiled_model_of, next_time)

__all__ = ["NonsmoothGeneralizedAlpha", "alpha_coefficients"]

# the smooth Newton iteration stops at this relative change of the acceleration
NEWTON_RTOL = 1e-12
NEWTON_MAXITER = 25
# the position correction stops when every corrected gap is above -this
POSITION_TOL = 1e-14
# a predicted gap below this counts as closed: after a corrected impact the flight is
# symmetric and the next impact lands on the floor on a grid time, where rounding alone
# would otherwise decide between contact and flight (and change the energy lost)
CONTACT_TOL = 1e-12
POSITION_MAXITER = 8


def alpha_coefficients(rho_inf):
    """``(alpha_m, alpha_f, gamma, beta)`` of the generalized-α method for ``rho_inf``.

    Examples
    --------
    >>> alpha_coefficients(1.0)
    (0.5, 0.5, 0.5, 0.25)
    """
    rho = float(rho_inf)
    am = (2.0 * rho - 1.0) / (rho + 1.0)
    af = rho / (rho + 1.0)
    gamma = 0.5 + af - am
    beta = 0.25 * (gamma + 0.5) ** 2
    return am, af, gamma, beta


@register_integrator("nonsmooth-generalized-alpha")
class NonsmoothGeneralizedAlpha(CompiledRecording, Integrator):
    """Nonsmooth generalized-α time stepping (see the module docstring).

    Parameters
    ----------
    scene : Scene
    t0, q0, v0, t_bound
        See :class:`~moreau.integrators.base.Integrator`.
    h : float
        Time step, > 0; the last step is shortened to end on ``t_bound``.
    rho_inf : float
        Spectral radius at infinity, in ``[0, 1]`` (default 0.9: mild damping
        of the highest modes).
    position_level : bool
        Correct positions onto the admissible set (no penetration, no drift).
    lcp_method : {"auto", "lemke", "qp"}
    save_every : int
    fast : {"auto", True, False}
        Run the compiled loop (:mod:`moreau.integrators._nsga_kernels`, the same
        step, equal to rounding) on a scene with a ``compiled_model()``;
        ``"auto"`` does so unless ``lcp_method="qp"``. A step the loop cannot
        finish (Lemke fails, the Painlevé condition, the smooth Newton
        iteration) is taken by the generic step.
    max_steps : int

    Examples
    --------
    A unit mass on a unit spring, far from its one contact: second order.

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.scenes.base import Scene
    >>> class Spring(Scene):
    ...     ndof, mu, restitution = 1, np.array([0.0]), np.array([0.0])
    ...     def mass(self, q): return np.eye(1)
    ...     def forces(self, q, v, t): return -np.asarray(q, float)
    ...     def force_jacobians(self, q, v, t): return -np.eye(1), np.zeros((1, 1))
    ...     def gaps(self, q, t): return np.array([q[0] + 10.0])
    ...     def contact_jacobians(self, q, t):
    ...         return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)
    >>> err = [abs(simulate(Spring(), (0.0, 2.0), [1.0], [0.0], "nonsmooth-generalized-alpha",
    ...                     h=h).q[-1, 0] - np.cos(2.0)) for h in (0.02, 0.01)]
    >>> round(float(np.log2(err[0] / err[1])))
    2
    """

    compare_settings = ("steps_per_period", (50, 100, 200, 500, 1000, 2000, 5000),
                        (100, 1000), {})

    def __init__(self, scene, t0, q0, v0, t_bound, h=None, rho_inf=0.9, position_level=True,
                 lcp_method="auto", save_every=1, fast="auto", max_steps=MAX_STEPS):
        super().__init__(scene, t0, q0, v0, t_bound)
        if h is None:
            raise InputError("`h` (the time step) is required for the "
                             "nonsmooth-generalized-alpha scheme")
        self.h = positive("h", h)
        self.rho_inf = in_closed_interval("rho_inf", rho_inf, 0.0, 1.0)
        if not isinstance(position_level, (bool, np.bool_)):
            raise InputError(f"`position_level` must be True or False, got {position_level!r}")
        self.position_level = bool(position_level)
        if lcp_method not in LCP_METHODS:
            raise InputError(f"`lcp_method` must be one of {list(LCP_METHODS)}, got {lcp_method!r}")
        self.lcp_method = lcp_method
        self.save_every = positive_int("save_every", save_every)
        check_work(scene, self.t0, self.t_bound, self.h, self.save_every,
                   positive_int("max_steps", max_steps))
        self.mu_c, self.e_c = check_scene_contacts(scene)
        self.am, self.af, self.gamma, self.beta = alpha_coefficients(self.rho_inf)
        nc = scene.ncontacts
        self._trow = np.full(nc, -1, dtype=int)
        self._trow[scene.frictional_index] = np.arange(len(scene.frictional_index))
        self._closed = np.zeros(nc, dtype=bool)
        self._k = 0
        self.counters = {"steps": 0, **new_contact_counters(), "max_penetration": 0.0,
                         "newton_iterations": 0, "position_iterations": 0}
        self._pending_initial = True
        acc0 = np.linalg.solve(np.asarray(scene.mass(self.q), float),
                               np.asarray(scene.forces(self.q, self.v, self.t0), float))
        self._acc = acc0
        self._a = acc0.copy()
        if fast not in ("auto", True, False):
            raise InputError(f"`fast` must be 'auto', True or False, got {fast!r}")
        model = compiled_model_of(scene)
        if fast is True and (model is None or lcp_method == "qp"):
            raise InputError("`fast=True` needs a scene with a compiled model and an "
                             "`lcp_method` other than 'qp'")
        self._fast = model is not None and fast is not False and lcp_method != "qp"
        if self._fast:
            self._model = model
            self._stats = new_stats()
            self._lcp_ctl = new_lcp_control(nc, force_lemke=lcp_method == "lemke",
                                            warm_start=False)
            self._blocks = []
            self._coef = np.array([self.am, self.af, self.gamma, self.beta])
            for name in STAT_NAMES:
                self.counters.setdefault(name, 0)

    def _fast_block(self):
        m, n, nc = self._model, self.scene.ndof, self.scene.ncontacts
        ns = FAST_BLOCK // self.save_every + 2
        buf = (np.empty(ns), np.empty((ns, n)), np.empty((ns, n)),
               np.empty((ns, nc), dtype=np.int64), np.empty((ns, nc)), np.empty((ns, nc)),
               np.empty((ns, nc)), np.empty((ns, nc)))
        q, v, a, acc = self.q.copy(), self.v.copy(), self._a.copy(), self._acc.copy()
        closed = self._closed.copy()
        st = self._stats
        st[:] = 0.0
        status, k, nrec = runner_for(m, nsga_loop, self.scene)(
            m.par, self.mu_c, self.e_c, self.t0, self.h, self.t_bound, self._k, FAST_BLOCK,
            q, v, a, acc, self._coef, closed, self.save_every, self._pending_initial,
            self.position_level, self._lcp_ctl, *buf, st)
        ndone = k - self._k
        if nrec:
            self._blocks.append(tuple(b[:nrec].copy() for b in buf))
        if ndone:
            self._pending_initial = False
        self._k, self.q, self.v, self._a, self._acc, self._closed = k, q, v, a, acc, closed
        t = self.t0 + k * self.h
        self.t = self.t_bound if t >= self.t_bound - 1e-9 * self.h else t
        c = self.counters
        for name, x in zip(STAT_NAMES, st):
            c[name] = max(c[name], float(x)) if name.startswith("max_") else c[name] + int(x)
        c["steps"] += ndone - 1     # the base class counts one step per call
        if status in (LCP_HANDBACK, PAINLEVE, CONVERGENCE):
            c["steps"] += 1
            self._generic_step()
            return
        if status == SINGULAR:
            self._fail(-5, f"a singular mass or iteration matrix at t = {self.t!r}")
        elif status == NUMERICAL:
            self._fail(-5, f"non-finite state after the step at t = {self.t!r}")

    def _smooth(self, q, v, a, acc, t1, h):
        """Newton on ``acc_{n+1}``: the smooth generalized-α step (no contact)."""
        sc = self.scene
        am, af, gamma, beta = self.am, self.af, self.gamma, self.beta
        c = (1.0 - af) / (1.0 - am)
        x = acc.copy()
        for it in range(1, NEWTON_MAXITER + 1):
            a1 = (c * x + (af * acc - am * a) / (1.0 - am))
            qs = q + h * v + h * h * (0.5 - beta) * a + h * h * beta * a1
            vs = v + h * (1.0 - gamma) * a + h * gamma * a1
            M = np.asarray(sc.mass(qs), float)
            f = np.asarray(sc.forces(qs, vs, t1), float)
            K, C = (np.asarray(m, float) for m in sc.force_jacobians(qs, vs, t1))
            r = M @ x - f
            J = M - c * (h * h * beta * K + h * gamma * C)
            dx = np.linalg.solve(J, -r)
            x = x + dx
            self.counters["newton_iterations"] += 1
            if np.max(np.abs(dx)) <= NEWTON_RTOL * max(1.0, np.max(np.abs(x))):
                a1 = c * x + (af * acc - am * a) / (1.0 - am)
                qs = q + h * v + h * h * (0.5 - beta) * a + h * h * beta * a1
                vs = v + h * (1.0 - gamma) * a + h * gamma * a1
                return qs, vs, a1, x
        raise ConvergenceError(f"the smooth Newton iteration did not converge in "
                               f"{NEWTON_MAXITER} iterations at t = {self.t!r}")

    def _correct_positions(self, q, t, cand):
        """``q + M^-1 WN^T nu`` with ``0 <= g _|_ nu >= 0`` on the candidate contacts."""
        sc = self.scene
        M = np.asarray(sc.mass(q), float)
        ic = np.flatnonzero(cand)
        for _ in range(POSITION_MAXITER):
            g = np.asarray(sc.gaps(q, t), float)[ic]
            if np.min(g, initial=np.inf) >= -POSITION_TOL:
                break
            WN = np.asarray(sc.contact_jacobians(q, t)[0], float)[ic]
            MinvWT = np.linalg.solve(M, WN.T)
            r = solve_lcp(WN @ MinvWT, g, method="lemke" if self.lcp_method != "qp" else "qp")
            if not r.success:
                raise LCPError(f"the position correction at t = {t!r} was not solved: "
                               f"{r.message}")
            q = q + MinvWT @ r.z
            self.counters["position_iterations"] += 1
        return q

    def _step_impl(self):
        if self._fast:
            return self._fast_block()
        return self._generic_step()

    def _generic_step(self):
        sc = self.scene
        t0, q, v = self.t, self.q, self.v
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)
        qs, vs, a1, acc1 = self._smooth(q, v, self._a, self._acc, t1, h)
        nc = sc.ncontacts
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        slip = np.zeros(nc)
        v1, q1 = vs, qs
        if nc:
            gs = np.asarray(sc.gaps(qs, t1), float)
            active = (gs <= CONTACT_TOL) | self._closed
            if active.any():
                ia = np.flatnonzero(active)
                fa = ia[self._trow[ia] >= 0]
                tr = self._trow[fa]
                WN0, wN0, _, _ = sc.contact_jacobians(q, t0)
                vN0 = (np.asarray(WN0, float) @ v + np.asarray(wN0, float))[ia]
                WN, wN, WT, wT = (np.asarray(x, float) for x in sc.contact_jacobians(qs, t1))
                H = np.vstack([WN[ia], WT[tr]])
                MinvHT = np.linalg.solve(np.asarray(sc.mass(qs), float), H.T)
                W = H @ MinvHT
                U_free = H @ vs + np.concatenate([wN[ia], wT[tr]])
                p, pn, pt = solve_contact_problem(W, U_free, self.mu_c[ia], self.e_c[ia], vN0,
                                                  lcp_method=self.lcp_method,
                                                  counters=self.counters, t=t0)
                pN[ia], pT[ia] = pn, pt
                v1 = vs + MinvHT @ p
                slip[fa] = (U_free + W @ p)[ia.size:]
                if self.position_level:
                    q1 = self._correct_positions(qs, t1, active)
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            self.counters["steps"] -= 1
            self._fail(-5, f"non-finite state after the step at t = {t0!r}")
            return
        gap = np.asarray(sc.gaps(q1, t1), float) if nc else np.zeros(0)
        if nc:
            self.counters["max_penetration"] = max(self.counters["max_penetration"],
                                                   float(np.max(-gap, initial=0.0)))
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)])
        self._closed = pN > 0.0
        self._k += 1
        fN, fT = pN / h, pT / h
        if self._pending_initial:
            g0 = np.asarray(sc.gaps(q, t0), float) if nc else gap
            self._record(t0, q, v, regime, fN, fT, slip, g0)
            self._pending_initial = False
        self.t, self.q, self.v = t1, q1, v1
        self._a, self._acc = a1, acc1
        if self._k % self.save_every == 0 or t1 >= self.t_bound:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)
