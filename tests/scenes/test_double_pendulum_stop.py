"""The double pendulum against a wall (two revolute joints, one contact): energy and refusals."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.double_pendulum_stop import DoublePendulumStopCase, double_pendulum_stop


def test_energy_is_kept_to_the_schemes_order_through_an_impact():
    # frictionless, e = 1: the energy is conserved (2 in the scene's units, above the
    # hanging rest). Moreau-Jean theta = 1/2 over [0, 3] (the tip strikes the wall once, at
    # t = 2.4), h = 0.04, 0.02, 0.01. With the joint rows on the midpoint velocity the joint
    # and contact impulses do no work on it, and with a constant mass matrix and gravity the
    # step keeps the energy exactly (moreau_jean's module docstring): measured largest
    # energy error 8.9e-16, 3.1e-15, 2.7e-15 (1.4e-14 at h = 0.005; it was first order,
    # 0.706, 0.390, 0.205, with the rows on the end velocity); joint drift 2.17e-3, 5.19e-4,
    # 1.32e-4, 3.32e-5 (order 2.06, 1.97, 1.99)
    case = DoublePendulumStopCase()
    sc = case.scene
    q0, v0 = sc.initial_state()
    e0 = case.energy(q0[None], v0[None])[0]
    assert e0 == pytest.approx(2.0, rel=1e-14)      # m g l / 2 + m g (l + l / 2) in units
    errors, drifts = [], []
    for h in (0.04, 0.02, 0.01):
        res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=h, theta=0.5,
                       joint_rows="theta")
        assert res.status == 0, res.message
        assert np.any(res.force_N[:, 0] > 0.0)                   # it struck the wall
        errors.append(float(np.max(np.abs(case.energy(res.q, res.v) - e0))))
        drifts.append(res.constraint_drift)
    # better than second order: conserved to rounding at every step
    assert max(errors) < 1e-12 * e0, errors
    for k in range(2):
        assert 1.8 < math.log2(drifts[k] / drifts[k + 1]) < 2.2, drifts
    assert drifts[-1] < 2e-4


def test_the_joint_projection_keeps_the_joints_to_rounding_and_the_energy_at_order_two():
    # joint_projection=True: after each step q_{k+1} is projected onto gE = 0 (mass-weighted
    # Gauss-Newton). Measured over [0, 3], theta = 1/2: drift 6.8e-15, 8.1e-15, 9.9e-15 at
    # h = 0.04, 0.02, 0.01; energy error 2.40e-3, 5.50e-4, 1.35e-4 (order 2.12, 2.03: the
    # projection's O(h^3) position change a step moves the potential)
    case = DoublePendulumStopCase()
    sc = case.scene
    q0, v0 = sc.initial_state()
    e0 = case.energy(q0[None], v0[None])[0]
    errors = []
    for h in (0.04, 0.02, 0.01):
        res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=h, theta=0.5,
                       joint_rows="theta", joint_projection=True)
        assert res.status == 0, res.message
        assert res.constraint_drift < 1e-13
        assert res.stats["projection_iterations"] >= res.stats["steps"]
        errors.append(float(np.max(np.abs(case.energy(res.q, res.v) - e0))))
    for k in range(2):
        assert 1.8 < math.log2(errors[k] / errors[k + 1]) < 2.3, errors
    from moreau.scenes.bouncing_ball import BouncingBall
    with pytest.raises(InputError, match="`joint_projection` projects the positions onto the "
                                         "joints; scene 'bouncing-ball' has no joint rows"):
        simulate(BouncingBall(), (0.0, 1.0), [1.0], [0.0], "moreau-jean", h=0.01,
                 joint_projection=True)
    with pytest.raises(InputError, match="`joint_projection` must be True or False"):
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, joint_projection=1)


def test_bad_models_and_schemes_without_joints_are_refused_by_name():
    with pytest.raises(InputError, match=r"`wall` \(-2.5\) must not be left of the lower tip"):
        double_pendulum_stop(wall=-2.5)
    with pytest.raises(InputError, match=r"`wall` \(3.0\) must be within the reach"):
        double_pendulum_stop(wall=3.0)
    with pytest.raises(InputError, match=r"`mass2` must be finite and > 0, got 0.0"):
        double_pendulum_stop(mass2=0.0)
    with pytest.raises(InputError, match="needs `restitution` = 1 and `mu` = 0"):
        DoublePendulumStopCase(restitution=0.5)
    sc = double_pendulum_stop()
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match="scheme 'nonsmooth-generalized-alpha' solves no joints"):
        simulate(sc, (0.0, 1.0), q0, v0, "nonsmooth-generalized-alpha", h=0.01)
    with pytest.raises(InputError, match="`fast=True`: the compiled loop of 'moreau-jean' "
                                         "solves no joints"):
        # (the compiled loop of joints solves the contact as "auto" does, not by a forced solver)
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, fast=True, lcp_method="lemke")


def test_the_event_driven_reference_keeps_the_energy_through_the_strikes():
    # issue 36: the reference keeps the frictionless e = 1 pendulum's energy to 1e-10,
    # with its joints projected after each smooth phase and each impact
    from moreau.scenes.double_pendulum_stop import pendulum_energy

    sc = double_pendulum_stop()
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 3.0), q0, v0, "event-driven")
    assert res.status == 0
    energy = pendulum_energy(sc, res.q, res.v)
    assert np.max(np.abs(energy - energy[0])) < 1e-10
    assert res.constraint_drift < 1e-10
    # the tip does strike the wall in the window (once, near t = 2.376 in scene units)
    assert [e.kind for e in res.events].count("impact") == 1


def test_the_default_end_rows_lose_energy_at_first_order_and_refuse_bad_rows():
    # joint_rows="end" (the default) holds G v_{k+1} + w = 0: the end velocity stays on the
    # joints (no alternating velocity across them), at the price of a first-order energy
    # error at theta = 1/2 (measured 0.706, 0.390, 0.205 at h = 0.04, 0.02, 0.01)
    case = DoublePendulumStopCase()
    sc = case.scene
    q0, v0 = sc.initial_state()
    e0 = case.energy(q0[None], v0[None])[0]
    errors = []
    for h in (0.04, 0.02):
        res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=h, theta=0.5)
        errors.append(float(np.max(np.abs(case.energy(res.q, res.v) - e0))))
    assert 0.7 < math.log2(errors[0] / errors[1]) < 1.2, errors
    with pytest.raises(InputError, match="`joint_rows` must be 'end', 'theta' or "
                                         "'theta-projected'"):
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, joint_rows="mid")


def _joint_rate(sc, res):
    # the largest |G(q) v + w(t)| over the samples: a velocity across the joints
    return max(float(np.max(np.abs(G @ v + w))) for G, w, v in
               ((*sc.joint_jacobians(q, t), v) for t, q, v in zip(res.t, res.q, res.v)))


def test_theta_projected_rows_keep_the_energy_at_order_two_and_no_velocity_across_the_joints():
    # joint_rows="theta-projected": the "theta" rows, then the end velocity projected onto
    # G(q_k+1) v + w = 0 (mass-weighted). Measured over [0, 3], theta = 1/2, h = 0.04, 0.02:
    # energy error 1.46e-2, 2.72e-3 (0.01: 5.66e-4; order 2.4, 2.3), |G v + w| at the
    # samples 4.4e-16, 8.9e-16; the "theta" rows keep the energy to rounding but leave
    # velocities across the joints of 0.49, 0.24 (alternating), the "end" rows 0.17, 0.086
    # with an energy error of 0.71, 0.39
    case = DoublePendulumStopCase()
    sc = case.scene
    q0, v0 = sc.initial_state()
    e0 = case.energy(q0[None], v0[None])[0]
    errors = []
    for h in (0.04, 0.02):
        res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=h, theta=0.5,
                       joint_rows="theta-projected")
        assert res.status == 0, res.message
        assert np.any(res.force_N[:, 0] > 0.0)
        errors.append(float(np.max(np.abs(case.energy(res.q, res.v) - e0))))
        assert _joint_rate(sc, res) < 1e-13
        theta_rows = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=h, theta=0.5,
                              joint_rows="theta")
        assert _joint_rate(sc, theta_rows) > 1e3 * _joint_rate(sc, res)
    assert math.log2(errors[0] / errors[1]) > 1.8, errors
    assert errors[1] < 1e-2 * 0.39
