"""Time per Moreau–Jean step of many disks against the contacts: broad phase, assembly, NSGS.

CPU time (``time.process_time``): the machine is shared. The system: a triangular packing of equal disks (diameter 1, mass 1) in a box
(a rough floor and two walls, ``mu = 0.5``), ``rows x cols`` disks touching
their neighbours, under gravity, at rest: about three contacts a disk. It
runs :func:`moreau.integrators.granular.simulate_disks` (``theta = 1``,
``h = 1e-2`` in units of ``sqrt(d / g)``, NSGS to ``--tol``) for ``--warmup``
steps, then ``--steps`` steps timed: the wall time a step, split into the
broad phase with the contact set, the assembly of ``W = H M^-1 H^T`` and
``q``, and NSGS (warm started by pair); with the NSGS sweeps a step and the
steps that ended above ``tol``. The broad phase alone is also timed against
the brute-force pair search on the same centres.

Run: ``python benchmarks/bench_granular.py [--quick] [--tol 1e-6]``; prints the table.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from moreau.integrators.granular import simulate_disks  # noqa: E402
from moreau.model.granular import DiskSystem, HalfPlane, brute_pairs, grid_pairs  # noqa: E402


def packing(rows, cols):
    """A triangular packing of unit-diameter disks in a box, and the system."""
    s = math.sqrt(3.0) / 2.0
    x = np.array([[0.5 + c + 0.5 * (r % 2), 0.5 + s * r] for r in range(rows)
                  for c in range(cols)])
    walls = [HalfPlane((0.0, 0.0), (0.0, 1.0)), HalfPlane((0.0, 0.0), (1.0, 0.0)),
             HalfPlane((cols + 0.5, 0.0), (-1.0, 0.0))]
    n = rows * cols
    return DiskSystem(np.full(n, 0.5), np.ones(n), walls=walls, mu=0.5), x


def time_steps(rows, cols, args):
    sys, x = packing(rows, cols)
    v0 = np.zeros((sys.n_disks, 3))
    warm = simulate_disks(sys, x, v0, args.warmup, 1e-2, theta=1.0, tol=args.tol,
                          max_sweeps=args.budget)
    t0 = time.process_time()
    res = simulate_disks(sys, warm.x[-1], warm.v[-1], args.steps, 1e-2, theta=1.0, tol=args.tol,
                         max_sweeps=args.budget, phi0=warm.phi[-1])
    wall = (time.process_time() - t0) / args.steps
    tb = time.process_time()
    for _ in range(5):
        grid_pairs(warm.x[-1], sys.radii, 0.05)
    grid = (time.process_time() - tb) / 5
    brute = math.nan
    if sys.n_disks <= 5000:
        tb = time.process_time()
        brute_pairs(warm.x[-1], sys.radii, 0.05)
        brute = time.process_time() - tb
    per = {k: res.timing[k] / args.steps for k in ("broad_phase", "assembly", "solve")}
    return {"disks": sys.n_disks, "contacts": float(np.mean(res.steps["contacts"])),
            "step_ms": 1e3 * wall, **{k + "_ms": 1e3 * v for k, v in per.items()},
            "sweeps": float(np.mean(res.steps["sweeps"])),
            "us_per_sweep": 1e3 * per["solve"] / max(float(np.mean(res.steps["sweeps"])), 1.0), "unconverged": res.unconverged.size,
            "max_residual": res.max_residual, "grid_ms": 1e3 * grid, "brute_ms": 1e3 * brute}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--budget", type=int, default=2000)
    ap.add_argument("--warmup", type=int, default=10)
    ap.add_argument("--steps", type=int, default=20)
    args = ap.parse_args()
    # a layer 10 disks deep, wider and wider (the sweeps NSGS needs depend on the depth),
    # and square piles (deeper and deeper: the sweeps grow)
    sizes = [(10, 4), (10, 42), (10, 420), (6, 6), (19, 19), (58, 58)]
    if args.quick:
        sizes = [(10, 4), (10, 42), (6, 6), (19, 19)]
    small, x = packing(2, 2)
    simulate_disks(small, x, np.zeros((4, 3)), 2, 1e-2)      # the compiles, out of the timings
    brute_pairs(x, small.radii, 0.05)
    head = ("disks", "contacts", "step_ms", "broad_phase_ms", "assembly_ms", "solve_ms", "sweeps", "us_per_sweep",
            "unconverged", "max_residual", "grid_ms", "brute_ms")
    print(" | ".join(head))
    for rows, cols in sizes:
        row = time_steps(rows, cols, args)
        print(" | ".join(f"{row[k]:.4g}" if isinstance(row[k], float) else str(row[k])
                         for k in head), flush=True)


if __name__ == "__main__":
    main()
