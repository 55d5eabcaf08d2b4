"""Issue 33: Lemke on highly degenerate problems follows the exact lexicographic path.

Every case is run through ``solve_lcp(M, q, "lemke")`` and through the
textbook exact-rational Lemke of :mod:`tests.lcp.exact_reference` (explicit
``B^-1`` in fractions, covering vector of ones, lexicographic ratio test).
Asserted on each:

* the float Lemke never stops at its pivot limit where the exact one ends;
* it ends the same way (solution, or a ray: ``SECONDARY_RAY`` or a proven
  ``INFEASIBLE``), at the same point when the exact terminal basis is
  nondegenerate (then the point determines the basis); the one exception
  allowed: ``z0`` leaving on a tie within rounding of its ratio where the
  exact path pivots on, which gives a solution up to rounding (certified
  here) where the exact path may end on a ray;
* its pivot count is within ``PIVOT_SLACK`` of the exact count.

The families (Hypothesis draws the sizes, the knobs and a seed; numpy fills
the arrays): integers, times 1, 1/2 or 3/8, stored exactly, so that a tie of
the problem as meant is a tie of the floats too, while the eliminations
(pivots of 3, 5, 7, ...) make rounding noise of their exact zeros. With
non-dyadic data (0.1, 1/3) the stored floats differ from the problem meant
by 1e-17, and the exact path of the floats is decided by that difference,
which no floating-point pivoting can see: there the float path may end
elsewhere after a tie that rounding shows as exact (about 1 case in 500 in
``benchmarks/lcp_degenerate.py``), though never at the pivot limit (the
n = 40 case below is such data):

* ``q_zeros``: integer ``M``, ``q`` with 50-90 % zeros;
* ``repeated``: ``M`` built from 2-4 distinct integer rows and columns;
* ``ties``: ``q_i = -1`` on a set ``G`` of 6-11 rows and ``M_ir < M_rr`` for
  ``r = max G``: after ``z0`` enters at row ``r``, ``z_r`` enters with the
  other rows of ``G`` all at ratio 0, a 5-10-row tie (asserted);
* ``bimatrix``: ``M = [[0, A], [B^T, 0]]``, ``q = -1``, integer payoffs of
  both signs with repeated rows;
* ``zmatrix``: ``M = s I - B``, ``B >= 0`` integer (the Z-matrices of
  Chandrasekaran's method), ``q`` with zeros;
* Murty's exponential examples (``2^n`` pivots).
"""

import time
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from moreau.lcp import INFEASIBLE, MAX_ITER, SECONDARY_RAY, solve_lcp
from moreau.lcp.instances import murty
from moreau.lcp._exact import _column_ints, exact_step
from moreau.lcp.lemke import lemke_core, lemke_workspace

from .conftest import assert_certified
from .exact_reference import reference_lemke

#: the float pivot count may differ from the exact one by this much: only
#: where a hand-over to the exact path had to start afresh
PIVOT_SLACK = 3
EXAMPLES = 40


def _settings():
    return settings(max_examples=EXAMPLES, deadline=None, derandomize=False,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def _rng_factor(draw):
    rng = np.random.default_rng(draw(st.integers(0, 2**63 - 1)))
    return rng, draw(st.sampled_from([1.0, 0.5, 0.375]))


def _q(rng, n, zeros, factor):
    q = rng.integers(-2, 3, n).astype(float)
    q[rng.random(n) < zeros] = 0.0
    if q.min() >= 0.0:
        q[rng.integers(n)] = -1.0
    return q * factor


@st.composite
def q_zeros(draw):
    rng, f = draw(_rng_factor())
    n = draw(st.integers(3, 10))
    M = rng.integers(-3, 4, (n, n)).astype(float) * f
    return M, _q(rng, n, draw(st.sampled_from([0.5, 0.7, 0.9])), f)


@st.composite
def repeated(draw):
    rng, f = draw(_rng_factor())
    n = draw(st.integers(3, 12))
    k = draw(st.integers(2, 4))
    base = rng.integers(-3, 4, (k, k)).astype(float)
    M = base[rng.integers(0, k, n)][:, rng.integers(0, k, n)]
    if draw(st.booleans()):
        M = M + np.diag(rng.integers(0, 3, n))
    return M * f, _q(rng, n, 0.6, f)


@st.composite
def ties(draw):
    rng, f = draw(_rng_factor())
    n = draw(st.integers(6, 12))
    g = draw(st.integers(6, min(11, n)))
    G = np.sort(rng.choice(n, g, replace=False))
    r = G[-1]
    M = rng.integers(-3, 4, (n, n)).astype(float)
    M[r, r] = 4.0  # above every other entry of column r: each row of G has a_i > 0
    q = rng.integers(0, 3, n).astype(float)
    q[G] = -1.0
    return M * f, q * f


@st.composite
def bimatrix(draw):
    rng, f = draw(_rng_factor())
    m = draw(st.integers(1, 5))
    k = draw(st.integers(1, 5))
    # payoffs of both signs: with costs > 0 Lemke (covering ones) ends on a ray
    # at its second pivot on every game, which would test nothing here
    A = rng.integers(-3, 7, (m, k)).astype(float)
    B = rng.integers(-3, 7, (m, k)).astype(float)
    A = A[rng.integers(0, m, m)]
    B = B[:, rng.integers(0, k, k)]
    M = np.zeros((m + k, m + k))
    M[:m, m:] = A
    M[m:, :m] = B.T
    return M * f, -np.ones(m + k)


@st.composite
def zmatrix(draw):
    rng, f = draw(_rng_factor())
    n = draw(st.integers(3, 10))
    B = rng.integers(0, 3, (n, n)).astype(float)
    np.fill_diagonal(B, 0.0)
    s = float(draw(st.integers(0, 6)))
    return (s * np.eye(n) - B) * f, _q(rng, n, 0.5, f)


def _nondegenerate_point(M, q, z):
    # the exact terminal point determines the basis when no basic variable is 0:
    # then z_i > 0 or w_i > 0 for every i (z, w in exact arithmetic)
    from fractions import Fraction
    n = len(q)
    for i in range(n):
        wi = Fraction(float(q[i])) + sum(Fraction(float(M[i, j])) * z[j] for j in range(n) if z[j])
        if z[i] == 0 and wi == 0:
            return False
    return True


def check_against_exact(M, q):
    status, basis, pivots, z, max_ties = reference_lemke(M, q)
    res = solve_lcp(M, q, max_iter=10**5)
    assert status != "max_iter"
    assert res.status != MAX_ITER, f"float Lemke hit its pivot limit; exact ends ({status}) in {pivots}"
    if status == "solved":
        assert res.success, f"exact solves in {pivots} pivots; float: {res.message}"
        if _nondegenerate_point(M, q, z):
            ze = np.array([float(v) for v in z])
            np.testing.assert_allclose(res.z, ze, rtol=1e-9, atol=1e-12 * max(1.0, np.max(ze)))
    elif res.success:
        # z0 left on a tie within rounding of its ratio where the exact path
        # pivots on (and ends on a ray): a solution up to rounding, certified
        assert_certified(M, q, res.z, 1e-9)
        return status, pivots, res, max_ties, z
    else:
        assert res.status in (SECONDARY_RAY, INFEASIBLE), res.message
    assert abs(res.pivots - pivots) <= PIVOT_SLACK, (res.pivots, pivots, res.message)
    return status, pivots, res, max_ties, z


@_settings()
@given(q_zeros())
def test_q_with_many_zeros_follows_the_exact_path(prob):
    check_against_exact(*prob)


@_settings()
@given(repeated())
def test_repeated_rows_and_columns_follow_the_exact_path(prob):
    check_against_exact(*prob)


@_settings()
@given(ties())
def test_five_to_ten_rows_tied_at_an_entering_step_follow_the_exact_path(prob):
    _, _, _, max_ties, _ = check_against_exact(*prob)
    assert 5 <= max_ties, "the family must tie 5-10 rows"


@_settings()
@given(bimatrix())
def test_bimatrix_games_follow_the_exact_path(prob):
    check_against_exact(*prob)


@_settings()
@given(zmatrix())
def test_z_matrices_follow_the_exact_path(prob):
    check_against_exact(*prob)


@_settings()
@given(st.one_of(ties(), q_zeros(), bimatrix()))
def test_exact_step_takes_each_step_of_the_reference_path(prob):
    # the hand-over's exact step (B^-1 from the k x k block of the non-w basic
    # variables) against the reference's explicit B^-1, at every step of its
    # path: the same leaving variable (or the ray), and the right-hand side
    # after the step correctly rounded
    M, q = prob
    n = len(q)
    trace = []
    reference_lemke(M, q, trace=trace)
    for rows, entering, leaving, b in trace:
        kind, left, bx = exact_step(M, q, np.ones(n), rows, entering)
        assert (kind, left) == (("ray", None) if leaving is None else ("pivot", leaving))
        assert bx == [float(v) for v in b]


@settings(deadline=None, max_examples=50)
@given(st.sampled_from(["one scale", "any"]).flatmap(lambda kind: st.lists(
    st.integers(-40, 40).map(lambda k: k / 10) if kind == "one scale"
    else st.floats(allow_nan=False, allow_infinity=False), min_size=1, max_size=12)),
    st.integers(1, 3))
def test_column_ints_are_the_data_times_one_power_of_two(vals, rows):
    # data of one scale take the int64 shortcut, the others Python integers: either
    # way each entry is an integer a with a / 2^K equal to the float exactly
    F = np.array(vals * rows, dtype=float).reshape(rows, len(vals))
    ints, K = _column_ints(F)
    for row, frow in zip(ints, F):
        assert [type(a) for a in row] == [int] * len(row)
        assert [Fraction(a, 1 << K) for a in row] == [Fraction(float(x)) for x in frow]


def test_exact_step_refuses_a_basis_that_is_not_lexicographically_positive():
    # w_0 = -1 + 2 z_0 + t, w_1 = -1 + z_1 + t (t = z0, d = 1). With t basic in
    # row 1 (the first pivot's choice), w_0 = 0 - 2 z_0 ... has b_0 = 0 and
    # B^-1 row (1, -1): lexicographically positive. With t in row 0 instead,
    # w_1 has b_1 = 0 and B^-1 row (-1, 1): negative, no exact step from there
    M = np.array([[2.0, 0.0], [0.0, 1.0]])
    q = np.array([-1.0, -1.0])
    assert exact_step(M, q, np.ones(2), [0, 4], 3) is not None
    assert exact_step(M, q, np.ones(2), [4, 1], 2) is None
    # a right-hand side below zero: not a feasible basis at all
    assert exact_step(M, np.array([-1.0, -2.0]), np.ones(2), [4, 1], 2) is None


@pytest.mark.parametrize("n", [2, 3, 5, 7])
def test_murty_follows_the_exact_path(n):
    inst = murty(n)
    status, pivots, _, _, _ = check_against_exact(inst.M, inst.q)
    assert status == "solved" and pivots == 2**n


def degenerate_40(seed=636, n=40):
    """A degenerate n = 40 LCP on which the former kernel cycled to its pivot limit.

    Few distinct rows and columns (multiples of 0.1, so that exact zeros of
    the elimination come out as rounding noise) plus a sparse perturbation,
    a positive diagonal, ``q`` 60 % zeros. The former kernel let noise of
    1e-15 decide a lexicographic tie and repeated a basis; it stopped at its
    limit of 654 720 pivots. Exact Lemke solves it in 25.
    """
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 12))
    base = rng.integers(-1, 4, (k, k)).astype(float) * 0.1
    M = base[rng.integers(0, k, n)][:, rng.integers(0, k, n)] + rng.integers(0, 3, (n, n)) * 0.1
    M[np.diag_indices(n)] = np.abs(M[np.diag_indices(n)]) + 0.1
    q = rng.integers(-2, 3, n).astype(float)
    q[rng.random(n) < 0.6] = 0.0
    q[0] = -1.0
    return M, q


def test_degenerate_n40_that_cycled_is_solved_on_the_exact_path():
    M, q = degenerate_40()
    status, pivots, _, _, _ = check_against_exact(M, q)
    assert status == "solved" and pivots == 25
    res = solve_lcp(M, q)
    assert res.success and res.pivots == 25
    # the compiled entry (time steppers) has no exact path: it counts noise as a
    # tie and stops on a repeated basis, never running to its pivot limit
    n = len(q)
    work, iwork = lemke_workspace(n)
    z_out, w_out, ray = np.zeros(n), np.zeros(n), np.zeros(n + 1)
    st_, piv, _ = lemke_core(M, q, np.ones(n), z_out, w_out, ray, work, iwork, 10**6, 1e-9)
    assert st_ != MAX_ITER and piv < 1000


def test_the_compiled_exact_walk_is_the_whole_tableau_s_path():
    # _exact_finish walks a path of n >= 33 one exact step at a time (the k x k block of
    # the basis's z variables, compiled) instead of pivoting the whole tableau of Python
    # integers (1.6 s a pivot at n = 650): the same pivots, the same end, the same point
    # (correctly rounded) and ray on these degenerate problems (n = 33 .. 40)
    from moreau.lcp._exact import exact_lemke
    from moreau.lcp.lemke import _exact_walk
    def zmat(seed, n=34):
        # s I - B, B >= 0 integer: a secondary ray after 21 to 38 pivots for these seeds
        rng = np.random.default_rng(seed)
        B = rng.integers(0, 3, (n, n)).astype(float)
        np.fill_diagonal(B, 0.0)
        q = rng.integers(-2, 3, n).astype(float)
        q[rng.random(n) < 0.5] = 0.0
        q[0] = -1.0
        return (float(seed % 4) * np.eye(n) - B) * 0.5, q

    ends = set()
    for seed in (0, 1, 2, 3, 8, 9, 10):
        # degenerate_40's family at n = 33-36 (solved in 3 to 7 pivots), then rays
        M, q = degenerate_40(seed, 33 + seed) if seed < 4 else zmat(seed)
        st_a, z_a, ray_a, piv_a, _ = exact_lemke(M, q)
        st_b, z_b, ray_b, piv_b, resumed = _exact_walk(M, q, None, None, None, 10**6, 0,
                                                        time.process_time() + 60.0)
        assert (st_b, piv_b, resumed) == (st_a, piv_a, False)
        assert [float(v) for v in z_b] == [float(v) for v in z_a]
        if st_a == 1:
            assert [float(v) for v in ray_b] == [float(v) for v in ray_a]
        ends.add(st_a)
    assert ends == {0, 1}                                   # solutions and rays both met


def test_a_spent_exact_arithmetic_budget_is_a_pivot_limit_that_names_it(monkeypatch):
    # a problem whose path is finished in exact arithmetic (found among degenerate_40's
    # family at n = 6; 8 pivots), with no time left: no answer, said so, and "auto"
    # goes on to its fallback
    from moreau.lcp import lemke
    from moreau.lcp.lemke import _exact_walk
    M, q = degenerate_40(25, 6)
    res = solve_lcp(M, q)
    assert res.success and res.pivots == 8 and "finished in exact arithmetic" in res.detail
    monkeypatch.setattr(lemke, "EXACT_TIME_BUDGET", -1.0)
    spent = solve_lcp(M, q)
    assert spent.status == MAX_ITER and not spent.success
    assert "stopped at its time budget (-1 CPU s, moreau.lcp.lemke.EXACT_TIME_BUDGET)" \
        in spent.detail
    np.testing.assert_array_equal(spent.z, 0.0)
    np.testing.assert_array_equal(spent.w, q)
    auto = solve_lcp(M, q, "auto")
    assert auto.path[-1] == "qp" and "Lemke first" in auto.detail
    # the walk (n >= 33) stops at the deadline too, before its first pivot
    M, q = degenerate_40(0, 40)
    st_, z, _, piv, _ = _exact_walk(M, q, None, None, None, 10**6, 0, time.process_time() - 1.0)
    assert st_ == 3 and z is None and piv == 1
