"""``moreau sweep --scene bidirectional``: steady states of the two-rod drive over one parameter.

The points go through the same engine as the single-rod sweeps
(:func:`moreau.analysis.engine.run_points` with ``scene="bidirectional"``):
cached on disk, in parallel, a failed point kept as its ``status``. The
output is the same kind of tidy CSV (units in the column names), JSON
sidecar and figure.

Any field of :class:`~moreau.scenes.bidirectional_drive.BidirectionalDriveParams`
can be swept, plus ``frequency`` and the direction-control knob ``balance``
(:func:`moreau.studies.bidirectional.direction_control.bidirectional_params`: ``-1`` rod
``a`` alone, ``0`` both rods, ``+1`` rod ``b`` alone). ``x10`` sets both
stator amplitudes when it is fixed (``--x10`` or ``--set x10=...``).
"""

import json
import math
import sys
from dataclasses import asdict

from ... import __version__
# the module, not its function: a test (or a user) that replaces
# engine.run_points reaches these sweeps too
from ...analysis import engine
from ...analysis.engine import check_output_dir, code_version
from ...analysis.sweep import require_xarray, write_netcdf_beside
from ...errors import InputError
from ...model import registry
from ...outputs import claim_outputs
from ...provenance import provenance
from ...scenes.bidirectional_drive import BidirectionalDriveParams, params_from_kwargs
from ..paper.figures import sweep_figure
from ..paper.sweeps import (apply_settings, fixed_frequency, log_modes, make_scheme, scheme_tag,
                           settings_of, sweep_options, sweep_settings, sweep_values)
from ..paper.tables import run_columns, write_table
from ..paper.valid_range import lift_off_margin, range_marks
from .direction_control import bidirectional_params

__all__ = ["command", "params_from_args", "BIDIRECTIONAL_SWEEPABLE", "BIDIRECTIONAL_COLUMNS", "point_params",
           "run_bidirectional_sweep"]

#: swept (or fixed) parameter -> CSV column, units in the name
BIDIRECTIONAL_COLUMNS = {"frequency": "frequency_Hz", "m": "m_kg", "m2": "m2_kg",
                         "k": "k_N_per_m", "length": "length_m", "phi0": "phi0_rad", "mu": "mu",
                         "x10_a": "x10_a_m", "x10_b": "x10_b_m", "phase": "phase_rad",
                         "balance": "balance", "load": "load_N", "restitution": "restitution"}
#: parameters a bidirectional sweep can vary
BIDIRECTIONAL_SWEEPABLE = tuple(BIDIRECTIONAL_COLUMNS)
_VALUE_COLUMNS = ["mode", "displacement_per_period_m", "average_velocity_m_per_s",
                  "min_normal_force_N", "periodic_residual", "shooting_iterations", "status"]


def point_params(params, parameter, value):
    """The :class:`BidirectionalDriveParams` of one sweep point (validated).

    Examples
    --------
    >>> from moreau.scenes.bidirectional_drive import BidirectionalDriveParams
    >>> p = point_params(BidirectionalDriveParams(), "balance", -1.0)
    >>> p.x10_a, p.x10_b
    (2e-06, 0.0)
    >>> point_params(BidirectionalDriveParams(), "phase", 1.0).phase
    1.0
    """
    if parameter == "frequency":
        return params
    if parameter == "balance":
        return bidirectional_params("balance", float(value), params)
    if parameter not in BIDIRECTIONAL_SWEEPABLE:
        raise InputError(f"`PARAM` must be one of {list(BIDIRECTIONAL_SWEEPABLE)}, "
                         f"got {parameter!r}")
    return params.with_(**{parameter: float(value)})


def _lift_off_margin(p, frequency):
    # each rod's free normal acceleration on its contact manifold depends on its
    # own stator only (M is diagonal): the worst of the excited rods
    m = [lift_off_margin(p.rod(r), frequency) for r in "ab" if getattr(p, f"x10_{r}") > 0]
    return max(m) if m else math.nan


def _marks(p, parameter, frequency):
    rods = [p.rod(r) for r in "ab" if getattr(p, f"x10_{r}") > 0]
    if not rods or parameter not in ("frequency", "mu", "phi0"):
        return {}
    if parameter == "frequency":
        f = [range_marks(r, "frequency").get("contact_loss_Hz") for r in rods]
        f = [x for x in f if x is not None]
        return {"contact_loss_Hz": min(f)} if f else {}
    if parameter == "mu":
        return range_marks(rods[0], "mu", frequency)
    vr = [range_marks(r, "phi0", frequency) for r in rods]
    out = {"lift_off_edge": max(v["lift_off_edge"] for v in vr),
           "painleve_edge": min(v["painleve_edge"] for v in vr)}
    inner = sorted({e for v in vr for e in v.get("inner_edges", [])})
    if inner:
        out["inner_edges"] = inner
    return out


def tidy_rows(parameter, values, frequency, params, rows):
    """Tidy CSV rows: the swept value, the fixed key parameters, the margins, the results."""
    out = []
    for x, row in zip(values, rows):
        p = point_params(params, parameter, x)
        f = float(x) if parameter == "frequency" else frequency
        r = {BIDIRECTIONAL_COLUMNS[parameter]: float(x)}
        fixed = {"frequency": f, "mu": p.mu, "phi0": p.phi0, "x10_a": p.x10_a,
                 "x10_b": p.x10_b, "phase": p.phase}
        for name, val in fixed.items():
            r.setdefault(BIDIRECTIONAL_COLUMNS[name], val)
        r["painleve_margin"] = 1.0 - p.mu * math.tan(p.phi0)
        r["lift_off_margin"] = _lift_off_margin(p, f)
        for c in _VALUE_COLUMNS:
            r[c] = row.get(c, math.nan if c != "mode" else "")
        out.append(run_columns(r, row))
    return out


def run_bidirectional_sweep(parameter, params=None, frequency=None, start=None, stop=None,
                            points=None, scale="linear", scheme=None, out="out", cache_dir=None,
                            n_jobs=-1, scheduler=None, progress=True, plot=True, log=print,
                            force=False, continuation=True, netcdf=False):
    """Steady states of the bidirectional drive over one parameter, through the sweep engine.

    Writes ``OUT/sweep_bidirectional_TAG.csv`` (tidy, units in the column
    names, a ``status`` column), ``.json`` (scene, parameters, scheme,
    versions, cache statistics) and the figure ``.png``/``.svg``.

    Parameters
    ----------
    parameter : str
        One of :data:`BIDIRECTIONAL_SWEEPABLE`.
    params : BidirectionalDriveParams, optional
        The fixed parameters (paper's rod, both stators at 2 um, in phase).
    frequency : float, optional
        Drive frequency [Hz]; required unless ``parameter`` is ``"frequency"``.
    start, stop, points, scale
        The swept values (``points`` from ``start`` to ``stop``, linear or log).
    scheme : Scheme, optional
        From :func:`moreau.studies.paper.sweeps.make_scheme` (event-driven by default).
    out, netcdf
        As for :func:`moreau.studies.paper.sweeps.run_sweep`.

    Returns
    -------
    list of dict
        The tidy rows.
    """
    params = BidirectionalDriveParams() if params is None else params
    if netcdf:
        require_xarray("`netcdf`")
    if parameter not in BIDIRECTIONAL_SWEEPABLE:
        raise InputError(f"`PARAM` must be one of {list(BIDIRECTIONAL_SWEEPABLE)} for the "
                         f"bidirectional drive, got {parameter!r}")
    if start is None or stop is None:
        raise InputError(f"`START` and `STOP` are required for a bidirectional sweep of "
                         f"{parameter!r}")
    values = sweep_values("frequency", start, stop, 50 if points is None else points, scale)
    frequency = fixed_frequency(parameter, frequency)
    if parameter == "frequency" and values.min() <= 0:
        raise InputError("`START` and `STOP` must be > 0 for a frequency sweep")
    # every value must make a valid parameter set before any work starts
    for x in (values.min(), values.max()):
        point_params(params, parameter, x)
    scheme = make_scheme() if scheme is None else scheme
    out = check_output_dir(out)
    cache_dir = out / "cache" if cache_dir is None else cache_dir
    # the scheme and its non-default settings are in the name, as in the friction drive's sweep
    tag = "bidirectional_" + (parameter if parameter == "frequency"
                              else f"{parameter}_{frequency:g}Hz") + scheme_tag(scheme)
    stem = out / f"sweep_{tag}"
    settings = claim_outputs(stem, sweep_settings(parameter, values, scale, frequency, params,
                                                  scheme, continuation), force)

    pts = [(asdict(point_params(params, parameter, x)),
            float(x) if parameter == "frequency" else frequency) for x in values]
    # neighbours in segments, each point shot from the previous one's orbit
    rows, stats = engine.run_points(pts, scheme, cache_dir=cache_dir, n_jobs=n_jobs,
                                    scheduler=scheduler, progress=progress,
                                    desc=f"sweep {parameter}", scene="bidirectional",
                                    energy=True,
                                    chunk=engine.line_chunk(len(pts), n_jobs, continuation),
                                    continuation=bool(continuation))
    table = tidy_rows(parameter, values, frequency, params, rows)
    for r, row in zip(table, rows):
        r.update(engine.line_columns(row))
    for r in table:
        r["scheme"] = scheme.name
    write_table(table, (stem.parent / (stem.name + ".csv")))
    marks = _marks(params, parameter, frequency)
    meta = {
        "study": f"sweep_{tag}",
        "scene": "bidirectional-drive",
        "swept_parameter": BIDIRECTIONAL_COLUMNS[parameter],
        "points": int(len(values)),
        "range": [float(values[0]), float(values[-1])],
        "frequency_Hz": frequency,
        "parameters_SI": asdict(params),
        "reference_scheme": {**scheme.record,
                             "projection": True if scheme.name == "moreau-jean" else None},
        "valid_range": marks,
        "package_version": __version__,
        "code_version": code_version(),
        "python": sys.version.split()[0],
        "engine": stats,
        "provenance": provenance(code_version()),
        "settings": settings,
    }
    (stem.parent / (stem.name + ".json")).write_text(json.dumps(meta, indent=2))
    log(f"wrote {(stem.parent / (stem.name + '.csv'))} ({len(table)} points: {stats['computed']} computed, "
        f"{stats['cached']} from the cache)")
    if netcdf:
        write_netcdf_beside(stem, table, [BIDIRECTIONAL_COLUMNS[parameter]], log)
    if plot:
        label = scheme.description
        title = f"Bidirectional drive: steady state against {parameter}" + (
            f" at f = {frequency:g} Hz" if frequency is not None else "")
        try:
            paths = sweep_figure(table, parameter, frequency, marks, stem, log=scale == "log",
                                 scheme_label=label, title=title)
            log(f"wrote {paths[0]}")
        except ImportError:  # matplotlib is optional for the data
            pass
    log_modes(table, BIDIRECTIONAL_COLUMNS[parameter], log)
    return table


def params_from_args(args):
    """The two-rod drive's parameters from a command's options (``--x10-a`` etc.; ``--x10`` sets both)."""
    x10 = args.x10
    return params_from_kwargs(
        mu=args.mu, phi0=args.phi0, k=args.k, m=args.m, m2=args.m2, length=args.length,
        load=args.load, restitution=args.restitution, phase=args.phase,
        x10_a=args.x10_a if args.x10_a is not None else x10,
        x10_b=args.x10_b if args.x10_b is not None else x10)


def command(args):
    """``moreau sweep --scene bidirectional-drive PARAM START STOP ...`` (registered as the
    scene's sweep hook); every option is checked before any work."""

    param = args.parameter
    if param not in BIDIRECTIONAL_SWEEPABLE:
        raise InputError(f"`PARAM` must be one of {list(BIDIRECTIONAL_SWEEPABLE)} for "
                         f"`--scene bidirectional`, got {param!r} (`x10` sets both rods: "
                         "sweep `x10_a`, `x10_b` or `balance`)")
    settable = [p for p in BIDIRECTIONAL_SWEEPABLE if p != "balance"] + ["x10"]
    settings = settings_of(args.set, settable)
    # the stator amplitudes a balance point sets, and the parameter swept, cannot also be fixed
    fixed_by_sweep = {"balance": ("x10_a", "x10_b")}.get(param, (param,))
    for key in fixed_by_sweep:
        if key in settings:
            raise InputError(f"`--set {key}` fixes what the sweep of {param!r} varies; leave it out")
        if key != "frequency" and getattr(args, key, None) is not None:
            raise InputError(f"`--{key.replace('_', '-')}` fixes what the sweep of {param!r} "
                             "varies; leave it out")
    frequency = settings.pop("frequency", args.frequency)
    if "frequency" in fixed_by_sweep and args.frequency is not None:
        raise InputError("`--frequency` is the swept parameter here; leave it out")
    apply_settings(args, settings)
    params = params_from_args(args)
    scheme, points, scale = sweep_options(args, args.scale or "linear")
    run_bidirectional_sweep(param, params, frequency=frequency, start=args.start, stop=args.stop,
                            points=points,
                            scale=scale, scheme=scheme, out=args.out, cache_dir=args.cache,
                            n_jobs=args.jobs, scheduler=args.scheduler, progress=not args.quiet,
                            plot=not args.no_plot, force=args.force,
                            continuation=not args.cold, netcdf=getattr(args, "netcdf", False))


registry.register_hook("bidirectional-drive", "sweep", command)
