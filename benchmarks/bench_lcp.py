"""Benchmark of the LCP solvers against the peers a user would otherwise pick.

Runs the same instances, side by side in one process, through

* ``moreau``: ``solve_lcp(M, q)`` (Lemke, input checked), the lean path
  ``check_input=False``, and ``lemke_kernel`` called from a compiled loop
  (what the Moreau-Jean stepper does: no Python per solve);
* QuantEcon's ``quantecon.optimize.lcp_lemke`` (numba-compiled Lemke);
* the PyPI package ``lemkelcp`` (pure Python/NumPy). Its release 0.1
  assigns into a ``range`` object and raises ``TypeError`` on Python 3 as
  soon as ``q`` has a negative entry; that counts as a failure, and a
  second column times it with that one attribute patched into a list so
  that its speed can still be compared.

Timings are CPU time of this process (``time.process_time``, so that other
work on a shared machine does not count), medians over interleaved rounds
in which every solver runs a batch; ratios are ``moreau / peer`` in the same
run. Correctness: a solve counts as correct when the solver
reports success and ``z`` has a scaled residual (``moreau.lcp.lcp_residual``)
``<= 1e-8``; on infeasible instances, when it reports failure.

With ``--siconos``, instead: ``solve_lcp(M, q)`` against Siconos's
lexicographic Lemke (``sn.lcp_lexicolemke``, run by
``benchmarks/siconos_lcp_peer.py`` under ``/usr/bin/python3``, timed inside
that process per call: building ``sn.LCP(M, q)`` and solving, as a user with
new data does) on a test set of this project's own families (P-matrix, PSD,
non-monotone, degenerate, bimatrix; n = 2 to 40), interleaved with our
timings in the same run. It prints each problem's times and ratio, the
geometric mean of the ratios over the problems both solve and the largest.

Usage::

    python benchmarks/bench_lcp.py            # full run, a few minutes
    python benchmarks/bench_lcp.py --quick    # smaller sizes, fewer repeats
    python benchmarks/bench_lcp.py --siconos  # against Siconos's Lemke

Nothing is written to disk. Peers that are not installed are skipped with
a message (``pip install quantecon lemkelcp``).
"""

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from numba import njit  # noqa: E402

from moreau.lcp import lcp_residual, lcp_violation, lemke_kernel, solve_lcp  # noqa: E402
from moreau.lcp.instances import (  # noqa: E402
    classic_instances,
    random_friction,
    random_p_matrix,
)

RES_TOL = 1e-8

try:
    from quantecon.optimize import lcp_lemke as _qe_lcp_lemke
except ImportError:  # pragma: no cover - benchmark-only peer
    _qe_lcp_lemke = None
    print("quantecon is not installed: its column is skipped (pip install quantecon)")

try:
    from lemkelcp.lemkelcp import lemkelcp as _lk_solve
    from lemkelcp.lemkelcp import lemketableau as _lk_tableau
except ImportError:  # pragma: no cover - benchmark-only peer
    _lk_solve = None
    _lk_tableau = None
    print("lemkelcp is not installed: its columns are skipped (pip install lemkelcp)")


# -- uniform adapters: each returns (success, z) ------------------------------

def run_moreau(M, q, max_iter=None):
    r = solve_lcp(M, q, max_iter=max_iter)
    return r.success, r.z


def run_moreau_lean(M, q, max_iter=None):
    r = solve_lcp(M, q, max_iter=max_iter, check_input=False)
    return r.success, r.z


# compiled in memory: an on-disk cache would be written into benchmarks/__pycache__
@njit
def _kernel_loop(M, q, z, w, reps):
    st = 0
    for _ in range(reps):
        st, piv, res = lemke_kernel(M, q, z, w, 100000, 1e-9)
    return st


def run_qe(M, q, max_iter=None):
    # QuantEcon's own default limit (10^6 pivots) in every case
    r = _qe_lcp_lemke(M, q)
    return bool(r.success), r.z


def _lk_iters(n, max_iter):
    return max(1000, 50 * n) if max_iter is None else max_iter


def run_lemkelcp(M, q, max_iter=None):
    # the published entry point, as a user would call it
    z, code, _ = _lk_solve(M, q, _lk_iters(len(q), max_iter))
    return code == 0 and z is not None, z


def run_lemkelcp_patched(M, q, max_iter=None):
    t = _lk_tableau(M, q, _lk_iters(len(q), max_iter))
    t.wPos = list(t.wPos)
    t.zPos = list(t.zPos)
    z, code, _ = t.lemkeAlgorithm()
    return code == 0 and z is not None, z


def solvers():
    out = [("moreau", run_moreau), ("moreau-lean", run_moreau_lean)]
    if _qe_lcp_lemke is not None:
        out.append(("quantecon", run_qe))
    if _lk_solve is not None:
        out.append(("lemkelcp", run_lemkelcp))
        out.append(("lemkelcp*", run_lemkelcp_patched))
    return out


def outcome(fn, M, q, feasible, max_iter=None):
    """'ok', 'FAIL' (wrong answer or status) or 'ERR' (raised)."""
    try:
        success, z = fn(M, q, max_iter)
    except Exception:
        return "ERR"
    if not feasible:
        return "ok" if not success else "FAIL"
    if success and z is not None and np.all(np.isfinite(z)) and lcp_residual(M, q, z) <= RES_TOL:
        return "ok"
    return "FAIL"


def time_per_call(fns, rounds, budget=0.02):
    """CPU seconds per call of each function, one sample per interleaved round.

    Returns a list (one per function) of per-round samples. A function whose
    single call takes longer than 50 ms is sampled once.
    """
    clock = time.process_time
    numbers = []
    for fn in fns:
        fn()  # warm-up (compilation, caches)
        t0 = time.perf_counter()
        fn()
        dt = time.perf_counter() - t0
        numbers.append(0 if dt > 0.05 else max(1, min(5000, int(budget / max(dt, 1e-7)))))
    samples = [[] for _ in fns]
    for r in range(rounds):
        for k, fn in enumerate(fns):
            num = numbers[k]
            if num == 0:
                if r > 0:
                    continue
                num = 1
            t0 = clock()
            for _ in range(num):
                fn()
            samples[k].append((clock() - t0) / num)
    return samples


def bench_instances(quick):
    rng = np.random.default_rng(0)
    out = []
    f1 = random_friction(1, np.random.default_rng(1))
    out.append(("friction 1 contact (4 vars)", f1.M, f1.q, True, None))
    for nc in ((5, 20) if quick else (5, 20, 50)):
        f = random_friction(nc, np.random.default_rng(nc))
        out.append((f"friction {nc} contacts", f.M, f.q, True, None))
    for n in ((4, 10, 30, 100) if quick else (2, 4, 10, 30, 60, 100, 200, 300)):
        M = random_p_matrix(n, rng)
        q = rng.standard_normal(n)
        out.append((f"random P-matrix n={n}", M, q, True, None))
    for inst in classic_instances(murty_orders=(8,) if quick else (8, 12)):
        # Murty's examples need more pivots than the default limit
        out.append((inst.name, inst.M, inst.q, inst.expect != "ray", inst.max_iter))
    return out


PEER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "siconos_lcp_peer.py")


def peer_instances():
    """The test set of ``--siconos``: this project's families, n = 2 to 40 (seeded)."""
    from moreau.lcp.instances import random_psd

    rng = np.random.default_rng(33)
    out = []
    for n in (2, 5, 10, 20, 40):
        out.append((f"P-matrix n={n}", random_p_matrix(n, rng), rng.standard_normal(n)))
    for n in (4, 12, 30):
        M, q, _, _ = random_psd(n, max(1, n // 2), rng)
        out.append((f"PSD rank n/2 n={n}", M, q))
    for n in (3, 8, 20):
        # non-monotone: integer, indefinite symmetric part, positive diagonal
        M = rng.integers(-3, 4, (n, n)).astype(float)
        M[np.diag_indices(n)] = rng.integers(1, 4, n)
        out.append((f"non-monotone n={n}", M, -rng.integers(0, 3, n).astype(float) - 0.5))
    for n in (6, 15, 40):
        # degenerate: few distinct rows and columns (tenths), q mostly zeros
        k = 3
        base = rng.integers(-1, 4, (k, k)).astype(float) * 0.1
        M = base[rng.integers(0, k, n)][:, rng.integers(0, k, n)] + rng.integers(0, 3, (n, n)) * 0.1
        M[np.diag_indices(n)] = np.abs(M[np.diag_indices(n)]) + 0.1
        q = rng.integers(-2, 3, n).astype(float)
        q[rng.random(n) < 0.6] = 0.0
        q[0] = -1.0
        out.append((f"degenerate n={n}", M, q))
    for m in (2, 5):
        # bimatrix games, positive payoffs: Lemke with covering ones ends on a ray
        A = rng.integers(1, 7, (m, m)).astype(float)
        B = rng.integers(1, 7, (m, m)).astype(float)
        M = np.zeros((2 * m, 2 * m))
        M[:m, m:] = A
        M[m:, :m] = B.T
        out.append((f"bimatrix {m}x{m}", M, -np.ones(2 * m)))
    for n in (4, 10):
        M = np.triu(rng.integers(1, 3, (n, n)).astype(float))  # P-matrix, integer, degenerate q
        q = -rng.integers(0, 2, n).astype(float)
        q[-1] = -1.0
        out.append((f"triangular integer n={n}", M, q))
    return out


def run_peer(problems, rounds, budget):
    """Siconos's per-call times, or None with the reason printed."""
    import json
    import subprocess

    job = {"problems": [{"M": M.tolist(), "q": q.tolist()} for _, M, q in problems],
           "rounds": rounds, "budget": budget, "max_iter": 100000}
    try:
        proc = subprocess.run(["/usr/bin/python3", PEER], input=json.dumps(job), text=True,
                              capture_output=True, timeout=1800)
        data = json.loads(proc.stdout)
    except (OSError, ValueError, subprocess.SubprocessError) as exc:
        print(f"Siconos peer not run: {exc}")
        return None
    if not data.get("available"):
        print(f"Siconos peer not available: {data.get('reason')}")
        return None
    return data


def siconos_comparison(quick):
    """Per-call time of solve_lcp against Siconos's lexicographic Lemke, in alternating batches."""
    problems = peer_instances()
    alternations = 2 if quick else 3
    rounds = 3 if quick else 5
    ours = [[] for _ in problems]
    peer = [[] for _ in problems]
    peer_solve = [[] for _ in problems]
    info = None
    for _ in range(alternations):
        data = run_peer(problems, rounds, 0.02)
        if data is None:
            return
        info = data["results"]
        for k, r in enumerate(info):
            peer[k] += r["times"]
            peer_solve[k] += r["solve_s"]
        for k, (_, M, q) in enumerate(problems):
            ours[k] += time_per_call([lambda M=M, q=q: solve_lcp(M, q)], rounds)[0]
    print(f"solve_lcp(M, q) against Siconos {data['version']} sn.lcp_lexicolemke (build sn.LCP + "
          f"solve), CPU microseconds per call, median of {alternations * rounds} batches; "
          f"ratio = moreau / Siconos")
    head = (f"{'problem':28s} {'n':>3s} {'moreau':>9s} {'status':>7s} {'siconos':>9s} {'info':>4s}"
            f" {'ratio':>6s} {'sic. solve only':>15s}")
    print(head)
    print("-" * len(head))
    both = []
    for k, (name, M, q) in enumerate(problems):
        res = solve_lcp(M, q)
        zp = np.array(info[k]["z"])
        ok_peer = info[k]["info"] == 0 and lcp_violation(M, q, zp) <= 1e-9
        t_ours = float(np.median(ours[k]))
        t_peer = float(np.median(peer[k]))
        ratio = t_ours / t_peer
        if res.success and ok_peer:
            both.append(ratio)
        print(f"{name:28s} {len(q):3d} {fmt_us(t_ours):>9s} {res.status:7d} {fmt_us(t_peer):>9s}"
              f" {info[k]['info']:4d}{'' if ok_peer or info[k]['info'] else '!'} {ratio:6.2f}"
              f" {fmt_us(float(np.median(peer_solve[k]))):>15s}")
    if both:
        print(f"\nover the {len(both)} problems both solve: geometric mean ratio "
              f"{float(np.exp(np.mean(np.log(both)))):.2f}, largest {max(both):.2f}")


def fmt_us(t):
    if t is None:
        return "-"
    us = t * 1e6
    return f"{us:.1f}" if us < 1e4 else f"{us:.3g}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes and fewer repeats")
    ap.add_argument("--siconos", action="store_true",
                    help="per-call time against Siconos's lexicographic Lemke (/usr/bin/python3)")
    args = ap.parse_args(argv)
    if args.siconos:
        siconos_comparison(args.quick)
        return
    rounds = 7 if args.quick else 21
    n_robust = 60 if args.quick else 300

    names = [n for n, _ in solvers()]
    print(f"LCP benchmark ({'quick' if args.quick else 'full'}): median CPU time per solve in microseconds, "
          f"{rounds} interleaved rounds")
    print("moreau = solve_lcp(M, q); lean = check_input=False; kernel = lemke_kernel called from a compiled loop")
    print("ratio = median over rounds of moreau / peer timed back to back (< 1: moreau faster); "
          "'!' marks a wrong answer, 'E' an exception\n")
    head = (f"{'instance':30s} {'n':>4s} {'moreau':>9s} {'lean':>9s} {'kernel':>9s}"
            f" {'quantecon':>10s} {'ratio':>6s} {'lemkelcp*':>10s} {'ratio':>7s}")
    print(head)
    print("-" * len(head))
    worst_qe = None
    for name, M, q, feasible, max_iter in bench_instances(args.quick):
        n = len(q)
        fns = dict(solvers())
        marks = {k: outcome(fn, M, q, feasible, max_iter) for k, fn in fns.items()}
        calls = []
        keys = []
        for k in ("moreau", "moreau-lean", "quantecon", "lemkelcp*"):
            if k in fns and not (k == "lemkelcp*" and marks[k] == "ERR"):
                keys.append(k)
                calls.append(lambda fn=fns[k]: fn(M, q, max_iter))
        z = np.empty(n)
        w = np.empty(n)
        keys.append("kernel")
        reps = 20
        calls.append(lambda: _kernel_loop(M, q, z, w, reps))
        samples = dict(zip(keys, time_per_call(calls, rounds)))
        samples["kernel"] = [t / reps for t in samples["kernel"]]
        times = {k: float(np.median(v)) for k, v in samples.items()}

        def paired_ratio(peer):
            # median over rounds of moreau/peer measured back to back, which
            # cancels most of the drift of a shared machine
            a, b = samples["moreau"], samples[peer]
            if len(b) < len(a):
                return times["moreau"] / times[peer]
            return float(np.median(np.array(a) / np.array(b)))

        def cell(k):
            t = times.get(k)
            s = fmt_us(t)
            m = marks.get(k, "ok")
            return s + ("" if m == "ok" else ("!" if m == "FAIL" else "E"))

        r_qe = paired_ratio("quantecon") if "quantecon" in times else None
        r_lk = paired_ratio("lemkelcp*") if "lemkelcp*" in times else None
        if r_qe is not None and marks.get("quantecon") == "ok":
            worst_qe = r_qe if worst_qe is None else max(worst_qe, r_qe)
        print(f"{name:30s} {n:4d} {cell('moreau'):>9s} {cell('moreau-lean'):>9s} {fmt_us(times['kernel']):>9s}"
              f" {cell('quantecon'):>10s} {('-' if r_qe is None else f'{r_qe:.2f}'):>6s}"
              f" {cell('lemkelcp*'):>10s} {('-' if r_lk is None else f'{r_lk:.3f}'):>7s}")
    if worst_qe is None:
        print("\nno moreau/quantecon ratio: the peer is missing (pip install quantecon) or "
              "solved no instance")
    else:
        print(f"\nworst moreau/quantecon ratio over the instances both solve: {worst_qe:.2f}")
    if "lemkelcp" in dict(solvers()):
        print("lemkelcp 0.1 as published (without the patch) raised an exception on every instance with a "
              "negative q entry; 'lemkelcp*' is the same code with `wPos`/`zPos` turned into lists.")

    # -- robustness: random 2D friction LCPs, 5-40 contacts -----------------
    print(f"\nrandom 2D friction LCPs with 5-40 contacts ({n_robust} instances, "
          f"Delassus W = J Mass^-1 J^T, mu in [0.05, 1] with 20% mu = 0, e in [0, 1]):")
    rng = np.random.default_rng(12345)
    fails = {k: 0 for k in names}
    fails["moreau auto"] = 0
    errors = {k: 0 for k in names}
    t0 = time.perf_counter()
    for _ in range(n_robust):
        inst = random_friction(int(rng.integers(5, 41)), rng)
        for k, fn in solvers():
            mark = outcome(fn, inst.M, inst.q, True, None)
            if mark != "ok":
                fails[k] += 1
                errors[k] += mark == "ERR"
        r = solve_lcp(inst.M, inst.q, method="auto", friction=inst.layout)
        if not (r.success and lcp_residual(inst.M, inst.q, r.z) <= RES_TOL):
            fails["moreau auto"] += 1
    for k, v in fails.items():
        extra = f" ({errors[k]} raised)" if errors.get(k) else ""
        print(f"  {k:14s} failed on {v:4d} / {n_robust}{extra}")
    print(f"  ({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main()
