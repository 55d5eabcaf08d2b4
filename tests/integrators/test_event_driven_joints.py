"""The event-driven reference with joints: index reduction, impacts and projection.

The ideal slider-crank (six joint rows, no freedom: its motion is the
closed-form kinematics) and a pendulum in maximal coordinates, pinned by
two joint rows, bouncing elastically off a wall (an impact with joints,
energy conserved).
"""

import math

import numpy as np

from moreau.integrators import simulate
from moreau.integrators.event_driven_generic import ContactModeSolver, project_onto_joints
from moreau.model.scene import Scene
from moreau.scenes.slider_crank import SliderCrankParams, slider_crank, slider_kinematics


def test_slider_crank_follows_its_closed_form_kinematics_to_1e_10():
    sc = slider_crank()
    q0, v0 = sc.initial_state()
    p = SliderCrankParams()
    span = math.pi                       # half a crank turn (time unit 1 / omega)
    res = simulate(sc, (0.0, span), q0, v0, "event-driven",
                   t_eval=np.linspace(0.0, span, 97))
    assert res.status == 0, res.message
    x, dx, ddx = slider_kinematics(res.t, p.crank_radius / p.rod_length, 1.0)
    ms = ContactModeSolver(sc)
    no_contact = np.zeros(0, dtype=int)
    acc = np.array([ms.solve(t, q, v, no_contact)[0][3] for t, q, v in zip(res.t, res.q, res.v)])
    assert np.max(np.abs(res.q[:, 3] - x)) <= 1e-10
    assert np.max(np.abs(res.v[:, 3] - dx)) <= 1e-10
    assert np.max(np.abs(acc - ddx)) <= 1e-10
    # the slider stays on its axis and the joints hold
    assert np.max(np.abs(res.q[:, 4])) <= 1e-12
    assert res.constraint_drift is not None and res.constraint_drift <= 1e-12


class PinnedRodWall(Scene):
    """A uniform rod of length 2 pinned at its top to the origin, its tip against a wall.

    Maximal coordinates ``(x, y, theta)`` of the centre (mass 1, inertia
    1/3, gravity -1 along y). The pin: the top ``(x - sin th, y + cos th)``
    at the origin (two joint rows). The tip ``(x + sin th, y - cos th)``
    against the wall ``x = d``, frictionless, Newton restitution ``e``.
    """

    ndof = 3
    name = "pinned-rod-wall"

    def __init__(self, d, e=1.0):
        self.d = d
        self.mu = np.zeros(1)
        self.restitution = np.array([e])
        self.n_joint_rows = 2

    def mass(self, q):
        return np.diag([1.0, 1.0, 1.0 / 3.0])

    def forces(self, q, v, t):
        return np.array([0.0, -1.0, 0.0])

    def force_jacobians(self, q, v, t):
        return np.zeros((3, 3)), np.zeros((3, 3))

    def gaps(self, q, t):
        return np.array([self.d - q[0] - math.sin(q[2])])

    def contact_jacobians(self, q, t):
        return (np.array([[-1.0, 0.0, -math.cos(q[2])]]), np.zeros(1), np.zeros((0, 3)),
                np.zeros(0))

    def contact_drift(self, q, v, t):
        return np.array([math.sin(q[2]) * v[2] ** 2]), np.zeros(0)

    def joint_residuals(self, q, t):
        return np.array([q[0] - math.sin(q[2]), q[1] + math.cos(q[2])])

    def joint_jacobians(self, q, t):
        c, s = math.cos(q[2]), math.sin(q[2])
        return np.array([[1.0, 0.0, -c], [0.0, 1.0, -s]]), np.zeros(2)

    def joint_drift(self, q, v, t):
        c, s = math.cos(q[2]), math.sin(q[2])
        return np.array([s * v[2] ** 2, -c * v[2] ** 2])

    def energy(self, q, v):
        return 0.5 * (v[0] ** 2 + v[1] ** 2 + v[2] ** 2 / 3.0) + q[1]


def _released(th0):
    return np.array([math.sin(th0), -math.cos(th0), th0]), np.zeros(3)


def test_an_elastic_impact_with_joints_keeps_the_energy_and_the_joints():
    wall = 2.0 * math.sin(0.3)          # the tip reaches the wall at theta = 0.3
    sc = PinnedRodWall(wall, e=1.0)
    q0, v0 = _released(-0.6)
    res = simulate(sc, (0.0, 7.0), q0, v0, "event-driven")
    assert res.status == 0, res.message
    hits = [ev.t for ev in res.events if ev.kind == "impact"]
    assert len(hits) == 1
    e0 = sc.energy(q0, v0)
    energy = np.array([sc.energy(q, v) for q, v in zip(res.q, res.v)])
    assert np.max(np.abs(energy - e0)) <= 1e-10
    assert res.constraint_drift <= 1e-12
    # the rod bounces back to its release angle (e = 1), after the impact
    after = res.t > hits[0]
    assert abs(np.min(res.q[after, 2]) + 0.6) <= 1e-4


def test_a_plastic_impact_with_joints_leaves_the_rod_resting_on_the_wall():
    q0, v0 = _released(-0.2)
    sc = PinnedRodWall(2.0 * math.sin(-0.1), e=0.0)      # the wall before the rest angle
    res = simulate(sc, (0.0, 4.0), q0, v0, "event-driven")
    assert res.status == 0, res.message
    # after the plastic impact the tip stays on the wall at rest, the pin holding it
    assert abs(res.q[-1, 2] + 0.1) <= 1e-12 and np.max(np.abs(res.v[-1])) <= 1e-12
    assert res.constraint_drift <= 1e-12


def test_projection_puts_a_state_on_the_joints():
    sc = PinnedRodWall(1.0)
    q = np.array([0.3, -0.9, 0.25])
    p = project_onto_joints(sc, 0.0, q)
    assert np.max(np.abs(sc.joint_residuals(p, 0.0))) <= 1e-15
    # a projection in the metric of M: a state pushed off the joints along M^-1 WE^T c
    # comes back to where it was, to second order in c
    q1, _ = _released(0.4)
    WE, _ = sc.joint_jacobians(q1, 0.0)
    for c in (1e-3, 1e-4):
        off = q1 + np.linalg.solve(sc.mass(q1), WE.T @ np.array([c, -2.0 * c]))
        back = project_onto_joints(sc, 0.0, off)
        assert np.max(np.abs(back - q1)) <= 10.0 * c * c
