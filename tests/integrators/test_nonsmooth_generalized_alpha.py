"""Nonsmooth generalized-α: order, impacts, drift, friction, energy, options."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from moreau.analysis.scheme_settings import ED_REFERENCE, make_scheme, steady_of
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.nonsmooth_generalized_alpha import (alpha_coefficients,
                                                            consistent_acceleration,
                                                            contact_drift_of, mixed_projection)
from moreau.model.registry import make_scene

from _toy_scenes import Block, ForcedSlider, Oscillator

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


@pytest.mark.slow
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
    assert np.max(np.abs(held.force_N[1:, 0] - 1.0)) <= 1e-12
    # the smooth contact force holds it at velocity level alone, too (before the smooth
    # force the weight came through the impulses and the gap sank to -0.25)
    also = simulate(ball, (0.0, 50.0), q_rest, [0.0], NAME, h=1e-2, position_level=False)
    assert np.max(np.abs(also.gap)) <= 1e-14


def test_second_order_in_a_persistent_sliding_contact():
    # the contact stays closed and slides under smooth forcing: measured slope 2.00
    # (errors 3.1e-3 ... 4.9e-5 at h = 0.1 ... 0.0125; the scheme without the smooth
    # force: 0.97, errors 2.7e-2 ... 3.7e-3)
    ref = solve_ivp(ForcedSlider.sliding_rhs, (0.0, 3.0), [0.0, 1.0], rtol=1e-13, atol=1e-14,
                    dense_output=True)
    hs = [0.1 / 2**k for k in range(4)]
    errs = []
    for h in hs:
        r = simulate(ForcedSlider(), (0.0, 3.0), [0.0, 0.0], [1.0, 0.0], NAME, h=h)
        x, v = ref.sol(r.t)
        errs.append(max(np.max(np.abs(r.q[:, 0] - x)), np.max(np.abs(r.v[:, 0] - v))))
        # no drift, no impulse: the gap and the normal velocity stay at rounding level
        assert np.max(np.abs(r.gap)) <= 1e-14 and np.max(np.abs(r.v[:, 1])) <= 1e-14
        assert set(r.regime_letters()[1:]) == {"P"}
        assert np.max(np.abs(r.force_N[1:, 0] - (1.0 - 0.5 * np.sin(3.0 * r.t[1:])))) < 1e-12
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert slope >= 1.9 and errs[-1] < 1e-4


def test_a_block_sliding_down_an_incline_is_exact():
    # constant forces: with a consistent start acceleration (the contact force in a_0) the
    # generalized-alpha step is exact; with a_0 = M^-1 h the error was O(h)
    sc = make_scene("sliding-block", incline=0.5, mu=0.3)
    acc = np.sin(0.5) - 0.3 * np.cos(0.5)
    for fast in (True, False):
        r = simulate(sc, (0.0, 2.0), [0.0, 0.0], [1.0, 0.0], NAME, h=0.01, fast=fast)
        assert np.max(np.abs(r.q[:, 0] - (r.t + 0.5 * acc * r.t**2))) < 1e-12
        assert np.max(np.abs(r.v[:, 0] - (1.0 + acc * r.t))) < 1e-12
        assert np.max(np.abs(r.gap)) <= 1e-14


def test_the_start_acceleration_carries_the_contact_forces():
    sc = make_scene("sliding-block", incline=0.3, mu=0.5)
    # sliding: the weight's normal part and -mu of it along the slide
    acc, lam = consistent_acceleration(sc, np.zeros(2), np.array([1.0, 0.0]), 0.0)
    assert acc == pytest.approx([np.sin(0.3) - 0.5 * np.cos(0.3), 0.0], abs=1e-15)
    assert lam == pytest.approx([np.cos(0.3)], abs=1e-15)
    # at rest with tan(alpha) < mu: it sticks
    acc, lam = consistent_acceleration(sc, np.zeros(2), np.zeros(2), 0.0)
    assert acc == pytest.approx([0.0, 0.0], abs=1e-15)
    # lifting off (normal velocity > 0) or in flight: no contact force
    acc, lam = consistent_acceleration(sc, np.zeros(2), np.array([0.0, 1.0]), 0.0)
    assert lam == pytest.approx([0.0]) and acc == pytest.approx([np.sin(0.3), -np.cos(0.3)])


def test_the_drift_terms_by_differences_match_a_scenes_own():
    sc = make_scene("friction-drive")
    q, v = np.array([0.3, -0.2]), np.array([0.7, 1.1])
    own = sc.contact_drift(q, v, 0.4)

    class NoDrift(type(sc)):
        def contact_drift(self, q, v, t):
            raise NotImplementedError

    fd = contact_drift_of(NoDrift(), q, v, 0.4)
    assert np.allclose(fd[0], own[0], rtol=1e-7, atol=1e-9)
    assert np.allclose(fd[1], own[1], rtol=1e-7, atol=1e-9)


def test_the_mixed_projection_holds_equalities_and_complementarity():
    W = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]])
    g = np.array([0.3, -0.5, 0.4])
    eq = np.array([True, False, False])
    nu = mixed_projection(W, g, eq)
    u = W @ nu + g
    assert abs(u[0]) < 1e-14
    assert np.all(nu[1:] >= 0.0) and np.all(u[1:] >= -1e-14) and abs(nu[1:] @ u[1:]) < 1e-14
    assert nu[0] < 0.0    # an equality row pulls as well as pushes


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


@pytest.mark.slow
def test_friction_drive_steady_state_against_the_reference():
    sc = make_scene("friction-drive", frequency=185.0)
    ref = steady_of(sc, ED_REFERENCE).displacement_per_period
    ss = steady_of(sc, make_scheme(NAME, steps_per_period=1600))
    # measured -1.04e-3 (-4.8e-3 at 400, -1.6e-4 at 6400); before the smooth contact force
    # 2.0e-3 (3.3e-2 at 400). The slip reversals inside a step keep it near first order
    assert abs(ss.displacement_per_period / ref - 1.0) < 2e-3


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


@pytest.mark.parametrize("scene_name", ["bouncing-ball", "friction-drive", "sliding-box",
                                        "sliding-block"])
def test_the_compiled_loop_is_the_generic_step(scene_name):
    # impacts with the position correction, the rheonomic frictional drive (Newton on
    # its nonlinear forces, the smooth force in persistent slip), two contacts through
    # Lemke in all three problems, a block sliding to rest
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
    assert np.max(np.abs(fast.force_N - slow.force_N)) <= 1e-9
    # once the box rests on two corners the split of its (zero) friction force between them
    # is not determined, and the two Lemke codes pick different vertices: the regimes are
    # compared while it moves, the resultant everywhere
    moving = np.max(np.abs(slow.v), axis=1) > 1e-12
    assert np.array_equal(fast.regime[moving], slow.regime[moving])
    assert np.max(np.abs(fast.force_T.sum(axis=1) - slow.force_T.sum(axis=1))) <= 1e-9


@pytest.mark.slow
def test_second_order_on_the_painleve_rod_sliding_on_its_tip():
    # a registered scene, compiled loop: the rod slides on its tip for the whole window
    # (persistent frictional contact, mu = 2); against the sliding ODE at rtol 1e-12:
    # trajectory errors 3.0e-7, 3.4e-8, 3.0e-9 at 100, 300, 1000 steps (Moreau-Jean
    # theta = 1: 9.8e-4 ... 3.3e-5)
    from moreau.analysis.compare import fit_order, make_case
    case = make_case("painleve-rod")
    steps = [100, 200, 400]
    errs = []
    for n in steps:
        opts = {"steps_per_period": n}
        out = case.scheme(NAME, opts)
        errs.append(case.measure_scheme(NAME, opts, out))
    assert fit_order(steps, errs) >= 1.9 and errs[-1] < 3e-8
