"""Bidirectional friction drive: two mirror-image tilted rods on one rotor.

The paper's conclusion proposes "adding another tilt rod with opposite
tilting direction" so that one motor can move both ways. Rod ``a`` is the
paper's rod (tilt ``+phi0``, tip pointing in ``+x``); rod ``b`` is its mirror
image about the vertical (tilt ``-phi0``, tip pointing in ``-x``). Both are
pressed by their springs on the same rotor surface, at height ``l sin phi0``
above their hinges. Each hinge sits on its own stator group, driven
vertically with its own amplitude and a common frequency::

    x1a(t) = x10_a (1 - cos w t),    x1b(t) = x10_b (1 - cos(w t - delta))

Exciting rod ``a`` alone moves the rotor as the paper's scene does (the
direction depends on the frequency: backwards at 20 and 185 Hz, forwards at 2000 Hz with the paper's values);
exciting rod ``b`` alone moves it the opposite way by exactly the same amount
(mirror symmetry ``x -> -x``).

Derivation
----------
Generalized coordinates ``(phi_a, phi_b, x2)``; each angle is measured from
the horizontal, in the rod's own (mirrored) sense, so both rest at ``phi0``.
The stator motions ``x1a, x1b`` are prescribed. Rod ``a`` is hinged at
``(0, x1a)``, rod ``b`` at ``(d, x1b)`` (``d`` drops out). Rod centres and tips::

    c_a = ( l/2 cos phi_a,      x1a + l/2 sin phi_a),  tip_a = ( l cos phi_a,     x1a + l sin phi_a)
    c_b = (d - l/2 cos phi_b,   x1b + l/2 sin phi_b),  tip_b = (d - l cos phi_b,  x1b + l sin phi_b)

With ``|c'|^2 = l^2/4 phi'^2 + x1'^2 + l x1' phi' cos phi`` for either rod and
the rod's moment of inertia ``m l^2 / 12`` about its centre,

    T = sum_r [1/6 m l^2 phi_r'^2 + 1/2 m l x1r' phi_r' cos phi_r + 1/2 m x1r'^2] + 1/2 m2 x2'^2
    V = sum_r 1/2 k l^2 (sin phi0 - sin phi_r)^2

(the stator masses only add terms in the prescribed ``x1r``). Gaps and
tangential (rotor-relative-to-tip) displacements::

    g_Na = l sin phi0 - l sin phi_a - x1a,   g_Ta = x2 - l cos phi_a
    g_Nb = l sin phi0 - l sin phi_b - x1b,   g_Tb = x2 - d + l cos phi_b

and the virtual work of the contact forces is ``sum_r (f_Nr dg_Nr + f_Tr dg_Tr)``.
With ``tau = w t``, ``u = x / l``, forces over ``m l w^2``, ``J = m2/m``,
``P = k/(m w^2)``, ``u1r = u10r (1 - cos(tau - delta_r))`` (``delta_a = 0``,
``delta_b = delta``) and ``q = (phi_a, phi_b, u2)``, Lagrange's equations read
``M q'' = h + WN^T f_N + WT^T f_T`` with

    M  = diag(1/3, 1/3, J)
    h  = (P cos phi_a (sin phi0 - sin phi_a) - 1/2 u1a'' cos phi_a,
          P cos phi_b (sin phi0 - sin phi_b) - 1/2 u1b'' cos phi_b,
          -f_L)
    WN = [[-cos phi_a, 0, 0], [0, -cos phi_b, 0]],    wN = (-u1a', -u1b')
    WT = [[ sin phi_a, 0, 1], [0, -sin phi_b, 1]],    wT = (0, 0)
    wNbar = (phi_a'^2 sin phi_a - u1a'',  phi_b'^2 sin phi_b - u1b'')
    wTbar = (phi_a'^2 cos phi_a,         -phi_b'^2 cos phi_b)

(``d2 g/dtau2 = W q'' + wbar``). The ``M`` is diagonal: the rods are coupled
only through the rotor, i.e. through the contact forces. Deleting ``phi_b``
and contact ``b`` leaves exactly the equations of
:class:`~moreau.scenes.friction_drive.FrictionDrive`; rod ``b`` alone is that
scene under the mirror map ``u2 -> -u2`` (which flips the sign of its slip
velocity, so rod ``b``'s Painlevé configuration is *positive* slip with
``1 - mu tan(phi_b) <= 0``).
"""

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from ..errors import InputError
from ..model.params import FINITE, NONNEGATIVE, param
from ..model.drawing import rod_drive_shapes
from ..model.units import DriveUnits
from numba import njit

from ..compiled import CompiledModel
from .friction_drive.rod import (AMPLITUDE, MEMO_SLOTS, ROD_RESTITUTION, ROTOR_LOAD, RodParams,
                                  StatorMotion, memo_sincos, rod_forces, rod_gap, rod_rows)
from ..model.compiled_scene import CompiledScene
from ..model.scene import params_with
from .friction_drive.scene import FrictionDrive, FrictionDriveParams
from ..analysis.cases import DriveCase
from ..model.registry import Parameter, SceneEntry, parameters_of, register_scene

__all__ = ["BidirectionalDriveParams", "BidirectionalDrive"]


@dataclass(frozen=True)
class BidirectionalDriveParams(RodParams):
    """Physical parameters of the two-rod drive, in SI units.

    The rod, spring, rotor, friction, load and restitution parameters mean
    what they mean in :class:`~moreau.scenes.friction_drive.FrictionDriveParams`
    and are shared by both rods (they are mirror images).

    {attributes}

    Examples
    --------
    >>> p = BidirectionalDriveParams(x10_b=0.0)
    >>> p.x10_a, p.x10_b, p.phase
    (2e-06, 0.0, 0.0)
    """

    x10_a: float = AMPLITUDE(2.0e-6, "Stator displacement amplitude of rod ``a``",
                             rule=NONNEGATIVE, note="0 leaves the rod unexcited.")
    x10_b: float = AMPLITUDE(2.0e-6, "Stator displacement amplitude of rod ``b``",
                             rule=NONNEGATIVE, note="0 leaves the rod unexcited.")
    phase: float = param(0.0, "rad", FINITE, "Phase lag ``delta`` of stator ``b`` behind stator "
                                             "``a``")
    load: float = ROTOR_LOAD(0.0)
    restitution: float = ROD_RESTITUTION(0.0)

    sweepable = ("frequency", "m", "m2", "k", "length", "phi0", "mu", "x10_a", "x10_b", "phase",
                 "load", "restitution")

    def __post_init__(self):
        super().__post_init__()
        self._check_amplitude("x10_a", self.x10_a)
        self._check_amplitude("x10_b", self.x10_b)


    def rod(self, which):
        """The :class:`FrictionDriveParams` of rod ``"a"`` or ``"b"`` alone.

        Raises :class:`InputError` if that rod is not excited (``x10 = 0``),
        which the single-rod scene does not allow.
        """
        if which not in ("a", "b"):
            raise InputError(f"`which` must be 'a' or 'b', got {which!r}")
        x10 = self.x10_a if which == "a" else self.x10_b
        if x10 <= 0.0:
            raise InputError(f"`x10_{which}` must be > 0 for a single-rod scene, got {x10!r}")
        return FrictionDriveParams(m=self.m, m2=self.m2, k=self.k, length=self.length,
                                   phi0=self.phi0, mu=self.mu, x10=x10, load=self.load,
                                   restitution=self.restitution)

    @classmethod
    def from_single(cls, params, x10_b=None, phase=0.0):
        """Two mirror rods built from a single-rod :class:`FrictionDriveParams`.

        ``x10_a = params.x10``; ``x10_b`` defaults to the same amplitude.
        """
        if not isinstance(params, FrictionDriveParams):
            raise InputError("`params` must be a FrictionDriveParams instance")
        return cls(m=params.m, m2=params.m2, k=params.k, length=params.length, phi0=params.phi0,
                   mu=params.mu, x10_a=params.x10, x10_b=params.x10 if x10_b is None else x10_b,
                   phase=phase, load=params.load, restitution=params.restitution)


# -- compiled model (moreau.compiled) ---------------------------------------------------
# par: J, P, sin_phi0, fL, u10a, u10b, delta_a, delta_b, then the memory of memo_sincos:
# rod r's angle at MEMO + 6 r, its phase at MEMO + 6 r + 3; rod r (angle q[r], stator
# phase delta_r) on the rotor q[2], the second rod mirrored (sgn = -1)
MEMO = 8


@njit(cache=True)
def _mass(par, q, M):
    M[0, 0] = 1.0 / 3.0
    M[1, 1] = 1.0 / 3.0
    M[2, 2] = par[0]


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    for r in range(2):
        s, c = memo_sincos(par, MEMO + 6 * r, q[r])
        ct = memo_sincos(par, MEMO + 6 * r + 3, t - par[6 + r])[1]
        rod_forces(D, r, par[1], par[2], par[4 + r], s, c, ct, need_jac)
    D[2, 0] = -par[3]


@njit(cache=True)
def _gaps(par, q, t, G):
    for r in range(2):
        s = memo_sincos(par, MEMO + 6 * r, q[r])[0]
        ct = memo_sincos(par, MEMO + 6 * r + 3, t - par[6 + r])[1]
        G[r, 0] = rod_gap(par[2], par[4 + r], s, ct)


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    for r in range(2):
        s, c = memo_sincos(par, MEMO + 6 * r, q[r])
        st, ct = memo_sincos(par, MEMO + 6 * r + 3, t - par[6 + r])
        if need_gap:
            G[r, 0] = rod_gap(par[2], par[4 + r], s, ct)
        rod_rows(G, r, r, 2, 3, 1.0 - 2.0 * r, par[4 + r], s, c, st, need_T)


@njit(cache=True)
def _drift(par, q, v, t, Dr):
    for r in range(2):
        w2 = v[r] * v[r]
        s, c = memo_sincos(par, MEMO + 6 * r, q[r])
        ct = memo_sincos(par, MEMO + 6 * r + 3, t - par[6 + r])[1]
        Dr[r, 0] = w2 * s - par[4 + r] * ct
        Dr[r, 1] = (1.0 - 2.0 * r) * w2 * c


def params_from_kwargs(**kwargs):
    """Build :class:`BidirectionalDriveParams` from keyword arguments, ignoring ``None`` values."""
    return BidirectionalDriveParams.from_kwargs(**kwargs)


class BidirectionalDrive(StatorMotion, DriveUnits, CompiledScene):
    """Two mirror-image rods driving one rotor, in the paper's dimensionless form.

    Coordinates ``q = (phi_a, phi_b, u2)``, velocities their derivatives in
    ``tau = w t``; contacts ``0`` (rod ``a``) and ``1`` (rod ``b``), both
    frictional when ``mu > 0``. See the module docstring for the derivation;
    the model methods (``mass``, ``forces``, ``gaps``, ...) evaluate the
    compiled model, where the equations are written once
    (:class:`~moreau.model.compiled_scene.CompiledScene`).

    Parameters
    ----------
    params : BidirectionalDriveParams, optional
        Physical parameters; the paper's rod with both stators at its amplitude
        and in phase by default.
    frequency : float
        Common drive frequency ``f`` [Hz], > 0.
    **overrides
        Individual parameters replacing those of ``params`` (``x10_b=0.0``).

    Examples
    --------
    >>> s = BidirectionalDrive(BidirectionalDriveParams(x10_b=0.0), frequency=185.0)
    >>> s.ndof, s.ncontacts, round(s.J)
    (3, 2, 100)
    >>> q0, v0 = s.rest_state()
    >>> s.gaps(q0, 0.0).tolist()
    [0.0, 0.0]
    """

    ndof = 3
    name = "bidirectional-drive"
    Params = BidirectionalDriveParams
    #: each rod's geometry (tip towards the rotor, contact above its hinge) holds only there
    valid_region = "0 < phi_a, phi_b < pi/2 (each rod leans towards the rotor from below upright)"
    period = 2.0 * math.pi
    cyclic_coordinates = (2,)

    def __init__(self, params=None, frequency=185.0, **overrides):
        self.params = p = params_with(self.Params, params, overrides)
        self.frequency = V.positive("frequency", frequency)
        self.omega = 2.0 * math.pi * self.frequency
        self.J = p.m2 / p.m
        self.P = p.k / (p.m * self.omega ** 2)
        self.u10 = np.array([p.x10_a, p.x10_b]) / p.length
        self.delta = np.array([0.0, p.phase])
        self.force_scale = p.m * p.length * self.omega ** 2
        self.fL = p.load / self.force_scale
        self.phi0 = p.phi0
        self.sin_phi0 = math.sin(p.phi0)
        self.mu = np.array([p.mu, p.mu])
        self.restitution = np.array([p.restitution, p.restitution])
        # +1 for rod a (tip towards +x), -1 for the mirrored rod b
        self._side = np.array([1.0, -1.0])
        #: velocity scale of the motion (the larger stator velocity amplitude), for tolerances
        self.velocity_scale = float(np.max(self.u10)) if np.max(self.u10) > 0 else 1.0

    # -- conveniences (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def slip_velocities(self, q, v):
        """Slip velocities ``u2' + s_r sin(phi_r) phi_r'`` of both rods (defined also for mu = 0)."""
        return v[2] + self._side * np.sin(np.asarray(q[:2], float)) * np.asarray(v[:2], float)

    def rod_layout(self):
        """``(u10, delta, side)`` of both rods: stator amplitudes, phases and tip directions.

        The layout the energy audit (:mod:`moreau.analysis.energy`) reads.
        """
        return self.u10.copy(), self.delta.copy(), self._side.copy()

    def shapes(self, q, t=0.0):
        """Both rods (``q[0:2]`` [rad], mirror images) and the rotor (``q[2]`` [m]) at ``t`` [s]."""
        return rod_drive_shapes(self, q, t, rods=[(0, 1.0), (1, -1.0)], rotor=2)

    def rest_state(self, tau=0.0):
        """State at ``tau`` with both rods on their contact manifolds and the rotor at rest.

        ``sin phi_r = sin phi0 - u1r(tau)``, ``phi_r' = -u1r'(tau) / cos phi_r``.
        """
        tau = V.finite_scalar("tau", tau)
        phi = np.arcsin(self.sin_phi0 - self.u1(tau))
        dphi = -self.du1(tau) / np.cos(phi)
        return np.array([phi[0], phi[1], 0.0]), np.array([dphi[0], dphi[1], 0.0])

    def inside_valid_region(self, t, q, v):
        phi = np.asarray(q)[:, :2]
        return np.all((phi > 0.0) & (phi < 0.5 * math.pi), axis=1)

    def initial_state(self):
        """The rest state at ``tau = 0`` (:meth:`rest_state`)."""
        return self.rest_state()

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`)."""
        # the parameters, then per rod the memory of its angle's and its phase's sines
        # and cosines (MEMO)
        par = np.array([self.J, self.P, self.sin_phi0, self.fL, self.u10[0], self.u10[1],
                        self.delta[0], self.delta[1], *(MEMO_SLOTS * 4)], dtype=np.float64)
        return CompiledModel(_mass, _forces, _contacts, _drift, par, 3, 2, True, True, gaps=_gaps)

    def single_rod(self, which):
        """The paper's :class:`FrictionDrive` for rod ``"a"`` or ``"b"`` alone, same frequency."""
        return FrictionDrive(self.params.rod(which), frequency=self.frequency)

    # -- units ------------------------------------------------------------------
    #: ``q = (phi_a, phi_b, u2)``: the rod angles are in rad
    angle_coordinates = (0, 1)
    #: what each coordinate is, in the names of ``to_si``'s extras (a run's sidecar)
    coordinate_names = ("phi_a", "phi_b", "x2")

    def to_si(self, result):
        """SI time histories of a :class:`SimulationResult` of this scene.

        Returns a dict with the keys every scene gives
        (:data:`moreau.model.units.COMMON_KEYS`): ``t`` [s], ``q`` (n, 3) =
        (``phi_a``, ``phi_b`` [rad], rotor displacement [m]), ``v`` (n, 3)
        [rad/s, rad/s, m/s], ``force_N``, ``force_T`` (n, 2) [N] (rods a, b),
        ``slip_velocity`` (n, 2) [m/s], ``gap`` (n, 2) [m], ``regime`` (n, 2)
        codes; and the named coordinates: ``x2`` rotor displacement [m],
        ``v2`` rotor velocity [m/s], ``phi_a``, ``phi_b`` [rad], each (n,).
        """
        si = self._si_histories(result)
        si.update(x2=si["q"][:, 2].copy(), v2=si["v"][:, 2].copy(),
                  phi_a=si["q"][:, 0].copy(), phi_b=si["q"][:, 1].copy())
        return si


class BidirectionalDriveCase(DriveCase):
    """The two-rod drive's steady state; Moreau–Jean against the generic event-driven reference.

    By default rod a runs at full and rod b at half amplitude (``x10_b =
    1e-6`` m), so that both contacts carry load and slip both ways (mode
    ``NSP|NP`` at 185 Hz).
    """

    mj_tolerance = 5e-3
    scene_class = BidirectionalDrive
    default_params = {"x10_b": 1.0e-6}

    @staticmethod
    def scale_of(scene):
        return float(np.max(scene.u10))


register_scene(SceneEntry(
    name="bidirectional-drive",
    factory=BidirectionalDrive,
    parameters=parameters_of(BidirectionalDriveParams, extra=(
        Parameter("frequency", "Hz", 185.0, "common drive frequency"),)),
    description="the paper's proposed two-rod drive: two mirrored rods on one rotor (two contacts)",
    case=BidirectionalDriveCase,
    aliases=("bidirectional",),
))
