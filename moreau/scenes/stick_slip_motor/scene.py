"""Stick–slip motor: the paper's first type of friction drive (its Fig. 1a).

A slider of mass ``m`` is pressed onto a stator by a constant normal force
``N``; the stator vibrates along the direction of motion with a prescribed
displacement ``X s(w t)``. Coulomb friction ``mu`` between them carries the
slider along while it sticks and lets the stator slip back underneath it; an
asymmetric drive therefore moves the slider by a net step every period.

Scales
------
Time ``tau = w t`` (``w = 2 pi f``), so one drive period is ``2 pi``; lengths
in units of the drive amplitude ``X``; forces in ``m X w^2``. The
dimensionless problem has three numbers::

    n  = N   / (m X w^2)    normal force
    fL = F_L / (m X w^2)    load, opposing positive slider motion
    mu                      friction coefficient

and the drive shape ``s(tau)`` (:class:`SineDrive`, :class:`SawtoothDrive`).

Coordinates: ``q = (x, y)``, the slider position along the drive and its
height above the stator surface (the gap; the slider is pressed on by ``n``
and never leaves). The slip velocity is that of the slider relative to the
stator, ``gammaT = dx/dtau - s'(tau)``; positive slip gives the friction
force ``-mu n`` on the slider. In slip the slider acceleration is
``-fL -+ mu n``; in stick it follows the stator, ``x'' = s''``, which is
possible while ``|s'' + fL| <= mu n``.
"""

import bisect
import math
from dataclasses import dataclass

import numpy as np

from numba import njit

from ...compiled import CompiledModel
from ..._validate import finite_scalar, in_open_interval, positive, restitution
from ...errors import InputError
from ...model.params import LOAD, MASS, MU, POSITIVE, RESTITUTION, Declared, param
from ...model.drawing import contact, polygon
from ...model.compiled_scene import CompiledScene
from ...model.units import SIUnits
from ...model.scene import params_with
from ...analysis.cases import GRID, CompareCase, regime_switches
from ...integrators import get_integrator, simulate
from ...model.registry import Parameter, SceneEntry, parameters_of, register_scene
from .._block_on_line import block_contacts, block_mass

__all__ = ["StickSlipMotorParams", "StickSlipMotor", "SineDrive", "SawtoothDrive"]

TWO_PI = 2.0 * math.pi


class _Drive:
    """Shape ``s(tau)`` of the stator displacement, period ``2 pi``, unit amplitude.

    Subclasses implement ``_eval(tau)`` -> ``(s, s', s'')`` on arrays, the
    tuple ``breakpoints`` (points in ``[0, 2 pi)`` where ``s''`` jumps) and
    ``_crossings(level)``: every ``tau`` in ``[0, 2 pi)`` where ``s''``
    crosses or touches ``level`` (a superset is fine).
    """

    name = "drive"
    breakpoints = ()

    def __call__(self, tau):
        """``(s, s', s'')`` at ``tau``; right-continuous where ``s''`` jumps."""
        if isinstance(tau, (float, int, np.floating, np.integer)):
            # one time (the event-driven schemes ask for one per call): a subclass's
            # `_eval` may take the scalar path; np.asarray would make it a 0-d array
            return self._eval(tau)
        return self._eval(np.asarray(tau, dtype=float))

    def acceleration_crossings(self, level):
        """Sorted points of ``[0, 2 pi)`` where ``s''`` crosses or touches ``level``,
        together with the breakpoints."""
        pts = np.concatenate([np.asarray(self._crossings(float(level)), float),
                              np.asarray(self.breakpoints, float)])
        pts = np.mod(pts, TWO_PI)
        pts[pts >= TWO_PI] = 0.0
        return np.unique(pts)

    def acceleration_range(self):
        """``(min s'', max s'')`` over a period."""
        raise NotImplementedError


class SineDrive(_Drive):
    """``s(tau) = sin(tau) + b sin(2 tau + psi)``.

    A pure sinusoid (``b = 0``) is symmetric under ``s(tau + pi) = -s(tau)``,
    which maps every motion onto its mirror image half a period later; without
    a load its periodic steady state therefore has zero net displacement. A
    second harmonic (or a load) breaks the symmetry.

    Parameters
    ----------
    harmonic2 : float
        Relative amplitude ``b`` of the second harmonic, finite.
    phase2 : float
        Its phase ``psi`` [rad], finite.

    Examples
    --------
    >>> d = SineDrive()
    >>> [round(float(x), 12) for x in d(math.pi / 2)]
    [1.0, 0.0, -1.0]
    """

    name = "sine"

    def __init__(self, harmonic2=0.0, phase2=0.0):
        self.b = finite_scalar("harmonic2", harmonic2)
        self.psi = finite_scalar("phase2", phase2)

    def _eval(self, t):
        b, psi = self.b, self.psi
        a2 = 2.0 * t + psi
        s = np.sin(t) + b * np.sin(a2)
        ds = np.cos(t) + 2.0 * b * np.cos(a2)
        dds = -np.sin(t) - 4.0 * b * np.sin(a2)
        return s, ds, dds

    def _jerk(self, t):
        return -np.cos(t) - 8.0 * self.b * np.cos(2.0 * t + self.psi)

    def _crossings(self, level):
        # s'' - level is a trigonometric polynomial of degree 2; with
        # z = exp(i tau) it becomes a quartic whose unit-modulus roots are the
        # crossings. Coefficients of z^0 .. z^4 of 2i z^2 (s'' - level):
        b, psi = self.b, self.psi
        ep, em = np.exp(1j * psi), np.exp(-1j * psi)
        c = np.array([4.0 * b * em, 1.0, -2j * level, -1.0, -4.0 * b * ep], dtype=complex)
        c = c[::-1]  # numpy.roots wants the highest power first
        while len(c) > 1 and c[0] == 0:
            c = c[1:]
        z = np.roots(c) if len(c) > 1 else np.zeros(0)
        # a tangency is a double root, perturbed off the circle by ~sqrt(eps)
        z = z[np.abs(np.abs(z) - 1.0) < 1e-6]
        taus = np.mod(np.angle(z), TWO_PI)
        out = []
        for tau in taus:
            for _ in range(4):
                f = self._eval(tau)[2] - level
                fp = self._jerk(tau)
                if fp == 0.0 or abs(f) < 1e-300:
                    break
                step = f / fp
                if abs(step) > 1e-3:     # near a tangency Newton would wander
                    break
                tau -= step
            out.append(tau)
        return np.array(out, float)

    def acceleration_range(self):
        tau = np.linspace(0.0, TWO_PI, 4097)
        a = self._eval(tau)[2]
        ext = list(self._crossings_of_jerk())
        if ext:
            a = np.concatenate([a, self._eval(np.array(ext))[2]])
        return float(a.min()), float(a.max())

    def _crossings_of_jerk(self):
        # s''' = -cos(t) - 8 b cos(2t + psi) = 0, as a quartic in z as above
        b, psi = self.b, self.psi
        ep, em = np.exp(1j * psi), np.exp(-1j * psi)
        # 2 z^2 s''' = -(z^3 + z) - 8 b (ep z^4 + em)
        c = np.array([-8.0 * b * ep, -1.0, 0.0, -1.0, -8.0 * b * em], dtype=complex)
        while len(c) > 1 and c[0] == 0:
            c = c[1:]
        z = np.roots(c)
        z = z[np.abs(np.abs(z) - 1.0) < 1e-6]
        return np.mod(np.angle(z), TWO_PI)

    def __repr__(self):
        return f"SineDrive(harmonic2={self.b!r}, phase2={self.psi!r})"


class SawtoothDrive(_Drive):
    """Asymmetric sawtooth with parabolic corners: slow ramp up, fast return.

    The stator velocity is trapezoidal: ``+V1`` on the ramp, ``-V2`` on the
    return, changed linearly over a corner of duration ``Tb`` at each end.
    The displacement is therefore piecewise quadratic with continuous slope,
    the acceleration piecewise constant (``0`` or ``-+A``) and bounded, which
    keeps stick–slip transitions well defined and lets a time-stepping
    scheme converge. The displacement spans ``[-1, 1]``.

    Timing over one period ``2 pi``: the ramp takes ``rise * 2 pi`` (from
    corner centre to corner centre), the return the rest;
    ``Tb = smoothing * 2 pi * min(rise, 1 - rise)``. At ``tau = 0`` the
    constant-velocity ramp starts.

    Parameters
    ----------
    rise : float
        Fraction of the period spent ramping up, in (0, 1); > 0.5 gives the
        usual slow-forward, fast-back sawtooth that drives the slider forward.
    smoothing : float
        Corner duration relative to the shorter phase, in (0, 1]; 1 leaves no
        constant-velocity return.

    Examples
    --------
    >>> d = SawtoothDrive(rise=0.9, smoothing=0.5)
    >>> s, ds, dds = d(np.linspace(0.0, 2 * math.pi, 1001))
    >>> round(float(s.min()), 12), round(float(s.max()), 12)
    (-1.0, 1.0)
    """

    name = "sawtooth"

    def __init__(self, rise=0.9, smoothing=0.5):
        r = in_open_interval("rise", rise, 0.0, 1.0)
        c = finite_scalar("smoothing", smoothing)
        if not 0.0 < c <= 1.0:
            raise InputError(f"`smoothing` must be in (0, 1], got {c!r}")
        self.rise, self.smoothing = r, c
        Tb = c * TWO_PI * min(r, 1.0 - r)
        T1 = TWO_PI * r - Tb
        T2 = TWO_PI * (1.0 - r) - Tb
        # zero mean velocity: V1 (T1 + Tb) = V2 (T2 + Tb); stroke 2 = V1 (T1 + (1 - r) Tb)
        V1 = 2.0 / (T1 + (1.0 - r) * Tb)
        V2 = V1 * r / (1.0 - r)
        A = (V1 + V2) / Tb
        self.V1, self.V2, self.A, self.Tb = V1, V2, A, Tb
        starts = np.array([0.0, T1, T1 + Tb, T1 + Tb + T2])
        acc = np.array([0.0, -A, 0.0, A])
        vel = np.array([V1, V1, -V2, -V2])
        # the minimum -1 is where the velocity crosses zero inside the last
        # corner, (1 - r) Tb before the end of the period
        pos = np.empty(4)
        pos[0] = -1.0 + 0.5 * V1 * (1.0 - r) * Tb
        for k in range(1, 4):
            dt = starts[k] - starts[k - 1]
            pos[k] = pos[k - 1] + vel[k - 1] * dt + 0.5 * acc[k - 1] * dt * dt
        if T2 <= 0.0:   # smoothing == 1 (or the mirror): the return segment is empty
            keep = np.array([True, True, False, True])
            starts, acc, vel, pos = starts[keep], acc[keep], vel[keep], pos[keep]
        if T1 <= 0.0:
            keep = np.ones(len(starts), bool)
            keep[0] = False
            starts, acc, vel, pos = starts[keep], acc[keep], vel[keep], pos[keep]
        self._starts, self._acc, self._vel, self._pos = starts, acc, vel, pos
        self._lists = None
        self.breakpoints = tuple(float(x) for x in starts)

    def _eval(self, t):
        if isinstance(t, (float, int, np.floating, np.integer)):
            return self._eval_scalar(float(t))
        tm = np.mod(t, TWO_PI)
        k = np.searchsorted(self._starts, tm, side="right") - 1
        k = np.where(k < 0, len(self._starts) - 1, k)
        dt = np.where(tm >= self._starts[k], tm - self._starts[k], tm + TWO_PI - self._starts[k])
        a = self._acc[k]
        v = self._vel[k] + a * dt
        s = self._pos[k] + self._vel[k] * dt + 0.5 * a * dt * dt
        return s, v, a

    def _eval_scalar(self, t):
        # the event-driven schemes ask for one time at a time (twice per right-hand
        # side): plain floats here take 2 us against 37 us through the array path
        if self._lists is None:
            self._lists = tuple([float(x) for x in a]
                                for a in (self._starts, self._acc, self._vel, self._pos))
        starts, acc, vel, pos = self._lists
        tm = t % TWO_PI
        k = bisect.bisect_right(starts, tm) - 1
        if k < 0:
            k = len(starts) - 1
        dt = tm - starts[k] if tm >= starts[k] else tm + TWO_PI - starts[k]
        a = acc[k]
        return (np.float64(pos[k] + vel[k] * dt + 0.5 * a * dt * dt), np.float64(vel[k] + a * dt),
                np.float64(a))

    def _crossings(self, level):
        # s'' is piecewise constant: it can change sides only at breakpoints
        return np.zeros(0)

    def acceleration_range(self):
        return float(self._acc.min()), float(self._acc.max())

    def __repr__(self):
        return f"SawtoothDrive(rise={self.rise!r}, smoothing={self.smoothing!r})"


def make_drive(drive):
    """A drive object from ``"sine"``, ``"sawtooth"`` or a drive instance.

    A subclass of a drive is refused: the scene's compiled model, which its
    Python methods evaluate, knows ``s(tau)`` of these two drives only.
    """
    if type(drive) in (SineDrive, SawtoothDrive):
        return drive
    if isinstance(drive, _Drive):
        raise InputError(f"`drive` must be a SineDrive or a SawtoothDrive, got a subclass "
                         f"{type(drive).__name__}: the scene's compiled model evaluates the "
                         "stator's motion of these two drives only")
    if drive == "sine":
        return SineDrive()
    if drive == "sawtooth":
        return SawtoothDrive()
    raise InputError(f"`drive` must be 'sine', 'sawtooth', a SineDrive or a SawtoothDrive, "
                     f"got {drive!r}")


@dataclass(frozen=True)
class StickSlipMotorParams(Declared):
    """SI parameters of the stick–slip motor."""

    mass: float = MASS(0.01, "Slider mass")
    normal_force: float = param(1.0, "N", POSITIVE,
                                "Constant force pressing the slider onto the stator")
    mu: float = MU(0.2, rule=POSITIVE, note="Without friction nothing moves.")
    amplitude: float = param(1e-6, "m", POSITIVE, "Stator displacement amplitude ``X``",
                             "Half the stroke of the sawtooth, the fundamental's amplitude of "
                             "the sine drive.")
    load: float = LOAD(0.0, "External force on the slider opposing positive motion")
    restitution: float = RESTITUTION(0.0, "Newton restitution of the contact",
                                     note="Irrelevant while the slider stays pressed on.")

    sweepable = ("frequency", "mass", "normal_force", "mu", "amplitude", "load")


class StickSlipMotor(SIUnits, CompiledScene):
    """Slider pressed on a stator that vibrates along the slider's path.

    Parameters
    ----------
    params : StickSlipMotorParams, optional
        SI parameters; defaults if omitted.
    frequency : float
        Drive frequency [Hz], > 0.
    drive : {"sawtooth", "sine"} or SineDrive or SawtoothDrive
        Shape of the stator displacement.
    **overrides
        Individual parameters replacing those of ``params``.

    Attributes
    ----------
    n, fL : float
        Dimensionless normal force and load.
    drive : SineDrive or SawtoothDrive
    omega : float
        Angular drive frequency [rad/s].
    length, time, force : float
        SI scales: ``X`` [m], ``1 / omega`` [s], ``m X omega^2`` [N].

    Examples
    --------
    >>> motor = StickSlipMotor(frequency=1000.0, drive="sawtooth")
    >>> round(motor.n, 4), round(motor.friction_level, 4)   # N / (m X w^2), mu n
    (2.533, 0.5066)
    >>> motor.contact_jacobians([0.0, 0.0], 0.0)[2]
    array([[1., 0.]])
    """

    ndof = 2
    name = "stick-slip-motor"
    Params = StickSlipMotorParams
    period = TWO_PI
    cyclic_coordinates = (0,)

    def __init__(self, params=None, frequency=1000.0, drive="sawtooth", **overrides):
        p = params_with(self.Params, params, overrides)
        f = positive("frequency", frequency)
        self.drive = make_drive(drive)
        self.params = p
        self.frequency = f
        self.omega = TWO_PI * f
        self.length = p.amplitude
        self.time = 1.0 / self.omega
        self.force = p.mass * p.amplitude * self.omega ** 2
        self.n = p.normal_force / self.force
        self.fL = p.load / self.force
        self.mu = np.array([p.mu])
        self.restitution = np.array([p.restitution])

    @property
    def friction_level(self):
        """Dimensionless sliding friction force ``mu n``."""
        return float(self.mu[0]) * self.n

    def certain_runaway(self):
        """Why the slider must run away whatever it does, or None.

        Over a period the friction force on the slider is at most ``mu n``
        in size, so with ``|fL| > mu n`` its velocity changes by at least
        ``2 pi (|fL| - mu n)`` against the load every period: no steady
        state, periodic or statistical (:mod:`moreau.analysis.runaway`).

        Examples
        --------
        >>> StickSlipMotor(frequency=1000.0, load=0.1).certain_runaway() is None
        True
        """
        mun = self.friction_level
        if not abs(self.fL) > mun:
            return None
        p = self.params
        way = "backwards" if self.fL > 0 else "forwards"
        return (f"no steady state: the load |F_L| = {abs(p.load):g} N exceeds the sliding "
                f"friction mu N = {p.mu * p.normal_force:g} N, so the slider's speed changes "
                f"by at least {TWO_PI * (abs(self.fL) - mun):.4g} (scene units) every period; "
                f"it runs away {way}")

    def stator(self, tau):
        """Stator displacement, velocity and acceleration ``(s, s', s'')`` at ``tau``."""
        return self.drive(tau)

    def shapes(self, q, t=0.0):
        """The stator (at its prescribed displacement at ``t`` [s]), the slider (``q[0]`` [m]) and their contact."""
        X = self.params.amplitude
        s = float(self.drive(float(t) / self.time)[0]) * X
        x, y = float(q[0]), float(q[1])
        return [polygon([(s - 3 * X, -0.6 * X), (s + 3 * X, -0.6 * X), (s + 3 * X, 0.0),
                         (s - 3 * X, 0.0)], role="stator"),
                polygon([(x - 0.5 * X, y), (x + 0.5 * X, y), (x + 0.5 * X, y + X),
                         (x - 0.5 * X, y + X)]),
                contact(0, (x, y), (0.0, 1.0), (1.0, 0.0))]

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def forcing_breakpoints(self, t0, t1):
        """The drive's breakpoints (where ``s''`` jumps) in ``(t0, t1)``, every period."""
        b = np.asarray(getattr(self.drive, "breakpoints", ()), float)
        if b.size == 0 or not t1 > t0:
            return np.zeros(0)
        k0 = math.floor((t0 - float(np.max(b))) / TWO_PI)
        k1 = math.ceil((t1 - float(np.min(b))) / TWO_PI)
        ts = (b[None, :] + TWO_PI * np.arange(k0, k1 + 1)[:, None]).ravel()
        return np.sort(ts[(ts > t0) & (ts < t1)])

    def initial_state(self):
        """Slider on the stator at ``x = 0``, moving with it (sticking) at ``tau = 0``."""
        _, ds, _ = self.drive(0.0)
        return np.zeros(2), np.array([float(ds), 0.0])

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        par = np.zeros(22)
        par[0], par[1] = self.fL, self.n
        d = self.drive
        if isinstance(d, SineDrive):
            par[2], par[3], par[4] = 0.0, d.b, d.psi
        else:                   # a SawtoothDrive (make_drive admits no other)
            m = len(d._starts)
            par[2], par[5] = 1.0, m
            par[6:6 + m], par[10:10 + m] = d._starts, d._acc
            par[14:14 + m], par[18:18 + m] = d._vel, d._pos
        return CompiledModel(block_mass, _forces, _contacts, _drift, par, 2, 1, True, False)


class StickSlipCase(CompareCase):
    """One period from the exact periodic state; reference: the exact stick–slip solution."""

    ref_scheme = "stick-slip-exact"
    headline_name = "displacement per period"

    def __init__(self, frequency=1000.0, drive="sawtooth", **params):
        self.scene = StickSlipMotor(frequency=frequency, drive=drive, **params)
        self._params = dict(frequency=frequency, drive=drive, **params)
        self._ss = None
        self._grid = None

    def parameters(self):
        return dict(self._params)

    def _steady(self):
        if self._ss is None:
            self._ss = get_integrator(self.ref_scheme).steady_state(self.scene)
        return self._ss

    def reference(self, rtol):
        ss = get_integrator(self.ref_scheme).steady_state(self.scene)
        return ss.displacement_per_period, regime_switches(ss.regimes)

    def start(self):
        return np.array([0.0, 0.0]), np.array([self._steady().state0[0], 0.0])

    def reference_grid(self):
        if self._grid is None:
            grid = np.linspace(0.0, TWO_PI, GRID + 1)
            q, v = self.start()
            xs = [q[0]]
            for a, b in zip(grid[:-1], grid[1:]):
                r = simulate(self.scene, (a, b), q, v, "stick-slip-exact")
                q, v = r.q[-1].copy(), r.v[-1].copy()
                xs.append(q[0])
            self._grid = np.array(xs)
        return self._grid

    def headline_of_run(self, res):
        return float(res.q[-1, 0] - res.q[0, 0])


# -- compiled model (moreau.compiled) ---------------------------------------------------
# par: [fL, n, drive (0 sine, 1 sawtooth), b, psi, nseg, starts[4], acc[4], vel[4], pos[4]]

@njit(cache=True)
def _drive(par, t):
    # (s, s', s'') of the stator at t
    if par[2] == 0.0:
        b = par[3]
        a2 = 2.0 * t + par[4]
        return (math.sin(t) + b * math.sin(a2), math.cos(t) + 2.0 * b * math.cos(a2),
                -math.sin(t) - 4.0 * b * math.sin(a2))
    nseg = int(par[5])
    # Python's float modulo, as np.mod in the Python model
    tm = t % TWO_PI
    k = -1
    for i in range(nseg):
        if par[6 + i] <= tm:
            k = i
    if k < 0:
        k = nseg - 1
    st = par[6 + k]
    dt = tm - st if tm >= st else tm + TWO_PI - st
    a = par[10 + k]
    v0 = par[14 + k]
    return par[18 + k] + v0 * dt + 0.5 * a * dt * dt, v0 + a * dt, a


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    D[0, 0] = -par[0]
    D[1, 0] = -par[1]


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    block_contacts(par, q, t, G, need_gap, need_T)
    if need_T:
        # the stator moves under the block: its rate enters the slip
        G[0, 2] = -_drive(par, t)[1]


@njit(cache=True)
def _drift(par, q, v, t, Dr):
    Dr[0, 0] = 0.0
    Dr[0, 1] = -_drive(par, t)[2]


register_scene(SceneEntry(
    name="stick-slip-motor",
    factory=StickSlipMotor,
    parameters=parameters_of(StickSlipMotorParams, extra=(
        Parameter("frequency", "Hz", 1000.0, "drive frequency"),
        Parameter("drive", "choice", "sawtooth", "stator waveform: sawtooth or sine"))),
    description="stick-slip (inertial) motor: a slider on a stator driven by a sawtooth or sine",
    case=StickSlipCase,
    reference="stick-slip-exact",
))
