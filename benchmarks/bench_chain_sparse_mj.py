"""Moreau–Jean on the ball chain to N = 10 000 with the sparse contact solvers, against Siconos.

The chain of ``moreau.scenes.ball_chain`` in its dimensionless form (unit
balls of radius 1, the striker at speed 1, ``e = 1``, gap 1.1), stepped by
Moreau–Jean (``theta = 1``, ``h = 0.01`` over ``t* + 0.5``: 161 steps) with
the contact problem of every step in FCLib's layout and ``W`` in CSR (the
disks' ``(x, y, theta)`` Jacobian of :func:`moreau.contact._sparse.disk_jacobian`,
frictionless, so the tangential rows carry no impulse): ``M`` is diagonal,
``W = H M^-1 H^T`` is built once (the chain stays on its line, so ``H`` does
not change), and a step takes the rows of its index set
(``g + (h/2) g' <= 0``, Moreau–Jean's) from it. Nothing is dense: the cost
of a step is that of its solve.

Solvers: ``nsgs`` (over-relaxed at ``omega = 2 / (1 + sin(pi / N))``, SOR's
optimum for the chain's tridiagonal ``W``: plain NSGS needs of the order of
``N^2`` sweeps on the pressed chain, out of reach at N = 10 000) and
``apgd``, both to the natural-map tolerance ``--tol`` from zero impulses,
and for N <= 100 the dense Lemke of ``moreau.lcp``. Each run's final
velocities are held to the exact block result (every ball but the striker
at ``2 / N``, the striker at ``2 / N - 1``): the largest deviation is a
column. Siconos's Moreau–Jean (``MoreauJeanOSI`` + ``LCP``) runs the same
chain by ``benchmarks/siconos_peer.py`` (N = 100; its dense LCP at 1000 and
more is out of reach), and Siconos's 2D NSGS the impact step's problem by
``bench_contact_solvers.py`` (N = 1000, 10 000).

Run: ``python benchmarks/bench_chain_sparse_mj.py [--sizes 100 1000 10000] [--no-siconos]``.

``--scaling`` gives the scaling table of the package's own Moreau–Jean
(:class:`moreau.integrators.moreau_jean.MoreauJean` on the ``ball-chain``
scene, its default window ``t* + 2`` cut to ``t* + 0.5``, ``h = 0.01``)
with ``lcp_method`` ``"auto"`` (the compiled dense Lemke below 150 balls,
the sparse active set from there), ``"nsgs"`` (``lcp_omega`` at
:func:`moreau.scenes.ball_chain.sor_omega`) and ``"apgd"``, CPU time
(``time.process_time``), medians of ``--repeats`` runs:

* at a fixed number of sweeps (``--sweeps``, 100): the impact step of a
  run with ``lcp_max_iter`` = sweeps and ``lcp_tol`` = 1e-15, which the
  step does not reach (it fails, status -3, after exactly that many sweeps or
  gradient steps): the whole step's cost, assembly, layout and checks included;
* at the tolerance (``--tol``, 1e-8): the run's mean cost a step, the
  impact step's, its sweeps, and the velocities after it against the exact
  block result (:func:`moreau.scenes.ball_chain.simultaneous_impact`) with
  the bound ``(1 + lambda_max) / sqrt(lambda_min) tol (1 + ||q||)`` derived
  in ``tests/scenes/test_ball_chain_iterative.py``, and at the end of the run (50 steps
  later: Moreau–Jean with ``e = 1`` amplifies a perturbation of the touching chain, so
  the impact's error grows there; the bound holds for the impact step only).

``python benchmarks/bench_chain_sparse_mj.py --scaling [--sizes ...] [--repeats 3]``.

``--orders`` counts the sweeps of projected Gauss–Seidel on the struck
chain's frictionless LCP (``W = tridiag(-1, 2, -1)``, ``q = (-2, 0, ...)``)
to the natural map ``--tol`` in three orders along the chain (from the
striker, towards it, and symmetric: one each way, two sweeps), plain and at
:func:`moreau.scenes.ball_chain.sor_omega`: a sweep is one pass over the
contacts, what NSGS's sweep costs.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from numba import njit  # noqa: E402

from moreau.contact._sparse import delassus, disk_jacobian  # noqa: E402
from moreau.contact.solvers.apgd import solve_apgd  # noqa: E402
from moreau.contact.solvers.nsgs import solve_nsgs  # noqa: E402
from moreau.integrators.moreau_jean import MoreauJean  # noqa: E402
from moreau.lcp import solve_lcp  # noqa: E402
from moreau.scenes.ball_chain import (SPARSE_FROM, BallChain, simultaneous_impact,  # noqa: E402
                                      sor_omega)

HERE = os.path.dirname(os.path.abspath(__file__))
H, E, GAP = 0.01, 1.0, 1.1


def chain(N):
    """``(WN rows as CSR over x-velocities, W in FCLib layout)`` of the straight chain."""
    centres = np.column_stack([2.0 * np.arange(N), np.zeros(N)])
    contacts = [(i, i + 1, (centres[i, 0] + 1.0, 0.0), (1.0, 0.0)) for i in range(N - 1)]
    Hd = disk_jacobian(contacts, centres, N)
    W = delassus(Hd, np.tile([1.0, 1.0, 2.0], (N, 1)))
    return Hd, W


def run(N, solver, tol):
    Hd, W = chain(N)
    Hx = Hd[:, 0::3]                      # the x columns: the chain moves on its line
    HxT = Hx.T.tocsr()
    q = 2.0 * np.arange(N) - 2.0
    q[0] -= GAP
    v = np.zeros(N)
    v[0] = 1.0
    t_end = GAP + 0.5
    steps = int(math.ceil(t_end / H - 1e-9))
    omega = 2.0 / (1.0 + math.sin(math.pi / N))
    sweeps = 0
    worst_res = 0.0
    t0 = time.process_time()
    for _ in range(steps):
        U = Hx @ v                       # [u_N0, u_T0, u_N1, ...]: u_T = 0 on the line
        g = q[1:] - q[:-1] - 2.0
        act = np.flatnonzero(g + 0.5 * H * U[0::2] <= 0.0)
        if act.size:
            rows = np.column_stack([2 * act, 2 * act + 1]).ravel()
            Wa = W[rows][:, rows]
            qa = U[rows].copy()
            qa[0::2] += E * np.minimum(U[rows][0::2], 0.0)   # Newton's law folded in
            mu = np.zeros(act.size)
            if solver == "nsgs":
                res = solve_nsgs(Wa, qa, mu, tol=tol, max_sweeps=10 ** 7, omega=omega)
            elif solver == "apgd":
                res = solve_apgd(Wa, qa, mu, tol=tol, max_iter=10 ** 7)
            else:
                lcp = solve_lcp(Wa.toarray()[0::2, 0::2], qa[0::2], method="lemke")
                r = np.zeros_like(qa)
                r[0::2] = lcp.z
                res = None
            if res is not None:
                r = res.r
                sweeps += res.iterations
                worst_res = max(worst_res, res.residual)
                if not res.converged:
                    raise RuntimeError(f"{solver} N={N}: {res.message}")
            p = np.zeros(2 * (N - 1))
            p[rows] = r
            v = v + HxT @ p
        q = q + H * v
    dt = time.process_time() - t0
    w = 2.0 / N
    exact = np.full(N, w)
    exact[0] = w - 1.0
    return {"N": N, "solver": solver, "steps": steps, "seconds": dt,
            "us_per_step": dt / steps * 1e6, "sweeps": sweeps, "worst_residual": worst_res,
            "v_error": float(np.max(np.abs(v - exact)))}


def siconos_mj(N):
    par = {"sizes": [N], "ratio": 1.0, "e": E, "gap": GAP, "h": H, "t_end": GAP + 0.5}
    out = subprocess.run(["/usr/bin/python3", os.path.join(HERE, "siconos_peer.py"), "--case",
                          "ball-chain", "--repeats", "3", "--chain-params", json.dumps(par)],
                         capture_output=True, text=True, timeout=3600)
    if out.returncode:
        return {"error": out.stderr[-300:]}
    return json.loads(out.stdout)


@njit(cache=False)
def _projected_sor(n, omega, order, tol, max_sweeps):
    # order 0: from the striker, 1: towards it, 2: one each way; returns sweeps or -1
    p = np.zeros(n)
    q = np.zeros(n)
    q[0] = -2.0
    sweeps = 0
    while sweeps < max_sweeps:
        for k in range(2 if order == 2 else 1):
            forward = order == 0 or (order == 2 and k == 0)
            for j in range(n):
                i = j if forward else n - 1 - j
                b = q[i] - (p[i - 1] if i > 0 else 0.0) - (p[i + 1] if i < n - 1 else 0.0)
                p[i] = max(0.0, p[i] + omega * (max(0.0, -0.5 * b) - p[i]))
            sweeps += 1
        s = 0.0
        for i in range(n):
            u = q[i] + 2.0 * p[i] - (p[i - 1] if i > 0 else 0.0) - (p[i + 1] if i < n - 1 else 0.0)
            f = min(p[i], u)
            s += f * f
        if math.sqrt(s) / 3.0 <= tol:
            return sweeps
    return -1


def sweep_orders(sizes, tol):
    """Sweeps to ``tol`` of projected (S)SOR on the struck chain in each order (module docstring)."""
    rows = []
    for N in sizes:
        om = sor_omega(np.ones(N))
        for omega in (1.0, om):
            budget = 4 * N * N if omega == 1.0 else 100 * N
            row = {"N": N, "omega": omega}
            for order, name in enumerate(("from the striker", "towards it", "symmetric")):
                row[name] = int(_projected_sor(N - 1, omega, order, tol, budget))
            rows.append(row)
            print(json.dumps(row), flush=True)
    return rows


def _mj_run(N, method, **options):
    """One Moreau–Jean run of the chain stepped by hand: ``(CPU seconds of each step, the
    integrator, the velocities after the impact step)``."""
    sc = BallChain(n_balls=N)
    q0, v0 = sc.initial_state()
    if method == "nsgs":
        options.setdefault("lcp_omega", sor_omega(sc.masses))
    integ = MoreauJean(sc, 0.0, q0, v0, sc.impact_time + 0.5, h=H, lcp_method=method, **options)
    times, v_after = [], None
    while integ.status == "running":
        t0 = time.process_time()
        integ.step()
        times.append(time.process_time() - t0)
        if v_after is None and integ.v[-1] != 0.0:
            v_after = integ.v.copy()
    return times, integ, v_after


def _bound(N, tol):
    # tests/scenes/test_ball_chain_iterative.py: unit balls, ||q|| = 2 at the impact
    return 5.0 / (2.0 * math.sin(math.pi / (2 * N))) * tol * 3.0


def scaling_row(N, method, sweeps, tol, repeats):
    """One row of the scaling table (module docstring), medians over ``repeats`` runs."""
    sc = BallChain(n_balls=N)
    exact = simultaneous_impact(sc.masses, sc.initial_state()[1], 1.0)
    row = {"N": N, "contacts": N - 1, "solver": method}
    if method != "auto":
        fixed = []
        for _ in range(repeats):
            times, integ, _ = _mj_run(N, method, lcp_max_iter=sweeps, lcp_tol=1e-15)
            if integ.status_code != -3 or integ.counters["iterations"] != sweeps:
                raise RuntimeError(f"{method} N={N}: the fixed-sweeps step did not stop at "
                                   f"{sweeps}: {integ.message}")
            fixed.append(times[-1])
        step = statistics.median(fixed)
        row.update(fixed_sweeps=sweeps, fixed_step_ms=step * 1e3,
                   ns_per_contact_sweep=step / ((N - 1) * sweeps) * 1e9)
    means, impacts = [], []
    for _ in range(repeats):
        opts = {} if method == "auto" else {"lcp_tol": tol, "lcp_max_iter": 10 ** 7}
        times, integ, v_after = _mj_run(N, method, **opts)
        if integ.status != "finished":
            raise RuntimeError(f"{method} N={N}: {integ.message}")
        means.append(sum(times) / integ.counters["steps"])
        impacts.append(max(times))
    c = integ.counters
    row.update(us_per_step=statistics.median(means) * 1e6,
               impact_step_ms=statistics.median(impacts) * 1e3,
               steps=c["steps"], iterations=c.get("iterations", 0),
               max_residual=c["max_residual"],
               v_error=float(np.max(np.abs(v_after - exact))),
               v_error_end=float(np.max(np.abs(integ.v - exact))),
               bound=_bound(N, tol) if method != "auto" else None)
    return row


def _table(rows):
    print("| N | contacts | solver | step at fixed sweeps (ms) | ns a contact-sweep | "
          "us a step (run) | impact step (ms) | sweeps (run) | velocity error | bound | "
          "at the end |")
    print("| " + " | ".join(["---"] * 11) + " |")
    for r in rows:
        f = (f"{r['fixed_step_ms']:.3g} ({r['fixed_sweeps']})" if "fixed_step_ms" in r else "-")
        ns = f"{r['ns_per_contact_sweep']:.0f}" if "fixed_step_ms" in r else "-"
        b = f"{r['bound']:.1e}" if r["bound"] is not None else "-"
        auto = r["solver"] == "auto"
        # the dense compiled loop takes the whole run in one call: no impact step of its own
        imp = "-" if auto and r["N"] < SPARSE_FROM else f"{r['impact_step_ms']:.3g}"
        sweeps = "-" if auto else r["iterations"]
        print(f"| {r['N']} | {r['contacts']} | {r['solver']} | {f} | {ns} | "
              f"{r['us_per_step']:.0f} | {imp} | {sweeps} | {r['v_error']:.1e} | {b} | "
              f"{r['v_error_end']:.1e} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10_000])
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--scaling", action="store_true",
                    help="the scaling table of moreau's Moreau-Jean (module docstring)")
    ap.add_argument("--sweeps", type=int, default=100)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--orders", action="store_true",
                    help="sweeps of projected SOR on the struck chain by sweep order")
    ap.add_argument("--no-siconos", action="store_true")
    ap.add_argument("--no-lemke", action="store_true", help="skip the dense Lemke runs")
    args = ap.parse_args()
    if args.orders:
        sweep_orders([N for N in args.sizes if N <= 1000], args.tol)
        return
    if args.scaling:
        for method in ("auto", "nsgs", "apgd"):       # load the compiled solvers once
            _mj_run(200, method)
        rows = []
        for N in args.sizes:
            _mj_run(N, "auto")                         # the dense loop compiles per length
            for method in ("auto", "nsgs", "apgd"):
                rows.append(scaling_row(N, method, args.sweeps, args.tol, args.repeats))
                print(json.dumps(rows[-1]), flush=True)
        _table(rows)
        return
    run(10, "nsgs", args.tol)
    run(10, "apgd", args.tol)
    for N in args.sizes:
        dense = N <= 100 and not args.no_lemke
        for solver in ("lemke", "nsgs", "apgd") if dense else ("nsgs", "apgd"):
            print(json.dumps(run(N, solver, args.tol)), flush=True)
    if not args.no_siconos:
        print(json.dumps({"siconos_mj": siconos_mj(100)}), flush=True)


if __name__ == "__main__":
    main()
