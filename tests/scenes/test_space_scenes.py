"""The spatial scenes against their closed forms: Moreau–Jean with the exact cone, and the facets' cost.

Orders are fitted over three steps ``h, h/2, h/4``. Moreau–Jean's friction
impulse is implicit in the end velocity, so sliding is first order at either
theta; a motion of constant acceleration (rolling) is exact at theta = 1/2.
"""

import math

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.scenes.billiard_backspin import billiard_backspin, billiard_exact, rolling_onset
from moreau.scenes.puck_incline import puck_incline, puck_incline_path
from moreau.scenes.sphere_incline import sphere_incline, sphere_incline_exact


def _order(steps, errors):
    return -np.polyfit(np.log(steps), np.log(errors), 1)[0]


def _run(sc, span, n, **opts):
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, span), q0, v0, "moreau-jean", h=span / n, **opts)
    assert res.status == 0, res.message
    return res


def test_the_sphere_rolls_at_five_sevenths_g_sin_alpha_to_the_schemes_order():
    sc = sphere_incline()
    p, span = sc.params, 10.0
    s, sd, w = sphere_incline_exact(p, [span * sc.time])
    errs = []
    for n in (10, 20, 40):
        res = _run(sc, span, n, cone="exact")
        assert set(res.regime_letters()) == {"S"}
        # the velocity is exact at every step: constant forces, constant impulse
        assert res.v[-1, 0] * sc.length / sc.time == pytest.approx(sd[0], rel=1e-12)
        assert res.v[-1, 4] / sc.time == pytest.approx(w[0], rel=1e-12)
        errs.append(abs(res.q[-1, 0] * sc.length - s[0]))
    assert 0.98 < _order([10, 20, 40], errs) < 1.02
    # theta = 1/2 is the trapezoidal rule: exact for a constant acceleration
    res = _run(sc, span, 10, cone="exact", theta=0.5)
    assert res.q[-1, 0] * sc.length == pytest.approx(s[0], rel=1e-12)
    assert abs(np.linalg.norm(res.q[-1, 3:7]) - 1.0) <= 1e-15


@pytest.mark.parametrize("factor, letter", [(1.01, "S"), (0.99, "P")])
def test_the_sphere_slips_below_mu_two_sevenths_tan_alpha(factor, letter):
    slope = 0.4
    sc = sphere_incline(slope=slope, mu=factor * 2.0 / 7.0 * math.tan(slope), speed=0.0)
    res = _run(sc, 5.0, 10, cone="exact", theta=0.5)
    assert set(res.regime_letters()[1:]) == {letter}
    _, sd, w = sphere_incline_exact(sc.params, [5.0 * sc.time])
    assert res.v[-1, 0] * sc.length / sc.time == pytest.approx(sd[0], rel=1e-12)
    assert res.v[-1, 4] / sc.time == pytest.approx(w[0], rel=1e-12)
    acc = res.v[-1, 0] * sc.length / sc.time / (5.0 * sc.time)
    g, mu = 9.81, sc.params.mu
    expected = 5.0 / 7.0 * g * math.sin(slope) if letter == "S" else g * (
        math.sin(slope) - mu * math.cos(slope))
    assert acc == pytest.approx(expected, rel=1e-12)


def test_the_billiard_ball_rolls_from_the_closed_form_time_at_the_closed_form_speed():
    sc = billiard_backspin()
    p, span = sc.params, 20.0
    t_star, v_star = rolling_onset(p)
    x, _, _ = billiard_exact(p, [span * sc.time])
    errs, onset = [], []
    for n in (50, 100, 200):
        res = _run(sc, span, n, cone="exact")
        letters = res.regime_letters()
        k = letters.index("S")
        assert set(letters[1:k]) == {"P"} and set(letters[k:]) == {"S"}
        # the onset lies in the step that ends on the first rolling sample
        assert res.t[k - 1] * sc.time <= t_star <= res.t[k] * sc.time
        onset.append(res.t[k] * sc.time - t_star)
        assert res.v[-1, 0] * sc.length / sc.time == pytest.approx(v_star, rel=1e-12)
        assert res.v[-1, 4] / sc.time * p.radius == pytest.approx(v_star, rel=1e-12)
        errs.append(abs(res.q[-1, 0] * sc.length - x[0]))
    assert 0.9 < _order([50, 100, 200], errs) < 1.1


def test_the_puck_follows_its_closed_form_path_at_order_one_with_the_exact_cone():
    sc = puck_incline()
    span = 16.0
    errs = []
    for n in (50, 100, 200):
        res = _run(sc, span, n, cone="exact")
        ref = puck_incline_path(sc.params, res.t * sc.time) / sc.length
        errs.append(np.max(np.hypot(res.q[:, 0] - ref[:, 0], res.q[:, 1] - ref[:, 1])))
        # it slides flat, without spin, all the way
        assert set(res.regime_letters()[1:]) == {"P"}
        assert np.max(np.abs(res.v[:, 3:])) == 0.0 and np.max(np.abs(res.q[:, 2])) < 1e-14
    # measured: 0.277, 0.138, 0.069 puck radii
    assert 0.95 < _order([50, 100, 200], errs) < 1.05 and errs[-1] < 0.08


def test_compare_on_a_spatial_scene_adds_the_facet_rows_and_their_order():
    from moreau.analysis.compare import compare
    rep = compare("puck-incline", steps=[50, 100], thetas=(1.0,), quick=True, progress=False)
    facets = {r["lcp"]: r for r in rep["rows"] if str(r["lcp"]).startswith("cone=")}
    assert sorted(facets) == ["cone=16", "cone=32", "cone=4", "cone=8", "cone=exact"]
    assert all(r["status"] == 0 and r["steps_per_period"] == 100 for r in facets.values())
    # the puck's path against d, measured at 100 steps (path errors 8.17, 2.61, 0.877, 0.253
    # puck radii against the closed form at d = 4..32, the exact cone's 0.138: the step's own
    # error); at 200 steps the orders were 1.60 and 1.60
    f = rep["facet_order"]
    assert f["d"] == [4, 8, 16, 32] and 1.5 < f["order_headline"] < 1.9
    assert 1.5 < f["order"] < 1.8 and np.all(np.diff(f["trajectory_error"]) < 0)
    assert facets["cone=exact"]["error"] < 0.5 * facets["cone=32"]["error"]
    # no forced-LCP rows: a spatial step solves a cone
    assert not any(r["lcp"] in ("lemke", "qp") for r in rep["rows"])
