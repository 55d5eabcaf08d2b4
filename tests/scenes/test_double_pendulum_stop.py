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
    # t = 2.4), h = 0.04, 0.02, 0.01. Measured: largest energy error 0.706, 0.390, 0.205
    # (order 0.86, 0.92; 0.106, 0.054 at h = 0.005, 0.0025: order 0.95, 0.98); joint drift
    # 5.28e-3, 1.37e-3, 3.58e-4 (order 1.95, 1.94). The energy is first order even before
    # the impact (0.0478, 0.0243 at t = 2.2, h = 0.01, 0.005: order 0.97): the joints'
    # impulses on the velocity-level rows do work O(h^2) a step
    case = DoublePendulumStopCase()
    sc = case.scene
    q0, v0 = sc.initial_state()
    e0 = case.energy(q0[None], v0[None])[0]
    assert e0 == pytest.approx(2.0, rel=1e-14)      # m g l / 2 + m g (l + l / 2) in units
    errors, drifts = [], []
    for h in (0.04, 0.02, 0.01):
        res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=h, theta=0.5)
        assert res.status == 0, res.message
        assert np.any(res.force_N[:, 0] > 0.0)                   # it struck the wall
        errors.append(float(np.max(np.abs(case.energy(res.q, res.v) - e0))))
        drifts.append(res.constraint_drift)
    for k in range(2):
        assert 0.8 < math.log2(errors[k] / errors[k + 1]) < 1.2, errors
        assert 1.8 < math.log2(drifts[k] / drifts[k + 1]) < 2.2, drifts
    assert errors[-1] < 0.12 * e0


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
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, fast=True)


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
