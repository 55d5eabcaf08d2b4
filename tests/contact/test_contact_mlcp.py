"""The mixed LCP: contact problems with bilateral rows, against exact solutions.

* a rigid bar whose upper end slides in a frictionless vertical guide (one
  bilateral row) and whose lower end strikes a floor with Coulomb friction,
  solved in exact rational arithmetic by its four cases on the full problem
  (no Schur complement), against the solver's floats;
* random MLCPs with a planted solution (unique: the Schur complement of a
  positive definite matrix is positive definite), in floats and, with
  integer data, checked exactly;
* redundant and inconsistent joints named, never divided by.
"""

from fractions import Fraction as F

import numpy as np
import pytest

from _contact_reference import random_problem
from moreau.contact import ContactProblem, solve
from moreau.lcp.mlcp import RankDeficientError, mlcp_violation, solve_mlcp

# -- the bar in a guide, exactly -------------------------------------------------------------
# Uniform bar, mass 2, length 2 (I = m L^2 / 12 = 2/3), centre (x, y), angle theta with
# cos = 4/5, sin = -3/5: the end A = c - (cos, sin) is up and left, B = c + (cos, sin) down
# and right. d/dt (cos, sin) = omega (-sin, cos) = omega (3/5, 4/5), so
#   x-velocity of A  (guide, bilateral):   vx - 3/5 omega      row E = (1, 0, -3/5)
#   y-velocity of B  (floor, normal):      vy + 4/5 omega      row N = (0, 1,  4/5)
#   x-velocity of B  (floor, tangential):  vx + 3/5 omega      row T = (1, 0,  3/5)
J = [[F(1), F(0), F(-3, 5)], [F(0), F(1), F(4, 5)], [F(1), F(0), F(3, 5)]]
MINV = [F(1, 2), F(1, 2), F(3, 2)]


def _delassus():
    return [[sum(J[i][k] * MINV[k] * J[j][k] for k in range(3)) for j in range(3)] for i in range(3)]


def _solve_exact(A, b):
    # Gauss-Jordan in rationals
    n = len(b)
    T = [list(A[i]) + [b[i]] for i in range(n)]
    for c in range(n):
        piv = next(r for r in range(c, n) if T[r][c] != 0)
        T[c], T[piv] = T[piv], T[c]
        for r in range(n):
            if r != c and T[r][c] != 0:
                f = T[r][c] / T[c][c]
                T[r] = [a - f * b_ for a, b_ in zip(T[r], T[c])]
    return [T[i][n] / T[i][i] for i in range(n)]


def bar_exact(v, mu, e):
    """The impulse (pE, pN, pT) and its case, by trying each case in rationals."""
    W = _delassus()
    u = [sum(J[i][k] * v[k] for k in range(3)) for i in range(3)]
    b = u[1] + e * min(u[1], 0)                 # vN_pre = the normal velocity before
    U = lambda p: [u[i] + sum(W[i][j] * p[j] for j in range(3)) for i in range(3)]  # noqa: E731
    found = []
    pE = -u[0] / W[0][0]                         # open
    if u[1] + W[1][0] * pE + (b - u[1]) >= 0:
        found.append(("open", [pE, F(0), F(0)]))
    p = _solve_exact(W, [-u[0], -b, -u[2]])      # stick: U_E = 0, U_N = -(b - u_N), U_T = 0
    if p[1] >= 0 and abs(p[2]) <= mu * p[1]:
        found.append(("stick", p))
    for s, name in ((1, "slip+"), (-1, "slip-")):
        # p_T = -s mu p_N: two unknowns (pE, pN) from the equality and normal rows
        A = [[W[0][0], W[0][1] - s * mu * W[0][2]], [W[1][0], W[1][1] - s * mu * W[1][2]]]
        pE_, pN_ = _solve_exact(A, [-u[0], -b])
        p = [pE_, pN_, -s * mu * pN_]
        if pN_ > 0 and s * U(p)[2] > 0:
            found.append((name, p))
    assert len(found) == 1, found                # W positive definite: exactly one case
    return found[0]


BAR_CASES = [((F(0), F(-1), F(0)), F(1, 2), F(0)),        # dropped: the guide makes it slide right
             ((F(-2), F(-1), F(0)), F(1, 10), F(0)),      # moving left on a slippery floor
             ((F(2), F(-1), F(0)), F(1, 2), F(1, 2)),     # moving right, e = 1/2: slides right
             ((F(-2), F(-1), F(1)), F(1, 4), F(0)),       # moving left and turning: sticks
             ((F(0), F(1), F(1, 2)), F(1, 2), F(0)),      # moving up: the floor is left
             ((F(1, 3), F(-3), F(-2)), F(3, 2), F(1))]    # falling hard, e = 1, rough: sticks


@pytest.mark.parametrize("v, mu, e", BAR_CASES)
def test_the_bar_in_a_guide_against_its_exact_solution(v, mu, e):
    case, p_exact = bar_exact(v, mu, e)
    W = np.array(_delassus(), dtype=float)
    u = np.array([float(sum(J[i][k] * v[k] for k in range(3))) for i in range(3)])
    pb = ContactProblem(W, u, [float(mu)], [float(e)], [u[1]], n_eq=1)
    for method in ("auto", "mlcp"):
        sol = solve(pb, method)
        assert sol.success and sol.method == "mlcp+closed-form"
        assert np.allclose(sol.p, np.array(p_exact, dtype=float), rtol=1e-14, atol=1e-15), (case, sol.p)
    # the inner solver's Lemke on the same reduced problem: the same to Lemke's rounding
    sol = solve(pb, "mlcp", inner="lemke")
    assert sol.success and sol.method == "mlcp+lemke"
    assert np.allclose(sol.p, np.array(p_exact, dtype=float), rtol=1e-12, atol=1e-14)
    # the guide holds: A's x-velocity after the impact is zero, to rounding
    assert abs(pb.velocities(sol.p)[0]) <= 1e-15


def test_the_bar_cases_cover_every_regime():
    assert {bar_exact(*c)[0] for c in BAR_CASES} == {"open", "stick", "slip+", "slip-"}


# -- random MLCPs with a planted solution ----------------------------------------------------
def planted(rng, k, nc, integer=False):
    n = k + nc
    if integer:
        R = rng.integers(-3, 4, (n, n)).astype(float)
        S = rng.integers(-2, 3, (n, n)).astype(float)
        x_free = rng.integers(-5, 6, k).astype(float)
        z = rng.integers(0, 4, nc).astype(float) * (rng.random(nc) < 0.5)
        w = rng.integers(1, 4, nc).astype(float) * (z == 0)
    else:
        R = rng.standard_normal((n, n))
        S = rng.standard_normal((n, n))
        x_free = rng.standard_normal(k)
        z = rng.uniform(0.5, 2.0, nc) * (rng.random(nc) < 0.5)
        w = rng.uniform(0.5, 2.0, nc) * (z == 0)
    # positive definite, not symmetric: R R^T + I plus a skew part
    M = R @ R.T + np.eye(n) + (S - S.T)
    x = np.concatenate([x_free, z])
    q = np.concatenate([np.zeros(k), w]) - M @ x
    return M, q, x


def test_random_mlcps_return_their_planted_solution():
    rng = np.random.default_rng(36)
    for trial in range(40):
        k, nc = 1 + trial % 3, 2 + trial % 5
        M, q, x = planted(rng, k, nc)
        r = solve_mlcp(M, q, k)
        assert r.success, (trial, r.message)
        assert np.allclose(r.x, x, rtol=1e-10, atol=1e-10), trial
        assert r.residual <= 1e-12 and mlcp_violation(M, q, k, r.x) == r.residual


def test_integer_mlcps_are_solved_exactly_up_to_rounding():
    # the float answer, checked in exact rationals: the equations hold and the
    # complementarity is met to a few units of rounding of the data
    rng = np.random.default_rng(7)
    for trial in range(10):
        k, nc = 2, 4
        M, q, x = planted(rng, k, nc, integer=True)
        r = solve_mlcp(M, q, k)
        assert r.success, r.message
        Mf = [[F(a) for a in row] for row in M.tolist()]
        xf = [F(a) for a in r.x.tolist()]
        w = [sum(Mf[i][j] * xf[j] for j in range(k + nc)) + F(q[i]) for i in range(k + nc)]
        scale = F(float(np.max(np.abs(M)) * np.max(np.abs(x)) + np.max(np.abs(q))))
        bound = 64 * F(np.finfo(float).eps) * scale
        assert all(abs(wi) <= bound for wi in w[:k])
        assert all(min(xi, wi) >= -bound and abs(min(xi, wi)) <= bound
                   for xi, wi in zip(xf[k:], w[k:]))
        assert np.max(np.abs(r.x - x)) <= 1e-12 * (1.0 + np.max(np.abs(x)))


def test_a_contact_problem_with_joints_meets_every_law_on_the_callers_data():
    # random bodies with two bilateral rows and three contacts: checked law by law,
    # independently of the solver's own certificate
    rng = np.random.default_rng(5)
    for trial in range(20):
        nc, k = 3, 2
        mu = np.where(rng.random(nc) < 0.3, 0.0, rng.uniform(0.1, 1.0, nc))
        m = k + nc + int(np.sum(mu > 0))
        ndof = m + 2
        Jm = rng.standard_normal((m, ndof))
        W = Jm @ Jm.T / ndof
        u = rng.standard_normal(m)
        e = rng.uniform(0.0, 1.0, nc)
        vN = rng.standard_normal(nc)
        target = rng.standard_normal(k) * 0.1
        pb = ContactProblem(W, u, mu, e, vN, n_eq=k, eq_target=target)
        sol = solve(pb)
        assert sol.success and sol.method.startswith("mlcp"), sol.message
        U = pb.velocities(sol.p)
        tol = 1e-10 * (1.0 + np.max(np.abs(sol.p)))
        assert np.max(np.abs(U[:k] - target)) <= tol
        gN = U[k:k + nc] + pb.impact_shift()
        assert np.all(sol.pN >= -tol) and np.all(gN >= -tol)
        assert np.all(np.minimum(sol.pN, gN) <= tol)
        fr = pb.frictional
        assert np.all(np.abs(sol.pT[fr]) <= mu[fr] * sol.pN[fr] + tol)
        UT = U[k + nc:]
        sliding = np.abs(UT) > tol
        assert np.allclose(sol.pT[fr][sliding], -mu[fr][sliding] * sol.pN[fr][sliding]
                           * np.sign(UT[sliding]), atol=tol)
        assert sol.p_eq.tolist() == sol.p[:k].tolist()


def test_without_contacts_the_joints_alone_are_solved():
    W = np.array([[2.0, 1.0], [1.0, 3.0]])
    sol = solve(ContactProblem(W, [1.0, -1.0], np.zeros(0), n_eq=2, eq_target=[0.5, 0.0]))
    assert sol.success and np.allclose(W @ sol.p_eq + [1.0, -1.0], [0.5, 0.0], atol=1e-15)


def test_without_joints_mlcp_is_its_inner_solver():
    W, U, mu, e, vN = random_problem(np.random.default_rng(9), 3)
    pb = ContactProblem(W, U, mu, e, vN)
    assert np.array_equal(solve(pb, "mlcp").p, solve(pb, "auto").p)


# -- redundant and inconsistent joints ---------------------------------------------------------
def _doubled_guide(target=(0.0, 0.0)):
    Jd = np.array(J, dtype=float)[[0, 0, 1, 2]]           # the guide's row twice
    W = Jd @ np.diag(np.array(MINV, dtype=float)) @ Jd.T
    u = Jd @ np.array([0.0, -1.0, 0.0])
    return ContactProblem(W, u, [0.5], n_eq=2, eq_target=list(target))


def test_redundant_joints_are_named_not_divided_by():
    with pytest.raises(RankDeficientError) as err:
        solve(_doubled_guide())
    msg = str(err.value)
    assert "equality (bilateral) rows [0, 1] are linearly dependent: rank 1 of 2" in msg
    assert "0.707 r0 - 0.707 r1 = 0" in msg and "redundant rows" in msg
    assert err.value.consistent is True and err.value.dependent == [[0, 1]]


def test_inconsistent_joints_are_named():
    with pytest.raises(RankDeficientError, match="inconsistent rows, with no solution") as err:
        solve(_doubled_guide(target=(0.0, 0.1)), "mlcp")
    assert err.value.consistent is False


def test_a_dependency_among_three_rows_names_its_rows():
    rng = np.random.default_rng(4)
    G = rng.standard_normal((2, 5))
    Jm = np.vstack([G[0], G[1], G[0] - 2.0 * G[1], rng.standard_normal((1, 5))])
    W = Jm @ Jm.T
    with pytest.raises(RankDeficientError, match=r"rows \[0, 1, 2\].*rank 2 of 3") as err:
        solve(ContactProblem(W, np.ones(4), [0.0], n_eq=3))
    assert err.value.dependent == [[0, 1, 2]] and err.value.consistent is False


def test_the_pure_mlcp_refuses_a_singular_block_and_bad_input():
    M = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(RankDeficientError, match=r"equality rows \[0, 1\]"):
        solve_mlcp(M, np.array([1.0, 1.0, -1.0]), 2)
    with pytest.raises(ValueError, match=r"`n_eq` must be an integer in \[0, 3\]"):
        solve_mlcp(M, np.zeros(3), 4)
