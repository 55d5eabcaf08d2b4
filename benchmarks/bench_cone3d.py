"""The spatial friction cone two ways: facet error against d, and time per solve.

Part 1, the facet table: a sphere (mass 2, I = 2/5 m R^2, Delassus matrix
diag(1, 7/2, 7/2)/2) pressed on a plane (q_N = -1) and sliding (|q_T| = 3,
mu = 0.5), over ``--angles`` sliding directions. For d = 4, 8, 16, 32 it
prints the worst angle between the polyhedral and the exact tangential
impulse, the worst relative shortfall of its magnitude, the worst error of
the post-step velocity, and the order fitted to each (slope of log error
against log d).

Part 2, time per solve (CPU time of this process, median over repeats) of
:func:`moreau.contact.cone3d.solve_exact` and of
:func:`~moreau.contact.cone3d.solve_polyhedral` at d = 8 and 32 on random
well-posed problems with nc = 1, 4, 16 contacts (W = H M^-1 H^T), with the
exact solver's sweeps, Newton steps and relative residual.

Usage::

    python benchmarks/bench_cone3d.py            # 360 directions, 20 problems a size
    python benchmarks/bench_cone3d.py --quick    # 72 directions, 5 problems a size

Nothing is written to disk.
"""

import argparse
import math
import time

import numpy as np

from moreau.contact.cone3d import local_solve, solve_exact, solve_polyhedral

W_SPHERE = np.diag([1.0, 3.5, 3.5]) / 2.0


def facet_table(n_angles, mu=0.5, ds=(4, 8, 16, 32)):
    rows = []
    for d in ds:
        ang = short = du = 0.0
        for th in np.arange(n_angles) * 2 * np.pi / n_angles + 0.01:
            q = np.array([-1.0, 3.0 * math.cos(th), 3.0 * math.sin(th)])
            ref = local_solve(W_SPHERE, q, mu)
            sol = solve_polyhedral(W_SPHERE, q, mu, d=d)
            a, b = sol.r[1:], ref[1:]
            ang = max(ang, abs(math.atan2(a[0] * b[1] - a[1] * b[0], a @ b)))
            short = max(short, 1.0 - np.linalg.norm(a) / np.linalg.norm(b))
            du = max(du, np.linalg.norm(sol.u - (W_SPHERE @ ref + q)) / np.linalg.norm(q))
        rows.append((d, ang, short, du))
    return rows


def order(ds, errs):
    return -np.polyfit(np.log(ds), np.log(errs), 1)[0]


def random_problem(rng, nc):
    ndof = 3 * nc + 3
    H = rng.standard_normal((3 * nc, ndof))
    W = H @ np.diag(rng.uniform(0.5, 2.0, ndof)) @ H.T / ndof
    W = 0.5 * (W + W.T)
    q = rng.standard_normal(3 * nc)
    q[0::3] = -np.abs(q[0::3]) * rng.choice([1.0, 1.0, -1.0], nc)
    return W, q, rng.uniform(0.1, 0.8, nc)


def cpu_time(fn, repeat):
    times = []
    for _ in range(repeat):
        t = time.process_time()
        out = fn()
        times.append(time.process_time() - t)
    return float(np.median(times)), out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer directions and problems")
    args = ap.parse_args(argv)
    n_angles, n_problems, repeat = (72, 5, 5) if args.quick else (360, 20, 20)

    solve_exact(W_SPHERE, np.array([-1.0, 3.0, 4.0]), 0.5)          # compile first
    print(f"Facet table: sphere on a plane sliding, worst over {n_angles} directions")
    rows = facet_table(n_angles)
    print(f"{'d':>4} {'direction [rad]':>16} {'|r_T| shortfall':>16} {'|du|/|q|':>12}")
    for d, a, s, du in rows:
        print(f"{d:>4} {a:16.4e} {s:16.4e} {du:12.4e}")
    ds = np.array([r[0] for r in rows], dtype=float)
    for th in (0.3, 1.0):
        q = np.array([-1.0, 3.0 * math.cos(th), 3.0 * math.sin(th)])
        ref = local_solve(W_SPHERE, q, 0.5)
        errs = [np.linalg.norm(solve_polyhedral(W_SPHERE, q, 0.5, d=d).r - ref) / np.linalg.norm(ref)
                for d, *_ in rows]
        print(f"one direction, theta = {th}: |r - r_exact|/|r_exact| = "
              + ", ".join(f"{e:.3g}" for e in errs) + " (irregular: the polygon's vertices move)")
    print(f"fitted order in 1/d: direction {order(ds, [r[1] for r in rows]):.2f}, "
          f"magnitude {order(ds, [r[2] for r in rows]):.2f}, "
          f"velocity {order(ds, [r[3] for r in rows]):.2f}")

    print("\nTime per solve (CPU, median), random well-posed problems")
    print(f"{'nc':>4} {'exact [ms]':>11} {'sweeps':>7} {'newton':>7} {'max rel res':>12} "
          f"{'d=8 [ms]':>9} {'d=32 [ms]':>10} {'all certified':>14}")
    rng = np.random.default_rng(1)
    for nc in (1, 4, 16):
        te, t8, t32, sw, nw, rr, ok = [], [], [], [], [], [], True
        for _ in range(n_problems):
            W, q, mu = random_problem(rng, nc)
            t, ex = cpu_time(lambda: solve_exact(W, q, mu), repeat)
            te.append(t)
            sw.append(ex.iterations["sweeps"])
            nw.append(ex.iterations["newton"])
            rr.append(ex.relative_residual)
            t, p8 = cpu_time(lambda: solve_polyhedral(W, q, mu, d=8), repeat)
            t8.append(t)
            t, p32 = cpu_time(lambda: solve_polyhedral(W, q, mu, d=32), max(1, repeat // 4))
            t32.append(t)
            ok &= ex.success and p8.success and p32.success
        print(f"{nc:>4} {1e3 * np.median(te):11.3f} {np.median(sw):7.0f} {np.median(nw):7.0f} "
              f"{max(rr):12.2e} {1e3 * np.median(t8):9.3f} {1e3 * np.median(t32):10.3f} "
              f"{str(ok):>14}")


if __name__ == "__main__":
    main()
