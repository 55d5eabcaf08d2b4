"""Speed of the friction drive built with the planar builder against the hand-written drive.

``friction-drive`` (hand-written compiled functions, which keep the last
angle's and phase's sines and cosines) and ``friction-drive-built`` (the
builder's generated functions, :mod:`moreau.model.planar`), run in one
process through the paths a user takes: ``simulate`` with the
time-stepping schemes at their default options (Moreau–Jean at ``theta =
1`` and ``1/2``, Schatzman–Paoli, nonsmooth generalized-α; one sample
kept), and Moreau–Jean's periodic steady state
(``find_steady_state(scene, "moreau-jean")``). Each time is a median over
``--repeats`` runs after a warm-up, the two scenes' runs interleaved (a
busy machine's load falls on both alike), from rest at 185 Hz. The ratios
of rates built / hand-written are printed; the target of issue 36 is >= 0.7.

Usage::

    python benchmarks/bench_drive_built.py [--repeats 7] [--periods 200] [--json out.json]
"""

import argparse
import json
import math
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from moreau.analysis.steady_state import find_steady_state  # noqa: E402
from moreau.integrators import simulate  # noqa: E402
from moreau.scenes.friction_drive import FrictionDrive  # noqa: E402
from moreau.scenes.friction_drive_built import friction_drive_built  # noqa: E402

#: steps per drive period
STEPS = 1000
SCHEMES = (("moreau-jean", {}), ("moreau-jean", {"theta": 0.5}), ("schatzman-paoli", {}),
           ("nonsmooth-generalized-alpha", {}))


def medians(jobs, repeats):
    """Median time of each job, the jobs' runs interleaved, after one warm-up run each."""
    for job in jobs.values():
        job()
    times = {name: [] for name in jobs}
    for _ in range(repeats):
        for name, job in jobs.items():
            t0 = time.perf_counter()
            job()
            times[name].append(time.perf_counter() - t0)
    return {name: statistics.median(ts) for name, ts in times.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--periods", type=int, default=200)
    ap.add_argument("--frequency", type=float, default=185.0)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    scenes = {"hand-written": FrictionDrive(frequency=args.frequency),
              "built": friction_drive_built(frequency=args.frequency)}
    h = 2.0 * math.pi / STEPS
    n = args.periods * STEPS
    out = {}
    for scheme, opts in SCHEMES:
        label = scheme + "".join(f" {k}={v}" for k, v in opts.items())
        jobs = {}
        for name, sc in scenes.items():
            q0, v0 = sc.initial_state()

            def job(sc=sc, q0=q0, v0=v0):
                res = simulate(sc, (0.0, n * h), q0, v0, scheme, h=h, save_every=n, **opts)
                if not res.success:
                    raise RuntimeError(f"benchmark run failed: {res.message}")
            jobs[name] = job
        t = medians(jobs, args.repeats)
        out[label] = {name: n / t[name] for name in scenes}

    def steady(sc):
        return lambda: find_steady_state(sc, "moreau-jean", steps_per_period=STEPS,
                                         statistical=False)
    t = medians({name: steady(sc) for name, sc in scenes.items()}, args.repeats)
    out["steady state (moreau-jean)"] = {name: 1.0 / t[name] for name in scenes}
    print(f"{'friction drive, ' + str(args.frequency) + ' Hz':40s} {'hand/s':>10s} "
          f"{'built/s':>10s} {'built/hand':>10s}")
    for label, r in out.items():
        r["ratio"] = r["built"] / r["hand-written"]
        print(f"{label:40s} {r['hand-written']:10.3e} {r['built']:10.3e} {r['ratio']:10.2f}")
    print("(steps per second; the steady state: solves per second)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
    return out


if __name__ == "__main__":
    main()
