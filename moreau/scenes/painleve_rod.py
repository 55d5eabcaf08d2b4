"""A uniform rod sliding on one tip over a rough floor: the Painlevé paradox.

For a sliding tip in contact, eliminating the accelerations from

    M a = h + (WN - mu s WT)^T lambdaN,   d2g/dt2 = WN a + wNbar = 0,
    s = sign(gammaT)

leaves a scalar equation ``A lambdaN + b = 0`` with

    A = WN M^-1 (WN - mu s WT)^T = 1 + 3 cos(phi)^2 + 3 mu s sin(phi) cos(phi)
    b = WN M^-1 h + wNbar       = -1 + sin(phi) dphi^2

(dimensionless, uniform rod). While ``A > 0`` the sliding motion is well
posed. ``A <= 0`` (the Painlevé condition fails) needs
``mu >= mu_c(phi) = (1 + 3 cos^2 phi) / (3 |sin phi cos phi|)``, whose
minimum ``4/3`` is reached at ``tan(phi) = 2``, and a slip direction with
``s sin(phi) cos(phi) < 0``: the friction torque then drives the tip into the
floor. There the contact problem has no solution (``b < 0``: sliding would
need a pulling normal force and lift-off would penetrate) or two (``b > 0``:
lift-off and sliding both consistent). A time-stepping scheme still returns
*something* (typically a tangential impulse that jams the tip), so the run
must be stopped and reported instead: :meth:`PainleveRod.check_well_posed`.

Scales
------
Lengths in units of the half-length ``a = params.length / 2``, time in
``T = sqrt(a / g)``, velocities in ``sqrt(g a)``, forces in the weight
``m g``. Then ``M = diag(1, 1, 1/3)`` (the centroidal inertia
``m (2a)^2 / 12 = m a^2 / 3``) and ``h = (0, -1, 0)``.

Coordinates: ``q = (x, y, phi)``, the centre of mass and the angle between
the rod and the floor, counter-clockwise. The contact is the lower tip
``(x - cos(phi), y - sin(phi))``, so the model is meant for ``0 < phi < pi``;
the upper end is not a contact. Slip velocity: the tip's ``x`` velocity.
"""

import math
from dataclasses import dataclass

import numpy as np

from numba import njit

from ..compiled import CompiledModel
from .._validate import finite_array, finite_scalar, nonnegative, restitution
from ..errors import InputError, PainleveError
from ..model.params import GRAVITY, MASS, MU, POSITIVE, RESTITUTION, Declared, param
from ..model.drawing import contact, line
from ..model.compiled_scene import CompiledScene
from ..model.units import SIUnits
from ..model.scene import FromParams
from scipy.integrate import solve_ivp

from ..analysis.cases import GRID, CompareCase
from ..errors import MoreauError
from ..model.registry import SceneEntry, register_scene

__all__ = ["PainleveRodParams", "PainleveRod", "painleve_critical_mu", "PAINLEVE_MU_MIN"]

#: smallest friction coefficient for which a uniform rod can meet the
#: paradox, reached at ``tan(phi) = 2``
PAINLEVE_MU_MIN = 4.0 / 3.0


def painleve_critical_mu(phi):
    """Friction coefficient above which a uniform rod at angle ``phi`` is paradoxical.

    ``mu_c = (1 + 3 cos(phi)^2) / (3 |sin(phi) cos(phi)|)``; ``inf`` for a
    flat or upright rod. Its minimum over ``phi`` is ``4/3`` at ``tan(phi) = 2``.

    Examples
    --------
    >>> round(painleve_critical_mu(math.atan(2.0)), 12)
    1.333333333333
    """
    p = finite_scalar("phi", phi)
    sc = abs(math.sin(p) * math.cos(p))
    if sc == 0.0:
        return math.inf
    return (1.0 + 3.0 * math.cos(p) ** 2) / (3.0 * sc)


@dataclass(frozen=True)
class PainleveRodParams(Declared):
    """SI parameters of the rod."""

    mass: float = MASS(1.0, "Mass of the rod")
    length: float = param(1.0, "m", POSITIVE, "Full length of the rod")
    mu: float = MU(2.0, "Coulomb friction coefficient at the tip",
                   note="The default 2 exceeds the paradox threshold 4/3.")
    gravity: float = GRAVITY(9.81)
    restitution: float = RESTITUTION(0.0, "Newton restitution of the tip contact")

    sweepable = ("mu", "mass", "length")


class PainleveRod(FromParams, SIUnits, CompiledScene):
    """Uniform rod with its lower tip on a rough floor.

    {params}

    Attributes
    ----------
    length, time, force : float
        SI scales (m, s, N) of one dimensionless unit; ``length`` is the
        half-length of the rod.

    Examples
    --------
    >>> rod = PainleveRod(mu=2.0)
    >>> q0, v0 = rod.sliding_state(phi=math.atan(2.0), tip_speed=-1.0)
    >>> round(rod.painleve_indicator(q0, v0), 12)   # 1 + 3/5 - 3*2*2/5
    -0.8
    >>> rod.check_well_posed(q0, v0, 0.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    moreau.errors.PainleveError: Painlevé paradox at t = 0: ...
    """

    ndof = 3
    name = "painleve-rod"
    #: the lower tip is the only contact: past phi = 0 or pi the other end would be
    #: the lower one, and it passes through the floor unseen
    valid_region = "0 < phi < pi (the contact tip is the rod's lowest point)"
    #: from the default start the rod slides, falls flat (phi -> 0) within it
    default_window = 2.0

    Params = PainleveRodParams

    def _setup(self, p):
        self.mu = np.array([p.mu])
        self.restitution = np.array([p.restitution])
        self._scale_by_weight(0.5 * p.length, p.mass, p.gravity)
        self._M = np.diag([1.0, 1.0, 1.0 / 3.0])

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def inside_valid_region(self, t, q, v):
        phi = np.asarray(q)[:, 2]
        return (phi > 0.0) & (phi < math.pi)

    def initial_state(self):
        """Tip on the floor at 45 degrees, sliding at unit speed the well-posed way (away from the rod)."""
        return self.sliding_state(phi=math.pi / 4, tip_speed=1.0)

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        return CompiledModel(_mass, _forces, _contacts, _drift, [], 3, 1, True, False)

    # -- units ----------------------------------------------------------------
    angle_coordinates = (2,)

    def _qscale(self):
        return np.array([self.length, self.length, 1.0])

    def shapes(self, q, t=0.0):
        """The floor, the rod (centre ``q[0:2]`` [m], angle ``q[2]`` [rad]) and its tip's contact."""
        ell = self.length                      # the half-length
        x, y, phi = (float(v) for v in q)
        d = (ell * math.cos(phi), ell * math.sin(phi))
        tip = (x - d[0], y - d[1])
        return [line([(x - 3 * ell, 0.0), (x + 3 * ell, 0.0)], role="ground"),
                line([tip, (x + d[0], y + d[1])]), contact(0, tip, (0.0, 1.0), (1.0, 0.0))]

    # -- states and the paradox ---------------------------------------------
    def sliding_state(self, phi, tip_speed, dphi=0.0):
        """State with the tip on the floor at ``x = 0``, sliding at ``tip_speed``.

        The tip's normal velocity is zero, so the rod neither leaves nor hits
        the floor at ``t = 0``.

        Parameters
        ----------
        phi : float
            Angle with the floor [rad], in (0, pi).
        tip_speed : float
            Tangential velocity of the tip (dimensionless).
        dphi : float
            Angular velocity (dimensionless).

        Returns
        -------
        q0, v0 : ndarray, shape (3,)
        """
        p = finite_scalar("phi", phi)
        if not 0.0 < p < math.pi:
            raise InputError(f"`phi` must be in the open interval (0, pi) for the lower tip "
                             f"to touch the floor, got {p!r}")
        u = finite_scalar("tip_speed", tip_speed)
        w = finite_scalar("dphi", dphi)
        c, s = math.cos(p), math.sin(p)
        return np.array([c, s, p]), np.array([u - s * w, c * w, w])

    def painleve_indicator(self, q, v):
        """Normal-acceleration coefficient ``A`` of the sliding tip; > 0 is well posed.

        ``A = WN M^-1 (WN - mu s WT)^T = 1 + 3 cos^2(phi) + 3 mu s sin(phi) cos(phi)``
        with ``s = sign(gammaT)``. For a tip at rest (``gammaT = 0``) the
        smaller of the two slip directions is returned, i.e. the value the
        tip would meet if it started to slip the wrong way.
        """
        q = finite_array("q", q, shape=(3,))
        v = finite_array("v", v, shape=(3,))
        return self._indicator(q, v)[0]

    def _indicator(self, q, v):
        WN, _, WT, wT = self.contact_jacobians(q, 0.0)
        if WT.shape[0] == 0:
            return float(WN[0] @ np.linalg.solve(self._M, WN[0])), 0.0, 0.0
        gT = float(WT[0] @ v + wT[0])
        Minv_WN = np.linalg.solve(self._M, WN[0])
        nn = float(WN[0] @ Minv_WN)
        nt = float(WT[0] @ Minv_WN)
        mu = float(self.mu[0])
        if gT != 0.0:
            s = math.copysign(1.0, gT)
            return nn - mu * s * nt, s, gT
        # a tip at rest: report the worse of the two directions
        s = 1.0 if nt > 0.0 else -1.0
        return nn - mu * s * nt, s, gT

    def sliding_contact_problem(self, q, v):
        """The sliding-contact equation ``A lambdaN + b = 0`` at state ``(q, v)``.

        Returns
        -------
        A : float
            :meth:`painleve_indicator`.
        b : float
            Normal acceleration of the tip without contact force,
            ``WN M^-1 h + wNbar = -1 + sin(phi) dphi^2``.
        lambdaN : float
            ``-b / A``, the normal force a sliding contact would need
            (``inf`` with the sign of ``-b`` if ``A == 0``).
        """
        q = finite_array("q", q, shape=(3,))
        v = finite_array("v", v, shape=(3,))
        A = self._indicator(q, v)[0]
        b = self._free_normal_acceleration(q, v)
        if A == 0.0:
            return A, b, math.copysign(math.inf, -b)
        return A, b, -b / A

    def _free_normal_acceleration(self, q, v):
        WN, _, _, _ = self.contact_jacobians(q, 0.0)
        wNbar, _ = self.contact_drift(q, v, 0.0)
        h = self.forces(q, v, 0.0)
        return float(WN[0] @ np.linalg.solve(self._M, h) + wNbar[0])

    def sliding_accelerations(self, q, v):
        """Exact accelerations and contact forces of a tip sliding in contact.

        Valid while the Painlevé indicator is positive and the resulting
        normal force is >= 0.

        Returns
        -------
        a : ndarray, shape (3,)
        lambdaN, lambdaT : float
            Normal force and friction force ``-mu sign(gammaT) lambdaN``.

        Raises
        ------
        PainleveError
            If the indicator is <= 0 (see :meth:`check_well_posed`).
        """
        q = finite_array("q", q, shape=(3,))
        v = finite_array("v", v, shape=(3,))
        A, s, gT = self._indicator(q, v)
        if gT == 0.0:
            raise InputError("`v` must give the tip a nonzero slip velocity for sliding "
                             "accelerations, got slip velocity 0")
        if A <= 0.0:
            self._raise_paradox(q, v, 0.0, A, s, gT)
        b = self._free_normal_acceleration(q, v)
        lamN = -b / A
        lamT = -float(self.mu[0]) * s * lamN
        WN, _, WT, _ = self.contact_jacobians(q, 0.0)
        rhs = self.forces(q, v, 0.0) + WN[0] * lamN
        if WT.shape[0]:
            rhs = rhs + WT[0] * lamT
        return np.linalg.solve(self._M, rhs), lamN, lamT

    def check_well_posed(self, q, v, t=0.0, active=None, gap_tol=1e-9, slip_tol=0.0):
        """Raise :class:`~moreau.errors.PainleveError` if the sliding tip is paradoxical.

        A state is flagged when the tip is in contact, slips
        (``|gammaT| > slip_tol``) and :meth:`painleve_indicator` is <= 0.
        Integrators call this before solving a step's contact problem.

        Parameters
        ----------
        q, v : array_like, shape (3,)
        t : float
            Time, only for the message.
        active : bool, optional
            Whether the contact is active; by default ``gap <= gap_tol``.
        gap_tol : float
            Gap below which the tip counts as touching (default ``1e-9``).
        slip_tol : float
            Slip speed at or below which the tip counts as sticking.

        Raises
        ------
        PainleveError
            Naming ``mu``, ``phi``, the indicator's value and whether the
            contact problem has no or two solutions.
        """
        q = finite_array("q", q, shape=(3,))
        v = finite_array("v", v, shape=(3,))
        t = finite_scalar("t", t)
        nonnegative("gap_tol", gap_tol)
        nonnegative("slip_tol", slip_tol)
        if active is None:
            active = self.gaps(q, t)[0] <= gap_tol
        if not active or self.mu[0] == 0.0:
            return
        A, s, gT = self._indicator(q, v)
        if abs(gT) <= slip_tol or A > 0.0:
            return
        self._raise_paradox(q, v, t, A, s, gT)

    def _raise_paradox(self, q, v, t, A, s, gT):
        phi = float(q[2])
        mu = float(self.mu[0])
        b = self._free_normal_acceleration(q, v)
        if b < 0.0:
            what = (f"no solution: sliding contact would need the normal force -b/A = "
                    f"{-b / A:.6g} < 0 and lift-off would penetrate the floor "
                    f"(free normal acceleration b = {b:.6g})") if A else "no solution"
        elif b > 0.0:
            what = (f"two solutions: lift-off, or sliding contact with normal force "
                    f"-b/A = {-b / A:.6g}") if A else "two solutions"
        else:
            what = "a continuum of solutions (free normal acceleration b = 0)"
        raise PainleveError(
            f"Painlevé paradox at t = {t:.6g}: the sliding tip's normal-acceleration "
            f"coefficient A = WN M^-1 (WN - mu*sign(vT)*WT)^T = 1 + 3cos(phi)^2 + "
            f"3*mu*sign(vT)*sin(phi)cos(phi) = {A:.6g} <= 0 with `mu` = {mu:.6g}, "
            f"`phi` = {phi:.6g} rad ({math.degrees(phi):.4g} deg), slip velocity "
            f"vT = {gT:.6g}; `mu` exceeds the critical {painleve_critical_mu(phi):.6g} "
            f"for this angle (at least 4/3 for any angle). The contact problem has {what}.")


class PainleveRodCase(CompareCase):
    """The rod sliding on its tip on the well-posed side; reference: the sliding ODE by DOP853."""

    mj_tolerance = 2e-2
    listed_reference = ref_scheme = "sliding-ode"
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10)
    tight_rtol = 1e-13
    window = 0.5
    headline_name = "centre position at the end of the window"

    def __init__(self, phi=0.9, tip_speed=-1.0, dphi=0.4, mu=0.5, **params):
        self.scene = PainleveRod(mu=mu, **params)
        self._params = dict(mu=mu, phi=phi, tip_speed=tip_speed, dphi=dphi, **params)
        self.q0, self.v0 = (np.asarray(a, dtype=float)
                            for a in self.scene.sliding_state(phi, tip_speed, dphi=dphi))
        self._sol = None

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.q0.copy(), self.v0.copy()

    def _ode(self, rtol):
        rod = self.scene

        def rhs(t, y):
            a, lam_n, _ = rod.sliding_accelerations(y[:3], y[3:])
            if not lam_n > 0.0:
                raise MoreauError("the rod leaves the ground: the sliding reference does not apply")
            return np.concatenate([y[3:], a])

        return solve_ivp(rhs, (0.0, self.window), np.concatenate([self.q0, self.v0]),
                         method="DOP853", rtol=rtol, atol=rtol, dense_output=True)

    def reference(self, rtol):
        sol = self._ode(rtol)
        return float(sol.y[0, -1]), []

    def reference_grid(self):
        if self._sol is None:
            self._sol = self._ode(self.tight_rtol)
        return self._sol.sol(np.linspace(0.0, self.window, GRID + 1))[0]


# -- compiled model (moreau.compiled); no parameters ------------------------------------

@njit(cache=True)
def _mass(par, q, M):
    M[0, 0] = 1.0
    M[1, 1] = 1.0
    M[2, 2] = 1.0 / 3.0


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    D[1, 0] = -1.0


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    if need_gap:
        G[0, 0] = q[1] - math.sin(q[2])
    G[0, 4] = 1.0
    G[0, 5] = -math.cos(q[2])
    if need_T:
        G[0, 6] = 1.0
        G[0, 8] = math.sin(q[2])


@njit(cache=True)
def _drift(par, q, v, t, Dr):
    w2 = v[2] * v[2]
    Dr[0, 0] = math.sin(q[2]) * w2
    Dr[0, 1] = math.cos(q[2]) * w2


register_scene(SceneEntry(
    name="painleve-rod",
    factory=PainleveRod,
    description="rod sliding on its tip in the Painlevé configuration",
    case=PainleveRodCase,
))
