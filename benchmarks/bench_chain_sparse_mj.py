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
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from moreau.contact._sparse import delassus, disk_jacobian  # noqa: E402
from moreau.contact.solvers.apgd import solve_apgd  # noqa: E402
from moreau.contact.solvers.nsgs import solve_nsgs  # noqa: E402
from moreau.lcp import solve_lcp  # noqa: E402

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


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10_000])
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--no-siconos", action="store_true")
    ap.add_argument("--no-lemke", action="store_true", help="skip the dense Lemke runs")
    args = ap.parse_args()
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
