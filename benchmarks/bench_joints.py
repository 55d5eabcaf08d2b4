"""Speed of Moreau–Jean's step on scenes with joints: the generic Python step against the compiled loop.

Steps per second of ``double-pendulum-stop`` (four joint rows, one contact,
over its first strike), ``slider-crank`` (six joint rows) and
``slider-crank-clearance`` (four joint rows, the pin's contact) at ``theta =
1`` and ``1/2``, through ``simulate`` with one sample kept, on the generic
step (``fast=False``, the mixed LCP in Python) and on the compiled loop of
joints (:mod:`moreau.integrators._mj_joint_kernels`, the default): medians
over ``--repeats`` runs after a warm-up (which compiles), all runs in one
process, interleaved. The compiled runs take ``--compiled-factor`` times more
steps, so that a run lasts long enough to time.

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
from moreau.scenes.slider_crank_clearance import slider_crank_clearance  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--compiled-factor", type=int, default=20)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    # the pendulum's window [0, 3] holds its first strike (t = 2.4)
    spans = {"double-pendulum-stop": (double_pendulum_stop(), 3.0),
             "slider-crank": (slider_crank(), 1.5),
             "slider-crank-clearance": (slider_crank_clearance(), 1.5)}
    runs = {}
    for name, (scene, span) in spans.items():
        q0, v0 = scene.initial_state()
        for theta in (1.0, 0.5):
            for fast in (False, "auto"):
                steps = args.steps * (1 if fast is False else args.compiled_factor)

                def run(scene=scene, q0=q0, v0=v0, span=span, theta=theta, fast=fast,
                        steps=steps):
                    res = simulate(scene, (0.0, span), q0, v0, "moreau-jean", h=span / steps,
                                   theta=theta, save_every=steps, fast=fast)
                    if res.status != 0:
                        raise RuntimeError(f"benchmark run failed: {res.message}")
                run()
                runs[(name, theta, fast)] = (run, steps)
    times = {k: [] for k in runs}
    for _ in range(args.repeats):
        for k, (run, _) in runs.items():
            t0 = time.perf_counter()
            run()
            times[k].append(time.perf_counter() - t0)
    out = {}
    for (name, theta, fast), ts in times.items():
        label = f"{name} theta={theta:g} {'generic' if fast is False else 'compiled'}"
        out[label] = runs[(name, theta, fast)][1] / statistics.median(ts)
    for k, r in out.items():
        print(f"{k:48s} {r:10.0f} steps/s  ({1e3 / r:.4f} ms a step)")
    for name in spans:
        for theta in (1.0, 0.5):
            g = out[f"{name} theta={theta:g} generic"]
            c = out[f"{name} theta={theta:g} compiled"]
            print(f"{name} theta={theta:g}: compiled / generic = {c / g:.1f}x")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
    return out


if __name__ == "__main__":
    main()
