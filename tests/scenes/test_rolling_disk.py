"""The rolling disk's steady precession: its relation at rounding, and Moreau–Jean's order on it.

The scheme runs a quarter precession period from the steady state with the
exact cone; the errors of the tilt (largest over the run) and of the mean
precession rate are fitted over ``h, h/2, h/4``.
"""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.model.spatial import rotation_matrix
from moreau.scenes.rolling_disk import (rolling_disk, rolling_disk_exact, steady_motion,
                                        tilt_and_heading)


def _order(steps, errors):
    return -np.polyfit(np.log(steps), np.log(errors), 1)[0]


@pytest.mark.parametrize("overrides", [{}, {"tilt": 0.7, "circle": 0.1, "mu": 2.0}])
def test_the_started_state_satisfies_newton_euler_with_a_rolling_contact_at_rounding(overrides):
    sc = rolling_disk(**overrides)
    p = sc.params
    s = steady_motion(p)
    q, v = sc.initial_state()
    # rolling: on the floor, the contact point at rest
    WN, _, WT, _ = sc.contact_jacobians(q, 0.0)
    assert abs(sc.gaps(q, 0.0)[0]) < 1e-15
    assert np.max(np.abs(WN @ v)) < 1e-14 and np.max(np.abs(WT @ v)) < 1e-13
    # the steady accelerations: the centre towards the circle's centre (the origin), the body
    # rate turning with the precessing frame, d(omega_body)/dt = R^T (Omega z x omega_world)
    W = s["precession"] * sc.time
    R = rotation_matrix(q[3:7])
    acc = np.concatenate([-W * W * np.array([q[0], q[1], 0.0]),
                          R.T @ np.cross([0.0, 0.0, W], R @ v[3:6])])
    # Newton-Euler with the scene's own forces (gravity, gyroscopic) and contact rows: the
    # contact force that makes up the difference, by least squares on all six equations
    H = sc.contact_rows(q)[0]
    lhs = sc.mass(q) @ acc - sc.forces(q, v, 0.0)
    lam, *_ = np.linalg.lstsq(H.T, lhs, rcond=None)
    assert np.max(np.abs(H.T @ lam - lhs)) < 1e-14 * np.max(np.abs(lhs))
    # the weight (1 in the scene's units) and the friction ratio of the closed form
    assert lam[0] == pytest.approx(1.0, rel=1e-14)
    assert math.hypot(lam[1], lam[2]) / lam[0] == pytest.approx(s["friction_ratio"], rel=1e-13)
    # and the contact stays closed and rolling at the acceleration level
    wN, wT = sc.contact_drift(q, v, 0.0)
    assert np.max(np.abs(H @ acc + np.concatenate([wN, wT]))) < 1e-14 * W * W * 10.0


def test_the_exact_motion_starts_at_the_scenes_state_and_the_relation_meets_its_limits():
    sc = rolling_disk()
    p = sc.params
    q, v = sc.initial_state()
    eps = 1e-5
    (x0, x1), (p0, p1) = (np.asarray(a) for a in rolling_disk_exact(p, [-eps, eps]))
    assert np.allclose((x1 - x0) / (2 * eps), v[:3] * sc.length / sc.time, rtol=0, atol=1e-8)
    # the body rate from the quaternion's difference: 2 conj(p) dp/dt
    pm = 0.5 * (p0 + p1)
    dp = (p1 - p0) / (2 * eps)
    w = 2.0 * np.array([pm[0] * dp[1] - pm[1] * dp[0] - pm[2] * dp[3] + pm[3] * dp[2],
                        pm[0] * dp[2] + pm[1] * dp[3] - pm[2] * dp[0] - pm[3] * dp[1],
                        pm[0] * dp[3] - pm[1] * dp[2] + pm[2] * dp[1] - pm[3] * dp[0]])
    assert np.allclose(w, v[3:6] / sc.time, rtol=0, atol=1e-6 * np.max(np.abs(w)))
    # Euler's disk (the centre at rest): Omega^2 = 4 g / (a sin(theta)) (Moffatt 2000)
    e = steady_motion(circle=p.radius * math.cos(p.tilt))
    assert e["precession"] ** 2 == pytest.approx(4 * p.gravity / (p.radius * math.sin(p.tilt)),
                                                 rel=1e-14)
    # a large circle: the leaning coin's tan(pi/2 - theta) = 3 v^2 / (2 g b), to O(a / b)
    c = steady_motion(circle=100.0, mu=2.0)
    lean = 3 * c["speed"] ** 2 / (2 * p.gravity * c["centre_radius"])
    assert abs(lean / math.tan(0.5 * math.pi - p.tilt) - 1.0) < p.radius / 100.0


@pytest.mark.parametrize("theta, steps", [(0.5, (50, 100, 200)), (1.0, (100, 200, 400))])
def test_moreau_jean_keeps_the_tilt_and_the_precession_rate_to_order_one(theta, steps):
    sc = rolling_disk()
    p = sc.params
    span = sc.default_window
    W = steady_motion(p)["precession"] * sc.time
    q0, v0 = sc.initial_state()
    tilt_err, rate_err = [], []
    for n in steps:
        res = simulate(sc, (0.0, span), q0, v0, "moreau-jean", h=span / n, theta=theta,
                       cone="exact")
        assert res.status == 0 and set(res.regime_letters()) == {"S"}
        tilt, heading = tilt_and_heading(res.q)
        tilt_err.append(np.max(np.abs(tilt - p.tilt)))
        rate_err.append(abs(heading[-1] / span - W) / W)
        assert abs(np.linalg.norm(res.q[-1, 3:7]) - 1.0) <= 1e-15
    # measured (tilt [rad], rate relative): theta = 1/2: 0.0113, 0.0059, 0.0030 and 0.021,
    # 0.011, 0.0059; theta = 1: 0.115, 0.055, 0.027 and 0.14, 0.069, 0.034
    assert 0.9 < _order(steps, tilt_err) < 1.1 and 0.9 < _order(steps, rate_err) < 1.1
    assert tilt_err[-1] < (0.0035 if theta == 0.5 else 0.03)


@pytest.mark.parametrize("overrides, match", [
    ({"circle": 0.01}, r"`circle` must be > \(5/6\) radius cos\(tilt\)"),
    ({"mu": 0.1}, "`mu` must be >= 0.2558"),
    ({"tilt": 1.6}, "`tilt` must be"),
    ({"radius": -0.05}, "`radius` must be > 0"),
])
def test_bad_parameters_are_refused_by_name(overrides, match):
    with pytest.raises(InputError, match=match):
        rolling_disk(**overrides)
