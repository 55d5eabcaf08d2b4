"""The spatial event-driven reference (one persistent contact) against the scenes' closed forms."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.model.space import Puck, Sphere, SpaceModel
from moreau.scenes.billiard_backspin import billiard_backspin, billiard_exact, rolling_onset
from moreau.scenes.bouncing_ball import BouncingBall
from moreau.scenes.puck_incline import puck_incline, puck_incline_path
from moreau.scenes.rolling_disk import rolling_disk, rolling_disk_exact, tilt_and_heading
from moreau.scenes.sphere_incline import sphere_incline, sphere_incline_exact

SCHEME = "event-driven-space"


@pytest.mark.parametrize("mu", [0.0884, 0.0883])
def test_sphere_on_the_incline_rolls_at_five_sevenths_g_sin_alpha_above_the_slip_threshold(mu):
    # slope 0.3: rolling needs mu >= (2/7) tan(0.3) = 0.08836; just below it the sphere,
    # started rolling, slips at once (the cone cannot hold the rolling friction)
    sc = sphere_incline(mu=mu)
    p = sc.params
    assert (mu >= 2.0 / 7.0 * math.tan(p.slope)) == (mu == 0.0884)
    res = simulate(sc, (0.0, 10.0), *sc.initial_state(), SCHEME, sample_dt=0.5)
    assert res.success and not res.events
    rolling = mu == 0.0884
    assert set(res.regime[:, 0].tolist()) == {3 if rolling else 1}     # STICK or sliding
    t = res.t * sc.time
    s, sd, w = sphere_incline_exact(p, t)
    L, T = sc.length, sc.time
    assert np.max(np.abs(res.q[:, 0] * L - s)) <= 1e-10 * s[-1]
    assert np.max(np.abs(res.v[:, 0] * L / T - sd)) <= 1e-10 * sd[-1]
    assert np.max(np.abs(res.v[:, 4] / T - w)) <= 1e-10 * w[-1]
    acc = (res.v[-1, 0] - res.v[0, 0]) * L / T / (t[-1] - t[0])
    exact = (5.0 / 7.0 * p.gravity * math.sin(p.slope) if rolling
             else p.gravity * (math.sin(p.slope) - mu * math.cos(p.slope)))
    assert abs(acc / exact - 1.0) <= 1e-10
    assert (np.max(res.slip_velocity) <= 1e-14) == rolling


def test_a_frictionless_sphere_slides_at_g_sin_alpha_and_keeps_its_spin():
    sc = sphere_incline(mu=0.0)
    res = simulate(sc, (0.0, 4.0), *sc.initial_state(), SCHEME, sample_dt=1.0)
    assert res.success and not res.events and set(res.regime[:, 0].tolist()) == {1}
    p, L, T = sc.params, sc.length, sc.time
    t = res.t * T
    assert np.max(np.abs(res.v[:, 0] * L / T - (p.speed + p.gravity * math.sin(p.slope) * t))) \
        <= 1e-12 * p.gravity * t[-1]
    assert np.max(np.abs(res.v[:, 4] / T - p.speed / p.radius)) <= 1e-12 * p.speed / p.radius


def test_puck_launched_across_the_incline_follows_the_closed_form_path():
    # mu = tan(slope): the slip direction turns from across the slope towards down it
    sc = puck_incline()
    res = simulate(sc, (0.0, 16.0), *sc.initial_state(), SCHEME, sample_dt=1.0)
    assert res.success and not res.events
    z = puck_incline_path(sc.params, res.t * sc.time)
    L, T = sc.length, sc.time
    scale = float(np.max(np.abs(z[:, :2])))
    assert np.max(np.abs(res.q[:, :2] * L - z[:, :2])) <= 1e-10 * scale
    assert np.max(np.abs(res.v[:, :2] * L / T - z[:, 2:])) <= 1e-10 * sc.params.speed


def test_billiard_ball_rolls_from_the_closed_form_time_at_the_closed_form_speed():
    sc = billiard_backspin()
    res = simulate(sc, (0.0, 10.0), *sc.initial_state(), SCHEME, sample_dt=0.5)
    t_star, v_star = rolling_onset(sc.params)
    (ev,) = res.events
    assert ev.kind == "transition" and (ev.before.letter, ev.after.letter) == ("P", "S")
    assert abs(ev.t * sc.time - t_star) <= 1e-10 * t_star
    L, T = sc.length, sc.time
    assert abs(res.v[-1, 0] * L / T - v_star) <= 1e-10 * v_star
    assert abs(res.v[-1, 4] * L / T - v_star) <= 1e-10 * v_star      # rolling: r w = v
    x, vx, _ = billiard_exact(sc.params, res.t * T)
    assert np.max(np.abs(res.q[:, 0] * L - x)) <= 1e-10 * x[-1]
    assert np.max(np.abs(res.v[:, 0] * L / T - vx)) <= 1e-10 * sc.params.speed
    assert res.stats["quaternion_norm_drift"] <= 1e-12


def test_rolling_disk_keeps_its_steady_precession_over_a_quarter_period():
    sc = rolling_disk()
    res = simulate(sc, (0.0, sc.default_window), *sc.initial_state(), SCHEME,
                   sample_dt=sc.default_window / 16)
    assert res.success and not res.events
    x, quat = rolling_disk_exact(sc.params, res.t * sc.time)
    tilt, heading = tilt_and_heading(res.q)
    tilt_x, heading_x = tilt_and_heading(np.hstack([x / sc.length, quat]))
    assert abs(heading_x[-1] - 0.5 * math.pi) <= 1e-12       # a quarter period
    assert np.max(np.abs(tilt - tilt_x)) <= 1e-10
    assert np.max(np.abs(heading - heading_x)) <= 1e-10
    assert np.max(np.abs(res.q[:, :3] * sc.length - x)) <= 1e-10 * sc.params.radius


def test_a_contact_that_would_lift_off_stops_the_run_by_name():
    # a ball under a ceiling: gravity pulls it off, the normal force is -m g at the start
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.1)
    ceiling = m.add_half_space((0.0, 0.0, 0.2), (0.0, 0.0, -1.0))
    ball = m.add_body(1.0, [0.004] * 3, position=(0.0, 0.0, 0.1), velocity=(1.0, 0.0, 0.0))
    m.add_contact(ball, Sphere(0.1), ceiling, mu=0.3)
    sc = m.build("ceiling")
    res = simulate(sc, (0.0, 1.0), *sc.initial_state(), SCHEME)
    assert not res.success and res.status == -2
    assert "lift-off at t = 0" in res.message and "models no flight" in res.message
    assert res.events[0].kind == "liftoff"


def test_a_scene_it_cannot_keep_is_refused_by_name():
    with pytest.raises(InputError, match="'event-driven-space' steps spatial scenes only"):
        simulate(BouncingBall(), (0.0, 1.0), [1.0], [0.0], SCHEME)
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.1)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    puck = m.add_body(1.0, [0.01, 0.01, 0.02], position=(0.0, 0.0, 0.0))
    m.add_contact(puck, Puck(0.1, 0.0), floor, mu=0.3)
    sc = m.build("puck")
    with pytest.raises(InputError, match="keeps one persistent contact: `scene` 'puck' has 3"):
        simulate(sc, (0.0, 1.0), *sc.initial_state(), SCHEME)
    q0, v0 = billiard_backspin().initial_state()
    q0[2] += 0.5
    with pytest.raises(InputError, match="must start on the contact"):
        simulate(billiard_backspin(), (0.0, 1.0), q0, v0, SCHEME)


def _egg(mu):
    # a ball of radius 0.1 m with its centre of mass 3 cm below the sphere's centre, rolling:
    # the friction that rolling needs swings with the turning offset, past the cone at mu = 0.1
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.1)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    # contact point at s = (0, 0, -0.07) from the centre of mass: x' = -w x s rolls
    egg = m.add_body(1.0, [0.004] * 3, position=(0.0, 0.0, 0.07), velocity=(0.35, 0.0, 0.0),
                     angular_velocity=(0.0, 5.0, 0.0))
    m.add_contact(egg, Sphere(0.1, centre=(0.0, 0.0, 0.03)), floor, mu=mu)
    return m.build("egg")


def test_rolling_turns_to_sliding_where_the_cone_saturates_and_back_where_the_slip_ends():
    sc = _egg(0.1)
    res = simulate(sc, (0.0, 6.0), *sc.initial_state(), SCHEME, sample_dt=0.25)
    assert res.success
    ev1, ev2 = res.events
    assert (ev1.before.letter, ev1.after.letter, ev2.before.letter, ev2.after.letter) == (
        "S", "P", "P", "S")
    # at the first event the rolling friction (the stick rows' forces, assembled here from
    # the scene) sits on the cone: mu lamN = |lamT|
    k = int(np.flatnonzero(res.t == ev1.t)[0])
    q, v = res.q[k], res.v[k]
    H = sc.contact_rows(q)[0]
    Minv = sc.mass_inverse(q)
    wN, wT = sc.contact_drift(q, v, ev1.t)
    lam = np.linalg.solve(H @ Minv @ H.T, -(H @ Minv @ sc.forces(q, v, ev1.t)
                                           + np.array([wN[0], *wT])))
    assert abs(0.1 * lam[0] - np.hypot(lam[1], lam[2])) <= 1e-9 * lam[0]
    # the slip is zero up to the first event and after the second, and not between
    k2 = int(np.flatnonzero(res.t == ev2.t)[-1])
    assert np.max(res.slip_velocity[:k, 0]) <= 1e-13
    assert np.max(res.slip_velocity[k2:, 0]) <= 1e-13
    assert np.min(res.slip_velocity[k + 1:k2, 0]) > 1e-4
    # rolling keeps the energy, sliding dissipates it
    m = sc.masses[0]
    energy = np.array([0.5 * (m * v[:3] @ v[:3] + v[3:] @ sc.inertias[0] @ v[3:])
                       - m * sc.gravity[2] * q[2] for q, v in zip(res.q, res.v)])
    assert np.ptp(energy[:k + 1]) <= 1e-10 * energy[0]
    assert np.ptp(energy[k2:]) <= 1e-10 * energy[0]
    assert energy[k2] < energy[k] - 1e-3 * energy[0] and np.all(np.diff(energy[k:k2 + 1]) <= 1e-12)
