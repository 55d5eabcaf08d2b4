"""Speed of the generic (Python) path of the simple scenes: per model call and per run.

The scenes' Python methods (``mass``, ``forces``, ``gaps``, ...) evaluate
their compiled model's functions (:class:`moreau.model.compiled_scene.CompiledScene`).
This prints, per scene, the median time of one call of each method and the
median run time of ``"event-driven-generic"`` over the scene's default span
from its initial state. Run it once on a tree with hand-written Python
methods and once on this one to compare.

Run: ``python benchmarks/bench_compiled_scene.py [--quick]``
"""

import argparse
import os
import sys
import timeit

sys.path.insert(0, os.path.dirname(__file__))
from _timing import median_time  # noqa: E402

import numpy as np  # noqa: E402

from moreau.integrators import simulate  # noqa: E402
from moreau.scenes import registry  # noqa: E402

SCENES = ("bouncing-ball", "sliding-block", "sliding-box", "ball-chain", "rocking-block",
          "painleve-rod")


def per_call_us(f, number=2000, repeat=7):
    f()
    return 1e6 * float(np.median(timeit.repeat(f, number=number, repeat=repeat))) / number


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    ap.add_argument("--scenes", nargs="*", default=list(SCENES))
    args = ap.parse_args()
    rep = 3 if args.quick else 9
    print(f"{'scene':>14} {'mass':>6} {'forces':>6} {'gaps':>6} {'jacob':>6} {'drift':>6} "
          f"{'[us/call]':>9} {'event-driven-generic [ms]':>26} {'events':>7}")
    for name in args.scenes:
        sc = registry.make_scene(name)
        q, v = sc.initial_state()
        t = 0.3
        calls = [per_call_us(lambda: sc.mass(q)), per_call_us(lambda: sc.forces(q, v, t)),
                 per_call_us(lambda: sc.gaps(q, t)),
                 per_call_us(lambda: sc.contact_jacobians(q, t)),
                 per_call_us(lambda: sc.contact_drift(q, v, t))]
        span = (0.0, sc.default_span())

        def run():
            return simulate(sc, span, q, v, "event-driven-generic")

        res = run()
        ms = 1e3 * median_time(run, repeat=rep, warmup=1)
        nev = len(getattr(res, "events", []) or [])
        print(f"{name:>14} " + " ".join(f"{c:6.2f}" for c in calls) +
              f" {'':>9} {ms:26.2f} {nev:7d}")


if __name__ == "__main__":
    main()
