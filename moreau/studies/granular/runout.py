"""The granular column's runout against its aspect ratio, each column as wide as its size needs.

The normalised runout ``(L_inf - L0) / L0`` of a collapsing column depends
on its aspect ratio ``a = H0 / L0`` alone in the experiments. In
two-dimensional (channel) geometry:

* E. Lajeunesse, J. B. Monnier and G. M. Homsy, *Granular slumping on a
  horizontal surface*, Phys. Fluids 17 (2005) 103302: linear in ``a`` for
  ``a`` below about 3, ``a^(2/3)`` beyond;
* G. Lube, H. E. Huppert, R. S. J. Sparks and A. Freundt, *Collapses of
  two-dimensional granular columns*, Phys. Rev. E 72 (2005) 041301: the
  same two branches, ``a`` and ``a^(2/3)``;
* L. Staron and E. J. Hinch, J. Fluid Mech. 545 (2005) 1-27, with
  two-dimensional discrete grains (rigid disks, contact dynamics as here):
  the same exponents.

Only the exponents are compared here (1 below the crossover, 2/3 above);
the prefactors depend on the material and are not.

:func:`runout_rows` collapses one column per ``(a, L0)`` pair
(:func:`moreau.scenes.granular_column.collapse`, the broad phase every
step), so that a short column can be wide and a tall one narrow at a
similar number of grains; :func:`moreau.scenes.granular_column.fit_runout`
fits both branches. :func:`runout_ensemble` runs every column once per
seed (independent fillings) and :func:`runout_summary` gives each
column's mean and spread over the seeds and both branches fitted on every
run, with standard errors. ``benchmarks/granular_runout.py`` runs it a
row at a time, writing each as it finishes.

Measured (the defaults above, ``mu = mu_floor = mu_wall = 0.5``, ``e = 0``,
``h = 0.01``, ``tol = 1e-5``, 500 sweeps; every front stopped before
``max_time``; 15 to 164 s of CPU a column; 7-48 % of the steps ended above
``tol``), each column with three seeds (:func:`runout_ensemble`; seed 0
from the first run of this protocol, seeds 1 and 2 after it):

=========  ========  =====  ===============  ===========================  =====  =====
``a`` aim  ``L0/d``  disks  ``a`` (mean,sd)  runout per seed (0, 1, 2)    mean   sd
=========  ========  =====  ===============  ===========================  =====  =====
0.5        10        72     0.64, 0.02       0.13, 0.39, 0.26             0.26   0.13
1          8         93     1.27, 0.09       0.43, 0.65, 0.56             0.54   0.11
2          6         104    2.43, 0.10       1.65, 2.03, 1.55             1.75   0.25
4          5         145    4.65, 0.14       3.08, 2.32, 2.92             2.77   0.40
8          4         185    9.56, 0.21       5.28, 4.34, 6.05             5.22   0.86
=========  ========  =====  ===============  ===========================  =====  =====

The runout ``(L_inf - L0) / L0`` scatters over seeds by 14-50 % of its mean
(sample standard deviation), so one seed a column says little. Fitted on
every run (:func:`runout_summary`, split at ``a = 3``): the tall branch
(six runs at two aspect ratios, 4.65 and 9.56) ``0.69 a^(0.89 +- 0.15)``,
the experiments' exponent 2/3 1.5 standard errors below; the short branch
(nine runs, ``a`` 0.64 to 2.43) ``0.43 a^(1.47 +- 0.21)``, least squares
through the origin ``lambda = 0.64 +- 0.06``. The data reach the short
branch's lower end only: between the means at ``a = 0.64`` and ``1.27``
the log-log slope is 1.07 (linear, as in the experiments), between 1.27
and 2.43 it is 1.81, and above 0.71 (2.43 to 4.65) and 0.88 (4.65 to
9.56). With rolling resistance ``0.1 d`` a short column of rigid disks
barely spreads (0.26 at ``a = 0.64``), and the steep rise between
``a = 1.3`` and 2.4 is where the crossover falls here; the split at 3 is
the protocol's (Lajeunesse et al.), set before these runs (split at 2
instead: ``a^(0.80 +- 0.08)`` above, ``lambda = 0.43 +- 0.04`` below).
The columns aimed at ``a`` settle taller than aimed at narrow ``L0`` (the
packing estimate of :func:`~moreau.scenes.granular_column.column_system`);
the measured ``a`` is used, each run by its own.
"""

import math

import numpy as np

from ..._validate import positive
from ...errors import InputError
from ...scenes.granular_column import collapse, fit_runout

__all__ = ["runout_rows", "runout_ensemble", "runout_summary"]

#: the study's defaults: ``+-20 %`` radii, rolling resistance a tenth of a diameter,
#: random horizontal start speeds (columns of rolling-resistant disks stand in the start
#: lattice's stacks otherwise: :mod:`moreau.scenes.granular_column`)
DEFAULTS = {"spread": 2.0 / 3.0, "mu_r": 0.1 * 0.005, "diameter": 0.005, "scatter": 0.5,
            "max_time": 80.0, "settle_time": 30.0}


def runout_rows(cases, *, a_split=3.0, on_row=None, **options):
    """Collapse one column per ``(aspect, L0)`` (``L0`` in diameters); the rows and their fit.

    ``options`` go to :func:`~moreau.scenes.granular_column.collapse` over
    the study's defaults (``spread = 2/3``, ``mu_r = 0.1 d``, ``scatter =
    0.5``, ``max_time = 80``, ``settle_time = 30``). ``on_row(row)`` is
    called as each column finishes. ``a_split`` divides the two branches
    (the measured aspect ratios; Lajeunesse et al.: about 3).

    Returns
    -------
    rows : list of dict
        :func:`~moreau.scenes.granular_column.collapse`'s, each with ``aim``.
    fit : dict
        :func:`~moreau.scenes.granular_column.fit_runout` of the rows.

    Examples
    --------
    >>> rows, fit = runout_rows([(0.5, 3.0)], max_time=0.3, settle_time=0.2)
    >>> len(rows), rows[0]["L0"], fit["p"] is None
    (1, 3.0, True)
    """
    cases = [(float(a), float(L0)) for a, L0 in cases]
    if not cases:
        raise InputError("`cases` must hold one (aspect, L0) pair at least")
    opts = {**DEFAULTS, **options}
    d = opts["diameter"]
    rows = []
    for a, L0 in cases:
        row = collapse(aspect=a, width=L0 * d, **opts)
        row["aim"] = a
        rows.append(row)
        if on_row is not None:
            on_row(row)
    fit = fit_runout([r["aspect"] for r in rows], [r["runout"] for r in rows], a_split)
    return rows, fit


def runout_ensemble(cases, seeds, *, a_split=3.0, on_row=None, **options):
    """Collapse every ``(aspect, L0)`` column once per seed; the rows and their summary.

    The seed draws the column's radii, its start lattice's jitter and its
    start speeds (:func:`~moreau.scenes.granular_column.collapse`), so each
    seed is an independent filling of the same column. The columns run one
    at a time, every case with one seed before the next seed (an interrupted
    run keeps whole curves); ``on_row(row)`` is called as each finishes.
    ``options`` as for :func:`runout_rows`.

    Returns
    -------
    rows : list of dict
        :func:`runout_rows`'s, each with its ``seed``.
    summary : dict
        :func:`runout_summary` of the rows.

    Examples
    --------
    >>> rows, s = runout_ensemble([(0.5, 3.0)], [0, 1], max_time=0.3, settle_time=0.2)
    >>> [r["seed"] for r in rows], s["n"].tolist(), s["p"] is None
    ([0, 1], [2], True)
    """
    cases = [(float(a), float(L0)) for a, L0 in cases]
    if not cases:
        raise InputError("`cases` must hold one (aspect, L0) pair at least")
    seeds = _seeds(seeds)
    a_split = positive("a_split", a_split)
    rows = []
    for seed in seeds:
        def tag(row, seed=seed):
            row["seed"] = seed
            if on_row is not None:
                on_row(row)

        rows += runout_rows(cases, a_split=a_split, on_row=tag, seed=seed, **options)[0]
    return rows, runout_summary(rows, a_split=a_split)


def runout_summary(rows, *, a_split=3.0):
    """Mean and spread of the runout over seeds per column, and both branches fitted with errors.

    Parameters
    ----------
    rows : sequence of dict
        One per column run, each with ``aim`` (the aspect ratio aimed at),
        ``L0``, ``aspect`` (measured) and ``runout``; the runs of one
        ``(aim, L0)`` are seeds of one column.
    a_split : float
        The branches' divide on the measured aspect ratio (each run by its own).

    Returns
    -------
    dict
        Per column (sorted by ``aim``): ``aim``, ``L0``, ``n`` (runs),
        ``aspect`` and ``runout`` (means), ``aspect_std``, ``runout_std``
        (standard deviations over the seeds, ``ddof = 1``; NaN for one run),
        ``runout_sem`` (``runout_std / sqrt(n)``). The fits on every run:
        ``c``, ``p`` and ``p_se`` (``runout = c a^p`` above ``a_split``, a
        line in log-log, the slope's standard error from the residuals;
        None without three runs at two aspect ratios at least), ``c_small``,
        ``p_small``, ``p_small_se`` (the same below), ``lambda`` and
        ``lambda_se`` (``runout = lambda a`` below, least squares through
        the origin; None without two runs), ``a_split``.

    Examples
    --------
    Two seeds of three columns on ``2 a^(2/3)`` above ``a = 3``, ``+-0.1`` about it:

    >>> a = [4.0, 4.0, 8.0, 8.0, 16.0, 16.0]
    >>> r = [2 * x ** (2 / 3) + d for x, d in zip(a, [0.1, -0.1] * 3)]
    >>> rows = [{"aim": x, "L0": 5.0, "aspect": x, "runout": y} for x, y in zip(a, r)]
    >>> s = runout_summary(rows)
    >>> s["runout"].round(4).tolist(), s["runout_std"].round(4).tolist()
    ([5.0397, 8.0, 12.6992], [0.1414, 0.1414, 0.1414])
    >>> round(s["p"], 2), s["p_se"] < 0.02, s["lambda"] is None
    (0.67, True, True)
    """
    rows = list(rows)
    if not rows:
        raise InputError("`rows` must hold one run at least")
    a_split = positive("a_split", a_split)
    for k, row in enumerate(rows):
        missing = [key for key in ("aim", "L0", "aspect", "runout") if key not in row]
        if missing:
            raise InputError(f"`rows` must give every run's aim, L0, aspect and runout; run {k} "
                             f"lacks {', '.join(missing)}")
    groups = {}
    for row in rows:
        groups.setdefault((float(row["aim"]), float(row["L0"])), []).append(row)
    keys = sorted(groups)
    out = {"aim": np.array([k[0] for k in keys]), "L0": np.array([k[1] for k in keys]),
           "n": np.array([len(groups[k]) for k in keys])}
    for name in ("aspect", "runout"):
        vals = [np.array([float(r[name]) for r in groups[k]]) for k in keys]
        out[name] = np.array([v.mean() for v in vals])
        out[name + "_std"] = np.array([v.std(ddof=1) if v.size > 1 else math.nan for v in vals])
    out["runout_sem"] = out["runout_std"] / np.sqrt(out["n"])
    a = np.array([float(r["aspect"]) for r in rows])
    y = np.array([float(r["runout"]) for r in rows])
    large, small = a > a_split, a <= a_split
    for part, c_key, p_key in ((large, "c", "p"), (small, "c_small", "p_small")):
        out[c_key], out[p_key], out[p_key + "_se"] = _power_fit(a[part], y[part])
    out["lambda"] = out["lambda_se"] = None
    if np.count_nonzero(small) >= 2:
        x, z = a[small], y[small]
        lam = float(x @ z / (x @ x))
        out["lambda"] = lam
        out["lambda_se"] = float(math.sqrt(np.sum((z - lam * x) ** 2) / (x.size - 1) / (x @ x)))
    out["a_split"] = float(a_split)
    return out


def _power_fit(a, y):
    """``y = c a^p`` by least squares in log-log, and the slope's standard error."""
    if a.size < 3 or np.unique(a).size < 2 or np.any(y <= 0.0):
        return None, None, None
    la, ly = np.log(a), np.log(y)
    p, logc = np.polyfit(la, ly, 1)
    resid = ly - (p * la + logc)
    sxx = float(np.sum((la - la.mean()) ** 2))
    return float(math.exp(logc)), float(p), float(math.sqrt(resid @ resid / (a.size - 2) / sxx))


def _seeds(seeds):
    try:
        seeds = [int(s) for s in seeds]
    except (TypeError, ValueError):
        raise InputError(f"`seeds` must be a sequence of whole numbers, got {seeds!r}") from None
    if not seeds or len(set(seeds)) != len(seeds) or min(seeds) < 0:
        raise InputError(f"`seeds` must hold one seed at least, distinct and >= 0, got {seeds}")
    return seeds
