"""Box contacts in space: box on a half-space, sphere against box, box against box. Rows and
drift against central differences on tumbling bodies, the points each configuration gives,
a step's impulses, and bad input refused by name."""

import numpy as np
import pytest

from moreau.check import check_scene
from moreau.errors import IllPosedError, InputError
from moreau.integrators import simulate
from moreau.model.space import Box, SpaceModel, Sphere, advance_coordinates
from moreau.model.spatial import quat_exp, rotation_matrix


def _differences(sc, q, v, eps=1e-6):
    # (rows against the gaps' rates, against the slip of the material points, drift against
    # the rows' rates): the largest error of each relative to max(1, the rate), and the kinds
    nc = sc.ncontacts
    qp, qm = advance_coordinates(sc, q, v, eps), advance_coordinates(sc, q, -v, eps)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    gdot = (sc.gaps(qp, 0.0) - sc.gaps(qm, 0.0)) / (2 * eps)
    pdot = (sc.material_points(qp, q) - sc.material_points(qm, q)) / (2 * eps)
    bases = sc.contact_bases(q)
    slip = np.array([[bases[i][1] @ pdot[i], bases[i][2] @ pdot[i]] for i in range(nc)]).ravel()
    Jp, Jm = sc.contact_jacobians(qp, 0.0), sc.contact_jacobians(qm, 0.0)
    wNb, wTb = sc.contact_drift(q, v, 0.0)
    dN = (Jp[0] @ v - Jm[0] @ v) / (2 * eps)
    dT = (Jp[2] @ v - Jm[2] @ v) / (2 * eps)

    def rel(a, b):
        return float(np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b))))
    return rel(WN @ v + wN, gdot), rel(WT @ v + wT, slip), rel(wNb, dN), rel(wTb, dT)


def _two_boxes(ha, hb, pb, oa, ob, margin=0.5):
    m = SpaceModel()
    a = m.add_body(1.0, Box(ha).inertia(1.0), orientation=oa)
    b = m.add_body(2.0, Box(hb).inertia(2.0), position=pb, orientation=ob)
    m.add_box_contact(a, Box(ha), b, Box(hb), mu=0.3, margin=margin)
    return m.build("two boxes")


def _touching(ha, hb, oa, ob, xy, depth):
    # box b lowered onto box a along z until its deepest point is 1 to 1.5 `depth` into it
    # (bisection; too deep for the margin counts as too low)
    sc = _two_boxes(ha, hb, (xy[0], xy[1], 3.0), oa, ob)
    q, _ = sc.initial_state()
    lo, hi = 0.0, 3.0
    for _ in range(60):
        q[9] = 0.5 * (lo + hi)
        try:
            g = np.min(sc.gaps(q, 0.0))
        except IllPosedError:
            g = -np.inf
        if -1.5 * depth <= g < -depth:
            return sc, q
        lo, hi = (q[9], hi) if g < -depth else (lo, q[9])
    raise AssertionError("no contact")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_box_box_rows_and_drift_are_the_rates_of_the_gaps_and_of_the_material_points(seed):
    # tumbling boxes of different sizes, touching face to face (tilted, twisted: clipped
    # points of the three kinds) or edge to edge
    rng = np.random.default_rng(seed)
    ha, hb = np.array([1.0, 0.8, 0.5]), np.array([0.7, 0.9, 0.4])
    kinds = set()
    for _ in range(6):
        oa, ob = quat_exp(0.3 * rng.standard_normal(3)), quat_exp(0.3 * rng.standard_normal(3))
        sc, q = _touching(ha, hb, oa, ob, 0.3 * rng.standard_normal(2), 0.02)
        use = sc.contacts_in_use(q)
        assert 1 <= use.sum() <= 8 and not use[use.sum():].any()   # slots filled in order
        kinds |= {sc._box_point(q, i)[4].kind for i in np.flatnonzero(use)}
        # an unused slot reports the margin, with zero rows
        g = sc.gaps(q, 0.0)
        assert np.all(g[~use] == 0.5) and np.all(g[use] <= 0.5)
        assert not sc.contact_rows(q)[~use].any()
        v = rng.standard_normal(sc.nvel)
        for err in _differences(sc, q, v):
            assert err < 1e-8
    assert kinds >= {"fa", "ee"}


def test_box_box_points_of_every_kind_match_differences():
    # one configuration with all three kinds: a vertex of b on a's face, a vertex of a on b's
    # face and edges crossing (a twisted, tilted box on a smaller one)
    rng = np.random.default_rng(13)
    ha, hb = np.array([1.0, 0.8, 0.5]), np.array([0.7, 0.9, 0.4])
    oa, ob = quat_exp(0.3 * rng.standard_normal(3)), quat_exp(0.3 * rng.standard_normal(3))
    found = None
    for _ in range(40):
        oa, ob = quat_exp(0.3 * rng.standard_normal(3)), quat_exp(0.3 * rng.standard_normal(3))
        sc, q = _touching(ha, hb, oa, ob, (0.2, -0.1), 0.02)
        kinds = [sc._box_point(q, i)[4].kind for i in np.flatnonzero(sc.contacts_in_use(q))]
        if {"fa", "fb", "ee"} <= set(kinds):
            found = sc, q
            break
    assert found is not None
    sc, q = found
    for err in _differences(sc, q, rng.standard_normal(sc.nvel)):
        assert err < 1e-8
    assert check_scene(sc).ok


def test_aligned_boxes_touch_at_the_four_corners_of_the_smaller_face_and_offset_ones_at_the_overlap():
    h = np.array([0.5, 0.4, 0.25])
    sc = _two_boxes(h, h, (0.0, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    q, _ = sc.initial_state()
    pts = [sc._box_point(q, i)[4] for i in range(4)]
    assert all(p.kind == "fa" and p.g == 0.0 for p in pts)
    assert np.all(sc.gaps(q, 0.0)[4:] == 0.5)
    corners = sorted((q[:3] + p.sa).round(12).tolist() for p in pts)
    assert corners == sorted([[sx * 0.5, sy * 0.4, 0.25] for sx in (-1, 1) for sy in (-1, 1)])
    # offset by 0.3 along x: the overlap [-0.2, 0.5] x [-0.4, 0.4], two of b's corners and two
    # crossings of b's edges with a's edge x = 0.5
    sc = _two_boxes(h, h, (0.3, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    q, _ = sc.initial_state()
    use = sc.contacts_in_use(q)
    pts = [sc._box_point(q, i)[4] for i in np.flatnonzero(use)]
    assert sorted(p.kind for p in pts) == ["ee", "ee", "fa", "fa"]
    xy = sorted((q[:3] + p.sa)[:2].round(12).tolist() for p in pts)
    assert xy == [[-0.2, -0.4], [-0.2, 0.4], [0.5, -0.4], [0.5, 0.4]]
    assert all(abs(p.g) < 1e-15 and np.allclose(p.n, [0.0, 0.0, 1.0]) for p in pts)


def test_crossed_boxes_touch_edge_to_edge_at_one_point():
    # a turned 45 degrees about y (its top a ridge along y), b above it turned 45 degrees
    # about x (its bottom a ridge along x): the two ridges cross at one point
    ha = hb = np.array([0.5, 0.5, 0.5])
    oa = quat_exp([0.0, np.pi / 8, 0.0])        # (quat_exp takes half the rotation vector)
    ob = quat_exp([np.pi / 8, 0.0, 0.0])
    ridge = 0.5 * np.sqrt(2.0)
    sc = _two_boxes(ha, hb, (0.0, 0.0, 2 * ridge - 0.01), oa, ob)
    q, _ = sc.initial_state()
    use = sc.contacts_in_use(q)
    assert use.sum() == 1
    p = sc._box_point(q, 0)[4]
    assert p.kind == "ee" and abs(p.g + 0.01) < 1e-14 and np.allclose(p.n, [0, 0, 1], atol=1e-14)
    assert np.allclose(q[:3] + p.sa, [0.0, 0.0, ridge], atol=1e-14)
    rng = np.random.default_rng(3)
    for err in _differences(sc, q, rng.standard_normal(12)):
        assert err < 1e-8


@pytest.mark.parametrize("clamped", [1, 2, 3])
def test_sphere_box_rows_in_the_face_edge_and_vertex_regions(clamped):
    rng = np.random.default_rng(clamped)
    m = SpaceModel()
    hb = np.array([0.7, 0.9, 0.4])
    ob = quat_exp(0.5 * rng.standard_normal(3))
    b = m.add_body(2.0, Box(hb).inertia(2.0), orientation=ob)
    loc = np.array([0.3, -0.2, 0.1]) * hb
    for ax in range(clamped):
        loc[ax] = (1.0 if ax != 1 else -1.0) * (hb[ax] + 0.3)
    oa = quat_exp([0.1, 0.2, 0.3])
    ca = np.array([0.05, 0.0, 0.02])
    a = m.add_body(1.0, [0.4] * 3, position=rotation_matrix(ob) @ loc - rotation_matrix(oa) @ ca,
                   orientation=oa)
    m.add_box_contact(a, Sphere(0.35, centre=ca), b, Box(hb), mu=0.3)
    sc = m.build("sphere and box")
    q, _ = sc.initial_state()
    # the closest point is 0.3 from the face, 0.3 sqrt(2) from the edge, 0.3 sqrt(3) from the
    # corner
    assert sc.gaps(q, 0.0)[0] == pytest.approx(0.3 * np.sqrt(clamped) - 0.35, abs=1e-14)
    for err in _differences(sc, q, rng.standard_normal(12)):
        assert err < 1e-8


def _stack2(cone_gap=1e-13):
    # two equal boxes on the floor, the top one 1e-13 into the bottom one (rounding leaves
    # every contact closed at the first step)
    h = (0.1, 0.1, 0.1)
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.1)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    a = m.add_body(1.0, Box(h).inertia(1.0), position=(0.0, 0.0, 0.1))
    b = m.add_body(2.0, Box(h).inertia(2.0), position=(0.02, 0.0, 0.3 - 0.1 * cone_gap))
    m.add_contact(a, Box(h), floor, mu=0.5)
    m.add_box_contact(a, Box(h), b, Box(h), mu=0.5)
    return m.build("two boxes on the floor")


@pytest.mark.parametrize("cone", ["exact", pytest.param(8, marks=pytest.mark.slow)])
def test_one_step_of_a_resting_pair_of_boxes_carries_the_weights_on_both_cones(cone):
    # (d = 8 with the long checks: Lemke's exact arithmetic takes this degenerate problem,
    # eight points closed on twelve velocities, 22 s under load)
    # the floor's four bottom corners carry both weights, the interface's four points the
    # top one's: h g (m_a + m_b) and h g m_b (scene units: g = 1, masses in kg)
    sc = _stack2()
    q0, v0 = sc.initial_state()
    h = 0.05
    res = simulate(sc, (0.0, h), q0, v0, "moreau-jean", h=h, cone=cone)
    assert res.status == 0, res.message
    fN = res.force_N[-1]
    assert fN[:4].sum() == pytest.approx(3.0, rel=1e-10) and np.all(fN[4:8] == 0.0)
    assert fN[8:12].sum() == pytest.approx(2.0, rel=1e-10) and np.all(fN[12:] == 0.0)
    assert np.max(np.abs(res.v[-1])) < 1e-12 and np.max(np.abs(res.q[-1] - q0)) < 1e-12


def test_a_box_dropped_edge_first_on_a_box_keeps_momentum_in_free_space():
    # no gravity: a box falls edge first onto another free box; the impulses between them
    # are equal and opposite (linear momentum to rounding) and friction acts
    m = SpaceModel(length=0.1, time=0.1)
    h = (0.1, 0.08, 0.06)
    a = m.add_body(1.0, Box(h).inertia(1.0), orientation=quat_exp([0.2, 0.1, 0.0]))
    b = m.add_body(1.5, Box(h).inertia(1.5), position=(0.03, 0.02, 0.2),
                   orientation=quat_exp([0.0, 0.6, 0.3]), velocity=(0.0, 0.0, -1.0),
                   angular_velocity=(1.0, 0.0, 2.0))
    m.add_box_contact(a, Box(h), b, Box(h), mu=0.4, restitution=0.5)
    sc = m.build("free boxes")
    q0, v0 = sc.initial_state()
    for cone in ("exact", 8):
        res = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, cone=cone)
        assert res.status == 0, res.message
        P = [sc.masses[0] * v[:3] + sc.masses[1] * v[6:9] for v in (res.v[0], res.v[-1])]
        assert np.max(np.abs(P[1] - P[0])) <= 1e-14 * np.max(np.abs(P[0]))
        assert res.stats["lcp_solves"] >= 1 and np.max(res.force_T) > 0.0
        assert res.v[-1, 8] > -0.5     # b bounced off a


def test_bad_box_contacts_are_refused_by_name():
    m = SpaceModel()
    a = m.add_body(1.0, (1.0, 1.0, 1.0))
    b = m.add_body(1.0, (1.0, 1.0, 1.0), position=(0.0, 0.0, 3.0))
    box = Box((0.5, 0.5, 0.5))
    with pytest.raises(InputError, match="`half_extents` must be > 0"):
        Box((0.5, -0.5, 0.5))
    with pytest.raises(InputError, match="`mass` must be > 0"):
        box.inertia(0.0)
    with pytest.raises(InputError, match="`body_b` must be another body than `body_a`"):
        m.add_box_contact(a, box, a, box)
    with pytest.raises(InputError, match="`body_a` must be the index of an added body"):
        m.add_box_contact(7, box, b, box)
    with pytest.raises(InputError, match="`shape_a` must be a Sphere or a Box"):
        m.add_box_contact(a, (0.5, 0.5, 0.5), b, box)
    with pytest.raises(InputError, match="`box_b` must be a Box"):
        m.add_box_contact(a, box, b, Sphere(0.5))
    with pytest.raises(InputError, match="`margin` must be > 0"):
        m.add_box_contact(a, box, b, box, margin=0.0)
    with pytest.raises(InputError, match="`mu` must be >= 0"):
        m.add_box_contact(a, box, b, box, mu=-0.1)
    c = m.add_body(1.0, (1.0, 1.0, 1.0), position=(0.0, 0.0, 0.3))
    with pytest.raises(InputError, match="must not interpenetrate at the initial positions.*"
                                         "interpenetrate by 0.7"):
        m.add_box_contact(a, box, c, box)
    with pytest.raises(InputError, match="must not interpenetrate.*centre is inside a box"):
        m.add_box_contact(a, Sphere(0.5), c, box)
    m.add_box_contact(a, box, b, box)
    m.add_box_contact(a, Sphere(0.5), b, box)
    sc = m.build("boxes")
    # a run that sinks the boxes into each other stops, naming the contact and the cause
    q, _ = sc.initial_state()
    q[9] = 0.6
    with pytest.raises(IllPosedError, match="contact 0 .bodies 0 and 1.: two boxes "
                                            "interpenetrate by 0.4.*past the contact's margin"):
        sc.gaps(q, 0.0)
    m2 = SpaceModel()
    s = m2.add_body(1.0, (1.0, 1.0, 1.0))
    k = m2.add_body(1.0, (1.0, 1.0, 1.0), position=(0.0, 0.0, 1.0))
    m2.add_box_contact(s, Sphere(0.4), k, box)
    sc2 = m2.build("sphere on box")
    q, _ = sc2.initial_state()
    q[9] = 0.3
    with pytest.raises(IllPosedError, match="contact 0 .bodies 0 and 1.: a sphere's centre is "
                                            "inside a box"):
        sc2.contact_rows(q)
    q0, v0 = sc.initial_state()
    # the spatial event-driven reference and the compiled loop refuse box contacts by name
    with pytest.raises(InputError, match="keeps one persistent contact with a half-space: "
                                         "`scene` 'boxes' has box contacts"):
        simulate(sc, (0.0, 1.0), q0, v0, "event-driven-space")
    with pytest.raises(InputError, match="`fast=True`: the compiled spatial step cannot state "
                                         "box contacts"):
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.1, fast=True)
