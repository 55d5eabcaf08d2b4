"""Studer's compiled macro step: its own loop (benchmarks/_studer_loop_old.py) against the driver's.

Both run through ``simulate`` in one process, alternately (old, new, old,
...), ``--repeat`` times per scene; each run's process CPU time and the CPU
time inside the compiled calls are kept, and the medians printed with the
ratio old / new (above 1: the driver's loop is faster). The two runs'
results are compared bit for bit. ``--compile``: the CPU time of each
template's first call in a fresh numba cache (run once per order, old first
and new first, each in its own process).

Run: ``python benchmarks/bench_studer_driver.py [--repeat 9] [--shared] [--compile]``.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))

CASES = {
    # scene, its options, span in periods (or [0, 2] s), tol, runs per timed unit
    "friction-drive": ("friction-drive", {}, 400.0, 1e-9, 1),
    "piezo-drive": ("piezo-drive", {}, 200.0, 1e-9, 1),
    "bouncing-ball": ("bouncing-ball", {"restitution": 0.5}, None, 1e-9, 200),
    "rocking-block": ("rocking-block", {}, None, 1e-9, 100),
}


def install(kind, clock):
    """Make StuderExtrapolation's compiled block call the ``kind`` loop, timing each call."""
    import _studer_loop_old as old
    from moreau.integrators import studer_extrapolation as se
    from moreau.integrators._loops import runner_for

    new_template = se.studer_loop if not hasattr(se, "_NEW_LOOP") else se._NEW_LOOP
    se._NEW_LOOP = new_template

    def runner(m, template, scene):
        if kind == "new":
            run = runner_for(m, new_template, scene)

            def call(*args):
                t = time.process_time()
                out = run(*args)
                clock[0] += time.process_time() - t
                return out
            return call
        run = runner_for(m, old.studer_loop, scene)

        def call(par, mu, e, t0, h, t_bound, k0, nmax, q, v, opts, memo, save_every,
                 record_initial, lcp_ctl, *rest):
            th, closed, reg, acc, cnt, rk, ra0, ra1 = memo
            tol, K, h_min, budget = opts
            rec, st = rest[:8], rest[8]
            t = time.process_time()
            out = run(par, mu, e, t_bound, tol, K, h_min, budget, nmax, th, q, v, closed, reg,
                      acc, record_initial, lcp_ctl, *rec, rk, ra0, ra1, st, cnt)
            clock[0] += time.process_time() - t
            return out
        return call
    se.runner_for = runner


def case_run(name):
    from moreau.integrators import simulate
    from moreau.model.registry import make_scene
    scene_name, kw, periods, tol, inner = CASES[name]
    sc = make_scene(scene_name, **kw)
    q0, v0 = sc.initial_state()
    span = (0.0, periods * sc.period) if periods else (0.0, 2.0)

    def run():
        for _ in range(inner):
            r = simulate(sc, span, q0, v0, "studer-extrapolation", tol=tol)
        return r
    return run


def same(a, b):
    return all(np.array_equal(getattr(a, f), getattr(b, f)) for f in ("t", "q", "v"))


def speed(names, repeat):
    clock = [0.0]
    print(f"{'scene':16s} {'base steps':>10s} {'old CPU s':>10s} {'new CPU s':>10s} {'old/new':>8s}"
          f" {'loop old':>9s} {'loop new':>9s} {'old/new':>8s}  bits")
    for name in names:
        run = case_run(name)
        res, tt, tl = {}, {"old": [], "new": []}, {"old": [], "new": []}
        for kind in ("old", "new"):
            install(kind, clock)
            res[kind] = run()            # compile or load
        for _ in range(repeat):
            for kind in ("old", "new"):
                install(kind, clock)
                clock[0] = 0.0
                t = time.process_time()
                run()
                tt[kind].append(time.process_time() - t)
                tl[kind].append(clock[0])
        mt = {k: statistics.median(x) for k, x in tt.items()}
        ml = {k: statistics.median(x) for k, x in tl.items()}
        print(f"{name:16s} {res['new'].stats['base_steps']:10d} {mt['old']:10.4f} {mt['new']:10.4f}"
              f" {mt['old'] / mt['new']:8.3f} {ml['old']:9.4f} {ml['new']:9.4f}"
              f" {ml['old'] / ml['new']:8.3f}  {'same' if same(res['old'], res['new']) else 'DIFFER'}",
              flush=True)


def first_call(order, name):
    clock = [0.0]
    run = case_run(name)
    for kind in order:
        install(kind, clock)
        t = time.process_time()
        run()
        print(f"{kind}: first call {time.process_time() - t:.1f} CPU s", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--scenes", default=",".join(CASES))
    ap.add_argument("--shared", action="store_true", help="the shared loops, not the models' own")
    ap.add_argument("--compile", action="store_true")
    ap.add_argument("--first-call", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.first_call:
        first_call(args.first_call.split(","), args.scenes.split(",")[0])
        return
    if args.compile:
        for order in ("old,new", "new,old"):
            with tempfile.TemporaryDirectory() as cache:
                env = dict(os.environ, NUMBA_CACHE_DIR=cache, MOREAU_SPECIALISE="1")
                subprocess.run([sys.executable, __file__, "--first-call", order, "--scenes",
                                args.scenes.split(",")[0]], env=env, check=True)
        return
    # both loops of one kind: unset, each run would pick its own (a fresh disk cache or not)
    os.environ["MOREAU_SPECIALISE"] = "0" if args.shared else "1"
    speed(args.scenes.split(","), args.repeat)


if __name__ == "__main__":
    main()
