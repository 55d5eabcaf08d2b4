"""Moreau–Jean on the ball chain with the iterative contact solvers (issue 38).

The reference is the chain's simultaneous impact, exact in closed form
(``tests/scenes/test_ball_chain.py``'s module docstring): a striker of mass
1 at speed 1 on ``N - 1`` resting unit balls with ``e = 1`` leaves the chain
as a block at ``w = 2 / N`` and the striker at ``w - 1``.

The bound between the solver's tolerance and the velocity error, derived
here. The step's problem in FCLib's layout (:mod:`moreau.contact.fclib_layout`)
is an LCP ``0 <= r _|_ W r + q >= 0`` with ``W`` symmetric positive definite
(the chain's ``WN M^-1 WN^T`` on the normal rows, 1 on each frictionless
contact's decoupled tangential row, whose impulse the cone holds at 0), and
the solver stops on the natural map ``F(r) = r - max(0, r - (W r + q))``,
``||F(r)|| <= tol (1 + ||q||)``. With ``y = r - F(r) >= 0`` the projection's
inequality ``(r* - y).(r - W r - q - y) <= 0`` and the solution's
``(y - r*).(W r* + q) >= 0`` add up, with ``d = r - r*``, to
``(F - d).(F - W d) <= 0``, so ``d.W d <= F.(I + W) d - |F|^2``. Hence
``lambda_min |d|^2 <= (1 + lambda_max) |F| |d|``, ``|d| <= (1 + lambda_max)
|F| / lambda_min``, and the velocities ``v - v* = M^-1 WN^T d`` have
``|v - v*|_M^2 = d.W d <= (1 + lambda_max)^2 |F|^2 / lambda_min``:

    ``max_i |v_i - v*_i| <= (1 + lambda_max) / sqrt(lambda_min m_min) tol (1 + ||q||)``.

For unit balls ``W_NN = tridiag(-1, 2, -1)`` of size ``N - 1`` has the
eigenvalues ``4 sin^2(k pi / 2N)``, ``k = 1 .. N - 1``; with the tangential
rows' 1, ``lambda_min = 4 sin^2(pi / 2N)``, ``lambda_max < 4``, and at the
impact ``q = (-(1 + e), 0, ...)``, ``||q|| = 2``: the bound is ``15 tol /
(2 sin(pi / 2N))``, about ``4.8 N tol``.

The bound is held on the impact step's velocities, not on a later state:
with ``e = 1`` Moreau–Jean amplifies a perturbation of the touching chain
(a contact in the index set that separates, ``U- > 0``, and takes an impulse
gains ``p U- / 2`` of energy), so the impact's error of the size of the
tolerance grows in the steps after it (measured with the exact solver from
1e-9 of noise: 7.3e-6 after 25 steps at N = 1000; the exact block itself,
equal floats, has nothing to grow).
"""

import math

import numpy as np
import pytest

from moreau.contact.solvers.nsgs import solve_nsgs
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.moreau_jean import MoreauJean
from moreau.model import registry
from moreau.scenes.ball_chain import SPARSE_FROM, BallChain, simultaneous_impact, sor_omega

H = 0.01
TOL = 1e-8
#: the striker 0.004 radii from the chain: the impact in the first step (t* = 0.004), a run
#: of two steps (the generic step inverts a 100 x 100 mass matrix each step)
GAP = 0.00004


def _chain(n):
    return BallChain(n_balls=n, striker_gap=GAP)


def _bound(n, tol):
    """The module docstring's bound on the velocities' error for unit balls."""
    lam_min = 4.0 * math.sin(math.pi / (2 * n)) ** 2
    lam_max = 4.0
    return (1.0 + lam_max) / math.sqrt(lam_min) * tol * (1.0 + 2.0)


def _impact_run(n, method, **options):
    chain = _chain(n)
    q0, v0 = chain.initial_state()
    res = simulate(chain, (0.0, chain.impact_time + H), q0, v0, "moreau-jean", h=H,
                   lcp_method=method, **options)
    exact = simultaneous_impact(chain.masses, v0, 1.0)
    return res, exact


def _after_impact(res):
    # the first recorded state where the last ball moves: the end of the impact step
    return res.v[np.flatnonzero(res.v[:, -1] != 0.0)[0]]


@pytest.mark.parametrize("n", [100, 1000])
@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_the_impact_step_is_the_block_result_within_the_tolerance_bound(n, method):
    options = {"lcp_omega": sor_omega(np.ones(n))} if method == "nsgs" else {}
    res, exact = _impact_run(n, method, lcp_tol=TOL, **options)
    assert res.success, res.message
    assert 0.0 < res.stats["max_residual"] <= TOL
    err = np.max(np.abs(_after_impact(res) - exact))
    assert err <= _bound(n, TOL)
    # and the bound says something: speeds are of order 1
    assert _bound(n, TOL) < 1e-4
    if method == "nsgs":
        # over-relaxed at Young's optimum, a few N sweeps (test below: plain, more than N^2)
        assert res.stats["iterations"] < 4 * n


def test_the_dense_and_the_sparse_path_take_the_solver():
    small, long = _chain(100), _chain(SPARSE_FROM)
    for chain, sparse in ((small, False), (long, True)):
        integ = MoreauJean(chain, 0.0, *chain.initial_state(), 0.1, h=H, lcp_method="apgd")
        assert (integ._sparse is not None) is sparse


def test_plain_sweeps_grow_as_n_squared():
    # the struck chain's impact problem, every contact pressing: Gauss-Seidel on
    # tridiag(-1, 2, -1) contracts the slowest mode by cos^2(pi / N) a sweep, so plain
    # sweeps to 1e-8 exceed N^2 at N = 100; at Young's optimum the rate is omega - 1 and
    # the sweeps a few N
    plain = solve_nsgs(*_impact_problem(100), tol=TOL, max_sweeps=20_000)
    assert plain.converged and plain.iterations > 100 ** 2


def _impact_problem(n):
    """The impact step's problem in FCLib's layout, built by hand: ``(W, q, mu)``."""
    m = 2 * (n - 1)
    W = np.zeros((m, m))
    i = np.arange(n - 1)
    W[2 * i, 2 * i] = 2.0
    W[2 * i[1:], 2 * i[:-1]] = -1.0
    W[2 * i[:-1], 2 * i[1:]] = -1.0
    W[2 * i + 1, 2 * i + 1] = 1.0
    q = np.zeros(m)
    q[0] = -2.0
    return W, q, np.zeros(n - 1)


def test_a_budget_too_small_fails_the_step_with_the_true_residual():
    # plain NSGS on 99 pressed contacts needs about 12 700 sweeps; the default budget is 10 000
    res, _ = _impact_run(100, "nsgs")
    assert not res.success and res.status == -3
    assert "nsgs: not converged" in res.message and "after 10000 iterations" in res.message
    # the impact step, the first, was not taken
    assert res.stats["steps"] == 0
    W, q, mu = _impact_problem(100)
    r = solve_nsgs(W, q, mu, tol=TOL, max_sweeps=10_000).r
    F = np.minimum(r, W @ r + q)
    true = np.linalg.norm(F) / (1.0 + np.linalg.norm(q))
    assert res.stats["max_residual"] == pytest.approx(true, rel=1e-9)
    assert true > TOL
    assert f"residual {true:.3e} > tol 1.0e-08" in res.message


class _PushedChain(BallChain):
    """The chain on its sparse path with a constant force 1 pushing the striker into it."""

    def sparse_contacts(self):
        inv_m, f, jacobian, gaps = super().sparse_contacts()
        f = f.copy()
        f[0] = 1.0
        return inv_m, f, jacobian, gaps


@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_a_pressed_chain_is_warm_started_from_the_last_step(method):
    # touching and at rest, pushed: every step presses every contact with the same impulses
    # h (N - 1 - i) / N, so from the second step on the last step's impulses solve it
    n = SPARSE_FROM + 50
    chain = _PushedChain(n_balls=n, striker_gap=0.0)
    q0 = 2.0 * np.arange(n) - 2.0
    options = {"lcp_omega": sor_omega(chain.masses)} if method == "nsgs" else {}
    runs = {}
    for steps in (1, 10):
        res = simulate(chain, (0.0, steps * H), q0, np.zeros(n), "moreau-jean", h=H,
                       lcp_method=method, **options)
        assert res.success and res.stats["lcp_solves"] == steps
        runs[steps] = res
    first = runs[1].stats["iterations"]
    assert first > 100
    # from zero each step would cost about `first` (measured: 404 sweeps, 1180 APGD steps);
    # from the last step's impulses, whose residual on the new problem is that of the last
    # solve (about tol), the nine cost 0-80 sweeps, 0-330 steps each
    assert runs[10].stats["iterations"] - first < 3 * first


def test_sor_omega_is_youngs_optimum():
    # N = 3: the Jacobi matrix of tridiag(-1, 2, -1) (2 x 2) has rho = 1/2
    assert sor_omega(np.ones(3)) == pytest.approx(2.0 / (1.0 + math.sqrt(0.75)), rel=1e-14)
    m = np.array([3.0, 1.0, 2.0, 0.5, 1.0])
    inv = 1.0 / m
    W = np.diag(inv[:-1] + inv[1:]) - np.diag(inv[1:-1], 1) - np.diag(inv[1:-1], -1)
    rho = np.max(np.abs(np.linalg.eigvals(np.eye(4) - W / np.diag(W)[:, None])))
    assert sor_omega(m) == pytest.approx(2.0 / (1.0 + math.sqrt(1.0 - rho ** 2)), rel=1e-12)
    with pytest.raises(InputError, match="`masses` must hold 3 or more"):
        sor_omega([1.0, 1.0])


@pytest.mark.parametrize("options, message", [
    ({"lcp_tol": 1e-6}, "`lcp_tol` is an option of the iterative contact solvers"),
    ({"lcp_method": "apgd", "lcp_omega": 1.5}, "`lcp_omega` over-relaxes NSGS"),
    ({"lcp_method": "nsgs", "lcp_omega": 2.0}, "`lcp_omega` must lie in (0, 2)"),
    ({"lcp_method": "nsgs", "lemke_max_iter": 5}, "`lcp_method='nsgs'` runs no Lemke"),
    ({"lcp_method": "gauss"}, "`lcp_method` must be one of"),
])
def test_options_are_checked(options, message):
    with pytest.raises(InputError) as exc:
        MoreauJean.Options(h=H, **options)
    assert message in str(exc.value)


def test_fast_true_is_refused_where_the_solver_takes_the_generic_step():
    chain = _chain(10)
    with pytest.raises(InputError, match="`fast=True` solves contacts in closed form or by Lemke"):
        MoreauJean(chain, 0.0, *chain.initial_state(), 0.1, h=H, lcp_method="nsgs", fast=True)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["nsgs", "apgd"])
def test_ten_thousand_balls(method):
    n = 10_000
    options = {"lcp_omega": sor_omega(np.ones(n))} if method == "nsgs" else {}
    res, exact = _impact_run(n, method, lcp_tol=TOL, lcp_max_iter=1_000_000, **options)
    assert res.success, res.message
    assert res.stats["max_residual"] <= TOL
    assert np.max(np.abs(_after_impact(res) - exact)) <= _bound(n, TOL)
    if method == "nsgs":
        assert res.stats["iterations"] < 4 * n


# -- the generic step with friction (any planar scene without joints) ---------------------

def test_a_frictional_scene_takes_the_solver_on_the_generic_step():
    # the sliding box: two frictional corner contacts, a well-conditioned 4 x 4 Delassus
    # matrix; Lemke's answer ("auto", exact to rounding) is the reference, and at 1e-12 a
    # step's error is of that order, 50 steps of it far below 1e-8 (APGD's frictional path
    # is the same code, met below where it stalls)
    method = "nsgs"
    sc = registry.get_entry("sliding-box").factory()
    q0, v0 = sc.initial_state()
    ref = simulate(sc, (0.0, 0.5), q0, v0, "moreau-jean", h=H, fast=False)
    res = simulate(sc, (0.0, 0.5), q0, v0, "moreau-jean", h=H, lcp_method=method,
                   lcp_tol=1e-12, lcp_max_iter=100_000)
    assert res.success, res.message
    assert 0.0 < res.stats["max_residual"] <= 1e-12 and res.stats["iterations"] > 0
    assert np.max(np.abs(res.q[-1] - ref.q[-1])) < 1e-8
    assert np.max(np.abs(res.v[-1] - ref.v[-1])) < 1e-8
    assert np.array_equal(res.regime, ref.regime)


def test_apgd_that_does_not_converge_fails_the_first_step():
    # the rocking block (mu = 10) pressed on both corners: APGD's shifted fixed point stalls
    # (a heuristic with slip, its module says); the run stops at once, by name and residual
    sc = registry.get_entry("rocking-block").factory()
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=H, lcp_method="apgd",
                   lcp_max_iter=2000)
    assert res.status == -3 and res.stats["steps"] == 0
    assert "apgd: not converged" in res.message and "after 2000 iterations" in res.message
    assert res.stats["max_residual"] > 1e-8
    assert f"residual {res.stats['max_residual']:.3e} > tol 1.0e-08" in res.message
