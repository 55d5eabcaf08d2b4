"""The command lines ``moreau suite`` and ``moreau animate`` (registered by :func:`add_commands`)."""

import os
import time

from ..analysis.engine import check_jobs, check_output_dir
from ..analysis.regression import calibration_time
from ..errors import InputError
from ..outputs import claim_outputs
from .animate import animate_run
from .history import compare_to_history, load_history, record_run
from .problem import problem_names
from .report import animation_tasks, format_overview, write_report
from .run import cell_task, instance, run_suite, settings_of

__all__ = ["add_commands"]


def _names(text, option):
    if isinstance(text, list):
        # names given space-separated, comma-separated or both
        text = ",".join(text)
    if text is None or text.strip() in ("", "all"):
        return None
    names = [x.strip() for x in text.split(",") if x.strip()]
    if len(set(names)) != len(names):
        raise InputError(f"`{option}` names one twice: {text!r}")
    return names


def _cmd_suite(args):
    """``moreau suite``: every registered scheme on every problem of the suite."""

    out = check_output_dir(args.out)
    hist = None
    if args.compare_to is not None:
        hist = load_history(args.compare_to)       # a bad history is refused before any work
    problems = _names(args.problems, "--problems")
    schemes = _names(args.schemes, "--schemes")
    settings = claim_outputs(out / "suite", {"quick": bool(args.quick), "problems": problems,
                                             "schemes": schemes,
                                             "peers": not args.no_peers}, args.force)
    t0 = time.perf_counter()
    n_jobs = None if args.jobs is None and args.quick else check_jobs(_jobs(args), 2)
    # the animations are tasks of the cells' pool, not of a second one after the last cell
    tasks = [] if args.no_plot else animation_tasks(problems or problem_names(), str(out))
    report = run_suite(problems=problems, schemes=schemes, quick=args.quick,
                       cache_dir=os.path.join(out, "cells"), progress=not args.quiet,
                       n_jobs=n_jobs, scheduler=args.scheduler,
                       peers=not args.no_peers, tasks=tasks)
    report["wall_time_s"] = time.perf_counter() - t0
    if hist is not None:

        calibration = calibration_time()
        report["flags"] = compare_to_history(
            report["rows"], hist, calibration=calibration,
            rerun=lambda r: cell_task(r["problem"], r["scheme"], r["setting"],
                                      _options(r, args.quick)))
        record_run(args.compare_to, hist, report["rows"], calibration, args.quick)
    paths = write_report(report, out, settings=settings, plot=not args.no_plot,
                         n_jobs=report["jobs"] if args.scheduler is None else 1,
                         animations=report["tasks"])
    cells = report["cells"]
    if hist is not None:
        flags = report["flags"]
        print(f"{len(flags)} flag(s) against {args.compare_to}" + (":" if flags else ""))
        for f in flags:
            print(f"  FLAG {f['kind']}: {f['text']}")
    print(format_overview(report["rows"], report["schemes"]))
    print(f"({cells['total']} cells: {cells['computed']} computed, {cells['cached']} from "
          f"{os.path.join(out, 'cells')}; {report['wall_time_s']:.1f} s)")
    print(f"wrote {len(paths)} files; start with {paths['page']}")


def _jobs(args):
    # the full suite keeps its cells' CPU times clean, one at a time, unless told otherwise;
    # the quick one (None) takes every core when it has cells enough (run_suite)
    return 1 if args.jobs is None else args.jobs


def _options(row, quick):

    prob, scene, _ = instance(row["problem"])
    return dict(settings_of(row["scheme"], prob, scene, quick))[row["setting"]]


def _cmd_animate(args):

    path, frames = animate_run(args.run, args.out, fps=args.fps, max_frames=args.frames,
                               force=args.force)
    print(f"wrote {path} ({frames} frames)")


def add_commands(sub):
    """Add ``suite`` and ``animate`` to the subcommands ``sub`` of ``moreau``'s parser."""
    s = sub.add_parser("suite", help="the benchmark suite: every registered scheme on every "
                                     "problem with a reference (table, figures, index.md)")
    s.add_argument("--quick", action="store_true",
                   help="two settings per scheme instead of three (a few minutes)")
    s.add_argument("--schemes", default=None, nargs="+", metavar="NAME,...",
                   help="registered schemes to run (default: all)")
    s.add_argument("--problems", default=None, nargs="+", metavar="NAME,...",
                   help="problems to run (default: all)")
    s.add_argument("--out", default="suite-results",
                   help="output folder (default ./suite-results); finished cells are kept in "
                        "OUT/cells and a rerun resumes from them")
    s.add_argument("--force", action="store_true",
                   help="replace the files of an earlier suite run with other settings")
    s.add_argument("--compare-to", default=None, metavar="HISTORY",
                   help="flag the cells that regressed against the history file HISTORY "
                        "(outcome changed, error grown above the tolerance, time over 1.5x "
                        "this machine's median, rerun first), then record this run in it "
                        "(created if missing; benchmarks/baselines.json's format)")
    s.add_argument("--no-peers", action="store_true",
                   help="leave out Siconos's OSIs (columns by default where Siconos is "
                        "installed, /usr/bin/python3)")
    s.add_argument("--jobs", type=int, default=None,
                   help="local worker processes, as for `moreau sweep` (-1: one per core; "
                        "default: one per core with --quick, else 1: the cells' CPU times "
                        "are cleanest one at a time)")
    s.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the cells on this Dask scheduler (e.g. tcp://host:8786)")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--no-plot", action="store_true", help="skip the figures")
    s.set_defaults(func=_cmd_suite)
    a = sub.add_parser("animate", help="an animation (GIF or MP4) of a `moreau run` output")
    a.add_argument("run", metavar="RUN",
                   help="the output folder of `moreau run` (or one of its .csv histories)")
    a.add_argument("--out", required=True, metavar="FILE",
                   help="the animation: FILE.gif (Pillow) or FILE.mp4 (ffmpeg)")
    a.add_argument("--fps", type=int, default=20, help="frames per second (default 20)")
    a.add_argument("--frames", type=int, default=100,
                   help="frames at most, spread evenly over the run (default 100)")
    a.add_argument("--force", action="store_true", help="replace an existing FILE")
    a.set_defaults(func=_cmd_animate)
