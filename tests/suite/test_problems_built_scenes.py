"""The suite's problems on the builder's scenes (disk-incline, rocking-block-built): references and cells."""

import math

import pytest

from moreau.suite.problem import get_problem, problem_names
from moreau.suite.run import run_suite


def _rows(problems, schemes):
    rep = run_suite(problems=problems, schemes=schemes, quick=True, progress=False)
    return {(r["problem"], r["scheme"], r["setting"]): r for r in rep["rows"]}


def test_disk_incline_reference_is_rolling_by_energy():
    prob = get_problem("disk-incline")
    ref = prob.reference()
    # scene units r = 1, g = 1, m = 1; launched rolling at 0.2 m/s on r = 0.1 m, g = 9.81
    v0, a, T = 0.2 / math.sqrt(9.81 * 0.1), 0.3, prob.window
    assert 0.5 >= math.tan(a) / 3                   # friction can hold the contact: it rolls
    # rolling keeps the energy: (1/2)(1 + 1/2) s'^2 - s sin(a) constant, and s'' constant
    # (the force is constant), so s = v0 T + (1/2) s'' T^2 with s'' from the energy's rate
    acc = math.sin(a) / 1.5
    s = v0 * T + 0.5 * acc * T ** 2
    assert ref["distance"] == pytest.approx(s, rel=1e-13)
    assert 0.75 * ref["speed"] ** 2 - ref["distance"] * math.sin(a) == pytest.approx(
        0.75 * v0 ** 2, rel=1e-12)
    assert ref["rolling_speed"] == pytest.approx(ref["speed"], rel=1e-15)


def test_rocking_block_built_shares_the_hand_written_reference():
    built, hand = get_problem("rocking-block-built"), get_problem("rocking-block")
    assert built.reference() == hand.reference()
    assert built.scales() == hand.scales() and built.impact_speed() == hand.impact_speed()
    assert built.make_scene().name == "rocking-block-built"


def test_subset_table_on_the_built_scenes():
    assert {"disk-incline", "rocking-block-built"} <= set(problem_names())
    rows = _rows(["disk-incline", "rocking-block-built", "rocking-block"], ["moreau-jean"])
    for prob, finest in (("disk-incline", "N=1000"), ("rocking-block-built", "N=20000")):
        r = rows[(prob, "moreau-jean", finest)]
        assert r["outcome"] == "ok", r
        p = get_problem(prob)
        ref, sc = p.reference(), p.scales()
        assert all(abs(r["values"][k] - ref[k]) / sc[k] <= p.tolerance for k in ref)
    # Moreau-Jean is first order in the distance: ten times the steps, a tenth of the error
    coarse = rows[("disk-incline", "moreau-jean", "N=100")]["max_error"]
    fine = rows[("disk-incline", "moreau-jean", "N=1000")]["max_error"]
    assert 9.0 < coarse / fine < 11.0
    # the built block is the hand-written one's equations: the same measured values
    for setting in ("N=2000", "N=20000"):
        b = rows[("rocking-block-built", "moreau-jean", setting)]["values"]
        h = rows[("rocking-block", "moreau-jean", setting)]["values"]
        assert b == pytest.approx(h, rel=1e-9, abs=1e-12)
