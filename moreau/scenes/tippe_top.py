r"""The tippe top: an eccentric sphere spun on a rough plane turns its symmetry axis from up to down.

A sphere of radius ``R`` and mass ``m`` has its centre of mass at ``a = alpha
R`` below the sphere's centre on its symmetry axis ``e3`` (moments ``A``
about a diameter through the centre of mass, ``C`` about ``e3``); it spins
at ``n0`` about ``e3``, tilted by ``theta0`` from the upward vertical, on a
plane with Coulomb friction ``mu``. The default parameters are Leine and
Glocker's tippe top (R. I. Leine, Ch. Glocker, "A set-valued force law for
spatial Coulomb–Contensou friction", Eur. J. Mech. A/Solids 22 (2003)
193–216, as used by Siconos's tippe-top example): ``m = 6 g``, ``R = 15
mm``, ``a = 3 mm``, ``A = 8e-7``, ``C = 7e-7 kg m^2``, ``mu = 0.3``, ``n0 =
180 rad/s``, ``theta0 = 0.1 rad``, and a contact patch of radius ``r =
0.5 mm`` (the same values in Capobianco, Harsch, Eugster and Leine's
tippe-top example, Int. J. Numer. Methods Eng. 2021, Sect. 10.6, citing
Leine and Glocker). Their stem is left out (the eccentric sphere of Or,
SIAM J. Appl. Math. 54 (1994) 597, and of Bou-Rabee, Marsden and Romero,
SIAM J. Appl. Dyn. Syst. 3 (2004) 352, and Ueda, Sasaki and Watanabe, SIAM
J. Appl. Dyn. Syst. 4 (2005) 1159). The patch is the option
``contact_radius``, Leine and Glocker's ``5e-4`` m by default
(``LEINE_GLOCKER_PATCH``): their published model is Coulomb–Contensou
friction (:mod:`moreau.model.space`), and with it the top inverts in its
exact motion. ``contact_radius=0`` is the point contact (Coulomb's cone
alone), whose exact motion rolls upright and does not invert (below).
Moreau–Jean's default ``cone="auto"`` solves the patched contact on the
exact cone.

Jellett's integral and the spin thresholds
------------------------------------------
With ``d = R z - a e3`` (``z`` the upward vertical) the contact point is
at ``-d`` from the centre of mass, so the contact force has no moment about
``d`` and ``J = L . d`` (``L`` the angular momentum about the centre of mass)
is conserved for any contact force: ``dJ/dt = (r x F) . d - a L . (omega x
e3)``, both zero for an axisymmetric body (Jellett's integral). Friction
dissipates energy at fixed ``J``; the states it can rest in are the minima
over the tilt ``theta`` of the least energy at that ``J`` (the kinetic
energy ``J^2 / (2 d.Id)`` of the rotation ``omega`` parallel to ``d``, the
least with ``L . d = J``):

.. math::

    V(\theta) = m g (R - a\cos\theta)
      + \frac{J^2}{2\,[C (R\cos\theta - a)^2 + A R^2 \sin^2\theta]} .

Expanding ``V`` about ``theta = pi`` (the inverted state, ``J = C n (R +
a)``) and about ``theta = 0`` (``J = C n (R - a)``) gives the classical
conditions (the energetics of Bou-Rabee, Marsden and Romero 2004, derived
here): the inverted state is a minimum iff ``C (R + a) > A R`` and

.. math::

    J^2 > \frac{m g a\, C^2 (R + a)^4}{R\,[C (R + a) - A R]},

the upright state is not iff ``A R > C (R - a)`` and ``J^2 > m g a C^2 (R -
a)^4 / (R [A R - C (R - a)])``. With ``gamma = A / C`` the first pair is the
classical condition ``1 - alpha < gamma < 1 + alpha`` for inversion, and
the bound on ``J`` is Rauch-Wojciechowski and Rutstam's threshold ``lambda >
sqrt(m g R^3 C alpha) (1 + alpha)^2 / sqrt(1 + alpha - gamma)`` ("Dynamics of
an inverting tippe top", SIGMA 10 (2014) 017). Spun at ``n0`` about its axis at the tilt
``theta0``, ``J = C n0 (R cos theta0 - a)``: for the default top the
upright state is unstable above ``n0 = 21.8 rad/s`` and the inverted state
stable above ``n0 = 120.3 rad/s`` (:func:`spin_thresholds`); between the two
the top rises to the tilt that minimises ``V`` and hangs there
(:func:`final_tilt`).

Sliding matters: a top whose contact point rolls without slipping keeps
``J`` and its energy, and does not rise. With a point contact
(``contact_radius=0``: Coulomb's cone, no drilling friction) that is what
the exact motion does at the other defaults: the event-driven reference (``event-driven-space``) finds the
slip ending at ``t = 0.036 s``, after which the top rolls upright at
constant energy (``cos(theta)`` 0.9993 at 3.9 s). A Moreau–Jean run inverts
it through the step's own dissipation: the axis passes horizontal at 1.15,
1.49, 2.14, 3.37 s for ``h`` = 0.1, 0.05, 0.025, 0.0125 units, and at 32000
steps over the window (``h`` = 0.003) the top stays upright like the
reference. The thresholds above say where a dissipating top can end, not
that this model's top dissipates; the inversion Leine and Glocker publish
comes with their Coulomb–Contensou (drilling) friction.

With the patch (the default ``contact_radius=5e-4``) the contact spins about the normal
and so slides in the ellipsoid's generalized sense all the time: friction
keeps dissipating and the top turns over. Its drilling torque ``M_d n``
has the moment ``M_d n . d = M_d (R - a cos theta)`` about ``d``, so
Jellett's integral is no longer kept: it falls slowly (by 4 % when the
axis passes horizontal, 24 % at 3.9 s, still 1.14 times the inversion
threshold's), and the thresholds above, taken at the initial ``J``, bound
from above where the top can end.
The event-driven reference (which slides with the drilling row) has the
axis horizontal at ``t = 0.975323 s``; Moreau–Jean (exact cone) reaches
it 0.0181, 0.0081, 0.0039, 0.0019 s later at ``h`` = 0.05, 0.025, 0.0125,
0.00625 units (order one), and the top is inverted (``cos theta <
-0.99``) from 2.7 s on (at h = 0.05 units). Spun at 108 rad/s (0.9 of the inversion
threshold) it rises and hangs above the tilt of least energy; at 15 rad/s
it stays upright. No inversion time was recovered from Leine and
Glocker's text for comparison.

The model: the symmetry axis is the body's ``z``, the sphere's centre at
``(0, 0, a)`` from the centre of mass (:class:`moreau.model.space.Sphere`
with ``centre``); units: lengths in ``R``, time in ``sqrt(R / g)``, mass in
``m``.
"""

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.cases import GRID, SpatialCase
from ..errors import InputError, MoreauError
from ..integrators.base import simulate
from ..model.params import (GRAVITY, MASS, MU, NONNEGATIVE, POSITIVE, RADIUS, Declared,
                            open_interval, param)
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with
from ..model.space import SpaceModel, Sphere
from ..model.spatial import quat_exp, rotation_matrix

__all__ = ["TippeTopParams", "tippe_top", "spin_thresholds", "final_tilt", "axis_height"]


#: the contact patch's radius [m] of Leine and Glocker's top (Capobianco et al. 2021's tippe-top
#: example, which cites Leine and Glocker 2003)
LEINE_GLOCKER_PATCH = 5e-4


@dataclass(frozen=True)
class TippeTopParams(Declared):
    """SI parameters of the tippe top (Leine and Glocker 2003, without the stem)."""

    mass: float = MASS(6e-3)
    radius: float = RADIUS(0.015, "The sphere's radius ``R``")
    offset: float = param(0.2, "", open_interval(0.0, 1.0, "0, 1"),
                          "Offset ``alpha = a / R`` of the centre of mass below the sphere's "
                          "centre")
    inertia_transverse: float = param(8e-7, "kg m^2", POSITIVE,
                                      "Transverse inertia ``A`` about the centre of mass")
    inertia_axial: float = param(7e-7, "kg m^2", POSITIVE,
                                 "Axial inertia ``C`` about the centre of mass",
                                 "It must be <= 2 A.")
    mu: float = MU(0.3, "Coulomb friction", rule=POSITIVE)
    gravity: float = GRAVITY(9.81)
    spin: float = param(180.0, "rad/s", POSITIVE, "Initial spin ``n0`` about the symmetry axis")
    tilt: float = param(0.1, "rad", open_interval(0.0, 0.5 * math.pi, "0, pi/2"),
                        "Initial tilt ``theta0`` of the axis from the upward vertical")
    contact_radius: float = param(LEINE_GLOCKER_PATCH, "m", NONNEGATIVE,
                                  "Contact patch's radius ``r``",
                                  "Its drilling friction couples with the sliding force "
                                  "(Coulomb–Contensou friction, :mod:`moreau.model.space`); "
                                  "``0`` is the point contact. Default Leine and Glocker's "
                                  "``r = 0.5 mm``.")

    sweepable = ("mu", "spin", "tilt", "offset")

    def __post_init__(self):
        super().__post_init__()
        if self.inertia_axial > 2.0 * self.inertia_transverse:
            raise InputError(f"`inertia_axial` must be <= 2 inertia_transverse (the triangle "
                             f"inequality), got {self.inertia_axial!r}")


def _jellett(p):
    R, a = p.radius, p.offset * p.radius
    return p.inertia_axial * p.spin * (R * math.cos(p.tilt) - a)


def spin_thresholds(params=None, **overrides):
    """``(n_up, n_inv)`` [rad/s]: the spin above which the upright state is unstable, and
    above which the inverted state is stable (``inf`` where the inertia rules it out).

    Examples
    --------
    >>> [round(n, 1) for n in spin_thresholds()]
    [21.8, 120.3]
    """
    p = params_with(TippeTopParams, params, overrides)
    m, g, R, a = p.mass, p.gravity, p.radius, p.offset * p.radius
    A, C = p.inertia_transverse, p.inertia_axial
    # J = C n0 (R cos theta0 - a) against the J^2 bounds of the module docstring
    k = C * (R * math.cos(p.tilt) - a)
    up = A * R - C * (R - a)
    inv = C * (R + a) - A * R
    n_up = math.sqrt(m * g * a * C * C * (R - a) ** 4 / (R * up)) / k if up > 0 else math.inf
    n_inv = math.sqrt(m * g * a * C * C * (R + a) ** 4 / (R * inv)) / k if inv > 0 else math.inf
    return n_up, n_inv


def final_tilt(params=None, **overrides):
    """The tilt [rad] of the least energy at the top's Jellett integral: where friction leaves it.

    ``pi`` above the inversion threshold, an intermediate tilt between the
    two thresholds, ``0`` below both (:func:`spin_thresholds`).

    Examples
    --------
    >>> round(final_tilt(), 6), round(math.degrees(final_tilt(spin=100.0)), 1)
    (3.141593, 147.0)
    """
    p = params_with(TippeTopParams, params, overrides)
    m, g, R, a = p.mass, p.gravity, p.radius, p.offset * p.radius
    A, C = p.inertia_transverse, p.inertia_axial
    J = _jellett(p)

    def V(th):
        return m * g * (R - a * np.cos(th)) + J * J / (
            2.0 * (C * (R * np.cos(th) - a) ** 2 + A * R * R * np.sin(th) ** 2))

    th = np.linspace(0.0, math.pi, 20001)
    k = int(np.argmin(V(th)))
    if 0 < k < th.size - 1:
        # golden-section polish inside the bracketing grid cells
        lo, hi = th[k - 1], th[k + 1]
        r = 0.5 * (math.sqrt(5.0) - 1.0)
        for _ in range(80):
            x1, x2 = hi - r * (hi - lo), lo + r * (hi - lo)
            if V(x1) < V(x2):
                hi = x2
            else:
                lo = x1
        return 0.5 * (lo + hi)
    return float(th[k])


def axis_height(q):
    """The symmetry axis' vertical component ``cos(theta)`` of each state (rows of ``q``).

    Examples
    --------
    >>> float(axis_height(tippe_top().initial_state()[0][None, :])[0]) == math.cos(0.1)
    True
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    return np.array([rotation_matrix(r[3:7] / np.linalg.norm(r[3:7]), check=False)[2, 2]
                     for r in q])


def tippe_top(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the tippe top on the plane.

    Examples
    --------
    >>> sc = tippe_top()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ncontacts, abs(float(sc.gaps(q0, 0.0)[0])) < 1e-15, round(float(v0[5] / sc.time), 9)
    (1, True, 180.0)
    """
    p = params_with(TippeTopParams, params, overrides)
    R, a = p.radius, p.offset * p.radius
    m = SpaceModel(gravity=(0.0, 0.0, -p.gravity), length=R, mass=p.mass)
    table = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    # tilted about y by theta0 (quat_exp takes half the rotation vector)
    orient = quat_exp(np.array([0.0, 0.5 * p.tilt, 0.0]))
    Rm = rotation_matrix(orient)
    top = m.add_body(p.mass, [p.inertia_transverse, p.inertia_transverse, p.inertia_axial],
                     position=np.array([0.0, 0.0, R]) - Rm @ np.array([0.0, 0.0, a]),
                     orientation=orient, angular_velocity=(0.0, 0.0, p.spin), name="top")
    m.add_contact(top, Sphere(R, centre=(0.0, 0.0, a)), table, mu=p.mu,
                  contact_radius=p.contact_radius)
    sc = m.build("tippe-top", default_window=100.0)
    sc.params = p
    return sc


tippe_top.Params = TippeTopParams


class TippeTopCase(SpatialCase):
    """The top over the window: its axis' height ``cos(theta)`` at the end, against the
    event-driven reference (``event-driven-space``) on the same model.

    The reference is the model's exact motion, whatever the parameters: with
    the contact patch (the scene's default) the top turns over, with the
    point contact (``contact_radius=0``) it rolls upright (the module
    docstring).
    """

    listed_reference = ref_scheme = "event-driven-space"
    mj_tolerance = 5e-2
    headline_name = "axis height cos(theta)"
    window = 100.0
    compares_switches = False

    scene_factory = staticmethod(tippe_top)

    def coordinate(self, q):
        return axis_height(q)

    def _reference_run(self, rtol):
        # the axis' height on the comparison grid, the last point the headline
        rtol = 1e-10 if rtol is None else rtol
        q0, v0 = self.start()
        res = simulate(self.scene, (0.0, self.window), q0, v0, "event-driven-space",
                       rtol=rtol, atol=1e-2 * rtol,
                       t_eval=np.linspace(0.0, self.window, GRID + 1))
        if res.status != 0:
            raise MoreauError(f"tippe top: the event-driven reference stopped at t = "
                              f"{res.t[-1]!r} (status {res.status}): {res.message}")
        return axis_height(res.q)

    def reference(self, rtol):
        grid = self._reference_run(rtol)
        self._tight = grid
        return float(grid[-1]), [(0.0, "P")]

    def reference_grid(self):
        grid = getattr(self, "_tight", None)
        return self._reference_run(None) if grid is None else grid

    def headline_of_run(self, res):
        return float(axis_height(res.q[-1:])[0])


register_scene(SceneEntry(
    name="tippe-top",
    factory=tippe_top,
    description=("tippe top (eccentric sphere, Leine and Glocker 2003): spun above the "
                 "threshold set by Jellett's integral, it turns its axis from up to down"),
    case=TippeTopCase,
))
