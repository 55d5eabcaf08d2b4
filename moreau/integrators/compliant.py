"""Regularised (compliant) contact, as many engineers model it, integrated as a smooth ODE.

Each contact becomes a spring–damper in the normal direction and a
regularised Coulomb law in the tangential one, so the motion is an ordinary
differential equation that a general-purpose solver integrates: scipy's
implicit Radau method (``"compliant-radau"``) or an explicit Runge–Kutta
method, Dormand–Prince 5(4) (``"compliant-rk45"``). These are the schemes
that the non-smooth ones are usually compared with: their error against the
non-smooth reference falls as the contact gets stiffer and the friction law
sharper, and their cost grows with the stiffness (the explicit method most).

Model (in the scene's dimensionless units). With the penetration
``delta_i = -g_i`` and its rate ``delta_i' = -(WN_i v + wN_i)``, the normal force
of contact ``i`` is zero while ``delta_i <= 0`` and otherwise

* Kelvin–Voigt: ``fN = max(0, k delta + c delta')``;
* Hunt–Crossley: ``fN = max(0, k delta^(3/2) + c delta^(3/2) delta')``;

clamped at zero so that a separating contact never pulls. The tangential
force of a frictional contact with slip velocity ``gT = WT_i v + wT_i`` is
``fT = -mu fN gT / sqrt(gT^2 + eps^2)``, Coulomb's law smoothed over slip
velocities of the size of ``eps = friction_velocity * velocity_scale``, with
the scene's ``velocity_scale`` (the stator's speed on the drives; 1 where a
scene has none): a smoothing that is small on one scene must be small on
all, and the drives' slip speeds are three decades below the ball's. Then

    M(q) v' = h(q, v, t) + WN^T fN + WT^T fT,    q' = v.

Kelvin–Voigt damping defaults to the scene's restitution ``e``: the damping
ratio ``zeta`` whose clamped linear spring–damper, on the contact's
effective mass ``m = 1 / (WN M^-1 WN^T)`` (at the initial state), rebounds
with ``e`` (:func:`clamped_restitution`; the unclamped formula ``e =
exp(-zeta pi / sqrt(1 - zeta^2))`` would rebound faster), and ``c = 2 zeta
sqrt(k m)``. Such a contact is never more plastic than ``e`` of about 0.136
(critical damping is used below that). Hunt–Crossley takes ``damping`` as
given (default 0: elastic).

The recorded regime of a contact is flight while it carries no normal force,
stick while its slip speed is within ``10 eps``, else the slip's sign. Forces
are the model's forces at the sample (not impulses).

Examples
--------
>>> from moreau.scenes import make_scene
>>> from moreau.integrators import simulate
>>> ball = make_scene("bouncing-ball", restitution=0.5)
>>> q0, v0 = ball.initial_state()
>>> r = simulate(ball, (0.0, 1.0), q0, v0, "compliant-radau", stiffness=1e6)
>>> r.success
True
"""

import dataclasses
import math
from typing import ClassVar

import numpy as np
from scipy.integrate import RK45, Radau
from scipy.optimize import brentq

from .._validate import nonnegative, positive, positive_int, relative_tolerance
from ..errors import InputError, MoreauError
from ..regimes import Regime
from .base import Integrator, SchemeOptions, register_integrator
from .event_driven_generic import contact_law_regimes

__all__ = ["CompliantRadau", "CompliantRK45", "CONTACT_MODELS", "damping_for_restitution",
           "clamped_restitution"]

#: default bound on the steps of one run: the steps are taken in Python, 0.3-1 ms each
MAX_STEPS = 10**6

#: normal force laws: name -> exponent of the penetration
CONTACT_MODELS = {"kelvin-voigt": 1.0, "hunt-crossley": 1.5}


def clamped_restitution(zeta):
    """Rebound of a mass on a linear spring–damper whose force is clamped at zero, damping ratio ``zeta``.

    With unit mass and stiffness the penetration is ``d = exp(-zeta t)
    sin(w t) / w`` (``w = sqrt(1 - zeta^2)``, impact at unit speed); the
    contact lets go when the force ``d + 2 zeta d'`` returns to zero, at
    ``w t = pi + atan2(-2 zeta, (1 - 2 zeta^2) / w)``, before the spring
    would pull, so the rebound ``-d'`` there exceeds the unclamped
    ``exp(-zeta pi / w)``. For ``0 <= zeta < 1``.

    Examples
    --------
    >>> clamped_restitution(0.0)
    1.0
    >>> round(clamped_restitution(0.2), 4)
    0.5717
    """
    if not 0.0 <= zeta < 1.0:
        raise InputError(f"`zeta` must be in [0, 1), got {zeta!r}")
    w = math.sqrt(1.0 - zeta * zeta)
    phi = math.pi + math.atan2(-2.0 * zeta, (1.0 - 2.0 * zeta * zeta) / w)
    return -math.exp(-zeta * phi / w) * (math.cos(phi) - zeta / w * math.sin(phi))


#: the damping ratio beyond which the closed form loses digits (w -> 0), and the
#: least restitution a clamped Kelvin-Voigt contact reaches below it (about 0.136)
_ZETA_MAX = 0.999
_E_MIN = clamped_restitution(_ZETA_MAX)


def damping_for_restitution(e, stiffness, mass):
    """Kelvin–Voigt damping ``c`` whose clamped spring–damper rebounds with restitution ``e``.

    Solves :func:`clamped_restitution` ``(zeta) = e`` and returns ``c = 2
    zeta sqrt(k m)``. A clamped Kelvin–Voigt contact cannot be more plastic
    than about ``e = 0.136``: below that, critical damping (``zeta = 1``) is
    used and the rebound stays near 0.13.

    Examples
    --------
    >>> c = damping_for_restitution(0.5, 1e6, 1.0)
    >>> round(clamped_restitution(c / (2 * 1e3)), 12)
    0.5
    """
    if e >= 1.0:
        return 0.0
    if e <= _E_MIN:
        zeta = 1.0
    else:
        zeta = brentq(lambda z: clamped_restitution(z) - e, 0.0, _ZETA_MAX, xtol=1e-15)
    return 2.0 * zeta * math.sqrt(stiffness * mass)


def _contact_model_option(value):
    if value not in CONTACT_MODELS:
        raise InputError(f"`contact_model` must be one of {sorted(CONTACT_MODELS)}, got "
                         f"{value!r}")
    return value


class _Compliant(Integrator):
    """Common part of the compliant schemes (see the module docstring)."""

    # the dense output of the ODE's steps is the scheme's motion (events as in solve_ivp)
    exact_motion = True
    _solver = None
    # the model error falls as the contact stiffens (about as 1/sqrt(k) for an
    # impact); the integration error is held below it
    compare_settings = ("stiffness", (1e3, 1e4, 1e5), (1e3, 1e4),
                        {"rtol": 1e-9, "atol": 1e-12, "friction_velocity": 1e-3})

    @dataclasses.dataclass(frozen=True)
    class Options(SchemeOptions):
        """Options of a compliant scheme (see :class:`CompliantRadau`)."""
        stiffness: float = 1e6
        damping: float | None = None
        contact_model: str = "kelvin-voigt"
        friction_velocity: float = 1e-4
        rtol: float = 1e-8
        atol: float = 1e-10
        max_step: float | None = None
        sample_dt: float | None = None
        max_steps: int = MAX_STEPS

        _rules: ClassVar[dict] = {
            "stiffness": lambda v: positive("stiffness", v),
            "damping": lambda v: None if v is None else nonnegative("damping", v),
            "contact_model": _contact_model_option,
            "friction_velocity": lambda v: positive("friction_velocity", v),
            "rtol": lambda v: relative_tolerance("rtol", v, floor=False),
            "atol": lambda v: positive("atol", v),
            "max_step": lambda v: None if v is None else positive("max_step", v),
            "sample_dt": lambda v: None if v is None else positive("sample_dt", v),
            "max_steps": lambda v: positive_int("max_steps", v)}

    takes_options_object = True

    def __init__(self, scene, t0, q0, v0, t_bound, options=None, **keywords):
        super().__init__(scene, t0, q0, v0, t_bound)
        self.options = o = self._take_options(options, keywords)
        damping, contact_model, max_step = o.damping, o.contact_model, o.max_step
        self.stiffness = o.stiffness
        self.contact_model = contact_model
        self.power = CONTACT_MODELS[contact_model]
        vs = float(np.max(np.abs(getattr(scene, "velocity_scale", 1.0))))
        self.eps = o.friction_velocity * (vs if vs > 0 else 1.0)
        self.rtol, self.atol = o.rtol, o.atol
        nc = scene.ncontacts
        self.mu = np.asarray(scene.mu, float).reshape(-1) if nc else np.zeros(0)
        self.fr = np.asarray(scene.frictional_index, int) if nc else np.zeros(0, int)
        WN = scene.contact_jacobians(self.q, self.t)[0] if nc else np.zeros((0, scene.ndof))
        Minv = np.linalg.inv(scene.mass(self.q))
        meff = 1.0 / np.maximum(np.einsum("ij,jk,ik->i", WN, Minv, WN), 1e-300)
        if damping is None:
            if contact_model == "kelvin-voigt":
                e = np.asarray(scene.restitution, float).reshape(-1) if nc else np.zeros(0)
                self.damping = np.array([damping_for_restitution(float(ei), self.stiffness, m)
                                         for ei, m in zip(e, meff)])
            else:
                self.damping = np.zeros(nc)
        else:
            self.damping = np.full(nc, damping)
        # a contact lasts about pi sqrt(m / k): steps must not jump over one
        given = max_step is not None
        if max_step is None:
            m_min = float(np.min(meff)) if nc else 1.0
            max_step = 0.1 * math.pi * math.sqrt(m_min / self.stiffness)
        self.max_step = positive("max_step", max_step)
        self.max_steps = o.max_steps
        steps = math.ceil((self.t_bound - self.t0) / self.max_step)
        if steps > self.max_steps:
            why = ("`max_step`" if given else
                   f"the default `max_step` = 0.1 pi sqrt(m / k) (a tenth of the contact's "
                   f"duration pi sqrt(m / k), effective mass m = {m_min:.3g}, `stiffness` k = "
                   f"{self.stiffness:g})")
            raise InputError(f"{why} = {self.max_step:.3g} takes at least {steps:.3g} steps over "
                             f"[{self.t0:g}, {self.t_bound:g}], more than `max_steps` = "
                             f"{self.max_steps:.3g} (about 1 ms a step): take a softer contact, "
                             f"a shorter run, or raise `max_steps`")
        self.sample_dt = o.sample_dt
        self.counters.update(rhs_evaluations=0, jacobian_evaluations=0)
        n = scene.ndof
        y0 = np.concatenate([self.q, self.v])
        self._n = n
        extra = {"jac": self._jac} if self._solver is Radau else {}
        atol_y = np.full(2 * n, self.atol)
        if self._solver is Radau and nc:
            m_min = float(np.min(meff))
            atol_y[n:] = max(self.atol, self._velocity_atol_floor(m_min, self.q))
        self.velocity_atol = float(atol_y[-1]) if n else self.atol
        self._ode = self._solver(self._rhs, self.t0, y0, self.t_bound, rtol=self.rtol,
                                 atol=atol_y, max_step=self.max_step, **extra)
        self._next_sample = self.t0
        # the start on a closed contact (gap and normal velocity zero) carries no spring
        # force yet: its regime is the contact law's (event_driven_generic), not flight
        row = list(self._sample_row(self.t0, y0))
        row[3] = contact_law_regimes(scene, self.t0, row[1], row[2], row[3])
        self._record(*row)
        self._next_sample = self.t0 + (self.sample_dt or 0.0)

    def _velocity_atol_floor(self, m_min, q0):
        """The least absolute velocity tolerance that Radau's Newton iteration can certify.

        A contact spring turns one rounding of a coordinate, ``ulp(q)``, into
        an acceleration jump of ``omega^2 ulp(q)`` (``omega^2 = k / m``, the
        stiffest contact; Hunt–Crossley's ``1.5 k delta^(1/2)`` is below ``k``
        for ``delta < 4/9``, far beyond any penetration of a usable model).
        Over a Newton stage of length ``h = min(max_step, 1 / omega)`` (a
        longer stage is bounded by the spring) that is a velocity increment
        ``h omega^2 ulp(q)`` of pure rounding, which no iteration
        removes. scipy's Radau stops its simplified Newton iteration when
        ``rate / (1 - rate) ||dW|| < newton_tol`` (``||.||`` the RMS norm
        of the increments over ``atol + rtol |y|``, ``newton_tol = max(10 eps
        / rtol, min(0.03, rtol^(1/2)))``) and gives up when the rate reaches
        1. Where the solution barely moves (a stuck phase, a contact at rest)
        every increment after the first is that rounding, the rate is about
        1, and each step fails: the Jacobian is rebuilt and the step halved,
        step after step (measured: 12 000 Jacobians for 1.2 s of rest of the
        sliding box at ``k = 1e3``, ``atol = 1e-12``). The floor makes the
        rounding increment a tenth of ``newton_tol`` in the velocity's
        scale, so that rates up to 0.9 still converge:

            floor = 10 h omega^2 ulp(max |q0|) / newton_tol

        with ``q0`` the coordinates that enter the forces (the scene's
        cyclic coordinates left out). Positions keep ``atol``.
        """
        stiff = self.stiffness / max(m_min, 1e-300)
        cyc = set(getattr(self.scene, "cyclic_coordinates", ()))
        qs = [abs(float(x)) for j, x in enumerate(q0) if j not in cyc]
        ulp = float(np.spacing(max(qs, default=1.0) or 1.0))
        eps = float(np.finfo(float).eps)
        newton_tol = max(10.0 * eps / self.rtol, min(0.03, math.sqrt(self.rtol)))
        # beyond a step of 1 / omega the stage's response to a force is bounded by the
        # spring (about jump / omega), not by the step
        h = min(self.max_step, 1.0 / math.sqrt(stiff))
        return 10.0 * h * stiff * ulp / newton_tol

    # -- the model ------------------------------------------------------------
    def _contact_forces(self, q, v, t):
        sc = self.scene
        nc = sc.ncontacts
        fN = np.zeros(nc)
        fT = np.zeros(nc)
        slip = np.zeros(nc)
        if nc == 0:
            return fN, fT, slip, np.zeros(0), None
        g = np.asarray(sc.gaps(q, t), float)
        WN, wN, WT, wT = sc.contact_jacobians(q, t)
        delta = -g
        rate = -(WN @ v + wN)
        d = np.maximum(delta, 0.0)
        if self.power == 1.0:
            f = self.stiffness * d + self.damping * rate
        else:
            # Hunt-Crossley: the damping grows with the contact area, so the force is
            # continuous at first touch
            f = d ** self.power * (self.stiffness + self.damping * rate)
        fN = np.where(delta > 0.0, np.maximum(0.0, f), 0.0)
        if len(self.fr):
            gT = WT @ v + wT
            slip[self.fr] = gT
            fT[self.fr] = -self.mu[self.fr] * fN[self.fr] * gT / np.sqrt(gT * gT + self.eps ** 2)
        return fN, fT, slip, g, (WN, WT)

    def _rhs(self, t, y):
        n = self._n
        q, v = y[:n], y[n:]
        sc = self.scene
        f = np.asarray(sc.forces(q, v, t), float).copy()
        fN, fT, _, _, rows = self._contact_forces(q, v, t)
        if rows is not None:
            WN, WT = rows
            f += WN.T @ fN
            if len(self.fr):
                f += WT.T @ fT[self.fr]
        self.counters["rhs_evaluations"] += 1
        a = np.linalg.solve(sc.mass(q), f)
        return np.concatenate([v, a])

    def _jac(self, t, y):
        # central differences with a fixed relative step: scipy's own adaptive ones grow
        # their step without bound on a column that is exactly zero (a coordinate the
        # forces do not depend on) and overflow
        n = self._n
        J = np.zeros((2 * n, 2 * n))
        J[:n, n:] = np.eye(n)
        for j in range(2 * n):
            dy = 1e-7 * max(1.0, abs(y[j]))
            yp = y.copy()
            ym = y.copy()
            yp[j] += dy
            ym[j] -= dy
            J[n:, j] = (self._rhs(t, yp)[n:] - self._rhs(t, ym)[n:]) / (2.0 * dy)
        self.counters["jacobian_evaluations"] += 1
        return J

    # -- stepping -------------------------------------------------------------
    def _record_state(self, t, y):
        self._record(*self._sample_row(t, y))

    def _sample_row(self, t, y):
        n = self._n
        q, v = y[:n], y[n:]
        fN, fT, slip, g, _ = self._contact_forces(q, v, t)
        reg = np.full(len(fN), int(Regime.FLIGHT))
        loaded = fN > 0.0
        stick = loaded & (np.abs(slip) <= 10.0 * self.eps)
        reg[loaded & (slip > 0)] = int(Regime.POSITIVE)
        reg[loaded & (slip < 0)] = int(Regime.NEGATIVE)
        reg[stick] = int(Regime.STICK)
        return t, q, v, reg, fN, fT, slip, g

    def _step_impl(self):
        ode = self._ode
        msg = ode.step()
        if ode.status == "failed":
            raise MoreauError(f"{type(ode).__name__} failed at t = {ode.t!r}: {msg}")
        y = ode.y
        if not np.all(np.isfinite(y)):
            raise MoreauError(f"non-finite state at t = {ode.t!r}")
        if self._want_pieces:
            # the step's dense output: the ODE's own motion between its step ends
            dense = ode.dense_output()
            self._add_piece([ode.t_old, ode.t], dense,
                            lambda t, dense=dense: self._sample_row(t, dense(t)))
        if self.sample_dt is None:
            self._record_state(ode.t, y)
        else:
            dense = ode.dense_output()
            while self._next_sample <= ode.t + 1e-12 * max(1.0, abs(ode.t)):
                ts = min(self._next_sample, ode.t)
                self._record_state(ts, dense(ts))
                self._next_sample += self.sample_dt
            if ode.status == "finished" and self._samples[-1][0] < ode.t:
                self._record_state(ode.t, y)
        self.t = self.t_bound if ode.status == "finished" else ode.t
        self.q, self.v = y[:self._n].copy(), y[self._n:].copy()
        self._note_paradox(ode.t, self.q, self.v)

    def _note_paradox(self, t, q, v):
        # a loaded contact sliding where the rigid model's normal-force coefficient
        # WN M^-1 (WN - mu s WT)^T is not positive: a Painlevé configuration, which the
        # compliant contact crosses by its stiffness; the result says so
        if not len(self.fr):
            return
        fN, _, slip, _, rows = self._contact_forces(q, v, t)
        live = [i for i in self.fr if fN[i] > 0.0 and abs(slip[i]) > 10.0 * self.eps]
        if not live:
            self._in_paradox = False
            return
        WN, WT = rows
        Minv = np.linalg.inv(np.asarray(self.scene.mass(q), float))
        row = {int(i): k for k, i in enumerate(self.fr)}
        bad = [i for i in live if WN[i] @ Minv @ (WN[i] - self.mu[i] * np.sign(slip[i])
                                                  * WT[row[int(i)]]) <= 0.0]
        if bad and not getattr(self, "_in_paradox", False):
            self.counters.setdefault("painleve_paradox_times", []).append(float(t))
        self._in_paradox = bool(bad)

    def result(self):
        """The run's :class:`SimulationResult`; its message notes a Painlevé configuration met."""
        res = super().result()
        times = self.counters.get("painleve_paradox_times")
        if times:
            res.message += (f" A loaded contact slid in a Painlevé configuration (the rigid "
                            f"contact's normal-force coefficient WN M^-1 (WN - mu s WT)^T <= 0) "
                            f"from t = {times[0]:.6g} ({len(times)} time(s), "
                            f"stats['painleve_paradox_times']): the compliant contact resolves "
                            f"it by its stiffness, where the rigid sliding contact has no solution or two.")
        return res


@register_integrator("compliant-radau")
class CompliantRadau(_Compliant):
    """Compliant contact integrated by scipy's implicit Radau IIA method (order 5).

    Options: ``stiffness`` (> 0), ``damping`` (>= 0; default from the
    restitution for Kelvin–Voigt), ``contact_model`` (``"kelvin-voigt"`` or
    ``"hunt-crossley"``), ``friction_velocity`` (> 0, in units of the scene's
    ``velocity_scale``), ``rtol`` (in ``(0, 1e-2]``), ``atol``,
    ``max_step`` (default a tenth of a contact's duration), ``sample_dt``
    (default: every step), ``max_steps`` (default ``1e6``: a run whose
    ``(t_bound - t0) / max_step`` exceeds it is refused before any work).

    The velocities' absolute tolerance is ``max(atol, floor)``, the floor
    being the least one Radau's Newton iteration can certify against the
    contact spring's rounding (:meth:`_velocity_atol_floor`; the value used
    is the attribute ``velocity_atol``). Positions keep ``atol``.
    """

    _solver = Radau


@register_integrator("compliant-rk45")
class CompliantRK45(_Compliant):
    """Compliant contact integrated by scipy's explicit Dormand–Prince 5(4) method.

    The same options as :class:`CompliantRadau`. Explicit: its steps are
    bounded by the contact's stiffness, so it pays most for a stiff contact.
    """

    _solver = RK45

