"""Regularised (compliant) contact under Radau and RK45, against exact non-smooth solutions."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.compliant import damping_for_restitution
from moreau.scenes import make_scene


def _ball_error(stiffness, method="compliant-radau"):
    # elastic ball (e = 1, no damping): the compliant bounce converges to the exact one;
    # radius 0.5: the soft contact (k = 1e2) sinks 0.14, deeper than the default ball's 0.05
    # radius, past the ball's valid region (its centre above the floor)
    ball = make_scene("bouncing-ball", restitution=1.0, radius=0.5)
    q0, v0 = ball.initial_state()
    T = 2.5                     # past the first bounce (at sqrt(2))
    r = simulate(ball, (0.0, T), q0, v0, method, stiffness=stiffness, damping=0.0,
                 rtol=1e-10, atol=1e-12)
    assert r.success, r.message
    qe, _ = ball.exact_solution([T], q0, v0)
    return abs(r.q[-1, 0] - qe[0, 0])


def test_elastic_ball_converges_to_the_exact_bounce_as_the_contact_stiffens():
    # k = 1e2, 1e4, 1e6 rather than 1e3 .. 1e7: the stiffest run is most of the cost
    # (Radau at k = 1e7: 9.5 of 13 CPU s); measured errors 0.162, 0.0109, 0.00104
    errors = [_ball_error(k) for k in (1e2, 1e4, 1e6)]
    # the contact lasts ~ pi / sqrt(k): the error falls about tenfold per hundredfold k
    assert errors[0] > 3 * errors[1] > 9 * errors[2]
    # within 1.5e-3 at k = 1e6 (measured 1.04e-3; 3.3e-4 at k = 1e7)
    assert errors[2] < 1.5e-3


def _one_dof_restitution(k, c, v_in):
    # an independent computation of the clamped Kelvin-Voigt contact: a unit mass hitting
    # a spring-damper at speed v_in, without gravity, until the force k d + c d' returns to 0
    def rhs(t, y):
        return [y[1], -(k * y[0] + c * y[1])]

    def release(t, y):
        return k * y[0] + c * y[1] if t > 0 else 1.0
    release.terminal, release.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 10.0 / math.sqrt(k)), [0.0, v_in], events=release, rtol=1e-12,
                    atol=1e-14, max_step=0.01 / math.sqrt(k))
    return -sol.y_events[0][0][1] / v_in


@pytest.mark.parametrize("e", [0.3, 0.8])
def test_kelvin_voigt_ball_rebounds_as_the_one_dof_contact_model(e):
    k = 1e6
    ball = make_scene("bouncing-ball", restitution=e)
    q0, v0 = ball.initial_state()
    # to 1.45: the first contact (from t = sqrt(2)) ends at 1.4166; the flight after it was
    # 15 % of the run to 1.6 and gives no sample the checks read
    r = simulate(ball, (0.0, 1.45), q0, v0, "compliant-radau", stiffness=k, rtol=1e-10,
                 atol=1e-13)
    assert r.success
    v = r.v[:, 0]
    v_in = math.sqrt(2.0)                       # free fall from one unit above the floor
    leave = np.flatnonzero((r.force_N[:-1, 0] > 0) & (r.force_N[1:, 0] == 0))[0] + 1
    expected = _one_dof_restitution(k, damping_for_restitution(e, k, 1.0), v_in)
    # gravity is about 1e-6 of the contact force: the rebound is the 1-dof contact's
    assert v[leave] / v_in == pytest.approx(expected, rel=2e-3)
    # the damping is chosen for the clamped law: the rebound is the scene's restitution
    assert expected == pytest.approx(e, rel=1e-6)


def test_sliding_block_stops_where_the_exact_block_stops():
    blk = make_scene("sliding-block", mu=0.3)
    q0, v0 = blk.initial_state()
    T = 1.0 / (0.3 * 1.0) + 1.0                 # past the stop at v0 / (mu g)
    qe, ve = blk.exact_solution([T], q0, v0)
    errs = []
    for k, eps in ((1e3, 1e-2), (1e4, 1e-3)):
        r = simulate(blk, (0.0, T), q0, v0, "compliant-radau", stiffness=k,
                     friction_velocity=eps, rtol=1e-10, atol=1e-12)
        assert r.success
        errs.append(abs(r.q[-1, 0] - qe[0, 0]))
    # measured 1.3e-3 and 4.4e-5
    assert errs[1] < errs[0] / 10 and errs[1] < 1e-4
    # resting on the spring: penetration g / k
    assert r.q[-1, 1] == pytest.approx(-1.0 / 1e4, rel=1e-6)


def test_radau_and_rk45_integrate_the_same_model():
    blk = make_scene("sliding-block", mu=0.3, incline=0.2)
    q0, v0 = blk.initial_state()
    opts = dict(stiffness=1e5, friction_velocity=1e-3, rtol=1e-10, atol=1e-12)
    a = simulate(blk, (0.0, 2.0), q0, v0, "compliant-radau", **opts)
    b = simulate(blk, (0.0, 2.0), q0, v0, "compliant-rk45", **opts)
    assert a.success and b.success
    np.testing.assert_allclose(a.q[-1], b.q[-1], atol=1e-7)


def test_samples_on_a_grid_and_regimes_named():
    blk = make_scene("sliding-block", mu=0.3)
    q0, v0 = blk.initial_state()
    r = simulate(blk, (0.0, 4.0), q0, v0, "compliant-radau", stiffness=1e3,
                 friction_velocity=1e-2, rtol=1e-6, atol=1e-9, sample_dt=0.25)
    np.testing.assert_allclose(r.t, np.arange(0.0, 4.01, 0.25), atol=1e-12)
    # slides forward, then sticks (at t = 0 it only touches: no force yet)
    assert set(np.unique(r.regime[r.t > 0.1])) == {1, 3}


@pytest.mark.parametrize("opts, message", [
    ({"stiffness": -1.0}, "`stiffness` must be > 0"),
    ({"friction_velocity": 0.0}, "`friction_velocity` must be > 0"),
    ({"contact_model": "hertz"}, "`contact_model` must be one of"),
    ({"damping": -2.0}, "`damping` must be >= 0"),
    ({"theta": 0.5}, "`theta` is not an option of scheme 'compliant-rk45'"),
])
def test_bad_options_are_refused_by_name(opts, message):
    ball = make_scene("bouncing-ball")
    q0, v0 = ball.initial_state()
    with pytest.raises(InputError, match=message):
        simulate(ball, (0.0, 1.0), q0, v0, "compliant-rk45", **opts)


def test_clamped_restitution_matches_the_one_dof_contact_and_is_bounded_below():
    from moreau.integrators.compliant import clamped_restitution
    for zeta in (0.05, 0.3, 0.8):
        c = 2.0 * zeta * 1e3
        assert clamped_restitution(zeta) == pytest.approx(_one_dof_restitution(1e6, c, 1.0),
                                                          rel=1e-6)
        # faster than the unclamped spring-damper's exp(-zeta pi / sqrt(1 - zeta^2))
        assert clamped_restitution(zeta) > math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2))
    # no clamped Kelvin-Voigt contact is fully plastic: critical damping below ~0.136
    assert damping_for_restitution(0.0, 1e6, 1.0) == pytest.approx(2.0 * 1e3)


# -- the stuck phase under Radau: the velocity tolerance's rounding floor ------------------

_BOX_OPTS = dict(stiffness=1e3, rtol=1e-9, atol=1e-12, friction_velocity=1e-3)


def _box_at_rest():
    # the sliding box's rest state under the compliant model: both corners pressed in by
    # their share of the weight (no tilt, no motion)
    from moreau.integrators.compliant import CompliantRadau
    box = make_scene("sliding-box", mu=0.4)
    q0, v0 = box.initial_state()
    scheme = CompliantRadau(box, 0.0, q0, 0.0 * v0, 1.0, **_BOX_OPTS)
    return box, scheme


def test_one_rounding_of_a_coordinate_moves_the_acceleration_by_at_most_the_floors_bound():
    # the floor assumes that one ulp of a coordinate changes the acceleration by at most
    # (k / m_min) ulp(q); measured on the right-hand side itself, at the box's rest state
    box, scheme = _box_at_rest()
    n = box.ndof
    q = np.array([0.0, box.b - 0.25e-3, 0.0])          # each corner carries 1/4 of weight/k
    y = np.concatenate([q, np.zeros(n)])
    a0 = scheme._rhs(0.0, y)[n:]
    WN = box.contact_jacobians(q, 0.0)[0]
    m_min = 1.0 / np.max(np.einsum("ij,jk,ik->i", WN, np.linalg.inv(box.mass(q)), WN))
    bound = scheme.stiffness / m_min * np.spacing(np.max(np.abs(q)))
    jumps = []
    for j in range(n):
        yj = y.copy()
        yj[j] = np.nextafter(yj[j], np.inf)
        jumps.append(np.max(np.abs(scheme._rhs(0.0, yj)[n:] - a0)))
    # the height's rounding is what the spring sees: a jump of the bound's size, not zero
    assert 0.05 * bound < jumps[1] <= bound
    assert max(jumps) <= bound


def test_radau_velocity_tolerance_is_floored_only_where_rounding_exceeds_it():
    box, scheme = _box_at_rest()
    # floor = 10 h omega^2 ulp(q) / newton_tol, recomputed here from its parts
    WN = box.contact_jacobians(box.initial_state()[0], 0.0)[0]
    m_min = 1.0 / np.max(np.einsum("ij,jk,ik->i", WN, np.linalg.inv(box.mass(None)), WN))
    w2 = 1e3 / m_min
    h = min(scheme.max_step, 1.0 / math.sqrt(w2))
    newton_tol = max(10 * np.finfo(float).eps / 1e-9, min(0.03, math.sqrt(1e-9)))
    assert scheme.velocity_atol == pytest.approx(10 * h * w2 * np.spacing(box.b) / newton_tol,
                                                 rel=1e-12)
    # a looser tolerance than the floor is kept as given
    from moreau.integrators.compliant import CompliantRadau
    loose = CompliantRadau(box, 0.0, *box.initial_state(), 1.0, **dict(_BOX_OPTS, atol=1e-6))
    assert loose.velocity_atol == 1e-6


def test_radau_sliding_box_comes_to_rest_without_rebuilding_its_jacobian_every_step():
    # the defect: with atol 1e-12 on the velocities, Radau's Newton iteration saw only the
    # rounding of the contact spring once the box stopped (t > 3.1), failed nearly every step,
    # rebuilt its Jacobian and halved the step: 12 015 Jacobians for the window (t <= 3.75),
    # 51 s. Counted, not timed.
    box = make_scene("sliding-box", mu=0.4)
    q0, v0 = box.initial_state()
    r = simulate(box, (0.0, 3.75), q0, v0, "compliant-radau", **_BOX_OPTS)
    assert r.success
    assert r.stats["jacobian_evaluations"] < 200, r.stats
    # stopped where the rigid box stops (v0^2 / (2 mu) = 1.25), up to the compliant model's
    # error, and at rest
    assert abs(r.q[-1, 0] - 1.25) < 1e-3
    assert np.max(np.abs(r.v[-1])) < 1e-9


@pytest.mark.slow
def test_radau_rest_phase_answer_is_unchanged_by_the_floor(monkeypatch):
    # the same stuck phase without the floor (slow: thousands of Jacobians) gives the same
    # stopping distance to the integrator's tolerance
    from moreau.integrators import compliant
    box = make_scene("sliding-box", mu=0.4)
    q0, v0 = box.initial_state()
    with_floor = simulate(box, (0.0, 3.3), q0, v0, "compliant-radau", **_BOX_OPTS)
    monkeypatch.setattr(compliant._Compliant, "_velocity_atol_floor", lambda self, m, q: 0.0)
    without = simulate(box, (0.0, 3.3), q0, v0, "compliant-radau", **_BOX_OPTS)
    assert without.stats["jacobian_evaluations"] > 10 * with_floor.stats["jacobian_evaluations"]
    assert abs(with_floor.q[-1, 0] - without.q[-1, 0]) < 1e-9 * 1.25
