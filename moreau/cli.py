"""Command line interface: ``moreau reproduce``, ``steady``, ``sweep``, ``atlas``, ``bifurcation``, ``run``, ``characteristic``.

Physical inputs and outputs are in SI units; the computation runs in the
paper's dimensionless variables.
"""

import argparse
import dataclasses
import json
import math
import os
import signal
import sys
import threading

from . import __version__
from .analysis import compare as cmp
from .analysis.engine import check_jobs, check_output_dir, check_scheduler, make_scheme
from .analysis.atlas import classify_budget, run_scene_atlas
from .analysis.bifurcation import bifurcation_diagram
from .analysis.characteristic import efficiency_vs_frequency, motor_characteristic
from .analysis.classify import CLASSIFY_PERIODS
from .analysis.statistical import MIN_PERIODS, PRECISION
from .analysis.sweep import require_xarray, run_scene_sweep, sweep_values
from .analysis.history import (default_run, history_tag, plot_history, run_history,
                               write_history)
from .analysis.summary import check_periodic, steady_state_report
from ._log import configure_cli
from .errors import BudgetExhaustedError, InputError, Interrupted, MoreauError
from .outputs import claim_outputs
from .provenance import provenance
from .integrators.base import (INTEGRATORS, check_options, get_integrator,
                               propagate_interrupts, scheme_options)
from .model.registry import (default_scene, describe, discover, entries, get_entry,
                              resolve_hook, scene_names)
from .studies.paper.reproduce import reproduce
from .studies.paper.stress import format_stress_table, run_catalogue, write_stress_outputs
from .suite.command import add_commands as add_suite_commands

__all__ = ["main"]


def scheme_names():
    """Every registered scheme (the scenes' own references included)."""
    discover()
    return sorted(INTEGRATORS)


def _flag(name):
    return "--" + name.replace("_", "-")


def _bool_value(text):
    low = str(text).strip().lower()
    if low in ("true", "yes", "1", "on"):
        return True
    if low in ("false", "no", "0", "off"):
        return False
    raise argparse.ArgumentTypeError(f"expected true or false, got {text!r}")


def _auto_bool_value(text):
    return "auto" if str(text).strip().lower() == "auto" else _bool_value(text)


def _help(text):
    return text.replace("%", "%%")


def scene_parameter_flags():
    """``{name: (Parameter, scenes)}`` of every registered scene's parameters, by name.

    Each is a flag of the commands that take a scene (``--mu 0.2`` is
    ``--set mu=0.2``), generated from the scenes' registered
    :class:`~moreau.model.registry.Parameter` entries.

    Examples
    --------
    >>> "friction-drive" in scene_parameter_flags()["phi0"][1]
    True
    """
    discover()
    out = {}
    for e in entries():
        for prm in e.parameters:
            out.setdefault(prm.name, (prm, []))[1].append(e.name)
    return out


def scheme_option_flags():
    """``{name: (field, schemes)}`` of the registered schemes' options that are flags.

    Every field of a scheme's ``Options`` dataclass, except a name that is
    also a scene parameter (``damping``) or another flag of the command
    (``--rtol``, the shooting tolerance, ``--theta``): those are given with
    ``--option NAME=VALUE``.

    Examples
    --------
    >>> flags = scheme_option_flags()
    >>> "save_every" in flags, "damping" in flags, "rtol" in flags
    (True, False, False)
    """
    scene = scene_parameter_flags()
    out = {}
    for name in scheme_names():
        opts = INTEGRATORS[name].Options
        for f in dataclasses.fields(opts) if opts is not None else ():
            if f.name in scene or f.name in _OWN_FLAGS or _field_type(f) is None:
                continue
            out.setdefault(f.name, (f, []))[1].append(name)
    return out


#: scheme options that have a flag of their own with its own meaning
_OWN_FLAGS = ("theta", "rtol")


def _field_type(field):
    """The command-line type of an options field (None: not a flag, e.g. an array)."""
    kind = field.type.__name__ if isinstance(field.type, type) else str(field.type)
    kind = kind.replace(" ", "")
    if kind in ("str|bool", "bool|str"):
        return _auto_bool_value
    if kind in ("str|int", "int|str"):
        return _int_or_word
    base = kind.replace("|None", "")
    return {"float": float, "int": int, "bool": _bool_value, "str": str}.get(base)


def _int_or_word(text):
    """An integer where the text is one (``--cone 16``), else the word (``--cone exact``)."""
    try:
        return int(text)
    except ValueError:
        return text


def _scene_flag_type(prm):
    if prm.unit == "choice" or isinstance(prm.default, str):
        return str
    if isinstance(prm.default, bool):
        return _bool_value
    if isinstance(prm.default, int):
        return int
    return float


def add_scene_flags(p):
    """A flag per registered scene parameter (not one the command has already)."""
    for name, (prm, scenes) in sorted(scene_parameter_flags().items()):
        if _flag(name) in p._option_string_actions:
            continue
        unit = f" [{prm.unit}]" if prm.unit and prm.unit != "choice" else ""
        # a scene's own words only where every scene taking the flag says the same
        docs = {q.doc for s in scenes for q in get_entry(s).parameters if q.name == name}
        what = prm.doc if len(docs) == 1 and prm.doc else name
        p.add_argument(_flag(name), dest=name, type=_scene_flag_type(prm), default=None,
                       help=_help(f"{what}{unit}, same as --set {name}=VALUE (scenes: "
                                  f"{', '.join(scenes)})"))


def add_scheme_flags(p):
    """A flag per registered scheme option (see :func:`scheme_option_flags`)."""
    for name, (f, schemes) in sorted(scheme_option_flags().items()):
        if _flag(name) in p._option_string_actions:
            continue
        p.add_argument(_flag(name), dest="scheme_opt_" + name, type=_field_type(f),
                       default=None, metavar=name.upper(),
                       help=_help(f"scheme option {name}, same as --option {name}=VALUE "
                                  f"(schemes: {', '.join(schemes)})"))


def _add_params(p, scheme_defaults=True):
    add_scene_flags(p)
    p.add_argument("--scheme", default="event-driven", choices=scheme_names(),
                   help="any registered scheme (default event-driven)")
    p.add_argument("--option", action="append", metavar="NAME=VALUE",
                   help="any other option of the scheme (repeatable), e.g. --option stiffness=1e6")
    # without defaults a command can tell (and refuse) a setting that would not act
    p.add_argument("--steps-per-period", type=int, default=1000 if scheme_defaults else None,
                   help="time-stepping schemes' steps per drive period (default 1000)")
    p.add_argument("--theta", type=float, default=1.0 if scheme_defaults else None,
                   help="Moreau-Jean theta in [1/2, 1] (default 1)")
    p.add_argument("--rtol", type=float, default=1e-10 if scheme_defaults else None,
                   help="shooting tolerance (default 1e-10 event-driven, 1e-12 Moreau-Jean)")
    add_scheme_flags(p)


def _scheme_args(args, rtol_acts=True):
    """Refuse scheme settings that would not act, then fill in the scheme's defaults."""
    if args.rtol is not None and not rtol_acts:
        raise InputError(f"`--rtol` does not act in `moreau {args.command}` (a time history "
                         "runs each scheme at its own tolerance); leave it out")
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol,
                         args.scheme_options)
    args.theta, args.steps_per_period, args.rtol = (scheme.theta, scheme.steps_per_period,
                                                    scheme.rtol)
    args.scheme_options = scheme.options


def shorthands():
    """The command-line shorthands of scene parameters (``--mu 0.2`` is ``--set mu=0.2``):
    ``--frequency`` and a flag per registered scene parameter."""
    return ("frequency",) + tuple(sorted(set(scene_parameter_flags()) - {"frequency"}))


def _scene_command(p, func, with_set=True):
    # the options every command on one scene ends with, and its function
    _add_params(p, scheme_defaults=False)
    add_scene_options(p, with_set=with_set)
    p.set_defaults(func=func)


def add_scene_options(p, with_set=True):
    """The ``--scene`` switch (and ``--set``); the scene parameters' flags where not yet there."""
    default = default_scene()
    p.add_argument("--scene", default=default, metavar="NAME",
                   help=f"a registered scene (`moreau scenes`; default {default})")
    if with_set:
        p.add_argument("--set", action="append", metavar="NAME=VALUE",
                       help="any parameter of the scene (repeatable), e.g. --set mu=0.3")
    add_scene_flags(p)


def scene_parameters(args, entry):
    """The parameters of scene ``entry`` given on the command line: ``--set`` and the shorthands.

    A name the scene does not have is refused, listing the ones it has.
    """
    params = parse_settings(args.set or [], "--set")
    short = shorthands()
    for key in short:
        val = getattr(args, key, None)
        if val is not None:
            if key in params:
                raise InputError(f"`{key}` is given twice (`--{key.replace('_', '-')}` and "
                                 f"`--set {key}=...`)")
            params[key] = val
    names = entry.parameter_names()
    for key in params:
        if key not in names:
            flag = (f"--{key.replace('_', '-')}" if key in short and not any(
                item.partition("=")[0].strip() == key for item in args.set or [])
                    else f"--set {key}")
            raise InputError(f"`{flag}`: `{key}` is not a parameter of scene {entry.name!r}; "
                             f"its parameters: {', '.join(names)}")
    return params


#: `moreau steady`'s default budget of a statistical steady state, drive periods of each start:
#: the reference at 15 kHz, e = 1 (no orbit; chaotic, its displacement per period correlated
#: over 10^4 periods and more) was called converged from rest after 1 638 400 periods (122 CPU
#: s) and from rest with the rotor at half the tip's speed after 3 000 000; the API's default
#: (MAX_PERIODS) stays small for the callers that only try it (the stress catalogue's fallback)
STEADY_MAX_PERIODS = 4000000


def _statistical_args(args):
    """The statistical steady state's options of ``moreau steady``, checked before any work."""
    if args.max_periods < MIN_PERIODS:
        raise InputError(f"`--max-periods` must be an integer >= {MIN_PERIODS}, got "
                         f"{args.max_periods}")
    if not (args.precision > 0.0 and math.isfinite(args.precision)):
        raise InputError(f"`--precision` must be a number > 0, got {args.precision!r}")
    if args.starts < 1:
        raise InputError(f"`--starts` must be an integer >= 1, got {args.starts}")
    return {"max_periods": args.max_periods, "precision": args.precision,
            "starts": args.starts, "progress": not args.quiet}


def _cmd_steady(args):
    stat = _statistical_args(args)
    _scheme_args(args)
    entry = get_entry(args.scene)
    params = scene_parameters(args, entry)
    if ("frequency" in entry.parameter_names() and "frequency" not in params
            and entry.defaults().get("frequency") is None):
        raise InputError("`--frequency` is required (drive frequency in Hz)")
    scene = entry.factory(**params)
    check_periodic(scene)
    try:
        rep = steady_state_report(scene, scheme=args.scheme,
                                  steps_per_period=args.steps_per_period, theta=args.theta,
                                  rtol=args.rtol, options=args.scheme_options,
                                  max_period=args.max_period, statistical_options=stat)
    except BudgetExhaustedError as exc:
        # the API names its argument; the command names its option
        raise BudgetExhaustedError(
            str(exc).replace("`max_periods`", "`--max-periods`") + "; raise `--max-periods` "
            "or loosen `--precision`", exc.periods, exc.mean, exc.half_width) from None
    if args.json:
        print(json.dumps(rep))
        return
    print(f"{rep['scene']} at {rep['frequency_Hz']:g} Hz ({rep['scheme']})")
    print(f"  operation mode            {rep['mode']}")
    print(f"  displacement per period   {rep['displacement_per_period_m']:.9e} m")
    print(f"  average velocity          {rep['average_velocity_m_per_s']:.9e} m/s")
    if rep["steady_state"] == "statistical":
        lo, hi = rep["confidence_interval_m"]
        print(f"  statistical steady state  mean over {rep['periods_used']} periods after a "
              f"transient of {rep['transient_periods']}")
        label = f"{100 * rep['confidence_level']:g} % interval"
        print(f"  {label:<26}[{lo:.9e}, {hi:.9e}] m")
        start = rep["start"]
        values = start.get("q_si", start["q"]) + start.get("v_si", start["v"])
        units = start.get("q_units", []) + start.get("v_units", []) or [""] * len(values)
        state = ", ".join(f"{x:.6g} {u}".rstrip() for x, u in zip(values, units))
        print(f"  averaging started         {start['description']}: q, v = {state}")
        if len(rep["starts"]) > 1:
            print(f"  attractors ({len(rep['starts'])} starts)")
            for a in rep["attractors"]:
                alo, ahi = a["confidence_interval_m"]
                print(f"    {a['mean_m']:.6e} m in [{alo:.6e}, {ahi:.6e}] from {a['starts']} "
                      f"start{'s' if a['starts'] > 1 else ''}")
            for k, row in enumerate(rep["starts"]):
                what = (f"{row['mean_m']:.6e} m (attractor {row['attractor'] + 1})"
                        if row["status"] == "converged" else row["status"])
                print(f"    start {k + 1}: {row['start']['description']}: {what}")
        print(f"  why not periodic          {rep['why_not_periodic']}")
    elif not rep["periodic"]:
        print(f"  note                      {rep.get('message', '')}")
    if rep["min_normal_force_N"] is not None:
        print(f"  min normal force          {rep['min_normal_force_N']:.6e} N")
    if rep["periodic_residual"] is not None:
        print(f"  periodic residual         {rep['periodic_residual']:.2e}")
    if rep["period"] > 1:
        print(f"  orbit period              {rep['period']} drive periods")
    if rep["floquet_multipliers"] is not None:
        mult = ", ".join(f"{re:.6g}{im:+.3g}j" if im else f"{re:.6g}"
                         for re, im in rep["floquet_multipliers"])
        print(f"  Floquet multipliers       {mult} ({'stable' if rep['stable'] else 'unstable'}, "
              f"margin {rep['stability_margin']:.3g})")
    if rep["regimes"]:
        print("  regimes (tau start):      " + ", ".join(f"{r}@{t:.4f}" for t, r in rep["regimes"]))
    print(f"  wall time                 {rep['wall_time_s'] * 1e3:.1f} ms")


def _cmd_sweep(args):
    """``moreau sweep``: the scene's own study sweep where its entry names one, else the generic one."""
    entry = get_entry(args.scene)
    if entry.sweep is not None:
        return resolve_hook(entry.sweep)(args)
    if args.num is not None and args.points is not None:
        raise InputError("`--num` is the old name of `--points`; give one of them")
    if args.start is None or args.stop is None:
        raise InputError(f"`START` and `STOP` are required for a sweep of scene {entry.name!r}")
    scale = "log" if args.log else (args.scale or "linear")
    if args.log and args.scale == "linear":
        raise InputError("`--log` contradicts `--scale linear`")
    points = args.points if args.points is not None else args.num
    values = sweep_values(args.start, args.stop, 50 if points is None else points, scale,
                          names=("START", "STOP", "--points"))
    params = scene_parameters(args, entry)
    if args.parameter in params and args.parameter != "frequency":
        raise InputError(f"`{args.parameter}` is swept; do not fix it with `--set` or its option")
    frequency = params.pop("frequency", None)
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol,
                         args.scheme_options)
    run_scene_sweep(entry.name, args.parameter, values, fixed=params, frequency=frequency,
                    scheme=scheme, out=args.out, cache_dir=args.cache, n_jobs=args.jobs,
                    scheduler=args.scheduler, progress=not args.quiet, plot=not args.no_plot,
                    force=args.force, continuation=not args.cold,
                    netcdf=args.netcdf)


def _cmd_characteristic(args):
    """``moreau characteristic``: velocity, power and efficiency against the load, stall located."""
    entry = get_entry(args.scene)
    params = scene_parameters(args, entry)
    if "load" in params:
        raise InputError("`--load` is swept by the characteristic (from no load to beyond "
                         "stall); leave it out")
    frequency = params.pop("frequency", None)
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol,
                         args.scheme_options)
    if args.efficiency_vs_frequency is not None:
        _efficiency_vs_frequency(args, entry, params, frequency, scheme)
        return
    ch = motor_characteristic(entry.name, frequency=frequency, fixed=params, scheme=scheme,
                              points=41 if args.points is None else args.points, out=args.out,
                              plot=not args.no_plot,
                              log=(lambda s: None) if args.json else print)
    s = ch["summary"]
    if args.json:
        print(json.dumps(s))
        return
    print(f"{s['scene']} at {s['frequency_Hz']:g} Hz ({s['scheme']}): load characteristic")
    print(f"  no-load velocity       {s['no_load_velocity_m_per_s']:.9e} m/s "
          f"({s['no_load_direction']})")
    print(f"  stall force            {s['stall_force_N']:.9e} N")
    print(f"  max output power       {s['max_power_W']:.9e} W at load "
          f"{s['load_at_max_power_N']:.9e} N")
    print(f"  load convention        {s['load_convention']}")
    print(f"  beyond stall           {s['reversal']}")
    for key, label in (("stall_located_by", "stall located by"),
                       ("max_power_located_by", "max power located by")):
        if "not refined" in s.get(key, ""):
            print(f"  {label:<23}{s[key]}")
    if s.get("note"):
        print(f"  note                   {s['note']}")


def _efficiency_vs_frequency(args, entry, params, frequency, scheme):
    if frequency is not None:
        raise InputError("`--frequency` and `--efficiency-vs-frequency` exclude each other: "
                         "the frequencies are the latter's values")
    points = 9 if args.points is None else args.points
    d = efficiency_vs_frequency(entry.name, args.efficiency_vs_frequency, fixed=params,
                                scheme=scheme, points=points, out=args.out,
                                plot=not args.no_plot, log=(lambda s: None) if args.json else print)
    if args.json:
        # JSON has no NaN: a value a failed row lacks is null
        rows = [{k: None if isinstance(v, float) and v != v else v for k, v in r.items()}
                for r in d["rows"]]
        print(json.dumps(dict(d, rows=rows), default=str))
    else:
        print(f"{entry.name} ({scheme.name}): efficiency at the load of maximum output power")
        print(f"  {'f [Hz]':>10} {'load [N]':>14} {'P_out [W]':>14} {'P_in [W]':>14} "
              f"{'efficiency':>11}")
        for r in d["rows"]:
            if r["status"] != "ok":
                print(f"  {r['frequency_Hz']:>10g}  {r['status']}")
                continue
            print(f"  {r['frequency_Hz']:>10g} {r['load_at_max_power_N']:>14.6e} "
                  f"{r['max_power_W']:>14.6e} {r['input_power_W']:>14.6e} "
                  f"{r['efficiency']:>11.6f}")
    if not any(r["status"] == "ok" for r in d["rows"]):
        raise MoreauError(f"no frequency has a characteristic: all {len(d['rows'])} failed "
                          f"(first: {d['rows'][0]['status']})")


def _cmd_bifurcation(args):
    """``moreau bifurcation``: section samples of the long-run motion against one parameter."""
    entry = get_entry(args.scene)
    scale = args.scale or ("log" if args.parameter == "frequency" else "linear")
    values = sweep_values(args.start, args.stop, args.points, scale,
                          names=("START", "STOP", "--points"))
    params = scene_parameters(args, entry)
    if args.parameter in params:
        raise InputError(f"`{args.parameter}` is swept; do not fix it with `--set` or its option")
    frequency = params.pop("frequency", None)
    if args.theta is not None:
        args.scheme_options = {**args.scheme_options, "theta": args.theta}
    if args.rtol is not None:
        raise InputError("`--rtol` does not act in `moreau bifurcation`; give a scheme's "
                         "tolerance with `--option rtol=...`")
    d = bifurcation_diagram(entry.name, args.parameter, values, fixed=params,
                            frequency=frequency, scheme=args.scheme,
                            scheme_options=args.scheme_options,
                            steps_per_period=args.steps_per_period, transient=args.transient,
                            samples=args.samples, lyapunov=not args.no_lyapunov,
                            shoot=not args.no_shoot, quantities=args.quantity, out=args.out,
                            progress=not args.quiet, plot=not args.no_plot, force=args.force,
                            log=(lambda s: None) if args.json else print,
                            refine=args.refine)
    if args.json:
        print(json.dumps({"scene": d["scene"], "scheme": d["scheme"],
                          "parameter": d["parameter_column"],
                          "points": [{k: p[k] for k in ("value", "period", "motion",
                                                        "lyapunov_per_period",
                                                        "lyapunov_is_bound", "flight", "start",
                                                        "status")} for p in d["points"]],
                          "marks": d["marks"], "provenance": provenance()}))
        return
    for p in d["points"]:
        print(f"  {p['value']:.6g}: {p['motion'] or p['status']}, Lyapunov "
              f"{'<= ' if p['lyapunov_is_bound'] else ''}{p['lyapunov_per_period']:.3g} a period"
              f"{', flight' if p['flight'] else ''}")
    for m in d["marks"]:
        print(f"  {m['kind']} ({m['from']} -> {m['to']}) between {m['between'][0]:.6g} and "
              f"{m['between'][1]:.6g}")


def _cmd_run(args):
    """``moreau run``: a time history of any registered scene under any registered scheme."""
    check_output_dir(args.out)
    entry = get_entry(args.scene)
    params = scene_parameters(args, entry)
    scene = entry.factory(**params)
    options = dict(args.scheme_options)
    for key in ("theta", "rtol"):
        val = getattr(args, key)
        if val is not None:
            if key in options:
                raise InputError(f"`{key}` is given twice (`--{key}` and `--option {key}=...`)")
            options[key] = val
    periodic = getattr(scene, "period", None) is not None
    periods, duration = args.periods, args.duration
    if periods is not None and duration is not None:
        raise InputError("give one of `--periods` and `--duration`")
    if periods is None and duration is None:
        if not periodic:
            raise InputError(f"`--duration` is required: scene {entry.name!r} has no drive period")
        periods = 10.0
    if args.scheme is None:
        args.scheme, own = default_run(scene)
        options = {**own, **options}
    cls = get_integrator(args.scheme)
    cls = cls.resolve(scene) if hasattr(cls, "resolve") else cls
    stepping = "h" in (scheme_options(cls) or ())
    steps = args.steps
    if args.steps_per_period is not None:
        if steps is not None:
            raise InputError("give one of `--steps` and `--steps-per-period`")
        if periods is None:
            raise InputError("`--steps-per-period` needs `--periods`; with `--duration` give `--steps`")
        steps = int(round(args.steps_per_period * periods))
    if stepping and steps is None and "h" not in options:
        steps = 1000 if periods is None else int(round(1000 * periods))
    check_options(args.scheme, options, scene)
    shown = dict(options)
    if stepping and steps is not None:
        shown["steps"] = steps
    tag = history_tag(entry.name, params, args.scheme, shown)
    run_settings = {"scene": entry.name, "parameters": params, "scheme": args.scheme,
                    "options": shown, "periods": periods, "duration": duration,
                    "samples": args.samples}
    # the files a finished run would replace are checked before the run, not after it
    settings = claim_outputs(os.path.join(args.out, tag), run_settings, args.force)
    # the one run is the whole job: an interrupt ends it with what it had (status -4)
    with propagate_interrupts(False):
        res, cols = run_history(scene, periods=periods, duration=duration, scheme=args.scheme,
                                steps=steps, samples=args.samples,
                                progress=not args.quiet, **options)
    interrupted = res.status == -4
    if interrupted:
        # never under the names of a finished run: the history is marked partial
        tag += ".partial"
    path = os.path.join(args.out, tag + ".csv")
    os.makedirs(args.out, exist_ok=True)
    names = getattr(scene, "coordinate_names", None)
    side = write_history(cols, path, {
        "scene": entry.name, "parameters": params,
        "coordinates": None if names is None else {f"q_{i}": n for i, n in enumerate(names)},
        "scheme": args.scheme, "options": shown,
        "periods": periods, "duration": duration, "status": res.status, "message": res.message,
        "partial": interrupted, "command": "moreau run", "settings": settings})
    if interrupted:
        end = cols[0][2][-1] if len(cols[0][2]) else 0.0
        raise KeyboardInterrupt(f"run: stopped at {cols[0][0]} = {end:.6g} {cols[0][1]}; the "
                                f"partial history ({len(cols[0][2])} samples) is in {path}")
    print(f"wrote {path} and {side} ({len(cols[0][2])} samples); status {res.status}: "
          f"{res.message}")
    if not args.no_plot:
        fig = os.path.join(args.out, tag + ".png")
        plot_history(cols, fig, title=f"{entry.name} ({args.scheme})")
        print(f"wrote {fig}")
    if not res.success:
        raise MoreauError(f"the run stopped early: {res.message}")


def _add_atlas(sub):
    p = sub.add_parser("atlas", help="operation mode and displacement over a parameter plane of "
                                     "any periodic scene (--x, --y); the friction drive's own: "
                                     "the (f, mu) and (f, phi0) planes with the lift-off, "
                                     "Painleve and contact-loss boundaries")
    p.add_argument("--x", nargs=3, metavar=("PARAM", "START", "STOP"), default=None,
                   help="first axis: a parameter of the scene (or frequency) and its range (SI)")
    p.add_argument("--y", nargs=3, metavar=("PARAM", "START", "STOP"), default=None,
                   help="second axis, as --x")
    p.add_argument("--x-points", type=int, default=None, help="values on --x (default 20)")
    p.add_argument("--x-scale", choices=["linear", "log"], default=None,
                   help="spacing on --x (default log for frequency, else linear)")
    p.add_argument("--y-scale", choices=["linear", "log"], default=None,
                   help="spacing on --y (default log for frequency, else linear)")
    p.add_argument("--frequency", type=float, default=None,
                   help="drive frequency [Hz] when neither axis is frequency")
    p.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="fix another parameter of the scene (repeatable)")
    p.add_argument("--plane", choices=["both", "f-mu", "f-phi0"], default=None,
                   help="friction drive's own atlas: the plane (default both)")
    p.add_argument("--f-points", type=int, default=None,
                   help="friction drive's own atlas: frequencies (default 200, log-spaced)")
    p.add_argument("--y-points", type=int, default=None,
                   help="values on --y (default 20), or mu or phi0 values of the friction "
                        "drive's own atlas (default 100)")
    p.add_argument("--fmin", type=float, default=None,
                   help="friction drive's own atlas: lowest frequency [Hz] (default 10)")
    p.add_argument("--fmax", type=float, default=None,
                   help="friction drive's own atlas: highest frequency [Hz] (default 12500)")
    p.add_argument("--quick", action="store_true", help="a coarse grid (24 x 12 per plane; "
                                                        "8 x 6 with --x/--y)")
    _add_points_options(p, "atlas", "the figures",
                        "also write each table as NetCDF (.nc next to the CSV, on the plane's "
                        "grid, units as attributes; needs pip install -e \".[data]\")")
    p.add_argument("--classify-periods", type=int, default=None, metavar="N",
                   help="budget of the plain run that names the motion of a point without a "
                        "periodic orbit (period-k, non-periodic with its mean, runaway); "
                        "0: none (default %d)" % CLASSIFY_PERIODS)
    _scene_command(p, _cmd_atlas, with_set=False)


#: options of a scene's own atlas that the generic one (--x, --y) does not take
_OWN_ATLAS_OPTIONS = ("plane", "f_points", "fmin", "fmax")


def _cmd_atlas(args):
    """``moreau atlas``: the scene's own atlas where its entry names one, else the generic one."""
    entry = get_entry(args.scene)
    if args.x is None and args.y is None:
        if entry.atlas is None:
            raise InputError(f"scene {entry.name!r} has no atlas of its own: give the plane as "
                             "`--x PARAM START STOP --y PARAM START STOP`")
        for key in ("x_points", "x_scale", "y_scale", "frequency"):
            if getattr(args, key) is not None:
                raise InputError(f"`--{key.replace('_', '-')}` applies with `--x` and `--y`")
        return resolve_hook(entry.atlas)(args)
    if args.x is None or args.y is None:
        raise InputError("give both axes: `--x PARAM START STOP` and `--y PARAM START STOP`")
    for key in _OWN_ATLAS_OPTIONS:
        if getattr(args, key) is not None:
            raise InputError(f"`--{key.replace('_', '-')}` belongs to a scene's own atlas; with "
                             "`--x` and `--y` give the ranges there")
    axes = []
    for flag, (name, start, stop), points, scale in (
            ("--x", args.x, args.x_points, args.x_scale),
            ("--y", args.y, args.y_points, args.y_scale)):
        try:
            start, stop = float(start), float(stop)
        except ValueError:
            raise InputError(f"`{flag}` takes PARAM START STOP with numbers, got "
                             f"{start!r} {stop!r}") from None
        if args.quick and points is not None:
            raise InputError("`--quick` sets the grid; leave out `--x-points`/`--y-points`")
        n = (8 if flag == "--x" else 6) if args.quick else (20 if points is None else points)
        scale = scale or ("log" if name == "frequency" else "linear")
        names = (f"{flag} START", f"{flag} STOP", f"{flag}-points")
        axes.append((name, sweep_values(start, stop, n, scale, names=names)))
    params = scene_parameters(args, entry)
    frequency = params.pop("frequency", None)
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol,
                         args.scheme_options)
    run_scene_atlas(entry.name, axes[0], axes[1], fixed=params, frequency=frequency,
                    scheme=scheme, out=args.out, cache_dir=args.cache, n_jobs=args.jobs,
                    scheduler=args.scheduler, progress=not args.quiet, plot=not args.no_plot,
                    force=args.force, continuation=not args.cold,
                    classify=classify_budget(args), netcdf=args.netcdf)


# -- moreau reproduce ---------------------------------------------------------------

def _cmd_reproduce(args):
    res = reproduce(args.out, quick=args.quick, scheduler=args.scheduler, n_jobs=args.jobs,
                    progress=not args.quiet, force=args.force)
    print(f"wrote {len(res['_paths'])} files to {args.out} in {res['_wall_time_s']:.1f} s; "
          f"start with {args.out}/report.md")
    print("  " + ", ".join(f"{k[:-2].replace('_', ' ')} {v:.1f} s" for k, v in res["_timings"].items()))


def _add_pool_options(p):
    """The worker pool's options, shared by every command that runs many points."""
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the points on this Dask scheduler (e.g. tcp://host:8786)")
    p.add_argument("--jobs", type=int, default=-1,
                   help="local worker processes (default -1: all cores)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _add_output_options(p, what, out=True):
    """The output folder, progress bar, figure and overwrite options of a command whose files
    are ``what`` (a run, a comparison)."""
    if out:
        p.add_argument("--out", default="out", help="output folder (default ./out)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--no-plot", action="store_true", help="skip the figure")
    p.add_argument("--force", action="store_true",
                   help=f"replace the files of an earlier {what} with other settings (refused "
                        "otherwise)")


def _add_points_options(p, what, figures, netcdf_help):
    """Output, cache, pool and start options of a command that runs a grid of points
    (an atlas, a sweep): ``what`` names its output, ``figures`` what --no-plot skips."""
    p.add_argument("--out", default="out", help="output folder (default ./out)")
    p.add_argument("--cache", default=None, help="cache folder (default OUT/cache)")
    _add_pool_options(p)
    p.add_argument("--no-plot", action="store_true", help=f"skip {figures}")
    p.add_argument("--netcdf", action="store_true", help=netcdf_help)
    p.add_argument("--force", action="store_true",
                   help=f"replace the files of an earlier {what} with other settings (refused "
                        "otherwise)")
    p.add_argument("--cold", action="store_true",
                   help="start every point's shooting from rest (default: from its "
                        "neighbour's orbit, with a cold start where that fails)")


def _add_reproduce(sub):
    p = sub.add_parser("reproduce", help="the paper's section 4.3: data, figures and report.md")
    p.add_argument("--out", default="moreau-results",
                   help="output folder (default ./moreau-results); the cache lives in OUT/cache")
    p.add_argument("--quick", action="store_true", help="coarse grids: a smoke run of a few seconds")
    _add_pool_options(p)
    p.add_argument("--force", action="store_true",
                   help="replace the files of an earlier run with other settings (--quick "
                        "against a full run; refused otherwise)")
    p.set_defaults(func=_cmd_reproduce)


def _cmd_compare(args):
    """``moreau compare``: work-precision of every scheme on one scene, or the stress map."""

    out = cmp.check_out_dir(args.out)
    progress = not args.quiet
    if args.stress:
        # with --stress, --schemes names the map's columns (keys of stress.SCHEMES)
        cols = None if args.schemes in (None, "all") else args.schemes.split(",")
        settings = claim_outputs(os.path.join(out, "stress"),
                                 {"stress": True, "quick": bool(args.quick), "schemes": cols},
                                 args.force)
        # every cell is kept in OUT/cache as it finishes: the same command resumes
        cache = os.path.join(out, "cache")
        report = run_catalogue(progress=progress, full=not args.quick, schemes=cols,
                               cache_dir=cache)
        cells = report["cells"]
        if report["interrupted"]:
            # no table that would claim to be the whole catalogue
            raise Interrupted(cells["cached"] + cells["computed"], cells["total"], cache,
                              "stress catalogue", unit="cells")
        report["settings"] = settings
        paths = write_stress_outputs(report, out, plot=not args.no_plot)
        if args.json:
            print(json.dumps(report))
        else:
            print(format_stress_table(report))
            print(f"({cells['total']} cells: {cells['computed']} computed, {cells['cached']} "
                  f"from the cache)")
            print("wrote " + ", ".join(p for p in paths.values() if p))
        return
    if args.scene is None:
        raise InputError("`--scene` is required (one of " + ", ".join(scene_names()) +
                         "), or give `--stress`")
    params = parse_settings(list(args.param or []) + list(args.set or []), "--set")
    for key in shorthands():
        if getattr(args, key, None) is not None:
            if key in params:
                raise InputError(f"`{key}` is given twice (`--{key}` and `--set {key}=...`)")
            params[key] = getattr(args, key)
    tag = f"compare_{args.scene}" + (f"_{params['frequency']:g}Hz" if "frequency" in params else "")
    partial = []

    def keep(row):
        partial.append(row)

    schemes = [x.strip() for x in args.schemes.split(",") if x.strip()] if args.schemes else None
    # a bad parameter is named before a clash of file names is
    cmp.make_case(args.scene, **params)
    # a quick and a full comparison (or two with other settings) share file names
    settings = claim_outputs(os.path.join(out, tag),
                             {"scene": args.scene, "parameters": params,
                              "quick": bool(args.quick), "schemes": schemes}, args.force)
    report = cmp.compare(args.scene, quick=args.quick, progress=progress, on_row=keep,
                         schemes=schemes, **params)
    report["settings"] = settings
    if report["interrupted"]:
        # the finished rows, never under the names of a finished comparison; no figure
        report["partial"] = True
        paths = cmp.write_outputs(report, out, tag=tag + ".partial", plot=False)
        n = len(report["rows"])
        raise KeyboardInterrupt(f"compare: {n} row{'' if n == 1 else 's'} finished, kept in "
                                f"{paths['csv']}")
    paths = cmp.write_outputs(report, out, tag=tag, plot=not args.no_plot)
    if args.json:
        print(json.dumps(report))
    else:
        print(cmp.format_table(report))
        print("wrote " + ", ".join(p for p in paths.values() if p))


def parse_settings(items, option):
    """``{name: value}`` from ``NAME=VALUE`` strings: numbers as floats, anything else as text."""
    out = {}
    for item in items:
        key, sep, val = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InputError(f"`{option}` takes NAME=VALUE, got {item!r}")
        if key in out:
            raise InputError(f"`{key}` is given twice in `{option}`")
        try:
            out[key] = float(val)
        except ValueError:
            out[key] = val.strip()
    return out


def _cmd_scenes(args):
    """``moreau scenes``: every registered scene with its parameters."""
    described = [describe(e) for e in entries()]
    if args.json:
        print(json.dumps(described))
        return
    for d in described:
        print(f"{d['name']}: {d['description']}")
        for p in d["parameters"]:
            unit = f" [{p['unit']}]" if p["unit"] and p["unit"] != "choice" else ""
            print(f"    {p['name']}{unit} = {p['default']!r}" + (f"  ({p['doc']})" if p["doc"] else ""))
        if d["compare"]:
            print("    compare case also takes: " + ", ".join(d["compare"]))


def build_parser():
    parser = argparse.ArgumentParser(prog="moreau", description=__doc__.splitlines()[0])
    parser.add_argument("-V", "--version", action="version", version=f"moreau {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="show notes (a compile starting) on stderr also when it is not a "
                             "terminal, e.g. in a log file")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("steady", help="periodic steady state of a driven scene (a statistical "
                                        "one, mean with interval, where no orbit exists)")
    p.add_argument("--frequency", type=float, default=None,
                   help="drive frequency [Hz] (default: the scene's)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    _add_params(p, scheme_defaults=False)
    p.add_argument("--max-period", type=int, default=1,
                   help="where the period-1 orbit fails or is unstable, look for a stable "
                        "period-k orbit, k <= MAX_PERIOD (at most 8; default 1)")
    p.add_argument("--max-periods", type=int, default=STEADY_MAX_PERIODS,
                   help="where there is no orbit, the statistical steady state's budget of "
                        f"drive periods, of each start (default {STEADY_MAX_PERIODS})")
    p.add_argument("--precision", type=float, default=PRECISION,
                   help="its wanted interval half-width relative to the mean (default "
                        f"{PRECISION:g})")
    p.add_argument("--starts", type=int, default=1,
                   help="its number of starts: the first, then rest with the rotor at "
                        "fractions up to 1 of the tip's speed amplitude; the means are "
                        "grouped into attractors (default 1)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_scene_options(p)
    p.set_defaults(func=_cmd_steady)
    s = sub.add_parser("sweep", help="steady states over one parameter range (tidy CSV + figure), "
                                      "cached and in parallel")
    s.add_argument("parameter", metavar="PARAM",
                   help="parameter to sweep: frequency [Hz] or a parameter of the scene (SI "
                        "units; `moreau scenes` lists them)")
    s.add_argument("start", metavar="START", type=float, nargs="?", default=None,
                   help="first value (the friction drive has defaults for frequency, mu, phi0)")
    s.add_argument("stop", metavar="STOP", type=float, nargs="?", default=None, help="last value")
    s.add_argument("--points", type=int, default=None, help="number of values")
    s.add_argument("--num", type=int, default=None, help=argparse.SUPPRESS)  # old name of --points
    s.add_argument("--scale", choices=["log", "linear"], default=None,
                   help="spacing of the values (default log for frequency, else linear)")
    s.add_argument("--log", action="store_true", help=argparse.SUPPRESS)  # old form of --scale log
    s.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="fix another parameter (repeatable), e.g. --set mu=0.3 --set frequency=185")
    s.add_argument("--frequency", type=float, default=None,
                   help="drive frequency [Hz] when PARAM is not frequency")
    _add_points_options(s, "run", "the figure",
                        "also write the table as NetCDF (.nc next to the CSV: the swept parameter "
                        "as coordinate, units as attributes; needs pip install -e \".[data]\")")
    _scene_command(s, _cmd_sweep, with_set=False)
    r = sub.add_parser("run", help="time history of any scene under any scheme, from its initial "
                                    "state (CSV with units, JSON sidecar, figure)")
    r.add_argument("--frequency", type=float, default=None, help="drive frequency [Hz]")
    r.add_argument("--periods", type=float, default=None,
                   help="drive periods to simulate (default 10 for a driven scene)")
    r.add_argument("--duration", type=float, default=None,
                   help="time to simulate [s] (or the scene's time unit if it has no SI units)")
    r.add_argument("--steps", type=int, default=None,
                   help="time-stepping schemes: steps over the whole run (default 1000 per "
                        "drive period, or 1000 over a `--duration` run)")
    r.add_argument("--samples", type=int, default=2000,
                   help="samples written, evenly spaced in time (default 2000)")
    _add_output_options(r, "run")
    _scene_command(r, _cmd_run)
    # a spatial scene is refused by the event-driven reference: the scheme follows the scene
    scheme_flag = r._option_string_actions["--scheme"]
    scheme_flag.default = None
    scheme_flag.help = ("any registered scheme (default: event-driven where it takes the scene, "
                        "else moreau-jean)")
    b = sub.add_parser("bifurcation", help="stroboscopic section of the long-run motion against "
                                          "one parameter, period, Lyapunov exponent and "
                                          "bifurcation marks (CSV, JSON sidecar, figure)")
    b.add_argument("parameter", metavar="PARAM",
                   help="parameter to sweep: frequency [Hz] or a parameter of the scene")
    b.add_argument("start", metavar="START", type=float, help="first value")
    b.add_argument("stop", metavar="STOP", type=float, help="last value")
    b.add_argument("--points", type=int, default=40, help="number of values (default 40)")
    b.add_argument("--scale", choices=["log", "linear"], default=None,
                   help="spacing of the values (default log for frequency, else linear)")
    b.add_argument("--frequency", type=float, default=None,
                   help="drive frequency [Hz] when PARAM is not frequency")
    b.add_argument("--transient", type=int, default=200,
                   help="periods run before sampling (default 200; fewer from a shot orbit)")
    b.add_argument("--samples", type=int, default=50, help="periods sampled (default 50)")
    b.add_argument("--quantity", action="append", metavar="COLUMN",
                   help="section column drawn (repeatable; default displacement_per_period, q_0)")
    b.add_argument("--no-lyapunov", action="store_true", help="skip the Lyapunov exponent")
    b.add_argument("--refine", action="store_true",
                   help="locate every mark between its neighbours by root finding on the "
                        "period-1 orbit (up to 40 more shootings a mark)")
    b.add_argument("--no-shoot", action="store_true",
                   help="do not start from a shot periodic orbit (only the transient)")
    b.add_argument("--json", action="store_true", help="print one JSON object")
    _add_output_options(b, "run")
    _scene_command(b, _cmd_bifurcation)
    ch = sub.add_parser("characteristic", help="the motor's load characteristic: no-load "
                                               "velocity, stall force, maximum output power "
                                               "(CSV, JSON sidecar, figure)")
    ch.add_argument("--frequency", type=float, default=None,
                    help="drive frequency [Hz] (default: the scene's)")
    ch.add_argument("--points", type=int, default=None,
                    help="loads from no load to 1.25 times the stall force (default 41; 9 with "
                         "--efficiency-vs-frequency, where Brent's method refines the maximum)")
    ch.add_argument("--efficiency-vs-frequency", type=float, nargs="+", default=None,
                    metavar="F",
                    help="instead of one characteristic: the efficiency at the load of maximum "
                         "output power at each of these frequencies [Hz] (CSV, JSON, figure)")
    ch.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    ch.add_argument("--out", default="out", help="output folder (default ./out)")
    ch.add_argument("--no-plot", action="store_true", help="skip the figure")
    _scene_command(ch, _cmd_characteristic)
    _add_reproduce(sub)
    _add_atlas(sub)
    sc = sub.add_parser("scenes", help="the registered scenes, their parameters and units")
    sc.add_argument("--json", action="store_true", help="print a JSON list")
    sc.set_defaults(func=_cmd_scenes)
    c = sub.add_parser("compare", help="error against run time of every scheme on one scene "
                                       "(table + figure), or the stiff/extreme-case map (--stress)")
    c.add_argument("--scene", default=None, metavar="NAME",
                   help="a registered scene (`moreau scenes` lists them)")
    c.add_argument("--frequency", type=float, default=None, help="drive frequency [Hz]")
    add_scene_flags(c)
    c.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="any parameter of the scene or of its comparison case (repeatable)")
    c.add_argument("--param", action="append", metavar="KEY=VALUE", help=argparse.SUPPRESS)
    c.add_argument("--stress", action="store_true",
                   help="run the stiff and extreme case catalogue instead (stability map)")
    c.add_argument("--schemes", default=None, metavar="NAME,...",
                   help="other registered schemes to compare too, e.g. compliant-radau,schatzman-paoli, "
                        "or all; with --stress, the map's columns (e.g. event-driven,mj-1/2,"
                        "schatzman-paoli; all by default)")
    c.add_argument("--quick", action="store_true", help="fewer points, one timing per run")
    c.add_argument("--out", default="out", help="output folder (default ./out)")
    c.add_argument("--json", action="store_true", help="print one JSON object")
    _add_output_options(c, "comparison", out=False)
    c.set_defaults(func=_cmd_compare)
    add_suite_commands(sub)     # moreau suite, moreau animate
    return parser


def _check_common(args):
    # the options several commands share, checked before any of them starts work
    if getattr(args, "jobs", None) is not None:
        check_jobs(args.jobs, 1)
    check_scheduler(getattr(args, "scheduler", None))
    if getattr(args, "cache", None) is not None:
        check_output_dir(args.cache, "--cache")
    if getattr(args, "netcdf", False):
        try:
            require_xarray("`--netcdf`")
        except ImportError as exc:
            raise InputError(str(exc)) from None
    if hasattr(args, "option"):
        # `--option NAME=VALUE` of the scheme, parsed once for every command (and study hook),
        # and the options' own flags
        args.scheme_options = parse_settings(args.option or [], "--option")
        for key in scheme_option_flags():
            val = getattr(args, "scheme_opt_" + key, None)
            if val is not None:
                if key in args.scheme_options:
                    raise InputError(f"`{key}` is given twice (`{_flag(key)}` and "
                                     f"`--option {key}=...`)")
                args.scheme_options[key] = val


def _stop_on_sigterm():
    """Make SIGTERM (``kill PID``, ``timeout``, a batch system's time limit) stop a command as
    Ctrl-C does: workers ended, the finished points kept, one line. Returns the handlers to
    restore and the record of the signal."""
    seen = {"signal": None}
    if threading.current_thread() is not threading.main_thread():
        return {}, seen  # handlers can be set in the main thread only

    def stop(signum, frame):
        seen["signal"] = signum
        raise KeyboardInterrupt

    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, stop)}
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        # Ctrl-C as before, but recorded: an error it causes where an interrupt cannot pass
        # (inside numba's compiler) is still the interruption (an ignored SIGINT stays so)
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, stop)
    default_hook = sys.unraisablehook

    def swallowed(unraisable):
        # an interrupt raised inside a ctypes callback (numba's LLVM object cache, while it
        # compiles) is printed and dropped by CPython, and the command would run on: send
        # the signal again, for the main thread to take once it is out of the callback
        if seen["signal"] is not None and isinstance(unraisable.exc_value, KeyboardInterrupt):
            if seen["resend"] is None:
                seen["resend"] = threading.Timer(0.05, os.kill, (os.getpid(), seen["signal"]))
                seen["resend"].daemon = True
                seen["resend"].start()
            return
        default_hook(unraisable)

    seen["resend"] = None
    sys.unraisablehook = swallowed
    previous["unraisablehook"] = default_hook
    return previous, seen


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    configure_cli(args.verbose)
    previous, seen = _stop_on_sigterm()
    try:
        try:
            _check_common(args)
            # a command is one job: an interrupt inside any of its runs stops it, not only
            # the run
            with propagate_interrupts():
                args.func(args)
        except Exception as exc:
            if seen["signal"] is not None:
                # numba's compiler, interrupted, fails with its own error: it is the signal's
                raise KeyboardInterrupt from exc
            raise
    except InputError as exc:
        print(f"moreau: error: {exc}", file=sys.stderr)
        return 2
    except MoreauError as exc:
        print(f"moreau: failed: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:
        # 128 + the signal, as a shell reports a command stopped by it
        how, status = (("terminated (SIGTERM)", 128 + signal.SIGTERM)
                       if seen["signal"] == signal.SIGTERM else ("interrupted", 130))
        if isinstance(exc, Interrupted):
            resume = "; run the same command again to resume" if exc.cache_dir is not None else ""
            print(f"\nmoreau: {how}: {exc}{resume}", file=sys.stderr)
        elif str(exc):
            # what the command kept (a partial history, the finished points)
            print(f"\nmoreau: {how}: {exc}", file=sys.stderr)
        else:
            print(f"\nmoreau: {how}", file=sys.stderr)
        return status
    finally:
        if seen.get("resend") is not None:
            # the command has stopped: a signal sent again now would land in the shutdown
            seen["resend"].cancel()
        for signum, handler in previous.items():
            if signum == "unraisablehook":
                sys.unraisablehook = handler
            else:
                signal.signal(signum, handler)
    return 0


if __name__ == "__main__":
    sys.exit(main())
