"""Studer's scheme against the walker on the friction drive's steady state, and its speed.

The goal of issue 18: on the friction drive's steady state at 185 Hz and
2000 Hz, the fastest time-stepping scheme reaches a relative error of 1e-6
in at most 10 times the time the event-driven walker needs for 1e-9.

For each frequency, the reference is the walker's steady state at shooting
tolerance 1e-13; the walker is timed at 1e-9, and Studer's scheme
(``studer-extrapolation``, compiled loop) is timed at each tolerance of
``--tols`` through the same entry point as ``moreau compare``
(:func:`moreau.analysis.scheme_settings.steady_of`: Newton shooting on its
period map). The two are timed alternately in the same process (medians
over ``--repeat`` pairs), so that a load on the machine hits both alike;
the table gives each row's error, its time and its ratio to the walker's.
The row to read is the fastest one below 1e-6.

Then the speed on single-contact scenes: base steps (Moreau midpoint steps)
and accepted macro steps per second of the compiled loop over one period of
the friction drive from its orbit and over the bouncing ball's fall and
rebounds (``t`` in [0, 2], e = 0.5), at tolerance 1e-9.

Run: ``python benchmarks/bench_studer.py [--quick] [--repeat N] [--tols 1e-8,1e-10]``;
prints the tables and writes ``studer.json`` to ``--out`` (default ``./out``).
"""

import argparse
import json
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))

from moreau.analysis.period_k import full_state_of  # noqa: E402
from moreau.analysis.scheme_settings import make_scheme, steady_of  # noqa: E402
from moreau.analysis.steady_state import find_steady_state  # noqa: E402
from moreau.integrators import simulate  # noqa: E402
from moreau.model.registry import make_scene  # noqa: E402

NAME = "studer-extrapolation"


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def pareto(frequency, tols, repeat):
    sc = make_scene("friction-drive", frequency=frequency)
    ref = find_steady_state(sc, rtol=1e-13, statistical=False).displacement_per_period

    def walker():
        return find_steady_state(sc, rtol=1e-9, statistical=False)

    rows = []
    walker()
    for tol in tols:
        sch = make_scheme(NAME, options={"tol": tol})

        def studer():
            return steady_of(sc, sch)
        try:
            studer()    # the compile, and the first-use costs
        except Exception as exc:  # a failed shooting is a row, not the end of the table
            rows.append(dict(frequency=frequency, tol=tol, error=None, time_s=None,
                             walker_s=None, ratio=None, message=str(exc)))
            continue
        tw, ts = [], []
        for _ in range(repeat):
            t, w = timed(walker)
            tw.append(t)
            t, ss = timed(studer)
            ts.append(t)
        t_w, t_s = statistics.median(tw), statistics.median(ts)
        rows.append(dict(frequency=frequency, tol=tol,
                         error=abs(ss.displacement_per_period / ref - 1.0), time_s=t_s,
                         walker_s=t_w, walker_error=abs(w.displacement_per_period / ref - 1.0),
                         ratio=t_s / t_w, period_maps=ss.stats.get("period_maps"),
                         message=""))
    return rows


def speed(repeat):
    out = []
    sc = make_scene("friction-drive", frequency=185.0)
    ss = find_steady_state(sc, rtol=1e-13, statistical=False)
    q0, v0 = full_state_of(sc, ss.state0)
    cases = [("friction-drive 185 Hz, one period", sc,
              (ss.section_tau, ss.section_tau + 2.0 * np.pi), q0, v0)]
    ball = make_scene("bouncing-ball", restitution=0.5)
    bq, bv = ball.initial_state()
    cases.append(("bouncing ball e = 0.5, t in [0, 2]", ball, (0.0, 2.0), bq, bv))
    for label, scene, span, q, v in cases:
        def run():
            return simulate(scene, span, q, v, NAME, tol=1e-9)
        r = run()
        t = statistics.median(timed(run)[0] for _ in range(repeat))
        out.append(dict(case=label, time_s=t, base_steps=r.stats["base_steps"],
                        macro_steps=r.stats["steps"],
                        base_steps_per_s=r.stats["base_steps"] / t,
                        macro_steps_per_s=r.stats["steps"] / t))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeat", type=int, default=None)
    ap.add_argument("--tols", default=None)
    ap.add_argument("--out", default="out")
    args = ap.parse_args()
    repeat = args.repeat or (3 if args.quick else 9)
    tols = ([float(x) for x in args.tols.split(",")] if args.tols else
            [1e-8, 1e-10] if args.quick else [1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12])
    rows = []
    for f in (185.0, 2000.0):
        rows += pareto(f, tols, repeat)
    print(f"{'f [Hz]':>7} {'tol':>7} {'rel. error':>10} {'time [ms]':>10} {'walker [ms]':>11} "
          f"{'ratio':>6} {'maps':>5}")
    for r in rows:
        if r["error"] is None:
            print(f"{r['frequency']:7g} {r['tol']:7.0e}  failed: {r['message']}")
            continue
        print(f"{r['frequency']:7g} {r['tol']:7.0e} {r['error']:10.2e} {r['time_s'] * 1e3:10.2f} "
              f"{r['walker_s'] * 1e3:11.2f} {r['ratio']:6.2f} {r['period_maps']:5d}")
    for f in (185.0, 2000.0):
        ok = [r for r in rows if r["frequency"] == f and r["error"] is not None
              and r["error"] <= 1e-6]
        if ok:
            best = min(ok, key=lambda r: r["time_s"])
            print(f"{f:g} Hz: 1e-6 reached at tol {best['tol']:.0e} in {best['ratio']:.2f} x the "
                  f"walker's time for 1e-9 (goal <= 10)")
        else:
            print(f"{f:g} Hz: no tolerance reached 1e-6")
    sp = speed(repeat)
    print(f"{'case':>36} {'time [ms]':>10} {'base steps':>10} {'base/s':>9} {'macro/s':>9}")
    for s in sp:
        print(f"{s['case']:>36} {s['time_s'] * 1e3:10.3f} {s['base_steps']:10d} "
              f"{s['base_steps_per_s']:9.3g} {s['macro_steps_per_s']:9.3g}")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "studer.json"), "w") as fh:
        json.dump({"pareto": rows, "speed": sp}, fh, indent=1)


if __name__ == "__main__":
    main()
