"""The collapse of a column of disks on a rough floor, and its runout against the aspect ratio.

A column of ``L0`` wide and ``H0`` high (aspect ratio ``a = H0 / L0``) of
rigid disks (radii uniform in ``[spread r, r]``, ``r`` half the ``diameter``)
stands on a rough floor against a wall on its left, held by a frictionless
gate on its right; the gate is removed and the column collapses and
spreads to the right. The runout ``(L_inf - L0) / L0`` (``L_inf`` the
foot of the deposit: the farthest edge of its largest connected cluster, so
that a grain rolling away on its own does not count) depends on ``a`` alone
in the experiments, as ``lambda a`` for small ``a`` and as a power of
``a`` below one for large ``a``:

* G. Lube, H. E. Huppert, R. S. J. Sparks and M. A. Hallworth, *Axisymmetric
  collapses of granular columns*, J. Fluid Mech. 508 (2004) 175-199;
* E. Lajeunesse, A. Mangeney-Castelnau and J. P. Vilotte, *Spreading of a
  granular mass on a horizontal plane*, Phys. Fluids 16 (2004) 2371-2381;
* in a channel (two dimensions), N. J. Balmforth and R. R. Kerswell,
  *Granular collapse in two dimensions*, J. Fluid Mech. 538 (2005) 399-428:
  ``(l_inf - L) / L ~ a^(0.9 +- 0.1)`` in wide channels, ``a^(0.65 +- 0.05)``
  in narrow slots, the prefactors depending on the material;
* with two-dimensional discrete grains by the same contact dynamics as here
  (Moreau–Jean, rigid disks, Coulomb friction): L. Staron and E. J. Hinch,
  *Study of the collapse of granular columns using two-dimensional
  discrete-grain simulation*, J. Fluid Mech. 545 (2005) 1-27: runout
  linear in ``a`` for small ``a`` and a power ``a^(2/3)`` for large ``a``.

Measured at six grains wide (``runout_study`` with ``width = 6 d``, ``mu = 0.5``, ``e = 0``,
``h = 0.01``, ``max_time = 80``, ``settle_time = 30``, seed 0), the two ranges apart:

* large ``a``: ``a`` = 2.32, 4.38, 8.70 ran out 2.48, 5.21, 10.68 (the last still
  creeping at ``80 sqrt(d / g)``): the log-log slope over the three is 1.10 (1.05
  between the last two), against Balmforth and Kerswell's ``0.65 +- 0.05`` (narrow
  slots) and ``0.9 +- 0.1`` (wide channels) and Staron and Hinch's ``2/3``;
* small ``a``: ``a`` = 0.61, 1.17, 1.65 ran out 3.07 (a front one grain thick still
  rolling at ``t = 80``), -0.02 (the column stood: its packing jammed between floor
  and wall when the gate went) and 2.49: no power law at all, where the experiments
  give a runout proportional to ``a``.

What the model lacks, and why it is not tuned to the experiments' numbers: at
``mu_r = 0`` (the default) rigid disks roll without resistance (real grains, angular
or rough, resist rolling), so a thin front keeps rolling and the runout depends on
how long the run is; and a column
six grains wide is far narrower, in grains, than the experiments' columns and Staron
and Hinch's, so that one jammed arch of grains decides whether a short column
collapses at all.

With rolling resistance (``mu_r = 0.1 d``, :mod:`moreau.model.granular`), measured
at the same width, ``max_time`` and ``settle_time``, seed 0: from the start lattice
the disks stack in its columns and stand apart (``a`` = 2 and 4 gave a "deposit"
one stack wide); with ``scatter = 0.5`` (random horizontal start speeds) ``a`` =
2.68 and 4.56 ran out 1.44 and 3.85, both fronts stopped (at 1932 and 2664 steps,
settling included), a log-log slope of 1.85 over the two; the same fills without
rolling resistance, ``a`` = 2.26 and 4.30, ran out 2.64 (still creeping at
``t = 80``) and 5.54 (stopped), a slope of 1.15. Two points each: no power law is
fitted, and neither is near Staron and Hinch's 2/3 or Balmforth and Kerswell's
``0.65 +- 0.05`` .. ``0.9 +- 0.1`` (the tallest column, ``a`` = 8, was not run with
rolling resistance).

:func:`collapse` runs one column with the broad phase every step
(:func:`moreau.integrators.granular.simulate_disks`); :func:`runout_study`
runs several aspect ratios and fits both laws (:func:`fit_runout`).

The registered scene (``make_scene("granular-column")``) is the column at
its release, the disks on their loose start lattice, as a
:class:`~moreau.model.granular.DiskScene` whose candidate contacts are every
pair of disks and every disk with the floor and the wall (``margin=None``):
each step measures them all, so the contacts close and open as the column
collapses and spreads, however far it runs (every scheme runs it; ``moreau
run`` takes Moreau–Jean with NSGS where no scheme is named). The pairs grow
as the square of the disks: the scene takes at most
:data:`~moreau.model.granular.EVERY_PAIR_MAX` disks (61 at ``width = 0.035``
at ``aspect = 1``; the default, 20 disks, 230 candidates); :func:`collapse`
runs larger columns with the broad phase. Units: the ``diameter`` ``d``,
``sqrt(d / g)``, the mass ``density d^2`` of a unit square of grains.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components

from .._validate import nonnegative
from ..errors import InputError
from ..integrators.granular import settle, simulate_disks
from ..model.granular import (EVERY_PAIR_MAX, DiskScene, DiskSystem, HalfPlane, grid_pairs,
                              random_fill)
from ..model.params import GRAVITY, POSITIVE, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with
from ._grains import (DENSITY, DIAMETER, GRAIN_MU, GRAIN_RESTITUTION, MU_R, SEED, SPREAD, WIDTH,
                      Grains)

__all__ = ["GranularColumnParams", "granular_column", "column_system", "deposit_front",
           "collapse", "runout_study", "fit_runout"]

#: the packing fraction the disk count is estimated with (a settled random packing of
#: disks of radii 0.8 r .. r, measured about 0.8); the column's actual height is measured
_PACKING = 0.8


@dataclass(frozen=True)
class GranularColumnParams(Grains):
    """SI parameters of the column (see the module docstring)."""

    width: float = WIDTH(0.02, "Width ``L0`` of the column")
    aspect: float = param(1.0, "", POSITIVE, "The aspect ratio aimed at, ``H0 / L0``",
                          "The column is filled to it and settles a little lower: "
                          ":func:`collapse` measures it.")
    diameter: float = DIAMETER(0.005)
    spread: float = SPREAD(0.8)
    density: float = DENSITY(10.0)
    mu: float = GRAIN_MU(0.5, "Friction between grains")
    mu_floor: float = GRAIN_MU(0.5, "Friction with the floor")
    mu_wall: float = GRAIN_MU(0.5, "Friction with the left wall")
    restitution: float = GRAIN_RESTITUTION(0.0)
    gravity: float = GRAVITY(9.81)
    seed: int = SEED(0)
    mu_r: float = MU_R(0.0, note="0: the grains roll freely (:mod:`moreau.model.granular`). The "
                                 "registered scene takes only 0; :func:`collapse` takes any.")


def column_system(params=None, *, gate=True, **overrides):
    """The column's :class:`DiskSystem` and its start centres, in grain units.

    Returns
    -------
    system : DiskSystem
        Floor (wall 0), left wall (wall 1) and, with ``gate``, the
        frictionless gate at ``x = L0`` (wall 2).
    x0 : ndarray, shape (N, 2)
        The disks on a loose lattice filling ``L0 x a L0`` (at the packing
        fraction of a settled column, about 0.8).
    L0 : float
        In diameters.

    Examples
    --------
    >>> sys, x0, L0 = column_system(width=0.02, aspect=0.5)
    >>> sys.n_disks, sys.n_walls, L0
    (10, 3, 4.0)
    """
    p = params_with(GranularColumnParams, params, overrides)
    L0 = p.width / p.diameter
    r_max, r_min = 0.5, 0.5 * p.spread
    mean_area = math.pi * (r_max ** 3 - r_min ** 3) / (3.0 * (r_max - r_min)) \
        if r_max > r_min else math.pi * r_max ** 2
    n = max(2, int(round(_PACKING * p.aspect * L0 * L0 / mean_area)))
    radii, x0 = random_fill(n, L0, r_min, r_max, seed=p.seed)
    walls = [HalfPlane((0.0, 0.0), (0.0, 1.0), mu=p.mu_floor),
             HalfPlane((0.0, 0.0), (1.0, 0.0), mu=p.mu_wall)]
    if gate:
        walls.append(HalfPlane((L0, 0.0), (-1.0, 0.0), mu=0.0, mu_r=0.0))
    sys = DiskSystem(radii, math.pi * radii ** 2, walls=walls, mu=p.mu,
                     restitution=p.restitution, gravity=(0.0, -1.0), mu_r=p.mu_r / p.diameter)
    return sys, x0, L0


def granular_column(params=None, **overrides):
    """The registered scene: the column at its release (a :class:`DiskScene`, module docstring).

    Every pair of disks and every disk with the floor and the wall is a
    candidate contact; a column of more than
    :data:`~moreau.model.granular.EVERY_PAIR_MAX` disks is refused, naming
    ``width`` and ``aspect``.

    Examples
    --------
    >>> sc = granular_column(width=0.02, aspect=0.5)
    >>> sc.name, sc.ndof, sc.ncontacts, bool(np.all(sc.gaps(sc.initial_state()[0], 0.0) >= 0.0))
    ('granular-column', 30, 65, True)
    """
    p = params_with(GranularColumnParams, params, overrides)
    sys, x0, _ = column_system(p, gate=False)
    if sys.n_disks > EVERY_PAIR_MAX:
        raise InputError(f"`width` = {p.width!r} m and `aspect` = {p.aspect!r} fill the column "
                         f"with {sys.n_disks} disks; the registered scene (every pair a "
                         f"candidate contact) takes at most {EVERY_PAIR_MAX}: run collapse() "
                         f"for a larger column (a broad phase every step)")
    d = p.diameter
    return DiskScene(sys, x0, margin=None, name="granular-column", length=d,
                     time=math.sqrt(d / p.gravity), force=p.density * d * d * p.gravity,
                     default_window=2.0)


granular_column.Params = GranularColumnParams


def deposit_front(x, radii, gap=0.05):
    """The farthest right edge of the largest cluster of disks (touching within ``gap``).

    Examples
    --------
    >>> deposit_front([[0.5, 0.5], [1.5, 0.5], [9.0, 0.5]], [0.5, 0.5, 0.5])
    2.0
    """
    x = np.asarray(x, dtype=float)
    radii = np.asarray(radii, dtype=float)
    n = radii.size
    i, j = grid_pairs(x, radii, gap)
    graph = coo_array((np.ones(i.size), (i, j)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    main = label == np.argmax(np.bincount(label))
    return float(np.max(x[main, 0] + radii[main]))


def collapse(params=None, *, h=0.01, tol=1e-5, max_sweeps=500, max_time=200.0,
             settle_time=60.0, scatter=0.0, **overrides):
    """Settle the column behind its gate, remove the gate, and measure the deposit.

    The collapse runs until the deposit's front (:func:`deposit_front`) has
    moved less than ``0.02 d`` over one time unit ``sqrt(d / g)``, after
    ``2 sqrt(2 H0)`` at least (a grain rolling away alone on a flat floor
    never stops, so the speeds do not tell), or ``max_time``. Rigid disks
    have no rolling resistance: a deposit one grain thick at its front keeps
    creeping, and its run ends at ``max_time`` with ``stopped`` False.
    ``scatter``: the disks start settling with horizontal speeds drawn
    uniformly in ``[-scatter, scatter]`` (grain units, seeded), which breaks
    up the start lattice's columns (disks with rolling resistance stacked
    on each other stand in them).

    Returns
    -------
    dict
        ``aspect`` (measured ``H0 / L0``), ``L0``, ``H0``, ``L_inf`` (in
        diameters), ``runout`` ``(L_inf - L0) / L0``, ``n_disks``,
        ``steps``, ``unconverged`` (steps whose NSGS solve ended above
        ``tol``), ``max_residual``, ``stopped`` (True: the front stopped
        before ``max_time``).
    """
    p = params_with(GranularColumnParams, params, overrides)
    scatter = nonnegative("scatter", scatter)
    sys, x0, L0 = column_system(p, gate=True)
    opts = dict(theta=1.0, tol=tol, max_sweeps=max_sweeps)
    v0 = np.zeros((sys.n_disks, 3))
    if scatter > 0.0:
        v0[:, 0] = np.random.default_rng(p.seed + 1).uniform(-scatter, scatter, sys.n_disks)
    packed = settle(sys, x0, v0, h,
                    max_steps=int(settle_time / h), speed_tol=2e-3, **opts)
    x = packed.x[-1]
    H0 = float(np.max(x[:, 1] + sys.radii))
    free, _, _ = column_system(p, gate=False)
    fronts = []
    per = max(1, int(round(1.0 / h)))

    # the column falls for about sqrt(2 H0) (Staron and Hinch: the collapse is a free fall),
    # slowly at first: the front is not judged before twice that
    t_min = 2.0 * math.sqrt(2.0 * H0)

    def front_stopped(k, t, xk, vk):
        if (k + 1) % per:
            return False
        fronts.append(deposit_front(xk, free.radii))
        return (k + 1) * h >= t_min and abs(fronts[-1] - fronts[-2]) < 0.02

    run = simulate_disks(free, x, np.zeros((free.n_disks, 3)), int(max_time / h), h,
                         phi0=packed.phi[-1], warm=packed.impulses, save_every=10 ** 9,
                         callback=front_stopped, **opts)
    L_inf = deposit_front(run.x[-1], free.radii)
    both = np.concatenate([packed.steps["converged"], run.steps["converged"]])
    res = np.concatenate([packed.steps["residual"], run.steps["residual"]])
    return {"aspect": H0 / L0, "L0": L0, "H0": H0, "L_inf": L_inf, "runout": (L_inf - L0) / L0,
            "n_disks": sys.n_disks, "steps": int(both.size),
            "unconverged": int(np.count_nonzero(~both)), "max_residual": float(np.max(res)),
            "stopped": run.steps["t"].size < int(max_time / h)}


def fit_runout(aspect, runout, a_split=2.0):
    """Fit ``runout = lambda a`` for ``a <= a_split`` and ``runout = c a^p`` above.

    The small range is also fitted by a power ``c_small a^p_small`` (a line
    in log-log), so that both ranges' exponents are reported side by side
    (the experiments: ``p_small = 1``, ``p`` below one).

    Returns
    -------
    dict
        ``lambda`` (least squares through the origin), ``c``, ``p`` (a line
        in log-log), ``c_small``, ``p_small``, each None without the points
        to fit it (two at least, every runout > 0, for a power).

    Examples
    --------
    >>> f = fit_runout([0.5, 1.0, 4.0, 8.0], [1.0, 2.0, 2.0 * 4 ** (2 / 3), 2.0 * 8 ** (2 / 3)])
    >>> round(f["lambda"], 6), round(f["c"], 6), round(f["p"], 6), round(f["p_small"], 6)
    (2.0, 2.0, 0.666667, 1.0)
    """
    a = np.asarray(aspect, dtype=float)
    r = np.asarray(runout, dtype=float)
    small, large = a <= a_split, a > a_split
    out = {"lambda": None, "c": None, "p": None, "c_small": None, "p_small": None,
           "a_split": float(a_split)}
    if small.any():
        out["lambda"] = float(a[small] @ r[small] / (a[small] @ a[small]))
    for part, c_key, p_key in ((large, "c", "p"), (small, "c_small", "p_small")):
        if np.count_nonzero(part) >= 2 and np.all(r[part] > 0):
            p, logc = np.polyfit(np.log(a[part]), np.log(r[part]), 1)
            out[c_key], out[p_key] = float(math.exp(logc)), float(p)
    return out


def runout_study(aspects=(0.5, 1.0, 2.0, 4.0, 8.0), *, width=0.03, a_split=2.0, **options):
    """:func:`collapse` at each aspect ratio; the rows and :func:`fit_runout` of them.

    ``options`` go to :func:`collapse` (parameters of
    :class:`GranularColumnParams` and the run's ``h``, ``tol``, ...).
    """
    rows = [collapse(aspect=a, width=width, **options) for a in aspects]
    fit = fit_runout([r["aspect"] for r in rows], [r["runout"] for r in rows], a_split)
    return rows, fit


register_scene(SceneEntry(
    name="granular-column",
    factory=granular_column,
    description=("collapse of a column of disks on a rough floor (runout against the aspect "
                 "ratio; contacts found every step by a broad phase in its study)"),
))
