"""A chain of balls on a line, struck at one end (Newton's cradle, a bead chain).

``N`` equal balls of radius ``r`` lie on a line; balls ``1 .. N-1`` are at
rest and touch their neighbours, and ball 0 (the striker, mass ratio
``striker_mass / mass``) approaches ball 1 at ``striker_speed`` from a gap
``striker_gap``. Contacts are frictionless, with one Newton restitution
coefficient ``e``; there is no gravity along the line.

The scene where the schemes must differ. When the striker arrives every
contact of the chain is closed at once, and the model's answer depends on
the impact law:

* **Newton's law at every contact, simultaneously** (the model as stated,
  what Moreau–Jean and the event-driven reference solve): the impulses
  solve one LCP, ``0 <= U+_i + e min(U-_i, 0) _|_ P_i >= 0``, over all
  contacts (:func:`simultaneous_impact`). For equal balls and ``e = 1``
  with ``N = 3`` the striker rebounds at ``-1/3`` and the two others leave
  together at ``2/3``: the chain moves as a block.
* **The sequential-impact picture** (:func:`sequential_impacts`): the
  contacts collide one pair at a time, in order along the chain, repeated
  until no pair approaches. For equal balls and ``e = 1`` the striker stops
  and the last ball leaves with the striker's speed: Newton's cradle as it
  is seen.
* **Two balls** (``N = 2``) have one contact and one answer
  (:func:`two_ball_impact`): ``v0+ = (m0 - e m1) V / (m0 + m1)``,
  ``v1+ = (1 + e) m0 V / (m0 + m1)``, from momentum conservation and
  ``v1+ - v0+ = e V``.

Long chains
-----------
``N`` runs from 2 to 10 000. From :data:`SPARSE_FROM` (150) balls on,
Moreau–Jean steps the chain on its sparse form (:meth:`BallChain.sparse_contacts`,
:mod:`moreau.integrators.moreau_jean`): no dense matrix, each step's LCP
solved exactly by the active-set method of :mod:`moreau.lcp.active_set`.
Moreau–Jean's ``lcp_method="nsgs"`` or ``"apgd"`` solves it by that iterative
solver instead (to ``lcp_tol``, on this sparse path and on the dense one
below 150 balls). The chain's Delassus matrix is tridiagonal, so Gauss–Seidel
needs of the order of ``N^2`` sweeps on the struck chain (the impulses fall
linearly along it, the slowest mode) in any sweep order, and over-relaxed
at Young's optimum (:func:`sor_omega`, ``lcp_omega``) of the order of ``N``.

Scales
------
Lengths in the radius ``r``, time in ``r / V`` (``V`` the striker speed),
masses in the ball mass ``m``, forces in ``m V^2 / r``. The striker speed is
1 in scene units, the chain's contacts are 2 apart, and the dimensionless
motion depends on ``N``, the mass ratio, ``e`` and ``striker_gap / r``.

Coordinates: ``q_i`` the centre of ball ``i``, ball 1 at 0; the gap of
contact ``i`` (balls ``i`` and ``i + 1``) is ``q_{i+1} - q_i - 2``.
"""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import scipy.sparse as sps
from scipy.linalg import eigvalsh_tridiagonal

from numba import njit

from ..compiled import CompiledModel
from .._validate import (finite_array, finite_scalar, in_closed_interval, positive, positive_int,
                         restitution, whole_number)
from ..analysis.cases import GRID, ExactReference, FactoryCase
from ..errors import InputError, LCPError, MoreauError
from ..lcp import solve_lcp
from ..lcp.active_set import solve_active_set
from ..model.params import (MASS, NONNEGATIVE, POSITIVE, RADIUS, RESTITUTION, SPEED, Declaration,
                            Declared, param)
from ..model.drawing import circle, contact
from ..model.units import SIUnits
from ..model.compiled_scene import CompiledScene
from ..model.scene import FromParams
from ..model.registry import SceneEntry, register_scene

__all__ = ["ChainParams", "BallChainParams", "BallChain", "ChainImpactCase", "two_ball_impact", "sequential_impacts",
           "simultaneous_impact", "sor_omega"]

#: the chain lengths the scene takes
MIN_BALLS, MAX_BALLS = 2, 10_000
#: balls from which Moreau–Jean runs the chain on its sparse step (:meth:`BallChain.sparse_contacts`)
#: and :func:`simultaneous_impact` solves by the sparse active-set method, not by dense Lemke:
#: the measured crossover (the default window at h = 0.01, 310 steps, best of 3, shared
#: machine): dense 111, 292, 221 us a step at 100, 130, 150 balls, sparse 177, 325, 178
SPARSE_FROM = 150


@dataclass(frozen=True)
class ChainParams(Declared):
    """SI parameters every chain of balls has, on a line or in space."""

    #: the most balls the chain takes
    max_balls: ClassVar[int] = MAX_BALLS

    n_balls: int = param(3, doc="Number of balls ``N`` including the striker",
                         note="A whole number in [2, ``max_balls``].")
    mass: float = MASS(0.1, "Mass of each ball of the chain")
    striker_mass: float = MASS(0.1, "Mass of the striker")
    radius: float = RADIUS(0.01, "Radius of every ball")
    striker_speed: float = SPEED(1.0, "Speed of the striker towards the chain", rule=POSITIVE)
    restitution: float = RESTITUTION(1.0, "Newton restitution of every contact")

    sweepable = ("restitution", "striker_mass", "n_balls")

    def __post_init__(self):
        object.__setattr__(self, "n_balls",
                           whole_number("n_balls", self.n_balls, MIN_BALLS, self.max_balls))
        super().__post_init__()


#: the striker's gap to the chain: the default, 1.1 radii, puts the impact at ``t* = 1.1 r / V``
STRIKER_GAP = Declaration("m", NONNEGATIVE, "Initial gap between the striker and the chain")


@dataclass(frozen=True)
class BallChainParams(ChainParams):
    """SI parameters of the ball chain: those of :class:`ChainParams` (up to 10 000 balls) and
    the striker's gap."""

    striker_gap: float = STRIKER_GAP(0.011, note=(
        "The default, 1.1 radii, puts the impact at ``t* = 1.1`` scene units, off the grids of "
        "the usual step counts over the comparison window ``t* + 2`` (at ``t* = 1`` the "
        "window's 150 and 1500 steps would land a step on ``t*`` and Moreau–Jean would place "
        "the impact exactly, by coincidence)."))


class BallChain(FromParams, SIUnits, CompiledScene):
    """``N`` balls on a line, the striker approaching the resting chain.

    {params}

    Examples
    --------
    >>> chain = BallChain(n_balls=3)
    >>> chain.ndof, chain.ncontacts, round(chain.impact_time, 12)
    (3, 2, 1.1)
    >>> [round(float(x), 12) for x in simultaneous_impact(chain.masses, [1.0, 0.0, 0.0], 1.0)]
    [-0.333333333333, 0.666666666667, 0.666666666667]
    """

    name = "ball-chain"
    #: only neighbours touch: a ball that passed its neighbour is not in the model
    valid_region = "q_0 < q_1 < ... < q_N-1 (every ball keeps its place in the chain)"

    @property
    def default_window(self):
        """The striker's impact and two time units after it."""
        return self.impact_time + 2.0

    Params = BallChainParams

    def _setup(self, p):
        n = p.n_balls
        self.ndof = n
        self.mu = np.zeros(n - 1)
        self.restitution = np.full(n - 1, p.restitution)
        self.length = p.radius
        self.time = p.radius / p.striker_speed
        self.force = p.mass * p.striker_speed ** 2 / p.radius
        self.mass_ratio = p.striker_mass / p.mass
        self.masses = np.ones(n)
        self.masses[0] = self.mass_ratio
        self.gap0 = p.striker_gap / p.radius

    @property
    def impact_time(self):
        """Time at which the striker reaches the chain (scene units: the gap over the speed 1)."""
        return self.gap0

    # -- Scene interface (mass, forces, gaps, ...: the compiled model's, CompiledScene) --
    def inside_valid_region(self, t, q, v):
        return np.all(np.diff(np.asarray(q), axis=1) > 0.0, axis=1)

    def initial_state(self):
        """The chain at rest, touching, ball 1 at 0; the striker ``gap0`` away at speed 1."""
        q = 2.0 * np.arange(self.ndof, dtype=float) - 2.0
        q[0] -= self.gap0
        v = np.zeros(self.ndof)
        v[0] = 1.0
        return q, v

    def compiled_model(self):
        """Compiled form of this model (:mod:`moreau.compiled`); ``par = (mass ratio,)``."""
        return CompiledModel(_mass, _forces, _contacts, None, [self.mass_ratio], self.ndof,
                             self.ndof - 1, True, False)

    def shapes(self, q, t=0.0):
        """The balls (centres ``q`` [m] on a line) and the contacts between neighbours."""
        r = self.params.radius
        x = np.asarray(q, dtype=float)
        return ([circle((xi, 0.0), r) for xi in x]
                + [contact(i, (x[i] + r, 0.0), (1.0, 0.0), (0.0, 1.0)) for i in range(len(x) - 1)])

    def sparse_contacts(self):
        """The chain's sparse contact model from :data:`SPARSE_FROM` balls on, else None.

        ``(inverse masses, forces (none), WN(q) as CSR, gaps(q))``: the form in
        which Moreau–Jean steps a long chain without a dense matrix
        (:mod:`moreau.integrators.moreau_jean`); shorter chains take the
        compiled dense path.
        """
        n = self.ndof
        if n < SPARSE_FROM:
            return None
        WN = _chain_rows(n)
        return 1.0 / self.masses, np.zeros(n), lambda q: WN, lambda q: np.diff(q) - 2.0

    def kinetic_energy(self, v):
        """``sum m_i v_i^2 / 2`` of velocities ``v`` (..., N), in scene units."""
        v = np.asarray(v, dtype=float)
        return 0.5 * np.sum(self.masses * v * v, axis=-1)


# -- the impact laws ---------------------------------------------------------------------------

def _chain_state(masses, v):
    """``masses`` and ``v`` as float vectors of one length >= 2, checked."""
    m = finite_array("masses", masses, ndim=1)
    u = finite_array("v", v, ndim=1).copy()
    if m.size < 2 or u.shape != m.shape:
        raise InputError(f"`masses` and `v` must have one equal length >= 2, got {m.shape} "
                         f"and {u.shape}")
    if not np.all(m > 0.0):
        raise InputError(f"`masses` must be > 0, got {m.min()!r} as the smallest")
    return m, u

def two_ball_impact(m0, m1, V, e):
    """Velocities ``(v0+, v1+)`` after ball ``m0`` at speed ``V`` hits ``m1`` at rest.

    Momentum ``m0 V = m0 v0+ + m1 v1+`` and Newton's law ``v1+ - v0+ = e V``.

    Parameters
    ----------
    m0, m1 : float
        Masses of the moving and the resting ball, > 0.
    V : float
        Speed of ``m0`` towards ``m1`` (finite).
    e : float
        Newton restitution coefficient, in [0, 1].

    Returns
    -------
    (float, float)
        ``(v0+, v1+)``.

    Examples
    --------
    >>> two_ball_impact(1.0, 1.0, 1.0, 1.0)
    (0.0, 1.0)
    >>> two_ball_impact(1.0, 3.0, 2.0, 0.0)
    (0.5, 0.5)
    """
    m0, m1 = positive("m0", m0), positive("m1", m1)
    V = finite_scalar("V", V)
    e = in_closed_interval("e", e, 0.0, 1.0)
    s = m0 + m1
    return (m0 - e * m1) * V / s, (1.0 + e) * m0 * V / s


def sequential_impacts(masses, v, e, max_sweeps=100000):
    """Final velocities of the sequential-impact picture of a chain.

    Pairs ``(i, i+1)`` that approach (``v_i > v_{i+1}``) collide as two
    balls (:func:`two_ball_impact` in their relative motion), left to right,
    sweep after sweep, until no pair approaches.

    Parameters
    ----------
    masses, v : array_like, shape (N,)
        Masses and velocities before the impacts.
    e : float
        Restitution coefficient of every pair.
    max_sweeps : int
        Bound on the sweeps along the chain, >= 1.

    Raises
    ------
    InputError
        Bad shapes or values.
    MoreauError
        If pairs still approach after ``max_sweeps`` sweeps.

    Notes
    -----
    At ``e = 1`` the pairwise impacts keep momentum and energy, and equal
    balls end after one sweep with the striker's speed on the last ball.
    Below ``e = 1`` the picture can collapse inelastically: the pairs
    collide again and again with relative speeds falling geometrically,
    and the chain tends to one common speed (equal balls at ``e = 1/2``: 3
    sweeps for ``N = 3``, but ``N = 10`` ends at ``1/N`` for all, to
    rounding, after 94 sweeps). ``max_sweeps`` bounds that.

    Examples
    --------
    >>> sequential_impacts([1.0, 1.0, 1.0], [1.0, 0.0, 0.0], 1.0).tolist()
    [0.0, 0.0, 1.0]
    """
    m, u = _chain_state(masses, v)
    e = in_closed_interval("e", e, 0.0, 1.0)
    max_sweeps = positive_int("max_sweeps", max_sweeps)
    for _ in range(max_sweeps):
        hit = False
        for i in range(m.size - 1):
            rel = u[i] - u[i + 1]
            if rel > 0.0:
                a, b = two_ball_impact(m[i], m[i + 1], rel, e)
                u[i], u[i + 1] = u[i + 1] + a, u[i + 1] + b
                hit = True
        if not hit:
            return u
    raise MoreauError(f"the sequential impacts did not end within {max_sweeps} sweeps")


def _chain_rows(n):
    """``WN`` of a chain of ``n`` balls (CSR): row ``i`` is ``q_{i+1} - q_i``."""
    i = np.arange(n - 1)
    return sps.csr_array((np.concatenate([-np.ones(n - 1), np.ones(n - 1)]),
                          (np.concatenate([i, i]), np.concatenate([i, i + 1]))), shape=(n - 1, n))


def simultaneous_impact(masses, v, e):
    """Velocities after one simultaneous impact with Newton's law at every contact.

    All ``N - 1`` contacts closed: with ``P`` the contact impulses,
    ``v+ = v + M^-1 WN^T P`` and ``0 <= WN v+ + e min(WN v, 0) _|_ P >= 0``,
    an LCP with the positive definite matrix ``WN M^-1 WN^T`` (unique
    solution), solved by Lemke's method (certified; an unsolved problem
    raises) below :data:`SPARSE_FROM` balls, and from there by the sparse
    active-set method (:func:`moreau.lcp.active_set.solve_active_set`: the
    matrix is tridiagonal, an M-matrix, and its answer exact to rounding;
    one whose residual exceeds 1e-12 raises).

    Examples
    --------
    >>> [round(float(x), 12) for x in simultaneous_impact([1.0, 1.0, 1.0], [1.0, 0.0, 0.0], 0.0)]
    [0.333333333333, 0.333333333333, 0.333333333333]
    """
    m, u = _chain_state(masses, v)
    e = in_closed_interval("e", e, 0.0, 1.0)
    n = m.size
    if n >= SPARSE_FROM:
        WN = _chain_rows(n)
        U = WN @ u
        A = WN @ sps.diags_array(1.0 / m) @ WN.T
        z, residual, _ = solve_active_set(A, U + e * np.minimum(U, 0.0))
        if not residual <= 1e-12:
            raise LCPError(f"the simultaneous impact problem was not solved: residual "
                           f"{residual:.3g}")
        return u + (WN.T @ z) / m
    WN = np.zeros((n - 1, n))
    i = np.arange(n - 1)
    WN[i, i] = -1.0
    WN[i, i + 1] = 1.0
    U = WN @ u
    A = WN @ (WN.T / m[:, None])
    r = solve_lcp(A, U + e * np.minimum(U, 0.0), method="lemke")
    if not r.success:
        raise LCPError(f"the simultaneous impact problem was not solved: {r.message}")
    return u + (WN.T @ r.z) / m


def sor_omega(masses):
    """Young's optimal over-relaxation of Gauss–Seidel on a pressed chain of ``masses``.

    The chain's Delassus matrix ``W = WN M^-1 WN^T`` is tridiagonal
    (``W_ii = 1/m_i + 1/m_{i+1}``, ``W_i,i+1 = -1/m_{i+1}``), hence
    consistently ordered, and positive definite, so SOR's best factor is
    ``2 / (1 + sqrt(1 - rho^2))`` with ``rho`` the spectral radius of the
    Jacobi matrix ``I - D^-1 W`` (Young 1954; Varga, *Matrix Iterative
    Analysis*, 2000, thm. 4.4), here the largest eigenvalue of the symmetric
    tridiagonal ``I - D^-1/2 W D^-1/2``. Equal masses give ``rho = cos(pi /
    N)`` and ``2 / (1 + sin(pi / N))``. It is Moreau–Jean's ``lcp_omega``
    for ``lcp_method="nsgs"`` on a struck chain, where every contact ends
    pressed and the LCP is this linear system.

    Parameters
    ----------
    masses : array_like, shape (N,)
        The balls' masses, > 0, ``N >= 3`` (two contacts at least).

    Examples
    --------
    >>> import math
    >>> round(sor_omega(np.ones(100)), 9), round(2.0 / (1.0 + math.sin(math.pi / 100)), 9)
    (1.939091659, 1.939091659)
    """
    m = finite_array("masses", masses, ndim=1)
    if m.size < 3 or not np.all(m > 0.0):
        raise InputError(f"`masses` must hold 3 or more masses > 0, got {m.size} with the "
                         f"smallest {m.min() if m.size else None!r}")
    inv = 1.0 / m
    diag = inv[:-1] + inv[1:]
    off = inv[1:-1] / np.sqrt(diag[:-1] * diag[1:])
    n = diag.size
    rho = float(eigvalsh_tridiagonal(np.zeros(n), off, select="i", select_range=(n - 1, n - 1))[0])
    return 2.0 / (1.0 + math.sqrt(max(1.0 - rho * rho, 0.0)))


# -- comparison case -----------------------------------------------------------------------------

class ChainImpactCase(ExactReference):
    """A mixin for a chain's comparison case: the last ball's position up to two time units
    after the striker's impact.

    The reference is the model's exact answer, one simultaneous impact at
    ``scene.impact_time`` (:func:`simultaneous_impact`), every ball at rest
    before it and at its final speed after it; the window ends two time
    units after the impact. The subclass gives :meth:`_last_start`.
    """

    mj_tolerance = 1e-3

    def __init__(self, **params):
        super().__init__(**params)
        self.window = self.scene.impact_time + 2.0

    def _last_start(self):
        """The last ball's coordinate at the start and the balls' speeds along the chain."""
        raise NotImplementedError

    def _last(self, t):
        sc = self.scene
        x0, v0 = self._last_start()
        v_after = simultaneous_impact(sc.masses, v0, sc.params.restitution)
        # at rest until the impact, then at its final speed
        return x0 + v_after[-1] * np.maximum(np.asarray(t, float) - sc.impact_time, 0.0)

    def reference(self, rtol):
        return float(self._last(self.window)), [(float(self.scene.impact_time), "0:S")]

    def reference_grid(self):
        return self._last(np.linspace(0.0, self.window, GRID + 1))


class BallChainCase(ChainImpactCase, FactoryCase):
    """The striker's impact on the chain: where the last ball is two time units after it.

    The reference is the model's exact answer, one simultaneous impact at
    ``t* = gap / V`` (:func:`simultaneous_impact`), after which every ball
    flies at constant speed; the window ends two time units after the
    impact (:class:`ChainImpactCase`). The headline (the last ball's
    position at the end) carries both the impact's outcome and its time, so
    a scheme's error shows how well it places the impact within its steps.
    """

    headline_name = "position of the last ball after the impacts"

    scene_factory = BallChain

    def _last_start(self):
        q0, v0 = self.scene.initial_state()
        return q0[-1], v0

    def coordinate(self, q):
        return q[:, -1]


# -- compiled model (moreau.compiled); par = (striker mass / ball mass,) -------------------

@njit(cache=True)
def _mass(par, q, M):
    M[0, 0] = par[0]
    for i in range(1, q.shape[0]):
        M[i, i] = 1.0


@njit(cache=True)
def _forces(par, q, v, t, D, need_jac):
    for i in range(q.shape[0]):
        D[i, 0] = 0.0


@njit(cache=True)
def _contacts(par, q, t, G, need_gap, need_T):
    n = q.shape[0]
    for i in range(n - 1):
        if need_gap:
            G[i, 0] = q[i + 1] - q[i] - 2.0
        G[i, 3 + i] = -1.0
        G[i, 4 + i] = 1.0



register_scene(SceneEntry(
    name="ball-chain",
    factory=BallChain,
    description="a striker hits a resting chain of N balls: simultaneous impacts (Newton's cradle)",
    case=BallChainCase,
))
