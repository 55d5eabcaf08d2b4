"""The compiled loop's warm-started contact LCP, and the hand-back of a step Lemke cannot solve."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators import moreau_jean as mj
from moreau.integrators.moreau_jean import MoreauJean
from moreau.lcp import lcp_violation
from moreau.lcp.friction import build_friction_lcp
from moreau.scenes import BidirectionalDrive, BidirectionalDriveParams, SlidingBox

from _agreement import assert_forces_agree

TWO_PI = 2.0 * math.pi

# the two shipped scenes with two frictional contacts, as the compiled-vs-generic
# test of test_compiled_engine.py runs them
CASES = {
    "sliding-box": (SlidingBox(), 0.004),
    "bidirectional-drive": (BidirectionalDrive(BidirectionalDriveParams(phase=1.0)), TWO_PI / 400),
}


def _run(sc, h, nsteps, **opts):
    q0, v0 = sc.initial_state()
    return simulate(sc, (0.0, nsteps * h), q0, v0, "moreau-jean", h=h, **opts)


def _assert_same_run(a, b, tol, h):
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.regime, b.regime)
    qs = max(1.0, float(np.max(np.abs(a.q))))
    vs = max(1.0, float(np.max(np.abs(a.v))))
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=tol * qs)
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=tol * vs)
    np.testing.assert_allclose(b.slip_velocity, a.slip_velocity, rtol=0, atol=tol * vs)
    assert_forces_agree(a, b, h, vs, tol)


@pytest.mark.parametrize("name", sorted(CASES))
def test_warm_start_skips_pivoting_and_changes_nothing(name):
    sc, h = CASES[name]
    warm = _run(sc, h, 1000, save_every=1)
    cold = _run(sc, h, 1000, save_every=1, lcp_warm_start=False)
    assert warm.success and cold.success
    for r in (warm, cold):
        # every step solves the two-contact LCP in the compiled loop
        assert r.stats["lcp_solves"] == 1000 and r.stats["direct_solves"] == 0
        assert r.stats["fallbacks"] == 0
    # measured: 997 (box) and 987 (drive) of 1000; Lemke runs on the first
    # contact step and where a contact changes regime
    assert warm.stats["warm_starts"] >= 950
    assert cold.stats["warm_starts"] == 0
    assert warm.stats["pivots"] < 0.05 * cold.stats["pivots"]
    # the certification of an accepted warm solution is Lemke's (<= 1e-9);
    # what they reach is rounding level, as Lemke's do
    assert warm.stats["max_residual"] <= 1e-10
    _assert_same_run(cold, warm, 1e-12, h)


def _lcps_of_generic_run(sc, h, nsteps):
    """Each step's friction LCP as the generic Python step builds it (``build_friction_lcp``)."""
    lcps = []
    orig = MoreauJean._solve_lcp

    def spy(self, W, U_free, mu, e, vN_pre, ia, pN, pT):
        lcps.append(build_friction_lcp(W, U_free, mu, e, vN_pre))
        return orig(self, W, U_free, mu, e, vN_pre, ia, pN, pT)

    MoreauJean._solve_lcp = spy
    try:
        _run(sc, h, nsteps, fast=False)
    finally:
        MoreauJean._solve_lcp = orig
    return lcps


@pytest.mark.parametrize("name", sorted(CASES))
def test_every_warm_solution_solves_the_step_lcp(name):
    # independent of the kernel: the impulses the compiled run took on each
    # step, written as the LCP unknowns (pN, pT+, pT-, beta = |vT|), checked
    # against that step's LCP built in Python by the generic step
    sc, h = CASES[name]
    n = 300
    res = _run(sc, h, n, save_every=1)
    assert res.stats["warm_starts"] >= 0.9 * n
    lcps = _lcps_of_generic_run(sc, h, n)
    assert len(lcps) == n
    worst = 0.0
    for k, (Ml, ql, layout) in enumerate(lcps):
        pN = res.force_N[k + 1] * h
        pT = res.force_T[k + 1] * h
        vT = res.slip_velocity[k + 1]
        z = np.concatenate([[pN[i], max(pT[i], 0.0), max(-pT[i], 0.0), abs(vT[i])]
                            for i in range(2)])
        worst = max(worst, lcp_violation(Ml, ql, z))
    assert worst <= 1e-9        # measured: 5e-15


def test_warm_start_option_is_checked():
    sc, h = CASES["sliding-box"]
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match=r"`lcp_warm_start` must be True or False"):
        MoreauJean(sc, 0.0, q0, v0, 1.0, h=h, lcp_warm_start="yes")


# -- Lemke failing inside the compiled loop: the step goes back to Python --------------------

@pytest.mark.parametrize("limit, warm", [(1, False), (3, False), (3, True)])
def test_lemke_failure_is_handed_back_to_the_qp_fallback(limit, warm):
    box = SlidingBox(mu=0.4)
    q0, v0 = box.initial_state()
    ts = box.stopping_time(v0)
    T = 1.6 * ts
    n = 100
    h = T / n
    # one pivot is Lemke's first (z0 entering): no contact step can finish, so
    # every one fails in the kernel and is taken by the generic step. Three
    # pivots finish the resting steps but not the sliding ones (measured: 4 to
    # 7 pivots): then kernel steps and handed-back steps alternate
    opts = dict(h=h, save_every=1, lemke_max_iter=limit, lcp_warm_start=warm)
    gen = simulate(box, (0.0, T), q0, v0, "moreau-jean", fast=False, **opts)
    comp = simulate(box, (0.0, T), q0, v0, "moreau-jean", fast=True, **opts)
    lemke = simulate(box, (0.0, T), q0, v0, "moreau-jean", h=h, save_every=1)
    for r in (gen, comp):
        assert r.success, r.message
        assert r.stats["lcp_solves"] == n
    nfall = comp.stats["fallbacks"]
    assert nfall == gen.stats["fallbacks"]
    if limit == 1:
        assert nfall == n and comp.stats["warm_starts"] == 0
    else:
        # the sliding steps (62 of them) and the first resting one
        assert 0.5 * n < nfall < n
        assert comp.stats["pivots"] > 0 and (comp.stats["warm_starts"] > 0) == warm
    assert lemke.stats["fallbacks"] == 0
    # the handed-back steps are the generic step itself and the kernel's steps
    # agree with it to rounding; measured difference 6e-16. Not held to 1e-12:
    # OSQP is iterative, and where rounding moves an iterate across its
    # stopping test the answer moves within the QP tolerance
    _assert_same_run(gen, comp, 1e-9, h)
    # the QP answers are accurate to its tolerance (1e-6), far below the
    # scheme's O(h) error: the trajectory matches the exact motion as well as
    # the Lemke run does (measured: equal errors, 0.0199)
    qe, ve = box.exact_solution(comp.t, q0, v0)
    err = max(np.max(np.abs(comp.q - qe)), np.max(np.abs(comp.v - ve)))
    qe, ve = box.exact_solution(lemke.t, q0, v0)
    err_lemke = max(np.max(np.abs(lemke.q - qe)), np.max(np.abs(lemke.v - ve)))
    assert err == pytest.approx(err_lemke, rel=1e-3)
    assert err < 0.02 * box.stopping_distance(v0)
    np.testing.assert_allclose(comp.v, lemke.v, rtol=0, atol=1e-9)


def test_warm_start_resumes_after_a_handback():
    # with the warm start on, a failed step leaves no support to start from,
    # so with one pivot every step fails too; a limit that lets Lemke finish
    # restores the normal path
    box = SlidingBox(mu=0.4)
    h = 0.01
    r = _run(box, h, 60, lemke_max_iter=1)
    assert r.success and r.stats["fallbacks"] == 60 and r.stats["warm_starts"] == 0
    r = _run(box, h, 60, lemke_max_iter=20)
    assert r.success and r.stats["fallbacks"] == 0 and r.stats["warm_starts"] >= 55


def test_pivot_limit_with_forced_lemke_is_an_lcp_error_on_both_paths():
    box = SlidingBox(mu=0.4)
    for fast in (False, True):
        r = _run(box, 0.01, 10, lcp_method="lemke", lemke_max_iter=1, fast=fast)
        # simulate turns the LCPError into the status that names it
        assert r.status == -3 and r.stats["steps"] == 0
        assert r.message.startswith("contact problem at t = 0.0 not solved: Iteration limit")


def test_pivot_limit_option_is_checked():
    box = SlidingBox()
    q0, v0 = box.initial_state()
    with pytest.raises(InputError, match=r"`lemke_max_iter` must be an integer >= 1"):
        MoreauJean(box, 0.0, q0, v0, 1.0, h=0.01, lemke_max_iter=0)
    with pytest.raises(InputError, match=r"`lemke_max_iter` limits Lemke's pivots"):
        MoreauJean(box, 0.0, q0, v0, 1.0, h=0.01, lemke_max_iter=5, lcp_method="qp")
    assert mj.LCP_METHODS == ("auto", "lemke", "qp")


# -- the regime solve where regimes change in every order -----------------------------------

TUMBLES = {
    # tilted and spinning, lands on one corner, slips, lands on both, one corner sticks
    # first, stops: runs of regimes (0,0) (2,0) (2,2) (2,3) (3,3); theta stays below 0.47
    # (a faster spin turns the box past pi/2, out of its model: two bottom corners)
    "tumble": (SlidingBox(mu=0.3), [0.0, 0.4, -0.25], [-1.5, 0.0, 2.2]),
    # the second corner bounces (e = 0.3) before the box slides on both and stops:
    # (1,0) and (1,1) alternate, one (3,0) step
    "bouncing-corner": (SlidingBox(mu=0.5, restitution=0.3), [0.0, 0.3, 0.05], [1.5, 0.0, 0.5]),
    # one corner slips, then both, then the box sticks: (0,0) (0,2) (2,2) (3,3)
    "settle": (SlidingBox(mu=0.5), [0.0, 0.27, 0.05], [-1.0, 0.0, -1.0]),
}


@pytest.mark.parametrize("name", sorted(TUMBLES))
def test_regime_solve_where_regimes_change(name):
    # the regime solve must refuse every step where a regime changes (Lemke
    # decides there) and give an LCP solution everywhere else
    sc, q0, v0 = TUMBLES[name]
    q0, v0 = np.array(q0), np.array(v0)
    h = 0.002
    n = 3000
    opts = dict(h=h, save_every=1)
    warm = simulate(sc, (0.0, n * h), q0, v0, "moreau-jean", **opts)
    cold = simulate(sc, (0.0, n * h), q0, v0, "moreau-jean", lcp_warm_start=False, **opts)
    gen = simulate(sc, (0.0, n * h), q0, v0, "moreau-jean", fast=False, **opts)
    for r in (warm, cold, gen):
        assert r.success, r.message
    reg = warm.regime[1:]
    changes = int(np.sum(np.any(reg[1:] != reg[:-1], axis=1)))
    assert changes >= 3
    assert np.sum(np.all(reg == 3, axis=1)) >= 500          # ends at rest on both corners
    two = warm.stats["lcp_solves"] - warm.stats["direct_solves"]
    assert two >= 1000
    # measured: every two-contact step but those at a change of regime (1973 of 1976,
    # 2626 of 2637, 2801 of 2804)
    assert warm.stats["warm_starts"] >= two - 2 * changes - 1
    assert cold.stats["warm_starts"] == 0
    assert warm.stats["pivots"] < 0.2 * cold.stats["pivots"]
    # A sliding contact's friction lies on the cone. The regime solve puts it there to
    # rounding (measured 3e-12); Lemke's answers on these LCPs (two contacts with nearly
    # equal tangential rows: dependent columns) are off by up to 1.3e-7 of mu f_N, within
    # its certification, and are then labelled "stick" while sliding at 1 m/s.
    slide = (warm.regime == 1) | (warm.regime == 2)
    on_cone = np.abs(warm.force_T[slide]) / (sc.mu[0] * warm.force_N[slide])
    assert np.max(np.abs(on_cone - 1.0)) <= 1e-11
    for ref in (cold, gen):
        # the motions agree to the accuracy of Lemke's answers (measured <= 3.5e-9)
        np.testing.assert_allclose(warm.q, ref.q, rtol=0, atol=1e-8)
        np.testing.assert_allclose(warm.v, ref.v, rtol=0, atol=1e-8)
        # and so do the regimes, but where Lemke's friction is within its error of the cone
        ratio = np.abs(ref.force_T) / np.maximum(sc.mu[0] * ref.force_N, 1e-300)
        differ = ref.regime != warm.regime
        assert not np.any(differ & (np.abs(ratio - 1.0) > 1e-6))


def test_the_generic_step_warm_starts_the_ties_lemke_would_finish_exactly():
    # the bidirectional drive from its initial state: both rods stick at the cone's edge, a
    # tie that Lemke's path would finish in exact arithmetic, so the generic step took the
    # QP on such steps (78 of the first 500). With the support of the step before it takes
    # that point, checked on the data, and follows the compiled loop as closely as before
    sc, h, n = BidirectionalDrive(), TWO_PI / 1000, 400
    slow = _run(sc, h, n, fast=False, save_every=n)
    fast = _run(sc, h, n, save_every=n)
    assert slow.stats["fallbacks"] == 0
    assert slow.stats["warm_starts"] >= 1
    assert slow.stats["lcp_solves"] == n
    np.testing.assert_allclose(slow.q[-1], fast.q[-1], rtol=0, atol=1e-14)
    np.testing.assert_allclose(slow.v[-1], fast.v[-1], rtol=0, atol=1e-14)


@pytest.mark.parametrize("scheme", ["schatzman-paoli", "nonsmooth-generalized-alpha",
                                    "time-discontinuous-galerkin", "moreau-jean-projected"])
def test_every_scheme_s_generic_step_warm_starts_those_ties(scheme):
    # the same ties in the other schemes' generic steps (before: 70 of 300 Schatzman–Paoli
    # steps and 481 of 889 generalized-alpha problems went to the QP); each place a step
    # solves a problem keeps its own memory (TimeStepping._lcp_warm)
    sc, h, n = BidirectionalDrive(), TWO_PI / 1000, 150
    q0, v0 = sc.initial_state()
    slow = simulate(sc, (0.0, n * h), q0, v0, scheme, h=h, save_every=n, fast=False)
    fast = simulate(sc, (0.0, n * h), q0, v0, scheme, h=h, save_every=n)
    assert slow.stats["fallbacks"] == 0
    assert slow.stats["warm_starts"] >= 1
    np.testing.assert_allclose(slow.q[-1], fast.q[-1], rtol=0, atol=1e-14)
    np.testing.assert_allclose(slow.v[-1], fast.v[-1], rtol=0, atol=1e-14)
