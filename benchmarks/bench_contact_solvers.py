"""Time per solve of the sparse 2D contact solvers against the contacts: NSGS, APGD, Siconos's NSGS.

Two families of FCLib-form problems (``moreau.contact._sparse``):

``chain``
    the struck chain of ``N`` equal disks, ``e = 1``, frictionless
    (:func:`chain_impact_problem`: ``N - 1`` contacts, the exact block result
    known); the worst case of Gauss–Seidel (a 1D Laplacian: plain NSGS needs
    of the order of ``N^2`` sweeps), so NSGS also runs over-relaxed
    (``nsgs_sor``, ``omega = 2 / (1 + sin(pi / N))``, the optimum of SOR for
    this matrix);
``stack``
    one granular step: 5 rows of disks on the ground, ``cols`` wide, in a
    square packing under gravity with random velocities, ``mu = 0.5``
    (:func:`stacked_disks_problem`: ``5 (2 cols - 1)`` contacts, hyperstatic).

Per problem and solver, two timings (CPU time, ``time.process_time``, median of
``--repeat`` rounds; a solve longer than 2 s is timed once):

``fixed``
    ``--sweeps`` sweeps (NSGS) or gradient steps (APGD), one residual check:
    the cost of a sweep, which should grow linearly in the contacts;
``to_tol``
    a solve from zero impulses to ``--tol`` (the natural-map residual over
    ``1 + ||q||``) within ``--budget`` sweeps or steps; the residual of the
    impulses returned is recomputed here for every solver, Siconos's
    included, and a solve that did not reach the tolerance says so.

Siconos's ``fc2d`` NSGS (``SICONOS_FRICTION_2D_NSGS`` on its sparse block
matrix) runs the same problems in the same run through
``benchmarks/siconos_fc2d_peer.py`` under ``/usr/bin/python3``, when that
interpreter has Siconos and scipy (its own tolerance set to ``--tol``; its
``fixed`` run has tolerance 0 and ``--sweeps`` sweeps). Its error is not our residual (its answers at its
``--tol`` had our residual 2 to 5 times larger), so it also runs at
``--tol / 10`` (``to_tol/10``): the two bracket equal residual.

``--crossover`` times, on short frictional chains (``mu = 0.3``, ``W``
positive definite), the dense path (``W`` dense, the friction LCP, Lemke)
against the sparse one (CSR ``W``, NSGS to 1e-10): the size above which the
dense path is slower.

Run: ``python benchmarks/bench_contact_solvers.py [--quick] [--no-siconos]
[--crossover] --out DIR``; writes ``contact_solvers.csv`` and
``contact_solvers.json`` to ``DIR`` and prints the tables.
"""

import os

# one BLAS thread: every solver here, and Siconos, runs on one core
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from moreau.contact._sparse import (chain_impact_problem, problem_residual,  # noqa: E402
                                    stacked_disks_problem)
from moreau.contact.solvers.apgd import solve_apgd  # noqa: E402
from moreau.contact.solvers.nsgs import solve_nsgs  # noqa: E402
from moreau.lcp import solve_lcp  # noqa: E402
from moreau.lcp.friction import build_friction_lcp  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
PEER = os.path.join(HERE, "siconos_fc2d_peer.py")


def cpu_median(fn, repeat):
    """Median CPU time of ``fn()``; one untimed warm-up; a call over 2 s is timed once.

    The solvers are compiled before (in :func:`main`), so the first call is a solve."""
    t0 = time.process_time()
    out = fn()
    first = time.process_time() - t0
    if first > 2.0:
        return first, out
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return statistics.median(times), out


def problems(quick):
    chain = (100, 1000) if quick else (100, 1000, 10_000)
    stack = (20, 200) if quick else (20, 200, 1000)
    for N in chain:
        W, q, mu, r = chain_impact_problem(N, e=1.0)
        yield f"chain-{N}", "chain", (W, q, mu), {"omega": 2.0 / (1.0 + math.sin(math.pi / N))}, r
    for c in stack:
        W, q, mu = stacked_disks_problem(5, c, mu=0.5)
        yield f"stack-5x{c}", "stack", (W, q, mu), None, None


def run_ours(name, data, sor, args):
    W, q, mu = data
    S = args.sweeps
    rows = []
    solvers = {
        "nsgs": lambda **k: solve_nsgs(W, q, mu, **k),
        "apgd": lambda **k: solve_apgd(W, q, mu, **{("max_iter" if kk == "max_sweeps" else kk): v
                                                    for kk, v in k.items()}),
    }
    if sor:
        solvers["nsgs_sor"] = lambda **k: solve_nsgs(W, q, mu, omega=sor["omega"], **k)
    for solver, fn in solvers.items():
        t, res = cpu_median(lambda: fn(tol=1e-15, max_sweeps=S, check_every=S), args.repeat)
        rows.append({"problem": name, "solver": solver, "run": "fixed", "iterations": res.iterations,
                     "seconds": t, "per_sweep_s": t / res.iterations, "residual": res.residual,
                     "status": res.status})
        t, res = cpu_median(lambda: fn(tol=args.tol, max_sweeps=args.budget), args.repeat)
        rows.append({"problem": name, "solver": solver, "run": "to_tol", "iterations": res.iterations,
                     "seconds": t, "per_sweep_s": t / max(res.iterations, 1),
                     "residual": res.residual, "status": res.status})
        print(f"  {name:12s} {solver:9s} fixed {rows[-2]['seconds']:.3e} s  to_tol {t:.3e} s "
              f"({res.iterations} it, residual {res.residual:.1e}, {res.status})", flush=True)
    return rows


def run_siconos(items, args, tmp):
    files = []
    for name, _, (W, q, mu), _, _ in items:
        path = os.path.join(tmp, f"{name}.npz")
        np.savez(path, indptr=W.indptr, indices=W.indices, data=W.data, q=q, mu=mu)
        files.append({"name": name, "file": path})
    job = {"problems": files, "rounds": args.repeat, "budget": 0.2, "out": tmp,
           "runs": [{"tol": 0.0, "max_iter": args.sweeps},
                    {"tol": args.tol, "max_iter": args.budget},
                    {"tol": args.tol / 10, "max_iter": args.budget}]}
    try:
        proc = subprocess.run(["/usr/bin/python3", PEER], input=json.dumps(job), text=True,
                              capture_output=True, timeout=3600)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return None, f"peer did not run: {exc}"
    try:
        answer = json.loads(proc.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        return None, f"peer failed: {proc.stderr.strip()[-300:]}"
    if not answer.get("available"):
        return None, answer.get("reason")
    data = {name: d for name, _, d, _, _ in items}
    rows = []
    for res in answer["results"]:
        W, q, mu = data[res["name"]]
        r = np.load(res["r_file"])
        ours, _, _ = problem_residual(W, q, mu, r)
        t = statistics.median(res["seconds"])
        it = res["iterations"]
        run = ("fixed", "to_tol", "to_tol/10")[res["run"]]
        status = "converged" if ours <= args.tol else "not converged"
        rows.append({"problem": res["name"], "solver": "siconos_nsgs", "run": run, "iterations": it,
                     "seconds": t, "per_sweep_s": t / max(it, 1), "residual": ours,
                     "status": status, "siconos_error": res["error"], "siconos_info": res["info"]})
        print(f"  {res['name']:12s} siconos   {run:6s} {t:.3e} s ({it} it, our residual {ours:.1e}, "
              f"its error {res['error']:.1e}, info {res['info']})", flush=True)
    return rows, answer.get("version")


def crossover(args):
    """Dense (Lemke on the friction LCP) against sparse (NSGS on CSR) on short frictional chains.

    The chain with ``mu = 0.3`` has a positive definite ``W`` (two rows a contact, three
    degrees of freedom a disk), where Lemke is at its best; on the hyperstatic stacks
    (singular ``W``) it is far slower (0.9 s at 18 contacts, 9.7 s at 30 in a first run).
    """
    rows = []
    for N in (3, 5, 9, 17, 33, 65, 129):
        W, q, mu, _ = chain_impact_problem(N, e=1.0, mu=0.3)
        nc = mu.shape[0]
        order = np.concatenate([2 * np.arange(nc), 2 * np.arange(nc) + 1])

        def dense():
            Wd = W.toarray()
            M, qq, _ = build_friction_lcp(Wd[np.ix_(order, order)], q[order], mu, 0.0, np.zeros(nc))
            return solve_lcp(M, qq, method="lemke")

        def sparse():
            return solve_nsgs(W, q, mu, tol=1e-10, max_sweeps=10**6,
                              omega=2.0 / (1.0 + math.sin(math.pi / N)))

        td, lem = cpu_median(dense, args.repeat)
        ts, res = cpu_median(sparse, args.repeat)
        rows.append({"contacts": nc, "dense_lemke_s": td, "lemke_ok": bool(lem.success),
                     "sparse_nsgs_s": ts, "nsgs_sweeps": res.iterations,
                     "nsgs_residual": res.residual})
        print(f"  {nc:4d} contacts: dense Lemke {td:.2e} s, NSGS (SOR) {ts:.2e} s "
              f"({res.iterations} sweeps, residual {res.residual:.1e})", flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="chain to N = 1000, stack to 200 wide")
    ap.add_argument("--no-siconos", action="store_true")
    ap.add_argument("--crossover", action="store_true", help="also time dense Lemke against sparse NSGS on short chains")
    ap.add_argument("--sweeps", type=int, default=100, help="sweeps of the fixed-cost run")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--budget", type=int, default=20_000, help="sweeps / steps of a to_tol solve")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    items = list(problems(args.quick))
    # compile (or load) the solvers before any timing: cpu_median times a long first call once
    W, q, mu, _ = chain_impact_problem(3)
    solve_nsgs(W, q, mu)
    solve_nsgs(W, q, mu, omega=1.5)
    solve_apgd(W, q, mu)
    rows = []
    print("ours:")
    for name, _, data, sor, _ in items:
        rows += run_ours(name, data, sor, args)
    version = None
    if not args.no_siconos:
        print("siconos:")
        with tempfile.TemporaryDirectory() as tmp:
            sic, version = run_siconos(items, args, tmp)
        if sic is None:
            print(f"  siconos left out: {version}")
        else:
            rows += sic
    contacts = {name: d[2].shape[0] for name, _, d, _, _ in items}
    for row in rows:
        row["contacts"] = contacts[row["problem"]]
    summary = {"rows": rows, "siconos_version": version, "args": vars(args)}
    if args.crossover:
        print("crossover (frictional chains):")
        summary["crossover"] = crossover(args)
    keys = ["problem", "contacts", "solver", "run", "iterations", "seconds", "per_sweep_s",
            "residual", "status", "siconos_error", "siconos_info"]
    with open(os.path.join(args.out, "contact_solvers.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for row in rows:
            w.writerow({k: row.get(k, "") for k in keys})
    with open(os.path.join(args.out, "contact_solvers.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print("\nper-sweep cost (fixed run), microseconds per sweep / contacts:")
    table = {}
    for row in rows:
        table.setdefault((row["problem"], row["contacts"]), {})[(row["solver"], row["run"])] = row
    solvers = ["nsgs", "nsgs_sor", "apgd", "siconos_nsgs"]
    print(f"{'problem':14s}{'contacts':>9s}" + "".join(f"{s:>22s}" for s in solvers))
    for (name, nc), cells in table.items():
        line = f"{name:14s}{nc:9d}"
        for s in solvers:
            c = cells.get((s, "fixed"))
            line += f"{'':>22s}" if c is None else f"{1e6 * c['per_sweep_s']:>12.1f} ({1e9 * c['per_sweep_s'] / nc:5.0f} ns)"
        print(line)
    print("\ntime to tolerance (s, iterations, our residual):")
    print(f"{'problem':14s}{'contacts':>9s}" + "".join(f"{s:>26s}" for s in solvers)
          + f"{'siconos at tol/10':>26s}")
    for (name, nc), cells in table.items():
        line = f"{name:14s}{nc:9d}"
        for key in [(s, "to_tol") for s in solvers] + [("siconos_nsgs", "to_tol/10")]:
            c = cells.get(key)
            line += f"{'':>26s}" if c is None else \
                f"{c['seconds']:>10.3e} {c['iterations']:>6d} {c['residual']:>8.1e} "
        print(line)


if __name__ == "__main__":
    main()
