"""One contact of a one-dof mechanism: a singular Delassus matrix with a solution.

A rod pinned at one end whose free tip touches a rough stop has one degree of
freedom: the normal and tangential rates of the tip are both multiples of the
rod's angular rate, so ``W`` (after the pin's rows are eliminated) has rank one,
and its determinant is rounding. The free velocities ``u = H v_free`` lie in
its range, so the contact problem has solutions (the velocities after the step
are unique; the impulses form a segment). The closed form's case formulas
cannot choose on such a ``W`` and used to raise a Painlevé error on about a
fifth of them; ``"auto"`` now hands them to Lemke, and only a problem with no
solution (``u`` outside the range) is still named a Painlevé case.
"""

import numpy as np
import pytest

from moreau.contact import ContactProblem, solve
from moreau.errors import PainleveError
from moreau.integrators.contact_problem import solve_contact_problem


def _pinned_rod(rng):
    m, L = rng.uniform(0.1, 2.0), rng.uniform(0.2, 2.0)
    th = rng.uniform(-1.5, 1.5)
    Mi = np.diag([1 / m, 1 / m, 12.0 / (m * L * L)])
    # pin at the end A = c - (L/2)(cos th, sin th): rows of d/dt (x_A, y_A)
    G = np.array([[1.0, 0.0, L / 2 * np.sin(th)], [0.0, 1.0, -L / 2 * np.cos(th)]])
    a = rng.uniform(0.0, 2 * np.pi)
    n, t = np.array([np.cos(a), np.sin(a)]), np.array([-np.sin(a), np.cos(a)])
    rB = np.array([-L / 2 * np.sin(th), L / 2 * np.cos(th)])     # tip B's lever, rotated
    H = np.array([[n[0], n[1], n @ rB], [t[0], t[1], t @ rB]])
    P = Mi @ G.T @ np.linalg.solve(G @ Mi @ G.T, G)                # M^-1 G^T (G M^-1 G^T)^-1 G
    S = Mi - P @ Mi
    W = H @ S @ H.T
    v = rng.normal(size=3)
    u = H @ (v - P @ v)                                            # a velocity the pin allows
    return W, u


def _cases(count):
    rng = np.random.default_rng(20261128)
    out = []
    while len(out) < count:
        W, u = _pinned_rod(rng)
        if u[0] < 0.0:
            out.append((W, u, rng.uniform(0.05, 1.5)))
    return out


def test_one_dof_contacts_are_solved_with_their_unique_velocities():
    raised_before = 0
    for W, u, mu in _cases(300):
        assert abs(np.linalg.det(W)) <= 1e-9 * (W[0, 0] * W[1, 1] + W[0, 1] ** 2)
        try:
            solve(ContactProblem(W, u, [mu]), "closed-form")
        except PainleveError:
            raised_before += 1
        sol = solve(ContactProblem(W, u, [mu]), "auto")
        assert sol.success and sol.residual <= 1e-9
        pN, pT = sol.p
        v = u + W @ sol.p
        scale = np.abs(u).max()
        # the one-dof answer: the tip pressing is stopped (v_N = 0); sticking inside the cone
        # (v_T = 0) or sliding on its edge against v_T
        assert pN >= 0.0 and abs(v[0]) <= 1e-9 * scale
        assert abs(pT) <= mu * pN * (1 + 1e-9)
        if abs(pT) < mu * pN * (1 - 1e-9):
            assert abs(v[1]) <= 1e-9 * scale
        else:
            assert pT * v[1] <= 1e-12 * scale * pN
        # the scheme's entry point agrees
        p2, _, _ = solve_contact_problem(W, u, np.array([mu]), np.zeros(1), np.zeros(1))
        assert np.allclose(W @ p2, W @ sol.p, atol=1e-9 * scale)
    # the closed form alone refused a good share of these solvable problems
    assert raised_before >= 10


def test_singular_w_without_a_solution_is_still_a_painleve_case():
    # u outside the range of W = w w^T, w = (1, 2): no impulse stops the tip
    with pytest.raises(PainleveError, match="singular Delassus"):
        solve(ContactProblem([[1.0, 2.0], [2.0, 4.0]], [-1.0, 1.0], [0.9]), "auto")


def test_closed_form_answer_is_checked_against_tol():
    sol = solve(ContactProblem(np.eye(2), [-1.0, 0.2], [0.5]), "closed-form", tol=0.0)
    # an exact answer (p = (1, -0.2)) meets even tol = 0
    assert sol.success and sol.residual == 0.0
    tight = solve(ContactProblem([[2.0, 0.3], [0.3, 1.0]], [-1.0, 0.7], [0.5]), "closed-form",
                  tol=1e-300)
    assert tight.status == "failed" and "exceeds tol" in tight.message
