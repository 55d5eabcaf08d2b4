"""Cost per Moreau–Jean step on the ball chain as it grows: compiled, Lemke, QP and Siconos.

For N = 2, 5, 10, 20, 50, 100 balls (``moreau.scenes.ball_chain``, equal
balls, ``e = 1``), the striker's impact and the flight after it, ``h = 0.01``
over ``t* + 0.5`` (150 steps, every one with the N - 1 chain contacts in the
index set). Per N and per solver path, the time per step (median of
``--repeat`` runs):

``compiled``
    the default: the compiled loop with its own contact solve (one
    contact in closed form, several by Lemke with a warm start);
``compiled_lemke``
    the compiled loop with every contact problem through Lemke
    (``lcp_method="lemke"``);
``generic_lemke``
    the generic Python step (``fast=False``) with Lemke;
``generic_qp``
    the generic Python step with ``lcp_method="qp"`` (qpsolvers + OSQP);
``siconos``
    Siconos's ``MoreauJeanOSI`` + ``LCP`` on the same chain, run by
    ``benchmarks/siconos_peer.py`` under ``/usr/bin/python3`` when that
    interpreter has Siconos (left empty otherwise).

BLAS runs on one thread (unless ``OPENBLAS_NUM_THREADS`` etc. are set):
every path, and Siconos, on one core. Every run's final velocities are checked against the simultaneous Newton
impact (the chain leaves as a block: striker ``(2 - N) / N``, the others
``2 / N``); the largest deviation of any path is a column. The first
compiled run of each N compiles (or loads) its loop and is not timed; its
time is reported as ``first_call_s``.

Run: ``python benchmarks/bench_ball_chain.py [--quick] [--no-siconos] --out DIR``;
writes ``ball_chain.csv`` and ``ball_chain.json`` to ``DIR``.
"""

import os

# One BLAS thread, set before numpy loads its library: the compiled loop and
# Siconos's solver run on one core, and on this 2-core shared machine a
# threaded BLAS made the generic step's 100 x 100 products vary from 0.6 to
# 110 ms a step with the load of other processes
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from _timing import median_time  # noqa: E402
from moreau.integrators import simulate  # noqa: E402
from moreau.scenes.ball_chain import BallChain, simultaneous_impact  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
H = 0.01
PATHS = {"compiled": {}, "compiled_lemke": {"lcp_method": "lemke"},
         "generic_lemke": {"lcp_method": "lemke", "fast": False},
         "generic_qp": {"lcp_method": "qp", "fast": False}}


def per_step(chain, repeat, **options):
    """``(seconds per step, stats, final velocities, first call seconds)`` of one path."""
    q0, v0 = chain.initial_state()
    span = (0.0, chain.impact_time + 0.5)

    def go():
        return simulate(chain, span, q0, v0, "moreau-jean", h=H, save_every=10**6, **options)

    t0 = time.perf_counter()
    res = go()
    first = time.perf_counter() - t0
    if not res.success:
        raise RuntimeError(res.message)
    return (median_time(go, repeat=repeat, warmup=0) / res.stats["steps"], res.stats,
            res.v[-1], first)


def siconos(sizes, chain, repeat):
    """Siconos's runs of the same chains, or ``{"available": False, "reason": ...}``."""
    exe = "/usr/bin/python3"
    if not os.path.exists(exe):
        return {"available": False, "reason": f"{exe} not found"}
    par = {"sizes": list(sizes), "ratio": chain.mass_ratio, "e": float(chain.restitution[0]),
           "gap": chain.gap0, "h": H, "t_end": chain.impact_time + 0.5}
    try:
        out = subprocess.run([exe, os.path.join(HERE, "siconos_peer.py"), "--case", "ball-chain",
                              "--repeats", str(repeat), "--chain-params", json.dumps(par)],
                             capture_output=True, text=True, timeout=1800)
        if out.returncode != 0:
            tail = out.stderr.strip().splitlines()[-1:] or [""]
            return {"available": False,
                    "reason": f"peer exited with code {out.returncode} {tail[0]}".strip()}
        return json.loads(out.stdout.strip().splitlines()[-1])
    except Exception as exc:  # a broken peer must not stop the benchmark
        return {"available": False, "reason": f"{type(exc).__name__}: {exc}"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder for ball_chain.csv and ball_chain.json")
    ap.add_argument("--quick", action="store_true", help="N up to 20, one run")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-siconos", action="store_true", help="skip the Siconos peer")
    a = ap.parse_args()
    if os.path.exists(a.out) and not os.path.isdir(a.out):
        sys.exit(f"`--out` must be a folder, but {a.out!r} is a file")
    os.makedirs(a.out, exist_ok=True)
    if not os.access(a.out, os.W_OK):
        sys.exit(f"`--out` must be a writable folder, {a.out!r} is not")
    if a.repeat < 1:
        sys.exit(f"`--repeat` must be >= 1, got {a.repeat}")
    sizes = (2, 5, 10, 20) if a.quick else (2, 5, 10, 20, 50, 100)
    repeat = 1 if a.quick else a.repeat
    peer = ({"available": False, "reason": "--no-siconos"} if a.no_siconos
            else siconos(sizes, BallChain(n_balls=2, restitution=1.0), repeat))
    if not peer.get("available"):
        print(f"Siconos: not run ({peer.get('reason')})", flush=True)
    rows = []
    for n in sizes:
        chain = BallChain(n_balls=n, restitution=1.0)
        block = simultaneous_impact(chain.masses, chain.initial_state()[1], 1.0)
        row = {"n_balls": n, "contacts": n - 1}
        dev = 0.0
        for name, opts in PATHS.items():
            # the Python paths cost up to a second a run at N = 100: fewer repeats
            rep = repeat if name.startswith("compiled") else max(1, repeat // 2)
            t, st, v, first = per_step(chain, rep, **opts)
            row[f"{name}_us_per_step"] = t * 1e6
            dev = max(dev, float(np.max(np.abs(v - block))))
            if name == "compiled":
                row.update(steps=st["steps"], contact_steps=st["lcp_solves"],
                           pivots=st["pivots"], warm_starts=st["warm_starts"],
                           first_call_s=first)
            if name == "generic_qp":
                row["qp_fallbacks"] = st["fallbacks"]
        sic = peer.get("ball_chain", {}).get(str(n)) if peer.get("available") else None
        row["siconos_us_per_step"] = sic["us_per_step"] if sic else None
        row["siconos_max_dv"] = (float(np.max(np.abs(np.array(sic["v_end"]) - block)))
                                 if sic else None)
        row["max_dv_from_block"] = dev
        row["qp_over_compiled"] = row["generic_qp_us_per_step"] / row["compiled_us_per_step"]
        row["siconos_over_compiled"] = (row["siconos_us_per_step"] / row["compiled_us_per_step"]
                                        if sic else None)
        rows.append(row)
        s = (f", Siconos {row['siconos_us_per_step']:8.1f}" if sic else "")
        print(f"N={n:3d} us/step: compiled {row['compiled_us_per_step']:8.2f}, compiled Lemke "
              f"{row['compiled_lemke_us_per_step']:8.2f}, generic Lemke "
              f"{row['generic_lemke_us_per_step']:9.1f}, generic QP "
              f"{row['generic_qp_us_per_step']:9.1f}{s}; max |v - block| {dev:.1e}", flush=True)
    with open(os.path.join(a.out, "ball_chain.json"), "w") as fh:
        json.dump({"h": H, "restitution": 1.0, "siconos": {k: v for k, v in peer.items()
                                                            if k != "ball_chain"},
                   "rows": rows}, fh, indent=1)
    with open(os.path.join(a.out, "ball_chain.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
