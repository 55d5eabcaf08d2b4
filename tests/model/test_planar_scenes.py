"""Scenes built with the planar builder against a hand-written scene and closed forms."""

import math

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.regimes import Regime
from moreau.scenes import registry
from moreau.scenes.disk_incline import DiskInclineParams, disk_incline, disk_incline_exact
from moreau.scenes.rocking_block import RockingBlock, housner_ratio
from moreau.scenes.rocking_block_built import rocking_block_built


@pytest.mark.parametrize("fast", [True, False])
def test_the_built_block_runs_the_hand_written_block(fast):
    # the same equations in the same variables: Moreau-Jean through the release, the Zeno
    # accumulation of impacts and rest, to rounding
    hand, built = RockingBlock(mu=2.0, tilt=0.1), rocking_block_built(mu=2.0, tilt=0.1)
    q0, v0 = hand.initial_state()
    qb, vb = built.initial_state()
    np.testing.assert_allclose(qb, q0, rtol=0, atol=1e-15)
    assert (built.length, built.time) == (hand.length, hand.time)
    span = (0.0, 4.0) if fast else (0.0, 1.0)
    ra = simulate(hand, span, q0, v0, "moreau-jean", h=2e-3, fast=fast)
    rb = simulate(built, span, q0, v0, "moreau-jean", h=2e-3, fast=fast)
    assert ra.success and rb.success and ra.q.shape == rb.q.shape
    for a, b in ((ra.q, rb.q), (ra.v, rb.v), (ra.force_N, rb.force_N)):
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a))
    # the run went through impacts on both corners
    assert np.max(ra.q[:, 2]) > 0.09 and np.min(ra.q[:, 2]) < -0.01


@pytest.mark.parametrize("width, height", [(0.2, 0.4), (0.2, 1.0)])
def test_housners_ratio_from_the_built_models_impact_law(width, height):
    # at theta = 0, turning about the left corner at w < 0: the landing right corner
    # sticks (no slip, no bounce, e = 0) and the left one lifts. Moreau's impact law on the
    # right corner's rows alone: W v+ = 0, v+ = v- + M^-1 W^T P
    sc = rocking_block_built(width=width, height=height, mu=10.0)
    hand = RockingBlock(width=width, height=height)
    q, v = hand.state_on_corner(1e-300, -0.7)
    q[2] = 0.0
    M = sc.mass(q)
    WN, wN, WT, wT = sc.contact_jacobians(q, 0.0)
    assert sc.gaps(q, 0.0) == pytest.approx([0.0, 0.0], abs=1e-15)
    W = np.vstack([WN[1], WT[1]])
    P = -np.linalg.solve(W @ np.linalg.solve(M, W.T), W @ v)
    vp = v + np.linalg.solve(M, W.T @ P)
    alpha = math.atan(width / height)
    assert vp[2] / v[2] == pytest.approx(housner_ratio(alpha), rel=1e-12)
    assert vp[2] / v[2] == pytest.approx(1.0 - 1.5 * math.sin(alpha) ** 2, rel=1e-12)
    # the left corner lifts, the landing corner's impulse pushes and friction holds it
    assert WN[0] @ vp > 0.0 and P[0] > 0.0 and abs(P[1]) <= 10.0 * P[0]


@pytest.mark.parametrize("width, height", [(0.2, 0.4), (0.2, 1.0)])
def test_housners_ratio_through_a_moreau_jean_impact(width, height):
    # falling on the left corner from theta = 0.02 to the impact and past it: the rate
    # before and after, each extrapolated from its own side to the impact time
    sc = rocking_block_built(width=width, height=height, mu=10.0, tilt=0.02)
    q0, v0 = sc.initial_state()
    h = 1e-4
    res = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean", h=h)
    th, w = res.q[:, 2], res.v[:, 2]
    k = int(np.argmax(th <= 0.0))          # first step at or past the impact
    assert k > 0 and np.all(th[k + 1:k + 200] < 0.0)
    # the impact step's own gravity impulse is O(h): linear fits on each side
    before = np.polyval(np.polyfit(res.t[k - 50:k], w[k - 50:k], 1), res.t[k])
    after = np.polyval(np.polyfit(res.t[k + 1:k + 51], w[k + 1:k + 51], 1), res.t[k])
    alpha = math.atan(width / height)
    assert after / before == pytest.approx(1.0 - 1.5 * math.sin(alpha) ** 2, rel=1e-3)
    # (measured: 7.0e-4 and 4.0e-4 at h = 1e-4; 1e-6 and 2e-7 at h = 1e-5)


@pytest.mark.parametrize("mu", [0.5, 0.05])
def test_the_disk_rolls_at_two_thirds_g_sin_alpha(mu):
    # mu = 0.5 >= tan(0.3) / 3: rolling at (2/3) g sin(alpha); mu = 0.05: slipping at
    # g (sin(alpha) - mu cos(alpha)) with r w' = 2 mu g cos(alpha)
    sc = disk_incline(mu=mu, slope=0.3)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 10.0), q0, v0, "moreau-jean", h=1e-2)
    si = sc.to_si(res)
    a = 0.3
    s = -(si["q"][:, 0] * math.cos(a) + si["q"][:, 1] * math.sin(a))
    sd = -(si["v"][:, 0] * math.cos(a) + si["v"][:, 1] * math.sin(a))
    es, esd, ew = disk_incline_exact(DiskInclineParams(mu=mu, slope=0.3), si["t"])
    # velocities exact at every step (constant accelerations: Moreau-Jean's theta-method is
    # exact on them), positions to the scheme's O(h)
    np.testing.assert_allclose(sd, esd, rtol=1e-10)
    np.testing.assert_allclose(si["v"][:, 2], ew, rtol=1e-10)
    assert np.max(np.abs(s - es)) <= 0.6 * 1e-2 * sc.time * np.max(esd)
    assert np.max(np.abs(si["gap"])) <= 1e-12
    # rolling sticks at every step; slipping slides one way (the tangent (n_y, -n_x) points
    # up the slope, the contact point moves down it: negative slip)
    want = Regime.STICK if mu == 0.5 else Regime.NEGATIVE
    assert np.all(res.regime[1:] == want)


def test_the_built_scenes_are_registered_and_checked():
    from moreau.check import check_scene
    for name in ("rocking-block-built", "disk-incline"):
        sc = registry.make_scene(name)
        report = check_scene(sc)
        assert report.ok, report.summary()
        assert report.errors["compiled model"] == 0.0


@pytest.mark.parametrize("scheme, options", [
    ("moreau-jean", {"theta": 0.5}), ("schatzman-paoli", {}), ("nonsmooth-generalized-alpha", {}),
    ("studer-extrapolation", {}), ("time-discontinuous-galerkin", {}), ("event-driven-generic", {})])
def test_every_scheme_runs_the_built_block_as_the_hand_written_one(scheme, options):
    # released at the default tilt, through the first impacts (t = 1.2: the first impact
    # is at 0.77). A fixed-step scheme at one step: to rounding. The adaptive Studer
    # extrapolation chooses its steps from error estimates, which carry the two models'
    # last-bit differences into the step sizes: to 1e-8 (measured 2.6e-9), far inside its
    # tolerance (1e-6)
    from moreau.integrators.base import get_integrator, scheme_options
    hand, built = RockingBlock(), rocking_block_built()
    q0, v0 = hand.initial_state()
    fixed = "h" in (scheme_options(get_integrator(scheme)) or ())
    if fixed:
        options = {"h": 2e-3, **options}
    ra = simulate(hand, (0.0, 1.2), q0, v0, scheme, **options)
    rb = simulate(built, (0.0, 1.2), q0, v0, scheme, **options)
    assert ra.success and rb.success and ra.q.shape == rb.q.shape
    tol = 1e-12 if fixed or scheme == "event-driven-generic" else 1e-8
    for a, b in ((ra.q, rb.q), (ra.v, rb.v)):
        assert np.max(np.abs(a - b)) <= tol * np.max(np.abs(a))
