"""The generic event-driven integrator against every scene's exact solution."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from moreau.analysis.steady_state import find_steady_state
from moreau.errors import InputError
from moreau.integrators import INTEGRATORS, simulate
from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state
from moreau.scenes.friction_drive.walker import EventDriven
from moreau.integrators.event_driven_generic import EventDrivenReference, GenericEventDriven
from moreau.regimes import Regime
from moreau.scenes import (BouncingBall, FrictionDrive, PainleveRod, SawtoothDrive, SineDrive,
                           SlidingBlock, StickSlipMotor)

TWO_PI = 2.0 * math.pi
GEN = "event-driven-generic"


# -- bouncing ball ------------------------------------------------------------------

@pytest.mark.parametrize("e, q0, v0", [(0.5, 0.6, 0.0), (0.8, 1.3, 0.7), (0.3, 0.2, -2.0)])
def test_ball_impact_times_and_velocities(e, q0, v0):
    ball = BouncingBall(restitution=e, radius=0.1)
    n = 8     # rebounds stay above the accumulation threshold (1e-6 of the approach speed)
    exact = ball.impacts([q0], [v0], n)
    res = simulate(ball, (0.0, float(exact.t[-1]) + 1e-3), [q0], [v0], GEN)
    assert res.status == 0
    t_imp = np.array([ev.t for ev in res.events if ev.kind == "impact"])
    assert len(t_imp) >= n
    t_imp = t_imp[:n]
    assert np.max(np.abs(t_imp - exact.t)) <= 1e-10
    # post-impact velocity: the samples recorded at the impacts
    after = [res.v[np.flatnonzero(res.t == t)[-1], 0] for t in t_imp]
    assert np.max(np.abs(np.array(after) - exact.v_after)) <= 1e-10


def test_ball_accumulation_ends_at_rest_near_the_zeno_time():
    ball = BouncingBall(restitution=0.5, radius=0.1)
    t_inf = ball.zeno_time([0.6], [0.0])
    res = simulate(ball, (0.0, t_inf + 1.0), [0.6], [0.0], GEN)
    assert res.status == 0 and res.stats["zeno_closures"] == 1
    closing = [ev for ev in res.events if ev.after != Regime.FLIGHT]
    assert len(closing) == 1
    # the policy cuts the geometric series where the rebound speed is 1e-6 of
    # the first impact speed: the remaining flight time is below 2e-6 / (1 - e)
    assert 0.0 <= t_inf - closing[0].t <= 4e-6 * 2.0
    assert res.q[-1, 0] == pytest.approx(0.1, abs=1e-14) and res.v[-1, 0] == 0.0
    assert res.force_N[-1, 0] == pytest.approx(1.0, rel=1e-12)


def test_a_rest_after_the_accumulation_costs_nothing_more_for_a_longer_window():
    # the defect: after the Zeno closure each max_step of the rest was integrated (T = 1e3:
    # 6.3 s, T = 1e4: 56 s; `moreau run --scene bouncing-ball --duration 1e9` never ended)
    ball = BouncingBall(restitution=0.5, radius=0.1)
    runs = [simulate(ball, (0.0, T), [0.6], [0.0], GEN, t_eval=[0.5, 10.0, T]) for T in (20, 1e9)]
    for res in runs:
        assert res.status == 0 and res.stats["rest_phases"] == 1
        # the rest state, exact (sampled inside the rest phase and at its end)
        assert res.q[-1, 0] == 0.1 and res.v[-1, 0] == 0.0 and res.q[1, 0] == 0.1
        assert res.force_N[-1, 0] == pytest.approx(1.0, rel=1e-12)
        assert res.q[0, 0] == pytest.approx(0.6 - 0.125, abs=1e-12)
    # the same right-hand sides and segments (measured 1151 and 21) for 20 and 1e9
    assert runs[0].stats["rhs"] == runs[1].stats["rhs"] < 2000
    assert runs[0].stats["segments"] == runs[1].stats["segments"]


class _LoadedBlock(SlidingBlock):
    """A block at rest on a floor, pushed by a force ``(t - 2)^2`` from ``t = 2`` on."""

    def __init__(self):
        super().__init__(mu=0.5, incline=0.0)

    def forces(self, q, v, t):
        f = np.array(super().forces(q, v, t), dtype=float)
        f[0] += max(t - 2.0, 0.0) ** 2
        return f


def test_a_rest_under_a_changing_forcing_is_integrated():
    # at rest at t = 0 with the push still zero: not an equilibrium, the forcing changes
    sc = _LoadedBlock()
    q0, v0 = np.zeros(sc.ndof), np.zeros(sc.ndof)
    res = simulate(sc, (0.0, 4.0), q0, v0, GEN)
    assert res.status == 0 and "rest_phases" not in res.stats
    # slips when (t - 2)^2 reaches mu N = 0.5; x(4) = int_ts^4 (4 - s) ((s - 2)^2 - 0.5) ds
    ts = 2.0 + math.sqrt(0.5)
    u = 4.0 - ts
    # with s = 4 - w: (s - 2)^2 = (2 - w)^2, x = int_0^u w ((2 - w)^2 - 0.5) dw
    x = 2.0 * u ** 2 - 4.0 * u ** 3 / 3.0 + u ** 4 / 4.0 - 0.25 * u ** 2
    assert res.q[-1, 0] == pytest.approx(x, abs=1e-9)


def test_perfectly_elastic_ball_keeps_its_energy():
    ball = BouncingBall(restitution=1.0, radius=0.1)
    res = simulate(ball, (0.0, 10.5), [0.6], [0.0], GEN)
    t_imp = [ev.t for ev in res.events if ev.kind == "impact"]
    np.testing.assert_allclose(t_imp, ball.impacts([0.6], [0.0], len(t_imp)).t, atol=1e-10)
    assert len(t_imp) == 5


def test_an_elastic_ball_bounces_past_max_impacts_but_an_accumulation_stops():
    # `max_impacts` counts the impacts within one `max_step` of time (an accumulation),
    # not in the run: an elastic ball bounces as long as asked (it used to stop with
    # "more than `max_impacts` impacts" once it had bounced that often)
    ball = BouncingBall(restitution=1.0, radius=0.1)
    res = simulate(ball, (0.0, 10.5), [0.6], [0.0], GEN, max_impacts=2)
    assert res.status == 0 and res.stats["impacts"] == 5
    # dropped from 1e-4 above the floor it bounces every 0.028: three impacts in 0.1
    low = simulate(ball, (0.0, 1.0), [0.1001], [0.0], GEN, max_impacts=2, max_step=0.1)
    assert low.status == -5 and "more than `max_impacts`=2 impacts within `max_step`=0.1" \
        in low.message


# -- sliding block -------------------------------------------------------------------

@pytest.mark.parametrize("mu, incline, u0", [(0.5, 0.0, 2.0), (0.3, 0.2, -2.0), (0.6, 0.3, 1.5),
                                              (0.1, 0.3, -1.0)])
def test_block_stopping_time_distance_and_afterwards(mu, incline, u0):
    block = SlidingBlock(mu=mu, incline=incline)
    m = block.motion([u0, 0.0])
    t_end = m.t_stop + 2.0
    res = simulate(block, (0.0, t_end), [0.0, 0.0], [u0, 0.0], GEN)
    assert res.status == 0
    ev = res.events[0]
    assert abs(ev.t - m.t_stop) <= 1e-10 * max(1.0, m.t_stop)
    x_stop = res.q[np.flatnonzero(res.t == ev.t)[-1], 0]
    assert abs(x_stop - block.stopping_distance([u0, 0.0])) <= 1e-10
    assert Regime(ev.after) == (Regime.STICK if m.sticks else
                                (Regime.POSITIVE if m.a_after > 0 else Regime.NEGATIVE))
    q, v = block.exact_solution(t_end, [0.0, 0.0], [u0, 0.0])
    np.testing.assert_allclose(res.q[-1], q, atol=1e-10)
    np.testing.assert_allclose(res.v[-1], v, atol=1e-10)


# -- stick-slip motor -----------------------------------------------------------------

@pytest.mark.parametrize("drive", [SineDrive(), SineDrive(0.3, 0.5), SawtoothDrive(0.9, 0.5),
                                   SawtoothDrive(0.7, 1.0)], ids=repr)
def test_stick_slip_motor_steady_state_against_the_exact_walker(drive):
    motor = StickSlipMotor(drive=drive, frequency=1000.0)
    ss = stick_slip_steady_state(motor)
    u = ss.state0[0]
    res = simulate(motor, (0.0, TWO_PI), [0.0, 0.0], [u, 0.0], GEN)
    assert res.status == 0
    assert abs(res.q[-1, 0] - ss.displacement_per_period) <= 1e-8
    assert abs(res.v[-1, 0] - u) <= 1e-8
    exact = simulate(motor, (0.0, TWO_PI), [0.0, 0.0], [u, 0.0], "stick-slip-exact")
    assert [(Regime(e.before), Regime(e.after)) for e in res.events] == \
           [(Regime(e.before), Regime(e.after)) for e in exact.events]


# -- friction drive ---------------------------------------------------------------------

@pytest.mark.parametrize("f", [20.0, 185.0, 2000.0])
def test_friction_drive_steady_period_against_the_walker(f):
    sc = FrictionDrive(frequency=f)
    ss = find_steady_state(sc, rtol=1e-12)
    phi, dphi, du2 = ss.state0
    ts = ss.section_tau
    res = simulate(sc, (ts, ts + TWO_PI), [phi, 0.0], [dphi, du2], GEN)
    assert res.status == 0 and res.scheme == GEN
    dx = res.q[-1, 1]
    assert abs(dx - ss.displacement_per_period) <= 1e-8 * abs(ss.displacement_per_period)
    assert abs(res.v[-1, 1] - du2) <= 1e-8 * sc.u10
    walker = simulate(sc, (ts, ts + TWO_PI), [phi, 0.0], [dphi, du2], "friction-drive-walker")
    assert [(e.before, e.after) for e in res.events] == [(e.before, e.after) for e in walker.events]
    np.testing.assert_allclose([e.t for e in res.events], [e.t for e in walker.events], atol=1e-6)


# -- ill-posed states, names and input --------------------------------------------------

def test_painleve_configuration_is_reported():
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(phi=math.atan(2.0), tip_speed=-1.0)
    res = simulate(rod, (0.0, 1.0), q0, v0, "event-driven")
    assert res.status == -1 and "Painlevé" in res.message


def test_well_posed_rod_slides_until_it_lies_flat_and_the_run_stops_there():
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(phi=math.atan(2.0), tip_speed=1.0)
    res = simulate(rod, (0.0, 3.0), q0, v0, "event-driven")
    # the tip slides all the way down: phi reaches 0 at t = 1.46001 on the sliding ODE
    # (DOP853 at 1e-12, an event on phi); the run stops at its first sample past it,
    # where it used to go on to a stick at t = 1.893 with the rod through the floor
    sol = solve_ivp(lambda t, y: np.concatenate([y[3:], rod.sliding_accelerations(y[:3], y[3:])[0]]),
                    (0.0, 3.0), np.concatenate([q0, v0]), method="DOP853", rtol=1e-12,
                    atol=1e-12, events=_phi_zero)
    t_flat = float(sol.t_events[0][0])
    assert res.status == -6 and "0 < phi < pi" in res.message and "t = 1.46" in res.message
    assert res.t[-2] < t_flat <= res.t[-1] < t_flat + 3.0 / 256
    assert res.q[-1, 2] < 0.0 < res.q[-2, 2]
    assert set(res.regime_letters()) == {"P"} and not res.events
    # the sliding phase agrees with the scene's exact sliding accelerations
    a, lamN, _ = rod.sliding_accelerations(q0, v0)
    assert res.force_N[0, 0] == pytest.approx(lamN, rel=1e-12)


def _phi_zero(t, y):
    return y[2]


_phi_zero.terminal = True


def test_event_driven_name_selects_the_walker_for_the_friction_drive_only():
    sc = FrictionDrive()
    assert isinstance(EventDrivenReference(sc, 0.0, *sc.rest_state(), 1.0), EventDriven)
    ball = BouncingBall()
    assert isinstance(EventDrivenReference(ball, 0.0, [1.0], [0.0], 1.0), GenericEventDriven)
    assert {"event-driven", "event-driven-generic", "friction-drive-walker"} <= set(INTEGRATORS)


def test_bad_input_is_rejected_before_work():
    ball = BouncingBall(radius=0.1)
    with pytest.raises(InputError, match="`ode_method`"):
        GenericEventDriven(ball, 0.0, [1.0], [0.0], 1.0, ode_method="RK45")
    with pytest.raises(InputError, match="`q0` penetrates"):
        GenericEventDriven(ball, 0.0, [0.05], [0.0], 1.0)
    with pytest.raises(InputError, match="`rtol`"):
        GenericEventDriven(ball, 0.0, [1.0], [0.0], 1.0, rtol=0.0)


def test_radau_option_agrees():
    block = SlidingBlock(mu=0.5)
    res = simulate(block, (0.0, 5.0), [0.0, 0.0], [2.0, 0.0], GEN, ode_method="Radau")
    assert abs(res.events[0].t - 4.0) <= 1e-9
