"""Cost of the friction drive's default atlas: continued against cold points, and the wall time.

Two measurements, both of ``moreau atlas``'s default grid (200 frequencies
from 10 Hz to 12.5 kHz, log-spaced, by 100 values of ``mu`` or ``phi0``,
the event-driven reference at a shooting tolerance of 1e-10):

``lines``
    Per point cost, in one process, of the same grid lines of constant
    frequency (every ``200 / --lines``-th frequency of both planes) solved
    twice: every point from a cold start (what ``moreau steady`` does for
    one point) and every point continued from its neighbour's orbit (the
    atlas's default, :mod:`moreau.analysis.continuation`). Without the
    classification run (``classify=0``): the shootings alone. Reported per
    plane: the total and median seconds per point of either, their ratio,
    the share of points where continuation was slower, the shooting
    iterations, and the largest relative difference of the displacement
    per period between the two where both found an orbit (and the number
    of points where only one did or they disagree on the mode).
``full`` (``--full``)
    The whole default atlas (both planes, 40 000 points) as ``moreau
    atlas`` runs it (``--jobs``, no cache), wall time per plane, with the
    classification budget ``--classify-periods`` (the default's, unless
    given), and where the time went: the compute seconds summed per class
    of point (period-1 orbits, classified, ill-posed, no contact, ...).

The machine is shared: the ratios in one process are the figures to
compare; the wall times depend on the load.

Run: ``python benchmarks/bench_atlas.py [--lines 20] [--full] [--jobs 2] --out DIR``;
writes ``atlas_bench.json`` to ``DIR``.
"""

import argparse
import json
import pathlib
import statistics
import time
from dataclasses import asdict

import numpy as np

from moreau.analysis.classify import CLASSIFY_PERIODS
from moreau.analysis.engine import ED_REFERENCE, evaluate_points
from moreau.scenes.friction_drive import PAPER_DEFAULTS
from moreau.studies.paper.atlas import PLANES, compute_atlas

F_RANGE, F_POINTS, Y_POINTS = (10.0, 12500.0), 200, 100


def _line(plane, f):
    y_name, y_range = PLANES[plane][:2]
    ys = np.linspace(*y_range, Y_POINTS)
    return [(asdict(PAPER_DEFAULTS.with_(**{y_name: float(y)})), float(f)) for y in ys]


def measure_lines(lines):
    """Cold and continued solves of the same grid lines, in this process."""
    freqs = np.geomspace(*F_RANGE, F_POINTS)
    pick = freqs[np.linspace(0, F_POINTS - 1, lines).round().astype(int)]
    evaluate_points(_line("f-mu", 185.0)[:2], ED_REFERENCE)    # imports, first calls
    out = {}
    for plane in PLANES:
        cold_t, cont_t, ratio = [], [], []
        it_cold = it_cont = 0
        worst, disagree, starts = 0.0, 0, {}
        wall = {"cold": 0.0, "continued": 0.0}
        for f in pick:
            pts = _line(plane, f)
            t0 = time.perf_counter()
            cold = evaluate_points(pts, ED_REFERENCE, continuation=False)
            t1 = time.perf_counter()
            cont = evaluate_points(pts, ED_REFERENCE, continuation=True)
            t2 = time.perf_counter()
            wall["cold"] += t1 - t0
            wall["continued"] += t2 - t1
            for a, b in zip(cold, cont):
                cold_t.append(a["compute_time_s"])
                cont_t.append(b["compute_time_s"])
                ratio.append(b["compute_time_s"] / max(a["compute_time_s"], 1e-9))
                it_cold += a["shooting_iterations"]
                it_cont += b["shooting_iterations"]
                starts[b["start"]] = starts.get(b["start"], 0) + 1
                if a["status"] == b["status"] == "ok" and a["mode"] == b["mode"]:
                    d = abs(a["displacement_per_period_m"] - b["displacement_per_period_m"])
                    worst = max(worst, d / max(abs(a["displacement_per_period_m"]), 1e-300))
                elif a["status"] == "ok" or b["status"] == "ok":
                    # one found an orbit and the other none, or another mode (another branch)
                    disagree += 1
        n = len(cold_t)
        out[plane] = {
            "frequencies_Hz": [float(f) for f in pick], "points": n,
            "cold_total_s": wall["cold"], "continued_total_s": wall["continued"],
            "total_ratio_continued_over_cold": wall["continued"] / wall["cold"],
            "cold_median_ms": 1e3 * statistics.median(cold_t),
            "continued_median_ms": 1e3 * statistics.median(cont_t),
            "median_per_point_ratio": statistics.median(ratio),
            "share_of_points_slower_continued": sum(r > 1.0 for r in ratio) / n,
            "iterations_cold": it_cold, "iterations_continued": it_cont,
            "starts": starts,
            "max_relative_difference_same_mode": worst,
            "points_differing_in_status_or_mode": disagree,
        }
        print(plane, json.dumps(out[plane], indent=1), flush=True)
    return out


def measure_full(jobs, classify):
    """The default atlas, both planes, as ``moreau atlas`` runs it (no cache)."""
    out = {}
    for plane in PLANES:
        t0 = time.perf_counter()
        a = compute_atlas(plane, f_range=F_RANGE, f_points=F_POINTS, y_points=Y_POINTS,
                          n_jobs=jobs, classify=classify)
        wall = time.perf_counter() - t0
        by_class = {}
        for cls, t in zip(a["classification"].ravel(), a["compute_time_s"].ravel()):
            c = by_class.setdefault(cls or "?", [0, 0.0])
            c[0] += 1
            c[1] += float(t)
        labels = {}
        for lab in a["label"].ravel():
            labels[lab] = labels.get(lab, 0) + 1
        starts = {}
        for s in a["start"].ravel():
            starts[s] = starts.get(s, 0) + 1
        out[plane] = {"wall_s": wall, "labels": labels, "starts": starts,
                      "compute_s_by_class": {k: {"points": v[0], "seconds": v[1]}
                                             for k, v in by_class.items()}}
        print(plane, json.dumps(out[plane], indent=1), flush=True)
    out["total_wall_s"] = sum(v["wall_s"] for v in out.values())
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=20, help="frequency lines per plane (of 200)")
    ap.add_argument("--full", action="store_true", help="also the whole default atlas")
    ap.add_argument("--jobs", type=int, default=-1, help="worker processes of the full atlas")
    ap.add_argument("--classify-periods", type=int, default=CLASSIFY_PERIODS)
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    result = {"lines": measure_lines(args.lines)}
    if args.full:
        result["full"] = measure_full(args.jobs, args.classify_periods)
        result["full"]["classify_periods"] = args.classify_periods
    (out / "atlas_bench.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {out / 'atlas_bench.json'}")


if __name__ == "__main__":
    main()
