"""A flat puck launched across a rough incline: its path in closed form for ``mu = tan(alpha)``.

A thin puck (a flat disk, :class:`moreau.model.space.Puck` of thickness 0,
lying on its face) slides on a plane inclined at ``alpha`` with Coulomb friction ``mu``,
launched at ``speed`` ``v0`` in the direction ``heading`` from the slope line
(``pi/2``: horizontal, across the slope). While it neither spins nor tips
its centre moves as a particle: with ``psi`` the angle of its velocity from
the down-slope direction, ``v`` its speed, ``s = sin(alpha)`` and ``mu =
tan(alpha)`` (friction ``mu g cos(alpha) = g s`` against the velocity),

.. math::

    \\dot v = g s (\\cos\\psi - 1), \\qquad v \\dot\\psi = -g s \\sin\\psi .

Derivation. ``dv/dpsi = v (1 - cos psi) / sin psi = v tan(psi/2)`` gives
``v (1 + cos psi) = V``, a constant (``V = v0 (1 + cos psi0)``), so the puck
ends sliding straight down at ``V / 2``. With ``tau = tan(psi/2)``, ``v =
V (1 + tau^2) / 2`` and ``dpsi = 2 dtau / (1 + tau^2)``, the time, the
across-slope distance ``y`` (``dy = v sin(psi) dt = -v^2 dpsi / (g s)``) and
the down-slope distance ``x`` (``dx = v cos(psi) dt``) integrate to

.. math::

    t(\\tau) = \\frac{V}{g s} \\bigl(F(\\tau_0) - F(\\tau)\\bigr), \\quad
    F(\\tau) = \\tfrac12 \\ln\\tau + \\tfrac14 \\tau^2,

    y(\\tau) = \\frac{V^2}{2 g s} \\Bigl(\\tau_0 + \\tfrac{\\tau_0^3}{3} - \\tau
    - \\tfrac{\\tau^3}{3}\\Bigr), \\quad
    x(\\tau) = \\frac{V^2}{4 g s} \\Bigl(\\ln\\frac{\\tau_0}{\\tau}
    + \\frac{\\tau^4 - \\tau_0^4}{4}\\Bigr),

from ``tau0 = tan(psi0 / 2)`` (``F`` increases with ``tau``: a time gives
``tau`` by Newton's method on ``ln tau``). Launched horizontally, ``V = v0``,
the puck drifts ``y_inf = 2 v0^2 / (3 g s)`` across the slope (a classical
problem: e.g. Irodov, Problems in General Physics, 1979, problem 1.83 [the
speed]; the path is derived here). For ``mu != tan(alpha)`` the reference
integrates the particle's equations (:func:`puck_incline_path`, rtol 1e-12),
at rest from the time the speed vanishes when ``mu > tan(alpha)``.

The model: the incline's frame (``x`` down the slope, ``y`` across, ``z`` the
normal), the thin puck's face touching through its centre, one contact
(:class:`~moreau.model.space.Puck`: no tipping moment, the uniform
pressure's resultant at the centre while it slides without spin; a puck of
some thickness touching through three rim points makes the friction
statically indeterminate, and its polyhedral LCP degenerate); units: lengths in the puck's radius,
time in ``sqrt(radius / g)``, mass in its mass.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from .._validate import finite_scalar, times
from ..analysis.cases import ClosedFormPath, SpatialCase
from ..errors import InputError
from ..model.params import GRAVITY, MASS, MU, POSITIVE, RADIUS, SLOPE, SPEED, Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import as_params, params_with
from ..model.space import Puck, SpaceModel

__all__ = ["PuckInclineParams", "puck_incline", "puck_incline_path"]


@dataclass(frozen=True)
class PuckInclineParams(Declared):
    """SI parameters of the puck on the incline."""

    mass: float = MASS(0.17, note="An ice-hockey puck: 0.17.")
    radius: float = RADIUS(0.038, note="An ice-hockey puck: 0.038.")
    slope: float = SLOPE(0.3, "Inclination ``alpha``")
    mu: float = MU(math.tan(0.3), "Coulomb friction",
                   note="The default ``tan(0.3)`` is ``tan(slope)`` at the default slope, where "
                        "the path has its closed form.")
    gravity: float = GRAVITY(9.81)
    speed: float = SPEED(1.0, "Launch speed", rule=POSITIVE)
    heading: float = param(0.5 * math.pi, "rad",
                           doc="Launch direction from the down-slope line, towards ``+y``",
                           note="In (-pi, pi); ``pi/2`` (the default) is horizontal.")

    sweepable = ("mu", "slope", "speed", "heading")

    def __post_init__(self):
        super().__post_init__()
        h = finite_scalar("heading", self.heading)
        if not -math.pi < h < math.pi:
            raise InputError(f"`heading` must be in (-pi, pi), got {h!r}")
        object.__setattr__(self, "heading", h)


def puck_incline(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the puck on the incline.

    Examples
    --------
    >>> sc = puck_incline()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ncontacts, sc.gaps(q0, 0.0).round(15).tolist(), v0[:3].round(12).tolist()
    (1, [0.0], [0.0, 1.637848389492, 0.0])
    """
    p = params_with(PuckInclineParams, params, overrides)
    g, a, r = p.gravity, p.slope, p.radius
    m = SpaceModel(gravity=(g * math.sin(a), 0.0, -g * math.cos(a)), length=r, mass=p.mass)
    ice = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    # a thin disk's moments: m r^2 / 4 about a diameter, m r^2 / 2 about its axis
    puck = m.add_body(p.mass, [0.25 * p.mass * r * r, 0.25 * p.mass * r * r, 0.5 * p.mass * r * r],
                      position=(0.0, 0.0, 0.0),
                      velocity=(p.speed * math.cos(p.heading), p.speed * math.sin(p.heading), 0.0),
                      name="puck")
    m.add_contact(puck, Puck(r, 0.0, rim_points=1), ice, mu=p.mu)
    sc = m.build("puck-incline", default_window=16.0)
    sc.params = p
    return sc


puck_incline.Params = PuckInclineParams


def _tau_at(F_target, tau0):
    # F(tau) = u/2 + e^(2u)/4 with u = ln tau: increasing and convex in u, so Newton from
    # u0 (where F > F_target) descends monotonically to the root
    u = math.log(tau0)
    for _ in range(200):
        f = 0.5 * u + 0.25 * math.exp(2.0 * u) - F_target
        step = f / (0.5 + 0.5 * math.exp(2.0 * u))
        u -= step
        if abs(step) <= 1e-15 * max(1.0, abs(u)):
            break
    return math.exp(u)


def _closed_form(p, tt):
    g, s = p.gravity, math.sin(p.slope)
    v0, psi0 = p.speed, abs(p.heading)
    sign = 1.0 if p.heading >= 0.0 else -1.0
    if psi0 == 0.0:
        return np.column_stack([v0 * tt, 0.0 * tt, np.full(tt.size, v0), 0.0 * tt])
    V = v0 * (1.0 + math.cos(psi0))
    tau0 = math.tan(0.5 * psi0)
    F0 = 0.5 * math.log(tau0) + 0.25 * tau0 ** 2
    out = np.empty((tt.size, 4))
    for k, t in enumerate(tt):
        tau = _tau_at(F0 - g * s * t / V, tau0) if t > 0.0 else tau0
        y = V * V / (2.0 * g * s) * (tau0 + tau0 ** 3 / 3.0 - tau - tau ** 3 / 3.0)
        x = V * V / (4.0 * g * s) * (math.log(tau0 / tau) + (tau ** 4 - tau0 ** 4) / 4.0)
        v = 0.5 * V * (1.0 + tau * tau)
        psi = 2.0 * math.atan(tau)
        out[k] = (x, sign * y, v * math.cos(psi), sign * v * math.sin(psi))
    return out


def _integrated(p, tt):
    g, a, mu = p.gravity, p.slope, p.mu

    def rhs(t, z):
        sp = math.hypot(z[2], z[3])
        return [z[2], z[3], g * math.sin(a) - mu * g * math.cos(a) * z[2] / sp,
                -mu * g * math.cos(a) * z[3] / sp]

    def stops(t, z):
        return math.hypot(z[2], z[3]) - 1e-9 * p.speed
    stops.terminal = True

    z0 = [0.0, 0.0, p.speed * math.cos(p.heading), p.speed * math.sin(p.heading)]
    sol = solve_ivp(rhs, (0.0, float(tt.max()) if tt.size else 0.0), z0, method="DOP853",
                    rtol=1e-12, atol=1e-14 * p.speed, dense_output=True, events=stops)
    out = np.empty((tt.size, 4))
    t_end = sol.t[-1]
    for k, t in enumerate(tt):
        z = sol.sol(min(t, t_end))
        out[k] = z if t <= t_end else (z[0], z[1], 0.0, 0.0)
    return out


def puck_incline_path(params, t):
    """``(x, y, x', y')`` of the puck's centre at times ``t`` [s] (SI), one row each.

    The closed form when ``mu = tan(slope)`` (to 1e-12), else the particle's
    equations integrated (see the module docstring).

    Examples
    --------
    >>> p = PuckInclineParams()
    >>> z = puck_incline_path(p, [0.0, 50.0])
    >>> v0, gs = p.speed, p.gravity * math.sin(p.slope)
    >>> round(float(z[1, 1] / (2 * v0 ** 2 / (3 * gs))), 12), round(float(z[1, 2] / v0), 12)
    (1.0, 0.5)
    """
    p = as_params(PuckInclineParams, params)
    tt = times("t", t)
    if abs(p.mu - math.tan(p.slope)) <= 1e-12 * math.tan(p.slope):
        return _closed_form(p, tt)
    return _integrated(p, tt)


class PuckInclineCase(ClosedFormPath, SpatialCase):
    """The puck over the window: its drift across the slope against the reference path."""

    headline_name = "distance across the slope"
    window = 16.0

    scene_factory = staticmethod(puck_incline)

    def coordinate(self, q):
        return q[:, 1]

    def path(self, tau):
        return puck_incline_path(self.p, tau * self.scene.time)[:, 1] / self.scene.length

    def first_regime(self):
        return "P"


register_scene(SceneEntry(
    name="puck-incline",
    factory=puck_incline,
    description=("flat puck launched across a rough incline: its path in closed form for "
                 "mu = tan(alpha), the polyhedral cone's facets against the exact cone"),
    case=PuckInclineCase,
))
