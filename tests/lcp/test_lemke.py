"""Lemke's method: the hard cases, statuses, scale invariance, the compiled kernel."""

import numpy as np
import pytest
from numba import njit

from moreau.errors import InputError, MoreauError
from moreau.lcp import (
    BREAKDOWN,
    INFEASIBLE,
    INVALID_INPUT,
    MAX_ITER,
    SECONDARY_RAY,
    SOLVED,
    lcp_residual,
    lcp_violation,
    lemke_core,
    lemke_kernel,
    lemke_workspace,
    solve_lcp,
)
from moreau.lcp.instances import murty, random_p_matrix
from moreau.lcp.lemke import default_max_iter

from .conftest import assert_complementary, assert_farkas


def test_murty_takes_exactly_two_to_the_n_pivots():
    for n in (3, 6, 10):
        inst = murty(n)
        res = solve_lcp(inst.M, inst.q, max_iter=2**n + 1)
        assert res.success
        assert res.pivots == 2**n
        np.testing.assert_array_equal(res.z, inst.z)


@pytest.mark.parametrize("n", [12, 16])
def test_murty_12_and_16_finish_within_the_default_pivot_limit(n):
    # 4096 and 65536 pivots: QuantEcon's and Siconos's Lemke solve these
    # with their defaults, so must ours
    inst = murty(n)
    res = solve_lcp(inst.M, inst.q)
    assert res.success and res.pivots == 2**n
    np.testing.assert_array_equal(res.z, inst.z)
    assert default_max_iter(n) == 2 ** (n + 1)


def test_default_pivot_limit_is_bounded_by_the_work_budget():
    assert default_max_iter(1) == 1000
    assert default_max_iter(20) == 2**21
    for n in (21, 50, 100, 200, 277):
        # pivots times the n (n + 1) entries each updates stays within 2^30
        assert default_max_iter(n) * n * (n + 1) <= 2**30
    assert default_max_iter(278) == 50 * 278
    assert default_max_iter(1000) == 50000


def test_the_default_pivot_limit_stops_an_exponential_run():
    inst = murty(11)
    res = solve_lcp(inst.M, inst.q, max_iter=default_max_iter(9))
    assert res.status == MAX_ITER and res.pivots == 1024


def test_pivot_limit_gives_max_iter_with_a_finite_point():
    inst = murty(10)
    res = solve_lcp(inst.M, inst.q, max_iter=100)
    assert res.status == MAX_ITER
    assert not res.success
    assert res.pivots == 100
    assert np.all(np.isfinite(res.z)) and np.all(res.z >= 0)
    np.testing.assert_allclose(res.w, inst.M @ res.z + inst.q)
    assert "max_iter" in res.message


def test_cycling_example_is_solved_by_the_lexicographic_rule():
    M = np.array([[1.0, 2, 0], [0, 1, 2], [2, 0, 1]])
    res = solve_lcp(M, -np.ones(3))
    assert res.success
    np.testing.assert_allclose(res.z, np.full(3, 1 / 3), atol=1e-15)
    assert res.pivots <= 8


def test_cps_4_4_16_takes_the_z0_tie_and_returns_0_1():
    res = solve_lcp(np.array([[1.0, -1], [-1, 1]]), np.array([1.0, -1]))
    assert res.success
    np.testing.assert_array_equal(res.z, [0.0, 1.0])
    assert res.pivots == 2


def test_no_solution_ends_on_a_secondary_ray_with_a_certificate():
    M = np.array([[-1.0]])
    q = np.array([-1.0])
    res = solve_lcp(M, q)
    # M = -1 is not copositive, but the ray is a Farkas vector by itself
    assert res.status == INFEASIBLE and not res.success
    assert "ray" in res.message and "Farkas" in res.message
    assert res.certificate.tolist() == [1.0]
    assert np.isfinite(res.residual) and res.residual > 0.1
    dz, dz0 = res.ray[:1], res.ray[1]
    # along (dz, dz0) the augmented w = M z + q + d z0 keeps its value
    np.testing.assert_allclose(M @ dz + dz0, 0.0)
    assert np.all(dz >= 0) and dz0 >= 0 and np.any(dz > 0)


def test_secondary_ray_direction_is_feasible_for_the_augmented_problem():
    # Murty (1988) ex. 2.9: z + t dz, z0 + t dz0 stays feasible for all t >= 0
    M = np.array([[-1.0, 0, -3], [1, -2, -5], [-2, -1, -2]])
    q = np.array([-3.0, -2, -1])
    res = solve_lcp(M, q)
    # row 1 reads w1 = -z1 - 3 z3 - 3 < 0: infeasible, and the ray says so
    assert res.status == INFEASIBLE
    assert_farkas(M, q, res.certificate)
    dz, dz0 = res.ray[:3], res.ray[3]
    assert np.all(dz >= -1e-12) and dz0 >= -1e-12
    dw = M @ dz + dz0 * np.ones(3)
    assert np.all(dw >= -1e-12)
    assert abs(dz @ dw) <= 1e-12


def test_covering_vector_changes_the_path():
    # Murty (1988) ex. 2.11: with d = (5, 16) Lemke ends on a ray, with d = 1 it solves
    M = np.array([[-1.5, 2], [-4, 4]])
    q = np.array([-5.0, 17])
    assert solve_lcp(M, q, covering=np.array([5.0, 16.0])).status == SECONDARY_RAY
    ray = solve_lcp(M, q, covering=np.array([5.0, 16.0]))
    # M is not copositive-plus and the ray is no Farkas vector: no claim of infeasibility
    assert ray.certificate is None and "proves nothing" in ray.message
    res = solve_lcp(M, q)
    assert res.success
    assert_complementary(M, q, res.z, 1e-12)


def test_q_nonnegative_returns_at_once():
    M = np.array([[1.0, 5.0], [-3.0, 2.0]])
    q = np.array([0.0, 2.0])
    res = solve_lcp(M, q)
    assert res.success and res.pivots == 0
    np.testing.assert_array_equal(res.z, [0.0, 0.0])
    np.testing.assert_array_equal(res.w, q)


def test_empty_problem():
    res = solve_lcp(np.zeros((0, 0)), np.zeros(0))
    assert res.success and res.z.shape == (0,) and res.pivots == 0


@pytest.mark.parametrize("s", [1e-9, 1e-3, 1e3, 1e9])
def test_scale_invariance(s):
    rng = np.random.default_rng(3)
    M = random_p_matrix(30, rng)
    q = rng.standard_normal(30)
    ref = solve_lcp(M, q)
    both = solve_lcp(s * M, s * q)  # same z
    only_q = solve_lcp(M, s * q)  # z scales with q
    only_m = solve_lcp(s * M, q)  # z scales with 1/s
    for res in (both, only_q, only_m):
        assert res.success
    assert both.pivots == ref.pivots == only_q.pivots == only_m.pivots
    np.testing.assert_allclose(both.z, ref.z, rtol=1e-10, atol=1e-12 * np.max(ref.z))
    np.testing.assert_allclose(only_q.z, s * ref.z, rtol=1e-10, atol=1e-12 * s * np.max(ref.z))
    np.testing.assert_allclose(only_m.z, ref.z / s, rtol=1e-10, atol=1e-12 * np.max(ref.z) / s)


def test_a_solution_that_fails_the_check_is_not_reported_solved():
    rng = np.random.default_rng(0)
    M = random_p_matrix(40, rng)
    q = rng.standard_normal(40)
    assert solve_lcp(M, q).residual > 1e-30  # rounding is there
    res = solve_lcp(M, q, tol=1e-30)
    assert res.status == BREAKDOWN and not res.success
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w))
    assert "residual" in res.message


def test_result_fields_and_check():
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    q = np.array([-1.0, 1.0])
    res = solve_lcp(M, q)
    assert res.method == "lemke" and res.path == ("lemke",) and not res.fallback_used
    assert res.ray is None
    assert res.message == "Solution found."
    assert res.check(M, q)
    assert not res.check(M, q + np.array([0.0, -5.0]))
    assert "LCPResult(status=0" in repr(res)
    # the residual is the certified violation: the exact one plus the rounding bound of w
    assert res.residual == pytest.approx(lcp_violation(M, q, res.z), abs=1e-16)
    assert lcp_residual(M, q, res.z) <= res.residual <= 1e-14


def test_lean_path_gives_the_same_answer_and_still_rejects_nan():
    rng = np.random.default_rng(5)
    M = random_p_matrix(12, rng)
    q = rng.standard_normal(12)
    a = solve_lcp(M, q)
    b = solve_lcp(M, q, check_input=False)
    np.testing.assert_array_equal(a.z, b.z)
    q[3] = np.nan
    with pytest.raises(InputError, match="`q` must contain only finite values"):
        solve_lcp(M, q, check_input=False)


# -- bad input ---------------------------------------------------------------

@pytest.mark.parametrize("method", ["lemke", "qp", "auto"])
def test_bad_input_raises_clear_errors(method):
    good = np.eye(3)
    q = -np.ones(3)
    with pytest.raises(InputError, match=r"`M` must be square, got shape \(3, 2\)"):
        solve_lcp(np.ones((3, 2)), q, method=method)
    with pytest.raises(InputError, match="`q` must have length 3 to match `M`, got 2"):
        solve_lcp(good, -np.ones(2), method=method)
    with pytest.raises(InputError, match="`M` must be a square 2-D array"):
        solve_lcp(np.ones(3), q, method=method)
    with pytest.raises(InputError, match="`q` must be a 1-D array"):
        solve_lcp(good, np.ones((3, 1)), method=method)
    bad = good.copy()
    bad[1, 2] = np.nan
    with pytest.raises(InputError, match="`M` must contain only finite values"):
        solve_lcp(bad, q, method=method)
    bad[1, 2] = np.inf
    with pytest.raises(InputError, match="`M` must contain only finite values"):
        solve_lcp(bad, q, method=method)
    with pytest.raises(InputError, match="`q` must contain only finite values"):
        solve_lcp(good, np.array([-1.0, -np.inf, 0.0]), method=method)
    with pytest.raises(InputError, match="`M` must be an array of real numbers"):
        solve_lcp([["a", "b"], ["c", "d"]], [1.0, 1.0], method=method)
    with pytest.raises(InputError, match="`max_iter` must be an integer >= 1"):
        solve_lcp(good, q, method=method, max_iter=0)
    with pytest.raises(InputError, match="`tol` must be > 0"):
        solve_lcp(good, q, method=method, tol=-1.0)


def test_errors_are_value_errors_and_moreau_errors():
    with pytest.raises(ValueError):
        solve_lcp(np.ones((2, 3)), np.ones(2))
    with pytest.raises(MoreauError):
        solve_lcp(np.ones((2, 3)), np.ones(2))


def test_unknown_method_lists_the_known_ones():
    with pytest.raises(InputError, match="`method` must be one of 'auto', 'lemke', 'qp'; got 'pgs'"):
        solve_lcp(np.eye(2), np.ones(2), method="pgs")


def test_bad_covering_vector():
    with pytest.raises(InputError, match="`covering` must be strictly positive"):
        solve_lcp(np.eye(2), -np.ones(2), covering=np.array([1.0, 0.0]))
    with pytest.raises(InputError, match="`covering` must have length 2"):
        solve_lcp(np.eye(2), -np.ones(2), covering=np.ones(3))


# -- the compiled kernel -------------------------------------------------------

@njit(cache=True)
def _many_small_lcps(Ms, qs, zs, ws, max_iter):
    # what a compiled time stepper does: many LCPs, no Python per pivot. max_iter is an
    # argument, as in the steppers: a constant 1000 would be typed as a literal and make
    # lemke_kernel a specialisation of its own, compiled again for the calls from Python
    n = qs.shape[1]
    statuses = np.empty(qs.shape[0], dtype=np.int64)
    d = np.ones(n)
    ray = np.empty(n + 1)
    work, iwork = lemke_workspace(n)
    for k in range(qs.shape[0]):
        if k % 2 == 0:
            st, piv, res = lemke_kernel(Ms[k], qs[k], zs[k], ws[k], max_iter, 1e-9)
        else:
            st, piv, res = lemke_core(Ms[k], qs[k], d, zs[k], ws[k], ray, work, iwork, max_iter,
                                      1e-9)
        statuses[k] = st
    return statuses


def test_kernel_is_callable_from_compiled_code():
    rng = np.random.default_rng(11)
    K, n = 20, 6
    Ms = np.stack([random_p_matrix(n, rng) for _ in range(K)])
    qs = rng.standard_normal((K, n))
    zs = np.empty((K, n))
    ws = np.empty((K, n))
    st = _many_small_lcps(Ms, qs, zs, ws, 1000)
    assert np.all(st == SOLVED)
    for k in range(K):
        ref = solve_lcp(Ms[k], qs[k])
        np.testing.assert_allclose(zs[k], ref.z, atol=1e-14)
        np.testing.assert_allclose(ws[k], Ms[k] @ zs[k] + qs[k], atol=1e-14)


def test_core_on_a_long_path_leaves_the_ray_zero_and_the_solution_exact():
    # Murty's order 6: 2^6 = 64 pivots, past the 2 n + 16 after which the visited
    # bases are hashed (the compiled path hands over to allocate the set and goes
    # on); the solution (0, ..., 0, z_n) and a ray output that stays zero
    inst = murty(6)
    n = 6
    z = np.full(n, 7.0)
    w = np.full(n, 7.0)
    ray = np.full(n + 1, 7.0)
    work, iwork = lemke_workspace(n)
    st, piv, res = lemke_core(inst.M, inst.q, np.ones(n), z, w, ray, work, iwork, 1000, 1e-9)
    assert (st, piv) == (SOLVED, 2**n)
    np.testing.assert_array_equal(z, inst.z)
    np.testing.assert_array_equal(ray, 0.0)
    # with a pivot limit inside the watched part: MAX_ITER at the limit, the ray zero
    st, piv, _ = lemke_core(inst.M, inst.q, np.ones(n), z, w, ray, work, iwork, 40, 1e-9)
    assert (st, piv) == (MAX_ITER, 40)
    np.testing.assert_array_equal(ray, 0.0)


def test_kernel_reports_invalid_input_as_a_status():
    M = np.eye(2)
    q = np.array([-1.0, np.nan])
    z = np.full(2, 7.0)
    w = np.full(2, 7.0)
    st, piv, res = lemke_kernel(M, q, z, w, 100, 1e-9)
    assert st == INVALID_INPUT and piv == 0 and res == np.inf
    np.testing.assert_array_equal(z, 0.0)
    d = np.array([1.0, -1.0])
    work, iwork = lemke_workspace(2)
    st, _, _ = lemke_core(M, -np.ones(2), d, z, w, np.empty(3), work, iwork, 100, 1e-9)
    assert st == INVALID_INPUT
    small = np.empty((2, 2))
    st, _, _ = lemke_core(M, -np.ones(2), np.ones(2), z, w, np.empty(3), small, iwork, 100, 1e-9)
    assert st == INVALID_INPUT


def test_kernel_and_python_wrapper_agree_on_pivots():
    rng = np.random.default_rng(2)
    for n in (2, 7, 33):
        M = random_p_matrix(n, rng)
        q = rng.standard_normal(n)
        z = np.empty(n)
        w = np.empty(n)
        st, piv, res = lemke_kernel(M, q, z, w, 10000, 1e-9)
        ref = solve_lcp(M, q)
        assert st == ref.status == SOLVED
        assert piv == ref.pivots
        assert res == pytest.approx(ref.residual, abs=1e-18)


def test_badly_scaled_triangular_p_matrix_is_not_cut_off_by_the_pivot_tolerance():
    # z_k = 17^(k-1): the pivot column spans eleven orders of magnitude and
    # a column-relative cut-off would end on a false secondary ray
    n = 10
    M = np.eye(n) - 16.0 * np.tril(np.ones((n, n)), -1)
    res = solve_lcp(M, -np.ones(n))
    assert res.success
    np.testing.assert_allclose(res.z, 17.0 ** np.arange(n), rtol=1e-12)


def test_an_exact_zero_left_by_rounding_is_not_taken_as_a_pivot():
    # copositive-plus (symmetric part PSD) and infeasible: y = (1, 1, 0).
    # After four pivots w_2 enters with the entry 5.55e-17 where exact
    # arithmetic has 0; pivoting on it ran z to 4.5e15 and broke down.
    M = np.array([[0.25, -0.25, -2.0], [-0.25, 0.25, 0.0], [2.0, 0.0, 1.0]])
    q = np.array([-0.5, -0.5, -1.0])
    res = solve_lcp(M, q)
    assert res.status == INFEASIBLE and res.pivots == 4
    assert_farkas(M, q, res.certificate)


def test_subnormal_data_are_pivoted_at_unit_scale():
    # entries 2^-1070: without rescaling the tableau keeps a few bits
    M = np.ldexp(np.array([[2.0, 1.0], [1.0, 2.0]]), -1070)
    q = np.ldexp(np.array([-1.0, 1.0]), -1000)
    res = solve_lcp(M, q)
    assert res.success
    np.testing.assert_array_equal(res.z, [2.0**69, 0.0])
    M = 5e-324 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    res = solve_lcp(M, np.array([-0.01, -0.01]))
    assert res.status == INFEASIBLE
    np.testing.assert_array_equal(res.certificate, [1.0, 1.0])
    assert np.all(np.isfinite(res.ray))


def test_an_answer_beyond_the_range_of_doubles_is_a_breakdown_not_a_nan():
    M = 1e-310 * np.array([[2.0, 1.0], [1.0, 2.0]])
    res = solve_lcp(M, np.array([-1.0, 1.0]))  # z1 = 5e309
    assert res.status == BREAKDOWN
    assert np.all(np.isfinite(res.z)) and np.all(np.isfinite(res.w)) and np.isfinite(res.residual)


def test_fortran_ordered_and_strided_matrices_reuse_the_c_ordered_compile():
    # a transposed or fancy-indexed matrix (Fortran order) or a strided one is copied to C
    # order at the entry: numba would otherwise compile the whole solver again for its
    # layout (23 CPU s on a cold cache); the same arithmetic, so the same bits
    from moreau.lcp import lemke
    rng = np.random.default_rng(3)
    M = random_p_matrix(6, rng)
    q = rng.standard_normal(6)
    ref = solve_lcp(M, q)
    for other in (np.asfortranarray(M), np.repeat(M, 2, axis=1)[:, ::2]):
        assert not other.flags.c_contiguous
        res = solve_lcp(other, q)
        assert res.success and ref.success
        np.testing.assert_array_equal(res.z, ref.z)
    layouts = {sig[0].layout for sig in lemke._solve_packed.signatures}
    assert layouts == {"C"}, layouts
