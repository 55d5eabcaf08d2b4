"""Work-precision diagram: steady-state error against run time, per scheme.

For the paper's friction drive at 20, 185 and 2000 Hz, the displacement per
period of the Moreau–Jean discrete steady state (250 .. 16000 steps per period)
and of the event-driven reference (shooting tolerance 1e-4 .. 1e-12) is
compared with the event-driven reference at tolerance 1e-13. Times are medians
over repeats. Writes ``work_precision.csv`` and ``work_precision.png`` to
``--out`` (default ``./out``; not committed).

Run: ``python benchmarks/work_precision.py [--quick] [--out DIR]``
"""

import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from _timing import median_time  # noqa: E402

from moreau.analysis.steady_state import find_steady_state  # noqa: E402
from moreau.scenes.friction_drive import FrictionDrive  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="out")
    args = ap.parse_args()
    rep = 3 if args.quick else 7
    steps = [250, 500, 1000, 2000, 4000, 8000] + ([] if args.quick else [16000])
    tols = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
    rows = []
    for f in (20.0, 185.0, 2000.0):
        sc = FrictionDrive(frequency=f)
        ref = find_steady_state(sc, rtol=1e-13).displacement_per_period
        for n in steps:
            ss = find_steady_state(sc, scheme="moreau-jean", steps_per_period=n)
            t = median_time(lambda: find_steady_state(sc, scheme="moreau-jean", steps_per_period=n),
                            repeat=rep, warmup=0)
            rows.append(dict(frequency=f, scheme="moreau-jean", setting=n, time_s=t,
                             error=abs(ss.displacement_per_period - ref) / abs(ref), mode=ss.mode))
        for tol in tols:
            ss = find_steady_state(sc, rtol=tol)
            t = median_time(lambda: find_steady_state(sc, rtol=tol), repeat=rep, warmup=0)
            rows.append(dict(frequency=f, scheme="event-driven", setting=tol, time_s=t,
                             error=max(abs(ss.displacement_per_period - ref) / abs(ref), 1e-17),
                             mode=ss.mode))
    print(f"{'f [Hz]':>7} {'scheme':>13} {'setting':>9} {'time [ms]':>10} {'rel. error':>11} mode")
    for r in rows:
        print(f"{r['frequency']:7g} {r['scheme']:>13} {r['setting']:9g} {r['time_s'] * 1e3:10.3f} "
              f"{r['error']:11.2e} {r['mode']}")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "work_precision.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure")
        return
    fig, ax = plt.subplots(figsize=(7, 5))
    for f, color in zip((20.0, 185.0, 2000.0), ("C0", "C1", "C2")):
        for scheme, marker in (("moreau-jean", "o-"), ("event-driven", "s--")):
            sel = [r for r in rows if r["frequency"] == f and r["scheme"] == scheme]
            ax.loglog([r["time_s"] * 1e3 for r in sel], [r["error"] for r in sel], marker,
                      color=color, label=f"{scheme}, {f:g} Hz")
    ax.set_xlabel("run time of one steady state [ms]")
    ax.set_ylabel("relative error of the displacement per period")
    ax.set_title("friction drive: work-precision")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(args.out, "work_precision.png")
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
