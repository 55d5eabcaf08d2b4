"""Float Lemke against exact-rational Lemke over the degenerate families of ``tests/lcp/test_lemke_exact.py``.

``python benchmarks/lcp_degenerate.py [--examples N]`` draws N members of
each family (the tests' Hypothesis strategies), runs ``solve_lcp(M, q)`` and
the textbook exact Lemke of ``tests/lcp/exact_reference.py`` on each, and
prints per family: cases, how each ended, the pivot-count differences (float
minus exact), how many stopped at the pivot limit where the exact run ends
(must be 0), how many a different way from the exact run, and how many
handed over to the exact path: how many steps were decided there (the path
then went on in floating point), how many runs had the whole path finished in
exact arithmetic instead, and how many of those had to start afresh.
Run from a checkout (it imports the test strategies).
"""

import argparse
import collections
import pathlib
import re
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

from hypothesis import HealthCheck, given, settings  # noqa: E402

from lcp.exact_reference import reference_lemke  # noqa: E402
from lcp.test_lemke_exact import bimatrix, q_zeros, repeated, ties, zmatrix  # noqa: E402
from moreau.lcp import INFEASIBLE, MAX_ITER, SECONDARY_RAY, SOLVED, solve_lcp  # noqa: E402


def run_family(strategy, n_examples):
    stats = collections.Counter()
    diffs = collections.Counter()
    exact_piv = []

    @settings(max_examples=n_examples, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(strategy)
    def run(prob):
        M, q = prob
        status, _, pivots, _, _ = reference_lemke(M, q)
        res = solve_lcp(M, q, max_iter=10**5)
        stats["cases"] += 1
        stats[f"exact {status}"] += 1
        exact_piv.append(pivots)
        if res.status == MAX_ITER and status != "max_iter":
            stats["MAX_ITER where exact ends"] += 1
        ended = {SOLVED: "solved", SECONDARY_RAY: "ray", INFEASIBLE: "ray"}.get(res.status, "other")
        if ended != status:
            stats["ended otherwise"] += 1
            if ended == "solved":
                stats["solved where exact rays"] += 1
        diffs[res.pivots - pivots] += 1
        if "exact arithmetic" in res.detail:
            stats["handed over"] += 1
            steps = re.search(r"(\d+) steps? of the path", res.detail)
            if steps:
                stats["exact steps"] += int(steps.group(1))
            if "finished in exact arithmetic" in res.detail:
                stats["whole path exact"] += 1
            if "afresh" in res.detail:
                stats["started afresh"] += 1
    run()
    return stats, diffs, exact_piv


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", type=int, default=300)
    args = ap.parse_args()
    fams = [("q with many zeros", q_zeros()), ("repeated rows/columns", repeated()),
            ("5-10 rows tied", ties()), ("bimatrix games", bimatrix()),
            ("Z-matrices", zmatrix())]
    total = collections.Counter()
    for name, strat in fams:
        t0 = time.perf_counter()
        stats, diffs, piv = run_family(strat, args.examples)
        total.update(stats)
        d = ", ".join(f"{k:+d}: {v}" for k, v in sorted(diffs.items()))
        print(f"{name:24s} cases {stats['cases']:4d}  exact solved/ray {stats['exact solved']}/"
              f"{stats['exact ray']}  exact pivots {min(piv)}-{max(piv)} (mean {sum(piv) / len(piv):.1f})"
              f"  float-exact pivots {{{d}}}  MAX_ITER where exact ends "
              f"{stats['MAX_ITER where exact ends']}  ended otherwise {stats['ended otherwise']}"
              f" (solved where exact rays {stats['solved where exact rays']})"
              f"  handed over {stats['handed over']} (exact steps {stats['exact steps']}, whole path "
              f"exact {stats['whole path exact']}, afresh {stats['started afresh']})"
              f"  [{time.perf_counter() - t0:.1f} s]")
    print(f"all: {total['cases']} cases, MAX_ITER where exact ends {total['MAX_ITER where exact ends']}, "
          f"ended otherwise {total['ended otherwise']}, handed over {total['handed over']} "
          f"(exact steps {total['exact steps']}, whole path exact {total['whole path exact']})")


if __name__ == "__main__":
    main()
