"""The revolute joint with clearance (a pin in a hole) against independent computations.

Every check runs on the structure of the ``slider-crank-clearance`` scene
(the pin on the slider, the hole at the rod's end): one generated module,
shared with the scene's own tests.
"""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.model.planar import Model
from moreau.scenes.slider_crank_clearance import (slider_crank_clearance,
                                                   slider_crank_clearance_model)

EPS = 1e-7


def _rot(th):
    c, s = math.cos(th), math.sin(th)
    return np.array([[c, -s], [s, c]])


def _states(sc, k, spread, seed):
    # rod and slider moved off the ideal pose (the pin anywhere within about `spread`
    # of the hole's centre), random velocities
    rng = np.random.default_rng(seed)
    q0, v0 = sc.initial_state()
    out = []
    for _ in range(k):
        q = q0 + np.r_[0.01 * rng.standard_normal(3), 0.0, 0.0, 0.0]
        q[2] += 0.3 * rng.standard_normal()
        # the slider's centre at the rod's end plus a random offset
        end = q[:2] + _rot(q[2]) @ np.array([0.5, 0.0])
        q[3:5] = end + spread * rng.standard_normal(2)
        q[5] = 0.2 * rng.standard_normal()
        out.append((q, v0 + rng.standard_normal(6)))
    return out


@pytest.fixture(scope="module")
def scene():
    # mu > 0 for the tangential row (the same structure: mu lives in par)
    return slider_crank_clearance(mu=0.2)


def _material_velocity(sc, q, v, t, which):
    # velocity of the material point of body A (which = 0) or B (1) at the contact point,
    # by central differences of the bodies' poses (independent of the contact rows)
    fr = sc.contact_frames(q, t)[0]
    rec = sc.description.contacts[0]
    body = rec["A"] if which == 0 else rec["B"]
    P = sc.poses(q, t)[body]
    s = fr[4:6] if which == 0 else fr[6:8]
    b = _rot(P[2]).T @ s

    def point(qq, tt):
        Pk = sc.poses(qq, tt)[body]
        return Pk[:2] + _rot(Pk[2]) @ b
    return (point(q + EPS * v, t + EPS) - point(q - EPS * v, t - EPS)) / (2 * EPS)


def test_gap_normal_and_rows_against_the_geometry_and_central_differences(scene):
    sc = scene
    c = 5e-4 / 0.12
    Rh = (0.01 + 5e-4) / 0.12
    t = 0.3
    for q, v in _states(sc, 6, c, 1):
        # the gap from the geometry: c - |pin centre - hole centre|
        hole = q[:2] + _rot(q[2]) @ np.array([0.5, 0.0])
        d = q[3:5] - hole
        g = sc.gaps(q, t)
        assert g[0] == pytest.approx(c - np.hypot(*d), abs=1e-15)
        fr = sc.contact_frames(q, t)[0]
        np.testing.assert_allclose(fr[2:4], -d / np.hypot(*d), atol=1e-14)
        # the pin's contact point is on the pin's surface, along d: |d| + R_p from the
        # hole's centre (R_h when the contact is closed)
        assert np.hypot(*(fr[0:2] - hole)) == pytest.approx(np.hypot(*d) + Rh - c, abs=1e-14)
        WN, wN, WT, wT = sc.contact_jacobians(q, t)
        fd = (sc.gaps(q + EPS * v, t + EPS) - sc.gaps(q - EPS * v, t - EPS)) / (2 * EPS)
        assert abs((WN @ v + wN)[0] - fd[0]) < 1e-7
        # both rows against the material points' velocities: n . (vA - vB) and the slip
        rel = _material_velocity(sc, q, v, t, 0) - _material_velocity(sc, q, v, t, 1)
        n = fr[2:4]
        tvec = np.array([n[1], -n[0]])
        assert abs((WN @ v + wN)[0] - n @ rel) < 1e-7
        assert abs((WT @ v + wT)[0] - tvec @ rel) < 1e-7


def test_drift_terms_against_central_differences_of_the_rows(scene):
    sc = scene
    c = 5e-4 / 0.12
    t = 0.3
    worst = 0.0
    for q, v in _states(sc, 6, c, 2):
        dN, dT = sc.contact_drift(q, v, t)

        def rows(s):
            WN, wN, WT, wT = sc.contact_jacobians(q + s * v, t + s)
            return np.r_[WN @ v + wN, WT @ v + wT]
        fd = (rows(EPS) - rows(-EPS)) / (2 * EPS)
        err = np.max(np.abs(np.r_[dN, dT] - fd)) / max(1.0, np.max(np.abs(fd)))
        worst = max(worst, err)
    # measured 1.5e-9 (terms up to 790: the curvature terms grow as |d| is a few c)
    assert worst < 1e-6


@pytest.mark.parametrize("offset", [0.0, 1e-300, 1e-14])
def test_at_the_centre_the_contact_is_open_and_nothing_is_nan(scene, offset):
    # |d| -> 0: the normal's direction is not defined; the rod's x axis stands for it, the
    # gap is the whole clearance and the drift drops its 1 / |d| terms: finite everywhere
    sc = scene
    c = 5e-4 / 0.12
    q, v = _states(sc, 1, 0.0, 3)[0]
    q[3] += offset
    g = sc.gaps(q, 0.0)
    assert g[0] == pytest.approx(c, abs=1e-13)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    dN, dT = sc.contact_drift(q, v, 0.0)
    fr = sc.contact_frames(q, 0.0)
    for a in (WN, wN, WT, wT, dN, dT, fr):
        assert np.all(np.isfinite(a))
    # the stand-in normal is minus the hole body's (the rod's) x axis
    np.testing.assert_allclose(fr[0, 2:4], -_rot(q[2])[:, 0], atol=1e-15)


def test_a_clearance_joint_refuses_bad_input_naming_it():
    m = slider_crank_clearance_model()
    rod, slider = m.bodies[2]["body"], m.bodies[3]["body"]
    with pytest.raises(InputError, match=r"`pin_radius` \(0.02\) must be less than "
                                         r"`hole_radius` \(0.01\)"):
        m.add_clearance_revolute(rod, (0.06, 0.0), slider, (0.0, 0.0), 0.01, 0.02)
    with pytest.raises(InputError, match="the pin of 'slider' starts .* beyond the clearance "
                                         ".* of the hole of 'rod'"):
        m.add_clearance_revolute(rod, (0.05, 0.0), slider, (0.0, 0.0), 0.0105, 0.01)
    with pytest.raises(InputError, match="`body_i` and `body_j` are one body"):
        m.add_clearance_revolute(rod, (0.06, 0.0), rod, (0.0, 0.0), 0.0105, 0.01)
    with pytest.raises(InputError, match="`restitution` must be"):
        m.add_clearance_revolute(rod, (0.06, 0.0), slider, (0.0, 0.0), 0.0105, 0.01,
                                 restitution=1.5)
    with pytest.raises(InputError, match="`hole_radius` must be"):
        m.add_clearance_revolute(rod, (0.06, 0.0), slider, (0.0, 0.0), -1.0, 0.0)
    other = Model().add_body(1.0, 1.0)
    with pytest.raises(InputError, match="`body_j` must be a body of this model"):
        m.add_clearance_revolute(rod, (0.06, 0.0), other, (0.0, 0.0), 0.0105, 0.01)
    assert len(m.contacts) == 1          # nothing was added by the refused calls


def _pin_in_slot():
    # a disk whose pin (radius 0.015 m) moves in a slot of half-width 0.02 m along the
    # ground's x axis, the pin 3 mm above the slot's centre line, thrown to the right
    m = Model(gravity=(0.0, -9.81), length=0.1)
    disk = m.add_body(0.5, 1e-4, position=(0.0, 0.003), velocity=(0.3, 0.0), name="disk")
    rows = m.add_clearance_prismatic(m.ground, (0.0, 0.0), (1.0, 0.0), disk, (0.0, 0.0),
                                     half_width=0.02, pin_radius=0.015, mu=0.3)
    return m, disk, rows


def test_a_clearance_prismatic_refuses_bad_input_naming_it():
    m, disk, rows = _pin_in_slot()
    assert rows == [0, 1]
    with pytest.raises(InputError, match=r"`pin_radius` \(0.03\) must be less than "
                                         r"`half_width` \(0.02\)"):
        m.add_clearance_prismatic(m.ground, (0.0, 0.0), (1.0, 0.0), disk, (0.0, 0.0), 0.02,
                                  0.03)
    with pytest.raises(InputError, match="the pin of 'disk' starts 0.013 m off the slot's "
                                         "centre line, beyond the clearance 0.005 m"):
        m.add_clearance_prismatic(m.ground, (0.0, -0.01), (1.0, 0.0), disk, (0.0, 0.0), 0.02,
                                  0.015)
    with pytest.raises(InputError, match="`axis` of a prismatic joint must not be zero"):
        m.add_clearance_prismatic(m.ground, (0.0, 0.0), (0.0, 0.0), disk, (0.0, 0.0), 0.02,
                                  0.015)
    assert len(m.contacts) == 2


@pytest.mark.slow   # a model structure of its own: a numba compile (5-15 s on 2 shared cores)
def test_a_pin_in_a_slot_has_the_walls_gaps_and_settles_on_the_lower_wall():
    from moreau.check import check_scene
    from moreau.integrators import simulate
    m, disk, _ = _pin_in_slot()
    sc = m.build("pin-in-slot")
    q0, v0 = sc.initial_state()
    # gaps W - R_p + s and W - R_p - s, s = 3 mm, in units of 0.1 m
    np.testing.assert_allclose(sc.gaps(q0, 0.0), [0.008 / 0.1, 0.002 / 0.1], atol=1e-15)
    report = check_scene(sc)
    assert report.ok, report.summary()
    res = simulate(sc, (0.0, 5.0), q0, v0, "moreau-jean", h=1e-2, projection=True)
    assert res.status == 0, res.message
    # it falls onto the lower wall (the pin's centre 5 mm below the centre line, the lower
    # gap closed) and friction (mu = 0.3) brings it to rolling: the wall's impulse J on the
    # pin's lowest point gives m (v - v0) = J, I w = R_p J, and rolling v = -w R_p, so
    # v = v0 m / (m + I / R_p^2) (measured to 1e-15)
    assert abs(res.q[-1, 1] + 0.005 / 0.1) < 1e-12 and abs(res.gap[-1, 0]) < 1e-12
    v = v0[0] * 0.5 / (0.5 + 1e-4 / 0.015 ** 2)
    R = 0.015 / 0.1
    assert res.v[-1, 0] == pytest.approx(v, rel=1e-12)
    assert res.v[-1, 2] == pytest.approx(-v / R, rel=1e-12) and abs(res.v[-1, 1]) < 1e-12


@pytest.mark.slow   # a model structure of its own: a numba compile (5-15 s on 2 shared cores)
def test_a_hole_in_a_driven_body_has_its_rheonomic_and_drift_terms():
    # the hole on a driven crank (turning and translating), the pin on a free bar: the
    # rows' rheonomic terms and the driven body's prescribed accelerations in the drift,
    # against central differences in time and along the motion (check_scene), with friction
    from moreau.check import check_scene
    from moreau.model.planar import TimeFunction
    m = Model(gravity=(0.0, -9.81), length=0.1)
    crank = m.add_driven(x=TimeFunction(0.0, harmonics=[(0.01, 7.0, 0.3)]),
                         theta=TimeFunction(0.2, rate=3.0, accel=1.5), name="crank")
    c0, s0 = math.cos(0.2), math.sin(0.2)
    hole = np.array([0.01 * math.sin(0.3) + 0.05 * c0, 0.05 * s0])
    bar = m.add_body(0.3, 2e-4, position=(hole[0] + 0.0003 + 0.04, hole[1]), name="bar")
    m.add_clearance_revolute(crank, (0.05, 0.0), bar, (-0.04, 0.0), hole_radius=0.0105,
                             pin_radius=0.01, mu=0.4, restitution=0.5)
    sc = m.build("driven-hole")
    q0, v0 = sc.initial_state()
    states = [(q0 + 0.003 * np.array([1.0, -0.5, 0.3]), v0 + np.array([0.5, -1.0, 2.0])),
              (q0 + 0.003 * np.array([-0.7, 0.4, -1.0]), v0 + np.array([-1.5, 0.2, -3.0]))]
    report = check_scene(sc, states=states, t=0.7)
    assert report.ok, report.summary()
    # measured 1.1e-10, 3.5e-11, 5.6e-10, 2.9e-10
    for key in ("gap rates (WN, wN)", "rheonomic terms (wN against d/dt of the gaps)",
                "normal drift (wNbar)", "tangential drift (wTbar)"):
        assert report.errors[key] < 1e-7, (key, report.errors[key])
    # the tangential row against the material points' velocities, the crank's included
    t = 0.7
    for q, v in states:
        WN, wN, WT, wT = sc.contact_jacobians(q, t)
        rel = _material_velocity(sc, q, v, t, 0) - _material_velocity(sc, q, v, t, 1)
        n = sc.contact_frames(q, t)[0, 2:4]
        assert abs((WT @ v + wT)[0] - np.array([n[1], -n[0]]) @ rel) < 1e-7
        assert abs((WN @ v + wN)[0] - n @ rel) < 1e-7
