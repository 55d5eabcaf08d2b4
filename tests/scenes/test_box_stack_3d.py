"""The stack of cubes in space: at rest each interface carries h g times the mass above, the
stack stays put; a sliding cube decelerates at mu g and stops at v^2 / (2 mu g); on an
incline it stays below the friction angle and slides at g (sin - mu cos) above it."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.box_stack_3d import BoxStack3DParams, block_motion, box_stack_3d


def _interface_totals(sc, res):
    # each step's total normal force on the plane and on each interface (scene units: m g)
    f = res.force_N[1:]
    out = [f[:, :4].sum(axis=1)]
    for k in range(1, sc.nbodies):
        out.append(f[:, 4 + 8 * (k - 1):12 + 8 * (k - 1)].sum(axis=1))
    return out


# (the offset pair with the long checks: its degenerate problems make the exact cone's Newton
# polish fail and restart from exact-arithmetic Lemke, 300 s under load)
@pytest.mark.parametrize("n, offset, steps", [(2, 0.0, 200), (3, 0.0, 40),
                                              pytest.param(2, 0.02, 40, marks=pytest.mark.slow)])
def test_a_resting_stack_carries_the_mass_above_on_each_interface_and_stays_at_rest(n, offset,
                                                                                     steps):
    sc = box_stack_3d(n_boxes=n, offset=offset)
    q0, v0 = sc.initial_state()
    h = 0.02
    res = simulate(sc, (0.0, steps * h), q0, v0, "moreau-jean", h=h, cone="exact")
    assert res.status == 0, res.message
    # the impulse of a step over interface k is h g (n - k) m: the force (n - k) m g
    for k, total in enumerate(_interface_totals(sc, res)):
        assert np.max(np.abs(total - (n - k))) <= 1e-10 * (n - k)
    # at rest: no velocity beyond rounding, positions to 1e-10, no slip; the points' friction
    # (self-balanced, indeterminate like their normal split) within the Coulomb limit
    assert np.max(np.abs(res.v)) <= 1e-12 * steps
    assert np.max(np.abs(res.q - q0)) <= 1e-10
    assert np.max(res.slip_velocity) <= 1e-12
    assert np.all(res.force_T <= 0.5 * res.force_N * (1.0 + 1e-9) + 1e-15)
    if offset:
        # two of the interface's points are the lower cube's edge crossing the upper one's
        kinds = sorted(sc._box_point(res.q[-1], i)[4].kind for i in range(4, 8))
        assert kinds == ["ee", "ee", "fa", "fa"]


def test_three_resting_cubes_on_the_eight_direction_pyramid_carry_the_mass_above():
    # the polyhedral cone (d = 8, Lemke on 12 contacts' 120-row LCP each step) on the
    # default stack: the same totals, at rest, every impulse inside its pyramid
    sc = box_stack_3d()
    assert sc.nbodies == 3
    q0, v0 = sc.initial_state()
    h, steps = 0.02, 40
    res = simulate(sc, (0.0, steps * h), q0, v0, "moreau-jean", h=h, cone=8)
    assert res.status == 0, res.message
    for k, total in enumerate(_interface_totals(sc, res)):
        assert np.max(np.abs(total - (3 - k))) <= 1e-10 * (3 - k)
    assert np.max(np.abs(res.v)) <= 1e-12 * steps
    assert np.max(np.abs(res.q - q0)) <= 1e-10
    assert np.max(res.slip_velocity) <= 1e-12
    # the inscribed octagon: |r_T| <= mu r_N
    assert np.all(res.force_T <= 0.5 * res.force_N * (1.0 + 1e-9) + 1e-15)


def test_a_sliding_cube_decelerates_at_mu_g_and_stops_at_v_squared_over_2_mu_g():
    p = BoxStack3DParams(n_boxes=1, speed=0.5, mu=0.4)
    sc = box_stack_3d(p)
    q0, v0 = sc.initial_state()
    t_stop = p.speed / (p.mu * p.gravity) / sc.time        # scene units
    h = t_stop / 40                                         # the stop on a step's end
    res = simulate(sc, (0.0, 1.5 * t_stop), q0, v0, "moreau-jean", h=h, theta=0.5,
                   cone="exact")
    assert res.status == 0, res.message
    s, sd = block_motion(p, res.t * sc.time)
    # the velocity is exact at every step (constant deceleration), the trapezoidal position too
    assert np.max(np.abs(res.v[:, 0] * sc.length / sc.time - sd)) <= 1e-11
    assert np.max(np.abs(res.q[:, 0] * sc.length - s)) <= 1e-10
    assert res.q[-1, 0] * sc.length == pytest.approx(p.speed ** 2 / (2 * p.mu * p.gravity),
                                                     rel=1e-10)


@pytest.mark.slow
def test_a_sliding_stack_moves_as_one_block():
    # (with the long checks: 3 s under load) two cubes (mu n < 1: upright) launched together:
    # each interface at its Coulomb limit,
    # no relative slip, the block's deceleration mu g
    p = BoxStack3DParams(n_boxes=2, speed=0.3, mu=0.3)
    sc = box_stack_3d(p)
    q0, v0 = sc.initial_state()
    t_stop = p.speed / (p.mu * p.gravity) / sc.time
    res = simulate(sc, (0.0, 0.5 * t_stop), q0, v0, "moreau-jean", h=t_stop / 40,
                   cone="exact")
    assert res.status == 0, res.message
    _, sd = block_motion(p, res.t * sc.time)
    for k in range(2):
        assert np.max(np.abs(res.v[:, 6 * k] * sc.length / sc.time - sd)) <= 1e-10


@pytest.mark.parametrize("slope, mu", [(0.3, 0.4), (0.4, 0.3)])
def test_a_cube_on_an_incline_stays_below_the_friction_angle_and_slides_above_it(slope, mu):
    p = BoxStack3DParams(n_boxes=1, slope=slope, mu=mu)
    sc = box_stack_3d(p)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean", h=0.05, cone="exact")
    assert res.status == 0, res.message
    v = res.v[:, 0] * sc.length / sc.time
    if math.tan(slope) < mu:
        assert np.max(np.abs(res.v)) <= 1e-12 and np.max(np.abs(res.q - q0)) <= 1e-12
    else:
        a = p.gravity * (math.sin(slope) - mu * math.cos(slope))
        assert np.max(np.abs(v - a * res.t * sc.time)) <= 1e-12
    _, sd = block_motion(p, res.t * sc.time)
    assert np.max(np.abs(v - sd)) <= 1e-12


@pytest.mark.parametrize("kwargs, match", [
    ({"n_boxes": 0}, "`n_boxes` must be a whole number in"),
    ({"half_size": 0.0}, "`half_size` must be > 0"),
    ({"mass": -1.0}, "`mass` must be > 0"),
    ({"slope": 1.6}, "`slope` must be in"),
    ({"n_boxes": 2, "offset": 0.06}, "stack would topple at interface 1"),
    ({"n_boxes": 3, "mu": 0.5, "speed": 1.0}, "stack would topple at interface 0"),
])
def test_bad_parameters_are_refused_by_name(kwargs, match):
    with pytest.raises(InputError, match=match):
        box_stack_3d(**kwargs)
