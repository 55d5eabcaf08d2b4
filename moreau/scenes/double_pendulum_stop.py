r"""A double pendulum whose lower link's tip strikes a wall, built with two revolute joints.

The mechanism of issue 36's energy check: two uniform bars (lengths
``l1, l2``, masses ``m1, m2``, centroidal inertias ``m l^2 / 12``), the
upper one pinned to the ground at the origin, the lower one pinned to the
upper one's tip, under gravity ``g`` along ``-y``; a rigid wall, the
half-plane ``x >= wall``, stops the lower link's tip (a point), frictionless
and with Newton's restitution ``e``. With ``e = 1`` and no friction the
energy::

    E = sum_i (m_i |V_i|^2 / 2 + I_i w_i^2 / 2 + m_i g y_i)

is conserved by the motion through every impact (an elastic frictionless
impact keeps the kinetic energy: the impulse reverses the normal relative
velocity, and the potential is continuous). A double pendulum on a stop
is the classic test of impact schemes (e.g. Acary and Brogliato,
*Numerical Methods for Nonsmooth Dynamical Systems*, Springer 2008); the
parameters here are our own: ``l1 = l2 = 1 m``, ``m1 = m2 = 1 kg``,
``g = 9.81 m/s^2``, the wall at ``x = 0.8 m``, both links released at rest
horizontal to the left (``theta1 = theta2 = pi``), ``e = 1``. The lower
tip first reaches the wall at ``t = 0.76 s`` (2.39 in the scene's time) and strikes it
again and again.

Coordinates (the builder's): each link's ``x, y, theta`` of its centre,
its body ``x`` axis from its upper joint to its lower end; units ``l1``,
``m1`` and ``sqrt(l1 / g)``. The model (:func:`double_pendulum_stop_model`)::

    m = Model(gravity=(0.0, -g), length=l1, mass=m1)
    a = m.add_body(m1, m1 * l1**2 / 12, position=(l1 / 2 * cos(th1), l1 / 2 * sin(th1)), angle=th1)
    b = m.add_body(m2, m2 * l2**2 / 12, position=tip1 + (l2 / 2 * cos(th2), ...), angle=th2)
    m.add_revolute(m.ground, (0.0, 0.0), a, (-l1 / 2, 0.0))
    m.add_revolute(a, (l1 / 2, 0.0), b, (-l2 / 2, 0.0))
    wall = m.add_shape(m.ground, HalfPlane((wall, 0.0), (-1.0, 0.0)))
    m.add_contact(m.add_shape(b, Point((l2 / 2, 0.0))), wall, mu=mu, restitution=e)
"""

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.cases import GRID, ExactReference, FactoryCase
from ..errors import InputError
from ..model.planar import HalfPlane, Model, Point, Segment
from ..model.params import Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with

__all__ = ["DoublePendulumStopParams", "double_pendulum_stop_model", "double_pendulum_stop",
           "pendulum_energy"]


@dataclass(frozen=True)
class DoublePendulumStopParams(Declared):
    """SI parameters of the double pendulum against a wall (checked where the model is built)."""

    length1: float = param(1.0, "m", doc="Upper link's length")
    length2: float = param(1.0, "m", doc="Lower link's length")
    mass1: float = param(1.0, "kg", doc="Upper link's mass")
    mass2: float = param(1.0, "kg", doc="Lower link's mass")
    wall: float = param(0.8, "m", doc="The wall's abscissa: the half-plane x >= wall")
    restitution: float = param(1.0, doc="Newton restitution of the tip's impacts")
    mu: float = param(0.0, doc="Coulomb friction at the wall")
    theta1: float = param(math.pi, "rad", doc="Initial angle of the upper link's axis from +x "
                                              "(at rest)")
    theta2: float = param(math.pi, "rad", doc="Initial angle of the lower link's axis from +x "
                                              "(at rest)")
    gravity: float = param(9.81, "m/s^2", doc="Gravity, along -y")


def _checked(p):
    for name in ("length1", "length2", "mass1", "mass2", "gravity"):
        value = getattr(p, name)
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"`{name}` must be finite and > 0, got {value!r}")
    for name in ("wall", "theta1", "theta2"):
        if not math.isfinite(getattr(p, name)):
            raise InputError(f"`{name}` must be finite, got {getattr(p, name)!r}")
    tip = (p.length1 * math.cos(p.theta1) + p.length2 * math.cos(p.theta2))
    if not tip <= p.wall:
        raise InputError(f"`wall` ({p.wall!r}) must not be left of the lower tip's start "
                         f"x = {tip!r} m: the tip would start inside the wall")
    if not abs(p.wall) < p.length1 + p.length2:
        raise InputError(f"`wall` ({p.wall!r}) must be within the reach {p.length1 + p.length2!r}"
                         " m of the pendulum: it would never touch the wall")
    return p


def double_pendulum_stop_model(params=None, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the double pendulum against a wall (SI parameters of :class:`DoublePendulumStopParams`)."""
    p = _checked(params_with(DoublePendulumStopParams, params, overrides))
    l1, l2, t1, t2 = p.length1, p.length2, p.theta1, p.theta2
    u1 = np.array([math.cos(t1), math.sin(t1)])
    u2 = np.array([math.cos(t2), math.sin(t2)])
    m = Model(gravity=(0.0, -p.gravity), length=l1, mass=p.mass1)
    a = m.add_body(p.mass1, p.mass1 * l1 * l1 / 12.0, position=0.5 * l1 * u1, angle=t1,
                   name="upper")
    b = m.add_body(p.mass2, p.mass2 * l2 * l2 / 12.0, position=l1 * u1 + 0.5 * l2 * u2, angle=t2,
                   name="lower")
    m.add_revolute(m.ground, (0.0, 0.0), a, (-0.5 * l1, 0.0))
    m.add_revolute(a, (0.5 * l1, 0.0), b, (-0.5 * l2, 0.0))
    wall = m.add_shape(m.ground, HalfPlane((p.wall, 0.0), (-1.0, 0.0)))
    m.add_contact(m.add_shape(b, Point((0.5 * l2, 0.0))), wall, mu=p.mu,
                  restitution=p.restitution)
    # drawn only
    m.add_shape(a, Segment((-0.5 * l1, 0.0), (0.5 * l1, 0.0)))
    m.add_shape(b, Segment((-0.5 * l2, 0.0), (0.5 * l2, 0.0)))
    return m


def double_pendulum_stop(params=None, **overrides):
    """The double pendulum against a wall (a :class:`~moreau.model.planar.PlanarScene`: four joint rows, one contact).

    Examples
    --------
    >>> sc = double_pendulum_stop()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ndof, sc.n_joint_rows, sc.ncontacts, [round(float(g), 12) for g in sc.gaps(q0, 0.0)]
    (6, 4, 1, [2.8])
    """
    return double_pendulum_stop_model(params, **overrides).build(
        "double-pendulum-stop", default_window=10.0)


double_pendulum_stop.Params = DoublePendulumStopParams


def pendulum_energy(scene, q, v):
    """The energy of every sample (rows of ``q``, ``v``), in the scene's units.

    Kinetic ``v^T M v / 2`` and the potential of the constant gravity forces
    ``-f . q`` (``f = scene.forces``, gravity only).

    Examples
    --------
    >>> sc = double_pendulum_stop()
    >>> q0, v0 = sc.initial_state()
    >>> round(float(pendulum_energy(sc, q0[None], v0[None])[0]), 12)   # centres at y = 0, at rest
    0.0
    >>> hanging = np.array([0.0, -0.5, -np.pi / 2, 0.0, -1.5, -np.pi / 2])
    >>> float(pendulum_energy(sc, hanging[None], v0[None])[0])          # -(m g l/2 + m g 3l/2)
    -2.0
    """
    q = np.atleast_2d(q)
    v = np.atleast_2d(v)
    M = scene.mass(q[0])
    f = scene.forces(q[0], np.zeros_like(q[0]), 0.0)
    return 0.5 * np.einsum("ij,jk,ik->i", v, M, v) - q @ f


class DoublePendulumStopCase(ExactReference, FactoryCase):
    """The energy after the window against its initial value (conserved at ``e = 1``, ``mu = 0``).

    Energies are counted from the pendulum hanging at rest (both links
    straight down), so that the headline is the energy the motion has.
    Moreau–Jean with ``theta = 1`` loses energy at first order, its
    numerical dissipation (measured 3.2 % over the window at 1000 steps);
    with ``theta = 1/2`` the joint rows on the midpoint velocity keep it to
    rounding (:mod:`moreau.integrators.moreau_jean`, *Energy*).
    """

    mj_tolerance = 5e-2
    headline_name = "energy above the hanging rest at the end of the window (conserved)"
    #: the first strike (t = 2.4) and the swing back
    window = 3.0
    # the reference is an invariant, not a trajectory: no switching times to compare
    compares_switches = False

    scene_factory = staticmethod(double_pendulum_stop)

    def __init__(self, **params):
        super().__init__(**params)
        p = params_with(DoublePendulumStopParams, None, params)
        if p.restitution != 1.0 or p.mu != 0.0:
            raise InputError("the double pendulum's case compares energies: it needs "
                             "`restitution` = 1 and `mu` = 0 (energy is then conserved)")
        r = p.length2 / p.length1
        hang = np.array([0.0, -0.5, -0.5 * math.pi, 0.0, -1.0 - 0.5 * r, -0.5 * math.pi])
        self._rest = float(pendulum_energy(self.scene, hang[None], np.zeros((1, 6)))[0])

    def energy(self, q, v):
        """The energy above the hanging rest of every sample (scene units)."""
        return pendulum_energy(self.scene, q, v) - self._rest

    def initial_energy(self):
        """The energy of the start, above the hanging rest (scene units)."""
        q0, v0 = self.start()
        return float(self.energy(q0[None], v0[None])[0])

    def reference(self, rtol):
        return self.initial_energy(), []

    def reference_grid(self):
        return np.full(GRID + 1, self.initial_energy())

    def headline_of_run(self, res):
        return float(self.energy(res.q[-1:], res.v[-1:])[0])

    def _trajectory_error(self, res):
        # the energy's largest departure over every sample, relative to the initial energy
        e = self.energy(res.q, res.v)
        return float(np.max(np.abs(e - self.initial_energy())) / abs(self.initial_energy()))


register_scene(SceneEntry(
    name="double-pendulum-stop",
    factory=double_pendulum_stop,
    description=("a double pendulum built with two revolute joints whose lower tip strikes "
                 "a wall (moreau.model.planar), Moreau-Jean only: energy conserved at e = 1"),
    case=DoublePendulumStopCase,
))
