"""A disk on a rough incline, stated with the planar builder: rolling at ``(2/3) g sin(alpha)``.

A uniform disk (mass ``m``, radius ``r``, centroidal inertia ``I = m r^2 / 2``)
on a plane inclined at ``alpha``, one frictional contact (Coulomb ``mu``).
Launched rolling down the slope at ``speed``, it keeps rolling when
friction can hold the contact point: with ``s`` the speed down the slope
and ``w`` the rotation, rolling ``s = r w`` and the equations along the
slope ``m s' = m g sin(alpha) - F``, ``I w' = r F`` give::

    s' = g sin(alpha) / (1 + I / (m r^2)) = (2/3) g sin(alpha),   F = m g sin(alpha) / 3

which needs ``F <= mu m g cos(alpha)``, i.e. ``mu >= tan(alpha) / 3``. Below
that the disk slips from the start: ``s' = g (sin(alpha) - mu cos(alpha))``
and ``r w' = 2 mu g cos(alpha)``, and the slip ``s - r w`` grows, so it
never sticks again. The textbook result (e.g. Goldstein, Poole and Safko,
Classical Mechanics, 3rd ed., 2002, ch. 1 and 5; Meriam and Kraige,
Engineering Mechanics: Dynamics, the rolling disk on an incline).

Units: lengths in ``r``, time in ``sqrt(r / g)``, mass in ``m`` (the
builder's defaults). Coordinates ``(x, y, theta)`` of the centre; the
incline passes through the origin, its outward normal ``(-sin alpha, cos
alpha)``; the disk starts touching it at the origin.

The model (:func:`disk_incline_model`)::

    m = Model(gravity=(0.0, -g))
    floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), (-sin(alpha), cos(alpha))))
    disk = m.add_body(mass, mass * r**2 / 2, position=r * normal, velocity=speed * down,
                      angular_velocity=speed / r)
    m.add_contact(m.add_shape(disk, Circle(r)), floor, mu=mu)
"""

import math
from dataclasses import dataclass

import numpy as np

from .._validate import times
from ..analysis.cases import ClosedFormPath, FactoryCase
from ..model.planar import Circle, HalfPlane, Model
from ..model.params import GRAVITY, MASS, MU, RADIUS, SLOPE, SPEED, Declared
from ..model.scene import as_params, params_with
from ..model.registry import SceneEntry, register_scene

__all__ = ["InclineParams", "DiskInclineParams", "disk_incline_model", "disk_incline", "disk_incline_exact",
           "incline_motion", "rolls_down"]


@dataclass(frozen=True)
class InclineParams(Declared):
    """SI parameters of a round body on an incline (the disk's and the sphere's)."""

    mass: float = MASS(1.0)
    radius: float = RADIUS(0.1)
    slope: float = SLOPE(0.3, "Inclination ``alpha``")
    mu: float = MU(0.5, "Coulomb friction at the contact")
    gravity: float = GRAVITY(9.81)
    speed: float = SPEED(0.2, "Initial speed down the slope, rolling")

    sweepable = ("mu", "slope", "speed")


@dataclass(frozen=True)
class DiskInclineParams(InclineParams):
    """SI parameters of the disk on an incline (those of :class:`InclineParams`)."""


def disk_incline_model(params=None, **overrides):
    """The builder's model of the disk on the incline (SI parameters of :class:`DiskInclineParams`)."""
    p = params_with(DiskInclineParams, params, overrides)
    sa, ca = math.sin(p.slope), math.cos(p.slope)
    normal, down = np.array([-sa, ca]), np.array([-ca, -sa])
    m = Model(gravity=(0.0, -p.gravity))
    floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), normal))
    # rolling: the contact point C = X - r n is at rest, V = r w perp(n) = r w down
    disk = m.add_body(p.mass, 0.5 * p.mass * p.radius ** 2, position=p.radius * normal,
                      velocity=p.speed * down, angular_velocity=p.speed / p.radius, name="disk")
    m.add_contact(m.add_shape(disk, Circle(p.radius)), floor, mu=p.mu)
    return m


def disk_incline(params=None, **overrides):
    """The scene (a :class:`~moreau.model.planar.PlanarScene`) of the disk on the incline.

    Examples
    --------
    >>> sc = disk_incline(slope=0.3)
    >>> q0, v0 = sc.initial_state()
    >>> float(sc.gaps(q0, 0.0)[0]), round(float(v0[2]), 12)    # rolling: w = speed / r, scene units
    (0.0, 0.201927510938)
    """
    p = params_with(DiskInclineParams, params, overrides)
    sc = disk_incline_model(p).build("disk-incline", default_window=10.0)
    sc.params = p
    return sc


disk_incline.Params = DiskInclineParams


def rolls_down(p, k):
    """Whether a round body of inertia ``k m r^2`` rolls down the incline of parameters ``p``
    (``slope``, ``mu``): ``mu >= k tan(alpha) / (1 + k)`` (``tan(alpha) / 3`` for a disk).

    >>> [rolls_down(DiskInclineParams(slope=0.3, mu=mu), 0.5) for mu in (0.104, 0.103)]
    [True, False]
    """
    return p.mu >= k / (1.0 + k) * math.tan(p.slope)


def incline_motion(p, t, k):
    """``(s, s', w)``: distance and speed down the slope and rotation rate at times ``t`` [s]
    (SI) of a round body of inertia ``k m r^2`` started rolling at ``p.speed`` down the
    incline of parameters ``p`` (``slope``, ``mu``, ``radius``, ``gravity``).

    Rolling, ``m a = m g sin(alpha) - F`` and ``k m r^2 a / r = F r`` give ``a = g
    sin(alpha) / (1 + k)`` with ``F = k m a <= mu m g cos(alpha)`` (:func:`rolls_down`);
    slipping, ``a = g (sin(alpha) - mu cos(alpha))`` and ``w' = mu g cos(alpha) / (k r)``.
    """
    tt = times("t", t)
    g, a, r = p.gravity, p.slope, p.radius
    if rolls_down(p, k):
        acc = g * math.sin(a) / (1.0 + k)
        alpha = acc / r
    else:
        acc = g * (math.sin(a) - p.mu * math.cos(a))
        alpha = p.mu * g * math.cos(a) / (k * r)
    return p.speed * tt + 0.5 * acc * tt ** 2, p.speed + acc * tt, p.speed / r + alpha * tt


def disk_incline_exact(params, t):
    """``(s, s', w)``: distance and speed down the slope and rotation at times ``t`` [s] (SI).

    Examples
    --------
    >>> s, sd, w = disk_incline_exact(DiskInclineParams(speed=0.0), [1.0])
    >>> round(float(sd[0]) / (9.81 * math.sin(0.3)), 12)     # rolling: 2/3 g sin(alpha)
    0.666666666667
    """
    p = as_params(DiskInclineParams, params)
    return incline_motion(p, t, 0.5)


class InclineCase(ClosedFormPath):
    """A round body of inertia ``inertia m r^2`` over the window: distance down the slope
    against :func:`incline_motion` (a mixin for the disk's and the sphere's cases)."""

    headline_name = "distance down the slope"
    window = 10.0
    inertia = None

    def path(self, tau):
        return incline_motion(self.p, tau * self.scene.time, self.inertia)[0] / self.scene.length

    def first_regime(self):
        return "S" if rolls_down(self.p, self.inertia) else "P"


class DiskInclineCase(InclineCase, FactoryCase):
    """The disk over the window: distance down the slope against the closed form."""

    inertia = 0.5
    scene_factory = staticmethod(disk_incline)

    def coordinate(self, q):
        a = self.p.slope
        return -(q[:, 0] * math.cos(a) + q[:, 1] * math.sin(a))


register_scene(SceneEntry(
    name="disk-incline",
    factory=disk_incline,
    description=("disk rolling down a rough incline at (2/3) g sin(alpha), built with the "
                 "planar builder (closed form)"),
    case=DiskInclineCase,
))
