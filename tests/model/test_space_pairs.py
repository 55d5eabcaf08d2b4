"""Contacts between two spatial bodies' spheres: rows and drift against central differences,
the impact's conservation laws, and bad input refused by name."""

import numpy as np
import pytest

from moreau.check import check_scene
from moreau.errors import IllPosedError, InputError
from moreau.integrators import simulate
from moreau.integrators.moreau_jean import MoreauJean
from moreau.model.space import Box, SpaceModel, Sphere, advance_coordinates
from moreau.model.spatial import quat_exp, rotation_matrix


def _pair_scene(rng, mu=0.3):
    # two eccentric spheres on two tumbling bodies, and one of them on a tilted floor
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.1, -0.2, 1.0))
    a = m.add_body(1.0, [0.002, 0.003, 0.0025], position=(0.0, 0.0, 0.05),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)))
    b = m.add_body(2.0, [0.004, 0.003, 0.0045], position=(0.07, 0.05, 0.09),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)))
    ca, cb = np.array([0.01, -0.005, 0.002]), np.array([-0.003, 0.004, 0.01])
    m.add_pair_contact(a, Sphere(0.05, centre=ca), b, Sphere(0.04, centre=cb), mu=mu)
    m.add_contact(a, Sphere(0.05), floor, mu=0.2)
    return m.build("pair"), ca, cb


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_pair_rows_are_the_rates_of_the_gap_and_of_the_material_points_relative_position(seed):
    rng = np.random.default_rng(seed)
    sc, ca, cb = _pair_scene(rng)
    q, _ = sc.initial_state()
    v = rng.standard_normal(sc.nvel)
    # the gap from the centres computed here: |p_b - p_a| - r_a - r_b (scene units)
    pa = q[:3] + rotation_matrix(q[3:7]) @ ca / 0.05
    pb = q[7:10] + rotation_matrix(q[10:14]) @ cb / 0.05
    assert sc.gaps(q, 0.0)[0] == pytest.approx(np.linalg.norm(pb - pa) - 1.8, abs=1e-15)
    eps = 1e-6
    qp, qm = advance_coordinates(sc, q, v, eps), advance_coordinates(sc, q, -v, eps)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    gdot = (sc.gaps(qp, 0.0) - sc.gaps(qm, 0.0)) / (2 * eps)
    assert np.max(np.abs(WN @ v + wN - gdot)) < 1e-8 * max(1.0, np.max(np.abs(gdot)))
    # the slip: the two material points' relative velocity on the tangents at q
    pdot = (sc.material_points(qp, q) - sc.material_points(qm, q)) / (2 * eps)
    bases = sc.contact_bases(q)
    slip = np.array([[bases[i][1] @ pdot[i], bases[i][2] @ pdot[i]] for i in range(2)]).ravel()
    assert np.max(np.abs(WT @ v + wT - slip)) < 1e-8 * max(1.0, np.max(np.abs(slip)))
    # the pair's rows act on both bodies, the rotations included
    assert np.min(np.abs(WN[0, [0, 3, 6, 9]])) > 0.0 or np.max(np.abs(WN[0, 3:6])) > 1e-3
    assert np.max(np.abs(WT[0:2, 9:12])) > 1e-3 and np.max(np.abs(WT[0:2, 3:6])) > 1e-3
    # drift: d/dt (W v) at constant velocities, the frame turning with the line of centres
    Jp, Jm = sc.contact_jacobians(qp, 0.0), sc.contact_jacobians(qm, 0.0)
    wNb, wTb = sc.contact_drift(q, v, 0.0)
    assert np.max(np.abs(wNb - (Jp[0] @ v - Jm[0] @ v) / (2 * eps))) < 1e-7
    assert np.max(np.abs(wTb - (Jp[2] @ v - Jm[2] @ v) / (2 * eps))) < 1e-7
    assert abs(wNb[0]) > 1e-2 and np.max(np.abs(wTb[:2])) > 1e-2
    # and the package's own check agrees
    report = check_scene(sc)
    assert report.ok, report.summary()


def _mom(sc, q, v):
    # linear and angular momentum (about the origin) of every body, scene units
    P, L = np.zeros(3), np.zeros(3)
    for k in range(sc.nbodies):
        R = rotation_matrix(q[7 * k + 3:7 * k + 7] / np.linalg.norm(q[7 * k + 3:7 * k + 7]))
        p = sc.masses[k] * v[6 * k:6 * k + 3]
        P += p
        L += np.cross(q[7 * k:7 * k + 3], p) + R @ (sc.inertias[k] @ v[6 * k + 3:6 * k + 6])
    return P, L


def _free_pair(mu, e, anisotropic):
    rng = np.random.default_rng(1)
    m = SpaceModel(length=0.05, time=0.05)
    Ja = [0.001, 0.0012, 0.0009] if anisotropic else [0.001] * 3
    a = m.add_body(1.0, Ja, position=(0.0, 0.0, 0.0),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)), velocity=(1.0, 0.1, 0.05),
                   angular_velocity=(3.0, -5.0, 2.0))
    b = m.add_body(2.0, [0.003] * 3, position=(0.12, 0.03, -0.01),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)),
                   velocity=(-0.5, 0.0, 0.1), angular_velocity=(-4.0, 1.0, 6.0))
    m.add_pair_contact(a, Sphere(0.05, centre=(0.003, 0.0, 0.002) if anisotropic else (0, 0, 0)),
                       b, Sphere(0.06), mu=mu, restitution=e)
    return m.build("free pair")


@pytest.mark.parametrize("fast", [False, True], ids=["python-step", "compiled-loop"])
@pytest.mark.parametrize("cone", ["exact", 8])
def test_an_oblique_impact_in_free_space_keeps_momentum_to_rounding(cone, fast):
    # spinning, eccentric, rough (mu = 0.4, e = 0.7): the impulses are equal and opposite
    sc = _free_pair(0.4, 0.7, True)
    q0, v0 = sc.initial_state()
    assert MoreauJean(sc, 0.0, q0, v0, 1.2, h=0.02, fast=fast)._fast == fast
    res = simulate(sc, (0.0, 1.2), q0, v0, "moreau-jean", h=0.02, cone=cone, fast=fast)
    assert res.status == 0 and res.stats["lcp_solves"] >= 1 and np.max(res.force_T) > 0.0
    P0, _ = _mom(sc, res.q[0], res.v[0])
    P1, _ = _mom(sc, res.q[-1], res.v[-1])
    assert np.max(np.abs(P1 - P0)) <= 4e-16 * np.max(np.abs(P0))
    assert np.max(np.abs(res.v[-1] - res.v[0])) > 0.1        # the impact happened
    # frictionless and elastic between isotropic spheres: energy and angular momentum too
    sc = _free_pair(0.0, 1.0, False)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 1.2), q0, v0, "moreau-jean", h=0.02, cone=cone, fast=fast)
    (P0, L0), (P1, L1) = _mom(sc, res.q[0], res.v[0]), _mom(sc, res.q[-1], res.v[-1])
    E = [0.5 * sum(sc.masses[k] * v[6 * k:6 * k + 3] @ v[6 * k:6 * k + 3]
                   + v[6 * k + 3:6 * k + 6] @ sc.inertias[k] @ v[6 * k + 3:6 * k + 6]
                   for k in range(2)) for v in (res.v[0], res.v[-1])]
    assert np.max(np.abs(P1 - P0)) <= 4e-16 * np.max(np.abs(P0))
    # (x x p summed over 60 steps of the centres: a few rounding units of |L|)
    assert np.max(np.abs(L1 - L0)) <= 1e-14 * np.max(np.abs(L0))
    assert abs(E[1] - E[0]) <= 1e-15 * E[0]
    assert np.max(np.abs(res.v[-1, :3] - res.v[0, :3])) > 0.1


def test_bad_pair_contacts_are_refused_by_name():
    m = SpaceModel()
    a = m.add_body(1.0, (1.0, 1.0, 1.0))
    b = m.add_body(1.0, (1.0, 1.0, 1.0), position=(1.0, 0.0, 0.0))
    with pytest.raises(InputError, match="`body_b` must be another body than `body_a`"):
        m.add_pair_contact(a, Sphere(0.5), a, Sphere(0.5))
    with pytest.raises(InputError, match="`sphere_b` must be a Sphere"):
        m.add_pair_contact(a, Sphere(0.5), b, Box((0.5, 0.5, 0.5)))
    with pytest.raises(InputError, match="`body_a` must be the index of an added body"):
        m.add_pair_contact(5, Sphere(0.5), b, Sphere(0.5))
    with pytest.raises(InputError, match="`mu` must be >= 0"):
        m.add_pair_contact(a, Sphere(0.5), b, Sphere(0.5), mu=-1.0)
    with pytest.raises(InputError, match="`restitution` must be in"):
        m.add_pair_contact(a, Sphere(0.5), b, Sphere(0.5), restitution=1.5)
    # concentric spheres have no normal: refused at the start, raised during a run
    with pytest.raises(InputError, match="`body_b`'s sphere must not be concentric"):
        m.add_pair_contact(a, Sphere(0.5, centre=(0.5, 0.0, 0.0)), b,
                           Sphere(0.5, centre=(-0.5, 0.0, 0.0)))
    m.add_pair_contact(a, Sphere(0.5), b, Sphere(0.5))
    sc = m.build("pair")
    q, _ = sc.initial_state()
    with pytest.raises(InputError, match="`q` must be given"):
        sc.contact_bases()
    q[7] = 0.0
    with pytest.raises(IllPosedError, match="are concentric"):
        sc.gaps(q, 0.0)
    with pytest.raises(InputError, match="`time` must be None with gravity"):
        SpaceModel(gravity=(0.0, 0.0, -9.81), time=0.1)
    # the spatial event-driven reference keeps one contact with a half-space
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match="keeps one persistent contact with a half-space"):
        simulate(sc, (0.0, 1.0), q0, v0, "event-driven-space")
    # the compiled spatial loop takes contacts between two bodies
    assert MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, fast=True)._fast
