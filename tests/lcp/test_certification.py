"""Issue 7: success certified the same way for every method; infeasibility as a status with its proof."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moreau.lcp import (
    INFEASIBLE,
    SECONDARY_RAY,
    SOLVED,
    SOLVER_FAILED,
    lcp_residual,
    lcp_violation,
    solve_lcp,
)
from moreau.lcp import qp as qp_module
from moreau.lcp.certify import copositive_plus_class, farkas_vector, infeasibility_from_ray
from moreau.lcp.qp import qp_formulation

from .conftest import assert_certified, assert_farkas

# the instance of the issue: PSD, and w1 + w2 = -2 whatever z is
ISSUE_M = np.array([[1.0, -1.0], [-1.0, 1.0]])
ISSUE_Q = np.array([-1.0, -1.0])


@pytest.mark.parametrize("method", ["lemke", "qp", "auto"])
def test_the_issue_instance_is_reported_infeasible_by_every_method(method):
    res = solve_lcp(ISSUE_M, ISSUE_Q, method=method)
    assert not res.success
    assert res.status == INFEASIBLE
    assert "Infeasible" in res.message
    assert_farkas(ISSUE_M, ISSUE_Q, res.certificate)
    np.testing.assert_allclose(res.certificate, [1.0, 1.0])
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))


def test_auto_takes_lemkes_proof_and_never_asks_the_qp(monkeypatch):
    def no_qp(*args, **kwargs):
        raise AssertionError("the QP was asked after Lemke proved infeasibility")

    monkeypatch.setattr(qp_module, "solve", no_qp)
    res = solve_lcp(ISSUE_M, ISSUE_Q, method="auto")
    assert res.status == INFEASIBLE and res.path == ("lemke",) and not res.fallback_used
    assert "copositive-plus" in res.message and "positive semidefinite" in res.message


@pytest.mark.parametrize("form", ["bound", "gap"])
def test_the_qp_message_names_osqps_certificate(form):
    # a skew part with K 1 = 0 keeps y = (1, 1, 1, 1) a Farkas vector
    # while making M non-symmetric, i.e. the "gap" formulation
    S = np.array([[2.0, 1.0], [1.0, 3.0]])
    M = np.block([[S, -S], [-S, S]])
    if form == "gap":
        M = M + np.array([[0.0, 1, -1, 0], [-1, 0, 1, 0], [1, -1, 0, 0], [0, 0, 0, 0]])
    q = -np.array([1.0, 2.0, 0.5, 1.0])
    assert qp_formulation(M) == form
    res = solve_lcp(M, q, method="qp")
    assert res.status == INFEASIBLE and not res.success
    if form == "bound":
        # the QP is unbounded below: only OSQP's dual certificate can come
        assert "OSQP: dual infeasible" in res.message
    else:
        # empty constraint set, and an objective unbounded on the recession
        # cone: OSQP may see either first (here: the dual one)
        assert "OSQP: dual infeasible" in res.message or "OSQP: primal infeasible" in res.message
    assert_farkas(M, q, res.certificate, rtol=1e-6)


def test_a_qp_answer_that_fails_the_certification_is_not_a_success(monkeypatch):
    # OSQP's old answer on the issue instance, reported as "solved": the
    # certification must turn it down whatever the backend says
    bogus = np.array([2.14e9, 2.14e9])
    monkeypatch.setattr(qp_module, "_osqp_run", lambda *a, **k: (bogus.copy(), "solved", None, None))
    res = solve_lcp(ISSUE_M, ISSUE_Q, method="qp", refine=False)
    assert res.status == SOLVER_FAILED and not res.success
    assert "certification" in res.message
    assert res.residual >= 1.0
    # the old, z-scaled residual would have passed it
    assert lcp_residual(ISSUE_M, ISSUE_Q, bogus) < 1e-6


def test_violation_does_not_shrink_as_z_grows():
    for t in (1.0, 1e3, 1e9, 1e15, 1e100):
        z = np.array([t, t])
        # w = -1 exactly; at large z the sum M z cancels below what even
        # twice the working precision can bound, and the violation grows with
        # that uncertainty instead of shrinking: never less than 1
        assert lcp_violation(ISSUE_M, ISSUE_Q, z) >= 1.0
    assert lcp_violation(ISSUE_M, ISSUE_Q, np.array([1e9, 1e9])) == pytest.approx(1.0, rel=1e-12)


def test_violation_is_the_three_checks():
    # w = z + q with M = I: each check fails alone, at exactly the stated size
    M = 4.0 * np.eye(2)
    q = np.array([-2.0, 1.0])  # tol_w = tol * 2, tol_z = tol * 2 / 4
    # an exact solution: only the rounding bound of w remains (a few ulps)
    assert lcp_violation(M, q, np.array([0.5, 0.0])) <= 1e-14
    assert lcp_violation(M, q, np.array([0.5, -0.01])) == pytest.approx(4 * 0.01 / 2)  # z < 0
    assert lcp_violation(M, q, np.array([0.49, 0.0])) == pytest.approx(0.04 / 2)  # w < 0
    # z_2 = 0.1 > 0 and w_2 = 1.4 > 0: complementarity, min(4 * 0.1, 1.4) / 2
    assert lcp_violation(M, q, np.array([0.5, 0.1])) == pytest.approx(0.2)


@pytest.mark.parametrize("a,b", [(1e-9, 1.0), (1e6, 1e-6), (1.0, 1e12), (3.0, 3.0)])
def test_violation_is_invariant_under_scaling_of_the_data(a, b):
    rng = np.random.default_rng(0)
    M = rng.standard_normal((5, 5))
    q = rng.standard_normal(5)
    z = np.abs(rng.standard_normal(5))
    # LCP(a M, b q) has the solutions (b / a) z of LCP(M, q)
    assert lcp_violation(a * M, b * q, (b / a) * z) == pytest.approx(lcp_violation(M, q, z), rel=1e-12)


def test_non_finite_candidate_has_infinite_violation():
    assert lcp_violation(ISSUE_M, ISSUE_Q, np.array([np.nan, 1.0])) == np.inf
    assert lcp_violation(ISSUE_M, ISSUE_Q, np.array([np.inf, 1.0])) == np.inf


def test_result_residual_is_the_certified_violation():
    rng = np.random.default_rng(1)
    M = rng.standard_normal((6, 6))
    M = M @ M.T + np.eye(6)
    q = rng.standard_normal(6)
    for method in ("lemke", "qp", "auto"):
        res = solve_lcp(M, q, method=method)
        assert res.success
        # equal up to the summation order of M z + q
        assert res.residual == pytest.approx(lcp_violation(M, q, res.z), rel=1e-9, abs=1e-14)
        assert_certified(M, q, res.z, 1e-9 if method == "lemke" else 1e-6)
        assert res.check(M, q, 1e-6)


def test_copositive_plus_classes():
    S = np.array([[2.0, 1.0], [1.0, 1.0]])
    assert copositive_plus_class(np.block([[S, -S], [-S, S]])) == "positive semidefinite (monotone)"
    assert copositive_plus_class(np.array([[0.0, 1.0], [-1.0, 0.0]])) == "positive semidefinite (monotone)"
    assert copositive_plus_class(np.array([[1.0, 7.0], [0.0, 2.0]])) == "nonnegative with a positive diagonal"
    # nonnegative, zero diagonal: z = e1 has z.M z = 0 but (M + M^T) z = e2
    assert copositive_plus_class(np.array([[0.0, 1.0], [0.0, 0.0]])) is None
    # symmetric, eigenvalue about -1e-6, negative entries: not certified
    assert copositive_plus_class(np.array([[1.0, -1.0], [-1.0, 1.0 - 2e-6]])) is None
    assert copositive_plus_class(np.array([[-1.0]])) is None


def test_farkas_vector_rejects_what_is_no_proof():
    M = ISSUE_M
    assert farkas_vector(M, ISSUE_Q, np.array([1.0, 1.0])) is not None
    # (1, 0) has M^T y = (1, -1): no proof by itself; the exact projection onto
    # the null space of M^T turns it into (1, 1), which is one, checked exactly
    assert farkas_vector(M, ISSUE_Q, np.array([1.0, 0.0])).tolist() == [1.0, 1.0]
    assert farkas_vector(M, ISSUE_Q, np.array([1.0, 0.0]) + 0) is not None
    assert farkas_vector(np.array([[1.0, -1.0], [-1.0, 1.0 + 1e-9]]), np.array([-1.0, 0.5]),
                         np.array([1.0, 1.0])) is None  # the issue's case: M^T y = (0, 1e-9)
    assert farkas_vector(M, ISSUE_Q, np.array([-1.0, -1.0])) is None  # y < 0
    assert farkas_vector(M, np.array([1.0, -1.0]), np.array([1.0, 1.0])) is None  # q.y = 0
    assert farkas_vector(M, ISSUE_Q, np.array([np.nan, 1.0])) is None
    assert farkas_vector(M, ISSUE_Q, np.zeros(2)) is None


def test_a_ray_of_a_copositive_plus_matrix_that_is_no_farkas_vector_proves_nothing():
    # a ray made up by rounding must not become a claim of infeasibility:
    # M = [[1, -1], [-1, 1 + 2^-30]] is positive definite, so the LCP is
    # feasible, and no exact Farkas vector exists to be found
    M = np.array([[1.0, -1.0], [-1.0, 1.0 + 2.0**-30]])
    y, why = infeasibility_from_ray(M, ISSUE_Q, np.array([1.0, 1.0, 0.0]))
    assert y is None and "artefact" in why


def test_a_solvable_lcp_whose_ray_proves_nothing_stays_a_secondary_ray():
    # Murty (1988) ex. 2.11 with covering (5, 16): a ray, yet solvable
    M = np.array([[-1.5, 2], [-4, 4]])
    q = np.array([-5.0, 17])
    res = solve_lcp(M, q, covering=np.array([5.0, 16.0]))
    assert res.status == SECONDARY_RAY and res.certificate is None
    assert solve_lcp(M, q).status == SOLVED


_DECIMALS = [0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0 / 3.0, 2.0, -0.1, -0.2, -0.3, -0.5, -1.0 / 3.0, -1.0]


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 6).flatmap(lambda n: st.tuples(
    st.lists(st.sampled_from(_DECIMALS), min_size=n * n, max_size=n * n),
    st.lists(st.sampled_from(_DECIMALS), min_size=n, max_size=n),
    st.lists(st.sampled_from([0.0, 0.1, 0.5, 1.0, 1.0 / 3.0, 3.0]), min_size=n, max_size=n))))
def test_the_compiled_farkas_check_is_exact(data):
    # sums of decimals cancel to exact zeros (0.5 + 0.5 - 1) and to values below
    # any rounding bound (0.1 + 0.2 - 0.3 = 2^-54 ... exactly): the compiled check
    # (float bound, then the exact sign of an expansion) decides every case, as
    # the rational check does
    from moreau.lcp._certified import farkas_float
    from moreau.lcp.certify import _exact_farkas

    Ml, ql, yl = data
    n = len(ql)
    M = np.array(Ml).reshape(n, n)
    q = np.array(ql)
    y = np.array(yl)
    v = farkas_float(M, q, y)
    if not np.any(y > 0):
        assert v == -1
        return
    assert v in (-1, 1)
    assert (v == 1) == _exact_farkas(M, q, y)


def test_a_column_that_cancels_below_its_rounding_bound_is_decided_exactly():
    from moreau.lcp._certified import farkas_float

    y = np.ones(3)
    q = -np.ones(3)
    # column sums 0.5 + 0.25 - 0.75 = 0 exactly, and 0.1 + 0.2 - 0.3 > 0 exactly
    M = np.array([[0.5, 0.1, -1.0], [0.25, 0.2, -1.0], [-0.75, -0.3, -1.0]])
    assert farkas_float(M, q, y) == -1
    M[:, 1] = [0.1, 0.2, -0.30000000000000004]
    assert farkas_float(M, q, y) == 1
