"""The compiled exact decisions of Lemke's path (moreau.lcp._modular) against Python's integers.

:func:`~moreau.lcp._modular.modular_step` must take the step that
:func:`~moreau.lcp._exact.exact_step` takes (same leaving variable, same ray,
same refusals) and mark exactly the zero right-hand sides after it;
:func:`~moreau.lcp._modular.exact_point` must give the bits of
:func:`~moreau.lcp._exact.basis_point`, with its float filter and without.
The data are integers times 1/10 or 1/3 (not dyadic), so that the exact zeros
and ties of the elimination come out of floating point as rounding noise:
the filter must leave those to the residues.
"""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from moreau.lcp._exact import basis_point, exact_step
from moreau.lcp._modular import (
    STEP_PIVOT,
    STEP_RAY,
    STEP_REFUSED,
    exact_point,
    modular_step,
    primes,
)

from .exact_reference import reference_lemke

P = primes()


@st.composite
def noisy_degenerate(draw):
    # repeated rows and columns, q with many zeros, entries k / 10 or k / 3
    rng = np.random.default_rng(draw(st.integers(0, 2**63 - 1)))
    n = draw(st.integers(3, 9))
    f = draw(st.sampled_from([0.1, 1.0 / 3.0]))
    k = draw(st.integers(2, 4))
    base = rng.integers(-3, 4, (k, k)).astype(float)
    M = base[rng.integers(0, k, n)][:, rng.integers(0, k, n)] + np.diag(rng.integers(0, 3, n))
    q = rng.integers(-2, 3, n).astype(float)
    q[rng.random(n) < 0.5] = 0.0
    if q.min() >= 0.0:
        q[0] = -1.0
    return M * f, q * f


def _agrees(M, q, rows, entering):
    n = len(q)
    ref = exact_step(M, q, np.ones(n), rows, entering)
    flags = np.empty(n)
    outcome, leaving = modular_step(M, q, np.ones(n), np.array(rows, dtype=np.int64), entering,
                                    P, flags)
    if ref is None:
        assert outcome == STEP_REFUSED
        return
    kind, left, b = ref
    assert (outcome, leaving) == ((STEP_RAY, -1) if kind == "ray" else (STEP_PIVOT, left))
    # 0.0 exactly where the exact right-hand side is zero, NaN (positive) elsewhere
    assert [v == 0.0 for v in b] == [x == 0.0 for x in flags]
    assert all(v > 0.0 for v, x in zip(b, flags) if x != 0.0)


@settings(max_examples=30, deadline=None, derandomize=False,
          suppress_health_check=[HealthCheck.too_slow])
@given(noisy_degenerate())
def test_modular_step_takes_each_step_of_the_exact_path_on_noisy_data(prob):
    M, q = prob
    trace = []
    reference_lemke(M, q, max_iter=60, trace=trace)
    for rows, entering, _, _ in trace:
        _agrees(M, q, rows, entering)


@settings(max_examples=30, deadline=None, derandomize=False,
          suppress_health_check=[HealthCheck.too_slow])
@given(noisy_degenerate(), st.integers(0, 2**32 - 1))
def test_modular_step_refuses_where_the_integers_do(prob, seed):
    # random almost-complementary bases: most are infeasible or not
    # lexicographically positive, some singular; the verdicts must agree
    M, q = prob
    n = len(q)
    rng = np.random.default_rng(seed)
    for _ in range(4):
        rows = [int(n + j if rng.random() < 0.4 else j) for j in range(n)]
        rows[int(rng.integers(n))] = 2 * n
        free = [v for v in range(2 * n) if v not in rows]
        _agrees(M, q, rows, int(rng.choice(free)))


@settings(max_examples=40, deadline=None, derandomize=False)
@given(noisy_degenerate(), st.integers(0, 2**32 - 1))
def test_exact_point_has_the_bits_of_the_rational_point(prob, seed):
    M, q = prob
    n = len(q)
    rng = np.random.default_rng(seed)
    J = np.sort(rng.choice(n, int(rng.integers(1, n + 1)), replace=False)).astype(np.int64)
    ref = basis_point(M, q, J.tolist())
    try:
        guess = np.zeros(n)
        guess[J] = np.linalg.solve(M[np.ix_(J, J)], -q[J])
    except np.linalg.LinAlgError:
        guess = np.zeros(n)
    if not np.isfinite(guess).all():
        guess = np.zeros(n)
    for use_filter in (True, False):
        z = guess.copy()
        if exact_point(M, q, J, P, z, use_filter):
            assert ref is not None
            # the same floats, signed zeros included
            assert [(v, np.signbit(v)) for v in ref] == [(v, np.signbit(v)) for v in z]
        else:
            # undecided only where the guess is far off (singular or
            # ill-conditioned blocks): z untouched
            assert np.array_equal(z, guess)


def test_exact_point_breaks_a_tie_to_even():
    # x1 + x2 = 2^53, x1 - x2 = 1: x1 = 2^52 + 1/2 lies halfway between two
    # floats (no filter can decide it) and rounds to the even 2^52; x2 = 2^52 - 1/2
    M = np.array([[1.0, 1.0], [1.0, -1.0]])
    q = -np.array([2.0**53, 1.0])
    ref = basis_point(M, q, [0, 1])
    assert ref == [2.0**52, 2.0**52 - 0.5]
    for use_filter in (True, False):
        z = np.array([2.0**52 + 1.0, 2.0**52])
        assert exact_point(M, q, np.array([0, 1]), P, z, use_filter)
        assert z.tolist() == ref


def test_noise_is_left_to_the_residues():
    # the n = 40 problem that cycled: its float tableau shows exact zeros as
    # 1e-15 noise; the compiled step decides each of the exact path's steps
    from .test_lemke_exact import degenerate_40
    M, q = degenerate_40()
    trace = []
    reference_lemke(M, q, trace=trace)
    assert len(trace) >= 20
    for rows, entering, _, _ in trace:
        _agrees(M, q, rows, entering)
