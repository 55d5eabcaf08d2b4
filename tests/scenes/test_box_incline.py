"""The box on the incline (four corner contacts) against its closed form."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.model.space import Box, SpaceModel
from moreau.scenes.box_incline import box_incline, box_incline_motion, stop_time

#: corners 1 and 3 sit at x = +a, down the slope (moreau.model.space.Box's numbering)
FRONT, BACK = [1, 3], [0, 2]


def _run(theta, n=200, window=10.0, cone="exact", **overrides):
    sc = box_incline(**overrides)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, window), q0, v0, "moreau-jean", h=window / n, theta=theta, cone=cone)
    assert res.status == 0
    s, sd, nf, nb = box_incline_motion(sc.params, res.t * sc.time)
    weight = sc.params.mass * sc.params.gravity
    return sc, res, s / sc.length, sd * sc.time / sc.length, nf / weight, nb / weight


@pytest.mark.parametrize("cone", ["exact", 8])
def test_the_box_slides_at_g_sin_minus_mu_cos_on_its_four_corners(cone):
    # midpoint: the constant acceleration exactly; the corners' normal forces split front and
    # back as the moment balance says (the split between the two front corners is free)
    sc, res, s, sd, nf, nb = _run(0.5, cone=cone)
    tol = 1e-10 * np.max(np.abs(s))
    assert np.max(np.abs(res.q[:, 0] - s)) <= tol
    assert np.max(np.abs(res.v[:, 0] - sd)) <= 1e-10 * np.max(np.abs(sd))
    assert np.max(np.abs(res.force_N[1:, FRONT].sum(axis=1) - nf[1:])) <= 1e-10
    assert np.max(np.abs(res.force_N[1:, BACK].sum(axis=1) - nb[1:])) <= 1e-10
    # flat: no rotation, no lift, no lateral velocity (to the cone solver's 1e-10)
    assert np.max(np.abs(res.v[:, 1:])) <= 1e-9 * np.max(np.abs(sd))
    assert nf[-1] - nb[-1] == pytest.approx(0.2 * 0.05 / 0.1 * math.cos(0.3), rel=1e-12)


def test_the_implicit_euler_error_is_a_t_h_over_two():
    # theta = 1 moves q by h v_(k+1): s_k - s(t_k) = acc t_k h / 2 exactly for a constant
    # acceleration (the sum of the step's first-order error)
    sc, res, s, sd, _, _ = _run(1.0, n=100)
    p = sc.params
    acc = math.sin(p.slope) - p.mu * math.cos(p.slope)
    assert np.max(np.abs(res.v[:, 0] - sd)) <= 1e-10 * np.max(np.abs(sd))
    assert np.max(np.abs(res.q[:, 0] - s - 0.5 * acc * res.t * 0.1)) <= 1e-10 * np.max(s)


def test_the_box_stays_at_rest_for_mu_above_tan_alpha():
    sc, res, s, sd, nf, nb = _run(1.0, n=50, mu=0.5, speed=0.0)
    assert stop_time(sc.params) == 0.0
    assert np.max(np.abs(res.v)) <= 1e-10 and np.max(np.abs(res.q[:, :3] - res.q[0, :3])) <= 1e-10
    # at rest the friction carries m g sin(alpha): the front takes c tan(alpha) / a more
    assert np.max(np.abs(res.force_N[1:, FRONT].sum(axis=1) - nf[1:])) <= 1e-10
    assert np.max(np.abs(res.force_N[1:, BACK].sum(axis=1) - nb[1:])) <= 1e-10
    assert np.max(np.abs(res.force_N[1:].sum(axis=1) - math.cos(0.3))) <= 1e-12


def test_a_launched_box_stops_at_the_closed_form_time_and_rests():
    sc, res, s, sd, _, _ = _run(0.5, n=200, mu=0.5)
    p = sc.params
    t_stop = stop_time(p) / sc.time
    h = 10.0 / 200
    acc = abs(math.sin(p.slope) - p.mu * math.cos(p.slope))
    moving = res.t < t_stop - h
    assert np.max(np.abs(res.q[moving, 0] - s[moving])) <= 1e-10 * np.max(s)
    k = int(np.argmax(np.abs(res.v[:, 0]) <= 1e-12))
    assert res.t[k - 1] < t_stop <= res.t[k] and np.all(np.abs(res.v[k:, 0]) <= 1e-12)
    assert abs(res.q[-1, 0] - s[-1]) <= acc * h * h


def _tall_box(mu):
    # a box twice as tall as long (c = 2a): it slides flat for mu c < a and tips beyond
    m = SpaceModel(gravity=(9.81 * math.sin(0.3), 0.0, -9.81 * math.cos(0.3)), length=0.05)
    plane = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    a, b, c = 0.05, 0.05, 0.1
    J = [(b * b + c * c) / 3.0, (a * a + c * c) / 3.0, (a * a + b * b) / 3.0]
    box = m.add_body(1.0, J, position=(0.0, 0.0, c), velocity=(1.0, 0.0, 0.0))
    m.add_contact(box, Box((a, b, c), corners=(0, 1, 2, 3)), plane, mu=mu)
    return m.build("tall-box")


@pytest.mark.parametrize("mu, tips", [(0.45, False), (0.55, True)])
def test_the_box_tips_over_its_front_edge_for_mu_c_above_a(mu, tips):
    sc = _tall_box(mu)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.02, cone="exact")
    back = res.force_N[1:, BACK].sum(axis=1)
    if tips:
        # the back corners lift (their gaps open) and the box pitches forward
        assert back[-1] == 0.0 and np.min(res.gap[-1, BACK]) > 1e-3 and res.v[-1, 4] > 0.0
    else:
        assert np.all(back > 0.0) and np.max(np.abs(res.v[:, 3:])) <= 1e-9


def test_parameters_that_tip_the_box_are_refused_by_name():
    with pytest.raises(InputError, match="`mu` times `half_height` must be below"):
        box_incline(mu=0.25, half_height=0.4, half_length=0.1, slope=0.2)
    with pytest.raises(InputError, match="`slope`'s tangent times `half_height`"):
        box_incline(mu=0.9, speed=0.0, half_height=0.4, half_length=0.1)
