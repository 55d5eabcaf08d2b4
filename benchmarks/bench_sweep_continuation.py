"""Continued against cold sweeps: the cost of ``moreau sweep``'s points either way, in one process.

A sweep's values are neighbours; ``moreau sweep`` sends them to the workers
in segments of :func:`moreau.analysis.engine.line_chunk` points and shoots
each point from the previous one's orbit (``--cold``: every point from
rest). Here the same segments are solved both ways in one process,
alternately, ``--repeats`` times (medians), without a cache:

- the paper's ``mu`` sweep (0.01 to 0.99, 99 points) at 185 and 2000 Hz;
- its ``phi0`` sweep over the valid range at 2000 Hz;
- its frequency sweep (10 Hz to 12.5 kHz, 250 log-spaced points).

Reported per sweep: median seconds of either, their ratio, the shooting
iterations, and the largest relative difference of the displacement per
period where both found an orbit (and the points where only one did or the
modes differ). The machine is shared: the ratio is the figure to compare.

Run: ``python benchmarks/bench_sweep_continuation.py [--repeats 3] [--jobs 2] [--json PATH]``.
"""

import argparse
import json
import statistics
import time
from dataclasses import asdict

import numpy as np

from moreau.analysis.engine import ED_REFERENCE, evaluate_points, line_chunk
from moreau.scenes.friction_drive import PAPER_DEFAULTS
from moreau.studies.paper.sweeps import sweep_values
from moreau.studies.paper.valid_range import phi0_valid_range


def _sweeps():
    p = PAPER_DEFAULTS
    mus = np.linspace(0.01, 0.99, 99)
    edges = phi0_valid_range(p, 2000.0)
    lo, hi = edges["lift_off_edge"], edges["painleve_edge"]
    out = {f"mu at {f:g} Hz": [(asdict(p.with_(mu=float(m))), f) for m in mus]
           for f in (185.0, 2000.0)}
    out["phi0 at 2000 Hz"] = [(asdict(p.with_(phi0=float(x))), 2000.0)
                              for x in np.linspace(lo, hi, 101)[1:-1]]
    out["frequency"] = [(asdict(p), float(f))
                        for f in sweep_values("frequency", 10.0, 12500.0, 250, "log")]
    return out


def _solve(points, continuation, jobs):
    chunk = line_chunk(len(points), jobs, continuation)
    t0 = time.perf_counter()
    rows = []
    for i in range(0, len(points), chunk):
        rows += evaluate_points(points[i:i + chunk], ED_REFERENCE, continuation=continuation)
    return time.perf_counter() - t0, rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--jobs", type=int, default=2, help="the worker count the segments are cut for")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    report = {}
    for name, points in _sweeps().items():
        times = {True: [], False: []}
        rows = {}
        for _ in range(args.repeats):
            for cont in (False, True):
                t, rows[cont] = _solve(points, cont, args.jobs)
                times[cont].append(t)
        both = [(c, w) for c, w in zip(rows[False], rows[True])
                if c["status"] == w["status"] == "ok"]
        diff = max((abs(w["displacement_per_period_m"] / c["displacement_per_period_m"] - 1.0)
                    for c, w in both if c["displacement_per_period_m"] != 0.0), default=0.0)
        odd = sum(1 for c, w in zip(rows[False], rows[True])
                  if (c["status"] == "ok") != (w["status"] == "ok") or c["mode"] != w["mode"])
        cold, warm = statistics.median(times[False]), statistics.median(times[True])
        report[name] = {
            "points": len(points), "segment": line_chunk(len(points), args.jobs),
            "cold_s": cold, "continued_s": warm, "ratio": warm / cold,
            "iterations_cold": sum(int(r.get("shooting_iterations") or 0) for r in rows[False]),
            "iterations_continued": sum(int(r.get("shooting_iterations") or 0)
                                        for r in rows[True]),
            "ok_cold": sum(r["status"] == "ok" for r in rows[False]),
            "ok_continued": sum(r["status"] == "ok" for r in rows[True]),
            "max_rel_difference": diff, "points_differing": odd}
        r = report[name]
        print(f"{name:18s} {r['points']:4d} pts  cold {cold:7.2f} s  continued {warm:7.2f} s  "
              f"ratio {r['ratio']:.2f}  iterations {r['iterations_cold']} -> "
              f"{r['iterations_continued']}  ok {r['ok_cold']} -> {r['ok_continued']}  "
              f"max diff {diff:.1e}  differing {odd}", flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=1)


if __name__ == "__main__":
    main()
