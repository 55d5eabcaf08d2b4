"""A rigid rectangular block rocking on its two bottom corners: an accumulation of impacts on two contacts.

Released from rest tilted on one corner, the block falls back about that
corner like an inverted pendulum, hits the floor with the other corner, and
rocks on about that one with less angular velocity; the impacts accumulate
(Zeno) and the block settles flat in finite time. With a large friction
coefficient the corners never slide, and with ``e = 0`` the impacting corner
stays down, so each impact is Housner's (Housner 1963, "The behavior of
inverted pendulum structures during earthquakes", Bull. Seismol. Soc. Am.
53(2), 403-417).

Geometry and units
------------------
Block of width ``2a`` and height ``2b``, mass ``m``, the two bottom corners
are the contacts; the model and its compiled form are those of
:class:`~moreau.scenes.sliding_box.SlidingBox` (coordinates ``(x, y, theta)``
of the centre and the counter-clockwise rotation). Lengths are in units of
the half-diagonal ``R = sqrt(a^2 + b^2)``, time in ``sqrt(R / g)``, forces in
``m g``, so that the centroidal inertia is ``1/3`` and the inertia about a
corner ``I_O = 4/3``. ``alpha = atan(a / b)`` is the angle between the
diagonal and the vertical.

Rocking about a corner
----------------------
On its left corner (``theta > 0``) the centre sits at
``R (sin(alpha - theta), cos(alpha - theta))`` from the corner, so
``I_O theta'' = -sin(alpha - theta)`` and, from rest at ``theta0``,
``(2/3) theta'^2 = cos(alpha - theta0) - cos(alpha - theta)`` (energy). The
time to fall from ``theta0`` to 0 is the quadrature
``T(theta0) = int_0^theta0 dtheta / sqrt((3/2)(cos(alpha - theta0) - cos(alpha - theta)))``
(:meth:`RockingBlock.phase_time`); for a slender block it tends to the
linearised ``sqrt(I_O) arccosh(alpha / (alpha - theta0))``. By symmetry the
motion on the right corner is the mirror image.

Housner's impact
----------------
At ``theta = 0`` the right corner ``O'`` lands while the block turns about
the left corner ``O`` at ``w``: ``v_G = w z x (a, b) = w (-b, a)``. The impact
forces act at the corners only; with the landing corner sticking and the
other lifting, the angular momentum about ``O'`` is conserved:
``I_G w + m (G - O') x v_G = I_O w'``, with ``(G - O') = (-a, b)``, giving
``w (R^2/3 + b^2 - a^2) = (4/3) R^2 w'``, so::

    w' / w = (1 + 3 cos^2 alpha - 3 sin^2 alpha) / 4 = 1 - (3/2) sin^2 alpha

(:func:`housner_ratio`). The left corner then leaves at ``2 a |w'|``. A
complete stop at the impact would need a pulling normal impulse at the
lifting corner (``a^2 - b^2 - R^2/3 < 0``), so with ``mu`` large enough
(the landing corner's impulse ratio is ``|p_T / p_N|`` at most ``b / a``
here) Housner's jump is the only solution of the impact law.

Amplitudes and the settling time
--------------------------------
The energy after impact ``k`` is ``r^2`` times the energy before it
(``r`` = Housner's ratio): the amplitude map is
``cos(alpha - theta_{k+1}) = cos(alpha) + r^2 (cos(alpha - theta_k) - cos(alpha))``,
and the block settles flat at the Zeno time
``t_inf = T(theta0) + 2 sum_{k >= 1} T(theta_k)`` (:meth:`RockingBlock.settling_time`).
For small amplitudes ``theta_{k+1} ~ r^2 theta_k`` and ``T(theta) ~
sqrt(2 I_O theta / sin(alpha))``, so the terms of the sum fall like ``r^k``.

Valid region: ``|theta| < pi/2`` (the top corners, which are not contacts,
stay above the floor; the block topples beyond ``|theta| = alpha``).
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad, solve_ivp

from .._validate import finite_array, finite_scalar, restitution
from ..analysis.cases import GRID, ExactReference, FactoryCase
from ..errors import InputError
from ..model.params import GRAVITY, MASS, MU, POSITIVE, RESTITUTION, Declared, param
from ..model.units import SIUnits
from ..model.compiled_scene import CompiledScene
from ..model.scene import FromParams
from ..model.registry import SceneEntry, register_scene
from .sliding_box import SlidingBox

__all__ = ["RockingBlockParams", "RockingBlock", "housner_ratio"]


def housner_ratio(alpha):
    """Housner's ratio ``w+ / w- = 1 - (3/2) sin^2(alpha)`` of a uniform rectangular block.

    ``alpha = atan(width / height)``.

    Examples
    --------
    >>> round(housner_ratio(math.atan(0.5)), 12)
    0.7
    """
    a = finite_scalar("alpha", alpha)
    return 1.0 - 1.5 * math.sin(a) ** 2


@dataclass(frozen=True)
class RockingBlockParams(Declared):
    """SI parameters of the rocking block."""

    mass: float = MASS(1.0)
    width: float = param(0.2, "m", POSITIVE, "Width of the block")
    height: float = param(0.4, "m", POSITIVE, "Height of the block")
    mu: float = MU(10.0, "Coulomb friction at both corners")
    gravity: float = GRAVITY(9.81)
    restitution: float = RESTITUTION(0.0, "Newton restitution at the corners")
    tilt: float = param(0.05, "rad", doc="Initial tilt on the left corner",
                        note="In ``[0, atan(width / height))``: beyond it the block topples.")

    sweepable = ("mu", "tilt", "width", "height")

    def __post_init__(self):
        super().__post_init__()
        alpha = math.atan(self.width / self.height)
        tilt = finite_scalar("tilt", self.tilt)
        if not 0.0 <= tilt < alpha:
            raise InputError(f"`tilt` must be in [0, atan(width / height)) = [0, {alpha:.6g}) "
                             f"for the block to fall back onto both corners, got {tilt!r}")


class RockingBlock(FromParams, SIUnits, CompiledScene):
    """Rectangular block on a level floor, its two bottom corners frictional contacts.

    {params}

    Examples
    --------
    >>> blk = RockingBlock()
    >>> q0, v0 = blk.initial_state()
    >>> [round(float(g), 12) for g in blk.gaps(q0, 0.0)], round(blk.housner_ratio, 12)
    ([0.0, 0.044702727979], 0.7)
    """

    ndof = 3
    name = "rocking-block"
    angle_coordinates = (2,)

    Params = RockingBlockParams

    def _setup(self, p):
        R = 0.5 * math.hypot(p.width, p.height)
        self._scale_by_weight(R, p.mass, p.gravity)
        self.alpha = math.atan(p.width / p.height)
        # the model of the sliding box, in units of R
        self._box = SlidingBox(mass=p.mass, half_width=0.5 * p.width, half_height=0.5 * p.height,
                               mu=p.mu, gravity=p.gravity, restitution=p.restitution, length=R)
        self.a, self.b = self._box.a, self._box.b
        self.mu = self._box.mu
        self.restitution = self._box.restitution

    # -- Scene interface (mass, forces, gaps, ...: the box's compiled model, CompiledScene) --
    def compiled_model(self):
        """Compiled form of this model: the sliding box's (:mod:`moreau.compiled`)."""
        return self._box.compiled_model()

    def _qscale(self):
        return np.array([self.length, self.length, 1.0])

    def shapes(self, q, t=0.0):
        """The floor, the block (centre ``q[0:2]`` [m], tilt ``q[2]`` [rad]) and its two corner contacts."""
        return self._box.shapes(q, t)

    def initial_state(self):
        """At rest on the left corner at ``x = 0``, tilted by ``params.tilt``."""
        return self.state_on_corner(self.params.tilt)

    def state_on_corner(self, theta, dtheta=0.0):
        """State turning about the left corner (at the origin) for ``theta >= 0``, the right one for ``theta < 0``.

        Returns
        -------
        q, v : ndarray, shape (3,)
        """
        th = finite_scalar("theta", theta)
        w = finite_scalar("dtheta", dtheta)
        s = -1.0 if th >= 0.0 else 1.0           # the pivot's side
        a, b = self.a, self.b
        # centre relative to the pivot: minus the pivot's body vector (s a, -b), rotated
        c, sn = math.cos(th), math.sin(th)
        rx = -(s * a * c + b * sn)
        ry = -(s * a * sn - b * c)
        return np.array([rx, ry, th]), np.array([-w * ry, w * rx, w])

    # -- valid region -------------------------------------------------------------------
    #: where the model holds: the top corners, not modelled as contacts, stay above the floor
    valid_region = "|theta| < pi/2"
    #: a run to rest: the Zeno time of the default release is 3.09
    default_window = 4.0

    def inside_valid_region(self, t, q, v):
        """Whether each state (a row of ``q``) lies in the valid region ``|theta| < pi/2``.

        Examples
        --------
        >>> RockingBlock().inside_valid_region(np.zeros(2), np.array([[0, 1, 0.3], [0, 0, 2.0]]),
        ...                                    np.zeros((2, 3))).tolist()
        [True, False]
        """
        q = np.asarray(q, dtype=float).reshape(-1, 3)
        return np.abs(q[:, 2]) < 0.5 * math.pi

    # -- closed forms ----------------------------------------------------------------------
    @property
    def housner_ratio(self):
        """``w+ / w-`` at every rocking impact (:func:`housner_ratio`)."""
        return housner_ratio(self.alpha)

    def phase_time(self, theta0):
        """Time to fall from rest at tilt ``theta0`` (``0 <= theta0 < alpha``) to flat, scene units."""
        th0 = finite_scalar("theta0", theta0)
        al = self.alpha
        if not 0.0 <= th0 < al:
            raise InputError(f"`theta0` must be in [0, alpha) = [0, {al:.6g}), got {th0!r}")
        if th0 == 0.0:
            return 0.0

        def g(th):
            # (cos(alpha - th0) - cos(alpha - th)) / (th0 - th), without cancellation
            d = 0.5 * (th0 - th)
            sinc = math.sin(d) / d if d != 0.0 else 1.0
            return math.sin(al - 0.5 * (th0 + th)) * sinc

        # the 1/sqrt(th0 - th) end point singularity goes to quad's algebraic weight
        val, _ = quad(lambda th: 1.0 / math.sqrt(1.5 * g(th)), 0.0, th0, weight="alg",
                      wvar=(0.0, -0.5), epsabs=0.0, epsrel=1e-13)
        return val

    def next_amplitude(self, theta):
        """Amplitude after the next impact, from amplitude ``theta`` (Housner's energy ratio)."""
        th = finite_scalar("theta", theta)
        al = self.alpha
        r2 = self.housner_ratio ** 2
        # cos(alpha - th') - cos(alpha) = r^2 (cos(alpha - th) - cos(alpha)), written with
        # 2 sin(alpha - th/2) sin(th/2) to keep the small amplitudes' digits
        rhs = r2 * 2.0 * math.sin(al - 0.5 * th) * math.sin(0.5 * th)
        # solve 2 sin(alpha - x/2) sin(x/2) = rhs for x by Newton from the small-angle guess
        x = rhs / math.sin(al)
        for _ in range(60):
            f = 2.0 * math.sin(al - 0.5 * x) * math.sin(0.5 * x) - rhs
            df = math.sin(al - x)
            dx = f / df
            x -= dx
            if abs(dx) <= 1e-16 * max(x, 1e-300):
                break
        return x

    def amplitudes(self, count):
        """The first ``count`` rocking amplitudes ``theta_0 = tilt, theta_1, ...``."""
        out = [float(self.params.tilt)]
        for _ in range(count - 1):
            out.append(self.next_amplitude(out[-1]))
        return np.array(out)

    def impact_times(self, count):
        """Times of the first ``count`` impacts from the initial state, scene units."""
        th = self.amplitudes(count)
        t = [self.phase_time(th[0])]
        for k in range(1, count):
            t.append(t[-1] + 2.0 * self.phase_time(th[k]))
        return np.array(t)

    def settling_time(self, rtol=1e-14):
        """Zeno time ``T(theta0) + 2 sum T(theta_k)`` at which the block lies flat, scene units."""
        th = float(self.params.tilt)
        total = self.phase_time(th)
        r = self.housner_ratio
        while True:
            th = self.next_amplitude(th)
            term = 2.0 * self.phase_time(th)
            total += term
            # the terms fall at least like r^k from here on: bound the tail
            if term * r / (1.0 - r) <= rtol * total or th == 0.0:
                return total

    def exact_solution(self, t):
        """``(theta, theta')`` at times ``t`` (scene units), rocking without slip, flat after the Zeno time.

        Each phase is the pendulum about the pivot integrated by DOP853 at a
        tight tolerance; the impacts are Housner's.
        """
        tt = np.atleast_1d(finite_array("t", t)).astype(float)
        if tt.size and (np.any(np.diff(tt) < 0) or tt[0] < 0.0):
            raise InputError("`t` must be increasing and >= 0")
        al, r = self.alpha, self.housner_ratio
        theta = np.zeros(tt.size)
        omega = np.zeros(tt.size)
        t0, th0, w0, side = 0.0, float(self.params.tilt), 0.0, 1.0
        t_inf = self.settling_time()

        def rhs(_, y, side=1.0):
            # side +1: on the left corner (theta > 0); -1: the right one
            return [y[1], -0.75 * side * math.sin(al - side * y[0])]

        while t0 < (tt[-1] if tt.size else 0.0) and t0 < t_inf:
            # the phase from (th0, w0) on the side of th0's sign until theta returns to 0
            # (the crossing back, not the start on theta = 0)
            def hit(_, y, _side):
                return y[0]

            hit.terminal, hit.direction = True, -side
            sol = solve_ivp(rhs, (t0, t_inf), [th0, w0], args=(side,), method="DOP853",
                            rtol=1e-13, atol=1e-15, dense_output=True, events=hit)
            t1 = float(sol.t_events[0][-1]) if sol.t_events[0].size else t_inf
            sel = (tt >= t0) & (tt < t1)
            if np.any(sel):
                y = sol.sol(tt[sel])
                theta[sel], omega[sel] = y[0], y[1]
            w1 = float(sol.sol(t1)[1]) * r
            t0, th0, w0, side = t1, 0.0, w1, -side
            if abs(w1) < 1e-12:
                break
        return theta, omega


class RockingBlockCase(ExactReference, FactoryCase):
    """The block from its release to halfway through its second rocking phase: tilt against the exact rocking."""

    mj_tolerance = 2e-2
    headline_name = "tilt at the end of the window"
    window = 1.0

    scene_factory = RockingBlock

    def coordinate(self, q):
        return q[:, 2]

    def _exact(self):
        # the block whose exact rocking is the reference: the scene run (the built
        # block's case keeps the hand-written one beside its scene)
        return self.scene

    def reference(self, rtol):
        th, _ = self._exact().exact_solution([self.window])
        t1 = float(self._exact().impact_times(1)[0])
        return float(th[0]), [(t1, "0:F"), (t1, "1:S")]

    def reference_grid(self):
        th, _ = self._exact().exact_solution(np.linspace(0.0, self.window, GRID + 1))
        return th

    trajectory_scale = 0.05


register_scene(SceneEntry(
    name="rocking-block",
    factory=RockingBlock,
    description=("block rocking on two frictional corners to rest: Housner's impacts "
                 "(Housner 1963) accumulating on two contacts"),
    case=RockingBlockCase,
))
