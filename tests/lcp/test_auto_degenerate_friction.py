"""`auto` on over-constrained friction LCPs: a long exact Lemke path is deferred to the certified QP.

The data are the first Moreau–Jean step's friction LCPs of the masonry arch
(:mod:`moreau.scenes.masonry_arch`, ``t / R = 0.15``, generic step) with two
and four voussoirs: every joint's two corners press a neighbour's face, so the
Delassus matrix is singular and the ratio tests tie. With four voussoirs
Lemke's floating-point path hands 24 steps over to exact arithmetic and then
finishes the whole path exactly (Python integers of thousands of bits); with
two it needs 4 exact steps and ends in floating point.
"""

from pathlib import Path

import numpy as np

from moreau.lcp import SOLVED, FrictionLayout, lcp_violation, solve_lcp
from moreau.lcp.lemke import DEFAULT_TOL, DEFER_STEPS

DATA = Path(__file__).parents[1] / "data"


def _arch(n):
    d = np.load(DATA / f"arch{n}_friction_lcp.npz")
    return d["M"], d["q"], FrictionLayout(d["mu"], d["e"])


def _certified(M, q, res):
    # recomputed on the stored data, not taken from the result
    z = res.z
    assert res.status == SOLVED and res.success
    assert lcp_violation(M, q, z) <= DEFAULT_TOL
    assert np.allclose(res.w, M @ z + q, rtol=0, atol=1e-12)


def test_a_long_exact_path_goes_to_the_qp_certified_at_lemkes_tolerance():
    M, q, layout = _arch(4)
    res = solve_lcp(M, q, "auto", friction=layout)
    _certified(M, q, res)
    assert res.path == ("lemke", "qp")
    assert f"more than {DEFER_STEPS} steps decided in exact arithmetic" in res.message


def test_a_short_exact_hand_over_stays_lemkes():
    # 4 exact steps (the deferral's limit) and the path ends in floating point
    M, q, layout = _arch(2)
    res = solve_lcp(M, q, "auto", friction=layout)
    _certified(M, q, res)
    assert res.path == ("lemke",)
    assert f"{DEFER_STEPS} steps of the path were decided in exact arithmetic" in res.message
    # and the same answer as Lemke called alone, bit for bit
    alone = solve_lcp(M, q, "lemke")
    assert np.array_equal(alone.z, res.z)


def test_without_a_qp_the_deferred_path_is_finished_exactly():
    # no friction layout: M is not monotone, the QP does not apply, and auto
    # finishes Lemke's path with exact steps as `lemke` does. Its last exact
    # step lets z0 leave; the floating-point resume breaks down there (its
    # point fails the check), and the path ends at that basis's exact point, not
    # by a second, whole path in exact arithmetic from the start
    M, q, _ = _arch(4)
    res = solve_lcp(M, q, "auto")
    _certified(M, q, res)
    assert res.path == ("lemke",)
    assert "the last one ending the path" in res.message
    assert "finished in exact arithmetic" not in res.message
