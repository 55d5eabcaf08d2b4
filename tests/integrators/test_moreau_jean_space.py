"""Moreau–Jean on a spatial scene: the cone option, SO(3) updates, the other schemes' refusal."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import INTEGRATORS, simulate
from moreau.integrators.base import get_integrator, scheme_options
from moreau.model.space import SpaceModel, Sphere
from moreau.model.spatial import rotation_matrix


def _ball(mu=0.2, spin=(0.0, 0.0, 0.0), speed=1.0):
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b = m.add_body(0.2, [0.4 * 0.2 * 0.05 ** 2] * 3, position=(0.0, 0.0, 0.05),
                   velocity=(speed, 0.3 * speed, 0.0), angular_velocity=spin)
    m.add_contact(b, Sphere(0.05), floor, mu=mu)
    return m.build("ball")


def test_a_spinning_sliding_ball_keeps_a_unit_quaternion_and_both_cones_end_rolling():
    # side and top spin while it slides: the orientation turns about a moving axis
    sc = _ball(spin=(30.0, -50.0, 80.0))
    q0, v0 = sc.initial_state()
    ends = {}
    for cone in ("exact", 8):
        res = simulate(sc, (0.0, 10.0), q0, v0, "moreau-jean", h=0.05, cone=cone)
        assert res.status == 0, res.message
        assert np.max(np.abs(np.linalg.norm(res.q[:, 3:7], axis=1) - 1.0)) <= 1e-14
        assert res.regime_letters()[-1] == "S" and "P" in res.regime_letters()
        ends[cone] = res.v[-1]
        # rolling at the end: the contact point at rest, the spin about the normal kept
        WN, _, WT, _ = sc.contact_jacobians(res.q[-1], res.t[-1])
        assert np.max(np.abs(WT @ res.v[-1])) < 1e-12
        spin = rotation_matrix(res.q[-1, 3:7]) @ res.v[-1, 3:6]
        assert spin[2] == pytest.approx(v0[5], rel=1e-12)
    # the polyhedral cone's friction points along a facet direction: another end speed
    assert np.max(np.abs(ends["exact"] - ends[8])) > 1e-4


@pytest.mark.parametrize("cone, match", [("round", '`cone` must be "auto", "exact" or an integer'),
                                         (2, '`cone` must be "auto", "exact" or an integer'),
                                         (True, '`cone` must be "auto", "exact" or an integer')])
def test_a_bad_cone_is_refused_by_name(cone, match):
    sc = _ball()
    with pytest.raises(InputError, match=match):
        simulate(sc, (0.0, 0.1), *sc.initial_state(), "moreau-jean", h=0.01, cone=cone)


def test_projection_is_refused_on_a_spatial_scene():
    sc = _ball()
    with pytest.raises(InputError, match="`projection` is not defined on a spatial scene"):
        simulate(sc, (0.0, 0.1), *sc.initial_state(), "moreau-jean", h=0.01, projection=True)


# (the spatial event-driven reference runs the ball: tests/integrators/test_event_driven_space.py)
@pytest.mark.parametrize("scheme", sorted(s for s in INTEGRATORS
                                          if s not in ("moreau-jean", "event-driven-space")))
def test_every_other_scheme_refuses_a_spatial_scene_by_name(scheme):
    sc = _ball()
    cls = get_integrator(scheme)
    opts = {"h": 0.01} if "h" in (scheme_options(cls) or ()) else {}
    with pytest.raises(InputError, match=r"scheme '[a-z0-9-]+' steps no spatial scene|`scene` "
                                         "must be a"):
        simulate(sc, (0.0, 0.1), *sc.initial_state(), scheme, **opts)


def test_sliding_then_rolling_to_the_closed_form_speed():
    # a ball launched sliding without spin rolls from t* = 2 v0 / (7 mu g) at 5/7 v0
    mu, v0x = 0.2, 1.0
    sc = _ball(mu=mu, speed=v0x)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=1e-2, cone="exact")
    speed = np.hypot(res.v[-1, 0], res.v[-1, 1]) * sc.length / sc.time
    assert speed == pytest.approx(5.0 / 7.0 * math.hypot(1.0, 0.3) * v0x, rel=1e-12)
    letters = res.regime_letters()
    t_star = res.t[letters.index("S")] * sc.time
    assert abs(t_star - 2.0 * math.hypot(1.0, 0.3) * v0x / (7.0 * mu * 9.81)) <= 1e-2 * sc.time


def test_a_free_tumbling_body_keeps_its_energy_at_theta_one_half():
    # no contact, J = (1, 2, 2.5), spun near the unstable middle axis: at theta = 1/2 the
    # rotation's implicit midpoint rule keeps the energy and |J omega| to rounding, matches
    # moreau.model.spatial.free_rigid_body (the same rule, written apart), and the world
    # angular momentum converges at order 2
    from moreau.model.spatial import free_rigid_body, kinetic_energy, world_angular_momentum
    J, w0 = np.diag([1.0, 2.0, 2.5]), np.array([0.1, 2.0, 0.1])
    m = SpaceModel()
    m.add_body(1.0, [1.0, 2.0, 2.5], angular_velocity=w0)
    sc = m.build("top")
    q0, v0 = sc.initial_state()
    L0 = J @ w0
    errs = []
    for n in (100, 200):
        res = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean", h=2.0 / n, theta=0.5)
        w = res.v[:, 3:]
        e = np.array([kinetic_energy(J, x) for x in w])
        assert np.max(np.abs(e / e[0] - 1.0)) < 1e-13
        assert np.max(np.abs(np.linalg.norm(w @ J, axis=1) / np.linalg.norm(L0) - 1.0)) < 1e-13
        assert np.max(np.abs(np.linalg.norm(res.q[:, 3:], axis=1) - 1.0)) <= 1e-14
        qs, ws = free_rigid_body(q0[3:], w0, J, 2.0 / n, n)
        assert np.max(np.abs(ws - w)) < 1e-12 and np.max(np.abs(qs - res.q[:, 3:])) < 1e-11
        errs.append(np.max(np.abs(world_angular_momentum(res.q[:, 3:], J, w) - L0)))
    assert 3.6 < errs[0] / errs[1] < 4.4
