"""Operation-mode atlas of any periodically driven scene over two of its parameters.

The generic ``moreau atlas --scene NAME --x PARAM START STOP --y PARAM START
STOP``: the steady state at every point of a grid of a parameter plane, each
one a call of the sweep engine (:func:`moreau.analysis.engine.run_points`:
cached, in parallel, a failed point kept as its ``status``), for any
registered scene with a periodic drive and any scheme. A scene whose study
has an atlas of its own (the paper's friction drive, with its lift-off and
Painlevé curves) names it in its registry entry (``SceneEntry.atlas``);
``moreau atlas`` runs that one unless ``--x`` and ``--y`` are given.

Outputs: ``OUT/atlas_SCENE_X-Y[_FREQ]_SCHEME.csv`` (one tidy row per point,
units in the column names), a JSON sidecar (scene, axes, fixed parameters,
scheme, engine statistics, provenance) and a figure: the operation mode of
every point as a coloured map beside the displacement per period.

Examples
--------
>>> rows = run_scene_atlas("stick-slip-motor", ("load", [0.0, 0.1]), ("mu", [0.2]),
...                        frequency=1000.0, out=None, progress=False, plot=False,
...                        log=lambda s: None)
>>> len(rows), sorted({r["status"] for r in rows})
(2, ['ok'])
"""

import math

import numpy as np

from ..errors import InputError
from ..outputs import claim_outputs, write_csv
from ..provenance import provenance
from . import engine
from .classify import CLASSIFY_COLUMNS, CLASSIFY_PERIODS
from .engine import ED_REFERENCE, check_output_dir
from .sweep import (VALUE_COLUMNS, MAX_POINTS, plan_points, require_xarray, sweep_tag,
                    write_netcdf_beside, write_points_sidecar)

__all__ = ["run_scene_atlas", "atlas_tag", "mode_map_figure", "classify_budget", "ATLAS_COLUMNS"]

#: the columns of an atlas row beyond the sweep's: how the point started and what it does
ATLAS_COLUMNS = ("start", "continuation_solves") + CLASSIFY_COLUMNS


def classify_budget(args):
    """The ``--classify-periods`` of parsed arguments, checked (default :data:`CLASSIFY_PERIODS`).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> classify_budget(SimpleNamespace(classify_periods=None)) == CLASSIFY_PERIODS
    True
    >>> classify_budget(SimpleNamespace(classify_periods=-1))
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `--classify-periods` must be a whole number >= 0 (0: no run), got -1
    """
    n = getattr(args, "classify_periods", None)
    if n is None:
        return CLASSIFY_PERIODS
    if isinstance(n, bool) or not isinstance(n, int) or n < 0:
        raise InputError(f"`--classify-periods` must be a whole number >= 0 (0: no run), got {n!r}")
    return n


def atlas_tag(scene, x, y, frequency, scheme):
    """File stem of an atlas: scene, the two parameters, the fixed frequency, the scheme.

    Examples
    --------
    >>> atlas_tag("stick-slip-motor", "load", "mu", 1000.0, ED_REFERENCE)
    'atlas_stick-slip-motor_load-mu_1000Hz_event-driven'
    """
    parameter = "frequency" if "frequency" in (x, y) else f"{x}-{y}"
    tag = sweep_tag(scene, parameter, frequency, scheme)
    if parameter == "frequency":
        tag = tag.replace("_frequency_", f"_{x}-{y}_", 1)
    return "atlas_" + tag[len("sweep_"):]


def run_scene_atlas(scene, x, y, fixed=None, frequency=None, scheme=ED_REFERENCE, out="out",
                    cache_dir=None, n_jobs=-1, scheduler=None, progress=True, plot=True,
                    log=print, force=False, continuation=True, classify=CLASSIFY_PERIODS,
                    netcdf=False):
    """Steady states of the registered scene ``scene`` on the grid ``x`` by ``y``.

    Parameters
    ----------
    scene : str
        A registered scene with a periodic drive.
    x, y : (str, array_like)
        Each axis: a numeric parameter of the scene (or ``"frequency"``) and
        its values in the parameter's SI unit. The two differ.
    fixed : dict, optional
        Other parameters of the scene (SI units); the rest keep their defaults.
    frequency : float, optional
        Drive frequency [Hz]; required unless an axis is ``"frequency"``.
    scheme : moreau.analysis.scheme_settings.Scheme
    out : path-like or None
        Output folder, checked writable before any work; None writes nothing.
    cache_dir : path-like, optional
        The engine's cache (default ``OUT/cache``; none without ``out``).
    force : bool
        Replace the files of an earlier atlas with other settings; refused
        otherwise, before any work (:func:`moreau.outputs.claim_outputs`).
    continuation : bool
        Along each line of constant ``y``, every point's shooting starts
        from its neighbour's orbit (:mod:`moreau.analysis.continuation`),
        with halved steps and a cold start where that fails; False: every
        point starts cold.
    classify : int
        Budget of drive periods of the plain run that names the long-run
        motion of a point without an orbit (:mod:`moreau.analysis.classify`);
        0: none.
    netcdf : bool
        Also write the table as ``STEM.nc`` on the ``x`` by ``y`` grid
        (:func:`moreau.analysis.sweep.write_netcdf_beside`; needs xarray,
        the ``[data]`` extra, checked before any work).

    Returns
    -------
    list of dict
        One tidy row per point, ``x`` varying fastest, with the
        :data:`ATLAS_COLUMNS` (``start``: continued, cold or
        cold-fallback; ``classification``: period-k, non-periodic,
        runaway, ..., with its detail and displacement).
    """
    (xname, xv), (yname, yv) = x, y
    if xname == yname:
        raise InputError(f"`--x` and `--y` must be two different parameters, got {xname!r} twice")
    xv = np.asarray(xv, dtype=float).reshape(-1)
    yv = np.asarray(yv, dtype=float).reshape(-1)
    for axis, name, v in (("x", xname, xv), ("y", yname, yv)):
        if np.unique(v).size != v.size:
            # a repeated value computes one point twice and collapses the grid of the NetCDF
            raise InputError(f"`{axis}`: the values of {name!r} must be distinct, got "
                             f"{v.tolist()}")
    if netcdf:
        if out is None:
            raise InputError("`netcdf` writes a file next to the CSV: give `out`")
        require_xarray("`netcdf`")
    if xv.size * yv.size > MAX_POINTS:
        raise InputError(f"the grid has {xv.size * yv.size} points, more than the limit "
                         f"{MAX_POINTS:.0e} of one atlas")
    entry, columns, point, frequency = plan_points(scene, (xname, yname), (xv, yv), fixed,
                                                   frequency)
    grid = [(a, b) for b in yv for a in xv]
    points = [point({xname: a, yname: b}) for a, b in grid]
    if out is not None:
        out = check_output_dir(out)
        cache_dir = out / "cache" if cache_dir is None else cache_dir
        stem = out / atlas_tag(entry.name, xname, yname, frequency, scheme)
        settings = claim_outputs(stem, {
            "scene": entry.name, "x": [xname, xv.tolist()], "y": [yname, yv.tolist()],
            "frequency_Hz": frequency,
            "fixed": {k: v for k, v in points[0][0].items() if k not in (xname, yname)},
            "scheme": [scheme.name, scheme.theta, scheme.steps_per_period, scheme.rtol,
                       scheme.options], "continuation": bool(continuation),
            "classify_periods": int(classify)}, force)
    # a line of constant y is one task: its points are continued one from the next
    rows, stats = engine.run_points(points, scheme, cache_dir=cache_dir, n_jobs=n_jobs,
                                    scheduler=scheduler, progress=progress,
                                    desc=f"atlas {xname}-{yname}", scene=entry.name,
                                    chunk=xv.size, continuation=continuation,
                                    classify=classify)
    table = []
    for (a, b), (p, f), row in zip(grid, points, rows):
        r = {columns[xname]: float(a), columns[yname]: float(b), "scene": entry.name,
             "scheme": scheme.name}
        if "frequency" not in (xname, yname):
            r[columns["frequency"]] = f
        for name, val in p.items():
            if name not in (xname, yname):
                r[columns[name]] = val
        for c in VALUE_COLUMNS + ATLAS_COLUMNS:
            r[c] = row.get(c, "" if c in ("mode", "status", "start", "classification",
                                          "classification_detail") else math.nan)
        table.append(r)
    if out is None:
        return table
    csv_path = stem.with_name(stem.name + ".csv")
    write_csv(csv_path, table)
    meta = {"scene": entry.name,
            "x": {"parameter": columns[xname], "points": int(xv.size),
                  "range": [float(xv.min()), float(xv.max())]},
            "y": {"parameter": columns[yname], "points": int(yv.size),
                  "range": [float(yv.min()), float(yv.max())]},
            "frequency_Hz": frequency,
            "fixed_parameters": {k: v for k, v in points[0][0].items()
                                 if k not in (xname, yname)},
            "scheme": scheme.record,
            "modes": _mode_counts(table),
            "continuation": bool(continuation), "classify_periods": int(classify),
            "starts": _counts(table, "start"), "classifications": _counts(table, "classification"),
            "engine": stats, "provenance": provenance(engine.code_version()),
            "settings": settings}
    write_points_sidecar(stem, meta, csv_path, len(table), stats, log)
    if netcdf:
        write_netcdf_beside(stem, table, [columns[xname], columns[yname]], log)
    if plot:
        fig_path = stem.with_name(stem.name + ".png")
        mode_map_figure(table, columns[xname], columns[yname], xv, yv,
                        f"{entry.name}: steady state ({scheme.description})", fig_path)
        log(f"wrote {fig_path}")
    return table


def _label(row):
    if row["status"] == "ok":
        return row["mode"]
    cls = row.get("classification", "")
    return cls if cls and cls != "failed" else "failed"


def _counts(table, key):
    counts = {}
    for r in table:
        counts[r.get(key, "")] = counts.get(r.get(key, ""), 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def _mode_counts(table):
    counts = {}
    for r in table:
        counts[_label(r)] = counts.get(_label(r), 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def mode_map_figure(table, xcol, ycol, xv, yv, title, path):
    """Two panels: the operation mode of every point, and the displacement per period."""
    import matplotlib  # noqa: PLC0415  (figures only)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    from matplotlib.colors import ListedColormap  # noqa: PLC0415

    labels = [_label(r) for r in table]
    names = list(_mode_counts(table))
    index = np.array([names.index(m) for m in labels], float).reshape(len(yv), len(xv))
    disp = np.array([r["displacement_per_period_m"] for r in table], float).reshape(
        len(yv), len(xv)) * 1e6
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5))
    colors = [plt.get_cmap("tab10")(i % 10) for i in range(len(names))]
    if "failed" in names:
        colors[names.index("failed")] = (0.85, 0.85, 0.85, 1.0)
    a1.pcolormesh(xv, yv, index, cmap=ListedColormap(colors), vmin=-0.5,
                  vmax=len(names) - 0.5, shading="nearest")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in colors]
    a1.legend(handles, names, title="mode", fontsize=7, loc="best")
    lim = np.nanmax(np.abs(disp)) if np.isfinite(disp).any() else 1.0
    im = a2.pcolormesh(xv, yv, disp, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest")
    fig.colorbar(im, ax=a2, label="displacement per period [\u00b5m]")
    for ax in (a1, a2):
        ax.set_xlabel(xcol)
        ax.set_ylabel(ycol)
        if xv.size > 2 and xv.min() > 0 and np.allclose(np.diff(np.log(xv)), np.log(xv[1] / xv[0])):
            ax.set_xscale("log")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
