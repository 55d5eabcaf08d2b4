"""A billiard ball struck with backspin: it slides, then rolls from ``t* = 2 (v0 - r w0) / (7 mu g)`` at ``(5 v0 + 2 r w0) / 7``.

A uniform ball (mass ``m``, radius ``r``, ``J = (2/5) m r^2``) on a level
cloth (Coulomb ``mu``), launched along ``x`` at ``speed`` ``v0`` with the spin
``w0`` about the ``y`` axis (``w0 = v0 / r`` is rolling, ``w0 < 0``
backspin). The contact point slips at ``u = v - r w``; while ``u > 0``
kinetic friction ``mu m g`` acts against it:

.. math::

    v' = -\\mu g, \\qquad r w' = \\tfrac{5}{2} \\mu g, \\qquad
    u' = -\\tfrac72 \\mu g,

so the slip ends at ``t* = 2 u0 / (7 mu g)`` (``u0 = v0 - r w0``), and the
ball rolls on at ``v* = v0 - mu g t* = (5 v0 + 2 r w0) / 7``, kept for
ever (no rolling resistance). A negative ``v*`` (a strong backspin) is the
draw shot: the ball comes back. Forward spin above rolling (``u0 < 0``)
reverses the signs: ``t* = 2 |u0| / (7 mu g)``, the same ``v*`` (Coriolis,
Théorie mathématique des effets du jeu de billard, 1835; e.g. Marlow, The
Physics of Pocket Billiards, 1995, ch. 2).

Frame: ``z`` up, the cloth ``z = 0``; units: lengths in ``r``, time in
``sqrt(r / g)``, mass in ``m``. Coordinates the centre and the unit
quaternion; velocities the centre's and the body-frame angular velocity.
"""

import math
from dataclasses import dataclass

import numpy as np

from .._validate import times
from ..analysis.cases import GRID, ExactReference, SpatialCase
from ..model.params import FINITE, GRAVITY, MASS, MU, POSITIVE, RADIUS, Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import as_params, params_with
from ._sphere_on_plane import sphere_on_plane

__all__ = ["BilliardParams", "billiard_backspin", "billiard_exact", "rolling_onset"]


@dataclass(frozen=True)
class BilliardParams(Declared):
    """SI parameters of the ball struck with spin."""

    mass: float = MASS(0.17, note="A pool ball: 0.17.")
    radius: float = RADIUS(0.028575, note="A pool ball: 0.028575.")
    mu: float = MU(0.2, "Ball-cloth friction", rule=POSITIVE)
    gravity: float = GRAVITY(9.81)
    speed: float = param(2.0, "m/s", FINITE, "Launch speed along ``x``")
    spin: float = param(-40.0, "rad/s", FINITE, "Launch spin about ``y``",
                        "``speed / radius`` rolls; negative is backspin.")

    sweepable = ("mu", "speed", "spin")


def rolling_onset(p):
    """``(t*, v*)``: the time [s] the ball starts rolling and its speed then [m/s].

    Examples
    --------
    >>> t, v = rolling_onset(BilliardParams(speed=2.0, spin=0.0))   # no spin: 5/7 of the speed
    >>> round(v, 12), round(t * 7 * 0.2 * 9.81 / 4.0, 12)
    (1.428571428571, 1.0)
    """
    u0 = p.speed - p.radius * p.spin
    return 2.0 * abs(u0) / (7.0 * p.mu * p.gravity), (5.0 * p.speed + 2.0 * p.radius * p.spin) / 7.0


def billiard_backspin(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the ball on the cloth.

    Examples
    --------
    >>> sc = billiard_backspin()
    >>> q0, v0 = sc.initial_state()
    >>> round(float(v0[0] - v0[4]), 12) > 0          # the contact point slips forward
    True
    """
    p = params_with(BilliardParams, params, overrides)
    return sphere_on_plane("billiard-backspin", p, (0.0, 0.0, -p.gravity), p.spin, "ball", 20.0)


billiard_backspin.Params = BilliardParams


def billiard_exact(params, t):
    """``(x, v, w)``: distance, speed along ``x`` and spin at times ``t`` [s] (SI).

    Examples
    --------
    >>> p = BilliardParams()
    >>> t, v = rolling_onset(p)
    >>> x, vx, w = billiard_exact(p, [t, 2 * t])
    >>> bool(abs(vx[1] - v) < 1e-15 and abs(w[1] * p.radius - v) < 1e-12)
    True
    """
    p = as_params(BilliardParams, params)
    tt = times("t", t)
    t_star, v_star = rolling_onset(p)
    sign = 1.0 if p.speed - p.radius * p.spin >= 0.0 else -1.0
    a = -sign * p.mu * p.gravity
    ts = np.minimum(tt, t_star)
    x = p.speed * ts + 0.5 * a * ts ** 2 + v_star * (tt - ts)
    v = np.where(tt < t_star, p.speed + a * tt, v_star)
    w = np.where(tt < t_star, p.spin - 2.5 * a * tt / p.radius, v_star / p.radius)
    return x, v, w


class BilliardCase(ExactReference, SpatialCase):
    """The ball over the window: distance along ``x`` against the closed form."""

    headline_name = "distance along the cloth"
    window = 20.0

    scene_factory = staticmethod(billiard_backspin)

    def reference(self, rtol):
        x, _, _ = billiard_exact(self.p, [self.window * self.scene.time])
        t_star, _ = rolling_onset(self.p)
        return float(x[0]) / self.scene.length, [(0.0, "P"), (t_star / self.scene.time, "S")]

    def reference_grid(self):
        x, _, _ = billiard_exact(self.p, np.linspace(0.0, self.window, GRID + 1) * self.scene.time)
        return x / self.scene.length


register_scene(SceneEntry(
    name="billiard-backspin",
    factory=billiard_backspin,
    description=("billiard ball struck with backspin: slides, then rolls from t* = "
                 "2 (v0 - r w0) / (7 mu g) at (5 v0 + 2 r w0) / 7 (closed form)"),
    case=BilliardCase,
))
