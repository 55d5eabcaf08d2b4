"""Run time per period of the generic event-driven reference beside the friction-drive walker.

For the paper's friction drive at 20, 185 and 2000 Hz, one steady period
(started on the walker's steady state at its Poincaré section) is run by
``"event-driven-generic"`` and by ``"friction-drive-walker"``; the medians
over repeated runs and their ratio are printed, with the generic scheme's
deviation from the walker's displacement per period. Both run in the same
process, so the ratio is meaningful on a shared machine.

Run: ``python benchmarks/bench_event_driven_generic.py [--quick]``
"""

import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from _timing import median_time  # noqa: E402

from moreau.analysis.steady_state import find_steady_state  # noqa: E402
from moreau.integrators import simulate  # noqa: E402
from moreau.scenes.friction_drive import FrictionDrive  # noqa: E402

TWO_PI = 2.0 * math.pi


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    args = ap.parse_args()
    rep = 3 if args.quick else 11
    print(f"{'f [Hz]':>8} {'mode':>6} {'generic [ms]':>13} {'walker [ms]':>12} {'ratio':>7} "
          f"{'|d dx| / |dx|':>14}")
    for f in (20.0, 185.0, 2000.0):
        sc = FrictionDrive(frequency=f)
        ss = find_steady_state(sc, rtol=1e-12)
        phi, dphi, du2 = ss.state0
        span = (ss.section_tau, ss.section_tau + TWO_PI)

        def run(name):
            return simulate(sc, span, [phi, 0.0], [dphi, du2], name)

        t_gen = median_time(lambda: run("event-driven-generic"), repeat=rep, warmup=1)
        t_walk = median_time(lambda: run("friction-drive-walker"), repeat=rep, warmup=1)
        dx = run("event-driven-generic").q[-1, 1]
        err = abs(dx - ss.displacement_per_period) / abs(ss.displacement_per_period)
        print(f"{f:8.0f} {ss.mode:>6} {t_gen * 1e3:13.1f} {t_walk * 1e3:12.2f} "
              f"{t_gen / t_walk:7.1f} {err:14.2e}")


if __name__ == "__main__":
    main()
