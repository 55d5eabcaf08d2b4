r"""A chain of spheres in space, struck at one end: the simultaneous impact between bodies.

``N`` equal spheres (mass ``m``, radius ``r``, ``J = (2/5) m r^2``) float
in space without gravity on the world's ``x`` axis, ``1 .. N-1`` at rest
and touching their neighbours; sphere 0, the striker (mass
``striker_mass``), approaches sphere 1 along the axis at ``striker_speed``
from the gap ``striker_gap``. Neighbours touch through sphere–sphere
contacts (:meth:`moreau.model.space.SpaceModel.add_pair_contact`), each with
Newton's restitution ``e`` and Coulomb's ``mu``: the spatial twin of the
planar :mod:`moreau.scenes.ball_chain`, its contacts between two free
bodies of six velocities each.

The reference (the model's exact answer)
----------------------------------------
When the striker arrives every contact of the chain is closed at once, and
Newton's law acts at all of them simultaneously: with ``P`` the normal
impulses, ``v+ = v- + M^-1 WN^T P`` and ``0 <= WN v+ + e min(WN v-, 0)
_|_ P >= 0``, one LCP over the chain (:func:`moreau.scenes.ball_chain.simultaneous_impact`,
the same problem on the line of centres). The impact is central: every
contact's tangential relative velocity is zero before it and stays zero
with zero friction impulse, whatever ``mu``, and the spheres do not turn.

For equal masses and ``e = 1`` the LCP has a closed form. Let the striker
arrive at ``V``. Guess every contact pressed (``P_i > 0``): the law gives
``U+_1 = V`` between the striker and sphere 1 and ``U+_i = 0`` further on,
so spheres ``1 .. N-1`` leave as a block at ``u`` and the striker at ``u -
V``; momentum, ``m V = m (u - V) + (N - 1) m u``, gives

.. math::

    u = \frac{2V}{N}, \qquad v_0^+ = \frac{(2 - N) V}{N},

and the guess holds: the impulse at contact ``i`` (spheres ``i - 1`` and
``i``) is the momentum given to spheres ``i .. N-1``, ``(N - i) m u > 0``.
(``N = 2`` is the elastic exchange, ``N = 3`` the striker's ``-V/3`` and
the block's ``2V/3`` of the planar chain.) Moreau–Jean solves this very LCP
at the step where the striker's contact closes (the others, at gap zero and
at rest, are active with it), so its velocities after the impact are the
block result to rounding; its positions carry the impact's time to within
the step (first order).

Scales: lengths in ``r``, time in ``r / V``, masses in ``m`` (the striker
speed is 1 inside). Coordinates: each sphere's centre (3) and unit
quaternion (4); velocities: the centre's (3) and the body-frame angular
velocity (3) (:class:`moreau.model.space.SpaceScene`).

A resting pyramid (:func:`sphere_pyramid`, not registered: it stays at rest)
-----------------------------------------------------------------------------
Three equal spheres (mass ``m``, radius ``r``) lie on a rough floor at the
corners of an equilateral triangle, their centres ``a`` from its centre and
apart from each other by ``spread`` times ``2r`` (``spread > 1``: they do
not touch each other); a fourth equal sphere rests on them. Let ``e_i`` be
the horizontal unit vector from the triangle's centre to bottom sphere
``i``; the line from its centre to the top one's makes the angle ``beta``
with the vertical, ``sin(beta) = a / (2r) = spread / sqrt(3)``, its unit
vector ``n_i = -sin(beta) e_i + cos(beta) e_z`` and the tangent in the
same vertical plane ``t_i = cos(beta) e_i + sin(beta) e_z``. By the
symmetry the top sphere takes ``N1 n_i + F1 t_i`` from bottom sphere ``i``
and bottom sphere ``i`` takes ``N0 e_z + f0 e_i`` from the floor. Then,
with ``k_i = e_z x e_i = n_i x t_i``:

* the top sphere, vertically: ``3 (N1 cos(beta) + F1 sin(beta)) = m g``;
  its friction torques ``-r F1 k_i`` add to zero over the three;
* bottom sphere ``i``, vertically: ``N0 = m g + N1 cos(beta) + F1
  sin(beta)``; along ``e_i``: ``N1 sin(beta) - F1 cos(beta) + f0 = 0``;
  about its centre (the torques of ``-F1 t_i`` at ``r n_i`` and of ``f0
  e_i`` at ``-r e_z``): ``-r (F1 + f0) k_i = 0``.

So ``f0 = -F1`` (the floor holds the bottom spheres inwards),
``N1 sin(beta) = F1 (1 + cos(beta))``, ``F1 = N1 tan(beta / 2)``, and as
``cos(beta) + sin(beta) tan(beta / 2) = 1``,

.. math::

    N_1 = \frac{m g}{3}, \quad F_1 = \frac{m g}{3} \tan\frac{\beta}{2}, \quad
    N_0 = \frac{4 m g}{3}, \quad |f_0| = \frac{m g}{3} \tan\frac{\beta}{2} :

the pyramid holds where ``mu >= tan(beta / 2)`` between the spheres and
``mu >= tan(beta / 2) / 4`` on the floor (derived here from the equations
of equilibrium of the four rigid spheres alone). The forces are determinate: the
18 rows of the six sticking contacts have rank 18 on the 24 velocities (the
free motions, each bottom sphere turning about the line through its two
contact points, are the gravity-free ones), so Moreau–Jean's step from rest
gives these impulses over ``h`` to rounding on the exact cone, and on a
polyhedral cone of ``d`` directions where ``mu cos(pi / d)`` still covers
``tan(beta / 2)`` (there Lemke's pivots on the degenerate resting problem
are dear: seconds a step).
"""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..analysis.cases import SpatialCase
from ..errors import InputError
from ..model.params import GRAVITY, MASS, MU, RADIUS, Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with
from ..model.space import SpaceModel, Sphere
from .ball_chain import STRIKER_GAP, ChainImpactCase, ChainParams

__all__ = ["BallChain3DParams", "ball_chain_3d", "block_result", "MAX_BALLS_3D",
           "PyramidParams", "sphere_pyramid", "pyramid_forces"]

#: the longest chain the scene takes (its step is the Python one, a dense cone problem)
MAX_BALLS_3D = 50


@dataclass(frozen=True)
class BallChain3DParams(ChainParams):
    """SI parameters of the chain of spheres in space: those of
    :class:`~moreau.scenes.ball_chain.ChainParams` (up to 50 spheres), friction and the
    striker's gap."""

    max_balls: ClassVar[int] = MAX_BALLS_3D

    mu: float = MU(0.0, "Coulomb friction at every contact",
                   note="A central impact calls on none.")
    striker_gap: float = STRIKER_GAP(0.011, note="The default, 1.1 radii, puts the impact at "
                                                 "``t* = 1.1 r / V``, off the usual grids.")


def ball_chain_3d(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the chain of spheres.

    ``scene.impact_time`` is the striker's arrival (scene units),
    ``scene.masses`` the spheres' masses (scene units).

    Examples
    --------
    >>> sc = ball_chain_3d(n_balls=3)
    >>> q0, v0 = sc.initial_state()
    >>> sc.ncontacts, sc.gaps(q0, 0.0).round(12).tolist(), round(sc.impact_time, 12)
    (2, [1.1, 0.0], 1.1)
    """
    p = params_with(BallChain3DParams, params, overrides)
    r, n = p.radius, p.n_balls
    m = SpaceModel(length=r, mass=p.mass, time=r / p.striker_speed)
    J = 0.4 * r * r
    bodies = []
    for i in range(n):
        mass = p.striker_mass if i == 0 else p.mass
        x = 2.0 * r * (i - 1) - (p.striker_gap if i == 0 else 0.0)
        bodies.append(m.add_body(mass, [J * mass] * 3, position=(x, 0.0, 0.0),
                                 velocity=(p.striker_speed if i == 0 else 0.0, 0.0, 0.0),
                                 name="striker" if i == 0 else f"sphere {i}"))
    for i in range(n - 1):
        m.add_pair_contact(bodies[i], Sphere(r), bodies[i + 1], Sphere(r), mu=p.mu,
                           restitution=p.restitution)
    sc = m.build("ball-chain-3d", default_window=p.striker_gap / r + 2.0)
    sc.params = p
    sc.impact_time = p.striker_gap / r
    return sc


ball_chain_3d.Params = BallChain3DParams


def block_result(n_balls, speed=1.0):
    """The spheres' speeds after the striker's impact, equal masses and ``e = 1``: the
    module docstring's closed form, ``(2 - N) V / N`` for the striker, ``2 V / N`` for the rest.

    Examples
    --------
    >>> block_result(3).round(12).tolist()
    [-0.333333333333, 0.666666666667, 0.666666666667]
    """
    n = int(n_balls)
    if n < 2:
        raise InputError(f"`n_balls` must be >= 2, got {n_balls!r}")
    out = np.full(n, 2.0 * speed / n)
    out[0] = (2.0 - n) * speed / n
    return out


@dataclass(frozen=True)
class PyramidParams(Declared):
    """SI parameters of the resting pyramid of four spheres (the module docstring)."""

    mass: float = MASS(0.2, "Mass of each sphere")
    radius: float = RADIUS(0.05, "Radius of each sphere")
    spread: float = param(1.2, "", doc="The bottom spheres' distance between centres over "
                                       "``2 radius``",
                          note="In ``(1, sqrt(3))``: above 1 they do not touch, below "
                               "``sqrt(3)`` the top sphere rests above them.")
    mu: float = MU(0.5, "Coulomb friction at every contact",
                   note="It holds for ``mu >= tan(beta / 2)``.")
    gravity: float = GRAVITY(9.81)

    def __post_init__(self):
        super().__post_init__()
        if not 1.0 < self.spread < math.sqrt(3.0):
            raise InputError(f"`spread` must be in (1, sqrt(3)) (the bottom spheres apart, the "
                             f"top one above them), got {self.spread!r}")


def pyramid_forces(params=None, **overrides):
    """The closed-form contact forces [N] of the pyramid at rest, and the least ``mu`` holding it.

    Returns ``{"beta", "normal_top", "friction_top", "normal_floor",
    "friction_floor", "mu_min"}``: each top contact's ``N1``, ``F1``, each
    floor contact's ``N0``, ``|f0|`` (the module docstring) and ``tan(beta / 2)``.

    Examples
    --------
    >>> f = pyramid_forces(mass=0.3, gravity=10.0)
    >>> round(f["normal_top"], 12), round(f["normal_floor"], 12)
    (1.0, 4.0)
    """
    p = params_with(PyramidParams, params, overrides)
    beta = math.asin(p.spread / math.sqrt(3.0))
    w = p.mass * p.gravity
    tb = math.tan(0.5 * beta)
    return {"beta": beta, "normal_top": w / 3.0, "friction_top": w / 3.0 * tb,
            "normal_floor": 4.0 * w / 3.0, "friction_floor": w / 3.0 * tb, "mu_min": tb}


#: the top sphere starts this fraction of the radius into its three supports, so that rounding
#: leaves every contact closed at the first step (the closed form's geometry moves by as much)
PYRAMID_SQUEEZE = 1e-13


def sphere_pyramid(params=None, **overrides):
    """The scene of the pyramid: contacts ``0..2`` the bottom spheres on the floor, ``3..5``
    the top sphere on bottom spheres ``0..2`` (normals from the bottom sphere to the top).

    Lengths in ``r``, time in ``sqrt(r / g)``, masses in ``m``.

    Examples
    --------
    >>> sc = sphere_pyramid()
    >>> sc.ncontacts, bool(np.all(sc.gaps(sc.initial_state()[0], 0.0) > -1e-12))
    (6, True)
    """
    p = params_with(PyramidParams, params, overrides)
    r, M = p.radius, p.mass
    beta = math.asin(p.spread / math.sqrt(3.0))
    a = 2.0 * r * math.sin(beta)
    m = SpaceModel(gravity=(0.0, 0.0, -p.gravity), length=r, mass=M)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    J = [0.4 * M * r * r] * 3
    bottom = [m.add_body(M, J, position=(a * math.cos(2.0 * math.pi * i / 3.0),
                                         a * math.sin(2.0 * math.pi * i / 3.0), r),
                         name=f"bottom {i}") for i in range(3)]
    top = m.add_body(M, J, position=(0.0, 0.0, r + 2.0 * r * math.cos(beta)
                                     - PYRAMID_SQUEEZE * r), name="top")
    for b in bottom:
        m.add_contact(b, Sphere(r), floor, mu=p.mu)
    for b in bottom:
        m.add_pair_contact(b, Sphere(r), top, Sphere(r), mu=p.mu)
    sc = m.build("sphere-pyramid", default_window=10.0)
    sc.params = p
    return sc


class BallChain3DCase(ChainImpactCase, SpatialCase):
    """The last sphere's position along the chain two time units after the impact.

    The reference is the simultaneous impact at ``t* = gap / r`` (scene
    units), every sphere at rest before it and at its speed after it
    (:class:`moreau.scenes.ball_chain.ChainImpactCase`).
    """

    headline_name = "position of the last sphere after the impacts"

    scene_factory = staticmethod(ball_chain_3d)

    def _last_start(self):
        q0, v0 = self.scene.initial_state()
        return q0[7 * (self.scene.nbodies - 1)], v0[0::6]

    def coordinate(self, q):
        return q[:, 7 * (self.scene.nbodies - 1)]

    def headline_of_run(self, res):
        return float(res.q[-1, 7 * (self.scene.nbodies - 1)])


register_scene(SceneEntry(
    name="ball-chain-3d",
    factory=ball_chain_3d,
    description=("a striker hits a resting chain of N spheres in space through sphere-sphere "
                 "contacts: the simultaneous impact's block result (closed form)"),
    case=BallChain3DCase,
))
