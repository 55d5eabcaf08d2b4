r"""Event-driven reference for spatial scenes with one persistent contact.

A :class:`~moreau.model.space.SpaceScene` whose single contact stays closed
(a sphere rolling or sliding on a plane, a disk rolling on its rim) is cut
into smooth phases of two modes, joined at events located by the root finder
of ``solve_ivp`` (Brent's method, to a few ulps of time).

Rolling (stick)
    The contact point's three velocity rows ``H = [n; t1; t2]``
    (:meth:`~moreau.model.space.SpaceScene.contact_rows`) hold at
    acceleration level with the scene's drift ``wbar``
    (:meth:`~moreau.model.space.SpaceScene.contact_drift`)::

        M a = f + H^T lam,    H a + wbar = 0,
        lam = -(H M^-1 H^T)^-1 (H M^-1 f + wbar).

    The phase ends where the friction leaves the round cone, ``mu lamN -
    |lamT| = 0``; sliding then starts opposite the friction force.

Sliding
    The friction is ``-mu lamN s`` with ``s`` the unit slip direction (in the
    tangents ``t1, t2``), and only the normal row holds::

        M a = f + (WN - mu s^T WT)^T lamN,    WN a + wNbar = 0.

    A coefficient ``WN M^-1 (WN - mu s^T WT)^T <= 0`` is Painlevé's case
    (:class:`~moreau.errors.PainleveError`). The phase ends where the slip's
    component along its direction ``d`` at the phase's start, ``u . d``,
    crosses zero. For a sphere (the billiard ball) the slip keeps its
    direction and decreases linearly, so this is a regular root of a smooth
    function, where ``|u|`` would have a kink. Where the slip has turned
    instead (``|u|`` still above ``vel_tol`` times the velocity scale) a new
    sliding phase starts along the new direction; otherwise the velocity is
    projected onto the three rows (metric of ``M``) and the contact sticks
    if the cone holds the friction that rolling needs, else it slides on.
    A phase that starts from zero slip (after the cone's saturation) takes
    ``s = d`` while ``|u| <= vel_tol`` times the scale.

Both modes stop the run where the normal force ``lamN`` reaches zero: the
contact would open, and this reference models no flight (status ``-2``, a
:class:`~moreau.errors.ContactLostError` naming the lift-off).

Each body's state is its centre, quaternion ``p``, centre velocity and
body-frame angular velocity, with ``p' = 1/2 p ⊗ (0, omega)`` integrated by
DOP853 beside the rest: its unit norm drifts by the integrator's error, and
is restored only at the events (the scene's rows take ``p / |p|`` all the
same); the largest drift met is the counter ``quaternion_norm_drift``. At
each event the centre is also moved along the normal onto the gap's zero
and the velocity projected onto the closed rows.

Coulomb–Contensou friction
    A contact with a patch (``contact_radius > 0``, :mod:`moreau.model.space`)
    slides in three generalized rows, the two slip rates and the drilling row
    ``r* n . (R omega)`` (:meth:`~moreau.model.space.SpaceScene.drilling_rows`):
    its slip ``u`` and direction ``s`` above have three components, and the
    force ``-mu lamN s`` is Leine and Glocker's ellipsoidal law, smooth while
    the generalized slip is not zero (the Contensou regularity: a spinning
    contact slides in every direction with bounded forces). Sliding with the
    drilling row is the same mode, ``G = WN - mu s^T [WT; D]``; the drilling
    row's drift is zero (``d(R omega)/dt = R omega'``). Where the generalized
    slip vanishes (rolling without spin about the normal) the run stops with
    a :class:`~moreau.errors.MoreauError` naming it: rolling under
    Coulomb–Contensou friction is left to ``moreau-jean``.

Known limits: one contact (scenes with several, the puck on three rim
points or a capsule, are refused by name); no impacts, no flight, no
rolling friction; no rolling with a contact patch (above).
"""

import dataclasses
import math

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import ContactLostError, InputError, MoreauError, PainleveError
from ..model.scene import is_spatial
from ..model.spatial import quat_multiply
from ..regimes import Regime
from .base import EventDrivenOptions, Integrator, register_integrator
from .result import Event

__all__ = ["SpaceEventDriven"]

_STICK, _SLIDE = int(Regime.STICK), int(Regime.POSITIVE)


@register_integrator("event-driven-space")
class SpaceEventDriven(Integrator):
    """Event-driven reference of a spatial scene with one persistent contact (rolling, sliding).

    See the module docstring for the method.

    Parameters
    ----------
    scene : SpaceScene
        A spatial scene with exactly one contact, closed at the start.
    t0, q0, v0, t_bound
        See :class:`~moreau.integrators.base.Integrator`.
    rtol, atol : float
        Tolerances of DOP853 in the smooth phases.
    max_step : float
        Largest integrator step.
    sample_dt : float, optional
        Output interval; ``(t_bound - t0) / 256`` by default.
    vel_tol : float
        Slip speed, relative to the contact velocities' scale, below which
        the slip counts as zero at an event.

    Examples
    --------
    >>> from moreau.scenes.billiard_backspin import billiard_backspin, rolling_onset
    >>> from moreau.integrators import simulate
    >>> sc = billiard_backspin(speed=0.5, spin=0.0)
    >>> res = simulate(sc, (0.0, 1.5), *sc.initial_state(), "event-driven-space", sample_dt=0.5)
    >>> (ev,) = res.events
    >>> t_star, _ = rolling_onset(sc.params)
    >>> ev.kind, abs(ev.t * sc.time - t_star) < 1e-12
    ('transition', True)
    """

    exact_motion = True
    solves_space = True

    @dataclasses.dataclass(frozen=True)
    class Options(EventDrivenOptions):
        """Options of :class:`SpaceEventDriven` (its parameters after ``t_bound``)."""

    takes_options_object = True

    def __init__(self, scene, t0, q0, v0, t_bound, options=None, **keywords):
        name = getattr(scene, "name", type(scene).__name__)
        if not is_spatial(scene):
            raise InputError(f"scheme 'event-driven-space' steps spatial scenes only: `scene` "
                             f"{name!r} is planar; use 'event-driven'")
        super().__init__(scene, t0, q0, v0, t_bound)
        self.options = o = self._take_options(options, keywords)
        if getattr(scene, "box_index", ()):
            raise InputError(f"scheme 'event-driven-space' keeps one persistent contact with a "
                             f"half-space: `scene` {name!r} has box contacts between bodies "
                             f"(sphere-box, box-box), whose points change as they move; use "
                             f"'moreau-jean'")
        if scene.ncontacts != 1:
            raise InputError(f"scheme 'event-driven-space' keeps one persistent contact: `scene` "
                             f"{name!r} has {scene.ncontacts} contacts; use 'moreau-jean'")
        if getattr(scene, "pair_index", ()):
            raise InputError(f"scheme 'event-driven-space' keeps one persistent contact with a "
                             f"half-space: `scene` {name!r}'s contact joins two bodies; use "
                             f"'moreau-jean'")
        self.sample_dt = (o.sample_dt if o.sample_dt is not None
                          else (self.t_bound - self.t0) / 256.0)
        self._next_sample = self.t0 + self.sample_dt
        self.mu = float(scene.mu[0])
        # the drilling row's lever r* (0: a point contact, two tangential rows)
        self.lever = (float(getattr(scene, "drilling_levers", np.zeros(1))[0])
                      if self.mu > 0.0 else 0.0)
        self.nb = scene.nbodies
        self.normal = np.asarray(scene.contact_bases()[0][0], dtype=float)
        self.Minv = scene.mass_inverse(self.q)
        self.counters.update({"events": 0, "rhs": 0, "segments": 0,
                              "quaternion_norm_drift": 0.0})
        self._vscale = 0.0
        g = float(scene.gaps(self.q, self.t)[0])
        rows = scene.contact_rows(self.q)[0]
        vN = float(rows[0] @ self.v)
        self._update_vscale(self.q, self.v)
        if abs(g) > 1e-9 or abs(vN) > 1e-9 * max(self._vscale, 1.0):
            raise InputError(f"`q0`, `v0` must start on the contact (gap and normal velocity "
                             f"zero), got gap {g:.3g} and normal velocity {vN:.3g}: scheme "
                             "'event-driven-space' keeps the contact closed")
        self.mode, self.direction = _SLIDE, None
        if self._attempt(self._first_mode):
            self._record_state(self.t, self.q, self.v)

    def _first_mode(self):
        # the start's mode (a failure stops the run at once)
        self.mode, self.direction = self._decide(self.t, *self._restart(self.q, self.v, None))

    # -- the contact's equations -------------------------------------------------------
    def _vtol(self):
        return self.options.vel_tol * max(self._vscale, 1e-300)

    def _update_vscale(self, q, v):
        rows = self.scene.contact_rows(q)[0]
        if self.lever > 0.0:
            rows = np.vstack([rows, self.scene.drilling_rows(q)[:1]])
        self._vscale = max(self._vscale, float(np.max(np.abs(rows) @ np.abs(v))))

    def _tangent_rows(self, q, rows):
        # the slip's rows: [t1, t2], and the drilling row with a contact patch
        if self.lever > 0.0:
            return np.vstack([rows[1:], self.scene.drilling_rows(q)[:1]])
        return rows[1:]

    def _slip(self, rows, v, T=None):
        if self.mu == 0.0:
            return np.zeros(2)
        return (rows[1:] if T is None else T) @ v

    def _no_rolling(self, t):
        raise MoreauError(f"the contact's generalized slip (sliding and drilling) reaches zero "
                          f"at t = {t:.12g}: scheme 'event-driven-space' models no rolling "
                          f"with a contact patch (`contact_radius` > 0); use 'moreau-jean'")

    def solve(self, t, q, v, mode, direction):
        """``(a, lamN, lamT, slip, coefficient)`` of ``mode`` at ``(t, q, v)``.

        ``lamT`` and ``slip`` are 2-vectors in the tangents ``(t1, t2)``;
        ``coefficient`` is the sliding mode's ``WN M^-1 G^T`` (1 in stick).
        """
        sc = self.scene
        f = sc.forces(q, v, t)
        rows = sc.contact_rows(q)[0]
        wN, wT = sc.contact_drift(q, v, t)
        T = self._tangent_rows(q, rows)
        u = self._slip(rows, v, T)
        Mf = self.Minv @ f
        if mode == _STICK and self.lever > 0.0:
            self._no_rolling(t)
        if mode == _STICK:
            H = rows
            wbar = np.array([wN[0], wT[0], wT[1]])
            MH = self.Minv @ H.T
            lam = np.linalg.solve(H @ MH, -(H @ Mf + wbar))
            return Mf + MH @ lam, lam[0], lam[1:], u, 1.0
        speed = float(np.linalg.norm(u))
        s = u / speed if speed > self._vtol() else direction
        G = rows[0] - self.mu * (s @ T) if self.mu > 0.0 else rows[0]
        if self.mu == 0.0:
            s = np.zeros(2)
        MG = self.Minv @ G
        coef = float(rows[0] @ MG)
        if coef <= 0.0:
            raise PainleveError(f"Painlevé configuration at t = {t:.12g}: the sliding contact's "
                                f"normal-force coefficient WN M^-1 (WN - mu s WT)^T = {coef:.6g} "
                                f"<= 0 (mu = {self.mu:.6g})")
        lamN = -(rows[0] @ Mf + wN[0]) / coef
        return Mf + MG * lamN, lamN, -self.mu * lamN * s, u, coef

    def _rates(self, t, y, a):
        n = self.scene.ndof
        q, v = y[:n], y[n:]
        out = np.empty_like(y)
        for b in range(self.nb):
            out[7 * b:7 * b + 3] = v[6 * b:6 * b + 3]
            w = v[6 * b + 3:6 * b + 6]
            out[7 * b + 3:7 * b + 7] = 0.5 * quat_multiply(q[7 * b + 3:7 * b + 7],
                                                            np.array([0.0, w[0], w[1], w[2]]))
        out[n:] = a
        self.counters["rhs"] += 1
        return out

    # -- events and restarts -----------------------------------------------------------
    def _restart(self, q, v, mode):
        """The state put back on the contact: unit quaternions, gap zero, rows' velocities zero."""
        q = q.copy()
        for b in range(self.nb):
            p = q[7 * b + 3:7 * b + 7]
            norm = float(np.linalg.norm(p))
            self.counters["quaternion_norm_drift"] = max(self.counters["quaternion_norm_drift"],
                                                         abs(norm - 1.0))
            q[7 * b + 3:7 * b + 7] = p / norm
        b = self.scene.contact_bodies[0]
        # the gap moves with the body's centre along the normal alone (its offset turns with R)
        q[7 * b:7 * b + 3] -= float(self.scene.gaps(q, self.t)[0]) * self.normal
        rows = self.scene.contact_rows(q)[0]
        H = rows if mode == _STICK else rows[:1]
        MH = self.Minv @ H.T
        v = v - MH @ np.linalg.solve(H @ MH, H @ v)
        return q, v

    def _decide(self, t, q, v):
        """``(mode, direction)`` at ``(t, q, v)``; ``q``, ``v`` become the state."""
        self.q, self.v = q, v
        self._update_vscale(q, v)
        rows = self.scene.contact_rows(q)[0]
        u = self._slip(rows, v, self._tangent_rows(q, rows))
        speed = float(np.linalg.norm(u))
        if self.mu == 0.0:
            # frictionless: the normal row alone, whatever the slip
            mode, d = _SLIDE, None
        elif speed > self._vtol():
            mode, d = _SLIDE, u / speed
        elif self.lever > 0.0:
            self._no_rolling(t)
        else:
            self.q, self.v = q, v = self._restart(q, v, _STICK)
            _, lamN, lamT, _, _ = self.solve(t, q, v, _STICK, None)
            size = math.hypot(lamT[0], lamT[1])
            if size <= self.mu * lamN:
                mode, d = _STICK, None
            else:
                # the cone cannot hold the rolling: slip starts opposite the friction force
                mode, d = _SLIDE, -lamT / size
        lamN = self.solve(t, self.q, self.v, mode, d)[1]
        if lamN < 0.0:
            self._liftoff(t, lamN)
        return mode, d

    def _liftoff(self, t, lamN):
        self.events.append(Event(t=t, kind="liftoff", before=Regime(self.mode),
                                 after=Regime.FLIGHT, contact=0))
        raise ContactLostError(f"lift-off at t = {t:.12g}: the contact's normal force reaches "
                               f"{lamN:.3g} <= 0; scheme 'event-driven-space' keeps the contact "
                               "closed and models no flight")

    # -- recording ---------------------------------------------------------------------
    def _sample_row(self, t, q, v, mode, direction):
        _, lamN, lamT, u, _ = self.solve(t, q, v, mode, direction)
        return (t, q, v, np.array([mode]), np.array([lamN]),
                np.array([math.hypot(lamT[0], lamT[1])]), np.array([math.hypot(u[0], u[1])]),
                self.scene.gaps(q, t))

    def _record_state(self, t, q, v):
        self._record(*self._sample_row(t, q, v, self.mode, self.direction))

    # -- smooth phase --------------------------------------------------------------------
    def _step_impl(self):
        mode, d, t0 = self.mode, self.direction, self.t
        n = self.scene.ndof
        y0 = np.concatenate([self.q, self.v])
        _, lamN0, lamT0, u0, _ = self.solve(t0, self.q, self.v, mode, d)
        skip = 1e-10 * max(1.0, abs(t0))

        def make(fun, start_zero):
            def ev(t, y):
                return 1.0 if start_zero and t < t0 + skip else fun(t, y)
            ev.terminal, ev.direction = True, -1.0
            return ev

        cache = {}

        def evaluate(t, y):
            # DOP853 evaluates its last stage where the event functions are checked next
            key = (t, y.tobytes())
            if cache.get("key") != key:
                cache["key"], cache["val"] = key, self.solve(t, y[:n], y[n:], mode, d)
            return cache["val"]

        def part(k):
            return lambda t, y: evaluate(t, y)[k]

        lam_n = part(1)
        fscale = max(abs(lamN0), 1e-300)
        events = [make(lam_n, lamN0 <= 1e-12 * fscale)]
        if mode == _STICK and self.mu > 0.0:
            def cone(t, y):
                _, lamN, lamT, _, _ = evaluate(t, y)
                return self.mu * lamN - math.hypot(lamT[0], lamT[1])
            events.append(make(cone, self.mu * lamN0 - math.hypot(*lamT0) <= 1e-12 * fscale))
        elif mode == _SLIDE and self.mu > 0.0:
            events.append(make(lambda t, y: float(part(3)(t, y) @ d), float(u0 @ d) <= self._vtol()))
            events.append(make(part(4), False))
        kinds = ["liftoff", "transition", "painleve"][:len(events)]
        self.counters["segments"] += 1
        sol = solve_ivp(lambda t, y: self._rates(t, y, evaluate(t, y)[0]), (t0, self.t_bound), y0,
                        method="DOP853", rtol=self.options.rtol, atol=self.options.atol,
                        events=events, dense_output=True, max_step=self.options.max_step)
        y1 = self._follow_phase(sol, lambda t, q, v: self._sample_row(t, q, v, mode, d))
        q, v = y1[:n].copy(), y1[n:].copy()
        if sol.status != 1:
            self.q, self.v = self._restart(q, v, mode)
            self._record_state(self.t, self.q, self.v)
            return
        fired = [kinds[k] for k, te in enumerate(sol.t_events) if len(te)]
        self.q, self.v = q, v
        if "liftoff" in fired:
            self._record_state(self.t, q, v)
            self._liftoff(self.t, float(lam_n(self.t, y1)))
        if "painleve" in fired:
            raise PainleveError(f"Painlevé condition fails at t = {self.t:.12g}: the sliding "
                                "contact's normal-force coefficient reaches 0")
        q, v = self._restart(q, v, _SLIDE)
        if mode == _STICK:
            # the cone saturates: slip starts opposite the friction force
            _, _, lamT, _, _ = self.solve(self.t, q, v, _STICK, None)
            self.q, self.v = q, v
            new, new_d = _SLIDE, -lamT / max(math.hypot(lamT[0], lamT[1]), 1e-300)
        else:
            new, new_d = self._decide(self.t, q, v)
        self.events.append(Event(t=self.t, kind="transition", before=Regime(mode),
                                 after=Regime(new), contact=0))
        self.counters["events"] += 1
        self.mode, self.direction = new, new_d
        self._record_state(self.t, self.q, self.v)
