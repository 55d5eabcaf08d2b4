"""Speed of Moreau–Jean's step on scenes with joints (the generic Python step with the mixed LCP).

Steps per second of ``double-pendulum-stop`` (four joint rows, one contact,
over its first strike) and ``slider-crank`` (six joint rows) at ``theta = 1``
and ``1/2``, through ``simulate`` with one sample kept: medians over
``--repeats`` runs after a warm-up, the runs interleaved.

Usage::

    python benchmarks/bench_joints.py [--repeats 5] [--steps 3000] [--json out.json]
"""

import argparse
import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from moreau.integrators import simulate  # noqa: E402
from moreau.scenes.double_pendulum_stop import double_pendulum_stop  # noqa: E402
from moreau.scenes.slider_crank import slider_crank  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    # the pendulum's window [0, 3] holds its first strike (t = 2.4)
    spans = {"double-pendulum-stop": (double_pendulum_stop(), 3.0),
             "slider-crank": (slider_crank(), 1.5)}
    runs = {}
    for name, (scene, span) in spans.items():
        q0, v0 = scene.initial_state()
        for theta in (1.0, 0.5):
            def run(scene=scene, q0=q0, v0=v0, span=span, theta=theta):
                res = simulate(scene, (0.0, span), q0, v0, "moreau-jean", h=span / args.steps,
                               theta=theta, save_every=args.steps)
                if res.status != 0:
                    raise RuntimeError(f"benchmark run failed: {res.message}")
            run()
            runs[(name, theta)] = run
    times = {k: [] for k in runs}
    for _ in range(args.repeats):
        for k, run in runs.items():
            t0 = time.perf_counter()
            run()
            times[k].append(time.perf_counter() - t0)
    out = {f"{name} theta={theta:g}": args.steps / statistics.median(ts)
           for (name, theta), ts in times.items()}
    for k, r in out.items():
        print(f"{k:32s} {r:8.0f} steps/s  ({1e3 / r:.3f} ms a step)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
    return out


if __name__ == "__main__":
    main()
