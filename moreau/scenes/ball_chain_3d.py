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
"""

from dataclasses import dataclass

import numpy as np

from .._validate import check_fields, nonnegative, positive, restitution
from ..analysis.cases import GRID, SpatialCase
from ..errors import InputError
from ..model.registry import SceneEntry, parameters_of, register_scene
from ..model.scene import params_with
from ..model.space import SpaceModel, Sphere
from .ball_chain import simultaneous_impact

__all__ = ["BallChain3DParams", "ball_chain_3d", "block_result", "MAX_BALLS_3D"]

#: the longest chain the scene takes (its step is the Python one, a dense cone problem)
MAX_BALLS_3D = 50


@dataclass(frozen=True)
class BallChain3DParams:
    """SI parameters of the chain of spheres in space.

    Attributes
    ----------
    n_balls : int
        Spheres ``N`` including the striker, a whole number in [2, 50].
    mass : float
        Mass of each sphere of the chain [kg], > 0.
    striker_mass : float
        Mass of the striker [kg], > 0.
    radius : float
        Radius of every sphere [m], > 0.
    striker_speed : float
        The striker's speed towards the chain [m/s], > 0.
    restitution : float
        Newton's restitution at every contact, in [0, 1].
    mu : float
        Coulomb friction at every contact, >= 0 (a central impact calls on
        none).
    striker_gap : float
        The striker's initial gap to the chain [m], >= 0; the default, 1.1
        radii, puts the impact at ``t* = 1.1 r / V``, off the usual grids.
    """

    n_balls: int = 4
    mass: float = 0.1
    striker_mass: float = 0.1
    radius: float = 0.01
    striker_speed: float = 1.0
    restitution: float = 1.0
    mu: float = 0.0
    striker_gap: float = 0.011

    def __post_init__(self):
        n = self.n_balls
        if isinstance(n, bool) or not (isinstance(n, (int, np.integer)) or (
                isinstance(n, float) and n.is_integer())) or not 2 <= int(n) <= MAX_BALLS_3D:
            raise InputError(f"`n_balls` must be a whole number in [2, {MAX_BALLS_3D}], "
                             f"got {n!r}")
        object.__setattr__(self, "n_balls", int(n))
        check_fields(self, positive, "mass", "striker_mass", "radius", "striker_speed")
        check_fields(self, restitution, "restitution")
        check_fields(self, nonnegative, "mu", "striker_gap")


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


class BallChain3DCase(SpatialCase):
    """The last sphere's position along the chain two time units after the impact.

    The reference is the simultaneous impact at ``t* = gap / r`` (scene
    units), every sphere at rest before it and at its speed after it
    (:func:`moreau.scenes.ball_chain.simultaneous_impact`).
    """

    headline_name = "position of the last sphere after the impacts"

    scene_factory = staticmethod(ball_chain_3d)

    def __init__(self, **params):
        super().__init__(**params)
        self.window = self.scene.impact_time + 2.0

    def _last(self, t):
        sc = self.scene
        q0, v0 = sc.initial_state()
        n = sc.nbodies
        after = simultaneous_impact(sc.masses, v0[0::6], self.p.restitution)
        return q0[7 * (n - 1)] + after[-1] * np.maximum(np.asarray(t, float) - sc.impact_time,
                                                        0.0)

    def coordinate(self, q):
        return q[:, 7 * (self.scene.nbodies - 1)]

    def reference(self, rtol):
        return float(self._last(self.window)), [(float(self.scene.impact_time), "0:S")]

    def reference_grid(self):
        return self._last(np.linspace(0.0, self.window, GRID + 1))

    def headline_of_run(self, res):
        return float(res.q[-1, 7 * (self.scene.nbodies - 1)])


register_scene(SceneEntry(
    name="ball-chain-3d",
    factory=ball_chain_3d,
    parameters=parameters_of(BallChain3DParams, {"n_balls": "", "mass": "kg",
                                                 "striker_mass": "kg", "radius": "m",
                                                 "striker_speed": "m/s", "restitution": "",
                                                 "mu": "", "striker_gap": "m"}),
    description=("a striker hits a resting chain of N spheres in space through sphere-sphere "
                 "contacts: the simultaneous impact's block result (closed form)"),
    case=BallChain3DCase,
    reference="exact",
    sweepable=("restitution", "striker_mass", "n_balls"),
    mj_tolerance=1e-3,
))
