"""The planar builder's contact kinematics and forces against independent computations.

``check_scene`` holds the normal rows, the rheonomic terms, the drift terms
and the force Jacobians to central differences, and the compiled model to
the Python methods. The tangential rows have no position whose rate they
are, so they are held here to the rates of the contact points themselves:
a material point of each body, followed along the motion by differences.
"""

import math

import numpy as np
import pytest

from moreau.check import check_scene
from moreau.model.planar import _kernels as K

from planar_zoo import mini_zoo, random_states, zoo

# the full zoo (21 contacts, 9 coordinates) compiles in about 50 s with an empty cache: its
# checks run with the long ones (-m slow); the default run checks the small one (15 s cold)
MODELS = {"mini": mini_zoo, "full": zoo}
ZOO = [pytest.param("mini"), pytest.param("full", marks=pytest.mark.slow)]
_BUILT = {}


def built(name):
    if name not in _BUILT:
        _BUILT[name] = MODELS[name]()
    return _BUILT[name]


@pytest.mark.slow
def test_the_zoo_has_every_contact_kind():
    SCENE, MODEL = built("full")
    kinds = [c["kind"] for c in MODEL.contacts]
    assert SCENE.ncontacts == 4 + 1 + 1 + 1 + 2 + 1 + 2 + 1 + 1 + 6 + 1 == 21
    assert {K.PLANE, K.POINTS, K.POLY} == set(kinds)
    assert SCENE.ndof == 9 and SCENE.frictional_index.size == 20


def test_the_mini_zoo_has_every_contact_kind():
    SCENE, MODEL = built("mini")
    assert [c["kind"] for c in MODEL.contacts] == [K.PLANE, K.POLY, K.POINTS, K.POLY]
    assert SCENE.ndof == 6 and len(MODEL.forces) == 4


@pytest.mark.parametrize("zoo_name", ZOO)
@pytest.mark.parametrize("seed", [1, 2])
def test_check_scene_passes_on_random_states(seed, zoo_name):
    SCENE, MODEL = built(zoo_name)
    # each state alone: the straight paths between states this far apart pass through deep
    # penetrations, where the distance to a polygon has kinks (the nearest face changes)
    for state in random_states(SCENE, 6, seed):
        report = check_scene(SCENE, states=[state], t=0.37, seed=seed, motion=False)
        assert report.ok, report.summary()
        assert report.errors["gap rates (WN, wN)"] <= 1e-7
        assert report.errors["normal drift (wNbar)"] <= 1e-6
        assert report.errors["tangential drift (wTbar)"] <= 1e-6
        assert report.errors["force Jacobians"] <= 1e-6
        assert report.errors["compiled model"] == 0.0


@pytest.mark.parametrize("zoo_name", ZOO)
def test_check_scene_passes_along_a_motion(zoo_name):
    # the default checks: the initial state, three perturbations and a Moreau-Jean motion
    SCENE, MODEL = built(zoo_name)
    report = check_scene(SCENE)
    assert report.ok, report.summary()


def _material_rate(scene, model, i, q, v, t, which, e):
    # the contact point of body `which` (0: A, 1: B) as a material point of that body,
    # moved along (q + s v, t + s): its velocity along e by central differences
    c = model.contacts[i]
    body = c["A"] if which == 0 else c["B"]
    fr = scene.contact_frames(q, t)[i]
    off = fr[4:6] if which == 0 else fr[6:8]
    th = scene.poses(q, t)[body, 2]
    local = np.array([math.cos(th) * off[0] + math.sin(th) * off[1],
                      -math.sin(th) * off[0] + math.cos(th) * off[1]])

    def pos(h):
        x, y, a = scene.poses(q + h * v, t + h)[body]
        return np.array([x + math.cos(a) * local[0] - math.sin(a) * local[1],
                         y + math.sin(a) * local[0] + math.cos(a) * local[1]])

    h = 1e-6
    return float(e @ (pos(h) - pos(-h)) / (2 * h))


@pytest.mark.parametrize("zoo_name", ZOO)
@pytest.mark.parametrize("seed", [3, 4])
def test_the_rows_are_the_relative_velocities_of_the_contact_points(seed, zoo_name):
    SCENE, MODEL = built(zoo_name)
    worst = 0.0
    for q, v in random_states(SCENE, 4, seed):
        t = 0.21
        WN, wN, WT, wT = SCENE.contact_jacobians(q, t)
        fr_index = list(SCENE.frictional_index)
        for i in range(SCENE.ncontacts):
            n = SCENE.contact_frames(q, t)[i, 2:4]
            tang = np.array([n[1], -n[0]])
            for e, row in ((n, WN[i] @ v + wN[i]),) + (
                    ((tang, WT[fr_index.index(i)] @ v + wT[fr_index.index(i)]),)
                    if i in fr_index else ()):
                rel = (_material_rate(SCENE, MODEL, i, q, v, t, 0, e)
                       - _material_rate(SCENE, MODEL, i, q, v, t, 1, e))
                worst = max(worst, abs(row - rel) / max(1.0, abs(rel)))
    assert worst <= 1e-7


def test_the_box_corners_are_the_sliding_box_rows():
    # the hand-derived rows of moreau.scenes.sliding_box at the same geometry and units
    from moreau.model.planar import HalfPlane, Model, Polygon
    from moreau.scenes.sliding_box import SlidingBox

    box = SlidingBox(half_width=0.3, half_height=0.2, mu=0.5, length=1.0)
    m = Model(length=1.0, mass=1.0)
    b = m.add_body(1.0, (0.3 ** 2 + 0.2 ** 2) / 3.0)
    m.add_contact(m.add_shape(b, Polygon.box(0.6, 0.4)), m.add_shape(m.ground, HalfPlane()),
                  mu=0.5, vertices=(0, 1))
    built = m.build()
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, v = rng.normal(size=3), rng.normal(size=3)
        for a, b_ in zip(built.contact_jacobians(q, 0.0), box.contact_jacobians(q, 0.0)):
            np.testing.assert_allclose(a, b_, rtol=0, atol=1e-15)
        for a, b_ in zip(built.contact_drift(q, v, 0.0), box.contact_drift(q, v, 0.0)):
            np.testing.assert_allclose(a, b_, rtol=0, atol=1e-14)
        np.testing.assert_allclose(built.gaps(q, 0.0), box.gaps(q, 0.0), rtol=0, atol=1e-15)
        np.testing.assert_allclose(built.mass(q), box.mass(q), rtol=1e-15)


def test_the_scaled_model_is_the_si_model_in_other_units():
    # the same model in metres and seconds and in its own units: one motion
    SCENE, _ = built("mini")
    si, _ = mini_zoo({"length": 1.0, "mass": 1.0, "time": 1.0})
    L, T, F = SCENE.length, SCENE.time, SCENE.force
    q0, v0 = SCENE.initial_state()
    qs = SCENE._qscale()
    for q, v in random_states(SCENE, 3, 6):
        t = 0.4
        np.testing.assert_allclose(si.gaps(q * qs, t * T), SCENE.gaps(q, t) * L, rtol=1e-12,
                                   atol=1e-14)
        Ms = SCENE.mass(q)
        a = np.linalg.solve(Ms, SCENE.forces(q, v, t))
        a_si = np.linalg.solve(si.mass(q * qs), si.forces(q * qs, v * qs / T, t * T))
        np.testing.assert_allclose(a_si, a * qs / T ** 2, rtol=1e-11, atol=1e-11)
