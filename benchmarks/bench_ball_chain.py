"""Cost per Moreau–Jean step on the ball chain as it grows: compiled Lemke against the QP path.

For N = 2, 5, 10, 20, 50, 100 balls (``moreau.scenes.ball_chain``), the
striker's impact and the flight after it: Moreau–Jean with its own contact
solve (compiled; one contact in closed form, several by Lemke), with every
contact problem forced through Lemke (compiled), and through the QP path
(qpsolvers + OSQP, the generic Python step). Each row gives the time per
step (median of ``--repeat`` runs), the steps that solved a contact problem
and the ratio QP / compiled Lemke. The first compiled run of each N
compiles its loop and is not timed.

Run: ``python benchmarks/bench_ball_chain.py [--quick] [--out DIR]``;
writes ``ball_chain.csv`` and ``ball_chain.json`` to ``--out`` (default ``./out``).
"""

import argparse
import csv
import json
import os
import sys

from _timing import median_time
from moreau.integrators import simulate
from moreau.scenes.ball_chain import BallChain


def per_step(chain, h, repeat, **options):
    q0, v0 = chain.initial_state()
    span = (0.0, chain.impact_time + 0.5)

    def go():
        return simulate(chain, span, q0, v0, "moreau-jean", h=h, save_every=10**6, **options)

    res = go()
    if not res.success:
        raise RuntimeError(res.message)
    return median_time(go, repeat=repeat, warmup=0) / res.stats["steps"], res.stats


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out")
    ap.add_argument("--quick", action="store_true", help="N up to 20, one run")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    if os.path.exists(a.out) and not os.path.isdir(a.out):
        sys.exit(f"`--out` must be a folder, but {a.out!r} is a file")
    os.makedirs(a.out, exist_ok=True)
    sizes = (2, 5, 10, 20) if a.quick else (2, 5, 10, 20, 50, 100)
    repeat = 1 if a.quick else a.repeat
    rows = []
    for n in sizes:
        chain = BallChain(n_balls=n, restitution=1.0)
        h = 0.01
        auto, st = per_step(chain, h, repeat)
        lemke, _ = per_step(chain, h, repeat, lcp_method="lemke")
        qp, stq = per_step(chain, h, max(1, repeat // 3), lcp_method="qp")
        rows.append({"n_balls": n, "contacts": n - 1, "steps": st["steps"],
                     "contact_steps": st["lcp_solves"], "auto_us_per_step": auto * 1e6,
                     "lemke_us_per_step": lemke * 1e6, "qp_us_per_step": qp * 1e6,
                     "qp_over_lemke": qp / lemke, "lemke_pivots": st["pivots"],
                     "qp_fallbacks": stq["fallbacks"]})
        r = rows[-1]
        print(f"N={n:3d}: own solve {r['auto_us_per_step']:9.2f} us/step, forced Lemke "
              f"{r['lemke_us_per_step']:9.2f}, QP {r['qp_us_per_step']:10.1f} "
              f"({r['qp_over_lemke']:.0f}x Lemke); {r['contact_steps']} contact steps of "
              f"{r['steps']}", flush=True)
    with open(os.path.join(a.out, "ball_chain.json"), "w") as fh:
        json.dump(rows, fh, indent=1)
    with open(os.path.join(a.out, "ball_chain.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
