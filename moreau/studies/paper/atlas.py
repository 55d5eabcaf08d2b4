"""Operation-mode atlases: the steady state over the (f, mu) and (f, phi0) planes.

The paper sweeps one parameter at a time. An atlas evaluates the steady state
on a grid of a parameter plane and shows at a glance where each operation
mode (NS, NP, SP, ...) lies, with the limits of the contact model drawn as
curves:

* lift-off, ``min f_N = 0``: on the contact manifold the normal force of the
  slipping rod vanishes where the free normal acceleration ``D`` reaches 0,
  so the curve is ``max_tau D = 0`` (:func:`~moreau.studies.paper.valid_range.lift_off_margin`,
  independent of ``mu``);
* Painlevé: ``1 - mu tan(phi0) = 0`` (beyond it the model is ill-posed);
* contact loss: where the computed steady state contains flight (or the rod
  never touches the rotor again).

Every point goes through the sweep engine (:mod:`moreau.analysis.engine`):
cached on disk, in parallel on local processes or on a Dask cluster. A grid
line of constant ``f`` is one task and one cache entry.
"""

import json
import math
import sys
import time
from dataclasses import asdict

import numpy as np

from ... import __version__
from ... import _validate as V
# the module, not its function: a test (or a user) that replaces
# engine.run_points reaches the atlas too
from ...analysis import engine
from ...analysis.atlas import classify_budget
from ...analysis.classify import CLASSIFY_PERIODS
from ...analysis.sweep import require_xarray, write_netcdf_beside
from ...analysis.engine import ED_REFERENCE, check_output_dir, code_version, make_scheme
from ...errors import InputError
from ...model import registry
from ...outputs import claim_outputs
from ...provenance import provenance
from ...scenes.friction_drive import PAPER_DEFAULTS
from .figures import atlas_figure
from .sweeps import params_from_args, scheme_tag
from .tables import write_table
from .valid_range import lift_off_margin

__all__ = ["PLANES", "compute_atlas", "run_atlas", "point_label", "command"]

#: plane name -> (parameter on the y axis, default range, axis label, CSV column)
PLANES = {
    "f-mu": ("mu", (0.01, 0.99), "friction coefficient \u03bc [-]", "mu"),
    # from just above the low lift-off edge (0.6155 rad at the paper's parameters): below it
    # the rod chatters on the rotor at low frequency, with accumulating impacts that cost
    # seconds per point, and the paper's model does not apply
    "f-phi0": ("phi0", (0.62, 1.5), "initial tilt angle \u03c6\u2080 [rad]", "phi0_rad"),
}

#: labels of points without a steady mode
NO_CONTACT, ILL_POSED, FAILED = "no contact", "ill-posed (Painlev\u00e9)", "failed"


def point_label(row):
    """The atlas label of one engine row: its mode, or why it has none.

    A point without a periodic orbit that was classified
    (:mod:`moreau.analysis.classify`) is labelled by its class
    (``period-2``, ``non-periodic``, ``runaway``); ``failed`` is left for
    the genuine failures.

    Examples
    --------
    >>> point_label({"status": "ok", "mode": "NS"})
    'NS'
    >>> point_label({"status": "PainleveError: 1 - mu*tan(phi) <= 0", "mode": ""})
    'ill-posed (Painlevé)'
    """
    status = row.get("status", "")
    if status == "ok":
        return row["mode"]
    if status.startswith("PainleveError"):
        return ILL_POSED
    if "does not touch the rotor" in status:
        return NO_CONTACT
    cls = row.get("classification", "")
    if cls.startswith("period-") or cls in ("non-periodic", "runaway"):
        return cls
    return FAILED


def compute_atlas(plane, params=None, f_range=(10.0, 12500.0), y_range=None, f_points=200,
                  y_points=100, scheme=None, cache_dir=None, n_jobs=-1, scheduler=None,
                  progress=False, continuation=True, classify=CLASSIFY_PERIODS):
    """Steady states over one parameter plane.

    Parameters
    ----------
    plane : {"f-mu", "f-phi0"}
    params : FrictionDriveParams, optional
        The fixed parameters (paper defaults).
    f_range : (float, float)
        Drive frequencies [Hz], log-spaced.
    y_range : (float, float), optional
        Range of ``mu`` or ``phi0`` [rad] (defaults in :data:`PLANES`), linear.
    f_points, y_points : int
    scheme : Scheme, optional
        Event-driven (shooting tolerance 1e-10) by default.
    cache_dir, n_jobs, scheduler, progress
        As in :func:`moreau.analysis.engine.run_points`.
    continuation : bool
        Along each line of constant frequency, every point's shooting
        starts from its neighbour's orbit (:mod:`moreau.analysis.continuation`);
        False: every point starts cold.
    classify : int
        Budget of drive periods of the plain run that names the long-run
        motion of a point without an orbit (:mod:`moreau.analysis.classify`);
        0: no run (such points stay ``failed``).

    Returns
    -------
    dict
        ``frequency_Hz`` (f_points,), ``y`` (y_points,), and arrays of shape
        ``(f_points, y_points)``: ``mode``, ``label`` (mode or why none, see
        :func:`point_label`), ``status``, ``displacement_per_period_m``,
        ``min_normal_force_N``, ``start`` (continued or cold),
        ``classification`` and ``classification_detail``, and the boundary fields whose zero level is
        the curve: ``lift_off_field`` (``max D / u10``), ``painleve_field``
        (``1 - mu tan phi0``), ``contact_loss_field`` (+1 with flight or no
        contact, -1 in permanent contact, NaN where ill-posed or failed).
        Also ``y_name``, ``y_label``, ``y_column``, ``plane``, ``stats``,
        ``wall_time_s``.

    Examples
    --------
    >>> a = compute_atlas("f-mu", f_range=(20.0, 2000.0), y_range=(0.1, 0.98), f_points=2,
    ...                   y_points=2, n_jobs=1)
    >>> a["label"].tolist()
    [['NS', 'NS'], ['NP', 'SP']]
    """
    if plane not in PLANES:
        raise InputError(f"`plane` must be one of {list(PLANES)}, got {plane!r}")
    y_name, y_default, y_label, y_col = PLANES[plane]
    params = PAPER_DEFAULTS if params is None else params
    scheme = ED_REFERENCE if scheme is None else scheme
    f_points = V.positive_int("f_points", f_points)
    y_points = V.positive_int("y_points", y_points)
    f0, f1 = (V.positive("f_range", v) for v in f_range)
    y0, y1 = (V.finite_scalar("y_range", v) for v in (y_default if y_range is None else y_range))
    if not (f0 < f1 and y0 < y1):
        raise InputError("`f_range` and `y_range` must be increasing pairs")
    freqs = np.geomspace(f0, f1, f_points) if f_points > 1 else np.array([f0])
    ys = np.linspace(y0, y1, y_points) if y_points > 1 else np.array([y0])
    # every grid value must give a valid parameter set before any work starts
    for y in (ys[0], ys[-1]):
        params.with_(**{y_name: float(y)})

    t0 = time.perf_counter()
    line = [params.with_(**{y_name: float(y)}) for y in ys]
    points = [(asdict(p), float(f)) for f in freqs for p in line]
    rows, stats = engine.run_points(points, scheme, cache_dir=cache_dir, n_jobs=n_jobs,
                                    scheduler=scheduler, progress=progress,
                                    desc=f"atlas {plane}", chunk=y_points,
                                    continuation=continuation, classify=classify)
    shape = (f_points, y_points)
    pick = np.empty(shape, dtype=object)
    out = {k: np.full(shape, np.nan) for k in ("displacement_per_period_m", "min_normal_force_N",
                                              "average_velocity_m_per_s", "compute_time_s")}
    for key in ("classified_displacement_per_period_m", "classified_half_width_m"):
        out[key] = np.full(shape, np.nan)
    text = {k: np.full(shape, "", dtype=object)
            for k in ("mode", "status", "start", "classification", "classification_detail")}
    mode, status = text["mode"], text["status"]
    for k, r in enumerate(rows):
        i, j = divmod(k, y_points)
        pick[i, j] = point_label(r)
        for key in text:
            text[key][i, j] = r.get(key, "")
        for key in out:
            out[key][i, j] = r.get(key, math.nan)
    painleve = np.array([[1.0 - p.mu * math.tan(p.phi0) for p in line] for _ in freqs])
    if y_name == "mu":  # D does not depend on mu: one value per frequency
        lift = np.repeat([[lift_off_margin(params, f)] for f in freqs], y_points, axis=1)
    else:
        lift = np.array([[lift_off_margin(p, f) for p in line] for f in freqs])
    loss = np.full(shape, np.nan)
    for (i, j), lab in np.ndenumerate(pick):
        if lab == NO_CONTACT or (status[i, j] == "ok" and "F" in mode[i, j]):
            loss[i, j] = 1.0
        elif status[i, j] == "ok":
            loss[i, j] = -1.0
    return {"plane": plane, "frequency_Hz": freqs, "y": ys, "y_name": y_name, "y_label": y_label,
            "y_column": y_col, "label": pick, **text, **out,
            "lift_off_field": lift, "painleve_field": painleve, "contact_loss_field": loss,
            "scheme": scheme, "params": params, "stats": stats,
            "wall_time_s": time.perf_counter() - t0}


def atlas_rows(atlas):
    """Tidy rows of an atlas: one per grid point, units in the column names."""
    rows = []
    p = atlas["params"]
    for i, f in enumerate(atlas["frequency_Hz"]):
        for j, y in enumerate(atlas["y"]):
            r = {"frequency_Hz": float(f), "mu": p.mu, "phi0_rad": p.phi0}
            r[atlas["y_column"]] = float(y)
            r.update({
                "mode": atlas["mode"][i, j], "label": atlas["label"][i, j],
                "displacement_per_period_m": float(atlas["displacement_per_period_m"][i, j]),
                "average_velocity_m_per_s": float(atlas["average_velocity_m_per_s"][i, j]),
                "min_normal_force_N": float(atlas["min_normal_force_N"][i, j]),
                "painleve_margin": float(atlas["painleve_field"][i, j]),
                "lift_off_margin": float(atlas["lift_off_field"][i, j]),
                "status": atlas["status"][i, j],
                "start": atlas["start"][i, j],
                "classification": atlas["classification"][i, j],
                "classification_detail": atlas["classification_detail"][i, j],
                "classified_displacement_per_period_m":
                    float(atlas["classified_displacement_per_period_m"][i, j]),
                "classified_half_width_m": float(atlas["classified_half_width_m"][i, j]),
                "compute_time_s": float(atlas["compute_time_s"][i, j])})
            rows.append(r)
    return rows


def run_atlas(planes=("f-mu", "f-phi0"), params=None, out="out", f_range=(10.0, 12500.0),
              f_points=200, y_points=100, scheme=None, cache_dir=None, n_jobs=-1, scheduler=None,
              progress=True, plot=True, log=print, force=False, continuation=True,
              classify=CLASSIFY_PERIODS, netcdf=False):
    """The ``moreau atlas`` command: for each plane a tidy CSV, a JSON sidecar and a figure.

    Files: ``OUT/atlas_f-mu.csv`` (``.json``, ``.png``, ``.svg``) and the
    same for ``f-phi0``; a scheme other than the event-driven reference's
    default adds its tag (``atlas_f-mu_mj_theta1_N1000``). Files of an earlier
    atlas with other settings are not replaced unless ``force``. The cache lives in ``cache_dir`` (``OUT/cache`` by
    default). The output folder is checked before any work. ``continuation``
    and ``classify`` as in :func:`compute_atlas`. ``netcdf``: also
    ``OUT/atlas_PLANE.nc`` on the plane's grid
    (:func:`moreau.analysis.sweep.write_netcdf_beside`; needs xarray, the
    ``[data]`` extra, checked before any work).

    Returns
    -------
    dict
        ``{plane: atlas}`` (see :func:`compute_atlas`).
    """
    for plane in planes:
        if plane not in PLANES:
            raise InputError(f"`plane` must be one of {list(PLANES)}, got {plane!r}")
    if netcdf:
        require_xarray("`netcdf`")
    out = check_output_dir(out)
    cache_dir = out / "cache" if cache_dir is None else cache_dir
    scheme = ED_REFERENCE if scheme is None else scheme
    # the scheme and its non-default settings are in the names, as in the sweeps' names
    stems = {plane: out / f"atlas_{plane}{scheme_tag(scheme)}" for plane in planes}
    settings = {plane: claim_outputs(stems[plane], {
        "plane": plane, "f_range": list(f_range), "grid": [f_points, y_points],
        "parameters_SI": asdict(PAPER_DEFAULTS if params is None else params),
        "scheme": [scheme.name, scheme.theta, scheme.steps_per_period, scheme.rtol,
                   scheme.options], "continuation": bool(continuation),
        "classify_periods": int(classify)}, force) for plane in planes}
    results = {}
    for plane in planes:
        a = compute_atlas(plane, params, f_range=f_range, f_points=f_points, y_points=y_points,
                          scheme=scheme, cache_dir=cache_dir, n_jobs=n_jobs, scheduler=scheduler,
                          progress=progress, continuation=continuation, classify=classify)
        stem = stems[plane]
        s = a["scheme"]
        rows = atlas_rows(a)
        for r in rows:
            r["scheme"] = s.name
        write_table(rows, (stem.parent / (stem.name + ".csv")))
        meta = {"plane": plane, "grid": [f_points, y_points],
                "frequency_Hz": [float(a["frequency_Hz"][0]), float(a["frequency_Hz"][-1])],
                a["y_name"]: [float(a["y"][0]), float(a["y"][-1])],
                "parameters_SI": asdict(a["params"]),
                "scheme": {"name": s.name, "theta": s.theta, "steps_per_period": s.steps_per_period,
                           "rtol": s.rtol},
                "package_version": __version__, "code_version": code_version(),
                "python": sys.version.split()[0], "engine": a["stats"],
                "wall_time_s": a["wall_time_s"], "scheduler": scheduler,
                "continuation": bool(continuation), "classify_periods": int(classify),
                "starts": _counts(a["start"]), "classifications": _counts(a["classification"]),
                "provenance": provenance(code_version()), "settings": settings[plane]}
        (stem.parent / (stem.name + ".json")).write_text(json.dumps(meta, indent=2))
        counts = {}
        for lab in a["label"].ravel():
            counts[lab] = counts.get(lab, 0) + 1
        log(f"atlas {plane}: {f_points} x {y_points} points ({a['stats']['computed']} computed, "
            f"{a['stats']['cached']} from the cache) in {a['wall_time_s']:.1f} s; "
            + ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])))
        log(f"wrote {(stem.parent / (stem.name + '.csv'))}")
        if netcdf:
            write_netcdf_beside(stem, rows, ["frequency_Hz", a["y_column"]], log)
        if plot:
            paths = atlas_figure(a, stem)
            log(f"wrote {paths[0]}")
        results[plane] = a
    return results


def _counts(arr):
    counts = {}
    for v in np.asarray(arr, dtype=object).ravel():
        counts[v] = counts.get(v, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def command(args):
    """``moreau atlas``: the friction drive's atlas from the parsed command-line arguments
    (registered as the scene's atlas hook)."""
    for opt in ("x10_a", "x10_b", "phase"):
        if getattr(args, opt, None) is not None:
            raise InputError(f"`--{opt.replace('_', '-')}` is not a parameter of the friction drive")
    if getattr(args, "set", None):
        raise InputError("`--set` applies with `--x` and `--y`; the friction drive's own atlas "
                         "takes its fixed parameters as `--mu`, `--x10`, ...")
    params = params_from_args(args)
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol,
                         getattr(args, "scheme_options", None))
    plane = args.plane or "both"
    planes = ("f-mu", "f-phi0") if plane == "both" else (plane,)
    if args.quick:
        if args.f_points is not None or args.y_points is not None:
            raise InputError("`--quick` sets the grid; leave out `--f-points`/`--y-points`")
        f_points, y_points = 24, 12
    else:
        f_points = 200 if args.f_points is None else args.f_points
        y_points = 100 if args.y_points is None else args.y_points
    f_range = (10.0 if args.fmin is None else args.fmin,
               12500.0 if args.fmax is None else args.fmax)
    run_atlas(planes, params, out=args.out, f_range=f_range, f_points=f_points,
              y_points=y_points, scheme=scheme, cache_dir=args.cache, n_jobs=args.jobs,
              scheduler=args.scheduler, progress=not args.quiet, plot=not args.no_plot,
              force=args.force, continuation=not getattr(args, "cold", False),
              classify=classify_budget(args), netcdf=getattr(args, "netcdf", False))


registry.register_hook("friction-drive", "atlas", command)
