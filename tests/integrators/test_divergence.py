"""Issue 34: a run whose state blew up is named as diverged, with the step's stability bound."""

import math

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.integrators._divergence import divergence, fastest_oscillation
from moreau.scenes import make_scene
from moreau.scenes.bouncing_ball import BouncingBall


def test_a_spring_mass_oscillation_is_found_by_the_difference_stiffness():
    class Spring:
        # m = 2, k = 50: omega = 5 exactly
        def forces(self, q, v, t):
            return np.array([-50.0 * q[0]])

        def mass(self, q):
            return np.array([[2.0]])
    assert fastest_oscillation(Spring(), [0.3], [0.0], 0.0) == pytest.approx(5.0, rel=1e-8)


@pytest.mark.parametrize("fast", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_schatzman_paoli_beyond_its_step_bound_reports_the_divergence(fast):
    # the flexible rod at 100 steps a period: the state grew to 4e55 in 43 steps and the
    # run said "discrete Painleve condition violated (W_NN = 1.5e103)"; the generic step ran
    # on to the end of the window with 1e142 and status 0. (The compiled loop, slow here
    # for its compilation, 5 s.)
    sc = make_scene("flexible-rod-drive")
    q0, v0 = sc.rest_state()
    h = 2 * math.pi / 100
    r = simulate(sc, (0.0, 2 * math.pi), q0, v0, "schatzman-paoli", h=h, fast=fast)
    # the growing state leaves the rod's valid region (0 < phi < pi/2) before its velocity
    # has grown 1e8-fold: the stop there names the instability that drove it
    if r.status == -6:
        assert "0 < phi < pi/2" in r.message and r.message.endswith("which drove it there")
    else:
        assert r.status == -5
        assert r.message.startswith("the state diverged: its largest velocity is ")
    w = fastest_oscillation(sc, q0, v0, 0.0)
    assert h * w > 2.0
    assert f"exceeds the stability bound 2 / omega_max = {2 / w:.4g}" in r.message
    # the same scheme within its bound (h omega_max = 1.96) runs on: 100 such steps
    ok = simulate(sc, (0.0, 2 * math.pi / 3), q0, v0, "schatzman-paoli", h=2 * math.pi / 300,
                  fast=False)
    assert ok.success and 2 * math.pi / 300 * w < 2.0


def test_an_ordinary_state_is_not_diverged():
    ball = BouncingBall(restitution=0.5)
    q, v = ball.initial_state()
    # a free body's position grows without bound over a long window: not a divergence
    assert divergence(ball, q, v, 0.0, q + 1e12, v + 1e7, 1.0) is None
    assert divergence(ball, q, v, 0.0, q * np.inf, v, 1.0).startswith(
        "the state diverged: its largest velocity is inf")


@pytest.mark.slow
def test_the_stiff_rod_under_schatzman_paoli_diverges_by_name_without_overflow_warnings():
    # compare --stress printed "overflow encountered in matmul" (schatzman_paoli.py, the
    # Python step a compiled block handed a blown-up state back to) and named the row by
    # what the state broke on the way (a non-positive Delassus entry, a non-finite state)
    import warnings
    from moreau.studies.paper.stress import run_case
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        rows = run_case("flexible-rod-stiff-N50", schemes=("event-driven", "schatzman-paoli"))
    sp = rows[1]
    assert sp["outcome"] == "failed" and "the state diverged" in sp["message"]
    assert "exceeds the stability bound 2 / omega_max" in sp["message"]


@pytest.mark.slow
def test_a_flat_step_in_several_free_directions_is_named_at_once():
    # piezo drive, Schatzman-Paoli at 300 steps a period: P - I is singular (a direction the
    # grid-locked map leaves unchanged); 60 blind Newton steps (14 s) ended "did not
    # converge (residual 0.0162)"; now the flat step is named after one
    from moreau.analysis.scheme_settings import make_scheme, steady_of
    from moreau.errors import ResidualFloorError
    with pytest.raises(ResidualFloorError, match=r"met a flat step of the period map \(P - I "
                                                 r"singular in a free direction"):
        steady_of(make_scene("piezo-drive"), make_scheme("schatzman-paoli", None, 300))


@pytest.mark.slow
def test_compare_gives_a_grid_locked_scheme_its_long_run_mean_on_the_piezo_drive():
    # compare --scene piezo-drive --schemes all: SP, generalized-alpha and TDG failed at every
    # setting (ResidualFloorError); the row is now the scheme's statistical steady state
    # (SP at 300 steps: 1.2137e-3 against the reference's 1.2847e-3, measured)
    from moreau.analysis.compare import make_case
    case = make_case("piezo-drive")
    value, ss = case.scheme("schatzman-paoli", {"steps_per_period": 300})
    assert ss.statistical and "flat step of the period map" in ss.stats["why_not_periodic"]
    lo, hi = ss.confidence_interval
    assert lo <= value <= hi and hi - lo < 1e-6 * abs(value)
    assert abs(value / 1.2846675e-3 - 1.0) < 0.1
