"""Issue 33: proofs where exact ones exist, and ``auto`` deciding small problems Lemke cannot."""

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.lcp import (INFEASIBLE, NO_SOLUTION, SECONDARY_RAY, SOLVED, decide, lcp_violation,
                        solve_lcp)
from moreau.lcp.lemke import unit_farkas

from .conftest import assert_certified, assert_farkas


def _bimatrix(A, B):
    m, k = A.shape
    M = np.zeros((m + k, m + k))
    M[:m, m:] = A
    M[m:, :m] = B.T
    return M


def test_a_unit_farkas_vector_gives_infeasible_where_the_ray_proves_nothing():
    # row 0: q_0 < 0 and M_0j <= 0, so w_0 < 0 for every z >= 0 (y = e_1 of the
    # issue, 0-based here); the other rows make the ray itself no proof
    M = np.array([[0.0, -1.0, 0.0], [2.0, -1.0, 3.0], [-1.0, 4.0, -2.0]])
    q = np.array([-1.0, -1.0, 1.0])
    assert int(unit_farkas(M, q)) == 0
    for method in ("lemke", "auto"):
        res = solve_lcp(M, q, method=method)
        assert res.status == INFEASIBLE, res.message
        np.testing.assert_array_equal(res.certificate, [1.0, 0.0, 0.0])
        assert_farkas(M, q, res.certificate)


def test_the_lp_dual_gives_a_farkas_vector_that_lemke_and_unit_vectors_miss():
    M = _bimatrix(np.array([[-2.0, 1.0], [2.0, -2.0]]), np.array([[-2.0, 0.0], [-2.0, 3.0]]))
    q = np.array([-2.0, 2.0, 1.0, 2.0])
    assert solve_lcp(M, q).status == SECONDARY_RAY
    assert int(unit_farkas(M, q)) == -1
    res = solve_lcp(M, q, method="auto")
    assert res.status == INFEASIBLE and res.path == ("lemke", "lp")
    assert_farkas(M, q, res.certificate)


def test_auto_finds_the_equilibria_of_a_game_on_which_lemke_ends_on_a_ray():
    # a 2 x 2 game with cost matrices A, B > 0 (Cottle, Pang and Stone 1992,
    # Sec. 1.2): LCP M = [[0, A], [B^T, 0]], q = -1. With covering ones z_r
    # enters after z0 with a column -M_{:r} <= 0: a ray at once.
    A = np.array([[3.0, 1.0], [1.0, 2.0]])
    B = np.array([[2.0, 1.0], [1.0, 3.0]])
    M = _bimatrix(A, B)
    q = -np.ones(4)
    lem = solve_lcp(M, q)
    assert lem.status == SECONDARY_RAY and lem.pivots == 1
    res = solve_lcp(M, q, method="auto")
    assert res.status == SOLVED and res.method == "enumerate"
    assert_certified(M, q, res.z, 1e-9)
    # (x, y) = normalised z: a Nash equilibrium, no pure deviation lowers a cost
    x = res.z[:2] / res.z[:2].sum()
    y = res.z[2:] / res.z[2:].sum()
    assert np.all(A @ y >= x @ A @ y - 1e-12) and np.all(x @ B >= x @ B @ y - 1e-12)


def test_auto_proves_no_solution_by_exact_enumeration():
    # feasible (so no Farkas vector exists) yet without a solution
    M = _bimatrix(np.array([[3.0, 1.0], [1.0, 0.0]]), np.array([[3.0, -2.0], [-1.0, 1.0]]))
    q = np.array([1.0, -2.0, -2.0, 1.0])
    assert solve_lcp(M, q).status == SECONDARY_RAY
    res = solve_lcp(M, q, method="auto")
    assert res.status == NO_SOLUTION and res.certificate is None
    assert "16 complementary pieces" in res.message
    # the claim, checked independently: a feasible point exists (so no Farkas
    # vector could prove it), and an LP per piece finds each one empty
    z = np.array([1.0, 1.0, 2.0, 0.0])
    assert np.all(M @ z + q >= 0)
    out, _, counts = decide.enumerate_pieces(M, q)
    assert out == "none" and counts["regular"] + counts["singular"] == 16
    from scipy.optimize import linprog
    for mask in range(16):
        J = [i for i in range(4) if mask >> i & 1]
        Jc = [i for i in range(4) if not mask >> i & 1]
        # z_J >= 0, z_Jc = 0, w_J = 0, w_Jc >= 0
        bounds = [(0, None) if i in J else (0, 0) for i in range(4)]
        lp = linprog(np.zeros(4), A_ub=-M[Jc] if Jc else None, b_ub=q[Jc] if Jc else None,
                     A_eq=M[J] if J else None, b_eq=-q[J] if J else None, bounds=bounds)
        assert lp.status == 2, (J, lp.x)


def test_an_undecided_piece_is_reported_not_claimed(monkeypatch):
    M = _bimatrix(np.array([[3.0, 1.0], [1.0, 0.0]]), np.array([[3.0, -2.0], [-1.0, 1.0]]))
    q = np.array([1.0, -2.0, -2.0, 1.0])
    monkeypatch.setattr(decide, "_piece_certificate", lambda *a: False)
    res = solve_lcp(M, q, method="auto")
    assert res.status not in (SOLVED, NO_SOLUTION, INFEASIBLE)
    assert "could not be decided exactly, so nothing is proven" in res.message


def test_enumeration_respects_its_size_option():
    A = np.array([[3.0, 1.0], [1.0, 2.0]])
    M = _bimatrix(A, A.T)
    res = solve_lcp(M, -np.ones(4), method="auto", enumerate_max_n=3)
    assert res.status != SOLVED or res.method != "enumerate"
    for bad in (-1, 21, 2.5, True, "12"):
        with pytest.raises(InputError, match="`enumerate_max_n` must be an integer in"):
            solve_lcp(M, -np.ones(4), method="auto", enumerate_max_n=bad)


def test_enumeration_solution_lies_in_a_singular_piece():
    # the solutions are z = (1 + t, t), t >= 0: in the pieces J = {0} and {0, 1},
    # both with M_JJ singular; the regular pieces {} and {1} hold none
    M = np.array([[0.0, 0.0], [1.0, -1.0]])
    q = np.array([0.0, -1.0])
    out, z, counts = decide.enumerate_pieces(M, q)
    assert out == "solved" and counts["J"] in ([0], [0, 1])
    assert lcp_violation(M, q, z) <= 1e-12 and z[0] - z[1] == pytest.approx(1.0)
