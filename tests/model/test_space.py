"""Spatial bodies and their contact rows against central differences along the exponential-map motion."""

import numpy as np
import pytest

from moreau.errors import IllPosedError, InputError
from moreau.model.scene import is_spatial
from moreau.model.space import Box, Capsule, Disk, Puck, SpaceModel, Sphere, advance_coordinates
from moreau.model.spatial import quat_exp, quat_multiply, rotation_matrix


def _scene(tilt):
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    floor = m.add_half_space((0.0, 0.0, -0.01), (0.2, -0.1, 1.0))
    p = quat_exp(0.5 * np.asarray(tilt))
    ball = m.add_body(2.0, [0.002, 0.002, 0.002], position=(0.0, 0.0, 0.06), orientation=p)
    puck = m.add_body(0.5, [0.003, 0.003, 0.005], position=(0.3, 0.1, 0.03), orientation=p)
    m.add_contact(ball, Sphere(0.05), floor, mu=0.3)
    m.add_contact(puck, Puck(0.08, 0.02), floor, mu=0.4)
    return m.build("two")


def _motion(sc, q, v, eps):
    # q moved by eps along the velocities v (centres straight, orientations by exp)
    return advance_coordinates(sc, q, v, eps) if eps > 0 else advance_coordinates(sc, q, -v, -eps)


def _material_points(sc, q, q_at):
    # each contact's point, as the material point of its body fixed at q_at (body frame)
    out = []
    for i, (R0, s0) in enumerate(sc.contact_frames(q_at, 0.0)):
        b = sc._contacts[i]["body"]
        R = rotation_matrix(q[7 * b + 3:7 * b + 7])
        out.append(q[7 * b:7 * b + 3] + R @ (R0.T @ s0))
    return np.array(out)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_rows_are_the_rates_of_the_gaps_and_of_the_material_contact_points(seed):
    rng = np.random.default_rng(seed)
    sc = _scene(0.3 * rng.standard_normal(3))
    q, _ = sc.initial_state()
    v = rng.standard_normal(sc.nvel)
    eps = 1e-6
    qp, qm = _motion(sc, q, v, eps), _motion(sc, q, v, -eps)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    gdot = (sc.gaps(qp, 0.0) - sc.gaps(qm, 0.0)) / (2 * eps)
    assert np.max(np.abs(WN @ v + wN - gdot)) < 1e-8 * max(1.0, np.max(np.abs(gdot)))
    pdot = (_material_points(sc, qp, q) - _material_points(sc, qm, q)) / (2 * eps)
    bases = sc.contact_bases()
    slip = np.array([[t1 @ pd, t2 @ pd] for (n, t1, t2), pd in zip(bases, pdot)]).ravel()
    assert np.max(np.abs(WT @ v + wT - slip)) < 1e-8 * max(1.0, np.max(np.abs(slip)))
    # drift: d/dt (W v) at constant velocities (zero accelerations)
    dN = (sc.contact_jacobians(qp, 0.0)[0] @ v - sc.contact_jacobians(qm, 0.0)[0] @ v) / (2 * eps)
    dT = (sc.contact_jacobians(qp, 0.0)[2] @ v - sc.contact_jacobians(qm, 0.0)[2] @ v) / (2 * eps)
    wNb, wTb = sc.contact_drift(q, v, 0.0)
    assert np.max(np.abs(wNb - dN)) < 1e-7 and np.max(np.abs(wTb - dT)) < 1e-7
    assert np.max(np.abs(wNb[1:])) > 1e-3     # the puck's rows do turn


def test_the_gyroscopic_jacobian_against_differences_and_the_quaternion_moves_on_so3():
    rng = np.random.default_rng(5)
    sc = _scene([0.1, 0.2, 0.3])
    q, _ = sc.initial_state()
    v = rng.standard_normal(sc.nvel)
    _, C = sc.force_jacobians(q, v, 0.0)
    eps = 1e-6
    fd = np.column_stack([(sc.forces(q, v + eps * e, 0.0) - sc.forces(q, v - eps * e, 0.0))
                          / (2 * eps) for e in np.eye(sc.nvel)])
    assert np.max(np.abs(C - fd)) < 1e-8 and np.max(np.abs(C)) > 1e-3
    q1 = q
    for _ in range(1000):
        q1 = advance_coordinates(sc, q1, v, 0.01)
    assert abs(np.linalg.norm(q1[3:7]) - 1.0) < 1e-14
    # the exponential map is the flow of a constant body rate: 1000 steps = one of 10
    one = quat_multiply(q[3:7], quat_exp(0.5 * 10.0 * v[3:6]))
    assert np.max(np.abs(q1[3:7] - one)) < 1e-12
    assert is_spatial(sc) and sc.mass(q).shape == (12, 12)


@pytest.mark.parametrize("kwargs, match", [
    ({"orientation": (1.0, 0.0, 0.0, 0.1)}, "`orientation` must be a unit quaternion"),
    ({"inertia": (-1.0, 1.0, 1.0)}, "`inertia` must be positive definite"),
    ({"inertia": (1.0, 1.0, 3.0)}, "`inertia` must satisfy the triangle inequality"),
])
def test_a_bad_body_is_refused_by_name(kwargs, match):
    m = SpaceModel()
    args = {"mass": 1.0, "inertia": (1.0, 1.0, 1.0), **kwargs}
    with pytest.raises(InputError, match=match):
        m.add_body(**args)


def test_a_bad_shape_or_contact_is_refused_by_name():
    m = SpaceModel()
    with pytest.raises(InputError, match="`rim_points` must be an integer >= 3"):
        Puck(0.1, 0.01, rim_points=2)
    b = m.add_body(1.0, (1.0, 1.0, 1.0))
    f = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    with pytest.raises(InputError, match="`mu` must be >= 0"):
        m.add_contact(b, Sphere(1.0), f, mu=-0.1)
    with pytest.raises(InputError, match="`plane` must be the index"):
        m.add_contact(b, Sphere(1.0), 3)


def _rows_and_drift_against_differences(sc, q, v):
    # the gap's rate, the contact point's slip and the rows' time derivative by central
    # differences along the motion; returns the drift (wNb, wTb)
    eps = 1e-6
    qp, qm = _motion(sc, q, v, eps), _motion(sc, q, v, -eps)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    gdot = (sc.gaps(qp, 0.0) - sc.gaps(qm, 0.0)) / (2 * eps)
    assert np.max(np.abs(WN @ v + wN - gdot)) < 1e-8 * max(1.0, np.max(np.abs(gdot)))
    pdot = (_material_points(sc, qp, q) - _material_points(sc, qm, q)) / (2 * eps)
    (_, t1, t2), = sc.contact_bases()
    slip = np.array([t1 @ pdot[0], t2 @ pdot[0]])
    assert np.max(np.abs(WT @ v + wT - slip)) < 1e-8 * max(1.0, np.max(np.abs(slip)))
    dN = (sc.contact_jacobians(qp, 0.0)[0] @ v - sc.contact_jacobians(qm, 0.0)[0] @ v) / (2 * eps)
    dT = (sc.contact_jacobians(qp, 0.0)[2] @ v - sc.contact_jacobians(qm, 0.0)[2] @ v) / (2 * eps)
    wNb, wTb = sc.contact_drift(q, v, 0.0)
    assert np.max(np.abs(wNb - dN)) < 1e-7 and np.max(np.abs(wTb - dT)) < 1e-7
    return wNb, wTb


@pytest.mark.parametrize("seed", [0, 1])
def test_an_eccentric_sphere_rows_and_drift_against_differences(seed):
    # a sphere whose centre is off the centre of mass (the tippe top): its support point is
    # not material, only the centre's offset R c turns with the body
    rng = np.random.default_rng(seed)
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.02)
    floor = m.add_half_space((0.0, 0.0, -0.01), (0.1, 0.2, 1.0))
    c = np.array([0.002, -0.001, 0.004])
    top = m.add_body(0.01, [1e-6, 1.2e-6, 0.9e-6], position=(0.0, 0.0, 0.01),
                     orientation=quat_exp(0.5 * rng.standard_normal(3)))
    m.add_contact(top, Sphere(0.015, centre=c), floor, mu=0.3)
    sc = m.build("eccentric")
    q, _ = sc.initial_state()
    v = rng.standard_normal(sc.nvel)
    # the gap: the sphere's lowest point along the normal, from points sampled on its surface
    R = rotation_matrix(q[3:7])
    u = rng.standard_normal((200000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    n = np.array([0.1, 0.2, 1.0]) / np.linalg.norm([0.1, 0.2, 1.0])
    pts = q[:3] * 0.02 + R @ c + 0.015 * u
    assert abs(sc.gaps(q, 0.0)[0] * 0.02 - np.min((pts - (0.0, 0.0, -0.01)) @ n)) < 1e-6
    wNb, wTb = _rows_and_drift_against_differences(sc, q, v)
    assert abs(wNb[0]) > 1e-3 and np.max(np.abs(wTb)) > 1e-3    # the offset does turn


def _disk_scene(rng):
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    normal = np.array([0.2, -0.1, 1.0])
    floor = m.add_half_space((0.0, 0.0, -0.01), normal)
    disk = m.add_body(0.3, [0.0002, 0.0002, 0.0004], position=(0.01, 0.02, 0.04),
                      orientation=quat_exp(0.5 * (np.array([0.9, 0.3, 0.0])
                                                  + 0.3 * rng.standard_normal(3))))
    m.add_contact(disk, Disk(0.05), floor, mu=0.5)
    return m.build("disk"), normal / np.linalg.norm(normal)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_disks_rim_point_gap_rows_and_drift_against_sampling_and_differences(seed):
    rng = np.random.default_rng(seed)
    sc, n = _disk_scene(rng)
    q, _ = sc.initial_state()
    v = rng.standard_normal(sc.nvel)
    # the gap: the rim's lowest point along the normal, from 200000 points on the rim
    R = rotation_matrix(q[3:7])
    phi = np.linspace(0.0, 2.0 * np.pi, 200000, endpoint=False)
    rim = q[:3] * 0.05 + 0.05 * (np.outer(np.cos(phi), R[:, 0]) + np.outer(np.sin(phi), R[:, 1]))
    lowest = np.min((rim - (0.0, 0.0, -0.01)) @ n)
    assert abs(sc.gaps(q, 0.0)[0] * 0.05 - lowest) < 1e-11
    # and the contact point is that lowest rim point
    (R0, s0), = sc.contact_frames(q, 0.0)
    k = int(np.argmin((rim - (0.0, 0.0, -0.01)) @ n))
    assert np.linalg.norm((q[:3] + s0) * 0.05 - rim[k]) < 1e-5
    wNb, wTb = _rows_and_drift_against_differences(sc, q, v)
    # the rim point slides round the rim: its drift is not a material point's
    s = s0
    w = R @ v[3:6]
    material = np.cross(w, np.cross(w, s)) @ n
    assert abs(wNb[0]) > 1e-3 and abs(wNb[0] - material) > 1e-3


def test_a_disk_lying_flat_is_refused_by_name():
    m = SpaceModel(gravity=(0.0, 0.0, -9.81))
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    flat = m.add_body(1.0, [0.25, 0.25, 0.5], position=(0.0, 0.0, 0.0))
    with pytest.raises(InputError, match="`orientation` of a Disk's body must tilt its axis"):
        m.add_contact(flat, Disk(1.0), floor)
    with pytest.raises(InputError, match="`radius` must be > 0"):
        Disk(0.0)
    # a run that brings the disk flat stops there, naming the configuration
    tilted = m.add_body(1.0, [0.25, 0.25, 0.5], position=(0.0, 0.0, 0.5),
                        orientation=quat_exp(np.array([0.25, 0.0, 0.0])))
    m.add_contact(tilted, Disk(1.0), floor)
    sc = m.build("disks")
    q, _ = sc.initial_state()
    q[10:14] = (1.0, 0.0, 0.0, 0.0)
    with pytest.raises(IllPosedError, match="a disk lies flat on a half-space"):
        sc.gaps(q, 0.0)


def _box_on_incline(slope, mu, speed, corners=(0, 1, 2, 3), orientation=(1.0, 0.0, 0.0, 0.0)):
    g, (hx, hy, hz), M = 9.81, (0.1, 0.075, 0.05), 2.0
    m = SpaceModel(gravity=(g * np.sin(slope), 0.0, -g * np.cos(slope)), length=hx, mass=M)
    f = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    J = [M / 3 * (hy * hy + hz * hz), M / 3 * (hx * hx + hz * hz), M / 3 * (hx * hx + hy * hy)]
    b = m.add_body(M, J, position=(0.0, 0.0, hz), velocity=(speed, 0.0, 0.0),
                   orientation=orientation)
    m.add_contact(b, Box((hx, hy, hz), corners=corners), f, mu=mu)
    return m.build("box")


def test_a_box_slides_down_an_incline_at_g_sin_alpha_minus_mu_g_cos_alpha():
    # four bottom corners share the weight (statically indeterminate); the centre's
    # acceleration is not: a = g (sin(alpha) - mu cos(alpha)), constant, so Moreau-Jean's
    # velocity is exact at every step and theta = 1/2 (the trapezoidal rule) exact in position
    from moreau.integrators import simulate
    slope, mu, v0 = 0.4, 0.3, 0.5
    sc = _box_on_incline(slope, mu, v0)
    q0, v = sc.initial_state()
    res = simulate(sc, (0.0, 1.0), q0, v, "moreau-jean", h=0.1, theta=0.5, cone="exact")
    a = 9.81 * (np.sin(slope) - mu * np.cos(slope))
    t = res.t * sc.time
    assert np.allclose(res.v[:, 0] * sc.length / sc.time, v0 + a * t, rtol=1e-12, atol=0)
    assert np.allclose(res.q[:, 0] * sc.length, v0 * t + 0.5 * a * t * t, rtol=1e-12, atol=0)
    # it neither turns nor lifts a corner, and every step's corners carry the weight's normal part
    assert np.max(np.abs(res.v[:, 3:])) < 1e-9 and np.max(np.abs(res.gap)) < 1e-14
    assert np.allclose(res.force_N[1:].sum(axis=1), np.cos(slope), rtol=1e-12)


def test_a_box_at_rest_on_an_incline_below_its_friction_angle_stays_at_rest():
    from moreau.integrators import simulate
    slope = 0.4
    sc = _box_on_incline(slope, 1.01 * np.tan(slope), 0.0)
    q0, v = sc.initial_state()
    res = simulate(sc, (0.0, 1.0), q0, v, "moreau-jean", h=0.1, cone="exact")
    assert np.max(np.abs(res.v)) < 1e-12 and np.max(np.abs(res.q[-1] - q0)) < 1e-12
    # (the corners' friction, indeterminate, may pull across the slope too: the sum of its
    # magnitudes bounds the weight's slope part, 1 being m g in the scene's units)
    assert np.all(res.force_T[1:].sum(axis=1) >= np.sin(slope) * (1.0 - 1e-12))
    assert np.all(res.force_T <= res.force_N * 1.01 * np.tan(slope) * (1.0 + 1e-9))
    assert np.allclose(res.force_N[1:].sum(axis=1), np.cos(slope), rtol=1e-12)


def test_a_boxs_corners_gaps_and_rows_against_differences():
    rng = np.random.default_rng(7)
    sc = _box_on_incline(0.3, 0.5, 0.0, corners=range(8),
                         orientation=quat_exp(0.5 * rng.standard_normal(3)))
    q, _ = sc.initial_state()
    R = rotation_matrix(q[3:7])
    corners = np.array([[sx, sy, sz] for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)])
    heights = q[2] + corners * [1.0, 0.75, 0.5] @ R.T @ [0.0, 0.0, 1.0]
    assert np.allclose(sc.gaps(q, 0.0), heights, rtol=0, atol=1e-15)
    v = rng.standard_normal(sc.nvel)
    eps = 1e-6
    qp, qm = _motion(sc, q, v, eps), _motion(sc, q, v, -eps)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    gdot = (sc.gaps(qp, 0.0) - sc.gaps(qm, 0.0)) / (2 * eps)
    assert np.max(np.abs(WN @ v + wN - gdot)) < 1e-8 * max(1.0, np.max(np.abs(gdot)))
    dN = (sc.contact_jacobians(qp, 0.0)[0] @ v - sc.contact_jacobians(qm, 0.0)[0] @ v) / (2 * eps)
    assert np.max(np.abs(sc.contact_drift(q, v, 0.0)[0] - dN)) < 1e-7


@pytest.mark.parametrize("kwargs, match", [
    ({"half_extents": (0.1, 0.0, 0.1)}, "`half_extents` must be > 0"),
    ({"half_extents": (0.1, 0.1, 0.1), "corners": (0, 8)}, "`corners` must be distinct corner"),
    ({"half_extents": (0.1, 0.1, 0.1), "corners": (1, 1)}, "`corners` must be distinct corner"),
])
def test_a_bad_box_is_refused_by_name(kwargs, match):
    with pytest.raises(InputError, match=match):
        Box(**kwargs)


def test_a_capsule_touches_at_its_lowest_end_and_rolls_down_an_incline_in_closed_form():
    from moreau.integrators import simulate
    rng = np.random.default_rng(3)
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    n = np.array([0.1, -0.2, 1.0])
    floor = m.add_half_space((0.0, 0.0, 0.0), n)
    b = m.add_body(1.0, [0.004, 0.004, 0.001], position=(0.0, 0.0, 0.2),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)))
    m.add_contact(b, Capsule(0.05, 0.15), floor, mu=0.3)
    sc = m.build("capsule")
    q, _ = sc.initial_state()
    # the gap: the lowest of 20001 points on the segment, less the radius
    R = rotation_matrix(q[3:7])
    seg = q[:3] * 0.05 + np.outer(np.linspace(-0.15, 0.15, 20001), R[:, 2])
    assert abs(sc.gaps(q, 0.0).min() * 0.05 - (np.min(seg @ n) / np.linalg.norm(n) - 0.05)) < 1e-15
    # lying across an incline (axis along y) it rolls as a round body of k = I_axis / (m r^2):
    # a = g sin(alpha) / (1 + k), constant, exact at every step (theta = 1/2)
    slope, r, M, Ia, v0 = 0.3, 0.05, 1.0, 0.0015, 0.2
    m = SpaceModel(gravity=(9.81 * np.sin(slope), 0.0, -9.81 * np.cos(slope)), length=r)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    across = quat_exp(np.array([-0.25 * np.pi, 0.0, 0.0]))      # body z -> world y
    w_body = rotation_matrix(across).T @ np.array([0.0, v0 / r, 0.0])
    # (its ends' heights differ by rounding: started 1e-12 m into the floor, both touch at
    # the first step; an end 1e-17 above would leave the first step to the other alone)
    b = m.add_body(M, [0.004, 0.004, Ia], position=(0.0, 0.0, r - 1e-12), orientation=across,
                   velocity=(v0, 0.0, 0.0), angular_velocity=w_body)
    assert m.add_contact(b, Capsule(r, 0.15), floor, mu=0.5) == [0, 1]
    sc = m.build("capsule-incline")
    q0, v = sc.initial_state()
    res = simulate(sc, (0.0, 2.0), q0, v, "moreau-jean", h=0.2, theta=0.5, cone="exact")
    a = 9.81 * np.sin(slope) / (1.0 + Ia / (M * r * r))
    t = res.t * sc.time
    assert set(res.regime_letters()) == {"S"}
    assert np.allclose(res.v[:, 0] * r / sc.time, v0 + a * t, rtol=1e-12, atol=0)
    assert np.allclose(res.q[:, 0] * r, v0 * t + 0.5 * a * t * t, rtol=1e-12, atol=0)
    # each end carries half the weight's normal part
    assert np.allclose(res.force_N[1:], 0.5 * np.cos(slope), rtol=1e-12)
