"""Schatzman–Paoli: order, impacts, energy, friction, against exact solutions and the reference."""

import numpy as np
import pytest

from moreau.analysis.scheme_settings import ED_REFERENCE, make_scheme, steady_of
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.registry import make_scene

from _toy_scenes import Block, Oscillator


def _order(name, **options):
    hs = [0.1 / 2**k for k in range(4)]
    errs = []
    for h in hs:
        r = simulate(Oscillator(), (0.0, 4.0), [1.0], [0.0], name, h=h, **options)
        errs.append(max(abs(r.q[-1, 0] - np.cos(4.0)), abs(r.v[-1, 0] + np.sin(4.0))))
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


def test_second_order_in_a_smooth_phase_where_moreau_jean_is_first_order():
    # Stormer-Verlet in smooth phases; measured slopes 2.00 and 0.98
    assert _order("schatzman-paoli") == pytest.approx(2.0, abs=0.05)
    assert _order("moreau-jean", theta=1.0) == pytest.approx(1.0, abs=0.1)


def test_bouncing_ball_converges_to_the_exact_solution():
    ball = make_scene("bouncing-ball", restitution=0.5)
    q0, v0 = ball.initial_state()
    exact = ball.exact_solution(np.array([2.0]), q0, v0)[0][0, 0]
    errs = [abs(simulate(ball, (0.0, 2.0), q0, v0, "schatzman-paoli", h=h).q[-1, 0] - exact)
            for h in (1e-2, 1e-3, 1e-4)]
    # first order with impacts inside a step (not monotone from one h to the next)
    assert errs[-1] < 1e-3 and errs[-1] < errs[0] / 10


def test_an_elastic_ball_keeps_its_energy_between_impacts():
    ball = make_scene("bouncing-ball", restitution=1.0)
    q0, v0 = ball.initial_state()
    r = simulate(ball, (0.0, 20.0), q0, v0, "schatzman-paoli", h=1e-3)
    energy = 0.5 * r.v[:, 0] ** 2 + r.q[:, 0]
    # samples two steps away from any impulse: the impact step's own velocity is a mean
    impulse = r.force_N[:, 0] > 0
    quiet = ~(impulse | np.roll(impulse, 1) | np.roll(impulse, -1) | np.roll(impulse, 2))
    drift = np.max(np.abs(energy[quiet] - energy[0]))
    assert drift < 2e-3
    # Moreau-Jean theta = 1 loses energy at every impact
    rm = simulate(ball, (0.0, 20.0), q0, v0, "moreau-jean", h=1e-3, theta=1.0)
    assert 0.5 * rm.v[-1, 0] ** 2 + rm.q[-1, 0] < energy[0] - 5e-5   # measured 1.0e-4


def test_a_resting_contact_does_not_drift():
    ball = make_scene("bouncing-ball", restitution=0.5)
    q_rest = -ball.gaps(np.zeros(1), 0.0)            # gap 0
    r = simulate(ball, (0.0, 50.0), q_rest, [0.0], "schatzman-paoli", h=1e-2)
    # the first step starts from a virtual previous position h^2/2 below the floor
    # (the Verlet start at rest), which e lifts by e h^2 / 2; the offset decays by -e a step
    assert r.gap[1:6, 0] == pytest.approx([2.5e-5, 0.0, -1.25e-5, 0.0, 6.25e-6], abs=1e-15)
    assert np.max(np.abs(r.gap[60:])) < 1e-12 and np.max(np.abs(r.v[60:])) < 1e-10


def test_a_sliding_block_stops_where_coulomb_says():
    # speed 1, deceleration mu g = 0.5: stops at t = 2 after sliding 1
    r = simulate(Block(), (0.0, 3.0), [0.0, 0.0], [1.0, 0.0], "schatzman-paoli", h=1e-2)
    assert r.q[-1, 0] == pytest.approx(1.0, abs=1e-2)
    assert abs(r.v[-1, 0]) < 1e-12 and r.regime_letters()[-1] == "S"
    assert r.regime_letters()[50] == "P"


def test_friction_drive_steady_state_against_the_reference():
    sc = make_scene("friction-drive", frequency=185.0)
    ref = steady_of(sc, ED_REFERENCE).displacement_per_period
    sp = steady_of(sc, make_scheme("schatzman-paoli", steps_per_period=1600))
    # measured 8.8e-5 (and 1.4e-3 at 400 steps per period)
    assert abs(sp.displacement_per_period / ref - 1.0) < 2e-4


@pytest.mark.parametrize("options, message", [
    ({"h": 0.0}, "`h` must be"),
    ({"h": -1e-3}, "`h` must be"),
    ({}, "`h` (the time step) is required"),
    ({"h": 1e-3, "lcp_method": "pgs"}, "`lcp_method` must be one of"),
    ({"h": 1e-3, "lcp_method": "qp", "lemke_max_iter": 5}, "`lemke_max_iter` limits"),
    ({"h": 1e-3, "theta": 0.5}, "`theta` is not an option of scheme 'schatzman-paoli'"),
])
def test_bad_options_are_refused_by_name(options, message):
    with pytest.raises(InputError) as err:
        simulate(Block(), (0.0, 1.0), [0.0, 0.0], [1.0, 0.0], "schatzman-paoli", **options)
    assert message in str(err.value)


@pytest.mark.parametrize("scene_name", ["bouncing-ball", "friction-drive", "sliding-box"])
def test_the_compiled_loop_is_the_generic_step(scene_name):
    # one frictionless impact scene, the rheonomic frictional drive, two contacts through Lemke
    sc = make_scene(scene_name)
    q0, v0 = sc.initial_state()
    T = sc.period or 2.0
    fast = simulate(sc, (0.0, 2 * T), q0, v0, "schatzman-paoli", h=T / 400, fast=True)
    slow = simulate(sc, (0.0, 2 * T), q0, v0, "schatzman-paoli", h=T / 400, fast=False)
    assert fast.success and slow.success and fast.t.shape == slow.t.shape
    assert np.max(np.abs(fast.q - slow.q)) <= 1e-12 * max(1.0, np.max(np.abs(slow.q)))
    assert np.max(np.abs(fast.v - slow.v)) <= 1e-12 * max(1.0, np.max(np.abs(slow.v)))
    assert np.array_equal(fast.regime, slow.regime)
    assert fast.stats["lcp_solves"] == slow.stats["lcp_solves"]
