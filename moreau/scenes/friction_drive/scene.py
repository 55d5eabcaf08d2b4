"""The friction drive of a piezoelectric motor (Liu, Zhou, Ruan, Fu; second type).

A stator moves vertically with the prescribed displacement
``x1(t) = x10 (1 - cos w t)``. A rigid rod (mass ``m``, length ``l``) is hinged
on the stator at angle ``phi`` from the horizontal and held by a spring ``k``
at the initial tilt ``phi0``. Its tip presses on a rotor (mass ``m2``,
horizontal coordinate ``x2``) through a unilateral contact with Coulomb
friction ``mu``; a load ``F_L`` acts on the rotor.

Derivation (independent of the paper's printed formulas, which have typos)
---------------------------------------------------------------------------
Rod centre ``(l/2 cos phi, x1 + l/2 sin phi)``, so

    T = 1/2 (m + m1) x1'^2 + 1/2 m2 x2'^2 + 1/6 m l^2 phi'^2 + 1/2 m l x1' phi' cos phi
    V = 1/2 k l^2 (sin phi0 - sin phi)^2

Gap and slip (tip at ``(l cos phi, x1 + l sin phi)``, rotor surface at ``l sin phi0``):

    g_N = l sin phi0 - l sin phi - x1,     g_T = x2 - l cos phi

With ``tau = w t``, ``u = x / l``, forces over ``m l w^2``, ``J = m2/m``,
``P = k/(m w^2)``, ``u1 = u10 (1 - cos tau)``, and ``q = (phi, u2)``, Lagrange's
equations with the contact forces ``f_N`` (along ``grad g_N``) and ``f_T``
(along ``grad g_T``) read ``M q'' = h + WN^T f_N + WT^T f_T`` with

    M  = diag(1/3, J)
    h  = (P cos phi (sin phi0 - sin phi) - 1/2 u1'' cos phi,  -f_L)
    WN = (-cos phi, 0),   dg_N/dtau = WN q' - u1'
    WT = ( sin phi, 1),   dg_T/dtau = WT q'
    g_N'' = WN q'' + phi'^2 sin phi - u1'',   g_T'' = WT q'' + phi'^2 cos phi

Hence the contact accelerations ``g_N'' = A f_N - B f_T + D`` and
``g_T'' = -B f_N + C f_T + E`` with ``A = 3 cos^2 phi``,
``B = 3 sin phi cos phi``, ``C = 1/J + 3 sin^2 phi`` and

    D = phi'^2 sin phi - u1'' + 3/2 u1'' cos^2 phi - 3 P cos^2 phi (sin phi0 - sin phi)
    E = phi'^2 cos phi - f_L/J - 3/2 u1'' sin phi cos phi + 3 P sin phi cos phi (sin phi0 - sin phi)

(the paper prints the ``P`` term of ``E`` with the wrong sign). The stator
load ``F_A`` only changes the force needed to impose ``x1`` and does not enter
the motion of the rod or the rotor, so it is not a parameter here.

In contact the constraint ``g_N = 0`` fixes the rod: ``sin phi = sin phi0 - u1``.
Everything in contact is then an explicit function of ``tau``, which the
event-driven reference exploits.

Preload (``preload = F_p``, default 0)
--------------------------------------
What a motor designer calls the preload: the normal force with which the rod
tip and the rotor are pressed together at rest. Its mechanism is a preload
spring of stiffness ``k_p``, compressed by ``delta_p = F_p / k_p`` at the rest
position, that pushes the tip towards the rotor; like the rod's spring it acts
on the tip height above the hinge, ``l sin phi``, so it moves with the
stator and does not depend on ``x1``:

    V_p = 1/2 k_p (delta_p + l sin phi0 - l sin phi)^2
        = const + F_p l (sin phi0 - sin phi) + 1/2 k_p l^2 (sin phi0 - sin phi)^2.

Its last term only adds ``k_p`` to ``k`` (give it there); the new parameter
is the linear term, ``V_p = F_p l (sin phi0 - sin phi)``: a soft preload
spring of large compression, whose force stays ``F_p`` over the rod's
micrometre strokes. With ``f_p = F_p / (m l w^2)`` it adds the generalised
force ``-dV_p/dphi = f_p cos phi`` to the rod, i.e. ``P (sin phi0 - sin phi)``
becomes ``P (sin phi0 - sin phi) + f_p`` in ``h``, ``D``, ``E`` and ``F_s``:

    D += -3 f_p cos^2 phi,    E += 3 f_p sin phi cos phi,    F_s += -f_p cos phi,

and the energy gains ``f_p (sin phi0 - sin phi)`` (in ``m l^2 w^2``). At rest
(``u1 = 0``, ``phi = phi0``) the rod equation ``0 = f_p cos phi0 - f_N cos
phi0`` gives ``f_N = f_p``: the contact carries the preload. The contact
manifold is unchanged, so the walker's contact pieces stay closed-form. Each
preload term is added after the spring's (``+ f_p c``, ``+ 0.0`` without a
preload), so with ``preload = 0`` every result is the same to the last bit.
"""

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, MoreauError
from ...regimes import Regime
from ...model.drawing import rod_drive_shapes
from ...model.units import DriveUnits
from numba import njit

from ...compiled import CompiledModel
from .rod import (AMPLITUDE, MEMO_SLOTS, PRELOAD, ROD_RESTITUTION, ROTOR_LOAD, OneRod, RodParams,
                  StatorMotion, memo_sincos, one_rod_mass, rod_forces, rod_gap, rod_rows)
from ...model.compiled_scene import CompiledScene
from ...model.scene import params_with
from ...analysis.cases import GRID, TWO_PI, DriveCase, regime_switches
from ...analysis.steady_state import find_steady_state
from ...integrators import simulate
from ...model.registry import Parameter, SceneEntry, parameters_of, register_scene

__all__ = ["FrictionDriveParams", "FrictionDrive", "PAPER_DEFAULTS", "FREQUENCY"]


@dataclass(frozen=True)
class FrictionDriveParams(RodParams):
    """Physical parameters of the friction drive, in SI units.

    {attributes}

    Examples
    --------
    >>> p = FrictionDriveParams(mu=0.2)
    >>> p.mu, p.m
    (0.2, 2e-05)
    """

    x10: float = AMPLITUDE(2.0e-6)
    load: float = ROTOR_LOAD(0.0)
    restitution: float = ROD_RESTITUTION(0.0)
    preload: float = PRELOAD(0.0)

    sweepable = ("frequency", "m", "m2", "k", "length", "phi0", "mu", "x10", "load",
                 "restitution", "preload")

    def __post_init__(self):
        super().__post_init__()
        self._check_amplitude("x10", self.x10)


PAPER_DEFAULTS = FrictionDriveParams()

#: the drive frequency, a one-rod drive's parameter besides its SI parameters (the paper's
#: 185 Hz by default)
FREQUENCY = Parameter("frequency", "Hz", 185.0, "drive frequency")


class FrictionDrive(OneRod, StatorMotion, DriveUnits, CompiledScene):
    """The paper's friction drive at one drive frequency, in dimensionless form.

    Coordinates ``q = (phi, u2)``, velocities ``v = (dphi/dtau, du2/dtau)``,
    time ``tau = w t`` with ``w = 2 pi f``. One frictional contact. The model
    methods (``mass``, ``forces``, ``gaps``, ...) evaluate the compiled model,
    where the equations are written once
    (:class:`~moreau.model.compiled_scene.CompiledScene`); the closed forms on
    the contact manifold (:meth:`contact_angle`, :meth:`coefficients`,
    :meth:`contact_forces`) are the walker's own.

    Parameters
    ----------
    params : FrictionDriveParams, optional
        Physical parameters; the paper's values by default.
    frequency : float
        Drive frequency ``f`` [Hz], > 0.
    **overrides
        Individual parameters replacing those of ``params`` (``mu=0.2``).

    Examples
    --------
    >>> s = FrictionDrive(frequency=185.0)
    >>> round(s.J), round(s.P, 1)
    (100, 370.1)
    >>> A, B, C, D, E = s.coefficients(s.phi0, 0.0, 0.0)
    """

    ndof = 2
    name = "friction-drive"
    Params = FrictionDriveParams
    period = 2.0 * math.pi
    cyclic_coordinates = (1,)
    #: the scene's own high-precision event-driven scheme, which
    #: ``simulate(..., "event-driven")`` selects for it
    reference_integrator = "friction-drive-walker"

    def __init__(self, params=None, frequency=185.0, **overrides):
        if params is None:
            params = PAPER_DEFAULTS
        params = params_with(self.Params, params, overrides)
        self.params = params
        self._scale_one_rod(params, frequency)

    # -- the rod on the contact manifold ------------------------------------
    def contact_angle(self, tau):
        """``(phi, phi', phi'')`` of the rod while the tip touches the rotor.

        From ``sin phi = sin phi0 - u1(tau)`` and its derivatives.
        """
        s = self.sin_phi0 - self.u1(tau)
        phi = np.arcsin(s)
        c = np.cos(phi)
        dphi = -self.du1(tau) / c
        ddphi = dphi * dphi * np.tan(phi) - self.ddu1(tau) / c
        return phi, dphi, ddphi

    def tip_velocity(self, tau):
        """Horizontal tip velocity ``-sin(phi) phi'`` on the contact manifold."""
        phi, dphi, _ = self.contact_angle(tau)
        return -np.sin(phi) * dphi

    def coefficients(self, phi, dphi, tau):
        """Coefficients ``A, B, C, D, E`` of the contact accelerations (module docstring)."""
        s, c = np.sin(phi), np.cos(phi)
        dd1 = self.ddu1(tau)
        spring = self.P * (self.sin_phi0 - s)
        A = 3.0 * c * c
        B = 3.0 * s * c
        C = 1.0 / self.J + 3.0 * s * s
        D = dphi * dphi * s - dd1 + 1.5 * dd1 * c * c - 3.0 * spring * c * c
        E = dphi * dphi * c - self.fL / self.J - 1.5 * dd1 * s * c + 3.0 * spring * s * c
        # preload, added last so that a zero preload leaves every bit as it was
        D = D - 3.0 * self.fp * c * c
        E = E + 3.0 * self.fp * s * c
        return A, B, C, D, E

    def contact_forces(self, tau, regime):
        """Dimensionless ``(f_N, f_T)`` in a contact regime, as functions of ``tau``.

        Parameters
        ----------
        tau : float or ndarray
        regime : Regime
            ``POSITIVE``, ``NEGATIVE`` or ``STICK``.
        """
        phi, dphi, ddphi = self.contact_angle(tau)
        s, c = np.sin(phi), np.cos(phi)
        # F_s of the paper: rod equation with the inertia moved to one side
        Fs = 0.5 * self.ddu1(tau) * c + ddphi / 3.0 - self.P * c * (self.sin_phi0 - s)
        Fs = Fs - self.fp * c
        mu = float(self.mu[0])
        if regime == Regime.POSITIVE:
            fN = -Fs / (c + mu * s)
            return fN, -mu * fN
        if regime == Regime.NEGATIVE:
            fN = -Fs / (c - mu * s)
            return fN, mu * fN
        if regime == Regime.STICK:
            ddu2 = -(dphi * dphi * c + ddphi * s)
            fT = self.J * ddu2 + self.fL
            return fT * s / c - Fs / c, fT
        raise InputError(f"`regime` must be POSITIVE, NEGATIVE or STICK, got {regime!r}")

    def rod_layout(self):
        """``(u10, delta, side)``: one rod, its stator amplitude, phase 0, tip towards ``+x``.

        The layout the energy audit (:mod:`moreau.analysis.energy`) reads;
        :class:`~moreau.scenes.bidirectional_drive.BidirectionalDrive` gives two rods.
        """
        return np.array([self.u10]), np.zeros(1), np.ones(1)

    def shapes(self, q, t=0.0):
        """The stator's hinge, the rod (``q[0]`` [rad]) and the rotor (``q[1]`` [m]) at ``t`` [s]."""
        return rod_drive_shapes(self, q, t, rods=[(0, 1.0)], rotor=1)

    def painleve_margin(self, phi):
        """``1 - mu tan(phi)``; the contact problem is well posed only where it is > 0."""
        return 1.0 - float(self.mu[0]) * np.tan(phi)

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def slip_velocity(self, q, v):
        """Tangential relative velocity ``u2' + sin(phi) phi'`` (defined also for mu = 0)."""
        return v[1] + math.sin(q[0]) * v[0]

    def rest_state(self):
        """State at ``tau = 0`` with the rod in contact and everything at rest."""
        return np.array([self.phi0, 0.0]), np.array([0.0, 0.0])

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        # the parameters, then the memory of the last angle's and phase's sines and
        # cosines (PHI_MEMO, PHASE_MEMO)
        par = np.array([self.J, self.P, self.u10, self.fL, self.sin_phi0, self.fp,
                        *MEMO_SLOTS, *MEMO_SLOTS], dtype=np.float64)
        return CompiledModel(one_rod_mass, _forces, _contacts, _drift, par, 2, 1, True, True, gaps=_gaps)

    # -- units ------------------------------------------------------------------
    #: ``q = (phi, u2)``: the rod angle is in rad
    angle_coordinates = (0,)
    #: what each coordinate is, in the names of ``to_si``'s extras (a run's sidecar)
    coordinate_names = ("phi", "x2")

    def to_si(self, result):
        """SI time histories of a :class:`SimulationResult` of this scene.

        Returns a dict with the keys every scene gives
        (:data:`moreau.model.units.COMMON_KEYS`): ``t`` [s], ``q`` (n, 2) =
        (rod angle [rad], rotor displacement [m]), ``v`` (n, 2) [rad/s, m/s],
        ``force_N``, ``force_T`` (n, 1) [N], ``slip_velocity`` (n, 1) [m/s],
        ``gap`` (n, 1) [m], ``regime`` (n, 1) codes; and the drive's named
        coordinates: ``x2`` rotor displacement [m], ``v2`` rotor velocity
        [m/s], ``phi`` rod angle [rad], each (n,).

        Examples
        --------
        >>> from moreau.integrators import simulate
        >>> s = FrictionDrive(frequency=185.0)
        >>> si = s.to_si(simulate(s, (0.0, 1.0), *s.rest_state(), "event-driven"))
        >>> si["q"].shape[1], si["force_N"].shape[1], bool((si["x2"] == si["q"][:, 1]).all())
        (2, 1, True)
        """
        si = self._si_histories(result)
        si.update(x2=si["q"][:, 1].copy(), v2=si["v"][:, 1].copy(), phi=si["q"][:, 0].copy())
        return si


# -- compiled model (moreau.compiled); par: J, P, u10, fL, sin_phi0, fp, then the memory of
# memo_sincos: angle phi, sin, cos; phase tau, sin, cos -----------------------------------
PHI_MEMO = 6
PHASE_MEMO = 9


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    s, c = memo_sincos(par, PHI_MEMO, q[0])
    ct = memo_sincos(par, PHASE_MEMO, t)[1]
    rod_forces(D, 0, par[1], par[4], par[2], s, c, ct, need_jac)
    # the preload's torque f_p cos(phi) (module docstring); + 0.0 without one
    D[0, 0] += par[5] * c
    if need_jac:
        D[0, 1] -= par[5] * s
    D[1, 0] = -par[3]


@njit(cache=True)
def _gaps(par, q, t, G):
    s = memo_sincos(par, PHI_MEMO, q[0])[0]
    G[0, 0] = rod_gap(par[4], par[2], s, memo_sincos(par, PHASE_MEMO, t)[1])


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    s, c = memo_sincos(par, PHI_MEMO, q[0])
    st, ct = memo_sincos(par, PHASE_MEMO, t)
    if need_gap:
        G[0, 0] = rod_gap(par[4], par[2], s, ct)
    rod_rows(G, 0, 0, 1, 2, 1.0, par[2], s, c, st, need_T)


@njit(cache=True)
def _drift(par, q, v, t, Dr):
    w2 = v[0] * v[0]
    s, c = memo_sincos(par, PHI_MEMO, q[0])
    Dr[0, 0] = w2 * s - par[2] * memo_sincos(par, PHASE_MEMO, t)[1]
    Dr[0, 1] = w2 * c


def params_from_kwargs(**kwargs):
    """Build :class:`FrictionDriveParams` from keyword arguments, ignoring ``None`` values."""
    return FrictionDriveParams.from_kwargs(**kwargs)


class FrictionDriveCase(DriveCase):
    """The friction drive's steady state; reference: the walker's steady state (contact segments in closed form)."""

    mj_tolerance = 5e-3
    ref_scheme = "event-driven"
    # the compiled steady state is cheap: go far enough to show the plateaus
    default_steps = (50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000)
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
    tight_rtol = 1e-13
    headline_name = "displacement per period"
    projection = True

    scene_class = FrictionDrive

    def reference(self, rtol):
        ss = find_steady_state(self.scene, rtol=rtol, statistical=False)
        return ss.displacement_per_period, regime_switches(ss.regimes)

    def _tight(self):
        if self._ref is None:
            ss = find_steady_state(self.scene, rtol=self.tight_rtol, statistical=False)
            q = np.array([ss.state0[0], 0.0])
            v = np.array(ss.state0[1:])
            tau_s = float(getattr(ss, "section_tau", 0.0) or 0.0)
            if tau_s > 0.0:
                # carry the periodic state from the section to tau = 2 pi = 0
                r = simulate(self.scene, (tau_s, TWO_PI), q, v, "event-driven", rtol=1e-12)
                q, v = np.array([r.q[-1, 0], 0.0]), r.v[-1].copy()
            grid_run = simulate(self.scene, (0.0, TWO_PI), q, v, "event-driven", rtol=1e-12,
                                samples_per_period=GRID)
            grid = np.linspace(0.0, TWO_PI, GRID + 1)
            idx = np.searchsorted(grid_run.t, grid - 1e-12)
            if np.max(np.abs(grid_run.t[idx] - grid)) > 1e-9:
                raise MoreauError("event-driven samples are not on the comparison grid")
            self._ref = dict(q0=q, v0=v, grid=grid_run.q[idx, 1])
        return self._ref

    def measure(self, n, theta, lcp, out):
        if lcp is not None:
            return super().measure(n, theta, lcp, out)
        _, ss = out
        # the trajectory: one period of the same scheme from the reference's periodic state
        res = self.run_mj(n, theta, None)
        return self._trajectory_error(res), regime_switches(ss.regimes), ss.mode


register_scene(SceneEntry(
    name="friction-drive",
    factory=FrictionDrive,
    parameters=parameters_of(FrictionDriveParams, extra=(FREQUENCY,)),
    description="the paper's friction drive of a piezoelectric motor (steady state)",
    case=FrictionDriveCase,
    reference="friction-drive-walker",
    default=True,
))
