"""Nonsmooth generalized-α: order, impacts, drift, friction, energy, options."""

import numpy as np
import pytest

from moreau.analysis.scheme_settings import ED_REFERENCE, make_scheme, steady_of
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.nonsmooth_generalized_alpha import alpha_coefficients
from moreau.scenes.registry import make_scene

from _toy_scenes import Block, Oscillator

NAME = "nonsmooth-generalized-alpha"


def _order(name, **options):
    hs = [0.1 / 2**k for k in range(4)]
    errs = []
    for h in hs:
        r = simulate(Oscillator(), (0.0, 4.0), [1.0], [0.0], name, h=h, **options)
        errs.append(max(abs(r.q[-1, 0] - np.cos(4.0)), abs(r.v[-1, 0] + np.sin(4.0))))
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


@pytest.mark.parametrize("rho_inf", [0.0, 0.5, 0.9, 1.0])
def test_coefficients_are_second_order_and_match_chung_hulbert(rho_inf):
    am, af, gamma, beta = alpha_coefficients(rho_inf)
    # second order: gamma = 1/2 - alpha_m + alpha_f; stability: beta = (gamma + 1/2)^2 / 4
    assert gamma == pytest.approx(0.5 - am + af)
    assert beta == pytest.approx(0.25 * (gamma + 0.5) ** 2)
    assert am <= af <= 0.5


def test_second_order_in_free_flight():
    # measured slope 2.00 (Moreau-Jean theta = 1: 0.98 on the same problem)
    assert _order(NAME) == pytest.approx(2.0, abs=0.05)
    assert _order(NAME, rho_inf=0.5) == pytest.approx(2.0, abs=0.1)


def test_bouncing_ball_converges_without_penetration():
    ball = make_scene("bouncing-ball", restitution=0.5)
    q0, v0 = ball.initial_state()
    exact = ball.exact_solution(np.array([2.0]), q0, v0)[0][0, 0]
    errs = []
    for h in (1e-2, 1e-3, 1e-4):
        r = simulate(ball, (0.0, 2.0), q0, v0, NAME, h=h)
        errs.append(abs(r.q[-1, 0] - exact))
        assert r.stats["max_penetration"] == 0.0 and r.gap.min() >= -1e-14
    # first order with impacts (measured 1.9e-3, 6.0e-4, 1.6e-4 at 1e-2 ... 1e-4)
    assert errs[-1] < 3e-4 and errs[-1] < errs[0] / 5


def test_position_level_removes_the_drift_of_a_resting_contact():
    ball = make_scene("bouncing-ball", restitution=0.5)
    q_rest = -ball.gaps(np.zeros(1), 0.0)
    held = simulate(ball, (0.0, 50.0), q_rest, [0.0], NAME, h=1e-2)
    assert np.max(np.abs(held.gap)) <= 1e-14 and np.max(np.abs(held.v)) <= 1e-14
    # velocity level alone: the gap sinks by about h^2 g beta per step (measured -0.25)
    sunk = simulate(ball, (0.0, 50.0), q_rest, [0.0], NAME, h=1e-2, position_level=False)
    assert sunk.gap[-1, 0] < -0.1


def test_a_sliding_block_stops_where_coulomb_says():
    r = simulate(Block(), (0.0, 3.0), [0.0, 0.0], [1.0, 0.0], NAME, h=1e-2)
    assert r.q[-1, 0] == pytest.approx(1.0, abs=2e-2)
    assert abs(r.v[-1, 0]) < 1e-12 and r.regime_letters()[-1] == "S"


def test_the_elastic_ball_loses_energy_only_through_the_position_correction():
    ball = make_scene("bouncing-ball", restitution=1.0)
    q0, v0 = ball.initial_state()
    r = simulate(ball, (0.0, 20.0), q0, v0, NAME, h=1e-3)
    energy = 0.5 * r.v[:, 0] ** 2 + r.q[:, 0]
    loss = energy[0] - energy[-1]
    # each impact lands the predicted, penetrating position back on the floor with the
    # velocity reversed: a loss of O(h) of the energy per impact (measured 8.8e-3 over
    # 7 impacts), and none between impacts
    assert 1e-3 < loss < 2e-2
    free = simulate(ball, (0.0, 0.5), q0, v0, NAME, h=1e-3)
    e_free = 0.5 * free.v[:, 0] ** 2 + free.q[:, 0]
    assert np.max(np.abs(e_free - e_free[0])) < 1e-12


def test_friction_drive_steady_state_against_the_reference():
    sc = make_scene("friction-drive", frequency=185.0)
    ref = steady_of(sc, ED_REFERENCE).displacement_per_period
    ss = steady_of(sc, make_scheme(NAME, steps_per_period=1600))
    # measured 2.0e-3 (3.3e-2 at 400): the persistent contact is first order
    assert abs(ss.displacement_per_period / ref - 1.0) < 5e-3


@pytest.mark.parametrize("options, message", [
    ({"h": 0.0}, "`h` must be"),
    ({}, "`h` (the time step) is required"),
    ({"h": 1e-3, "rho_inf": 1.5}, "`rho_inf` must be in [0.0, 1.0]"),
    ({"h": 1e-3, "rho_inf": float("nan")}, "`rho_inf`"),
    ({"h": 1e-3, "position_level": "yes"}, "`position_level` must be True or False"),
    ({"h": 1e-3, "lcp_method": "pgs"}, "`lcp_method` must be one of"),
    ({"h": 1e-3, "theta": 0.5}, "`theta` is not an option of scheme"),
])
def test_bad_options_are_refused_by_name(options, message):
    with pytest.raises(InputError) as err:
        simulate(Block(), (0.0, 1.0), [0.0, 0.0], [1.0, 0.0], NAME, **options)
    assert message in str(err.value)


@pytest.mark.parametrize("scene_name", ["bouncing-ball", "friction-drive", "sliding-box"])
def test_the_compiled_loop_is_the_generic_step(scene_name):
    # impacts with the position correction, the rheonomic frictional drive (Newton on
    # its nonlinear forces), two contacts through Lemke in both problems
    sc = make_scene(scene_name)
    q0, v0 = sc.initial_state()
    T = sc.period or 2.0
    # 397 steps: at 400 the ball's predicted position meets the floor exactly on a grid
    # time, where rounding alone decides between contact and flight
    fast = simulate(sc, (0.0, 2 * T), q0, v0, NAME, h=T / 397, fast=True)
    slow = simulate(sc, (0.0, 2 * T), q0, v0, NAME, h=T / 397, fast=False)
    assert fast.success and slow.success and fast.t.shape == slow.t.shape
    assert np.max(np.abs(fast.q - slow.q)) <= 1e-11 * max(1.0, np.max(np.abs(slow.q)))
    assert np.max(np.abs(fast.v - slow.v)) <= 1e-11 * max(1.0, np.max(np.abs(slow.v)))
    assert np.array_equal(fast.regime, slow.regime)
