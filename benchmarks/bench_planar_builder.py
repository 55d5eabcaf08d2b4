"""Speed of a model built with the planar builder against the same model written by hand.

The rocking block (``rocking-block``, hand-written compiled functions) and
the same block stated with :mod:`moreau.model.planar` (``rocking-block-built``,
the builder's shared functions reading the description from ``par``), run
by the compiled Moreau–Jean loop in one process: steps per second through
``simulate`` (one sample kept), in the shared loop (the model called
through pointers) and in the model's specialised loop, and the generic
Python path (``fast=False``, where the built scene's Python methods call
the compiled functions). Each rate is a median over ``--repeats`` runs
after a warm-up, the two scenes' runs interleaved; the block is released at its default tilt and rocks to
rest, so the runs mix one- and two-contact steps and flat rest. The
ratios built / hand-written are printed; the target of issue 36 is >= 0.7.

Usage::

    python benchmarks/bench_planar_builder.py [--repeats 5] [--steps 200000] [--json out.json]
"""

import argparse
import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from moreau.integrators import _loops, simulate  # noqa: E402
from moreau.scenes.rocking_block import RockingBlock  # noqa: E402
from moreau.scenes.rocking_block_built import rocking_block_built  # noqa: E402


def rates(scenes, h, nsteps, repeats, **opts):
    """Steps per second of each scene, its runs interleaved with the others' (a busy machine's
    load falls on all of them alike); medians over ``repeats`` after a warm-up."""
    runs = {}
    for name, scene in scenes.items():
        q0, v0 = scene.initial_state()

        def run(scene=scene, q0=q0, v0=v0):
            res = simulate(scene, (0.0, nsteps * h), q0, v0, "moreau-jean", h=h,
                           save_every=nsteps, **opts)
            if not res.success or res.stats["steps"] != nsteps:
                raise RuntimeError(f"benchmark run failed: {res.message}")
        run()
        runs[name] = run
    times = {name: [] for name in scenes}
    for _ in range(repeats):
        for name, run in runs.items():
            t0 = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - t0)
    return {name: nsteps / statistics.median(ts) for name, ts in times.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    # 4000 steps of h = 1e-3 reach rest (the Zeno time is 3.09): longer runs repeat the window
    h = 1e-3
    scenes = {"hand-written": RockingBlock(), "built": rocking_block_built()}
    out = {}
    saved = os.environ.get(_loops.SPECIALISE_ENV)
    for label, mode in (("shared", "0"), ("specialised", "1")):
        os.environ[_loops.SPECIALISE_ENV] = mode
        for name, r in rates(scenes, h, args.steps, args.repeats).items():
            out.setdefault(name, {})[label] = r
    if saved is None:
        os.environ.pop(_loops.SPECIALISE_ENV, None)
    else:
        os.environ[_loops.SPECIALISE_ENV] = saved
    for name, r in rates(scenes, h, 2000, max(1, args.repeats // 2), fast=False).items():
        out[name]["generic"] = r
    print(f"{'rocking block':14s} {'shared/s':>10s} {'specialised/s':>13s} {'generic/s':>10s}")
    for name in scenes:
        r = out[name]
        print(f"{name:14s} {r['shared']:10.3e} {r['specialised']:13.3e} {r['generic']:10.3e}")
    ratios = {k: out["built"][k] / out["hand-written"][k] for k in out["built"]}
    out["built_over_hand_written"] = ratios
    print("built / hand-written: " + ", ".join(f"{k} {v:.2f}" for k, v in ratios.items()))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
    return out


if __name__ == "__main__":
    main()
