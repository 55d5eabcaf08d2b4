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
parallel, a failing point recorded as a status. A folder that holds the
files of a run with other settings (``--quick`` against a full run) is
refused before any work unless ``force`` (:mod:`moreau.outputs`).
"""

import pathlib
import time

import joblib
import numpy as np

from ...analysis.engine import (ED_REFERENCE, Scheme, check_output_dir, end_worker_pool,
                                run_points, worker_pool_config)
from ...errors import Interrupted
from ...integrators import specialised_loops
from ...outputs import claim_outputs
from ...scenes.friction_drive import PAPER_DEFAULTS
from .figures import mode_figure_jobs, mode_points, sweep_figure
from .report import write_report
from .tables import sweep_point, tidy_rows, write_sidecar, write_table
from .valid_range import range_marks

__all__ = ["reproduce", "study_grids", "MJ_STEPS_PER_PERIOD", "FREQUENCIES", "write_table"]

#: Moreau–Jean steps per drive period of the cross-check
MJ_STEPS_PER_PERIOD = 2000
#: drive frequencies of the mu and phi0 studies [Hz]
FREQUENCIES = (20.0, 185.0, 2000.0)


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
    params = PAPER_DEFAULTS if params is None else params
    grids = {"frequency": ("frequency", np.geomspace(10.0, 12500.0, 12 if quick else 250), None,
                           range_marks(params, "frequency"))}
    mus = np.array([0.05, 0.1, 0.13, 0.2, 0.5, 0.89, 0.92, 0.98]) if quick else np.round(np.arange(1, 100) / 100.0, 2)
    for f in FREQUENCIES:
        grids[f"mu_{f:g}Hz"] = ("mu", mus, f, range_marks(params, "mu", f))
    for f in FREQUENCIES:
        vr = range_marks(params, "phi0", f)
        lo, hi = vr["lift_off_edge"], vr["painleve_edge"]
        # quick: 8 points, so that the 2000 Hz grid has one point past the contact loss
        # (1.376 > 1.367, with impacts) for the report's impact row
        n = 8 if quick else 101
        grids[f"phi0_{f:g}Hz"] = ("phi0", np.linspace(lo, hi, n + 2)[1:-1], f, vr)
    return grids


def run_jobs(jobs, n_jobs=-1):
    """Run ``[(function, args), ...]`` on local processes; concatenate the returned lists."""
    if n_jobs == 1:
        return [x for fn, args in jobs for x in fn(*args)]
    try:
        # as in the sweep engine: the workers ignore Ctrl-C, the parent alone ends them
        with worker_pool_config():
            done = joblib.Parallel(n_jobs=n_jobs)(joblib.delayed(fn)(*args) for fn, args in jobs)
    except KeyboardInterrupt:
        end_worker_pool(kill=True)
        raise
    end_worker_pool()
    return [x for part in done for x in part]


def reproduce(out="moreau-results", quick=False, scheduler=None, n_jobs=-1, progress=True,
              figures=True, report=True, log=print, force=False):
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
    force : bool
        Replace the files of an earlier run with other settings (a quick run
        in the folder of a full one, or the reverse); refused otherwise,
        before any work. A rerun with the same settings resumes.

    Returns
    -------
    dict
        ``{study name: list of rows}`` plus ``"_paths"`` (written files) and
        ``"_wall_time_s"``.
    """
    t0 = time.perf_counter()
    out = check_output_dir(out)
    (out / "data").mkdir(exist_ok=True)
    params = PAPER_DEFAULTS
    steps = 200 if quick else MJ_STEPS_PER_PERIOD
    checks = mj_checks(steps)
    grids = study_grids(params, quick)
    # what decides each table's content: the grid and the cross-check's steps
    settings = {name: claim_outputs(out / "data" / name, {
        "quick": bool(quick), "points": int(len(values)), "frequency_Hz": frequency,
        "mj_steps_per_period": steps}, force)
        for name, (_, values, frequency, _) in grids.items()}
    points, owner = [], []
    for name, (parameter, values, frequency, _) in grids.items():
        for x in values:
            points.append(sweep_point(params, parameter, x, frequency))
            owner.append(name)
    timings = {"grids_s": time.perf_counter() - t0}
    # 1700 Moreau-Jean steady states of one scene: its own loop (10 s to compile, then about
    # twice the shared loop's speed) pays for itself from the start
    with specialised_loops():
        rows, stats = run_points(points, ED_REFERENCE, checks, cache_dir=out / "cache",
                                 n_jobs=n_jobs, scheduler=scheduler, progress=progress,
                                 desc="reproduce")
    log(f"{len(points)} points: {stats['computed']} computed, {stats['cached']} from the cache")
    results, paths = {}, []
    for name, (parameter, values, frequency, extra) in grids.items():
        mine = [r for r, o in zip(rows, owner) if o == name]
        table = tidy_rows(parameter, values, frequency, params, mine, checks, steps)
        results[name] = table
        path = out / "data" / f"{name}.csv"
        write_table(table, path)
        write_sidecar(path.with_suffix(".json"), params, name, parameter, values, frequency,
                      extra, checks, steps, stats, settings=settings[name])
        paths += [path, path.with_suffix(".json")]
    timings["points_and_tables_s"] = time.perf_counter() - t0 - timings["grids_s"]
    # where each mode is drawn and looked at, shared by the figures and the report
    points = mode_points(results, params) if figures or report else None
    if figures:
        (out / "figures").mkdir(exist_ok=True)
        jobs = [(sweep_figure, (results[name], parameter, frequency, extra,
                                out / "figures" / name, checks))
                for name, (parameter, values, frequency, extra) in grids.items()]
        jobs += mode_figure_jobs(results, params, out / "figures", points)
        try:
            paths += run_jobs(jobs, n_jobs)
        except KeyboardInterrupt:
            # every point is computed and every table written: only the figures are missing
            raise Interrupted(len(rows), len(rows), out / "cache",
                              f"reproduce (tables written to {out / 'data'}, figures "
                              "unfinished)") from None
    wall = time.perf_counter() - t0
    timings["figures_s"] = wall - sum(timings.values())
    if report:
        paths.append(write_report(results, grids, params, out, checks, wall_time=wall, quick=quick,
                                  points=points))
    results["_paths"] = [pathlib.Path(p) for p in paths]
    results["_wall_time_s"] = time.perf_counter() - t0
    timings["report_s"] = results["_wall_time_s"] - wall
    results["_timings"] = timings
    return results
