"""A rigid box sliding on a level floor on its two bottom corners: two frictional contacts.

The multi-contact validation scene. Launched along the floor, the box slides
on both corners, decelerates at ``mu g`` and stops at ``t* = v0 / (mu g)``
after ``v0^2 / (2 mu g)``, like a point mass, but the weight is shared
unequally: friction acting below the centre of mass tips the box forward,
so the leading corner carries more. Every Moreau–Jean step with the box on
the floor solves a two-contact frictional LCP (Lemke).

Derivation
----------
Box of half-width ``a``, half-height ``b``, mass ``m``, centroidal inertia
``m (a^2 + b^2) / 3``; coordinates ``q = (x, y, theta)`` of the centre and the
rotation (counter-clockwise). Corner ``i`` (``s_i = -1`` rear-left, ``+1``
right) sits at body coordinates ``(s_i a, -b)``, i.e. at
``(x + s_i a cos(theta) + b sin(theta),  y + s_i a sin(theta) - b cos(theta))``. Its gap and
horizontal (slip) velocity are::

    g_i      = y + s_i a sin(theta) - b cos(theta)
    WN_i     = (0, 1, s_i a cos(theta) + b sin(theta)),   wN_i = 0
    WT_i     = (1, 0, b cos(theta) - s_i a sin(theta)),   wT_i = 0
    wNbar_i  = theta'^2 (b cos(theta) - s_i a sin(theta))
    wTbar_i  = -theta'^2 (s_i a cos(theta) + b sin(theta))

(second derivatives of the corner coordinates). Lengths in units of
``L = params.length``, time in ``sqrt(L / g)``, forces in ``m g``: ``M = diag(1,
1, (a^2 + b^2) / 3)``, ``h = (0, -1, 0)``.

Exact motion from ``theta = 0``, ``y = b``, speed ``v0 > 0`` along ``+x``: with
``theta'' = 0`` and ``y'' = 0`` the contact forces are
``lambda_N,i = (1 + s_i mu b / a) / 2`` and ``lambda_T,i = -mu lambda_N,i`` (moment
balance about the centre: ``a (N_+ - N_-) = mu b (N_+ + N_-)``), valid while
``mu b < a`` (otherwise the rear corner lifts and the box tips). Then
``x'' = -mu`` until ``t* = v0 / mu``, and rest after that.
"""

import math
from dataclasses import dataclass

import numpy as np

from numba import njit

from ..compiled import CompiledModel
from .._validate import finite_array, restitution, times
from ..errors import InputError
from ..model.params import GRAVITY, LENGTH, MASS, MU, POSITIVE, RESTITUTION, Declared, param
from ..model.drawing import contact, line, polygon
from ..model.compiled_scene import CompiledScene
from ..model.units import SIUnits
from ..model.scene import FromParams
from .._validate import finite_scalar
from ..analysis.cases import GRID, CompareCase, ExactReference, flatten
from ..model.registry import SceneEntry, register_scene

__all__ = ["SlidingBoxParams", "SlidingBox"]


@dataclass(frozen=True)
class SlidingBoxParams(Declared):
    """SI parameters of the sliding box."""

    mass: float = MASS(1.0)
    half_width: float = param(0.5, "m", POSITIVE, "Half the box's width")
    half_height: float = param(0.25, "m", POSITIVE, "Half the box's height")
    mu: float = MU(0.4, "Coulomb friction at both corners",
                   note="``mu * half_height < half_width`` keeps both corners on the floor "
                        "while sliding.")
    gravity: float = GRAVITY(9.81)
    restitution: float = RESTITUTION(0.0, "Newton restitution at the corners")
    length: float = LENGTH(1.0)

    sweepable = ("mu", "half_width", "half_height", "mass")


class SlidingBox(FromParams, SIUnits, CompiledScene):
    """Rigid box on a level floor, two frictional corner contacts.

    {params}

    Examples
    --------
    >>> box = SlidingBox(mu=0.5)
    >>> q0, v0 = box.initial_state()
    >>> box.gaps(q0, 0.0).tolist(), box.stopping_time(v0)
    ([0.0, 0.0], 2.0)
    >>> [round(x, 12) for x in box.normal_forces()]      # rear, front
    [0.375, 0.625]
    """

    ndof = 3
    name = "sliding-box"
    #: the two bottom corners are the only contacts: they must stay the lowest points
    valid_region = "|theta| < pi/2 (the contact corners are the box's lowest points)"
    #: the default launch stops at t* = 1 / mu = 2.5
    default_window = 4.0

    Params = SlidingBoxParams

    def _setup(self, p):
        self.a = p.half_width / p.length
        self.b = p.half_height / p.length
        self.inertia = (self.a ** 2 + self.b ** 2) / 3.0
        self.mu = np.array([p.mu, p.mu])
        self.restitution = np.array([p.restitution, p.restitution])
        self._scale_by_weight(p.length, p.mass, p.gravity)

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def inside_valid_region(self, t, q, v):
        return np.abs(np.asarray(q)[:, 2]) < 0.5 * math.pi

    def initial_state(self):
        """Flat on the floor at ``x = 0``, launched along ``+x`` at unit speed."""
        return np.array([0.0, self.b, 0.0]), np.array([1.0, 0.0, 0.0])

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        return CompiledModel(_mass, _forces, _contacts, _drift, [self.a, self.b, self.inertia],
                             3, 2, True, False)

    angle_coordinates = (2,)

    def shapes(self, q, t=0.0):
        """The floor, the box (centre ``q[0:2]`` [m], tilt ``q[2]`` [rad]) and its two corner contacts."""
        a, b = self.params.half_width, self.params.half_height
        x, y, th = (float(v) for v in q)
        c, s = math.cos(th), math.sin(th)

        def world(u, w):
            return (x + c * u - s * w, y + s * u + c * w)

        out = [line([(x - 4 * a, 0.0), (x + 4 * a, 0.0)], role="ground"),
               polygon([world(-a, -b), world(a, -b), world(a, b), world(-a, b)])]
        return out + [contact(i, world(side * a, -b), (0.0, 1.0), (1.0, 0.0))
                      for i, side in enumerate((-1.0, 1.0))]

    def _qscale(self):
        return np.array([self.length, self.length, 1.0])

    # -- exact solution -------------------------------------------------------
    def _check_flat(self):
        mu = float(self.mu[0])
        if not mu * self.b < self.a:
            raise InputError(f"`mu` * half_height must be < half_width for the box to slide on "
                             f"both corners (mu b / a = {mu * self.b / self.a:.6g}); it tips")
        if mu == 0.0:
            raise InputError("`mu` must be > 0 for the box to stop")

    def _speed(self, v0):
        v0 = finite_array("v0", v0, shape=(3,))
        if v0[1] != 0.0 or v0[2] != 0.0:
            raise InputError("`v0` must be a pure slide along the floor: v0[1] == v0[2] == 0")
        if not v0[0] > 0.0:
            raise InputError(f"`v0[0]` must be > 0 (sliding along +x), got {v0[0]!r}")
        return float(v0[0])

    def stopping_time(self, v0):
        """``v0 / mu`` (SI: ``v0 / (mu g)``)."""
        self._check_flat()
        return self._speed(v0) / float(self.mu[0])

    def stopping_distance(self, v0):
        """``v0^2 / (2 mu)`` (SI: ``v0^2 / (2 mu g)``)."""
        self._check_flat()
        u = self._speed(v0)
        return u * u / (2.0 * float(self.mu[0]))

    def normal_forces(self):
        """Exact normal forces ``(rear, front)`` while sliding along ``+x``: ``(1 -+ mu b / a) / 2``."""
        self._check_flat()
        r = float(self.mu[0]) * self.b / self.a
        return 0.5 * (1.0 - r), 0.5 * (1.0 + r)

    def exact_solution(self, t, q0, v0):
        """Exact ``(q, v)`` at times ``t >= 0`` from a flat sliding start ``(q0, v0)``.

        Returns arrays of shape ``(len(t), 3)``.
        """
        self._check_flat()
        q0 = finite_array("q0", q0, shape=(3,))
        if q0[2] != 0.0 or q0[1] != self.b:
            raise InputError("`q0` must be flat on the floor: q0[1] == half_height, q0[2] == 0")
        u = self._speed(v0)
        tt = times("t", t)
        mu = float(self.mu[0])
        ts = np.minimum(tt, u / mu)
        q = np.zeros((len(tt), 3))
        v = np.zeros((len(tt), 3))
        q[:, 0] = q0[0] + u * ts - 0.5 * mu * ts ** 2
        q[:, 1] = self.b
        v[:, 0] = u - mu * ts
        return q, v


class SlidingBoxCase(ExactReference, CompareCase):
    """The box launched at ``speed`` [m/s] on its two corners: stopping distance against the exact solution."""

    headline_name = "stopping distance"

    def __init__(self, speed=1.0, mu=0.4, **params):
        self.scene = SlidingBox(mu=mu, **params)
        self.q0, _ = self.scene.initial_state()
        self.v0 = np.array([finite_scalar("speed", speed), 0.0, 0.0])
        self._params = dict(mu=mu, speed=speed, **params)
        # checks mu b < a (both corners stay down) and mu > 0, before any work
        self.window = 1.5 * self.scene.stopping_time(self.v0)

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.q0.copy(), self.v0.copy()

    def reference(self, rtol):
        # both corners stop sliding together, at t* = v0 / mu
        t_stop = float(self.scene.stopping_time(self.v0))
        return (float(self.scene.stopping_distance(self.v0)),
                flatten([[(t_stop, "S")], [(t_stop, "S")]]))

    def reference_grid(self):
        q, _ = self.scene.exact_solution(np.linspace(0.0, self.window, GRID + 1), *self.start())
        return q[:, 0]

    def _run_switches(self, res, h):
        # each corner's stop is measured: Moreau–Jean may stop them a step apart
        return flatten([self._run_switches_of(res, h, c) for c in (0, 1)])


# -- compiled model (moreau.compiled); par: a, b, inertia -----------------------------
# corners at body coordinates (-a, -b) and (+a, -b)

@njit(cache=True)
def _mass(par, q, M):
    M[0, 0] = 1.0
    M[1, 1] = 1.0
    M[2, 2] = par[2]


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    D[1, 0] = -1.0


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    s = math.sin(q[2])
    c = math.cos(q[2])
    a = par[0]
    b = par[1]
    for i in range(2):
        sg = 2.0 * i - 1.0
        if need_gap:
            G[i, 0] = q[1] + sg * a * s - b * c
        G[i, 4] = 1.0
        G[i, 5] = sg * a * c + b * s
        if need_T:
            G[i, 6] = 1.0
            G[i, 8] = -sg * a * s + b * c


@njit(cache=True)
def _drift(par, q, v, t, Dr):
    s = math.sin(q[2])
    c = math.cos(q[2])
    w2 = v[2] * v[2]
    for i in range(2):
        sg = 2.0 * i - 1.0
        Dr[i, 0] = w2 * (-sg * par[0] * s + par[1] * c)
        Dr[i, 1] = w2 * (-sg * par[0] * c - par[1] * s)


register_scene(SceneEntry(
    name="sliding-box",
    factory=SlidingBox,
    description="box sliding to rest on two frictional corners (two contacts, exact solution)",
    case=SlidingBoxCase,
))
