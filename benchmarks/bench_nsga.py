"""Speed of the compiled nonsmooth generalized-α loop on the single-contact scenes.

The goal of issue 18: the new time-stepping schemes at 1e6 steps/s or more
on single-contact scenes. For each scene, the warm rate (steps per second
through ``simulate``, one sample kept in 1000) of the compiled
nonsmooth generalized-α loop and, measured in the same run, of the compiled
Moreau–Jean loop (theta = 1/2), each a median over ``--repeats`` runs after a
warm-up run (numba compilation excluded), in wall time and in the process's
CPU time (on a shared machine the wall time counts the others' turns):

``bouncing-ball``
    flight and impacts (e = 0.5), the position stage at each impact;
``sliding-block``
    a persistent sliding contact (incline 0.5 rad, mu = 0.3): the smooth
    contact force in every step;
``friction-drive``
    185 Hz, from rest: the rheonomic contact with nonlinear forces (Newton),
    in persistent slip once closed;
``stick-slip-motor``
    1000 Hz sawtooth: stick and slip of a pressed slider.

Usage::

    python benchmarks/bench_nsga.py [--repeats 5] [--steps 200000] [--json out.json]
"""

import argparse
import json
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from _timing import median_time  # noqa: E402
from moreau.integrators import simulate  # noqa: E402
from moreau.model.registry import make_scene  # noqa: E402

GOAL = 1e6

CASES = {
    "bouncing-ball": dict(restitution=0.5),
    "sliding-block": dict(incline=0.5, mu=0.3),
    "friction-drive": dict(frequency=185.0),
    "stick-slip-motor": dict(),
}


def rate(scene, scheme, options, steps, repeats):
    """Median steps per second of ``scheme`` on ``scene`` over ``steps`` steps."""
    q0, v0 = scene.initial_state()
    T = scene.period or 2.0
    h = T / 1000.0
    t_end = steps * h

    def go():
        r = simulate(scene, (0.0, t_end), q0, v0, scheme, h=h, save_every=1000, **options)
        if not r.success:
            raise RuntimeError(f"{scheme} failed on {scene.name}: {r.message}")
        return r

    go()
    sec = median_time(go, repeat=repeats, warmup=0)
    # CPU time as well: on a shared machine the wall time counts other processes' turns
    cpu = []
    for _ in range(repeats):
        c0 = time.process_time()
        go()
        cpu.append(time.process_time() - c0)
    return steps / sec, steps / statistics.median(cpu)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=200000)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    rows = []
    for name, params in CASES.items():
        sc = make_scene(name, **params)
        nsga, nsga_cpu = rate(sc, "nonsmooth-generalized-alpha", {}, a.steps, a.repeats)
        mj, mj_cpu = rate(sc, "moreau-jean", {"theta": 0.5}, a.steps, a.repeats)
        rows.append({"scene": name, "nsga_steps_per_s": nsga, "mj_steps_per_s": mj,
                     "nsga_steps_per_cpu_s": nsga_cpu, "mj_steps_per_cpu_s": mj_cpu,
                     "ratio_to_mj": nsga / mj, "meets_goal": bool(nsga >= GOAL)})
        print(f"{name:18s} nsga {nsga:9.3g} steps/s ({nsga_cpu:9.3g} per CPU s)   "
              f"moreau-jean 1/2 {mj:9.3g} ({mj_cpu:9.3g})   ratio {nsga / mj:5.2f}   "
              f"goal 1e6: {'yes' if nsga >= GOAL else 'no'}", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"goal_steps_per_s": GOAL, "rows": rows}, f, indent=1)
    return 0 if all(np.isfinite([r["nsga_steps_per_s"] for r in rows])) else 1


if __name__ == "__main__":
    sys.exit(main())
