"""A semicircular masonry arch of rigid voussoirs on two fixed abutments, under its own weight.

``n`` equal voussoirs (annular sectors of centreline radius ``R``,
thickness ``t``, radial joints at ``theta_k = pi (1 - k / n)`` from the
left springing) stand on a fixed ground at the springing line ``y = 0``;
the joints are dry, with Coulomb friction ``mu`` and no restitution. The
arch stands when its thickness ratio ``t / R`` exceeds a minimum, and
collapses by a four-hinge mechanism below it (the "Couplet–Heyman
problem"; Heyman 1966, "The stone skeleton", Int. J. Solids Struct. 2,
249-279; Heyman 1969, "The safety of masonry arches", Int. J. Mech. Sci.
11, 363-385).

Published values
----------------
For a continuous semicircular arch with radial joints ("radial
stereotomy") and enough friction Milankovitch (1907, "Theorie der
Druckkurven", Z. Math. Phys. 55, 1-27) found ``t / R = 0.1075``, the intrados hinge at about 54.5 deg from the crown; Heyman's
simplified weight distribution gives 0.106. Makris and Alexakis 2013 ("The
effect of stereotomy on the shape of the thrust-line and the minimum
thickness of semicircular masonry arches", Arch. Appl. Mech. 83,
1511-1533) confirm 0.1075 for radial joints and 0.1095 for vertical
ones; Cocchetti, Colasante and Rizzi 2011 ("On the analysis of minimum
thickness in circular masonry arches", Appl. Mech. Rev. 64, 050802)
review the variants. With ``n`` voussoirs the hinges can form at joints
only, so the limit is at most the continuous one:
:func:`limit_thickness` computes it exactly for any ``n`` by the safe
theorem (a thrust line inside every joint, an LP). It gives 0.10086 for
``n = 4`` and ``8``, 0.09661 for ``5``, 0.10510 for ``6`` and ``12``, and
0.10746 for ``n = 10`` (a joint at 54 deg from the crown, next to
Milankovitch's hinge), tending to 0.1075 as ``n`` grows (0.10748 at ``n =
400``).

The model
---------
Each voussoir is a free rigid body ``(x, y, theta)`` of its centroid, with
the annular sector's mass, centroid and inertia (area ``alpha (R_e^2 -
R_i^2)``, centroid at ``(2/3) (R_e^3 - R_i^3) / (R_e^2 - R_i^2) sin(alpha) /
alpha`` from the centre, ``alpha = pi / (2 n)``, ``R_i, R_e = R -+ t / 2``);
its shape is the quadrilateral of its four corners. It is built with the
planar builder (:mod:`moreau.model.planar`): at every joint the two corners
of the joint face of one block (intrados and extrados) are point-on-line
contacts against the joint face of its neighbour (a half-plane carried by
the neighbour), and at the springings the corners against the ground
``y = 0``: two contacts a joint, ``2 (n + 1)`` in all, each frictional.
Those two corners are where the hinges of a mechanism open, so the pair
model holds the arch's statics exactly: a joint transmits any force whose
line of action crosses it between its corners, inside the friction cone.
The half-planes are offset by :data:`PRELOAD` (1e-14 ``R``) into the
neighbour, so that every contact starts closed (a rounding gap of
``+1e-16`` would open it for the first step of Moreau–Jean's index set,
``g + (h/2) g' <= 0``, and drop the voussoir by a step of free fall; the
rounding measured is 1.7e-16 at most, 2 to 60 voussoirs), and within the
event-driven reference's ``gap_tol`` (1e-13) of touching, which it admits
as a start.

Stand or collapse
-----------------
:func:`stands` runs Moreau–Jean (``h = 0.01``, its compiled step, Lemke on
each step's contact problem) from rest over ``window`` = 1 ``sqrt(R / g)``
and calls the arch standing when no voussoir's centroid moved by more than
``1e-6 R`` and none turned by 0.2 rad (the model's valid region: a run that
leaves it has collapsed). Why this separates the two cases: when a thrust
line fits (the safe theorem), rest is a solution of every step's contact
problem, and Moreau–Jean keeps ``v = 0`` to the solver's residual
(``1e-14 R`` measured over the window, ten voussoirs at ``t / R = 0.13``
and 0.11); when none fits, no impulses hold the first step, and the arch
moves as a four-hinge mechanism, ``a t^2 / 2`` with an acceleration ``a``
that grows from zero with the thickness deficit (measured at ten
voussoirs: ``3.5e-2 R`` at ``t / R = 0.100`` and ``1.2e-2 R`` at 0.105,
1.3 % below the limit). The bound lies eight orders above the rest's
noise and far below a mechanism's motion, so the bisection
(:func:`minimal_thickness`) is limited by its bracket, not by the bound:
at ten voussoirs, from [0.09, 0.13] to a bracket of 0.2 %, it gives
0.10742 against the limit analysis's 0.10746 (-0.04 %; Milankovitch's
continuous 0.1075: -0.07 %), its last two collapses at 0.10719 and
0.10734 moving ``1.3e-3 R`` and ``5.6e-4 R``.

The registered scene
--------------------
``make_scene("masonry-arch")`` is the arch at rest at its start (four
voussoirs, ``t / R = 0.15``, above their limit 0.10086: it stands), a
:class:`~moreau.model.planar.PlanarScene` that every scheme runs. It has no
comparison case: its ``2 (n + 1)`` frictional contacts are all closed at
once, sticking while it stands and opening at the hinges of a mechanism
when it collapses, beyond the event-driven reference; its dynamics is held
instead to an independent statics, the thrust-line LP of
:func:`limit_thickness` (stands above it, collapses below it).

Scales
------
Lengths in ``R``, masses in one voussoir's mass, time in ``sqrt(R / g)``.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from .._validate import nonnegative, positive, positive_int
from ..errors import InputError
from ..integrators import simulate
from ..model.planar import HalfPlane, Model, Polygon
from ..model.params import GRAVITY, MU, POSITIVE, RADIUS, Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with

__all__ = ["MasonryArchParams", "masonry_arch", "arch_model", "voussoir_geometry",
           "limit_thickness", "stands", "minimal_thickness", "PRELOAD"]

#: how far (in R) each contact starts closed, so that Moreau–Jean's first index set holds it
PRELOAD = 1e-14


@dataclass(frozen=True)
class MasonryArchParams(Declared):
    """SI parameters of the masonry arch."""

    voussoirs: int = param(4, doc="Number of voussoirs ``n``", note="In [2, 60].")
    thickness: float = param(0.15, doc="Thickness over centreline radius ``t / R``",
                             note="In (0, 1).")
    radius: float = RADIUS(1.0, "Centreline radius ``R``")
    mu: float = MU(0.6, "Friction coefficient of every joint",
                   note="0.6: enough for the semicircular arch, whose limit needs 0.4 at most, "
                        "see :func:`limit_thickness`.")
    density: float = param(2000.0, "kg/m^3", POSITIVE, "Density of the stone")
    depth: float = param(0.5, "m", POSITIVE, "Depth of the arch, out of its plane")
    gravity: float = GRAVITY(9.81)

    def __post_init__(self):
        n = self.voussoirs
        if isinstance(n, float) and n.is_integer():
            n = int(n)
        n = positive_int("voussoirs", n)
        if not 2 <= n <= 60:
            raise InputError(f"`voussoirs` must be in [2, 60], got {n!r}")
        object.__setattr__(self, "voussoirs", n)
        t = positive("thickness", self.thickness)
        if t >= 1.0:
            raise InputError(f"`thickness` (t / R) must be < 1 (the intrados radius "
                             f"R (1 - t/2) > 0 with room), got {t!r}")
        object.__setattr__(self, "thickness", t)
        super().__post_init__()


def voussoir_geometry(n, thickness):
    """The voussoirs of a unit-radius arch: joint angles, corners, weights, centroids, inertias.

    Parameters
    ----------
    n : int
    thickness : float
        ``t / R``.

    Returns
    -------
    dict
        ``theta`` (n + 1 joint angles, from pi to 0), ``corners`` (n, 4, 2:
        left intrados, right intrados, right extrados, left extrados,
        counter-clockwise), ``area`` (of one voussoir), ``centroid`` (n, 2),
        ``inertia`` (centroidal polar moment of one voussoir over its area).

    Examples
    --------
    >>> g = voussoir_geometry(2, 0.2)
    >>> [round(float(x), 12) for x in g["corners"][0, 0]], round(g["area"], 12)
    ([-0.9, 0.0], 0.314159265359)
    """
    ri, re = 1.0 - 0.5 * thickness, 1.0 + 0.5 * thickness
    alpha = 0.5 * math.pi / n
    theta = math.pi * (1.0 - np.arange(n + 1) / n)
    area = alpha * (re ** 2 - ri ** 2)
    rc = (2.0 / 3.0) * (re ** 3 - ri ** 3) / (re ** 2 - ri ** 2) * math.sin(alpha) / alpha
    # polar moment about the arch's centre over the area, minus the centroid's share
    inertia = 0.5 * (re ** 2 + ri ** 2) - rc ** 2
    mid = 0.5 * (theta[:-1] + theta[1:])
    centroid = rc * np.column_stack([np.cos(mid), np.sin(mid)])
    u0 = np.column_stack([np.cos(theta[:-1]), np.sin(theta[:-1])])
    u1 = np.column_stack([np.cos(theta[1:]), np.sin(theta[1:])])
    corners = np.stack([ri * u0, ri * u1, re * u1, re * u0], axis=1)
    return dict(theta=theta, corners=corners, area=area, centroid=centroid, inertia=inertia)


def arch_model(params=None, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the arch (SI parameters of :class:`MasonryArchParams`)."""
    p = params_with(MasonryArchParams, params, overrides)
    R, n = p.radius, p.voussoirs
    geo = voussoir_geometry(n, p.thickness)
    mass = p.density * p.depth * geo["area"] * R * R
    inertia = mass * geo["inertia"] * R * R
    m = Model(gravity=(0.0, -p.gravity), length=R, mass=mass, time=math.sqrt(R / p.gravity))
    ground = m.add_shape(m.ground, HalfPlane((0.0, PRELOAD * R), (0.0, 1.0)))
    th = geo["theta"]
    prev = None
    for k in range(n):
        c = geo["centroid"][k] * R
        corners = geo["corners"][k] * R - c
        body = m.add_body(mass, inertia, position=tuple(c), name=f"voussoir{k}")
        block = m.add_shape(body, Polygon(corners))
        if prev is None:
            m.add_contact(block, ground, mu=p.mu, vertices=(0, 3))
        else:
            # the left neighbour's right joint face, its outward normal -e_theta at theta_k
            nrm = np.array([math.sin(th[k]), -math.cos(th[k])])
            face = m.add_shape(prev[0], HalfPlane(tuple(prev[1] + PRELOAD * R * nrm), tuple(nrm)))
            m.add_contact(block, face, mu=p.mu, vertices=(0, 3))
        prev = (body, geo["corners"][k][1] * R - c)
    m.add_contact(block, ground, mu=p.mu, vertices=(1, 2))
    return m


def _in_place(t, q, v):
    # rotations small enough for each joint's corners to stay on their neighbour's face
    th = np.asarray(q)[..., 2::3]
    return np.all(np.abs(th) < 0.2, axis=-1)


def masonry_arch(params=None, **overrides):
    """The arch's scene (a :class:`~moreau.model.planar.PlanarScene`, units ``R``, one voussoir's mass, ``sqrt(R / g)``).

    Examples
    --------
    >>> sc = masonry_arch(voussoirs=4, thickness=0.2)
    >>> sc.ndof, len(sc.mu)
    (12, 10)
    >>> q0, _ = sc.initial_state()
    >>> bool(np.all(np.abs(sc.gaps(q0, 0.0) + 1e-14) < 1e-15))   # doctest: +SKIP
    True
    """
    return arch_model(params, **overrides).build(
        "masonry-arch", valid_region="every voussoir turned by less than 0.2 rad",
        inside=_in_place, default_window=10.0)


masonry_arch.Params = MasonryArchParams


# -- the exact limit (safe theorem, an LP) ----------------------------------------------------

def _thrust_fits(n, thickness, mu):
    geo = voussoir_geometry(n, thickness)
    ri, re = 1.0 - 0.5 * thickness, 1.0 + 0.5 * thickness
    th = geo["theta"]
    nv = 3 * (n + 1)
    # unknowns per joint j: the force (Fx, Fy) the part left of it puts on the part right of
    # it, and its moment M about the arch's centre. Its normal N = F . (sin, -cos) (towards
    # the right part) and M = -rho N with rho the radius where its line crosses the joint
    A_eq = np.zeros((3 * n, nv))
    b_eq = np.zeros(3 * n)
    w = geo["area"]
    for k in range(n):
        for c in range(3):
            A_eq[3 * k + c, 3 * k + c] = 1.0
            A_eq[3 * k + c, 3 * (k + 1) + c] = -1.0
        # F_k - F_{k+1} + (0, -w) = 0 and M_k - M_{k+1} - w x_c = 0
        b_eq[3 * k + 1] = w
        b_eq[3 * k + 2] = w * geo["centroid"][k, 0]
    rows = []
    for j in range(n + 1):
        s, c = math.sin(th[j]), math.cos(th[j])
        o = 3 * j
        # R_i N <= -M <= R_e N (the line crosses the joint between its corners; N >= 0 follows)
        rows.append({o: ri * s, o + 1: -ri * c, o + 2: 1.0})
        rows.append({o: -re * s, o + 1: re * c, o + 2: -1.0})
        # |T| <= mu N, T = F . (cos, sin)
        rows.append({o: c - mu * s, o + 1: s + mu * c})
        rows.append({o: -c - mu * s, o + 1: -s + mu * c})
    A_ub = np.zeros((len(rows), nv))
    for i, r in enumerate(rows):
        for col, val in r.items():
            A_ub[i, col] = val
    res = linprog(np.zeros(nv), A_ub=A_ub, b_ub=np.zeros(len(rows)), A_eq=A_eq, b_eq=b_eq,
                  bounds=[(None, None)] * nv, method="highs")
    if res.status not in (0, 2):
        raise InputError(f"the thrust-line LP ended with status {res.status}: {res.message}")
    return res.status == 0


def limit_thickness(voussoirs, mu=0.6, tol=1e-7):
    """The least ``t / R`` at which a thrust line fits the arch of ``voussoirs`` blocks (safe theorem).

    An equilibrium of the voussoirs' weights by joint forces, each crossing
    its joint between the intrados and the extrados, inside the friction
    cone (Heyman's safe theorem; with ``mu`` large the friction rows never
    bind), exists for ``t / R`` above this value and for none below it.
    Each thickness is one feasibility LP (the three equations of each
    voussoir, two bounds a joint on where the thrust crosses, two on its
    inclination; scipy's HiGHS); the limit is bisected to ``tol``. The
    LP is independent of the simulation: statics only.

    Parameters
    ----------
    voussoirs : int
        ``n >= 2``.
    mu : float
        Friction coefficient of the joints.
    tol : float
        Width of the final bracket.

    Examples
    --------
    >>> round(limit_thickness(10), 5)
    0.10746
    """
    n = positive_int("voussoirs", voussoirs)
    if n < 2:
        raise InputError(f"`voussoirs` must be >= 2, got {n}")
    mu = nonnegative("mu", mu)
    lo, hi = 1e-4, 0.9
    if not _thrust_fits(n, hi, mu):
        raise InputError(f"no thrust line fits even at t / R = {hi} with mu = {mu}: "
                         f"the joints slide (raise `mu`)")
    if _thrust_fits(n, lo, mu):
        return lo
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if _thrust_fits(n, mid, mu):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


# -- stand or collapse, from a simulation ------------------------------------------------------

#: the criterion's settings (module docstring): step, window [sqrt(R/g)], displacement bound [R]
STAND_H, STAND_WINDOW, STAND_BOUND = 0.01, 1.0, 1e-6


def stands(window=STAND_WINDOW, h=STAND_H, bound=STAND_BOUND, lcp_method="auto", **params):
    """Whether the arch stands, from a Moreau–Jean run from rest (criterion: module docstring).

    Returns
    -------
    (bool, float)
        Standing, and the largest centroid displacement over the run [R]
        (``inf`` where the run left the valid region: a collapse).

    Examples
    --------
    >>> stands(window=1.0, voussoirs=4, thickness=0.3)[0]   # doctest: +SKIP
    True
    """
    sc = masonry_arch(**params)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, float(window)), q0, v0, "moreau-jean", h=h, lcp_method=lcp_method)
    if res.status == -6:
        return False, math.inf
    if not res.success:
        raise InputError(f"the arch's run failed: {res.message}")
    dq = (res.q - q0).reshape(len(res.t), -1, 3)[:, :, :2]
    moved = float(np.max(np.hypot(dq[..., 0], dq[..., 1])))
    return moved <= bound, moved


def minimal_thickness(voussoirs, lo=0.05, hi=0.2, tol=1e-3, **kwargs):
    """The least ``t / R`` at which :func:`stands` holds, by bisection to a relative ``tol``.

    Returns
    -------
    (float, list)
        The bracket's midpoint and the ``(t / R, stands, displacement)`` of each run.
    """
    log = []
    for t in (lo, hi):
        ok, d = stands(voussoirs=voussoirs, thickness=t, **kwargs)
        log.append((t, ok, d))
    if log[0][1] or not log[1][1]:
        raise InputError(f"`lo` = {lo} must collapse and `hi` = {hi} stand; got {log}")
    while hi - lo > tol * hi:
        mid = 0.5 * (lo + hi)
        ok, d = stands(voussoirs=voussoirs, thickness=mid, **kwargs)
        log.append((mid, ok, d))
        if ok:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi), log


register_scene(SceneEntry(
    name="masonry-arch",
    factory=masonry_arch,
    description=("a semicircular arch of voussoirs on two abutments under its own weight: "
                 "stands or collapses with its thickness (Heyman 1966, Milankovitch 1907)"),
))
