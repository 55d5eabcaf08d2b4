"""`auto` on over-constrained friction LCPs: a long exact Lemke path is deferred to the certified QP.

The data are the first Moreau–Jean step's friction LCPs of the masonry arch
(:mod:`moreau.scenes.masonry_arch`, ``t / R = 0.15``, generic step) with two
and four voussoirs: every joint's two corners press a neighbour's face, so the
Delassus matrix is singular and the ratio tests tie. With four voussoirs
Lemke's floating-point path hands 24 steps over to exact arithmetic and then
finishes the whole path exactly (Python integers of thousands of bits); with
two it needs 4 exact steps and ends in floating point.

The friction-cone LCP of a resting pyramid of four spheres
(:func:`moreau.scenes.ball_chain_3d.sphere_pyramid`, d = 8, its second step)
carries rounding noise from the first step (right-hand sides one ulp apart,
entries down to 1e-36): its exact lexicographic path is 75 pivots on integers
of thousands of bits (35 s), where the first step's support solves it.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from moreau.errors import InputError

from moreau.lcp import SOLVED, FrictionLayout, lcp_violation, solve_lcp
from moreau.lcp.lemke import DEFAULT_TOL, DEFER_STEPS, solve_on_support

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


def test_a_guessed_support_comes_before_the_long_exact_path():
    d = np.load(DATA / "pyramid_step2_cone_lcp.npz")
    M, q, support = d["M"], d["q"], d["support"]
    res = solve_lcp(M, q, "auto", support=support)
    _certified(M, q, res)
    assert res.path == ("lemke", "support") and res.method == "support" and res.pivots == 0
    assert f"more than {DEFER_STEPS} steps decided in exact arithmetic" in res.message
    assert np.array_equal(np.flatnonzero(res.z), support)
    # the floor contacts' normal impulses (z 0, 10, 20) carry the four spheres' weight,
    # h m g = 0.1 each in scene units: 4/3 of it on each
    assert np.max(np.abs(res.z[[0, 10, 20]] - 0.4 / 3.0)) <= 1e-14


def test_a_support_is_taken_only_where_its_point_solves():
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-1.0, 1.0])
    res = solve_on_support(M, q, [0])
    _certified(M, q, res)
    assert res.z.tolist() == [0.5, 0.0] and res.pivots == 0
    assert solve_on_support(M, q, [1]) is None          # z_1 = -1/2
    assert solve_on_support(M, q, []) is None           # w_0 = -1
    # a singular block: its point is not one vertex of a set
    assert solve_on_support(np.ones((2, 2)), np.array([-1.0, -1.0]), [0, 1]) is None
    # and auto without a deferral stays Lemke's, whatever the support given
    res = solve_lcp(M, q, "auto", support=[1])
    assert res.path == ("lemke",) and res.z.tolist() == [0.5, 0.0]


@pytest.mark.parametrize("support, rule", [([0, 0], "distinct"), ([2], "in [0, 2)"),
                                           ([-1], "in [0, 2)"), (["a"], "integer")])
def test_a_bad_support_is_refused_by_name(support, rule):
    for solve in (lambda: solve_on_support(np.eye(2), -np.ones(2), support),
                  lambda: solve_lcp(np.eye(2), -np.ones(2), "auto", support=support)):
        with pytest.raises(InputError, match=r"`support` must .*" + re.escape(rule)):
            solve()
