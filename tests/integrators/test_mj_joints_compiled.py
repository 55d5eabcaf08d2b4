"""Moreau–Jean's compiled loop of joints (moreau.integrators._mj_joint_kernels) against its generic step.

The generic step (``fast=False``) is the reference: the same mixed LCP solved in
Python (the equality rows eliminated, the contact in closed form or by Lemke).
"""

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.moreau_jean import MoreauJean
from moreau.model.planar import HalfPlane, Model, Point, Segment
from moreau.scenes.double_pendulum_stop import double_pendulum_stop
from moreau.scenes.slider_crank import slider_crank
from moreau.scenes.slider_crank_clearance import slider_crank_clearance


def _pair(scene, t_end, steps, **opts):
    q0, v0 = scene.initial_state()
    h = t_end / steps
    a = simulate(scene, (0.0, t_end), q0, v0, "moreau-jean", h=h, fast=False, **opts)
    b = simulate(scene, (0.0, t_end), q0, v0, "moreau-jean", h=h, **opts)
    return a, b


def _agree(a, b, rtol=1e-12):
    assert a.status == b.status == 0
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.regime, b.regime)
    qs = max(1.0, float(np.max(np.abs(a.q))))
    vs = max(1.0, float(np.max(np.abs(a.v))))
    assert np.max(np.abs(b.q - a.q)) <= rtol * qs
    assert np.max(np.abs(b.v - a.v)) <= rtol * vs
    if a.force_N.size:
        fs = max(1.0, float(np.max(np.abs(a.force_N))))
        assert np.max(np.abs(b.force_N - a.force_N)) <= rtol * fs
        assert np.max(np.abs(b.force_T - a.force_T)) <= rtol * fs
        assert np.max(np.abs(b.slip_velocity - a.slip_velocity)) <= rtol * vs
        assert np.max(np.abs(b.gap - a.gap)) <= rtol * qs
    assert b.constraint_drift == pytest.approx(a.constraint_drift, rel=1e-9, abs=1e-15)
    for key in ("steps", "lcp_solves"):
        assert a.stats[key] == b.stats[key], key


def test_joint_scenes_run_compiled():
    for sc in (slider_crank(), double_pendulum_stop()):
        q0, v0 = sc.initial_state()
        assert MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1)._fast
        assert not MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, joint_projection=True)._fast
        assert not MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, lcp_method="lemke")._fast


@pytest.mark.parametrize("make, t_end, opts", [
    (slider_crank, 1.5, {}),
    # the strike of the lower link on the wall (t = 2.4), frictional and bouncing
    (lambda: double_pendulum_stop(mu=0.3, restitution=0.5), 3.0,
     {"theta": 0.5, "joint_rows": "theta"}),
    (slider_crank_clearance, 0.75, {}),
    # the Baumgarte term on both rows (module docstring of moreau_jean, *Baumgarte*)
    (slider_crank, 1.5, {"theta": 0.5, "joint_baumgarte": 0.5}),
    (lambda: double_pendulum_stop(mu=0.3, restitution=0.5), 3.0,
     {"theta": 0.5, "joint_rows": "theta", "joint_baumgarte": 1.0}),
])
def test_compiled_joint_loop_equals_the_generic_step(make, t_end, opts):
    a, b = _pair(make(), t_end, 120, **opts)
    if a.force_N.size:
        assert a.stats["lcp_solves"] > 0
    _agree(a, b)


def _rod_on_two_supports():
    # a rod pinned at its left end falls onto two supports under its right half: two
    # contacts close at once, a step the compiled loop hands to the generic step (Lemke)
    m = Model(gravity=(0.0, -9.81))
    a = 0.02
    rod = m.add_body(1.0, 1.0 / 12.0, position=(0.5 * np.cos(a), 0.5 * np.sin(a)), angle=a)
    m.add_revolute(m.ground, (0.0, 0.0), rod, (-0.5, 0.0))
    floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), (0.0, 1.0)))
    m.add_contact(m.add_shape(rod, Point((0.3, 0.0))), floor, mu=0.2)
    m.add_contact(m.add_shape(rod, Point((0.5, 0.0))), floor, mu=0.2)
    m.add_shape(rod, Segment((-0.5, 0.0), (0.5, 0.0)))
    return m.build("rod-on-two-supports")


@pytest.mark.slow
def test_several_contacts_are_handed_to_the_generic_step():
    # slow: a model of its own (its generated functions compile in a fresh process)
    a, b = _pair(_rod_on_two_supports(), 2.0, 200, save_every=1)
    # both supports closed: Lemke's steps, the compiled run's taken by the generic step
    assert b.stats["pivots"] == a.stats["pivots"] > 50
    _agree(a, b)


@pytest.mark.slow
def test_a_pinned_rod_comes_to_rest_on_its_stop():
    # slow: a model of its own. Its tip's contact has a singular reduced Delassus matrix
    # (the joint ties the tip's normal and tangential rates): the one-contact closed form
    # missed (residual 1.7e-6, the check's violation 8.5e-6 > 1e-9) and the run stopped at
    # the strike (t = 0.23) with status -3; Lemke takes those steps now
    m = Model(gravity=(0.0, -9.81))
    a = 0.02
    rod = m.add_body(1.0, 1.0 / 12.0, position=(0.5 * np.cos(a), 0.5 * np.sin(a)), angle=a)
    m.add_revolute(m.ground, (0.0, 0.0), rod, (-0.5, 0.0))
    floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), (0.0, 1.0)))
    m.add_contact(m.add_shape(rod, Point((0.5, 0.0))), floor, mu=0.2)
    sc = m.build("rod-on-a-stop")
    q0, v0 = sc.initial_state()
    # measured at rest: |v| 1.6e-16 (theta = 1), 3.5e-18 ("end" rows), 1.5e-18
    # ("theta-projected"); the "theta" rows keep 1.6e-4 across the joint (alternating)
    for opts in ({"theta": 1.0}, {"theta": 0.5}, {"theta": 0.5, "joint_rows": "theta-projected"}):
        res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=0.01, **opts)
        assert res.status == 0, res.message
        # the singular steps reach Lemke: inside the contact problem's "auto" (the one-contact
        # closed form hands a singular Delassus matrix to it) or, where the closed form's
        # answer fails the check on the whole mixed problem, through the joint step's fallback
        assert res.stats["lcp_solves"] > 0
        assert np.max(np.abs(res.v[-10:])) < 1e-14
    res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=0.01, theta=0.5, joint_rows="theta")
    assert np.max(np.abs(res.v[-10:])) > 1e-5


def test_forced_compiled_joints_with_a_forced_solver_is_refused():
    sc = double_pendulum_stop()
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match="`fast=True`: the compiled loop of 'moreau-jean' "
                                         "solves no joints of this scene"):
        MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, fast=True, lcp_method="lemke")


def test_the_loops_rank_test_is_the_generic_steps():
    # the loop's shortcut (k cond_1 below 1e10: regular without an SVD) decides as
    # equality_block's SVD does, across the bound and the rank tolerance
    from moreau.integrators._mj_joint_kernels import _regular
    from moreau.lcp.mlcp import RankDeficientError, equality_block
    rng = np.random.default_rng(3)
    for k in (1, 2, 4, 6):
        for log_cond in (0, 6, 9, 10.5, 11.5, 12.5, 14, 20):
            U, _ = np.linalg.qr(rng.standard_normal((k, k)))
            s = np.logspace(0, -log_cond, k)
            A = (U * s) @ U.T
            try:
                equality_block(A)
                full = True
            except RankDeficientError:
                full = False
            assert _regular(A, k) == full, (k, log_cond)
    assert not _regular(np.zeros((2, 2)), 2)
    assert not _regular(np.array([[1.0, np.nan], [0.0, 1.0]]), 2)
