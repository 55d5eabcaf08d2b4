"""The ideal slider-crank: Moreau–Jean with joints against the closed-form kinematics."""

import math

import numpy as np
import pytest

from moreau.check import check_scene
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.model.planar import Model, TimeFunction
from moreau.scenes.slider_crank import slider_crank, slider_kinematics

WINDOW = 0.75 * 2.0 * math.pi      # three quarters of a crank turn, in the scene's time
R = 0.25                           # r / l at the defaults (0.05 m / 0.2 m)


def test_the_closed_form_derivatives_are_those_of_the_position():
    th = np.linspace(0.1, 6.0, 13)
    d = 1e-5
    x, dx, ddx = slider_kinematics(th, 0.3, 1.1, 2.0)
    xp, dxp, _ = slider_kinematics(th + d, 0.3, 1.1, 2.0)
    xm, dxm, _ = slider_kinematics(th - d, 0.3, 1.1, 2.0)
    # theta = omega t: d/dt = omega d/dtheta
    np.testing.assert_allclose(dx, 2.0 * (xp - xm) / (2 * d), rtol=0, atol=1e-9)
    np.testing.assert_allclose(ddx, 2.0 * (dxp - dxm) / (2 * d), rtol=0, atol=1e-8)
    # and the position is the loop closure |B - A| = l
    np.testing.assert_allclose((x - 0.3 * np.cos(th)) ** 2 + (0.3 * np.sin(th)) ** 2, 1.1 ** 2,
                               rtol=1e-14)


def _errors(theta, n):
    sc = slider_crank()
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, WINDOW), q0, v0, "moreau-jean", h=WINDOW / n, theta=theta)
    assert res.status == 0, res.message
    x, dx, _ = slider_kinematics(res.t, R, 1.0)
    return (float(np.max(np.abs(res.q[:, 3] - x))), float(np.max(np.abs(res.v[:, 3] - dx))),
            res.constraint_drift)


@pytest.mark.parametrize("theta, order", [(1.0, 1.0), (0.5, 2.0)])
def test_moreau_jean_converges_to_the_closed_form_at_its_order(theta, order):
    # measured (h = window / n, n = 100 .. 800): theta = 1: position 5.8e-3 .. 7.2e-4,
    # velocity 2.9e-3 .. 3.6e-4, drift 1.2e-2 .. 1.5e-3 (ratios 2.00); theta = 1/2 (joint
    # rows on the midpoint velocity): position 5.2e-5 .. 8.1e-7, velocity 1.2e-4 .. 1.8e-6,
    # drift 4.6e-5 .. 7.2e-7 (ratios 4.0)
    coarse, fine = _errors(theta, 100), _errors(theta, 200)
    for k, what in enumerate(("position", "velocity", "constraint drift")):
        rate = math.log2(coarse[k] / fine[k])
        assert abs(rate - order) < 0.1, (what, coarse[k], fine[k], rate)
    assert fine[0] < (1e-2 if theta == 1.0 else 1e-4)
    # the drift is reported and shrinks with h
    assert 0.0 < fine[2] < coarse[2]


def test_the_scene_passes_check_scene_and_states_its_joints():
    sc = slider_crank()
    report = check_scene(sc)
    # measured: 1.3e-10 and 1.1e-10 against central differences
    assert report.ok and report.errors["joint rates (WE, wE)"] < 1e-8
    assert report.errors["joint drift (wEbar)"] < 1e-8
    # a wrong drift term is caught and named
    bad = slider_crank()
    drift = bad.joint_drift
    bad.joint_drift = lambda q, v, t: drift(q, v, t) + 1e-3
    assert check_scene(bad).problems == [
        "joint drift (wEbar): differs from central differences by 1.00e-03 (> 1e-06)"]
    q0, v0 = sc.initial_state()
    assert sc.n_joint_rows == 6 and sc.ncontacts == 0
    WE, wE = sc.joint_jacobians(q0, 0.0)
    assert np.max(np.abs(WE @ v0 + wE)) < 1e-15          # a consistent start
    assert np.linalg.matrix_rank(WE) == 6                # no freedom left: the kinematics


def test_a_scheme_that_solves_no_joints_refuses_the_scene_by_name():
    sc = slider_crank()
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match="scheme 'schatzman-paoli' solves no joints"):
        simulate(sc, (0.0, 1.0), q0, v0, "schatzman-paoli", h=0.01)
    with pytest.raises(InputError, match="`fast=True`: the compiled loop of 'moreau-jean' "
                                         "solves no joints"):
        # (the compiled loop of joints solves the contact as "auto" does, not by a forced solver)
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, fast=True, lcp_method="lemke")
    with pytest.raises(InputError, match="`projection` projects onto the contacts only"):
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, projection=True)


def _pendulum_pair():
    m = Model(gravity=(0.0, -9.81))
    crank = m.add_driven(theta=TimeFunction(0.0, rate=1.0), name="crank")
    bar = m.add_body(1.0, 0.01, position=(0.5, 0.0), name="bar")
    return m, crank, bar


def test_a_repeated_revolute_is_refused_naming_both_joints():
    m, crank, bar = _pendulum_pair()
    m.add_revolute(crank, (0.0, 0.0), bar, (-0.5, 0.0))
    m.add_revolute(crank, (0.0, 0.0), bar, (-0.5, 0.0))
    with pytest.raises(InputError, match=r"the joints are redundant: their 4 rows have rank 2 "
                                         r".*revolute joint 0 \('crank'-'bar'\); revolute joint 1"):
        m.build()


@pytest.mark.slow   # a model structure of its own: a numba compile (5 s on 2 shared cores)
def test_two_revolutes_at_one_point_and_a_weld_are_refused_naming_the_redundancy():
    m = Model(gravity=(0.0, -9.81))
    a = m.add_body(1.0, 0.01, position=(0.0, 0.0), name="a")
    b = m.add_body(1.0, 0.01, position=(1.0, 0.0), name="b")
    m.add_revolute(a, (0.5, 0.0), b, (-0.5, 0.0))
    m.add_revolute(a, (0.5, 0.0), b, (-0.5, 0.0))
    m.add_weld(a, b)
    with pytest.raises(InputError, match=r"redundant: their 7 rows have rank 3 .*revolute joint "
                                         r"0 .*revolute joint 1 .*weld joint 2"):
        m.build()


@pytest.mark.slow   # a model structure of its own: a numba compile (5 s on 2 shared cores)
def test_a_pinned_bar_falls_onto_a_floor_and_rests_there_with_joint_and_contact_rows():
    # a uniform bar of length 1 pinned at its left end to the ground's origin, released
    # horizontal; its right end (a point) meets the floor y = -1/2 at angle -pi/6
    # (frictionless, e = 0): the mixed LCP of a joint (2 rows) and a contact (1 row)
    from moreau.model.planar import HalfPlane, Point
    m = Model(gravity=(0.0, -9.81), length=1.0)
    bar = m.add_body(1.0, 1.0 / 12.0, position=(0.5, 0.0), name="bar")
    m.add_revolute(m.ground, (0.0, 0.0), bar, (-0.5, 0.0))
    floor = m.add_shape(m.ground, HalfPlane((0.0, -0.5), (0.0, 1.0)))
    m.add_contact(m.add_shape(bar, Point((0.5, 0.0))), floor)
    sc = m.build("pinned-bar")
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=1e-3)
    assert res.status == 0, res.message
    assert res.stats["lcp_solves"] > 0
    # at rest on the floor: the angle -pi/6, the tip's gap closed to the step's accuracy
    assert abs(res.q[-1, 2] + math.pi / 6) < 1e-3
    assert np.max(np.abs(res.v[-1])) < 1e-9
    assert abs(res.gap[-1, 0]) < 1e-3
    assert res.constraint_drift < 1e-3
    # the first impact comes when the exact pendulum, phi'' = -(3 g / 2 L) cos(phi) (1.5
    # cos(phi) in the scene's units g = L = 1), reaches -pi/6: to the step's accuracy
    from scipy.integrate import solve_ivp

    def hit(t, y):
        return y[0] + math.pi / 6
    hit.terminal = True
    exact = solve_ivp(lambda t, y: [y[1], -1.5 * math.cos(y[0])], (0.0, 3.0), [0.0, 0.0],
                      events=hit, rtol=1e-12, atol=1e-12).t_events[0][0]
    k = int(np.argmax(res.force_N[:, 0] > 0.0))
    assert np.all(res.force_N[:k, 0] == 0.0)
    assert abs(res.t[k] - exact) < 5e-3, (res.t[k], exact)
