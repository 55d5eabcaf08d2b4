"""The friction drive with its stator driven by a voltage through a piezo stack.

The paper's friction drive (:mod:`moreau.scenes.friction_drive`) prescribes
the stator displacement ``x1 = x10 (1 - cos w t)`` and names the piezo
stack's hysteresis and saturation as future work. Here the voltage ``U(t)``
is prescribed instead; the stack turns it into a free displacement with
saturation and rate-independent hysteresis; the stator is a mass on the
stack's spring and damper, so the stroke depends on the drive frequency
near the stator's resonance; and the rod's contact force acts back on the
stator (two-way coupling: the stator is a degree of freedom and the contact
Jacobian has a stator column).

Why Bouc–Wen, not Prandtl–Ishlinskii
------------------------------------
Bouc–Wen's hysteresis is one smooth scalar ODE state driven by the input's
rate, which fits both the time-stepping schemes and the generic event-driven
solver without event detection of the operators' play switches. With
exponent 1 its solution is in closed form on every monotone piece of the
input (:mod:`moreau.scenes._piezo_stack`), so for a prescribed periodic
voltage the periodic loop is known exactly: the hysteresis enters the
equations of motion as a known function of time, exact and cheap in the
compiled model, and identification from a measured loop is a least-squares
fit of four numbers. A Prandtl–Ishlinskii operator would need tens of
play operators (and their weights) for the same smooth loop.

Stack model (Low and Guo's form of Bouc–Wen)
--------------------------------------------
Voltage ``U = U_pp (1 - c(tau)) / 2`` with a unit waveform ``c`` (sine,
smoothed triangle, smoothed square; :func:`moreau.scenes._piezo_stack.waveform`),
saturated ``U~ = U_sat tanh(U / U_sat)``, hysteresis ``h`` with
``h' = alpha d U~' - beta |U~'| h - gamma U~' |h|`` and free displacement

    x_p(t) = d U~(t) - h(t) - x_p0,

the periodic loop's value at ``U = 0`` taken out (``x_p0``), so that the rod
touches the rotor at ``phi0`` with the stator at rest at zero voltage. The
voltage is prescribed, so ``h`` depends on it alone; the scene uses the
periodic loop (the stack driven for long), which makes the forcing exactly
``2 pi`` periodic.

Derivation
----------
Coordinates ``(phi, x2, x1)``: rod angle, rotor, stator. As in the paper
(the stator block ``m1`` now free, on the stack's spring ``k1`` and damper ``c1``)

    T = 1/2 (m + m1) x1'^2 + 1/2 m2 x2'^2 + 1/6 m l^2 phi'^2 + 1/2 m l x1' phi' cos phi
    V = 1/2 k l^2 (sin phi0 - sin phi)^2,   F_stack = k1 (x_p(t) - x1) - c1 x1'

plus the friction drive's preload ``V_p = F_p l (sin phi0 - sin phi)`` (a soft
pre-compressed spring pressing the tip on with ``F_p``), gap
``g_N = l sin phi0 - l sin phi - x1`` and slip ``g_T = x2 - l cos phi``.
Lagrange's equations (``d/dt dT/dx1' = (m + m1) x1'' + 1/2 m l (phi'' cos phi
- phi'^2 sin phi)``, ``d/dt dT/dphi' - dT/dphi = 1/3 m l^2 phi'' + 1/2 m l x1''
cos phi``) in ``tau = w t``, ``u = x / l``, forces over ``m l w^2``, with
``J = m2 / m``, ``J1 = m1 / m``, ``P = k / (m w^2)``, ``K1 = k1 / (m w^2)``,
``C1 = c1 / (m w)``, ``f_p = F_p / (m l w^2)`` and ``w(tau) = x_p / l``, read ``M q'' = h + WN^T f_N + WT^T f_T``
for ``q = (phi, u2, u1)``::

    M  = [[1/3, 0, 1/2 cos phi], [0, J, 0], [1/2 cos phi, 0, 1 + J1]]
    h  = (P cos phi (sin phi0 - sin phi) + f_p cos phi,  -f_L,
          1/2 phi'^2 sin phi + K1 (w - u1) - C1 u1')
    WN = (-cos phi, 0, -1),  wN = 0,       WT = (sin phi, 1, 0),  wT = 0
    wNbar = phi'^2 sin phi,                wTbar = phi'^2 cos phi

The normal contact force pushes the stator down (``WN`` has ``-1`` in its
column): the two-way coupling.

Stator dynamics switched off (``stator="rigid"``) is the limit ``k1 -> oo``:
``u1 = w(tau)`` is prescribed, ``q = (phi, u2)`` and the equations are the
friction drive's with ``u1`` replaced by ``w``::

    h  = (P cos phi (sin phi0 - sin phi) - 1/2 w'' cos phi + f_p cos phi, -f_L)
    WN = (-cos phi, 0),  wN = -w',  wNbar = phi'^2 sin phi - w''

With ``alpha = 0`` (no hysteresis), ``u_sat = inf`` and a sine,
``w = d U_pp / (2 l) (1 - cos tau)``: the friction drive with ``x10 = d U_pp / 2``
and the same preload.

The paper's drive touches the rotor without force at the bottom of the
stroke; a compliant stator then leaves the rotor there in brief flights
every period. The preload (0.01 N by default) keeps the tip pressed on.

Identification and limits
-------------------------
:func:`identify_hysteresis` fits ``d, alpha, beta, gamma`` (and the offset,
optionally ``U_sat``) to a measured loop by ``scipy.optimize.least_squares``,
the model evaluated exactly along the samples from the state the loop
returns to. The scene's waveforms rise once and fall once per period, so
the loop has no minor loops; the hysteresis depends on the voltage alone
(the stack's force does not feed back into ``h``), as in Low and Guo's model.
"""

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.integrate import quad
from scipy.optimize import least_squares

from .. import _validate as V
from ..compiled import CompiledModel
from ..errors import InputError, MoreauError
from ..analysis.cases import DriveCase
from .friction_drive.rod import (PRELOAD, ROD_RESTITUTION, ROTOR_LOAD, OneRod, RodParams,
                                  one_rod_mass, rod_rows)
from ._piezo_stack import (WAVEFORMS, bouc_wen_branch, loop_top, periodic_pass, saturate,
                           steady_loop_ends, waveform)
from ..model.params import MASS, NONNEGATIVE, POSITIVE, param
from ..model.drawing import rod_drive_shapes
from ..model.units import DriveUnits
from ..model.compiled_scene import CompiledScene
from ..model.scene import params_with
from ..model.registry import Parameter, SceneEntry, parameters_of, register_scene

__all__ = ["PiezoDriveParams", "PiezoDrive", "HysteresisFit", "identify_hysteresis"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class PiezoDriveParams(RodParams):
    """Physical parameters of the voltage-driven friction drive, in SI units.

    The rod, rotor, spring, friction, load, restitution and preload as in
    :class:`~moreau.scenes.friction_drive.FrictionDriveParams`, and the stator's
    piezo stack.

    {attributes}

    Examples
    --------
    >>> p = PiezoDriveParams(gain=4e-8, alpha=0.0, u_sat=math.inf, preload=0.0)
    >>> round(p.gain * p.voltage / 2, 15)   # the friction drive's x10 [m]
    2e-06
    """

    load: float = ROTOR_LOAD(0.0)
    restitution: float = ROD_RESTITUTION(0.0)
    preload: float = PRELOAD(0.01, note="0: the paper's drive, which touches without force at "
                                        "zero voltage.")
    m1: float = MASS(2.0e-3, "Stator mass")
    k1: float = param(3.2e5, "N/m", POSITIVE, "Stack stiffness holding the stator",
                      "Resonance ``sqrt(k1 / (m + m1)) / 2 pi``, 2 kHz by default.")
    c1: float = param(15.0, "N s/m", NONNEGATIVE, "Stack damping")
    gain: float = param(6.0e-8, "m/V", POSITIVE, "Stack gain ``d``: free displacement per volt")
    voltage: float = param(100.0, "V", POSITIVE, "Peak voltage ``U_pp``",
                           "The voltage runs between 0 and ``U_pp``.")
    alpha: float = param(0.3, "", doc="Bouc–Wen weight of the hysteresis",
                         note="In [0, 1); 0 switches it off.")
    beta: float = param(0.02, "1/V", POSITIVE, "Bouc–Wen shape ``beta``")
    gamma: float = param(0.005, "1/V", doc="Bouc–Wen shape ``gamma``",
                         note="``|gamma| <= beta`` (a bounded loop).")
    u_sat: float = param(150.0, "V", doc="Saturation voltage",
                         note="> 0; ``inf`` for a linear stack.")

    sweepable = ("frequency", "m", "m2", "k", "length", "phi0", "mu", "load", "restitution",
                 "preload", "m1", "k1", "c1", "gain", "voltage", "alpha", "beta", "gamma",
                 "u_sat", "smoothing")

    def __post_init__(self):
        super().__post_init__()
        a = V.finite_scalar("alpha", self.alpha)
        if not 0.0 <= a < 1.0:
            raise InputError(f"`alpha` must be in [0, 1), got {a!r}")
        object.__setattr__(self, "alpha", a)
        g = V.finite_scalar("gamma", self.gamma)
        if abs(g) > self.beta:
            raise InputError(f"`gamma` must satisfy |gamma| <= beta = {self.beta!r} 1/V "
                             f"(a bounded loop), got {g!r}")
        object.__setattr__(self, "gamma", g)
        us = self.u_sat
        if not (isinstance(us, (int, float, np.floating)) and not isinstance(us, bool)
                and us == math.inf):
            us = V.positive("u_sat", us)
        object.__setattr__(self, "u_sat", float(us))


PIEZO_DEFAULTS = PiezoDriveParams()


# -- the stack's free displacement, dimensionless ------------------------------------
# par: 0 J, 1 P, 2 sin phi0, 3 fL, 4 A = d U_pp / l, 5 alpha, 6 b = beta U_pp,
# 7 g = gamma U_pp, 8 sigma = U_sat / U_pp (0: none), 9 waveform, 10 smoothing,
# 11 eta_lo, 12 eta_hi, 13 vmax, 14 J1, 15 K1, 16 C1, 17 f_p

@njit(cache=True)
def _stack(par, t):
    # (v, v', v'') of the saturated input and (eta, deta/dv, d2eta/dv2) on the periodic loop
    c, dc, ddc = waveform(int(par[9]), par[10], t)
    v, dv, ddv = saturate(par[8], 0.5 - 0.5 * c, -0.5 * dc, -0.5 * ddc)
    if t % TWO_PI < math.pi:
        eta, e1, e2 = bouc_wen_branch(par[11], v, par[5], par[6], par[7])
    else:
        eta, e1, e2 = bouc_wen_branch(par[12], v - par[13], par[5], par[6], par[7])
    return v, dv, ddv, eta, e1, e2


@njit(cache=True)
def _stroke(par, t):
    # (w, w', w'') of the free displacement w = A (v - eta + eta_lo)
    v, dv, ddv, eta, e1, e2 = _stack(par, t)
    A = par[4]
    return A * (v - eta + par[11]), A * (1.0 - e1) * dv, A * ((1.0 - e1) * ddv - e2 * dv * dv)


# -- compiled model, stator a degree of freedom: q = (phi, u2, u1) ---------------------

@njit(cache=True)
def _mass_dyn(par, q, M):
    M[0, 0] = 1.0 / 3.0
    M[1, 1] = par[0]
    M[2, 2] = 1.0 + par[14]
    M[0, 2] = 0.5 * math.cos(q[0])
    M[2, 0] = M[0, 2]


@njit(cache=True)
def _forces_dyn(par, q, v, t, D, need_jac):
    s, c = math.sin(q[0]), math.cos(q[0])
    spring = par[2] - s
    w = _stroke(par, t)[0]
    D[0, 0] = par[1] * c * spring + par[17] * c
    D[1, 0] = -par[3]
    D[2, 0] = 0.5 * v[0] * v[0] * s + par[15] * (w - q[2]) - par[16] * v[2]
    if need_jac:
        D[0, 1] = par[1] * (-s * spring - c * c) - par[17] * s
        D[2, 1] = 0.5 * v[0] * v[0] * c
        D[2, 3] = -par[15]
        D[2, 4] = v[0] * s
        D[2, 6] = -par[16]


@njit(cache=True)
def _gaps_dyn(par, q, t, G):
    G[0, 0] = par[2] - math.sin(q[0]) - q[2]


@njit(cache=True)
def _contacts_dyn(par, q, t, G, need_gap, need_T):
    s = math.sin(q[0])
    if need_gap:
        G[0, 0] = par[2] - s - q[2]
    G[0, 3] = -math.cos(q[0])
    G[0, 5] = -1.0
    if need_T:
        G[0, 6] = s
        G[0, 7] = 1.0


@njit(cache=True)
def _drift_dyn(par, q, v, t, Dr):
    w2 = v[0] * v[0]
    Dr[0, 0] = w2 * math.sin(q[0])
    Dr[0, 1] = w2 * math.cos(q[0])


# -- compiled model, rigid stator u1 = w(tau): q = (phi, u2) ----------------------------

@njit(cache=True)
def _forces_rig(par, q, v, t, D, need_jac):
    s, c = math.sin(q[0]), math.cos(q[0])
    ddw = _stroke(par, t)[2]
    spring = par[2] - s
    D[0, 0] = par[1] * c * spring - 0.5 * ddw * c + par[17] * c
    D[1, 0] = -par[3]
    if need_jac:
        D[0, 1] = par[1] * (-s * spring - c * c) + 0.5 * ddw * s - par[17] * s


@njit(cache=True)
def _gaps_rig(par, q, t, G):
    G[0, 0] = par[2] - math.sin(q[0]) - _stroke(par, t)[0]


@njit(cache=True)
def _contacts_rig(par, q, t, G, need_gap, need_T):
    s = math.sin(q[0])
    w, dw, _ = _stroke(par, t)
    if need_gap:
        G[0, 0] = par[2] - s - w
    # the friction drive's rod rows, the stator's rate dw given as u10 st = dw * 1
    rod_rows(G, 0, 0, 1, 2, 1.0, dw, s, math.cos(q[0]), 1.0, need_T)


@njit(cache=True)
def _drift_rig(par, q, v, t, Dr):
    w2 = v[0] * v[0]
    Dr[0, 0] = w2 * math.sin(q[0]) - _stroke(par, t)[2]
    Dr[0, 1] = w2 * math.cos(q[0])


STATORS = ("dynamic", "rigid")


class PiezoDrive(OneRod, DriveUnits, CompiledScene):
    """The friction drive with a voltage-driven piezo stack under a mass–spring–damper stator.

    Coordinates ``q = (phi, u2, u1)`` (rod angle, rotor, stator; ``q = (phi,
    u2)`` for a rigid stator), time ``tau = w t``; one frictional contact.
    See the module docstring for the model and its derivation; the model
    methods (``mass``, ``forces``, ``gaps``, ...) evaluate the compiled model,
    where the equations are written once
    (:class:`~moreau.model.compiled_scene.CompiledScene`).

    Parameters
    ----------
    params : PiezoDriveParams, optional
        Physical parameters; :class:`PiezoDriveParams`' defaults if omitted.
    frequency : float
        Drive frequency ``f`` [Hz], > 0.
    waveform : {"sine", "triangle", "square"}
        Voltage waveform (triangle and square smoothed, see ``smoothing``).
    smoothing : float
        In (0, 1): the triangle's corner rounding (``r = 1 - smoothing``) or
        the square's edge duration (``k = 1 / smoothing``); unused for a sine.
    stator : {"dynamic", "rigid"}
        ``"rigid"`` switches the stator dynamics off (the stator follows the
        stack's free displacement).
    **overrides
        Individual parameters replacing those of ``params``.

    Examples
    --------
    >>> s = PiezoDrive(frequency=1400.0)
    >>> s.ndof, s.ncontacts, round(s.resonance_hz(), -1)
    (3, 1, 2000.0)
    >>> q0, v0 = s.initial_state()
    >>> abs(float(s.gaps(q0, 0.0)[0])) < 1e-15   # at rest on the rotor, the stack pushed down
    True
    """

    name = "piezo-drive"
    Params = PiezoDriveParams
    period = TWO_PI
    cyclic_coordinates = (1,)
    angle_coordinates = (0,)

    def __init__(self, params=None, frequency=1400.0, waveform="sine", smoothing=0.2,
                 stator="dynamic", **overrides):
        self.params = p = params_with(self.Params, params, overrides)
        self.frequency = V.positive("frequency", frequency)
        if waveform not in WAVEFORMS:
            raise InputError(f"`waveform` must be one of {', '.join(map(repr, WAVEFORMS))}; "
                             f"got {waveform!r}")
        self.smoothing = V.in_open_interval("smoothing", smoothing, 0.0, 1.0)
        if stator not in STATORS:
            raise InputError(f"`stator` must be 'dynamic' or 'rigid', got {stator!r}")
        self.waveform, self.stator = waveform, stator
        self.omega = TWO_PI * self.frequency
        w = self.omega
        self.J = p.m2 / p.m
        self.J1 = p.m1 / p.m
        self.P = p.k / (p.m * w * w)
        self.K1 = p.k1 / (p.m * w * w)
        self.C1 = p.c1 / (p.m * w)
        self.A = p.gain * p.voltage / p.length
        self.force_scale = p.m * p.length * w * w
        self.fL = p.load / self.force_scale
        self.phi0 = p.phi0
        self.sin_phi0 = math.sin(p.phi0)
        #: dimensionless preload ``f_p = F_p / (m l w^2)``
        self.fp = p.preload / self.force_scale
        self.mu = np.array([p.mu])
        self.restitution = np.array([p.restitution])
        self.sigma = 0.0 if p.u_sat == math.inf else p.u_sat / p.voltage
        self.b, self.g = p.beta * p.voltage, p.gamma * p.voltage
        self.vmax = float(loop_top(self.sigma))
        self.eta_lo, self.eta_hi = steady_loop_ends(self.vmax, p.alpha, self.b, self.g)
        self._par = np.array([self.J, self.P, self.sin_phi0, self.fL, self.A, p.alpha, self.b,
                              self.g, self.sigma, float(WAVEFORMS[waveform]), self.smoothing,
                              self.eta_lo, self.eta_hi, self.vmax, self.J1, self.K1, self.C1,
                              self.fp])
        half = 0.5 * self.A * (self.vmax - self.eta_hi + self.eta_lo)
        if not 2.0 * half < self.sin_phi0:
            raise InputError(
                f"the stack's free stroke {2 * half * p.length!r} m (`gain` * `voltage` through "
                f"saturation and hysteresis) must be < length*sin(phi0) = "
                f"{p.length * self.sin_phi0!r} m so that the rod stays above the horizontal")
        #: velocity scale of the motion (half the quasi-static stroke), for tolerances
        self.velocity_scale = half
        self.ndof = 3 if stator == "dynamic" else 2
        self.coordinate_names = ("phi", "x2", "x1")[:self.ndof]

    def __repr__(self):
        return (f"PiezoDrive(frequency={self.frequency!r}, waveform={self.waveform!r}, "
                f"smoothing={self.smoothing!r}, stator={self.stator!r}, params={self.params!r})")

    # -- the stack ------------------------------------------------------------------
    def resonance_hz(self):
        """The stator's undamped natural frequency ``sqrt(k1 / (m + m1)) / 2 pi`` [Hz]."""
        p = self.params
        return math.sqrt(p.k1 / (p.m + p.m1)) / TWO_PI

    def voltage(self, tau):
        """The drive voltage ``U(tau)`` [V] (array in, array out)."""
        tau = np.asarray(tau, dtype=float)
        c = np.array([waveform(WAVEFORMS[self.waveform], self.smoothing, float(t))[0]
                      for t in tau.ravel()]).reshape(tau.shape)
        return 0.5 * self.params.voltage * (1.0 - c)

    def free_stroke(self, tau):
        """``(w, w', w'')``: the stack's free displacement over ``l`` and its ``tau`` derivatives."""
        tau = np.asarray(tau, dtype=float)
        out = np.array([_stroke(self._par, float(t)) for t in tau.ravel()])
        return tuple(out[:, i].reshape(tau.shape) for i in range(3))

    def hysteresis_loop(self, n=1001):
        """``(U [V], x_p [m])`` over one period at ``n`` equally spaced times: the stack's loop."""
        tau = np.linspace(0.0, TWO_PI, V.positive_int("n", n))
        return self.voltage(tau), self.free_stroke(tau)[0] * self.params.length

    def stroke(self):
        """Peak-to-peak free displacement of the stack [m] (quasi-static stroke)."""
        return 2.0 * self.velocity_scale * self.params.length

    def loop_area(self):
        """Area enclosed by the displacement–voltage loop ``x_p(U)`` [V m].

        ``oint x_p dU = -d U_pp^2 oint eta dy`` (the single-valued ``v(y)``
        encloses nothing); ``eta`` on each branch is the closed form, as a
        function of ``y = U / U_pp``, integrated by adaptive quadrature.
        """
        p = self.params
        alpha, b, g, sig, vm = p.alpha, self.b, self.g, self.sigma, self.vmax

        def sat(y):
            return saturate(sig, y, 0.0, 0.0)[0]

        def rising(y):
            return bouc_wen_branch(self.eta_lo, sat(y), alpha, b, g)[0]

        def falling(y):
            return bouc_wen_branch(self.eta_hi, sat(y) - vm, alpha, b, g)[0]

        opts = dict(limit=200, epsabs=0.0, epsrel=1e-13)
        up = quad(rising, 0.0, 1.0, **opts)[0]
        down = quad(falling, 0.0, 1.0, **opts)[0]
        return p.gain * p.voltage ** 2 * (up - down)

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def amplification(self, harmonics=7):
        """Largest dynamic amplification ``|H(k f)|`` of the stator over the first harmonics.

        ``H(f) = 1 / (1 - r^2 + 2 i zeta r)`` with ``r = f / f_s``; 1 for a rigid stator.
        """
        if self.ndof == 2:
            return 1.0
        p = self.params
        zeta = p.c1 / (2.0 * math.sqrt(p.k1 * (p.m + p.m1)))
        r = np.arange(1, V.positive_int("harmonics", harmonics) + 1) * (
            self.frequency / self.resonance_hz())
        return float(np.max(1.0 / np.abs(1.0 - r * r + 2j * zeta * r)))

    def tip_velocity(self, tau):
        """Horizontal tip speed ``sin(phi) phi'`` on the contact manifold over the free stroke.

        ``sin phi = sin phi0 - w``, ``phi' = -w' / cos phi``; scaled by
        :meth:`amplification` for a dynamic stator: a bound on how fast the
        tip drives the rotor (the steady-state solver's plausibility check).
        """
        w, dw, _ = self.free_stroke(tau)
        s = self.sin_phi0 - w
        return s * dw / np.sqrt(1.0 - s * s) * self.amplification()

    def slip_velocity(self, q, v):
        """Tangential relative velocity ``u2' + sin(phi) phi'`` (defined also for mu = 0)."""
        return v[1] + math.sin(q[0]) * v[0]

    def rest_state(self):
        """State at ``tau = 0``: at rest in static equilibrium at zero voltage, rod on the rotor.

        The contact force ``f_N = f_p + P (sin phi0 - sin phi)`` balances the
        preload and the rod's spring and pushes the stator down,
        ``K1 u1 = -f_N``, with the gap closed (``sin phi = sin phi0 - u1``):
        ``u1 = -f_p / (K1 + P)`` (``u1 = 0`` and ``phi = phi0`` for a rigid
        stator). Every waveform starts with zero voltage rate, so this state
        is on the contact manifold.
        """
        q, v = np.zeros(self.ndof), np.zeros(self.ndof)
        u1 = -self.fp / (self.K1 + self.P) if self.ndof == 3 else 0.0
        q[0] = math.asin(self.sin_phi0 - u1)
        if self.ndof == 3:
            q[2] = u1
        return q, v

    def shapes(self, q, t=0.0):
        """The stator's hinge (moving with the stack), the rod (``q[0]`` [rad]) and the rotor (``q[1]`` [m])."""
        return rod_drive_shapes(self, q, t, rods=[(0, 1.0)], rotor=1)

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        if self.ndof == 3:
            return CompiledModel(_mass_dyn, _forces_dyn, _contacts_dyn, _drift_dyn, self._par, 3,
                                 1, False, True, gaps=_gaps_dyn)
        return CompiledModel(one_rod_mass, _forces_rig, _contacts_rig, _drift_rig, self._par, 2, 1,
                             True, True, gaps=_gaps_rig)

    def to_si(self, result):
        """SI time histories of a :class:`SimulationResult` of this scene.

        The keys every scene gives (:data:`moreau.model.units.COMMON_KEYS`;
        ``q`` = (rod angle [rad], rotor [m], stator [m])) and the named
        coordinates ``phi`` [rad], ``x2`` [m], ``v2`` [m/s] and, with a
        dynamic stator, ``x1`` [m], ``v1`` [m/s].
        """
        si = self._si_histories(result)
        si.update(x2=si["q"][:, 1].copy(), v2=si["v"][:, 1].copy(), phi=si["q"][:, 0].copy())
        if self.ndof == 3:
            si.update(x1=si["q"][:, 2].copy(), v1=si["v"][:, 2].copy())
        return si


# -- identification -------------------------------------------------------------------

@dataclass(frozen=True)
class HysteresisFit:
    """Bouc–Wen parameters fitted to a measured loop (SI units).

    Attributes
    ----------
    gain, alpha, beta, gamma : float
        As in :class:`PiezoDriveParams` ([m/V], [-], [1/V], [1/V]).
    offset : float
        Displacement at zero stack input on the fitted loop's start [m].
    u_sat : float
        Saturation voltage [V] (given, fitted, or ``inf``).
    rms_residual : float
        Root mean square of the displacement residuals [m].
    nfev : int
        Model evaluations of the fit.
    """

    gain: float
    alpha: float
    beta: float
    gamma: float
    offset: float
    u_sat: float
    rms_residual: float
    nfev: int


def _fit_model(theta, y, fit_sat, sig_known):
    # x / xs = x0 + dh (v - eta): theta = (dh, alpha, log b, atanh(g / b), x0[, log sigma])
    dh, alpha, lb, rho, x0 = theta[:5]
    b = math.exp(lb)
    g = b * math.tanh(rho)
    sig = math.exp(theta[5]) if fit_sat else sig_known
    v = np.array([saturate(sig, float(t), 0.0, 0.0)[0] for t in y])
    eta = periodic_pass(v, alpha, b, g, np.empty_like(v))
    return x0 + dh * (v - eta)


def identify_hysteresis(voltage, displacement, u_sat=math.inf, guess=None):
    """Fit the Bouc–Wen stack model to a measured loop by least squares.

    The model is the scene's: ``x = x0 + d (U~ - h)`` with ``U~ = U_sat
    tanh(U / U_sat)`` and Bouc–Wen ``h`` (exponent 1), evaluated exactly
    along the samples (closed form between consecutive samples) from the
    state the loop returns to. The samples must be one closed loop in time
    order, the input monotone between consecutive samples.

    Parameters
    ----------
    voltage, displacement : array_like
        Samples ``U_k`` [V] and ``x_k`` [m] of one period, at least 8, finite.
    u_sat : float or "fit"
        Known saturation voltage [V] (``inf``: none), or ``"fit"`` to fit it too.
    guess : dict, optional
        Starting values of ``gain``, ``alpha``, ``beta``, ``gamma`` (and
        ``u_sat``); a linear fit's slope, 0.2, ``2 / max|U|``, 0 (and
        ``2 max|U|``) otherwise.

    Returns
    -------
    HysteresisFit

    Examples
    --------
    >>> s = PiezoDrive()
    >>> U, x = s.hysteresis_loop(201)
    >>> fit = identify_hysteresis(U[:-1], x[:-1], u_sat=150.0)
    >>> round(fit.alpha, 6), round(fit.beta, 8), round(fit.gamma, 8)
    (0.3, 0.02, 0.005)
    """
    U = V.finite_array("voltage", voltage, ndim=1)
    x = V.finite_array("displacement", displacement, ndim=1)
    if U.shape != x.shape:
        raise InputError(f"`voltage` and `displacement` must have the same length, got "
                         f"{U.size} and {x.size}")
    if U.size < 8:
        raise InputError(f"`voltage` must hold at least 8 samples of the loop, got {U.size}")
    Us = float(np.max(np.abs(U)))
    if Us == 0.0:
        raise InputError("`voltage` must not be identically zero")
    fit_sat = isinstance(u_sat, str)
    if fit_sat and u_sat != "fit":
        raise InputError(f"`u_sat` must be a voltage > 0, inf or 'fit', got {u_sat!r}")
    sig = 0.0
    if not fit_sat and u_sat != math.inf:
        sig = V.positive("u_sat", u_sat) / Us
    guess = dict(guess or {})
    y = U / Us
    xs = float(np.max(np.abs(x - x.mean()))) or 1.0
    slope = float(np.polyfit(U, x, 1)[0])
    d0 = float(guess.pop("gain", slope))
    a0 = float(guess.pop("alpha", 0.2))
    b0 = float(guess.pop("beta", 2.0 / Us)) * Us
    g0 = float(guess.pop("gamma", 0.0)) * Us
    s0 = float(guess.pop("u_sat", 2.0 * Us)) / Us
    if guess:
        raise InputError(f"`guess` has unknown keys {sorted(guess)}; known: gain, alpha, beta, "
                         f"gamma, u_sat")
    if not (b0 > 0.0 and abs(g0) < b0 and d0 != 0.0 and s0 > 0.0):
        raise InputError("`guess` must have gain != 0, beta > 0, |gamma| < beta and u_sat > 0")
    theta0 = [d0 * Us / xs, a0, math.log(b0), math.atanh(g0 / b0), 0.0]
    if fit_sat:
        theta0.append(math.log(s0))
    target = x / xs
    # the offset of the loop's start: x0 of the starting guess by its mean residual
    theta0[4] = float(np.mean(target - _fit_model(np.array(theta0), y, fit_sat, sig)))

    def residual(theta):
        return _fit_model(theta, y, fit_sat, sig) - target

    res = least_squares(residual, np.array(theta0), method="trf", x_scale="jac",
                        xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=2000)
    if not np.all(np.isfinite(res.fun)):
        raise MoreauError("the hysteresis fit diverged (non-finite residuals)")
    dh, alpha, lb, rho, x0 = res.x[:5]
    b = math.exp(lb)
    sat = math.exp(res.x[5]) * Us if fit_sat else (math.inf if sig == 0.0 else sig * Us)
    return HysteresisFit(gain=dh * xs / Us, alpha=float(alpha), beta=b / Us,
                         gamma=b * math.tanh(rho) / Us, offset=x0 * xs, u_sat=sat,
                         rms_residual=float(np.sqrt(np.mean(res.fun ** 2))) * xs,
                         nfev=int(res.nfev))


class PiezoDriveCase(DriveCase):
    """The piezo drive's steady state; Moreau–Jean against the generic event-driven reference.

    At 1400 Hz by default: mode NP in steady contact (the generic event-driven
    steady state in about 20 s), where the motor runs forwards at
    1.28e-3 l per period; near 1000 Hz its displacement crosses zero.
    """

    scene_class = PiezoDrive
    default_frequency = 1400.0
    # Moreau-Jean theta = 1 at 1000 steps: 6.5 % off the reference at 1400 Hz (the stator's
    # oscillation under first-order steps)
    mj_tolerance = 0.1

    @staticmethod
    def scale_of(scene):
        return scene.velocity_scale


register_scene(SceneEntry(
    name="piezo-drive",
    factory=PiezoDrive,
    parameters=parameters_of(PiezoDriveParams, extra=(
        Parameter("frequency", "Hz", 1400.0, "drive frequency"),
        Parameter("waveform", "choice", "sine", "voltage waveform: sine, triangle or square"),
        Parameter("smoothing", "", 0.2, "triangle corner / square edge smoothing, in (0, 1)"),
        Parameter("stator", "choice", "dynamic", "dynamic (mass-spring-damper) or rigid"))),
    description="the friction drive driven by a voltage: piezo stack with Bouc-Wen hysteresis "
                "and saturation, stator mass-spring-damper, two-way coupling",
    case=PiezoDriveCase,
))
