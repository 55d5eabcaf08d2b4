"""``moreau sweep --scene bidirectional-drive``: the two-rod drive's sweep (``--scene`` for steady too).

Kept apart from :mod:`moreau.cli` so that the shared CLI module only gains
the hooks. The rod, spring, rotor, friction, load and restitution options
are those of the single-rod drive and apply to both rods; ``--x10-a``,
``--x10-b`` and ``--phase`` set the two stators (``--x10`` sets both).
"""


from .errors import InputError
from .scenes.bidirectional_drive import params_from_kwargs
from .studies.bidirectional.bidirectional_sweep import BIDIRECTIONAL_SWEEPABLE, run_bidirectional_sweep
from .studies.paper.sweeps import make_scheme

__all__ = ["add_scene_options", "cmd_sweep_bidirectional"]


def add_scene_options(p, with_set=True):
    """The ``--scene`` switch and the two-stator options of ``moreau steady``."""
    p.add_argument("--scene", default="friction-drive", metavar="NAME",
                   help="a registered periodically driven scene (`moreau scenes`; default "
                        "friction-drive)")
    if with_set:
        p.add_argument("--set", action="append", metavar="NAME=VALUE",
                       help="any parameter of the scene (repeatable), e.g. --set mu=0.3")
    p.add_argument("--x10-a", dest="x10_a", type=float, default=None,
                   help="bidirectional: stator amplitude of rod a [m] (default --x10 or 2e-6)")
    p.add_argument("--x10-b", dest="x10_b", type=float, default=None,
                   help="bidirectional: stator amplitude of rod b [m] (default --x10 or 2e-6)")
    p.add_argument("--phase", type=float, default=None,
                   help="bidirectional: phase lag of stator b [rad] (default 0)")


def _params(args):
    x10 = args.x10
    return params_from_kwargs(
        mu=args.mu, phi0=args.phi0, k=args.k, m=args.m, m2=args.m2, length=args.length,
        load=args.load, restitution=args.restitution, phase=args.phase,
        x10_a=args.x10_a if args.x10_a is not None else x10,
        x10_b=args.x10_b if args.x10_b is not None else x10)


def cmd_sweep_bidirectional(args):
    """``moreau sweep --scene bidirectional PARAM START STOP ...``; every option is checked first."""

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
