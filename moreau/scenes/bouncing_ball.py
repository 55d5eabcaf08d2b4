"""A ball bouncing on a rigid floor under gravity, with Newton restitution.

The validation scene for impacts: its exact solution is a geometric series of
flights, and for ``e < 1`` the impact times accumulate at a finite time
``t_inf`` (Zeno behaviour) after which the ball rests on the floor.

Scales
------
Lengths are measured in units of the reference length ``L = params.length``,
time in ``T = sqrt(L / g)``, velocities in ``sqrt(g L)`` and forces in the
weight ``m g``. In these units gravity is 1 and the mass matrix is the
identity, so every dimensionless result depends on ``e`` and the radius
``r / L`` only.

Coordinates: ``q = (y,)``, the height of the ball's centre above the floor;
the gap is ``y - r``.
"""

import math
from collections import namedtuple
from dataclasses import dataclass, fields, replace

import numpy as np

from numba import njit

from ..compiled import CompiledModel
from .._validate import finite_array, positive
from ..errors import InputError
from ..model.params import GRAVITY, LENGTH, MASS, RADIUS, RESTITUTION, Declared
from ..model.drawing import circle, contact, line
from ..model.units import SIUnits, SIValues
from ..model.compiled_scene import CompiledScene
from ..model.scene import FromParams
from ..analysis.cases import GRID, CompareCase, ExactReference
from ..model.registry import SceneEntry, register_scene

__all__ = ["BouncingBallParams", "BouncingBall", "BallImpacts", "SIValues"]

#: the impacts of an exact bouncing-ball solution: times and the velocity
#: of the ball just before and just after each impact (all dimensionless)
BallImpacts = namedtuple("BallImpacts", ["t", "v_before", "v_after"])


@dataclass(frozen=True)
class BouncingBallParams(Declared):
    """SI parameters of the bouncing ball."""

    mass: float = MASS(0.1, "Mass of the ball")
    radius: float = RADIUS(0.05, "Radius of the ball")
    gravity: float = GRAVITY(9.81)
    restitution: float = RESTITUTION(0.5)
    length: float = LENGTH(1.0)

    sweepable = ("restitution", "radius", "gravity", "mass")


class BouncingBall(FromParams, SIUnits, CompiledScene):
    """A ball of radius ``r`` falling on the floor ``y = 0``, restitution ``e``.

    {params}

    Attributes
    ----------
    e : float
        Restitution coefficient.
    r : float
        Dimensionless radius ``radius / length``.
    length, time, force : float
        The SI scales (m, s, N) of one dimensionless unit.

    Examples
    --------
    >>> ball = BouncingBall(restitution=0.5, radius=0.1, length=1.0)
    >>> q0, v0 = [0.6], [0.0]             # centre 0.5 above contact, at rest
    >>> float(ball.impacts(q0, v0, 2).t[1])   # t1 = 1, t2 = t1 + 2 e V
    2.0
    >>> ball.zeno_time(q0, v0)
    3.0
    """

    ndof = 1
    name = "bouncing-ball"
    #: the floor is a half-plane: a centre below it is a ball that went through
    valid_region = "y > 0 (the ball's centre above the floor)"
    #: from the default start: the first impacts and, for e = 0.5, the ball at rest (t_inf = 4.24)
    default_window = 4.0

    Params = BouncingBallParams

    def _setup(self, p):
        self.e = p.restitution
        self.r = p.radius / p.length
        self._scale_by_weight(p.length, p.mass, p.gravity)
        self.mu = np.zeros(1)
        self.restitution = np.array([self.e])

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def inside_valid_region(self, t, q, v):
        return np.asarray(q)[:, 0] > 0.0

    def initial_state(self):
        """The ball at rest with its lowest point one length unit above the floor."""
        return np.array([self.r + 1.0]), np.zeros(1)

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        return CompiledModel(_mass, _forces, _contacts, None, [self.r], 1, 1, True, False)

    def shapes(self, q, t=0.0):
        """The floor, the ball (centre height ``q[0]`` [m]) and its contact point."""
        y, r = float(q[0]), self.params.radius
        return [line([(-3 * r, 0.0), (3 * r, 0.0)], role="ground"), circle((0.0, y), r),
                contact(0, (0.0, y - r), (0.0, 1.0))]

    # -- exact solution -------------------------------------------------------
    def _initial(self, q0, v0):
        y0 = float(finite_array("q0", q0, shape=(1,))[0])
        u0 = float(finite_array("v0", v0, shape=(1,))[0])
        if y0 < self.r:
            raise InputError(f"`q0` must not penetrate the floor: need q0[0] >= r = {self.r!r}, "
                             f"got {y0!r}")
        return y0, u0

    def _first_impact(self, y0, u0):
        """First impact time ``t1`` and impact speed ``V`` (both >= 0)."""
        V = math.sqrt(u0 * u0 + 2.0 * (y0 - self.r))
        # u0 + V loses every digit when the ball is thrown down hard from
        # close to the floor; the equivalent product form does not.
        if u0 >= 0.0:
            t1 = u0 + V
        else:
            t1 = 2.0 * (y0 - self.r) / (V - u0)
        return t1, V

    def zeno_time(self, q0, v0):
        """Accumulation time of the impacts, started from ``(q0, v0)`` at ``t = 0``.

        ``t_inf = t1 + 2 e V / (1 - e)`` with ``t1`` the first impact time and
        ``V`` the first impact speed; ``inf`` for ``e = 1``; ``t1`` for
        ``e = 0`` (the ball stops at the first impact); 0 for a ball already
        resting on the floor.
        """
        y0, u0 = self._initial(q0, v0)
        t1, V = self._first_impact(y0, u0)
        if V == 0.0:
            return 0.0
        if self.e == 1.0:
            return math.inf
        return t1 + 2.0 * V * self.e / (1.0 - self.e)

    def impacts(self, q0, v0, n):
        """The first ``n`` impacts of the exact solution.

        The ``k``-th impact (``k = 1, 2, ...``) happens at
        ``t_k = t1 + 2 V e (1 - e^(k-1)) / (1 - e)`` with velocity
        ``-e^(k-1) V`` before and ``e^k V`` after it. Fewer than ``n`` are
        returned when the series ends (``e = 0``: one impact; a resting ball: none).

        Returns
        -------
        BallImpacts
            Arrays ``t``, ``v_before``, ``v_after``.
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
            raise InputError(f"`n` must be an integer >= 0, got {n!r}")
        y0, u0 = self._initial(q0, v0)
        t1, V = self._first_impact(y0, u0)
        if V == 0.0:
            n = 0
        elif self.e == 0.0:
            n = min(n, 1)
        k = np.arange(n, dtype=float)
        ek = self.e ** k
        return BallImpacts(t=self._flight_start(t1, V, k), v_before=-V * ek,
                           v_after=self.e * V * ek)

    def _flight_start(self, t1, V, k):
        """Time of impact ``k + 1`` (``k = 0, 1, ...``), vectorized over ``k``."""
        e = self.e
        if e == 1.0:
            return t1 + 2.0 * V * k
        if e == 0.0:
            return np.full_like(k, t1)
        # expm1 keeps 1 - e^k accurate when e is close to 1
        return t1 + 2.0 * V * e * -np.expm1(k * math.log(e)) / (1.0 - e)

    def exact_solution(self, t, q0, v0):
        """Exact state at times ``t >= 0`` starting from ``(q0, v0)`` at ``t = 0``.

        Parameters
        ----------
        t : array_like
            Dimensionless times, >= 0.
        q0, v0 : array_like, shape (1,)

        Returns
        -------
        q, v : ndarray, shape (len(t), 1)
            Height of the centre and velocity; at an impact time the
            post-impact velocity is returned.
        """
        y0, u0 = self._initial(q0, v0)
        tt = finite_array("t", t)
        scalar = tt.ndim == 0
        tt = np.atleast_1d(tt).astype(float)
        if np.any(tt < 0.0):
            raise InputError("`t` must be >= 0 (the exact solution starts at t = 0)")
        t1, V = self._first_impact(y0, u0)
        e = self.e
        y = np.empty_like(tt)
        v = np.empty_like(tt)
        before = tt < t1
        y[before] = y0 + u0 * tt[before] - 0.5 * tt[before] ** 2
        v[before] = u0 - tt[before]
        after = ~before
        if V == 0.0 or e == 0.0:
            y[after], v[after] = self.r, 0.0
        else:
            ta = tt[after]
            t_inf = math.inf if e == 1.0 else t1 + 2.0 * V * e / (1.0 - e)
            if e == 1.0:
                k = np.floor((ta - t1) / (2.0 * V))
            else:
                s = np.clip((ta - t1) * (1.0 - e) / (2.0 * V * e), 0.0, 1.0)
                with np.errstate(divide="ignore"):
                    k = np.floor(np.log1p(-s) / math.log(e))
                k = np.where(np.isfinite(k), k, 0.0)
            k = np.maximum(k, 0.0)

            def start(kk):
                return self._flight_start(t1, V, kk)

            # the logarithm can misplace a time lying within rounding of an
            # impact; one correction each way puts it in the right flight
            k = np.where(start(k) > ta, k - 1.0, k)
            k = np.where(start(k + 1.0) <= ta, k + 1.0, k)
            k = np.maximum(k, 0.0)
            tk = start(k)
            uk = V * e ** (k + 1.0)
            dt = ta - tk
            ya = self.r + uk * dt - 0.5 * dt * dt
            va = uk - dt
            rest = ta >= t_inf
            ya[rest], va[rest] = self.r, 0.0
            y[after], v[after] = ya, va
        if scalar:
            return y.reshape(1, 1)[0], v.reshape(1, 1)[0]
        return y[:, None], v[:, None]


class BouncingBallCase(ExactReference, CompareCase):
    """The ball dropped from rest at ``height`` [m] (centre), window 2.6: three impacts against the exact solution."""

    mj_tolerance = 5e-2
    window = 2.6
    headline_name = "height at the end of the window"

    def __init__(self, height=0.6, restitution=0.5, radius=0.1, **params):
        self.scene = BouncingBall(restitution=restitution, radius=radius, **params)
        self._params = dict(restitution=restitution, radius=radius, height=height, **params)
        self.q0 = np.array([positive("height", height)])

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.q0.copy(), np.zeros(1)

    def reference(self, rtol):
        q0, v0 = self.start()
        q, _ = self.scene.exact_solution(np.array([self.window]), q0, v0)
        imp = self.scene.impacts(q0, v0, 64).t
        imp = [float(t) for t in imp if t < self.window]
        return float(q[-1, 0]), [(t, "!") for t in imp]

    def reference_grid(self):
        q0, v0 = self.start()
        q, _ = self.scene.exact_solution(np.linspace(0.0, self.window, GRID + 1), q0, v0)
        return q[:, 0]

    def _run_switches(self, res, h):
        # impacts: a contact step that follows a flight step
        letters = res.regime_letters()
        t = res.t - h
        return [(float(t[i]), "!") for i in range(1, len(letters))
                if letters[i] != "F" and letters[i - 1] == "F"]


# -- compiled model (moreau.compiled); par: r ---------------------------------------------

@njit(cache=True)
def _mass(par, q, M):
    M[0, 0] = 1.0


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    D[0, 0] = -1.0


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    if need_gap:
        G[0, 0] = q[0] - par[0]
    G[0, 3] = 1.0



register_scene(SceneEntry(
    name="bouncing-ball",
    factory=BouncingBall,
    description="ball bouncing on a rigid floor: impacts, Zeno accumulation (exact solution)",
    case=BouncingBallCase,
))
