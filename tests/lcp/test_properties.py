"""Property tests: what a solved result promises, and that failures stay finite."""

import numpy as np
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from moreau.lcp import SOLVED, build_friction_lcp, solve_lcp
from moreau.lcp.instances import random_friction_data

from .conftest import TOL, assert_complementary

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

entries = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False, width=64)


@st.composite
def square_problems(draw, max_n=8, elements=entries):
    n = draw(st.integers(1, max_n))
    M = draw(arrays(np.float64, (n, n), elements=elements))
    q = draw(arrays(np.float64, (n,), elements=elements))
    return M, q


@st.composite
def p_matrix_problems(draw, max_n=10):
    # D (A A^T / n + I/2 + S - S^T): positive definite symmetric part, then a
    # positive row scaling; both keep every principal minor positive
    n = draw(st.integers(1, max_n))
    A = draw(arrays(np.float64, (n, n), elements=st.floats(-3, 3, width=64)))
    S = draw(arrays(np.float64, (n, n), elements=st.floats(-3, 3, width=64)))
    D = draw(arrays(np.float64, (n,), elements=st.floats(0.01, 100.0, width=64)))
    M = D[:, None] * (A @ A.T / n + 0.5 * np.eye(n) + S - S.T)
    # no subnormal q: a solution below the smallest subnormal (q = -5e-324, M = 2) has no
    # representable point within the certified bound, and Lemke says so (BREAKDOWN); the
    # claim "solved" holds where the solution is representable. Subnormal data stays in
    # test_anything_marked_solved_is_complementary, which holds every status to honesty
    q = draw(arrays(np.float64, (n,), elements=st.floats(-100, 100, width=64,
                                                          allow_subnormal=False)))
    return M, q


@st.composite
def triangular_p_problems(draw, max_n=10):
    # Triangular with a positive diagonal: a P-matrix far from PD, Murty's
    # example among them. The entries keep the solution's spread (up to
    # (1 + max|l| / min d)^n = 5^10) well inside double precision: with
    # diagonal 0.05 and off-diagonal -5 it reaches 1e20, the tableau's
    # rounding then exceeds the entries that steer the path, and exact
    # rational arithmetic and floating point part ways (checked by hand). No
    # subnormal q, for the reason given in p_matrix_problems.
    n = draw(st.integers(1, max_n))
    L = draw(arrays(np.float64, (n, n), elements=st.floats(-2, 2, width=64)))
    diag = draw(arrays(np.float64, (n,), elements=st.floats(0.5, 5.0, width=64)))
    M = np.tril(L, -1) + np.diag(diag)
    if draw(st.booleans()):
        M = M.T.copy()
    q = draw(arrays(np.float64, (n,), elements=st.floats(-10, 10, width=64,
                                                          allow_subnormal=False)))
    return M, q


@SETTINGS
@given(square_problems())
def test_anything_marked_solved_is_complementary(prob):
    M, q = prob
    for method in ("lemke", "auto"):
        res = solve_lcp(M, q, method=method)
        assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))
        assert np.isfinite(res.residual)
        if res.status == SOLVED:
            assert res.residual <= TOL[method]
            assert_complementary(M, q, res.z, TOL[method])
        else:
            assert not res.success and res.message


@SETTINGS
@given(p_matrix_problems())
def test_every_p_matrix_lcp_is_solved(prob):
    M, q = prob
    res = solve_lcp(M, q)
    assert res.status == SOLVED, res.message
    assert_complementary(M, q, res.z, TOL["lemke"])


@SETTINGS
@given(triangular_p_problems())
def test_every_triangular_p_matrix_lcp_is_solved(prob):
    M, q = prob
    res = solve_lcp(M, q, max_iter=2 ** (len(q) + 1))
    assert res.status == SOLVED, res.message
    assert_complementary(M, q, res.z, TOL["lemke"])


def _subnormal_tie():
    # found by hypothesis: after a tie, a right-hand side of the exact step (about
    # 1 / 2.2e-309) lies beyond the floats and rounding it raised OverflowError; the exact
    # path now goes on from that basis and solves it (z_6 = 4.5e108)
    M = np.full((6, 6), 2.22507386e-309)
    M[4, 5], M[5, 1] = 1.0, -1.0
    return M, np.array([0.0, -1.0, 0.0, 0.0, 0.0, 0.0])


@SETTINGS
@given(square_problems(max_n=6, elements=st.floats(-1e6, 1e6, width=64)),
       st.sampled_from([1e-200, 1e-60, 1.0, 1e60, 1e200]), st.sampled_from([1e-200, 1.0, 1e200]))
@example(_subnormal_tie(), 1.0, 1e-200)
def test_no_status_ever_comes_with_a_nan(prob, sm, sq):
    M, q = prob
    M = M * sm
    q = q * sq
    assume(np.all(np.isfinite(M)) and np.all(np.isfinite(q)))
    res = solve_lcp(M, q, max_iter=50)
    assert not np.any(np.isnan(res.z)) and not np.any(np.isnan(res.w))
    assert np.all(np.isfinite(res.z))
    assert not np.isnan(res.residual)
    if res.status == SOLVED:
        assert res.residual <= TOL["lemke"]


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 12))
def test_friction_lcps_are_solved_by_auto(seed, nc):
    rng = np.random.default_rng(seed)
    W, v_free, mu, e, vN_pre = random_friction_data(nc, rng)
    M, q, layout = build_friction_lcp(W, v_free, mu, e, vN_pre)
    res = solve_lcp(M, q, method="auto", friction=layout)
    assert res.success, res.message
    assert_complementary(M, q, res.z, TOL["auto"])


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 12))
def test_symmetric_psd_lcps_are_solved_by_qp(seed, n):
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, max(1, n // 2)))
    M = B @ B.T
    q = rng.standard_normal(n)
    # make it feasible: q = w - M z for some complementary pair
    z = np.where(rng.random(n) < 0.5, rng.random(n), 0.0)
    w = np.where(z > 0, 0.0, rng.random(n))
    q = w - M @ z
    res = solve_lcp(M, q, method="qp")
    if not res.success:
        # the one honest way out, found by hypothesis (seed 78679498, n = 3): OSQP's
        # answer solves the balanced data but misses the check on the given data by
        # rounding (1.3e-6 against 1e-6); it is refused by name, never passed off
        assert "fails the check on the given data" in res.message, res.message
        assert res.residual <= 10 * TOL["qp"]
        return
    assert_complementary(M, q, res.z, TOL["qp"])
