"""``moreau reproduce``: the paper's section 4.3 end to end (data, figures, report).

Three studies at the paper's parameters (its section 4.1):

1. drive frequency 10 Hz .. 12.5 kHz, 250 log-spaced points;
2. ``mu`` from 0.01 to 0.99 in steps of 0.01 at 20, 185 and 2000 Hz;
3. ``phi0`` over its valid range (lift-off edge to Painlevé edge, see
   :mod:`moreau.studies.paper.valid_range`) at 20, 185 and 2000 Hz, 101 points.

The event-driven reference gives every value; Moreau–Jean with theta = 1/2
and theta = 1 at :data:`MJ_STEPS_PER_PERIOD` steps per period gives a
cross-check at every point. The points go through the sweep engine
(:mod:`moreau.analysis.engine`): cached on disk under ``DIR/cache``, in
parallel, a failing point recorded as a status.
"""

import csv
import json
import math
import pathlib
import sys
import time
from dataclasses import asdict

import numpy as np

from ...analysis.engine import ED_REFERENCE, Scheme, check_output_dir, code_version, mj_check_columns, run_points

__all__ = ["reproduce", "study_grids", "MJ_STEPS_PER_PERIOD", "FREQUENCIES", "write_table"]

#: Moreau–Jean steps per drive period of the cross-check
MJ_STEPS_PER_PERIOD = 2000
#: drive frequencies of the mu and phi0 studies [Hz]
FREQUENCIES = (20.0, 185.0, 2000.0)

SWEPT_COLUMN = {"frequency": "frequency_Hz", "mu": "mu", "phi0": "phi0_rad"}
PARAM_COLUMNS = {"frequency": "frequency_Hz", "m": "m_kg", "m2": "m2_kg", "k": "k_N_per_m",
                 "length": "length_m", "phi0": "phi0_rad", "mu": "mu", "x10": "x10_m",
                 "load": "load_N", "restitution": "restitution",
                 # the bidirectional drive's own parameters (moreau.studies.bidirectional.bidirectional_sweep)
                 "x10_a": "x10_a_m", "x10_b": "x10_b_m", "phase": "phase_rad",
                 "balance": "balance"}
VALUE_COLUMNS = ["mode", "displacement_per_period_m", "average_velocity_m_per_s",
                 "min_normal_force_N", "painleve_margin", "lift_off_margin", "periodic_residual",
                 "shooting_iterations", "status"]


def mj_checks(steps_per_period=MJ_STEPS_PER_PERIOD):
    """The two Moreau–Jean cross-checks (theta = 1/2 and 1)."""
    return (Scheme.moreau_jean(0.5, steps_per_period), Scheme.moreau_jean(1.0, steps_per_period))


def study_grids(params=None, quick=False):
    """The studies as ``{name: (parameter, values, frequency, extra)}``.

    ``extra`` holds the valid-range edges of the phi0 studies.

    Examples
    --------
    >>> g = study_grids()
    >>> len(g["frequency"][1]), len(g["mu_185Hz"][1]), len(g["phi0_20Hz"][1]) >= 99
    (250, 99, True)
    """
    from ...scenes.friction_drive import PAPER_DEFAULTS

    params = PAPER_DEFAULTS if params is None else params
    grids = {"frequency": ("frequency", np.geomspace(10.0, 12500.0, 12 if quick else 250), None,
                           range_marks(params, "frequency"))}
    mus = np.array([0.05, 0.1, 0.13, 0.2, 0.5, 0.89, 0.92, 0.98]) if quick else np.round(np.arange(1, 100) / 100.0, 2)
    for f in FREQUENCIES:
        grids[f"mu_{f:g}Hz"] = ("mu", mus, f, range_marks(params, "mu", f))
    for f in FREQUENCIES:
        vr = range_marks(params, "phi0", f)
        lo, hi = vr["lift_off_edge"], vr["painleve_edge"]
        n = 7 if quick else 101
        grids[f"phi0_{f:g}Hz"] = ("phi0", np.linspace(lo, hi, n + 2)[1:-1], f, vr)
    return grids


def range_marks(params, parameter, frequency=None):
    """Limits of the contact model along one swept parameter, to mark on its figure.

    ``{"contact_loss_Hz": f}`` for a frequency sweep (where ``max D = 0``),
    ``{"painleve_edge": 1/tan(phi0)}`` for ``mu``, the valid range of
    :func:`~moreau.studies.paper.valid_range.phi0_valid_range` for ``phi0``, and
    ``{}`` for the other parameters.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> round(range_marks(PAPER_DEFAULTS, "mu", 185.0)["painleve_edge"], 6)
    1.0
    """
    from scipy.optimize import brentq

    from .valid_range import lift_off_margin, phi0_valid_range
    if parameter == "frequency":
        # the frequency where the rod would lift off (max D = 0), if there is one
        f_hi = 1e3
        while lift_off_margin(params, f_hi) < 0 and f_hi < 1e7:
            f_hi *= 2
        if f_hi >= 1e7:
            return {}
        return {"contact_loss_Hz": brentq(lambda f: lift_off_margin(params, f), f_hi / 2, f_hi)}
    if parameter == "mu":
        return {"painleve_edge": 1.0 / math.tan(params.phi0)}
    if parameter == "phi0":
        return phi0_valid_range(params, frequency)
    return {}


def _point(params, parameter, value, frequency):
    if parameter == "frequency":
        return asdict(params), float(value)
    return asdict(params.with_(**{parameter: float(value)})), float(frequency)


def tidy_rows(parameter, values, frequency, params, rows, checks, steps=None):
    """Rows of a tidy CSV: the swept value and the fixed parameters first, with units."""
    from .valid_range import lift_off_margin

    out = []
    for x, row in zip(values, rows):
        p_dict, f = _point(params, parameter, x, frequency)
        p = params.with_(**{k: v for k, v in p_dict.items()})
        r = {SWEPT_COLUMN.get(parameter, PARAM_COLUMNS.get(parameter, parameter)): float(x)}
        for name in ("frequency", "mu", "phi0"):
            col = PARAM_COLUMNS[name]
            if col not in r:
                r[col] = f if name == "frequency" else p_dict[name]
        r["painleve_margin"] = 1.0 - p.mu * math.tan(p.phi0)
        r["lift_off_margin"] = lift_off_margin(p, f)
        for c in VALUE_COLUMNS:
            if c not in r:
                r[c] = row.get(c, math.nan if c != "mode" else "")
        if checks:
            r["mj_steps_per_period"] = steps
            for chk in checks:
                for c in mj_check_columns(chk):
                    r[c] = row.get(c, math.nan)
        r["compute_time_s"] = row.get("compute_time_s", math.nan)
        out.append(r)
    return out


def write_table(rows, path):
    """Write tidy rows as CSV (floats in full precision)."""
    cols = list(rows[0]) if rows else []
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols, restval="")
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})


def read_table(path):
    """Read a tidy CSV back: numbers as floats, text as text."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k, v in r.items():
            try:
                r[k] = float(v)
            except ValueError:
                pass
    return rows


def _sidecar(path, params, name, parameter, values, frequency, extra, checks, steps, stats,
             scheme=ED_REFERENCE):
    from ... import __version__
    meta = {
        "study": name,
        "swept_parameter": SWEPT_COLUMN.get(parameter, parameter),
        "points": int(len(values)),
        "range": [float(values[0]), float(values[-1])],
        "frequency_Hz": frequency,
        "parameters_SI": asdict(params),
        "reference_scheme": {"name": scheme.name, "theta": scheme.theta,
                             "steps_per_period": scheme.steps_per_period, "rtol": scheme.rtol},
        "cross_checks": [{"name": c.name, "theta": c.theta, "steps_per_period": c.steps_per_period}
                         for c in checks],
        "valid_range": {k: v for k, v in extra.items()},
        "package_version": __version__,
        "code_version": code_version(),
        "python": sys.version.split()[0],
        "engine": stats,
    }
    path.write_text(json.dumps(meta, indent=2))


def run_jobs(jobs, n_jobs=-1):
    """Run ``[(function, args), ...]`` on local processes; concatenate the returned lists."""
    if n_jobs == 1:
        return [x for fn, args in jobs for x in fn(*args)]
    import joblib
    done = joblib.Parallel(n_jobs=n_jobs)(joblib.delayed(fn)(*args) for fn, args in jobs)
    return [x for part in done for x in part]


def reproduce(out="moreau-results", quick=False, scheduler=None, n_jobs=-1, progress=True,
              figures=True, report=True, log=print):
    """Run the paper's three studies and write data, figures and the report.

    Parameters
    ----------
    out : path-like
        Output folder (created; checked writable before any work).
    quick : bool
        Coarse grids (a smoke run of a few seconds).
    scheduler : str, optional
        Dask scheduler address; local processes otherwise.
    n_jobs : int
        Local processes (-1: all cores).

    Returns
    -------
    dict
        ``{study name: list of rows}`` plus ``"_paths"`` (written files) and
        ``"_wall_time_s"``.
    """
    from ...scenes.friction_drive import PAPER_DEFAULTS

    t0 = time.perf_counter()
    out = check_output_dir(out)
    (out / "data").mkdir(exist_ok=True)
    params = PAPER_DEFAULTS
    steps = 200 if quick else MJ_STEPS_PER_PERIOD
    checks = mj_checks(steps)
    grids = study_grids(params, quick)
    points, owner = [], []
    for name, (parameter, values, frequency, _) in grids.items():
        for x in values:
            points.append(_point(params, parameter, x, frequency))
            owner.append(name)
    timings = {"grids_s": time.perf_counter() - t0}
    rows, stats = run_points(points, ED_REFERENCE, checks, cache_dir=out / "cache", n_jobs=n_jobs,
                             scheduler=scheduler, progress=progress, desc="reproduce")
    log(f"{len(points)} points: {stats['computed']} computed, {stats['cached']} from the cache")
    results, paths = {}, []
    for name, (parameter, values, frequency, extra) in grids.items():
        mine = [r for r, o in zip(rows, owner) if o == name]
        table = tidy_rows(parameter, values, frequency, params, mine, checks, steps)
        results[name] = table
        path = out / "data" / f"{name}.csv"
        write_table(table, path)
        _sidecar(path.with_suffix(".json"), params, name, parameter, values, frequency, extra,
                 checks, steps, stats)
        paths += [path, path.with_suffix(".json")]
    timings["points_and_tables_s"] = time.perf_counter() - t0 - timings["grids_s"]
    if figures:
        from .figures import mode_figure_jobs, sweep_figure
        (out / "figures").mkdir(exist_ok=True)
        jobs = [(sweep_figure, (results[name], parameter, frequency, extra,
                                out / "figures" / name, checks))
                for name, (parameter, values, frequency, extra) in grids.items()]
        jobs += mode_figure_jobs(results, params, out / "figures")
        paths += run_jobs(jobs, n_jobs)
    wall = time.perf_counter() - t0
    timings["figures_s"] = wall - sum(timings.values())
    if report:
        from .report import write_report
        paths.append(write_report(results, grids, params, out, checks, wall_time=wall, quick=quick))
    results["_paths"] = [pathlib.Path(p) for p in paths]
    results["_wall_time_s"] = time.perf_counter() - t0
    timings["report_s"] = results["_wall_time_s"] - wall
    results["_timings"] = timings
    return results
