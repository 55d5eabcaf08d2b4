"""The QP method: exact formulations, the Tresca fixed point and its distance from Lemke."""

import numpy as np
import pytest

from moreau.lcp import (
    MAX_ITER,
    NOT_APPLICABLE,
    SOLVED,
    SOLVER_FAILED,
    build_friction_lcp,
    friction_impulses,
    solve_lcp,
)
from moreau.lcp import qp as qp_module
from moreau.lcp.instances import random_friction_data, random_lp, random_psd
from moreau.lcp.qp import qp_formulation

from .conftest import assert_complementary


def test_bound_qp_on_rank_deficient_psd_recovers_the_unique_w():
    rng = np.random.default_rng(1)
    for n, rank in ((8, 8), (20, 5), (30, 29)):
        M, q, z_star, w_star = random_psd(n, rank, rng)
        assert qp_formulation(M) == "bound"
        res = solve_lcp(M, q, method="qp")
        assert res.status == SOLVED and "'bound'" in res.message
        assert_complementary(M, q, res.z, 1e-6)
        np.testing.assert_allclose(res.w, w_star, atol=1e-7)


def test_gap_qp_solves_the_lp_lcp_and_closes_the_duality_gap():
    rng = np.random.default_rng(2)
    m, k = 12, 8
    M, q = random_lp(m, k, rng)
    assert qp_formulation(M) == "gap"
    res = solve_lcp(M, q, method="qp")
    assert res.status == SOLVED and "'gap'" in res.message
    assert_complementary(M, q, res.z, 1e-6)
    x, y = res.z[:m], res.z[m:]
    c, b = q[:m], -q[m:]
    # primal and dual objectives meet at an LP optimum
    assert c @ x == pytest.approx(b @ y, abs=1e-6 * (1 + abs(c @ x)))


def test_non_monotone_without_layout_is_not_applicable():
    M = np.array([[0.0, 1.0], [2.0, 0.0]])  # symmetric part indefinite
    res = solve_lcp(M, -np.ones(2), method="qp")
    assert res.status == NOT_APPLICABLE and not res.success
    assert "friction layout" in res.message
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))


def test_osqp_failure_becomes_a_status(monkeypatch):
    monkeypatch.setattr(qp_module, "_osqp_run", lambda *a, **k: (None, "exception", None, None))
    res = solve_lcp(np.eye(3), -np.ones(3), method="qp")
    assert res.status == SOLVER_FAILED
    assert np.all(np.isfinite(res.z)) and not np.any(np.isnan(res.w))


def test_tresca_with_a_single_frictional_contact_matches_the_closed_form():
    # unit-mass block: pN = 1, pT = -mu pN while sliding
    M, q, layout = build_friction_lcp(np.eye(2), [-1.0, 3.0], [0.4], 0.0)
    res = solve_lcp(M, q, method="qp", friction=layout)
    assert res.status == SOLVED and "'tresca'" in res.message
    pN, pT = friction_impulses(res.z, layout)
    assert pN[0] == pytest.approx(1.0, abs=1e-9)
    assert pT[0] == pytest.approx(-0.4, abs=1e-9)


def test_tresca_fixed_point_distance_from_lemke():
    """Measure how far the QP answer lies from Lemke's on random friction LCPs.

    Distance: max |p_qp - p_lemke| / (1 + max |p_lemke|) over the stacked
    impulses. Figures at the time of writing (seed 7, 60 instances with
    1-50 contacts): 58 fixed points converge, in a median of 17 QP solves
    (at most 43); 2 stop at the limit of 60 (status MAX_ITER). Over the
    converged ones the distance has median 6e-11 and 90th percentile 5e-10;
    the largest, 0.1, is an instance where the QP answer passes the
    residual check too: a second solution of a non-unique Coulomb problem,
    not an error.
    """
    rng = np.random.default_rng(7)
    dists = []
    not_converged = 0
    for k in range(60):
        nc = (1, 5, 50)[k % 3] if k < 9 else int(rng.integers(5, 41))
        W, v_free, mu, e, vN_pre = random_friction_data(nc, rng)
        M, q, layout = build_friction_lcp(W, v_free, mu, e, vN_pre)
        lem = solve_lcp(M, q)
        if not lem.success:
            continue
        res = solve_lcp(M, q, method="qp", friction=layout, max_iter=60)
        assert res.status in (SOLVED, MAX_ITER)
        if res.status == MAX_ITER:
            not_converged += 1
            assert "did not converge" in res.message
            continue
        assert res.residual <= 1e-6
        pl = friction_impulses(lem.z, layout, stacked=True)
        pq = friction_impulses(res.z, layout, stacked=True)
        dists.append(np.max(np.abs(pl - pq)) / (1 + np.max(np.abs(pl))))
    dists = np.array(dists)
    assert len(dists) >= 50
    assert not_converged <= 5
    assert np.median(dists) <= 1e-8
    assert np.percentile(dists, 90) <= 1e-6


def test_refinement_never_makes_the_answer_worse():
    rng = np.random.default_rng(4)
    M, q, _, _ = random_psd(15, 6, rng)
    raw = solve_lcp(M, q, method="qp", refine=False)
    ref = solve_lcp(M, q, method="qp", refine=True)
    assert ref.residual <= raw.residual


def test_auto_falls_back_and_records_the_path():
    rng = np.random.default_rng(3)
    M, q, _, w_star = random_psd(12, 12, rng)
    res = solve_lcp(M, q, method="auto", max_iter=1)  # Lemke cannot finish in one pivot
    assert res.success
    assert res.method == "qp" and res.path == ("lemke", "qp") and res.fallback_used
    assert "Lemke first: Iteration limit" in res.message
    np.testing.assert_allclose(res.w, w_star, atol=1e-7)


def test_auto_without_fallback_is_plain_lemke():
    res = solve_lcp(np.eye(2), -np.ones(2), method="auto")
    assert res.method == "lemke" and res.path == ("lemke",) and not res.fallback_used


def test_auto_when_both_fail_keeps_both_messages():
    # Lemke stopped by the pivot limit, and no QP formulation for an indefinite M
    res = solve_lcp(np.array([[0.0, 1.0], [2.0, 0.0]]), -np.ones(2), method="auto", max_iter=1)
    assert not res.success
    assert res.path == ("lemke", "qp")
    assert "Iteration limit" in res.message and "QP" in res.message
