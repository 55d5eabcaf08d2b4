"""NSGS and APGD reached through ``moreau.contact.solve``: against Lemke, budgets, options, auto.

The residual these methods report is recomputed here from the solution's
stacked impulses on the problem's own rows (the De Saxcé natural map with the
2D cone projection written out below), not through FCLib's layout.
"""

import numpy as np
import pytest
from contact_helpers import random_problem

from moreau.contact import MAX_ITER, SOLVED, ContactProblem, solve
from moreau.contact._sparse import delassus, disk_jacobian
from moreau.errors import InputError


def _stacked(W, q, mu, e=0.0, vN_pre=None):
    # FCLib's interleaved [N_i, T_i] to the problem's rows [N all; T of mu > 0]
    nc = mu.size
    rows = np.concatenate([2 * np.arange(nc), 2 * np.flatnonzero(mu > 0.0) + 1])
    W = W.toarray() if hasattr(W, "toarray") else W
    return ContactProblem(W[np.ix_(rows, rows)], q[rows], mu, e=e, vN_pre=vN_pre)


def _natural_map(problem, p):
    """``||F|| / (1 + ||q||)`` from the stacked impulses, the cone projection by cases."""
    nc, fr = problem.n_contacts, problem.frictional
    U = problem.u_free + problem.W @ p
    shift = problem.e * np.minimum(problem.vN_pre, 0.0)
    rn, un = p[problem.normal_rows], U[problem.normal_rows] + shift
    rt, ut, qt = np.zeros(nc), np.zeros(nc), np.zeros(nc)
    rt[fr], ut[fr] = p[problem.tangential_rows], U[problem.tangential_rows]
    qt[fr] = problem.u_free[problem.tangential_rows]
    q = np.concatenate([problem.u_free[problem.normal_rows] + shift, qt])
    sq = 0.0
    for i in range(nc):
        m = problem.mu[i]
        xn, xt = rn[i] - (un[i] + m * abs(ut[i])), rt[i] - ut[i]
        if abs(xt) <= m * xn and xn >= 0.0:
            pn, pt = xn, xt
        elif m * abs(xt) <= -xn:
            pn, pt = 0.0, 0.0
        else:
            pn = (xn + m * abs(xt)) / (1.0 + m * m)
            pt = np.sign(xt) * m * pn
        sq += (rn[i] - pn) ** 2 + (rt[i] - pt) ** 2
    return np.sqrt(sq) / (1.0 + np.linalg.norm(q))


@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_iterative_methods_match_lemke_through_solve(method):
    # fixed draws: with friction a random problem may have several solutions, one found by
    # each method (tests/contact/test_nsgs.py, SEED)
    rng = np.random.default_rng(20261129)
    done = 0
    for _ in range(12):
        nc = int(rng.integers(2, 6))
        W, q, mu = random_problem(nc, rng, mu_max=0.3 if method == "apgd" else 0.5)
        # an impact law on top: restitution on the pre-step normal velocities
        pb = _stacked(W, q, mu, e=rng.uniform(0.0, 1.0, nc), vN_pre=rng.standard_normal(nc))
        ref = solve(pb, "lemke")
        assert ref.success, ref.message
        sol = solve(pb, method, tol=1e-12, max_iter=200_000)
        assert sol.method == method
        assert sol.residual == pytest.approx(_natural_map(pb, sol.p), rel=1e-9, abs=1e-15)
        if method == "apgd" and not sol.success:
            # APGD with De Saxce's shift may stall where contacts slip: then it says so
            assert sol.status == MAX_ITER and sol.residual > 1e-12
            continue
        done += 1
        assert sol.status == SOLVED and sol.residual <= 1e-12, sol.message
        scale = 1.0 + np.abs(ref.p).max()
        assert np.max(np.abs(sol.p - ref.p)) <= 1e-6 * scale
        assert np.array_equal(sol.pN, sol.p[pb.normal_rows])
        assert np.all(sol.pT[mu == 0.0] == 0.0)
        assert np.array_equal(sol.pT[mu > 0.0], sol.p[pb.tangential_rows])
    assert done >= 11


@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_one_sweep_is_not_converged_with_its_true_residual(method):
    rng = np.random.default_rng(7)
    pb = _stacked(*random_problem(6, rng, frictionless=0.0))
    sol = solve(pb, method, max_iter=1, tol=1e-12)
    assert sol.status == MAX_ITER and not sol.success
    assert sol.iterations == 1
    assert "not converged" in sol.message
    true = _natural_map(pb, sol.p)
    assert true > 1e-12
    assert sol.residual == pytest.approx(true, rel=1e-9)


@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_unknown_option_and_equality_rows_are_refused_by_name(method):
    pb = ContactProblem(np.eye(2), [-1.0, 1.0], [0.5])
    with pytest.raises(InputError, match=rf"`sweeps` is not an option of method '{method}'"):
        solve(pb, method, sweeps=3)
    W = np.array([[2.0, 1.0], [1.0, 1.0]])
    with pytest.raises(InputError, match=rf"`method` '{method}' solves no equality rows"):
        solve(ContactProblem(W, [-1.0, -2.0], [0.0], n_eq=1), method)
    with pytest.raises(InputError, match="`tol`"):
        solve(pb, method, tol=2.0)


def test_options_pass_through():
    rng = np.random.default_rng(3)
    pb = _stacked(*random_problem(5, rng, frictionless=0.0))
    a = solve(pb, "nsgs", tol=1e-12, omega=1.0)
    b = solve(pb, "nsgs", tol=1e-12, omega=1.3, check_every=1)
    assert a.success and b.success and a.iterations != b.iterations
    assert solve(pb, "nsgs", tol=1e-4).iterations <= a.iterations


def _disk_row_on_ground(n):
    """``n`` unit disks in a row on the ground against a wall on the left: ``2 n`` contacts.

    Ground contact under each disk, one between neighbours, one with the
    wall; free velocities: a step of gravity and a seeded random velocity,
    so that some contacts press, some slip and some open.
    """
    rng = np.random.default_rng(11)
    centres = np.column_stack([1.0 + 2.0 * np.arange(n), np.ones(n)])
    contacts = [(-1, 0, (0.0, 1.0), (1.0, 0.0))]
    contacts += [(-1, b, (centres[b, 0], 0.0), (0.0, 1.0)) for b in range(n)]
    contacts += [(b, b + 1, (centres[b, 0] + 1.0, 1.0), (1.0, 0.0)) for b in range(n - 1)]
    H = disk_jacobian(contacts, centres, n)
    W = delassus(H, np.tile([1.0, 1.0, 2.0], (n, 1)))
    v = 2e-2 * rng.standard_normal(3 * n)
    v[1::3] -= 9.81e-2
    return W, H @ v, np.full(len(contacts), 0.4)


def test_auto_above_the_crossover_is_nsgs_and_certified():
    pb = _stacked(*_disk_row_on_ground(100))
    assert pb.n_contacts == 200
    sol = solve(pb)
    assert sol.method == "nsgs" and sol.path == ("nsgs",)
    assert sol.status == SOLVED and sol.residual <= 1e-8
    assert _natural_map(pb, sol.p) <= 1e-8
    # gravity presses every disk on the ground
    assert np.all(sol.pN[1:101] > 0.0)


def test_auto_keeps_lemke_up_to_the_crossover():
    for nc, method in ((32, "lemke"), (33, "nsgs")):
        sol = solve(ContactProblem(2.0 * np.eye(nc), -np.ones(nc), np.zeros(nc)))
        assert sol.method == method and sol.success
        assert np.allclose(sol.pN, 0.5, rtol=0, atol=1e-9)


@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_equality_rows_through_mlcp_with_an_iterative_inner_solver(method):
    # a rod row E and a frictional contact (N, T): the mlcp eliminates E, the method solves
    # the rest, and the whole answer is certified on the caller's rows
    W = np.array([[2.0, 1.0, 0.5], [1.0, 1.0, 0.2], [0.5, 0.2, 1.0]])
    pb = ContactProblem(W, [-1.0, -2.0, 1.0], [0.4], n_eq=1)
    ref = solve(pb, "mlcp", inner="lemke")
    sol = solve(pb, "mlcp", inner=method, tol=1e-12)
    assert sol.success and sol.method == f"mlcp+{method}"
    assert np.allclose(sol.p, ref.p, rtol=0, atol=1e-9)
    # the equality row holds: U_E = 0
    assert abs(pb.velocities(sol.p)[0]) <= 1e-9
