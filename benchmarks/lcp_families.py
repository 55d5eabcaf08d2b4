"""Outcome counts of every LCP method over the generated families of the property tests.

``python benchmarks/lcp_families.py [--examples N]`` draws N members of each
family (the Hypothesis strategies of ``tests/lcp``), solves each with every
method, and counts successes, infeasibility proofs and honest failures, and
the claims that do not check out on the caller's data (which must be 0): a
success is checked in exact rational arithmetic, a Farkas vector exactly.
Run from a checkout (it imports the test strategies).
"""

import argparse
import collections
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

from hypothesis import HealthCheck, given, settings  # noqa: E402

from lcp.conftest import assert_certified, assert_farkas  # noqa: E402
from lcp.test_infeasibility_properties import (copositive_plus_infeasible,  # noqa: E402
                                               monotone_feasible, psd_infeasible,
                                               zmatrix_infeasible)
from lcp.test_no_silent_wrong import (CERT_TOL, METHODS, ill_conditioned_diagonal,  # noqa: E402
                                      near_singular, scaled_family_member)
from moreau.lcp import INFEASIBLE, solve_lcp  # noqa: E402


def count(name, strategy, n, table, unpack=lambda x: x):
    @settings(max_examples=n, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(strategy)
    def run(member):
        M, q = unpack(member)
        for method in METHODS:
            res = solve_lcp(M, q, method=method)
            key = "solved" if res.success else ("infeasible" if res.status == INFEASIBLE else "failed")
            table[(name, method, key)] += 1
            try:
                if res.success:
                    assert_certified(M, q, res.z, CERT_TOL[method])
                elif res.status == INFEASIBLE:
                    assert_farkas(M, q, res.certificate)
            except AssertionError:
                table[(name, method, "FALSE CLAIM")] += 1
    run()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", type=int, default=300)
    args = ap.parse_args()
    table = collections.Counter()
    families = [("psd (infeasible)", psd_infeasible(), lambda x: x),
                ("copositive-plus (infeasible)", copositive_plus_infeasible(), lambda x: x),
                ("z-matrix (infeasible)", zmatrix_infeasible(), lambda x: x),
                ("monotone (feasible)", monotone_feasible(), lambda x: x),
                ("near-singular x1e12/3.3e7", near_singular(), lambda x: x),
                ("ill-conditioned diagonal", ill_conditioned_diagonal(), lambda x: x),
                ("uniformly scaled members", scaled_family_member(),
                 lambda m: (m[3] * m[1], m[3] * m[2]))]
    print(f"{'family':32} {'method':6} {'solved':>7} {'infeas.':>7} {'failed':>7} {'false':>6}")
    for name, strat, unpack in families:
        count(name, strat, args.examples, table, unpack)
        for method in METHODS:
            c = [table[(name, method, k)] for k in ("solved", "infeasible", "failed", "FALSE CLAIM")]
            print(f"{name:32} {method:6} {c[0]:7d} {c[1]:7d} {c[2]:7d} {c[3]:6d}")


if __name__ == "__main__":
    main()
