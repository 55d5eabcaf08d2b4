"""``moreau steady`` and ``moreau sweep`` with ``--scene bidirectional``: the two-rod drive.

Kept apart from :mod:`moreau.cli` so that the shared CLI module only gains
the hooks. The rod, spring, rotor, friction, load and restitution options
are those of the single-rod drive and apply to both rods; ``--x10-a``,
``--x10-b`` and ``--phase`` set the two stators (``--x10`` sets both).
"""

import json
import time

from .errors import InputError

__all__ = ["add_scene_options", "bidirectional_report", "cmd_steady_bidirectional",
           "cmd_sweep_bidirectional"]


def add_scene_options(p):
    """The ``--scene`` switch and the two-stator options of ``moreau steady``."""
    p.add_argument("--scene", default="friction-drive", choices=["friction-drive", "bidirectional"],
                   help="the paper's single-rod drive (default) or the two-rod bidirectional drive")
    p.add_argument("--x10-a", dest="x10_a", type=float, default=None,
                   help="bidirectional: stator amplitude of rod a [m] (default --x10 or 2e-6)")
    p.add_argument("--x10-b", dest="x10_b", type=float, default=None,
                   help="bidirectional: stator amplitude of rod b [m] (default --x10 or 2e-6)")
    p.add_argument("--phase", type=float, default=None,
                   help="bidirectional: phase lag of stator b [rad] (default 0)")


def _params(args):
    from .scenes.bidirectional_drive import params_from_kwargs
    x10 = args.x10
    return params_from_kwargs(
        mu=args.mu, phi0=args.phi0, k=args.k, m=args.m, m2=args.m2, length=args.length,
        load=args.load, restitution=args.restitution, phase=args.phase,
        x10_a=args.x10_a if args.x10_a is not None else x10,
        x10_b=args.x10_b if args.x10_b is not None else x10)


def bidirectional_report(params, frequency, scheme="event-driven", steps_per_period=2000,
                         theta=0.5, rtol=1e-10):
    """Steady state of the bidirectional drive as a JSON-ready dict in SI units.

    Moreau–Jean runs with projection onto closed contacts.

    Examples
    --------
    >>> from moreau.scenes.bidirectional_drive import BidirectionalDriveParams
    >>> r = bidirectional_report(BidirectionalDriveParams(x10_b=0.0), 2000.0)
    >>> r["mode"], round(r["average_velocity_m_per_s"] * 1e3, 3)   # rod a alone: forward
    ('NP|F', 3.689)
    """
    from . import integrators  # noqa: F401  (load the schemes before the clock starts)
    from .analysis.steady_state import find_steady_state
    from .scenes.bidirectional_drive import BidirectionalDrive

    scene = BidirectionalDrive(params, frequency)
    t0 = time.perf_counter()
    if scheme == "moreau-jean":
        ss = find_steady_state(scene, scheme, steps_per_period=steps_per_period, theta=theta,
                               projection=True, **({} if rtol is None else {"tol": rtol}))
    else:
        ss = find_steady_state(scene, scheme, rtol=rtol)
    wall = time.perf_counter() - t0
    disp = scene.displacement_to_si(ss.displacement_per_period)
    out = {
        "scene": "bidirectional",
        "frequency_Hz": scene.frequency,
        "scheme": ss.scheme,
        "mode": ss.mode,
        "displacement_per_period_m": disp,
        "average_velocity_m_per_s": disp * scene.frequency,
        "regimes": [[float(t), r] for t, r in ss.regimes],
        "min_normal_force_N": scene.force_to_si(ss.min_normal_force),
        "periodic_residual": ss.periodic_residual,
        "shooting_iterations": ss.iterations,
        "wall_time_s": wall,
        "parameters": {k: getattr(params, k) for k in
                       ("m", "m2", "k", "length", "phi0", "mu", "x10_a", "x10_b", "phase",
                        "load", "restitution")},
    }
    if scheme == "moreau-jean":
        out["steps_per_period"] = steps_per_period
        out["theta"] = theta
    return out


def cmd_steady_bidirectional(args):
    if args.frequency is None:
        raise InputError("`--frequency` is required (drive frequency in Hz)")
    rep = bidirectional_report(_params(args), args.frequency, scheme=args.scheme,
                               steps_per_period=args.steps_per_period, theta=args.theta,
                               rtol=args.rtol)
    if args.json:
        print(json.dumps(rep))
        return
    p = rep["parameters"]
    print(f"bidirectional drive at {rep['frequency_Hz']:g} Hz ({rep['scheme']}): "
          f"x10_a = {p['x10_a']:g} m, x10_b = {p['x10_b']:g} m, phase = {p['phase']:g} rad")
    print(f"  operation mode (a|b)      {rep['mode']}")
    print(f"  displacement per period   {rep['displacement_per_period_m']:.9e} m")
    print(f"  average rotor velocity    {rep['average_velocity_m_per_s']:.9e} m/s")
    print(f"  min normal force          {rep['min_normal_force_N']:.6e} N")
    print(f"  periodic residual         {rep['periodic_residual']:.2e}")
    print(f"  wall time                 {rep['wall_time_s']:.2f} s")


def cmd_sweep_bidirectional(args):
    """``moreau sweep --scene bidirectional PARAM START STOP ...``; every option is checked first."""
    from .studies.bidirectional.bidirectional_sweep import BIDIRECTIONAL_SWEEPABLE, run_bidirectional_sweep
    from .studies.paper.sweeps import make_scheme

    param = args.parameter
    if param not in BIDIRECTIONAL_SWEEPABLE:
        raise InputError(f"`PARAM` must be one of {list(BIDIRECTIONAL_SWEEPABLE)} for "
                         f"`--scene bidirectional`, got {param!r} (`x10` sets both rods: "
                         "sweep `x10_a`, `x10_b` or `balance`)")
    settable = [p for p in BIDIRECTIONAL_SWEEPABLE if p != "balance"] + ["x10"]
    settings = {}
    for item in args.set or []:
        key, sep, val = item.partition("=")
        key = key.strip()
        if not sep or key not in settable:
            raise InputError(f"`--set` takes NAME=VALUE with NAME one of {settable}, got {item!r}")
        try:
            settings[key] = float(val)
        except ValueError:
            raise InputError(f"`--set {key}` must be a number, got {val.strip()!r}") from None
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
    for key, val in settings.items():
        if getattr(args, key, None) is not None:
            raise InputError(f"`{key}` is given twice (`--{key.replace('_', '-')}` and "
                             f"`--set {key}=...`)")
        setattr(args, key, val)
    params = _params(args)
    scheme = make_scheme(args.scheme, args.theta, args.steps_per_period, args.rtol)
    if args.num is not None and args.points is not None:
        raise InputError("`--num` is the old name of `--points`; give one of them")
    scale = args.scale or "linear"
    if args.log:
        if args.scale == "linear":
            raise InputError("`--log` contradicts `--scale linear`")
        scale = "log"
    run_bidirectional_sweep(param, params, frequency=frequency, start=args.start, stop=args.stop,
                            points=args.points if args.points is not None else args.num,
                            scale=scale, scheme=scheme, out=args.out, cache_dir=args.cache,
                            n_jobs=args.jobs, scheduler=args.scheduler, progress=not args.quiet,
                            plot=not args.no_plot)
