"""The primal-dual active-set LCP solver on sparse M-matrices, against Lemke."""

import numpy as np
import pytest
import scipy.sparse as sps

from moreau.errors import InputError, LCPError
from moreau.lcp import solve_lcp
from moreau.lcp.active_set import solve_active_set


def _chain_delassus(m):
    # WN M^-1 WN^T of balls of masses m on a line: tridiagonal, off-diagonal -1/m_{i+1}
    d = 1.0 / m[:-1] + 1.0 / m[1:]
    off = -1.0 / m[1:-1]
    return sps.diags_array([off, d, off], offsets=[-1, 0, 1], format="csr")


def _random_m_matrix(rng, n):
    # nonpositive off-diagonal entries, strictly diagonally dominant: a nonsingular M-matrix
    B = sps.random_array((n, n), density=0.15, rng=rng).toarray()
    np.fill_diagonal(B, 0.0)
    return sps.csr_array(np.diag(B.sum(axis=1) + rng.uniform(0.1, 1.0, n)) - B)


@pytest.mark.parametrize("seed", range(6))
def test_matches_lemke_on_m_matrices(seed):
    rng = np.random.default_rng(seed)
    n = 40
    A = _chain_delassus(rng.uniform(0.2, 5.0, n + 1)) if seed % 2 else _random_m_matrix(rng, n)
    q = rng.uniform(-1.0, 1.0, n)
    z, residual, solves = solve_active_set(A, q)
    ref = solve_lcp(A.toarray(), q, method="lemke")
    assert ref.success
    assert z == pytest.approx(ref.z, abs=1e-12)
    # the residual reported is the natural map recomputed here
    w = A @ z + q
    assert residual == pytest.approx(np.linalg.norm(np.minimum(z, w)) / (1 + np.linalg.norm(q)),
                                     abs=1e-300)
    assert residual < 1e-14 and 1 <= solves <= n + 2


def test_a_struck_chain_takes_one_solve():
    # every contact presses at once: the first guess (all rows pressed) is the answer
    m = np.ones(1000)
    A = _chain_delassus(m)
    q = np.zeros(999)
    q[0] = -2.0                          # U- = -1 and e = 1 folded in
    z, residual, solves = solve_active_set(A, q)
    assert solves == 1 and residual < 1e-14
    # impulses by hand: (N - 1 - i) 2 / N through contact i
    assert z == pytest.approx(2.0 * (999 - np.arange(999)) / 1000, abs=1e-11)


def test_a_matrix_that_is_no_m_matrix_is_reported():
    A = [[0.073, 0.459, -0.649], [0.726, 1.089, -0.401], [-0.155, -0.943, 0.255]]
    with pytest.raises(LCPError, match="M-matrix"):
        solve_active_set(A, [0.294, 0.231, -0.233])


@pytest.mark.parametrize("A, q, name", [(np.eye(2), [1.0, 2.0, 3.0], "A"),
                                        (np.eye(2), [1.0, np.nan], "q"),
                                        ([[1.0, np.inf], [0.0, 1.0]], [1.0, 1.0], "A")])
def test_bad_input_is_refused_by_name(A, q, name):
    with pytest.raises(InputError, match=f"`{name}`"):
        solve_active_set(A, q)
