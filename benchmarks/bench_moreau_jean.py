"""Speed of Moreau–Jean on the paper's friction drive.

Targets (issue #4): >= 1,000,000 Moreau–Jean steps per second on one core,
including the contact solve of every step; one discrete-map steady state at
1000 steps per period in <= 50 ms.

Every figure is the median over ``--repeats`` runs after a warm-up run (which
also absorbs numba's compilation). The baseline is the generic Python path of
the same integrator (``fast=False``) on the same scene, measured in the same
process, so the ratio does not depend on how busy the machine is.

Usage::

    python benchmarks/bench_moreau_jean.py [--repeats 7] [--json out.json] [--check]

``--check`` exits with status 1 when a target is missed.
"""

import argparse
import json
import math
import statistics
import sys
import time

import numpy as np

from moreau.analysis.mj_steady_state import moreau_jean_steady_state
from moreau.integrators import simulate
from moreau.integrators._mj_kernels import mj_run_fd, new_stats
from moreau.scenes._friction_drive_jit import pack_params
from moreau.scenes.friction_drive import FrictionDrive

TWO_PI = 2.0 * math.pi


def median_time(fn, repeats):
    fn()                       # warm-up (compilation, caches)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times)


def kernel_run(scene, steps_per_period, periods, theta, projection):
    """The bare compiled loop: every step solves its contact problem; nothing is recorded."""
    par = pack_params(scene)
    n = steps_per_period * periods
    h = TWO_PI / steps_per_period
    rec = (np.empty(2), np.empty((2, 2)), np.empty((2, 2)), np.empty(2, dtype=np.int64),
           np.empty(2), np.empty(2), np.empty(2), np.empty(2))
    stats = new_stats()

    def run():
        q, v = scene.rest_state()
        stats[:] = 0.0
        # save_every > n: only the final sample is written
        status, k, _, _ = mj_run_fd(par, 0.0, h, periods * TWO_PI, 0, n, q, v, theta,
                                    projection, False, n + 1, False, *rec, stats)
        assert status == 0 and k == n and stats[0] == n
    return run, n


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--json", default=None, help="write the results to this file")
    ap.add_argument("--check", action="store_true", help="exit 1 if a target is missed")
    args = ap.parse_args(argv)
    R = args.repeats
    out = {"repeats": R}
    ok = True

    print("Moreau-Jean on the friction drive (medians over %d runs)" % R)
    print()
    print("steps per second (1000 steps/period, 1000 periods = 1e6 steps)")
    print(f"  {'case':34s} {'median s':>10s} {'steps/s':>12s}")
    rows = {}
    for f in (20.0, 185.0, 2000.0):
        sc = FrictionDrive(frequency=f)
        for theta, proj in ((1.0, False), (1.0, True), (0.5, False)):
            run, n = kernel_run(sc, 1000, 1000, theta, proj)
            med, _ = median_time(run, R)
            key = f"{f:g} Hz theta={theta:g} projection={proj}"
            rows[key] = n / med
            print(f"  {key:34s} {med:10.4f} {n / med:12.3e}")
    out["kernel_steps_per_s"] = rows
    worst = min(rows.values())
    ok &= worst >= 1e6

    # through the public API (block calls, result assembly)
    sc = FrictionDrive(frequency=185.0)
    q0, v0 = sc.rest_state()

    def api_run():
        simulate(sc, (0.0, 1000 * TWO_PI), q0, v0, "moreau-jean", h=TWO_PI / 1000, save_every=1000)
    med_api, _ = median_time(api_run, R)
    out["simulate_steps_per_s"] = 1e6 / med_api
    print(f"  {'simulate(), 185 Hz, save_every=1000':34s} {med_api:10.4f} {1e6 / med_api:12.3e}")

    # baseline: the generic Python path, same scheme and scene
    n_slow = 2000

    def slow_run():
        simulate(sc, (0.0, 2 * TWO_PI), q0, v0, "moreau-jean", h=TWO_PI / 1000, fast=False,
                 save_every=n_slow)
    med_slow, _ = median_time(slow_run, max(3, R // 2))
    slow_rate = n_slow / med_slow
    out["generic_steps_per_s"] = slow_rate
    print(f"  {'generic Python path (baseline)':34s} {med_slow:10.4f} {slow_rate:12.3e}")
    print(f"  compiled / generic speed ratio at 185 Hz: {rows['185 Hz theta=1 projection=False'] / slow_rate:.0f}")
    out["speed_ratio"] = rows["185 Hz theta=1 projection=False"] / slow_rate

    print()
    print("steady state of the discrete map, 1000 steps/period")
    print(f"  {'frequency':10s} {'median ms':>10s} {'min ms':>8s} {'maps':>5s} {'mode':>5s}")
    ss_rows = {}
    for f in (20.0, 185.0, 2000.0):
        sc = FrictionDrive(frequency=f)
        holder = {}

        def ss_run():
            holder["ss"] = moreau_jean_steady_state(sc, 1000)
        med, best = median_time(ss_run, R)
        ss = holder["ss"]
        ss_rows[f"{f:g}"] = med
        print(f"  {f:8g}Hz {med * 1e3:10.2f} {best * 1e3:8.2f} {ss.stats['period_maps']:5d} "
              f"{ss.mode:>5s}")
    out["steady_state_s"] = ss_rows
    ok &= max(ss_rows.values()) <= 0.050

    print()
    print(f"targets: >= 1e6 steps/s (worst {worst:.3g}); steady state <= 50 ms "
          f"(worst {max(ss_rows.values()) * 1e3:.1f} ms): {'met' if ok else 'MISSED'}")
    out["targets_met"] = bool(ok)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=2)
    if args.check and not ok:
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
