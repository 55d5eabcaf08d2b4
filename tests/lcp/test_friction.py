"""The 2D Coulomb friction LCP: layout, read-back, physics of the solutions."""

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.lcp import (
    SOLVED,
    build_friction_lcp,
    contact_velocities,
    friction_impulses,
    solve_lcp,
)
from moreau.lcp.instances import random_friction_data

from .conftest import assert_complementary


def test_layout_and_matrix_entries_for_one_frictional_and_one_frictionless_contact():
    # contacts 0 (mu = 0.3) and 1 (mu = 0): W rows [N0, N1, T0]
    W = np.array([[2.0, 0.5, 0.1], [0.5, 3.0, 0.2], [0.1, 0.2, 4.0]])
    v_free = np.array([-1.0, -2.0, 0.7])
    M, q, layout = build_friction_lcp(W, v_free, [0.3, 0.0], [0.5, 0.0], vN_pre=np.array([-2.0, 1.0]))
    assert layout.size == 5
    assert layout.normal.tolist() == [0, 4]
    assert layout.tplus.tolist() == [1, -1]
    assert layout.tminus.tolist() == [2, -1]
    assert layout.beta.tolist() == [3, -1]
    assert layout.frictional.tolist() == [0]
    expected = np.array([
        #  pN0   pT+   pT-  beta   pN1
        [2.0, 0.1, -0.1, 0.0, 0.5],   # vN0 + e vpre^-
        [0.1, 4.0, -4.0, 1.0, 0.2],   # vT0 + beta
        [-0.1, -4.0, 4.0, 1.0, -0.2],  # -vT0 + beta
        [0.3, -1.0, -1.0, 0.0, 0.0],  # mu pN - pT+ - pT-
        [0.5, 0.2, -0.2, 0.0, 3.0],   # vN1 (mu = 0: normal row only)
    ])
    np.testing.assert_array_equal(M, expected)
    # restitution uses the negative part of the pre-impact velocity only
    np.testing.assert_array_equal(q, [-1.0 + 0.5 * -2.0, 0.7, -0.7, 0.0, -2.0])


def test_all_frictionless_gives_the_normal_problem_only():
    W = np.array([[1.0, 0.2], [0.2, 1.0]])
    M, q, layout = build_friction_lcp(W, [-1.0, 0.5], [0.0, 0.0], 0.0)
    np.testing.assert_array_equal(M, W)
    assert layout.size == 2 and layout.n_frictional == 0


def test_sliding_block_slips_with_friction_opposing_motion():
    # unit mass block on the ground: normal approach -1, sliding at +3
    M, q, layout = build_friction_lcp(np.eye(2), [-1.0, 3.0], [0.4], 0.0)
    res = solve_lcp(M, q)
    pN, pT = friction_impulses(res.z, layout)
    vN, vT = contact_velocities(np.eye(2), [-1.0, 3.0], res.z, layout)
    assert pN[0] == pytest.approx(1.0)
    assert pT[0] == pytest.approx(-0.4)
    assert vN[0] == pytest.approx(0.0, abs=1e-15)
    assert vT[0] == pytest.approx(2.6)
    assert res.z[layout.beta[0]] == pytest.approx(2.6)  # beta = |vT|


def test_slow_block_sticks():
    M, q, layout = build_friction_lcp(np.eye(2), [-1.0, 0.1], [0.4], 0.0)
    res = solve_lcp(M, q)
    pN, pT = friction_impulses(res.z, layout)
    vN, vT = contact_velocities(np.eye(2), [-1.0, 0.1], res.z, layout)
    assert pT[0] == pytest.approx(-0.1)
    assert abs(pT[0]) < 0.4 * pN[0]
    assert vT[0] == pytest.approx(0.0, abs=1e-15)


def test_newton_restitution_bounces_back():
    M, q, layout = build_friction_lcp(np.eye(1), [-2.0], [0.0], 0.75)
    res = solve_lcp(M, q)
    vN, _ = contact_velocities(np.eye(1), [-2.0], res.z, layout)
    assert vN[0] == pytest.approx(1.5)


def test_impulses_stacked_match_W_order():
    W = np.diag([1.0, 2.0, 3.0, 4.0, 5.0])
    M, q, layout = build_friction_lcp(W, [-1.0, -1.0, -1.0, 0.5, 0.5], [0.0, 0.5, 0.5], 0.0)
    z = solve_lcp(M, q).z
    p = friction_impulses(z, layout, stacked=True)
    pN, pT = friction_impulses(z, layout)
    np.testing.assert_array_equal(p, np.concatenate([pN, pT[layout.frictional]]))
    assert pT[0] == 0.0


def _check_physics(W, v_free, mu, e, vN_pre, z, layout, tol=1e-8):
    pN, pT = friction_impulses(z, layout)
    vN, vT = contact_velocities(W, v_free, z, layout)
    scale = 1.0 + np.max(np.abs(pN))
    vscale = 1.0 + np.max(np.abs(v_free)) + np.max(np.abs(W)) * scale
    target = -e * np.minimum(vN_pre, 0.0)
    assert np.all(pN >= -tol * scale)
    assert np.all(np.abs(pT) <= mu * pN + tol * scale)  # friction cone
    assert np.all(vN >= target - tol * vscale)  # Newton's law
    assert np.all(np.minimum(pN, vN - target) <= tol * vscale)  # no impulse at separation
    slipping = np.abs(vT) > 1e-6 * vscale
    # in slip, friction is saturated and opposes the slip velocity
    np.testing.assert_allclose(np.abs(pT[slipping]), (mu * pN)[slipping], rtol=0, atol=10 * tol * scale)
    assert np.all(pT[slipping] * vT[slipping] <= tol * scale * vscale)
    # frictionless contacts carry no tangential impulse
    assert np.all(pT[mu == 0] == 0.0)


@pytest.mark.parametrize("nc", [1, 5, 50])
def test_random_friction_instances_are_physical(nc):
    rng = np.random.default_rng(100 + nc)
    for _ in range(5):
        W, v_free, mu, e, vN_pre = random_friction_data(nc, rng)
        M, q, layout = build_friction_lcp(W, v_free, mu, e, vN_pre)
        res = solve_lcp(M, q, method="auto", friction=layout)
        assert res.success, res.message
        assert_complementary(M, q, res.z, 1e-8)
        _check_physics(W, v_free, mu, e, vN_pre, res.z, layout)


def test_lemke_solves_every_friction_lcp_without_restitution():
    # with q in the range of J (e = 0) Lemke's method provably processes the
    # friction LCP; 5-40 contacts, full and deficient rank, mu = 0 contacts
    rng = np.random.default_rng(2024)
    solved = 0
    for _ in range(150):
        nc = int(rng.integers(5, 41))
        W, v_free, mu, e, vN_pre = random_friction_data(nc, rng)
        M, q, layout = build_friction_lcp(W, v_free, mu, 0.0, vN_pre)
        res = solve_lcp(M, q)
        assert res.status == SOLVED, (nc, res.message)
        _check_physics(W, v_free, mu, np.zeros(nc), vN_pre, res.z, layout)
        solved += 1
    assert solved == 150


def test_auto_solves_every_friction_lcp_with_restitution():
    # with e > 0, q leaves the range where Lemke is guaranteed and a few
    # paths end on a secondary ray; the Tresca fallback then finds a solution
    rng = np.random.default_rng(7)
    fell_back = 0
    for _ in range(150):
        nc = int(rng.integers(5, 41))
        W, v_free, mu, e, vN_pre = random_friction_data(nc, rng)
        M, q, layout = build_friction_lcp(W, v_free, mu, e, vN_pre)
        res = solve_lcp(M, q, method="auto", friction=layout)
        assert res.success, res.message
        _check_physics(W, v_free, mu, e, vN_pre, res.z, layout)
        fell_back += res.fallback_used
    assert fell_back <= 5


def test_builder_rejects_bad_input():
    W = np.eye(3)
    with pytest.raises(InputError, match=r"`W` must have shape \(3, 3\)"):
        build_friction_lcp(np.eye(2), [0.0, 0.0, 0.0], [0.5, 0.0], 0.0)
    with pytest.raises(InputError, match=r"`v_free` must have shape \(3\)"):
        build_friction_lcp(W, [0.0, 0.0], [0.5, 0.0], 0.0)
    with pytest.raises(InputError, match="`mu` must be >= 0"):
        build_friction_lcp(W, [0.0, 0.0, 0.0], [0.5, -0.1], 0.0)
    with pytest.raises(InputError, match=r"`e` must lie in \[0, 1\]"):
        build_friction_lcp(W, [0.0, 0.0, 0.0], [0.5, 0.0], 1.5)
    with pytest.raises(InputError, match="`e` must be a scalar or have one entry per contact"):
        build_friction_lcp(W, [0.0, 0.0, 0.0], [0.5, 0.0], [0.1, 0.2, 0.3])
    with pytest.raises(InputError, match=r"`vN_pre` must have shape \(2\)"):
        build_friction_lcp(W, [0.0, 0.0, 0.0], [0.5, 0.0], 0.0, vN_pre=[1.0])
    with pytest.raises(InputError, match="`W` must contain only finite values"):
        build_friction_lcp(np.full((3, 3), np.nan), [0.0, 0.0, 0.0], [0.5, 0.0], 0.0)
    _, _, layout = build_friction_lcp(W, [0.0, 0.0, 0.0], [0.5, 0.0], 0.0)
    with pytest.raises(InputError, match=r"`z` must have shape \(5,\)"):
        friction_impulses(np.zeros(4), layout)
