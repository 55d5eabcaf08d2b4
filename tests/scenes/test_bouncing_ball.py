"""Bouncing ball: input checks, scene formulas, the exact impact series."""

import math

import numpy as np
import pytest

import moreau.integrators.moreau_jean  # noqa: F401  (registers "moreau-jean")
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.bouncing_ball import BouncingBall, BouncingBallParams


def central(f, s=1e-5):
    return (f(s) - f(-s)) / (2.0 * s)


# -- input checks -------------------------------------------------------------
@pytest.mark.parametrize("kwargs, match", [
    ({"mass": 0.0}, r"`mass` must be > 0"),
    ({"radius": -0.1}, r"`radius` must be > 0"),
    ({"gravity": float("nan")}, r"`gravity` must be finite"),
    ({"length": float("inf")}, r"`length` must be finite"),
    ({"restitution": 1.2}, r"`restitution` must be in \[0.0, 1.0\]"),
    ({"restitution": -0.1}, r"`restitution` must be in \[0.0, 1.0\]"),
    ({"bounce": 0.5}, r"`bounce` is not a parameter of BouncingBallParams"),
])
def test_bad_parameters_raise_input_error(kwargs, match):
    with pytest.raises(InputError, match=match):
        BouncingBall(**kwargs)


def test_params_must_be_the_right_type():
    with pytest.raises(InputError, match=r"`params` must be a BouncingBallParams"):
        BouncingBall(params={"mass": 1.0})


def test_exact_solution_rejects_bad_states():
    ball = BouncingBall(radius=0.1)
    with pytest.raises(InputError, match=r"`q0` must not penetrate the floor"):
        ball.exact_solution([0.0, 1.0], [0.05], [0.0])
    with pytest.raises(InputError, match=r"`t` must be >= 0"):
        ball.exact_solution([-1.0], [0.5], [0.0])
    with pytest.raises(InputError, match=r"`v0` must have shape \(1\)"):
        ball.zeno_time([0.5], [0.0, 1.0])
    with pytest.raises(InputError, match=r"`q0` must contain only finite values"):
        ball.impacts([np.nan], [0.0], 3)
    with pytest.raises(InputError, match=r"`n` must be an integer >= 0"):
        ball.impacts([0.5], [0.0], -1)


# -- scene formulas -------------------------------------------------------------
def test_contact_kinematics_match_finite_differences():
    ball = BouncingBall(radius=0.07, length=0.5)
    q, v, t = np.array([0.9]), np.array([-0.6]), 0.3
    WN, wN, WT, wT = ball.contact_jacobians(q, t)
    assert WT.shape == (0, 1) and wT.shape == (0,)
    gdot = central(lambda s: ball.gaps(q + s * v, t + s)[0])
    assert WN[0] @ v + wN[0] == pytest.approx(gdot, abs=1e-9)
    wNbar, wTbar = ball.contact_drift(q, v, t)
    rate = central(lambda s: ball.contact_jacobians(q + s * v, t + s)[0][0] @ v)
    assert wNbar[0] == pytest.approx(rate, abs=1e-9)
    assert ball.gaps(q, t)[0] == pytest.approx(0.9 - 0.14)


def test_mass_and_forces_from_the_si_lagrangian():
    # L = 1/2 m Y'^2 - m g Y in SI; scaling q by L, t by T, forces by F must
    # give M = S M_SI S / (T^2 F L) and h = S h_SI / (F L)
    p = BouncingBallParams(mass=0.3, radius=0.02, gravity=9.0, length=2.0)
    ball = BouncingBall(p)
    L, T, F = ball.length, ball.time, ball.force
    M_si = np.array([[p.mass]])
    h_si = np.array([-p.mass * p.gravity])
    S = np.diag([L])
    assert ball.mass([1.0]) == pytest.approx(S @ M_si @ S / (T ** 2 * F * L), rel=1e-14)
    assert ball.forces([1.0], [0.0], 0.0) == pytest.approx(S @ h_si / (F * L), rel=1e-14)


def test_si_round_trip_and_scales():
    ball = BouncingBall(length=2.0, gravity=8.0, mass=0.5)
    assert ball.time == pytest.approx(0.5)
    si = ball.to_si(t=[1.0], q=[[0.25]], v=[[2.0]], force=[3.0])
    assert si.t[0] == pytest.approx(0.5) and si.q[0, 0] == pytest.approx(0.5)
    assert si.v[0, 0] == pytest.approx(8.0) and si.force[0] == pytest.approx(12.0)
    back = ball.from_si(t=si.t, q=si.q, v=si.v, force=si.force)
    assert back.v[0, 0] == pytest.approx(2.0) and back.force[0] == pytest.approx(3.0)


# -- exact solution ---------------------------------------------------------------
def test_dyadic_impact_series_and_zeno_time():
    ball = BouncingBall(restitution=0.5, radius=0.1)
    q0, v0 = [0.6], [0.0]                    # 0.5 above contact: t1 = 1, V = 1
    imp = ball.impacts(q0, v0, 5)
    assert imp.t == pytest.approx([1.0, 2.0, 2.5, 2.75, 2.875], abs=1e-15)
    assert imp.v_before == pytest.approx([-1.0, -0.5, -0.25, -0.125, -0.0625])
    assert imp.v_after == pytest.approx([0.5, 0.25, 0.125, 0.0625, 0.03125])
    assert ball.zeno_time(q0, v0) == pytest.approx(3.0, abs=1e-15)


def test_impact_series_against_flight_by_flight_recursion():
    ball = BouncingBall(restitution=0.83, radius=0.05)
    q0, v0 = [0.4], [1.3]                    # thrown upwards
    y, u, t, times = 0.4, 1.3, 0.0, []
    for _ in range(30):
        # next landing of the parabola y + u s - s^2/2 = r
        s = u + math.sqrt(u * u + 2.0 * (y - 0.05))
        t += s
        times.append(t)
        y, u = 0.05, -0.83 * (u - s)
    imp = ball.impacts(q0, v0, 30)
    assert imp.t == pytest.approx(times, rel=1e-13)
    # t_inf is the limit of the impact times; the tail after 30 impacts is
    # 2 V e^30 / (1 - e) with V the first impact speed
    V = -imp.v_before[0]
    tail = 2.0 * V * 0.83 ** 30 / (1 - 0.83)
    assert ball.zeno_time(q0, v0) == pytest.approx(times[-1] + tail, rel=1e-13)
    # each impact keeps the fraction e^2 of the kinetic energy
    assert (imp.v_after / imp.v_before) ** 2 == pytest.approx(np.full(30, 0.83 ** 2))


def test_exact_solution_is_a_chain_of_parabolas():
    ball = BouncingBall(restitution=0.7, radius=0.1)
    q0, v0 = [1.1], [0.4]
    imp = ball.impacts(q0, v0, 6)
    # just before and after each impact: at the floor, velocities from the series
    for tk, vb, va in zip(imp.t, imp.v_before, imp.v_after):
        qm, vm = ball.exact_solution([tk - 1e-9], q0, v0)
        qp, vp = ball.exact_solution([tk + 1e-9], q0, v0)
        assert qm[0, 0] == pytest.approx(0.1, abs=1e-8) and qp[0, 0] == pytest.approx(0.1, abs=1e-8)
        assert vm[0, 0] == pytest.approx(vb, abs=1e-8) and vp[0, 0] == pytest.approx(va, abs=1e-8)
    # between impacts: dy/dt = v and dv/dt = -1 (gravity)
    tm = 0.5 * (imp.t[2] + imp.t[3])
    y = lambda s: ball.exact_solution([tm + s], q0, v0)[0][0, 0]
    v = lambda s: ball.exact_solution([tm + s], q0, v0)[1][0, 0]
    assert central(y) == pytest.approx(v(0.0), abs=1e-8)
    assert central(v) == pytest.approx(-1.0, abs=1e-8)
    # after the accumulation time the ball rests on the floor
    t_inf = ball.zeno_time(q0, v0)
    q, v = ball.exact_solution([t_inf, t_inf + 5.0], q0, v0)
    assert np.all(q == 0.1) and np.all(v == 0.0)
    # approaching t_inf the motion dies out
    q, v = ball.exact_solution([t_inf - 1e-6], q0, v0)
    assert q[0, 0] - 0.1 < 1e-6 and abs(v[0, 0]) < 2e-6


def test_elastic_ball_is_periodic_and_inelastic_ball_stops():
    elastic = BouncingBall(restitution=1.0, radius=0.1)
    assert elastic.zeno_time([0.6], [0.0]) == math.inf
    q, v = elastic.exact_solution([0.3, 0.3 + 2.0, 0.3 + 200.0], [0.6], [0.0])
    assert q[:, 0] == pytest.approx(np.full(3, 0.6 - 0.5 * 0.09), abs=1e-12)
    plastic = BouncingBall(restitution=0.0, radius=0.1)
    assert plastic.zeno_time([0.6], [0.0]) == pytest.approx(1.0)
    assert len(plastic.impacts([0.6], [0.0], 10).t) == 1
    q, v = plastic.exact_solution([1.5], [0.6], [0.0])
    assert q[0, 0] == 0.1 and v[0, 0] == 0.0


def test_first_impact_in_si():
    # dropped from rest with its centre 1.25 m up: lands after sqrt(2 (H - r) / g)
    ball = BouncingBall(radius=0.05, gravity=9.81, length=1.0)
    q0 = ball.from_si(q=[1.25]).q
    t1 = ball.impacts(q0, [0.0], 1).t[0]
    assert ball.to_si(t=t1).t == pytest.approx(math.sqrt(2 * 1.2 / 9.81), rel=1e-14)


# -- Moreau–Jean against the exact solution ---------------------------------------
def fitted_order(hs, errors):
    return np.polyfit(np.log(hs), np.log(errors), 1)[0]


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_moreau_jean_converges_at_first_order(theta):
    # Impact times 1, 2, 2.5, 2.75, ... are dyadic, so every step size 2^-k
    # lands on them: the error then comes from the scheme alone, not from
    # where an impact happens to fall inside a step, and the fitted slope is
    # clean. The run ends at 2.6, after three impacts.
    ball = BouncingBall(restitution=0.5, radius=0.1)
    q0, v0 = [0.6], [0.0]
    hs = [2.0 ** -k for k in range(4, 10)]
    errors = []
    for h in hs:
        res = simulate(ball, (0.0, 2.6), q0, v0, "moreau-jean", h=h, theta=theta)
        assert res.status == 0
        q_exact, _ = ball.exact_solution(res.t, q0, v0)
        errors.append(np.max(np.abs(res.q[:, 0] - q_exact[:, 0])))
    assert 0.8 <= fitted_order(hs, errors) <= 1.3
    assert errors[-1] < 5e-3


def test_moreau_jean_ball_comes_to_rest_after_the_zeno_point():
    ball = BouncingBall(restitution=0.5, radius=0.1)
    res = simulate(ball, (0.0, 4.0), [0.6], [0.0], "moreau-jean", h=2.0 ** -8)
    late = res.t > 3.1                        # past t_inf = 3
    assert np.all(np.abs(res.v[late, 0]) < 1e-12)
    assert np.all(np.abs(res.q[late, 0] - 0.1) < 2.0 ** -8)
