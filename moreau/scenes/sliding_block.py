"""A block sliding on a (possibly inclined) plane with Coulomb friction.

The validation scene for friction: a block launched along the plane slides
with constant deceleration, stops at ``t* = v0 / (mu g)`` after
``v0^2 / (2 mu g)`` on a level plane, and then sticks if ``tan(alpha) <= mu``.

Scales
------
Lengths in units of the reference length ``L = params.length``, time in
``T = sqrt(L / g)``, velocities in ``sqrt(g L)``, forces in the weight
``m g``. The dimensionless mass matrix is the identity and gravity has unit
size, so the dimensionless motion depends on ``mu`` and ``alpha`` only.

Coordinates: ``q = (x, y)`` with ``x`` along the plane, pointing downhill
(for ``alpha > 0``), and ``y`` the height above the plane, which is the gap.
The slip velocity is ``dx/dt``; positive slip means sliding downhill.
"""

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from numba import njit

from ..compiled import CompiledModel
from .._validate import finite_array, restitution
from ..errors import InputError
from ..model.params import GRAVITY, LENGTH, MASS, MU, RESTITUTION, Declared, open_interval, param
from ..model.drawing import contact, line, polygon
from ..model.compiled_scene import CompiledScene
from ..model.units import SIUnits
from ..model.scene import FromParams
from .._validate import finite_scalar
from ..analysis.cases import GRID, CompareCase, ExactReference
from ..model.registry import SceneEntry, register_scene
from ._block_on_line import block_contacts, block_mass

__all__ = ["SlidingBlockParams", "SlidingBlock"]

#: phases of the exact block motion: stopping time (``inf`` if it never
#: stops), whether it sticks after stopping, and the accelerations before and
#: after the stop
BlockMotion = namedtuple("BlockMotion", ["t_stop", "sticks", "a_before", "a_after"])


@dataclass(frozen=True)
class SlidingBlockParams(Declared):
    """SI parameters of the sliding block."""

    mass: float = MASS(1.0, "Mass of the block")
    mu: float = MU(0.3)
    incline: float = param(0.0, "rad", open_interval(-math.pi / 2, math.pi / 2, "-pi/2, pi/2",
                                                     "in the open interval (-pi/2, pi/2)"),
                           "Inclination alpha of the plane")
    gravity: float = GRAVITY(9.81)
    restitution: float = RESTITUTION(0.0, "Newton restitution of the contact",
                                     note="It matters only if the block is dropped onto the plane.")
    length: float = LENGTH(1.0)

    sweepable = ("mu", "incline", "mass")


class SlidingBlock(FromParams, SIUnits, CompiledScene):
    """A block on a plane inclined by ``alpha``, Coulomb friction ``mu``.

    {params}

    Attributes
    ----------
    alpha : float
        Inclination [rad].
    length, time, force : float
        The SI scales (m, s, N) of one dimensionless unit.

    Examples
    --------
    >>> block = SlidingBlock(mu=0.5)
    >>> block.stopping_time([2.0, 0.0]), block.stopping_distance([2.0, 0.0])
    (4.0, 4.0)
    >>> round(float(block.to_si(t=4.0).t), 4)   # seconds: T = sqrt(1 m / 9.81 m/s^2)
    1.2771
    """

    ndof = 2
    name = "sliding-block"
    #: the default launch stops at t* = 1 / mu = 3.33
    default_window = 5.0

    Params = SlidingBlockParams

    def _setup(self, p):
        self.alpha = p.incline
        self.mu = np.array([p.mu])
        self.restitution = np.array([p.restitution])
        self._scale_by_weight(p.length, p.mass, p.gravity)

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def initial_state(self):
        """On the plane at the origin, launched along it at unit speed."""
        return np.zeros(2), np.array([1.0, 0.0])

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        par = [math.sin(self.alpha), math.cos(self.alpha)]
        return CompiledModel(block_mass, _forces, block_contacts, None, par, 2, 1, True, False)

    def shapes(self, q, t=0.0):
        """The plane (inclined by ``alpha``), the block (a point mass, drawn 0.2 length units wide) and its contact."""
        ca, sa = math.cos(self.alpha), math.sin(self.alpha)
        ex, ey = np.array([ca, -sa]), np.array([sa, ca])   # along and across the plane
        base = float(q[0]) * ex + float(q[1]) * ey
        w = 0.1 * self.length
        corners = [base - w * ex, base + w * ex, base + w * ex + 2 * w * ey,
                   base - w * ex + 2 * w * ey]
        return [line([base - 10 * w * ex, base + 10 * w * ex], role="ground"), polygon(corners),
                contact(0, base, ey, ex)]

    # -- exact solution -------------------------------------------------------
    @property
    def sticks(self):
        """True when a block at rest stays at rest: ``|tan(alpha)| <= mu``."""
        return bool(abs(math.sin(self.alpha)) <= self.mu[0] * math.cos(self.alpha))

    def motion(self, v0):
        """Phases of the exact motion from a block on the plane with velocity ``v0``.

        Parameters
        ----------
        v0 : array_like, shape (2,)
            Initial velocity; ``v0[1]`` must be 0 (the block stays on the plane).

        Returns
        -------
        BlockMotion
            ``t_stop``: first time the block is at rest (0 if ``v0[0] = 0``,
            ``inf`` if it never stops); ``sticks``: whether it stays at rest
            afterwards; ``a_before``, ``a_after``: the constant accelerations
            along the plane before and after ``t_stop``.
        """
        u0 = self._launch_speed(v0)
        s, c, mu = math.sin(self.alpha), math.cos(self.alpha), float(self.mu[0])
        a_after = 0.0 if self.sticks else s - mu * c * math.copysign(1.0, s)
        if u0 == 0.0:
            return BlockMotion(0.0, self.sticks, a_after, a_after)
        a1 = s - mu * c * math.copysign(1.0, u0)
        if a1 * u0 >= 0.0:
            return BlockMotion(math.inf, False, a1, a1)
        return BlockMotion(-u0 / a1, self.sticks, a1, a_after)

    def stopping_time(self, v0):
        """Time until the block launched with ``v0`` first comes to rest.

        ``v0[0] / (mu cos(alpha) - sin(alpha))`` downhill,
        ``|v0[0]| / (mu cos(alpha) + sin(alpha))`` uphill; ``inf`` if the
        block never stops. On a level plane this is ``v0 / mu`` (SI:
        ``v0 / (mu g)``).
        """
        return self.motion(v0).t_stop

    def stopping_distance(self, v0):
        """Signed displacement along the plane until the block first stops.

        ``v0[0] * t* / 2``, i.e. ``v0^2 / (2 mu)`` on a level plane (SI:
        ``v0^2 / (2 mu g)``); ``inf`` (with the sign of ``v0``) if it never stops.
        """
        u0 = self._launch_speed(v0)
        t_stop = self.motion(v0).t_stop
        if math.isinf(t_stop):
            return math.copysign(math.inf, u0)
        return 0.5 * u0 * t_stop

    def exact_solution(self, t, q0, v0):
        """Exact state at times ``t >= 0`` from ``(q0, v0)`` at ``t = 0``.

        The block must start on the plane (``q0[1] = 0``, ``v0[1] = 0``); it
        stays there because the normal force ``cos(alpha)`` is positive.

        Returns
        -------
        q, v : ndarray, shape (len(t), 2)
        """
        x0, y0 = finite_array("q0", q0, shape=(2,))
        if y0 != 0.0:
            raise InputError(f"`q0` must put the block on the plane (q0[1] == 0), got {y0!r}")
        u0 = self._launch_speed(v0)
        tt = finite_array("t", t)
        scalar = tt.ndim == 0
        tt = np.atleast_1d(tt).astype(float)
        if np.any(tt < 0.0):
            raise InputError("`t` must be >= 0 (the exact solution starts at t = 0)")
        m = self.motion(v0)
        ts = min(m.t_stop, np.inf)
        t1 = np.minimum(tt, ts)
        x = x0 + u0 * t1 + 0.5 * m.a_before * t1 ** 2
        u = u0 + m.a_before * t1
        if math.isfinite(ts):
            u = np.where(tt >= ts, 0.0, u)
            t2 = np.maximum(tt - ts, 0.0)
            x = x + 0.5 * m.a_after * t2 ** 2
            u = u + m.a_after * t2
        q = np.stack([x, np.zeros_like(x)], axis=-1)
        v = np.stack([u, np.zeros_like(u)], axis=-1)
        if scalar:
            return q[0], v[0]
        return q, v

    def contact_forces(self, t, v0):
        """Exact dimensionless contact forces ``(lambdaN, lambdaT)`` at times ``t``.

        ``lambdaN = cos(alpha)``; ``lambdaT = -mu cos(alpha) sign(dx/dt)`` in
        slip and ``-sin(alpha)`` in stick.
        """
        tt = np.atleast_1d(finite_array("t", t)).astype(float)
        m = self.motion(v0)
        u0 = self._launch_speed(v0)
        s, c, mu = math.sin(self.alpha), math.cos(self.alpha), float(self.mu[0])
        lamN = np.full_like(tt, c)
        before = tt < m.t_stop
        lamT = np.where(before, -mu * c * math.copysign(1.0, u0) if u0 else 0.0, 0.0)
        after_force = -s if m.sticks else -mu * c * math.copysign(1.0, s)
        lamT = np.where(before, lamT, after_force)
        return lamN, lamT

    def _launch_speed(self, v0):
        u0, w0 = finite_array("v0", v0, shape=(2,))
        if w0 != 0.0:
            raise InputError(f"`v0` must be tangent to the plane (v0[1] == 0), got {w0!r}")
        return float(u0)


class SlidingBlockCase(ExactReference, CompareCase):
    """The block launched at ``speed`` [m/s] until it sticks: stopping distance against the exact solution."""

    headline_name = "stopping distance"

    def __init__(self, speed=2.0, mu=0.5, **params):
        self.scene = SlidingBlock(mu=mu, **params)
        self.v0 = np.array([finite_scalar("speed", speed), 0.0])
        self._params = dict(mu=mu, speed=speed, **params)
        self.window = 1.5 * self.scene.stopping_time(self.v0)

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return np.zeros(2), self.v0.copy()

    def reference(self, rtol):
        return (float(self.scene.stopping_distance(self.v0)),
                [(float(self.scene.stopping_time(self.v0)), "S")])

    def reference_grid(self):
        q, _ = self.scene.exact_solution(np.linspace(0.0, self.window, GRID + 1), *self.start())
        return q[:, 0]


# -- compiled model (moreau.compiled); par: sin(alpha), cos(alpha) -------------------------

@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    D[0, 0] = par[0]
    D[1, 0] = -par[1]



register_scene(SceneEntry(
    name="sliding-block",
    factory=SlidingBlock,
    description="block sliding to rest on a plane (exact solution)",
    case=SlidingBlockCase,
))
