"""Parameter sweeps of the friction drive's periodic steady state.

A sweep evaluates the steady state at each value, records the operation mode,
the displacement per period and the smallest normal force, and writes a CSV
file and (with matplotlib installed) a figure. A point where the model is
ill-posed is recorded with its reason instead of a number; an interrupted
sweep keeps the points it had finished.
"""

import math
from dataclasses import asdict

import numpy as np

from ..._validate import positive
# the modules, not their functions: a test (or a user) that replaces
# engine.run_points or steady_state.find_steady_state reaches the sweeps too
from ...analysis import engine, steady_state
from ...analysis import sweep as scene_sweep
from ...analysis.engine import check_output_dir, make_scheme
from ...errors import InputError, MoreauError
from ...model import registry
from ... import outputs
from ...outputs import claim_outputs
from ...scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive, params_from_kwargs
from .figures import sweep_figure
from .tables import sweep_point, tidy_rows, write_sidecar, write_table
from .valid_range import range_marks

__all__ = ["sweep", "run_sweep", "make_scheme", "sweep_values", "SWEEP_DEFAULTS", "SWEEPABLE",
           "fixed_frequency", "sweep_settings", "log_modes", "settings_of", "apply_settings",
           "sweep_options",
           "command", "params_from_args"]

#: parameter -> (start, stop, num, log)
SWEEP_DEFAULTS = {
    "frequency": (10.0, 12500.0, 250, True),
    "mu": (0.01, 0.99, 99, False),
    "phi0": (0.62, 1.46, 85, False),
}


def sweep(parameter, values, params=None, frequency=None, progress=False, rtol=1e-10):
    """Steady states of the friction drive over ``values`` of one parameter.

    Parameters
    ----------
    parameter : {"frequency", "mu", "phi0"}
    values : array_like
    params : FrictionDriveParams, optional
        The other parameters (paper defaults).
    frequency : float
        Drive frequency [Hz] for ``mu`` and ``phi0`` sweeps.
    progress : bool
        Show a progress bar.

    Returns
    -------
    list of dict
        One row per value: ``value``, ``mode``, ``displacement_per_period_m``,
        ``average_velocity_m_per_s``, ``min_normal_force_N``,
        ``periodic_residual``, ``error`` (empty when the point succeeded).

    Examples
    --------
    >>> rows = sweep("frequency", [20.0, 2000.0])
    >>> [r["mode"] for r in rows]
    ['NS', 'NP']
    """
    if parameter not in SWEEP_DEFAULTS:
        raise InputError(f"`parameter` must be one of {sorted(SWEEP_DEFAULTS)}, got {parameter!r}")
    params = PAPER_DEFAULTS if params is None else params
    if parameter != "frequency":
        frequency = positive("frequency", frequency if frequency is not None else float("nan"))
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise InputError("`values` must be a non-empty 1-D array of finite numbers")
    it = values
    if progress:
        from tqdm.auto import tqdm
        it = tqdm(values, desc=f"sweep {parameter}", unit="pt", disable=None)  # terminals only
    rows = []
    try:
        for x in it:
            row = {"value": float(x), "mode": "", "displacement_per_period_m": math.nan,
                   "average_velocity_m_per_s": math.nan, "min_normal_force_N": math.nan,
                   "periodic_residual": math.nan, "error": ""}
            try:
                if parameter == "frequency":
                    scene = FrictionDrive(params, float(x))
                else:
                    scene = FrictionDrive(params.with_(**{parameter: float(x)}), frequency)
                # a sweep point is periodic or failed (a statistical run per failed point would
                # cost up to its budget of periods)
                ss = steady_state.find_steady_state(scene, rtol=rtol, statistical=False)
                d = scene.displacement_to_si(ss.displacement_per_period)
                row.update(mode=ss.mode, displacement_per_period_m=d,
                           average_velocity_m_per_s=d * scene.frequency,
                           min_normal_force_N=scene.force_to_si(ss.min_normal_force),
                           periodic_residual=ss.periodic_residual)
            except MoreauError as exc:
                row["error"] = f"{type(exc).__name__}: {exc}"
            rows.append(row)
    except KeyboardInterrupt:
        pass  # keep the finished points
    return rows


def write_csv(rows, path):
    """Write sweep rows to ``path`` as CSV."""
    outputs.write_csv(path, rows, list(rows[0].keys()) if rows else ["value"])


def plot_sweep(rows, parameter, path, title=""):
    """Figure of displacement per period against the parameter, coloured by mode."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.array([r["value"] for r in rows])
    d = np.array([r["displacement_per_period_m"] for r in rows]) * 1e6
    modes = [r["mode"] or "error" for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(x, d, "k-", lw=1)
    for m in dict.fromkeys(modes):
        sel = np.array([mm == m for mm in modes])
        ax.plot(x[sel], np.where(np.isfinite(d[sel]), d[sel], 0.0), ".", ms=5, label=m)
    if parameter == "frequency":
        ax.set_xscale("log")
        ax.set_xlabel("drive frequency f [Hz]")
    else:
        ax.set_xlabel({"mu": "friction coefficient mu", "phi0": "initial tilt phi0 [rad]"}[parameter])
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.set_ylabel("displacement per period [um]")
    ax.set_title(title)
    ax.legend(title="mode", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


#: scene parameters a sweep can vary, besides ``frequency``
SWEEPABLE = ("frequency", "m", "m2", "k", "length", "phi0", "mu", "x10", "load", "restitution")


def _with(stem, suffix):
    # Path.with_suffix would take the ".5_N400" of a tag like theta0.5_N400 for a suffix
    return stem.parent / (stem.name + suffix)


def scheme_tag(scheme):
    """The file-name suffix of a scheme: empty for the event-driven reference at its default.

    Examples
    --------
    >>> scheme_tag(make_scheme())
    ''
    >>> scheme_tag(make_scheme("moreau-jean", theta=0.5, steps_per_period=2000))
    '_mj_theta0.5_N2000'
    >>> scheme_tag(make_scheme("event-driven", rtol=1e-6))
    '_ed_rtol1e-06'
    """
    if scheme.name == "moreau-jean" and not scheme.options:
        tag = f"_mj_theta{scheme.theta:g}_N{scheme.steps_per_period}"
        return tag + (f"_tol{scheme.rtol:g}" if scheme.rtol is not None else "")
    if scheme.name == "event-driven" and not scheme.options:
        return "" if scheme.rtol in (None, 1e-10) else f"_ed_rtol{scheme.rtol:g}"
    return f"_{scheme.label}" + (f"_tol{scheme.rtol:g}" if scheme.rtol is not None else "")


def sweep_values(parameter, start, stop, points, scale="linear"):
    """The swept values of a friction-drive sweep, checked (see
    :func:`moreau.analysis.sweep.sweep_values`); ``START`` and ``STOP`` differ when there are
    several points.

    Examples
    --------
    >>> sweep_values("frequency", 10, 1000, 3, "log").tolist()
    [10.0, 100.0, 1000.0]
    """
    if parameter not in SWEEPABLE:
        raise InputError(f"`PARAM` must be one of {list(SWEEPABLE)}, got {parameter!r}")
    values = scene_sweep.sweep_values(start, stop, points, scale,
                                      names=("START", "STOP", "--points"))
    if len(values) > 1 and values[0] == values[-1]:
        raise InputError("`START` and `STOP` must differ when `--points` > 1")
    return values


def fixed_frequency(parameter, frequency):
    """The drive frequency [Hz] of a sweep of ``parameter``: ``None`` when it is the swept one.

    Examples
    --------
    >>> fixed_frequency("mu", 185), fixed_frequency("frequency", None)
    (185.0, None)
    """
    if parameter == "frequency":
        if frequency is not None:
            raise InputError("`--frequency` is the swept parameter here; leave it out")
        return None
    if frequency is None:
        raise InputError(f"`--frequency` is required for a sweep of {parameter!r} (drive frequency in Hz)")
    return positive("frequency", frequency)


def sweep_settings(parameter, values, scale, frequency, params, scheme, continuation):
    """The settings of a sweep that :func:`moreau.outputs.claim_outputs` records with its outputs."""
    return {"parameter": parameter, "values": [values[0], values[-1], len(values), scale],
            "frequency_Hz": frequency, "parameters_SI": asdict(params),
            "scheme": [scheme.name, scheme.theta, scheme.steps_per_period, scheme.rtol,
                       scheme.options], "continuation": bool(continuation)}


def log_modes(table, column, log):
    """One line to ``log`` where the steady state's mode changes along a sweep's ``table``."""
    prev = None
    for r in table:
        label = r["mode"] if r["status"] == "ok" else "failed: " + r["status"].split(":")[0]
        if label != prev:
            log(f"  from {r[column]:.6g}: {label}")
            prev = label


def settings_of(items, names):
    """A sweep command's ``--set NAME=VALUE`` options as ``{NAME: float}``, each ``NAME`` in ``names``.

    Examples
    --------
    >>> settings_of(["mu=0.2", " k = 30"], ["mu", "k"])
    {'mu': 0.2, 'k': 30.0}
    """
    settings = {}
    for item in items or []:
        key, sep, val = item.partition("=")
        key = key.strip()
        if not sep or key not in names:
            raise InputError(f"`--set` takes NAME=VALUE with NAME one of {names}, got {item!r}")
        try:
            settings[key] = float(val)
        except ValueError:
            raise InputError(f"`--set {key}` must be a number, got {val.strip()!r}") from None
    return settings


def apply_settings(args, settings):
    """Each of ``settings`` onto the parsed options ``args``, refused where its own option is given too."""
    for key, val in settings.items():
        if getattr(args, key, None) is not None:
            raise InputError(f"`{key}` is given twice (`--{key.replace('_', '-')}` and "
                             f"`--set {key}=...`)")
        setattr(args, key, val)


def sweep_options(args, scale):
    """``(scheme, points, scale)`` of a sweep command's options, ``scale`` the default scale.

    ``--num`` is the old name of ``--points``; ``--log`` is ``--scale log``.
    """
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol,
                         getattr(args, "scheme_options", None))
    if args.num is not None and args.points is not None:
        raise InputError("`--num` is the old name of `--points`; give one of them")
    if args.log:
        if args.scale == "linear":
            raise InputError("`--log` contradicts `--scale linear`")
        scale = "log"
    return scheme, args.points if args.points is not None else args.num, scale


def run_sweep(parameter, params=None, frequency=None, start=None, stop=None, points=None,
              scale=None, scheme=None, out="out", cache_dir=None, n_jobs=-1, scheduler=None,
              progress=True, plot=True, log=print, force=False, continuation=True, netcdf=False):
    """The ``moreau sweep`` command: steady states over one parameter through the sweep engine.

    Every point goes through :func:`moreau.analysis.engine.run_points`: cached
    on disk (``cache_dir``, default ``OUT/cache``), in parallel on local
    processes or on a Dask scheduler, a failed point kept as its ``status``.
    Writes ``OUT/sweep_TAG.csv`` (tidy, units in the column names, the same
    columns as ``moreau reproduce`` plus ``scheme``; ``TAG`` names the
    parameter, the frequency and any scheme or setting other than the
    event-driven reference's default, :func:`scheme_tag`), ``sweep_TAG.json`` (parameters, scheme,
    package version) and the figure ``sweep_TAG.png``/``.svg``.

    Parameters
    ----------
    parameter : str
        One of :data:`SWEEPABLE`.
    params : FrictionDriveParams, optional
        The fixed parameters (paper defaults).
    frequency : float, optional
        Drive frequency [Hz] when ``parameter`` is not ``"frequency"``.
    start, stop, points, scale
        The values (defaults of :data:`SWEEP_DEFAULTS` for frequency, mu, phi0).
    scheme : Scheme, optional
        From :func:`make_scheme` (event-driven, shooting tolerance 1e-10).
    out : path-like
        Output folder, checked writable before any work.
    netcdf : bool
        Also write the table as NetCDF next to its CSV
        (:func:`moreau.analysis.sweep.write_netcdf_beside`; needs xarray, the
        ``[data]`` extra, checked before any work).

    Returns
    -------
    list of dict
        The tidy rows.
    """
    params = PAPER_DEFAULTS if params is None else params
    if netcdf:
        scene_sweep.require_xarray("`netcdf`")
    if parameter not in SWEEPABLE:
        raise InputError(f"`PARAM` must be one of {list(SWEEPABLE)}, got {parameter!r}")
    d0, d1, dn, dlog = SWEEP_DEFAULTS.get(parameter, (None, None, 50, False))
    if (start is None or stop is None) and d0 is None:
        raise InputError(f"`START` and `STOP` are required for a sweep of {parameter!r}")
    start = d0 if start is None else start
    stop = d1 if stop is None else stop
    scale = ("log" if dlog else "linear") if scale is None else scale
    values = sweep_values(parameter, start, stop, dn if points is None else points, scale)
    frequency = fixed_frequency(parameter, frequency)
    # every value must make a valid parameter set before any work starts
    for x in (values[0], values[-1]):
        sweep_point(params, parameter, x, frequency if frequency is not None else float(x))
    scheme = make_scheme() if scheme is None else scheme
    out = check_output_dir(out)
    cache_dir = out / "cache" if cache_dir is None else cache_dir
    tag = parameter if parameter == "frequency" else f"{parameter}_{frequency:g}Hz"
    # a scheme or setting other than the reference's default is in the name, so
    # that sweeps of one parameter by different schemes do not overwrite each other
    tag += scheme_tag(scheme)
    stem = out / f"sweep_{tag}"
    settings = claim_outputs(stem, sweep_settings(parameter, values, scale, frequency, params,
                                                  scheme, continuation), force)

    points_ = [sweep_point(params, parameter, x, frequency) for x in values]
    # neighbours in segments, each point shot from the previous one's orbit
    rows, stats = engine.run_points(points_, scheme, cache_dir=cache_dir, n_jobs=n_jobs,
                                    scheduler=scheduler, progress=progress,
                                    desc=f"sweep {parameter}", energy=True,
                                    chunk=engine.line_chunk(len(points_), n_jobs, continuation),
                                    continuation=bool(continuation))
    table = tidy_rows(parameter, values, frequency, params, rows, ())
    for r, row in zip(table, rows):
        r.update(engine.line_columns(row))
    for r in table:
        r["scheme"] = scheme.name
    write_table(table, _with(stem, ".csv"))
    marks = range_marks(params, parameter, frequency)
    write_sidecar(_with(stem, ".json"), params, f"sweep_{tag}", parameter, values, frequency,
                  marks, (), None, stats, scheme=scheme, settings=settings)
    log(f"wrote {_with(stem, '.csv')} ({len(table)} points: {stats['computed']} computed, "
        f"{stats['cached']} from the cache)")
    if netcdf:
        scene_sweep.write_netcdf_beside(stem, table, [list(table[0])[0]], log)
    if plot:
        label = scheme.description
        paths = sweep_figure(table, parameter, frequency, marks, stem, log=scale == "log",
                             scheme_label=label)
        log(f"wrote {paths[0]}")
    log_modes(table, list(table[0])[0] if table else None, log)
    return table


def params_from_args(args):
    """The friction drive's parameters from the options of a command (``--mu``, ``--phi0``, ...)."""
    return params_from_kwargs(mu=args.mu, phi0=args.phi0, x10=args.x10, k=args.k, m=args.m,
                              m2=args.m2, length=args.length, load=args.load,
                              restitution=args.restitution)




def command(args):
    """``moreau sweep`` of the paper's friction drive (registered as the scene's sweep hook).

    ``args`` are the parsed arguments of ``moreau sweep``; every option is
    checked before any work.
    """
    if args.parameter not in SWEEPABLE:
        raise InputError(f"`PARAM` {args.parameter!r} is not a parameter of the friction drive")
    for opt in ("x10_a", "x10_b", "phase"):
        if getattr(args, opt) is not None:
            raise InputError(f"`--{opt.replace('_', '-')}` is not a parameter of the friction drive")
    settings = settings_of(args.set, list(SWEEPABLE))
    if args.parameter in settings:
        raise InputError(f"`--set {args.parameter}` fixes the swept parameter; leave it out")
    if args.parameter != "frequency" and getattr(args, args.parameter, None) is not None:
        raise InputError(f"`--{args.parameter}` fixes the swept parameter; leave it out")
    frequency = settings.pop("frequency", args.frequency)
    apply_settings(args, settings)
    params = params_from_args(args)
    scheme, points, scale = sweep_options(args, args.scale)
    run_sweep(args.parameter, params, frequency=frequency, start=args.start, stop=args.stop,
              points=points, scale=scale,
              scheme=scheme, out=args.out, cache_dir=args.cache, n_jobs=args.jobs,
              scheduler=args.scheduler, progress=not args.quiet, plot=not args.no_plot,
              force=args.force, continuation=not args.cold,
              netcdf=getattr(args, "netcdf", False))


registry.register_hook("friction-drive", "sweep", command)
