r"""A thin disk rolling without slipping in steady precession on a horizontal plane.

A thin disk (a rim, :class:`moreau.model.space.Disk`) of mass ``m`` and
radius ``a``, moments ``C = m a^2 / 2`` about its axis and ``A = m a^2 / 4``
about a diameter, rolls on a rough horizontal plane with its plane at the
``tilt`` ``theta`` from the horizontal (its axis at ``theta`` from the
vertical), leaning towards the centre ``O`` of the circle that its contact
point traces at the radius ``rho`` (``circle``). Its centre of mass then
circles ``O`` at the radius ``b = rho - a cos(theta)`` and the same rate
``Omega`` (the precession).

Steady motion, derived from Newton–Euler
-----------------------------------------
Take the precessing frame: the upward vertical ``z``, the horizontal unit
``e`` from ``O`` out to the centre ``G``, and ``c = z x e``. The axis is
``n = cos(theta) z + sin(theta) e``, the in-plane unit from the contact
point ``P`` up to ``G`` is ``u = sin(theta) z - cos(theta) e`` (``P = G - a
u``), and the disk turns at ``omega = Omega z + psi' n`` (``psi'`` its spin
relative to the frame), ``omega . n = omega_3 = Omega cos(theta) + psi'``.

* Rolling (``P``'s material velocity zero): ``v_G = omega x a u = -a
  omega_3 c``; ``G`` circling ``O`` at ``Omega`` has ``v_G = Omega b c``, so
  ``omega_3 = -Omega b / a``.
* Newton: ``G`` accelerates towards ``O``, ``m a_G = -m Omega^2 b e``, so the
  contact force is ``F = m g z - m Omega^2 b e``.
* Euler about ``G``: the angular momentum ``H = A Omega sin(theta) u + C
  omega_3 n`` is fixed in the precessing frame, so ``H' = Omega z x H =
  Omega sin(theta) (C omega_3 - A Omega cos(theta)) c``, and the moment of
  ``F`` at ``P`` is ``(-a u) x F = a m (Omega^2 b sin(theta) - g cos(theta))
  c``; equal, with ``omega_3 = -Omega b / a``, they give

.. math::

    \Omega^2 \sin\theta \,\Bigl[\Bigl(\frac{C}{a} + m a\Bigr) b
      + A \cos\theta\Bigr] = m g a \cos\theta ,
    \qquad\text{thin disk:}\qquad
    \Omega^2 = \frac{4 g \cot\theta}{6 b + a \cos\theta} .

This is the relation of the classical treatment (Routh, *Advanced Part of
a Treatise on the Dynamics of a System of Rigid Bodies*, 1905, art. 244;
K. T. McDonald, "The rolling motion of a disk on a horizontal plane",
arXiv:physics/0008227, 2000, sec. 2.2, with ``alpha = theta`` the disk's
angle to the plane and ``b`` the centre's circle); two limits hold it to
other published forms: ``b = 0`` (the centre at rest, Euler's disk) gives
``Omega^2 = 4 g / (a sin(theta))`` (H. K. Moffatt, Nature 404 (2000) 833),
and ``b >> a`` gives the leaning coin's ``tan(pi/2 - theta) = 3 v^2 / (2 g
b)``. A solution needs the bracket positive, ``rho > (5/6) a cos(theta)``
for the thin disk, and rolling needs ``mu >= Omega^2 b / g`` (the friction
``m Omega^2 b`` over the weight): both are refused by name otherwise
(:class:`RollingDiskParams`).

The exact motion: ``G(t) = O + b (cos Omega t, sin Omega t, 0) + a
sin(theta) z``, the rotation ``R(t) = R_z(Omega t) R_0 R_z(psi' t)`` (the
last factor about the body's axis), from ``R_0`` the axis tilted by
``theta`` about ``y`` (:func:`rolling_disk_exact`). The time-stepping
schemes keep the tilt and the precession rate to their order
(``tests/scenes/test_rolling_disk.py``: order one at either ``theta``, as
the rolling rows are taken at the step's start); the event-driven reference
(``event-driven-space``) keeps the tilt and the heading of this closed form to
about 1e-12 over a quarter period (``tests/integrators/test_event_driven_space.py``).

The model: one :class:`~moreau.model.space.Disk` contact on the floor;
units: lengths in ``a``, time in ``sqrt(a / g)``, mass in ``m``. The
fall of Euler's disk (its dissipation) is not modelled here.
"""

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.cases import ClosedFormPath, SpatialCase
from ..errors import InputError
from ..model.params import GRAVITY, MASS, MU, POSITIVE, RADIUS, Declared, open_interval, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import as_params, params_with
from ..model.space import Disk, SpaceModel
from ..model.spatial import quat_exp, quat_multiply, rotation_matrix

__all__ = ["RollingDiskParams", "rolling_disk", "steady_motion", "rolling_disk_exact",
           "tilt_and_heading"]


@dataclass(frozen=True)
class RollingDiskParams(Declared):
    """SI parameters of the rolling disk in steady precession."""

    mass: float = MASS(0.1)
    radius: float = RADIUS(0.05, "The disk's radius ``a``")
    tilt: float = param(1.2, "rad", open_interval(0.0, 0.5 * math.pi, "0, pi/2"),
                        "Tilt ``theta`` of the disk's plane from the horizontal")
    circle: float = param(0.25, "m", POSITIVE, "Radius ``rho`` of the contact point's circle",
                          "It must be > (5/6) a cos(theta).")
    mu: float = MU(0.8, "Coulomb friction", rule=POSITIVE,
                   note="At least the ratio ``Omega^2 b / g`` that rolling needs.")
    gravity: float = GRAVITY(9.81)

    sweepable = ("tilt", "circle", "mu")

    def __post_init__(self):
        super().__post_init__()
        low = 5.0 / 6.0 * self.radius * math.cos(self.tilt)
        if self.circle <= low:
            raise InputError(f"`circle` must be > (5/6) radius cos(tilt) = {low!r} m (no steady "
                             f"rolling at a smaller circle), got {self.circle!r}")
        need = _friction_ratio(self)
        if self.mu < need:
            raise InputError(f"`mu` must be >= {need!r}, the friction over the weight that "
                             f"rolling on this circle needs, got {self.mu!r}")


def _rates(p):
    # (Omega, b, omega_3) in SI: the module docstring's relation for the thin disk
    a, th, g = p.radius, p.tilt, p.gravity
    b = p.circle - a * math.cos(th)
    W = math.sqrt(4.0 * g * math.cos(th) / (math.sin(th) * (6.0 * b + a * math.cos(th))))
    return W, b, -W * b / a


def _friction_ratio(p):
    W, b, _ = _rates(p)
    return W * W * b / p.gravity


def steady_motion(params=None, **overrides):
    """The steady motion's rates: ``{"precession", "spin", "centre_radius", "speed",
    "friction_ratio"}`` (SI: rad/s, rad/s about the axis, m, m/s, 1).

    Examples
    --------
    >>> s = steady_motion(circle=0.05 * math.cos(1.2))     # the centre at rest: Euler's disk
    >>> round(s["precession"] ** 2 * 0.05 * math.sin(1.2) / (4 * 9.81), 12), s["centre_radius"]
    (1.0, 0.0)
    """
    p = params_with(RollingDiskParams, params, overrides)
    W, b, w3 = _rates(p)
    return {"precession": W, "spin": w3, "centre_radius": b, "speed": W * b,
            "friction_ratio": W * W * b / p.gravity}


def _start(p):
    # (centre, quaternion, centre velocity, body-frame angular velocity) at t = 0, SI
    W, b, w3 = _rates(p)
    th, a = p.tilt, p.radius
    orient = quat_exp(np.array([0.0, 0.5 * th, 0.0]))
    R0 = rotation_matrix(orient)
    n = R0[:, 2]
    omega = W * np.array([0.0, 0.0, 1.0]) + (w3 - W * math.cos(th)) * n
    return (np.array([b, 0.0, a * math.sin(th)]), orient, np.array([0.0, W * b, 0.0]),
            R0.T @ omega)


def rolling_disk_exact(params, t):
    """``(centre, quaternion)`` of the steady motion at times ``t`` [s]: shapes (k, 3), (k, 4).

    Examples
    --------
    >>> p = RollingDiskParams()
    >>> T = 2 * math.pi / steady_motion(p)["precession"]
    >>> x, quat = rolling_disk_exact(p, [0.0, T])
    >>> bool(np.allclose(x[0], x[1], atol=1e-15)), round(float(tilt_and_heading(
    ...     np.hstack([x, quat]))[0][1]), 12)
    (True, 1.2)
    """
    p = as_params(RollingDiskParams, params)
    tt = np.atleast_1d(np.asarray(t, dtype=float))
    W, b, w3 = _rates(p)
    _, orient, _, _ = _start(p)
    psi = w3 - W * math.cos(p.tilt)
    x = np.column_stack([b * np.cos(W * tt), b * np.sin(W * tt),
                         np.full(tt.size, p.radius * math.sin(p.tilt))])
    quat = np.array([quat_multiply(quat_multiply(quat_exp(np.array([0.0, 0.0, 0.5 * W * s])),
                                                 orient),
                                   quat_exp(np.array([0.0, 0.0, 0.5 * psi * s]))) for s in tt])
    return x, quat


def tilt_and_heading(q):
    """``(tilt, heading)`` of each state (rows of ``q``): the disk's plane from the horizontal
    [rad], and the precession angle of its axis' horizontal part, unwrapped [rad].

    Examples
    --------
    >>> th, psi = tilt_and_heading(rolling_disk().initial_state()[0][None, :])
    >>> round(float(th[0]), 12), float(psi[0])
    (1.2, 0.0)
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    axes = np.array([rotation_matrix(r[3:7] / np.linalg.norm(r[3:7]), check=False)[:, 2]
                     for r in q])
    tilt = np.arctan2(np.hypot(axes[:, 0], axes[:, 1]), axes[:, 2])
    return tilt, np.unwrap(np.arctan2(axes[:, 1], axes[:, 0]))


def rolling_disk(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the disk, started on its steady motion.

    Its window is a quarter of the precession period: Moreau–Jean at ``theta =
    1`` damps the spin as implicit Euler does, the tilt sinks and the disk
    precesses faster (at 1000 steps the precession angle came out 26 % too
    large over a whole period, 1.3 % over a quarter).

    Examples
    --------
    >>> sc = rolling_disk()
    >>> q0, v0 = sc.initial_state()
    >>> WN, _, WT, _ = sc.contact_jacobians(q0, 0.0)
    >>> abs(float(sc.gaps(q0, 0.0)[0])) < 1e-15, float(np.max(np.abs(WT @ v0))) < 1e-14
    (True, True)
    """
    p = params_with(RollingDiskParams, params, overrides)
    a, m = p.radius, p.mass
    model = SpaceModel(gravity=(0.0, 0.0, -p.gravity), length=a, mass=m)
    floor = model.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    x0, orient, xd0, w0 = _start(p)
    disk = model.add_body(m, [0.25 * m * a * a, 0.25 * m * a * a, 0.5 * m * a * a], position=x0,
                          orientation=orient, velocity=xd0, angular_velocity=w0, name="disk")
    model.add_contact(disk, Disk(a), floor, mu=p.mu)
    quarter = 0.5 * math.pi / _rates(p)[0] / model.time
    sc = model.build("rolling-disk", default_window=quarter)
    sc.params = p
    return sc


rolling_disk.Params = RollingDiskParams


class RollingDiskCase(ClosedFormPath, SpatialCase):
    """The disk over a quarter precession period: its axis' precession angle against ``Omega t``."""

    mj_tolerance = 2e-2
    headline_name = "precession angle"

    scene_factory = staticmethod(rolling_disk)

    def __init__(self, **params):
        super().__init__(**params)
        self.window = self.scene.default_window

    def coordinate(self, q):
        return tilt_and_heading(q)[1]

    def path(self, tau):
        return steady_motion(self.p)["precession"] * self.scene.time * tau

    def headline_of_run(self, res):
        # the heading is unwrapped along the whole run
        return float(tilt_and_heading(res.q)[1][-1])


register_scene(SceneEntry(
    name="rolling-disk",
    factory=rolling_disk,
    description=("thin disk rolling without slipping in steady precession on a plane: "
                 "Omega^2 = 4 g cot(theta) / (6 b + a cos(theta)) (Routh art. 244)"),
    case=RollingDiskCase,
))
