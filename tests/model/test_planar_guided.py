"""Guided bodies and axial springs of the planar builder against an independent Lagrangian."""

import math

import numpy as np
import pytest

from moreau.check import check_scene
from moreau.errors import InputError
from moreau.model.planar import Circle, HalfPlane, Model, Point, TimeFunction

# a bar turning about a pivot moved in x and y, under gravity, held by an axial spring (with a
# dashpot) along a tilted axis between its tip and the ground; units 1 m, 1 kg, 1 s
M, I, C = 0.7, 0.05, (0.4, 0.1)
G = (0.3, -9.81)
XP = TimeFunction(0.1, rate=0.2, harmonics=[(0.05, 3.0, 0.4)])
YP = TimeFunction(-0.2, accel=1.5, harmonics=[(0.02, 5.0, 0.5 * math.pi)])
TIP, K, L0, DAMP = (0.8, -0.05), 40.0, 0.3, 0.6
AXIS = np.array([0.6, 0.8])


def _model():
    m = Model(gravity=G, length=1.0, mass=1.0, time=1.0)
    bar = m.add_guided(M, I, x=XP, y=YP, angle=0.3, angular_velocity=-0.5, centre=C)
    m.add_axial_spring(bar, TIP, m.ground, (0.0, 0.0), AXIS, K, rest_length=L0, damping=DAMP)
    return m


def _lagrangian(th, w, t):
    # T - V from the bar's centre of mass X(t) + R c and the tip's position (written here,
    # not with the builder's kernels)
    (x, dx, _), (y, dy, _) = XP(t), YP(t)
    c, s = math.cos(th), math.sin(th)
    rc = np.array([c * C[0] - s * C[1], s * C[0] + c * C[1]])
    vel = np.array([dx - w * rc[1], dy + w * rc[0]])
    T = 0.5 * M * vel @ vel + 0.5 * I * w * w
    tip = np.array([x + c * TIP[0] - s * TIP[1], y + s * TIP[0] + c * TIP[1]])
    V = -M * (G[0] * (x + rc[0]) + G[1] * (y + rc[1])) + 0.5 * K * (AXIS @ tip - L0) ** 2
    return T - V


def _tip_speed_along_axis(th, w, t):
    (_, dx, _), (_, dy, _) = XP(t), YP(t)
    c, s = math.cos(th), math.sin(th)
    r = np.array([c * TIP[0] - s * TIP[1], s * TIP[0] + c * TIP[1]])
    return AXIS @ np.array([dx - w * r[1], dy + w * r[0]])


@pytest.mark.slow
def test_a_guided_body_follows_lagranges_equation():
    sc = _model().build()
    assert sc.ndof == 1 and sc.angle_coordinates == (0,)
    e = 1e-4
    for th, w, t in ((0.3, -0.5, 0.0), (1.2, 2.0, 0.7), (-2.0, 0.3, 1.9)):
        # M = d2L/dw2; h = dL/dth - d2L/dw dt - w d2L/dw dth, by central differences
        Lw = lambda a, b, c: (_lagrangian(a, b + e, c) - _lagrangian(a, b - e, c)) / (2 * e)  # noqa: E731
        mass = (_lagrangian(th, w + e, t) - 2 * _lagrangian(th, w, t)
                + _lagrangian(th, w - e, t)) / e ** 2
        h = ((_lagrangian(th + e, w, t) - _lagrangian(th - e, w, t)) / (2 * e)
             - (Lw(th, w, t + e) - Lw(th, w, t - e)) / (2 * e)
             - w * (Lw(th + e, w, t) - Lw(th - e, w, t)) / (2 * e))
        # the dashpot's force, -c l' along the axis, as a generalized force on th
        lever = (_tip_speed_along_axis(th, w + e, t) - _tip_speed_along_axis(th, w - e, t)) / (2 * e)
        h -= DAMP * _tip_speed_along_axis(th, w, t) * lever
        assert abs(sc.mass([th])[0, 0] - (I + M * (C[0] ** 2 + C[1] ** 2))) <= 1e-15
        assert abs(sc.mass([th])[0, 0] - mass) <= 1e-6
        assert abs(sc.forces([th], [w], t)[0] - h) <= 1e-6 * max(1.0, abs(h))
    report = check_scene(sc)
    assert report.ok, report.summary()
    assert report.errors["compiled model"] <= 1e-12


@pytest.mark.slow
def test_a_slider_on_a_guide_with_a_circle_on_a_moving_floor():
    # a guided body with x free (a slider, y and theta prescribed) and one with y and theta
    # free under a floor moving as prescribed: the rows and drift terms against differences
    m = Model(gravity=(0.0, -9.81), length=0.1, mass=1.0)
    slider = m.add_guided(2.0, 0.01, y=0.05, theta=TimeFunction(0.0, rate=0.3), velocity=(0.4, 0.0))
    wheel = m.add_guided(1.0, 0.005, x=TimeFunction(0.0, rate=0.2), position=(0.0, 0.12),
                         angular_velocity=1.0)
    floor = m.add_driven(y=TimeFunction(0.0, harmonics=[(0.01, 7.0, 0.5 * math.pi)]))
    m.add_contact(m.add_shape(wheel, Circle(0.05)), m.add_shape(floor, HalfPlane()), mu=0.3)
    m.add_contact(m.add_shape(slider, Point((0.02, 0.01))), m.add_shape(wheel, Circle(0.05)),
                  mu=0.2)
    m.add_torque(wheel, 0.1)
    m.add_force(slider, (1.0, 2.0), point=(0.01, 0.0))
    sc = m.build()
    assert sc.ndof == 3 and sc.angle_coordinates == (2,)
    report = check_scene(sc)
    assert report.ok, report.summary()
    assert report.errors["compiled model"] <= 1e-12


def test_bad_guided_bodies_and_axial_springs_are_refused_by_name():
    m = Model(length=1.0, time=1.0)
    with pytest.raises(InputError, match="that is a driven body"):
        m.add_guided(1.0, 1.0, x=0.0, y=0.0, theta=0.0)
    with pytest.raises(InputError, match="`centre` off the frame's origin needs `x` and `y`"):
        m.add_guided(1.0, 1.0, x=0.0, centre=(0.1, 0.0))
    with pytest.raises(InputError, match="`mass` of a body must be > 0"):
        m.add_guided(0.0, 1.0, x=0.0)
    bar = m.add_guided(1.0, 1.0, x=0.0, y=0.0, centre=(0.5, 0.0))
    other = m.add_body(1.0, 1.0)
    with pytest.raises(InputError, match="`body_i` is a guided body"):
        m.add_revolute(bar, (0.0, 0.0), other, (0.0, 0.0))
    with pytest.raises(InputError, match="`axis` of a spring must not be zero"):
        m.add_axial_spring(bar, (1.0, 0.0), m.ground, (0.0, 0.0), (0.0, 0.0), 1.0)
    # a guided body's free coordinates follow the earlier bodies' in the order x, y, theta
    slider = m.add_guided(1.0, 1.0, y=0.0, theta=0.0, position=(0.3, 0.0), velocity=(2.0, 0.0))
    q0, v0, angles = m.initial_coordinates()
    assert q0.tolist() == [0.0, 0.0, 0.0, 0.0, 0.3] and v0.tolist() == [0.0] * 4 + [2.0]
    assert angles == (0, 3) and repr(slider) == "Body('body3', guided)"
