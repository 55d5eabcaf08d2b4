"""Friction drive: the generic compiled kernel against the deleted hand-written one.

Issue 9 asks that moving the friction drive onto the generic kernel
(``moreau.integrators._mj_kernels.mj_loop``, compiled per model by
``moreau.integrators._loops.runner_for``) costs no speed. The hand-written
kernel it replaced (``mj_run_fd`` with ``scenes/_friction_drive_jit.py``, last
present at commit ``e635941``) is loaded from git into a throw-away package
(kept under the temp folder so that numba's cache of it survives between
runs), and both run the same 185 Hz friction drive from rest, in this process,
alternately, over ``--steps`` steps. Reported: the median rate of each and
the median over the rounds of the per-round ratio new / old (with its
range), with and without projection.

Usage::

    python benchmarks/fd_kernel_ratio.py [--steps 200000] [--repeats 7]
"""

import argparse
import importlib
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from moreau.integrators import _mj_kernels as mk
from moreau.integrators._loops import runner_for
from moreau.scenes import FrictionDrive

OLD_COMMIT = "e635941"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILES = {"integrators/_mj_kernels.py": "moreau/integrators/_mj_kernels.py",
         "scenes/_friction_drive_jit.py": "moreau/scenes/_friction_drive_jit.py"}


def load_old():
    base = os.path.join(tempfile.gettempdir(), f"moreau_oldfd_{OLD_COMMIT}")
    pkg = os.path.join(base, "oldfd")
    for sub in ("", "integrators", "scenes"):
        os.makedirs(os.path.join(pkg, sub), exist_ok=True)
        init = os.path.join(pkg, sub, "__init__.py")
        if not os.path.exists(init):
            open(init, "w").close()
    for dst, src in FILES.items():
        path = os.path.join(pkg, dst)
        if not os.path.exists(path):
            text = subprocess.run(["git", "-C", ROOT, "show", f"{OLD_COMMIT}:{src}"], check=True,
                                  capture_output=True, text=True).stdout
            with open(path, "w") as fh:
                fh.write(text)
    if base not in sys.path:
        sys.path.insert(0, base)
    return (importlib.import_module("oldfd.integrators._mj_kernels"),
            importlib.import_module("oldfd.scenes._friction_drive_jit"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--frequency", type=float, default=185.0)
    args = ap.parse_args(argv)

    old_k, old_jit = load_old()
    scene = FrictionDrive(frequency=args.frequency)
    q0, v0 = scene.initial_state()
    q0 = np.asarray(q0, float)
    v0 = np.asarray(v0, float)
    h = 2.0 * math.pi / 1000
    N = args.steps
    t_bound = N * h
    par_old = old_jit.pack_params(scene)
    m = scene.compiled_model()
    mu = np.asarray(scene.mu, float)
    e = np.asarray(scene.restitution, float)
    ns = 4

    def bufs(nc):
        return (np.empty(ns), np.empty((ns, 2)), np.empty((ns, 2)),
                np.empty((ns, nc), dtype=np.int64), np.empty((ns, nc)), np.empty((ns, nc)),
                np.empty((ns, nc)), np.empty((ns, nc)))

    def run_old(projection):
        q, v = q0.copy(), v0.copy()
        st = old_k.new_stats()
        b = bufs(1)
        buf = (b[0], b[1], b[2], b[3][:, 0].copy(), b[4][:, 0].copy(), b[5][:, 0].copy(),
               b[6][:, 0].copy(), b[7][:, 0].copy())
        out = old_k.mj_run_fd(par_old, 0.0, h, t_bound, 0, N, q, v, 1.0, projection, False, N,
                              False, *buf, st)
        return out[1], q, v

    def run_new(projection):
        q, v = q0.copy(), v0.copy()
        st = mk.new_stats()
        closed = np.zeros(1, dtype=np.bool_)
        out = runner_for(m)(m.par, mu, e, 0.0, h, t_bound, 0, N, q, v, 1.0, projection, closed,
                            N, False, mk.new_lcp_control(1), *bufs(1), st)
        return out[1], q, v

    print(f"friction drive {args.frequency:g} Hz, h = 2 pi/1000, {N} steps, "
          f"median of {args.repeats}")
    print(f"{'':16s}{'old steps/s':>14s}{'new steps/s':>14s}{'new/old':>9s}   "
          f"[min, max] per round   |q_new - q_old|")
    for projection in (False, True):
        ko, qo, vo = run_old(projection)        # warm-up (cache load or compile)
        kn, qn, vn = run_new(projection)
        told, tnew = [], []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            run_old(projection)
            told.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            run_new(projection)
            tnew.append(time.perf_counter() - t0)
        ro = N / statistics.median(told)
        rn = N / statistics.median(tnew)
        # each round runs both back to back: the median of the per-round
        # ratios cancels the load drift of a shared machine
        ratios = sorted(a / b for a, b in zip(told, tnew))
        dq = float(np.max(np.abs(qn - qo)))
        label = "projection" if projection else "no projection"
        print(f"{label:16s}{ro:14.3e}{rn:14.3e}{statistics.median(ratios):9.2f}"
              f"   [{ratios[0]:.2f}, {ratios[-1]:.2f}]   {dq:.1e} (steps {ko}, {kn})")


if __name__ == "__main__":
    main()
