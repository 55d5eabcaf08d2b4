"""Speed of the event-driven reference on the paper's friction drive.

Measures (medians over repeated runs, one core):
- one periodic steady state at the paper's defaults (185 Hz) at rtol 1e-10;
- the frequency sweep over 250 log-spaced frequencies (10 Hz .. 12.5 kHz);
- one period of plain DOP853 integration of the free rod (scipy baseline).
Ratios are given against the in-process baselines, since the machines are shared.

Run: ``python benchmarks/bench_event_driven.py [--quick]``
"""

import argparse
import math
import os
import sys

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(__file__))
from _timing import calibration, median_time  # noqa: E402

from moreau.analysis.steady_state import find_steady_state  # noqa: E402
from moreau.scenes.friction_drive import FrictionDrive  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    args = ap.parse_args()
    rep = 5 if args.quick else 21
    cal = calibration()
    scene = FrictionDrive(frequency=185.0)

    t_ss = median_time(lambda: find_steady_state(FrictionDrive(frequency=185.0), rtol=1e-10),
                       repeat=rep)
    t_ss20 = median_time(lambda: find_steady_state(FrictionDrive(frequency=20.0), rtol=1e-10),
                         repeat=rep)
    t_ss2k = median_time(lambda: find_steady_state(FrictionDrive(frequency=2000.0), rtol=1e-10),
                         repeat=rep)

    def rod_period():
        w = scene

        def rhs(t, y):
            c = math.cos(y[0])
            return [y[1], 3 * (w.P * c * (w.sin_phi0 - math.sin(y[0])) - 0.5 * w.u10 * math.cos(t) * c)]
        solve_ivp(rhs, (0, 2 * math.pi), [w.phi0 - 1e-4, 0.0], method="DOP853", rtol=1e-10, atol=1e-14)

    t_base = median_time(rod_period, repeat=rep)

    fs = np.geomspace(10.0, 12500.0, 250)

    def run_sweep():
        for f in fs:
            find_steady_state(FrictionDrive(frequency=f), rtol=1e-10)

    t_sweep = median_time(run_sweep, repeat=1 if args.quick else 3, warmup=1)

    print(f"calibration workload                         {cal * 1e3:8.3f} ms")
    print(f"DOP853 one period of the rod (baseline)      {t_base * 1e3:8.3f} ms")
    print(f"steady state, 185 Hz, rtol 1e-10 (median)    {t_ss * 1e3:8.3f} ms  "
          f"= {t_ss / t_base:.2f} x baseline, {t_ss / cal:.1f} x calibration  (target <= 10 ms)")
    print(f"steady state,  20 Hz                         {t_ss20 * 1e3:8.3f} ms")
    print(f"steady state, 2000 Hz                        {t_ss2k * 1e3:8.3f} ms")
    print(f"frequency sweep, 250 points                  {t_sweep:8.3f} s   "
          f"({t_sweep / 250 * 1e3:.2f} ms/point; target <= 3 s)")


if __name__ == "__main__":
    main()
