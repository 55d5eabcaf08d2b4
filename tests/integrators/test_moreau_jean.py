"""Moreau–Jean on small scenes with exact solutions (generic Python path)."""

import math
import re

import numpy as np
import pytest

import moreau.integrators.moreau_jean as mjmod
from moreau.errors import InputError, MoreauError
from moreau.integrators import INTEGRATORS, simulate
from moreau.integrators.moreau_jean import (
    MoreauJean,
    classify_impulse,
    one_contact_impulse,
    one_contact_residual,
)
from moreau.lcp import build_friction_lcp, friction_impulses, lcp_residual, solve_lcp
from moreau.regimes import Regime
from moreau.scenes import make_scene
from moreau.model.scene import Scene

F, P, N, S = (int(r) for r in (Regime.FLIGHT, Regime.POSITIVE, Regime.NEGATIVE, Regime.STICK))


class PointOnGround(Scene):
    """Unit point mass (x, y) over the ground y >= 0; gravity g, horizontal push fx."""

    ndof = 2

    def __init__(self, mu=0.5, e=0.0, g=1.0, fx=0.0):
        self.mu = np.array([mu])
        self.restitution = np.array([e])
        self.g, self.fx = g, fx

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([self.fx, -self.g])

    def gaps(self, q, t):
        return np.array([q[1]])

    def contact_jacobians(self, q, t):
        WT = np.array([[1.0, 0.0]]) if self.mu[0] > 0 else np.zeros((0, 2))
        return np.array([[0.0, 1.0]]), np.zeros(1), WT, np.zeros(len(WT))


class TwoPoints(Scene):
    """Two independent unit point masses on the ground: two contacts, so the LCP path runs.

    ``far`` lifts the second contact out of reach (its gap is y + far), which
    leaves the first point's motion identical to :class:`PointOnGround`.
    """

    ndof = 4

    def __init__(self, mu=(0.5, 0.0), g=1.0, far=0.0):
        self.mu = np.array(mu, float)
        self.restitution = np.zeros(2)
        self.g, self.far = g, far

    def mass(self, q):
        return np.eye(4)

    def forces(self, q, v, t):
        return np.array([0.0, -self.g, 0.0, -self.g])

    def gaps(self, q, t):
        return np.array([q[1], q[3] + self.far])

    def contact_jacobians(self, q, t):
        WN = np.array([[0, 1.0, 0, 0], [0, 0, 0, 1.0]])
        rows = [np.array([1.0, 0, 0, 0]), np.array([0, 0, 1.0, 0])]
        WT = np.array([rows[i] for i in self.frictional_index]).reshape(-1, 4)
        return WN, np.zeros(2), WT, np.zeros(len(WT))


class Oscillator(Scene):
    """Undamped linear oscillator ``x'' = -w^2 x``, no contact."""

    ndof = 1
    mu = np.zeros(0)
    restitution = np.zeros(0)

    def __init__(self, w):
        self.w = w

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return -self.w ** 2 * q

    def force_jacobians(self, q, v, t):
        return np.array([[-self.w ** 2]]), np.zeros((1, 1))


class Ring(Scene):
    """Frictionless unit point mass held inside a ring of radius 1: g = 1 - |x| >= 0."""

    ndof = 2
    mu = np.zeros(1)
    restitution = np.zeros(1)

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.zeros(2)

    def gaps(self, q, t):
        return np.array([1.0 - math.hypot(q[0], q[1])])

    def contact_jacobians(self, q, t):
        r = math.hypot(q[0], q[1])
        return -np.array([[q[0] / r, q[1] / r]]), np.zeros(1), np.zeros((0, 2)), np.zeros(0)


class SkewContact(Scene):
    """One contact whose Delassus matrix breaks the Painlevé condition (W_NN = 1, W_NT = 2, mu = 1)."""

    ndof = 2
    mu = np.array([1.0])
    restitution = np.zeros(1)

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([-1.0, 0.0])

    def gaps(self, q, t):
        return np.array([q[0]])

    def contact_jacobians(self, q, t):
        return np.array([[1.0, 0.0]]), np.zeros(1), np.array([[2.0, 1.0]]), np.zeros(1)


def run(scene, t1, q0, v0, **opts):
    return simulate(scene, (0.0, t1), q0, v0, "moreau-jean", **opts)


# -- registration, options ----------------------------------------------------------

def test_registered_under_its_name():
    assert INTEGRATORS["moreau-jean"] is MoreauJean


@pytest.mark.parametrize("opts, match", [
    ({}, r"`h` \(the time step\) is required"),
    ({"h": -0.1}, r"`h` must be > 0"),
    ({"h": 0.1, "theta": 0.4}, r"`theta` must be in \[0.5, 1.0\]"),
    ({"h": 0.1, "theta": float("nan")}, r"`theta` must be finite"),
    ({"h": 0.1, "lcp_method": "simplex"},
     r"`lcp_method` must be one of \['auto', 'lemke', 'qp', 'nsgs', 'apgd'\]"),
    ({"h": 0.1, "projection": "yes"}, r"`projection` must be True or False"),
    ({"h": 0.1, "save_every": 0}, r"`save_every` must be an integer >= 1"),
    ({"h": 0.1, "fast": True}, r"`fast=True` needs a scene with a compiled model"),
    ({"h": 0.1, "closed0": [True, False]}, r"`closed0` must be a bool or 1 bools"),
    ({"h": 0.1, "fast": "maybe"}, r"`fast` must be 'auto', True or False"),
])
def test_bad_options_are_rejected_before_any_work(opts, match):
    with pytest.raises(InputError, match=match):
        run(PointOnGround(), 1.0, [0, 0], [1, 0], **opts)


def test_bad_scene_coefficients_are_rejected():
    sc = PointOnGround()
    sc.restitution = np.array([1.5])
    with pytest.raises(InputError, match=r"`scene.restitution` must lie in \[0, 1\]"):
        run(sc, 1.0, [0, 0], [1, 0], h=0.1)


# -- exact solutions on the ground ------------------------------------------------------

def test_sliding_block_velocity_is_exact_and_stops_in_stick():
    # v' = -mu g while sliding: the LCP gives v_k = 1 - k h mu g exactly, then stick
    h = 1.0 / 64
    res = run(PointOnGround(mu=0.5), 3.0, [0, 0], [1, 0], h=h)
    assert res.success and res.scheme == "moreau-jean"
    t = res.t
    np.testing.assert_allclose(res.v[:, 0], np.maximum(1.0 - 0.5 * t, 0.0), atol=1e-13)
    np.testing.assert_allclose(res.v[:, 1], 0.0, atol=1e-15)
    slipping = t[1:] <= 2.0 + 1e-9        # the step ending at t = 2 still slides
    assert np.all(res.regime[1:][slipping, 0] == P)
    assert np.all(res.regime[1:][~slipping, 0] == S)
    # impulse / step = Coulomb force while slipping, zero friction in stick
    np.testing.assert_allclose(res.force_N[1:, 0], 1.0, rtol=1e-13)
    np.testing.assert_allclose(res.force_T[1:][slipping, 0], -0.5, rtol=1e-13)
    np.testing.assert_allclose(res.force_T[1:][~slipping, 0], 0.0, atol=1e-13)
    assert res.stats["lcp_solves"] == res.stats["direct_solves"] == len(t) - 1
    assert res.stats["max_residual"] < 1e-14 and res.stats["max_penetration"] == 0.0


def test_sliding_block_position_converges_at_order_one():
    # exact rest position 1 (x = t - t^2/4 until t = 2); backward Euler in q gives O(h)
    errs = []
    hs = [1 / 16, 1 / 32, 1 / 64, 1 / 128]
    for h in hs:
        res = run(PointOnGround(mu=0.5), 2.5, [0, 0], [1, 0], h=h, save_every=10**6)
        errs.append(abs(res.q[-1, 0] - 1.0))
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 0.95 < order < 1.05
    assert errs[-1] < 5e-3


def test_negative_slip_and_stick_below_the_friction_limit():
    res = run(PointOnGround(mu=0.5), 1.0, [0, 0], [-1, 0], h=0.05)
    assert np.all(res.regime[1:, 0] == N)
    np.testing.assert_allclose(res.force_T[1:, 0], 0.5, rtol=1e-13)
    np.testing.assert_allclose(res.slip_velocity[1:, 0], -1.0 + 0.5 * res.t[1:], atol=1e-13)
    # a push 0.3 < mu g = 0.5 is held by static friction; 0.8 slides at 0.3
    held = run(PointOnGround(mu=0.5, fx=0.3), 1.0, [0, 0], [0, 0], h=0.05)
    assert np.all(held.regime[1:, 0] == S)
    np.testing.assert_allclose(held.force_T[1:, 0], -0.3, rtol=1e-13)
    np.testing.assert_allclose(held.v[:, 0], 0.0, atol=1e-15)
    pushed = run(PointOnGround(mu=0.5, fx=0.8), 1.0, [0, 0], [0, 0], h=0.05)
    assert np.all(pushed.regime[1:, 0] == P)
    np.testing.assert_allclose(pushed.v[:, 0], 0.3 * pushed.t, atol=1e-13)


def test_newton_impact_restitutes_the_approach_velocity():
    # dropped from height 1 (g = 1): the impact step ends at -e times the
    # normal velocity the step started with
    h = 1e-2
    res = run(PointOnGround(mu=0.0, e=0.5), 3.0, [0, 1.0], [0.3, 0.0], h=h)
    vy, reg = res.v[:, 1], res.regime[:, 0]
    k = int(np.flatnonzero(reg[1:] != F)[0]) + 1          # first sample after an impulse
    assert reg[k] == S                                      # closed frictionless contact
    assert vy[k] == pytest.approx(-0.5 * vy[k - 1], rel=1e-13)
    assert np.all(reg[1:k] == F) and reg[k + 1] == F         # one-step impact, then flight
    np.testing.assert_allclose(res.v[:, 0], 0.3, rtol=1e-14)  # frictionless: no tangential impulse
    assert res.stats["lcp_solves"] < len(res.t) / 4          # no contact problem in flight


def test_flight_solves_no_contact_problem():
    res = run(PointOnGround(), 0.5, [0, 10.0], [0, 0], h=0.01)
    assert np.all(res.regime[:, 0] == F)
    assert res.stats["lcp_solves"] == 0
    np.testing.assert_allclose(res.v[:, 1], -res.t, atol=1e-13)


# -- several contacts: the LCP path ---------------------------------------------------------

def test_lcp_path_with_a_frictionless_contact():
    res = run(TwoPoints(mu=(0.5, 0.0)), 1.0, [0, 0, 0, 0], [1, 0, 2, 0], h=0.05)
    assert res.success
    np.testing.assert_allclose(res.v[:, 0], 1.0 - 0.5 * res.t, atol=1e-12)
    np.testing.assert_allclose(res.v[:, 2], 2.0, atol=1e-12)
    assert np.all(res.regime[1:] == [P, S])
    np.testing.assert_allclose(res.slip_velocity[:, 1], 0.0)   # no tangential row
    st = res.stats
    assert st["lcp_solves"] == 20 and st["direct_solves"] == 0
    assert st["pivots"] >= 20 and st["fallbacks"] == 0 and st["max_residual"] < 1e-12


def test_lcp_path_matches_the_one_contact_path():
    # the second contact never closes, so both scenes move alike; forced to
    # Lemke, the first runs the LCP every step, the second the enumeration
    # (with "auto" a step with one active contact takes the enumeration too)
    h = 1.0 / 32
    two = run(TwoPoints(mu=(0.5, 0.3), far=10.0), 3.0, [0, 0, 0, 0], [1, 0, 0, 0], h=h,
              lcp_method="lemke")
    one = run(PointOnGround(mu=0.5), 3.0, [0, 0], [1, 0], h=h)
    assert two.stats["direct_solves"] == 0 and two.stats["lcp_solves"] == len(one.t) - 1
    auto = run(TwoPoints(mu=(0.5, 0.3), far=10.0), 3.0, [0, 0, 0, 0], [1, 0, 0, 0], h=h)
    assert auto.stats["direct_solves"] == auto.stats["lcp_solves"] == len(one.t) - 1
    np.testing.assert_allclose(auto.q[:, :2], one.q, atol=1e-13)
    np.testing.assert_allclose(two.q[:, :2], one.q, atol=1e-13)
    np.testing.assert_allclose(two.v[:, :2], one.v, atol=1e-13)
    np.testing.assert_array_equal(two.regime[:, 0], one.regime[:, 0])


def _random_contact(rng):
    while True:
        A = rng.normal(size=(2, 2))
        W = A @ A.T + 0.05 * np.eye(2)
        mu = rng.uniform(0.0, 1.5)
        if W[0, 0] - mu * abs(W[0, 1]) > 0.05 * W[0, 0]:
            return W, rng.normal(size=2), mu, rng.uniform(0, 1), rng.normal()


def test_enumeration_equals_the_lcp_on_random_data():
    rng = np.random.default_rng(12345)
    seen = set()
    for _ in range(3000):
        W, u, mu, e, vpre = _random_contact(rng)
        pN, pT = one_contact_impulse(W, u, mu, e, vpre)
        M, q, layout = build_friction_lcp(W, u, [mu], e, [vpre])
        r = solve_lcp(M, q, method="lemke")
        assert r.success
        zN, zT = friction_impulses(r.z, layout)
        scale = 1.0 + abs(zN[0])
        assert abs(pN - zN[0]) <= 1e-10 * scale and abs(pT - zT[0]) <= 1e-10 * scale
        # the shortcut residual is the LCP's own residual at the same point; both are
        # relative, and below 1e-15 they are rounding that each sums in its own order
        # (seen: 1.8e-16 against 4.4e-17)
        z = np.array([pN, max(pT, 0), max(-pT, 0), abs(u[1] + W[1] @ [pN, pT])])
        assert one_contact_residual(*W.ravel(), *u, mu, e, vpre, pN, pT) == pytest.approx(
            lcp_residual(M, q, z), rel=1e-9, abs=1e-15)
        seen.add(int(classify_impulse(pN, pT, mu)))
    assert seen == {F, P, N, S}           # every case was exercised


def test_enumeration_frictionless_and_restitution():
    assert one_contact_impulse([[2.0]], [-1.0], 0.0) == (0.5, 0.0)
    # approach at -2 with e = 0.5 must leave at +1: u_free = -1 needs pN = (1 + 1) / W
    assert one_contact_impulse([[2.0]], [-1.0], 0.0, e=0.5, vN_pre=-2.0) == (1.0, 0.0)
    # a separating pre-velocity is not restituted
    assert one_contact_impulse([[2.0]], [1.0], 0.0, e=0.5, vN_pre=3.0) == (0.0, 0.0)


def test_painleve_violation_is_a_tangential_impact_or_a_stop():
    # W_NN - mu W_NT = -1: positive slip has no solution; the step's answer is the jam,
    # the stick p = -W^-1 (uN, uT) = (7, -3) (|pT| <= mu pN)
    W = [[1.0, 2.0], [2.0, 5.0]]
    assert one_contact_impulse(W, [-1.0, 1.0], 1.0) == (pytest.approx(7.0), pytest.approx(-3.0))
    res = run(SkewContact(), 1.0, [0.0, 0.0], [0.0, 1.0], h=0.1)
    assert res.status == 0 and res.stats["tangential_impact_times"] == [0.0]
    assert res.regime_letters()[1] == "S" and res.v[1][1] * 1.0 + 2.0 * res.v[1][0] == \
        pytest.approx(0.0, abs=1e-14)        # the slip WT v = 2 v0 + v1 stopped
    res = run(SkewContact(), 1.0, [0.0, 0.0], [0.0, 1.0], h=0.1, painleve="stop")
    assert res.status == -1 and not res.success
    assert re.search(r"Painlevé condition W_NN - mu \|W_NT\| > 0 violated .* sliding the "
                     r"paradoxical way", res.message) and len(res.t) == 0


def test_harmless_slip_direction_runs_despite_the_painleve_condition():
    # same W, sliding the other way (W_NN + mu W_NT = 3 > 0): one solution, stick
    W = np.array([[1.0, 2.0], [2.0, 5.0]])
    pN, pT = one_contact_impulse(W, [-0.1, -0.2], 1.0)
    assert (pN, pT) == (pytest.approx(0.1), pytest.approx(0.0, abs=1e-15))
    M, q, layout = build_friction_lcp(W, [-0.1, -0.2], [1.0], 0.0)
    zN, zT = friction_impulses(solve_lcp(M, q, method="lemke").z, layout)
    assert (zN[0], zT[0]) == (pytest.approx(pN), pytest.approx(pT, abs=1e-12))
    res = run(SkewContact(), 1.0, [0.0, 0.0], [0.0, 0.0], h=0.1)
    assert res.status == 0 and set(res.regime_letters()) == {"S"}


def test_classification_thresholds():
    assert classify_impulse(0.0, 0.0, 0.3) == Regime.FLIGHT
    assert classify_impulse(1.0, -0.3 * (1 - 1e-12), 0.3) == Regime.POSITIVE
    assert classify_impulse(1.0, 0.3, 0.3) == Regime.NEGATIVE
    assert classify_impulse(1.0, 0.3 * (1 - 1e-8), 0.3) == Regime.STICK
    assert classify_impulse(1.0, 0.0, 0.0) == Regime.STICK


# -- smooth part: implicit theta-scheme -------------------------------------------------

def _energy(res, w):
    return 0.5 * res.v[:, 0] ** 2 + 0.5 * w ** 2 * res.q[:, 0] ** 2


def test_theta_half_conserves_oscillator_energy_and_is_second_order():
    w = 2.0
    res = run(Oscillator(w), 50.0, [1.0], [0.0], h=0.3, theta=0.5)
    np.testing.assert_allclose(_energy(res, w), 2.0, rtol=1e-12)
    errs = {}
    for theta in (0.5, 1.0):
        e = []
        for n in (64, 128, 256):
            r = run(Oscillator(w), 2.0, [1.0], [0.0], h=2.0 / n, theta=theta, save_every=10**6)
            e.append(abs(r.q[-1, 0] - math.cos(4.0)))
        errs[theta] = np.log2(np.array(e[:-1]) / np.array(e[1:]))
    np.testing.assert_allclose(errs[0.5], 2.0, atol=0.05)
    np.testing.assert_allclose(errs[1.0], 1.0, atol=0.1)



class WallOscillator(Oscillator):
    """The oscillator with a frictionless wall at ``x = -d`` (gap ``x + d``)."""

    mu = np.zeros(1)

    def __init__(self, w, d, e):
        super().__init__(w)
        self.d = d
        self.restitution = np.array([e])

    def gaps(self, q, t):
        return np.array([q[0] + self.d])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)


# Energy across impacts (the property Acary, ZAMM 2016, studies), derived here for one
# frictionless contact with a constant WN and a linear or constant force, M = 1:
# v+ = v + h f_mid + P and q+ = q + h v_mid (theta = 1/2: v_mid = (v + v+)/2, and f_mid =
# (f(q) + f(q+))/2, which for f = -w^2 q or a constant is minus the potential's
# difference quotient). Then E+ - E = v_mid (v+ - v) + (V(q+) - V(q)) = v_mid P: the
# only work is the impulse's on the mean velocity. Newton's law U+ = -e U where P > 0
# makes it (1 - e) U P / 2 <= 0, zero for e = 1; theta = 1 adds -(v+ - v)^2 / 2.
# The algebra holds for any h: the oscillator (a Python scene, stepped in Python) takes
# h = 4e-3, a quarter of the steps of h = 1e-3 with the same 10 impacts (measured: energy
# kept to 1e-15, the lossy run ends at 0.125 and the theta = 1 run at 0.41 of 0.5)
@pytest.mark.parametrize("scene, q0, t1, h, energy", [
    (lambda e: make_scene("bouncing-ball", restitution=e), None, 20.0, 1e-3,
     lambda q, v: 0.5 * v ** 2 + q),
    (lambda e: WallOscillator(1.0, 0.5, e), [1.0], 40.0, 4e-3,
     lambda q, v: 0.5 * v ** 2 + 0.5 * q ** 2),
], ids=["ball", "wall-oscillator"])
def test_theta_half_keeps_the_energy_across_elastic_impacts_and_loses_it_otherwise(
        scene, q0, t1, h, energy):
    elastic = scene(1.0)
    q0 = elastic.initial_state()[0] if q0 is None else np.array(q0)
    v0 = np.zeros(1)
    r = run(elastic, t1, q0, v0, h=h, theta=0.5)
    impacts = int(np.count_nonzero(r.force_N[:, 0] > 0))
    assert impacts >= 5                                  # the property is across impacts
    E = energy(r.q[:, 0], r.v[:, 0])
    assert np.max(np.abs(E - E[0])) < 1e-12 * max(1.0, abs(E[0])) * math.sqrt(len(E))
    # e < 1: the impulse's work (1 - e) U P / 2 is a loss at every impact (U <= 0). The one
    # exception the derivation allows: a contact still penetrated (theta = 1/2 lets the gap
    # go negative) but already separating, U > 0, where Newton's law still pushes and
    # v_mid P > 0 (measured once on the ball, +1.2e-7, at the end of its Zeno sequence)
    lossy = run(scene(0.5), t1, q0, v0, h=h, theta=0.5)
    El = energy(lossy.q[:, 0], lossy.v[:, 0])
    gains = np.flatnonzero(np.diff(El) > 1e-12)
    assert np.all((lossy.v[gains, 0] > 0.0) & (lossy.gap[gains + 1, 0] < 0.0))
    assert El[-1] < El[0] - 1e-3
    # theta = 1 with e = 1 loses energy on the whole. On the ball (constant force f = -1,
    # q+ - q = h v_theta, v_theta = (1 - theta) v + theta v+) the same algebra gives
    # E+ - E = v_mid P - (theta - 1/2) h f (v+ - v): a loss of h^2 / 2 on every free step
    # and a gain of about h |U| on an impact step; over a flight the free steps win
    damped = run(elastic, t1, q0, v0, h=h, theta=1.0)
    Ed = energy(damped.q[:, 0], damped.v[:, 0])
    assert Ed[-1] < Ed[0] - 1e-5


def test_stiff_spring_with_a_huge_step_stays_bounded():
    # w h = 1000: explicit schemes explode, theta = 1 damps, theta = 1/2 keeps the energy
    w = 1e4
    damped = run(Oscillator(w), 1.0, [1.0], [0.0], h=0.1, theta=1.0)
    e = _energy(damped, w)
    assert np.all(np.diff(e) <= 0.0) and e[-1] < 1e-10 * e[0]
    kept = run(Oscillator(w), 1.0, [1.0], [0.0], h=0.1, theta=0.5)
    np.testing.assert_allclose(_energy(kept, w), 0.5 * w ** 2, rtol=1e-10)


# -- drift and projection -----------------------------------------------------------------

def test_projection_removes_the_drift_of_a_curved_contact():
    # uniform circular motion inside a ring: velocity-level contact lets the
    # point drift outward by ~h^2 V^2 / 2 per step; projection puts it back
    h, t1 = 0.01, 4.0
    free = run(Ring(), t1, [1.0, 0.0], [0.0, 1.0], h=h)
    proj = run(Ring(), t1, [1.0, 0.0], [0.0, 1.0], h=h, projection=True)
    pen = -free.gap[:, 0]
    k = len(pen) // 2
    assert pen[-1] == pytest.approx(2 * pen[k], rel=0.05)   # grows linearly in time
    assert free.stats["max_penetration"] == pytest.approx(t1 / h * h * h / 2, rel=0.05)
    assert proj.stats["max_penetration"] < 1e-14
    np.testing.assert_allclose(np.hypot(proj.q[:, 0], proj.q[:, 1]), 1.0, atol=1e-14)
    # the normal force of circular motion is V^2 / R (the first step starts
    # tangent to the ring and needs no impulse); the velocity-level scheme
    # loses speed like cos(h V)^k, the known dissipation of Moreau-Jean
    speed = np.hypot(proj.v[:, 0], proj.v[:, 1])
    np.testing.assert_allclose(proj.force_N[2:, 0], speed[2:] ** 2, rtol=1e-3)
    assert speed[-1] == pytest.approx(math.cos(h) ** (t1 / h), rel=1e-3)
    assert proj.stats["projection_iterations"] >= len(proj.t) - 1


# -- result object --------------------------------------------------------------------

def test_result_shapes_and_save_every():
    res = run(TwoPoints(), 1.0, [0, 0, 0, 0], [1, 0, 2, 0], h=0.1, save_every=3)
    n = len(res.t)
    np.testing.assert_allclose(res.t, [0.0, 0.3, 0.6, 0.9, 1.0], atol=1e-15)
    assert res.q.shape == res.v.shape == (n, 4)
    for a in (res.regime, res.force_N, res.force_T, res.slip_velocity, res.gap):
        assert a.shape == (n, 2)
    assert res.stats["steps"] == 10 and res.status == 0


def test_last_step_is_cut_to_the_end_of_the_interval():
    res = run(Oscillator(1.0), 1.05, [1.0], [0.0], h=0.1)
    assert res.t[-1] == 1.05 and len(res.t) == 12
    assert res.t[-2] == pytest.approx(1.0, abs=1e-15)


def test_non_finite_state_is_reported_not_returned():
    class Blowup(Oscillator):
        def forces(self, q, v, t):
            return np.array([np.inf])

    res = run(Blowup(1.0), 1.0, [1.0], [0.0], h=0.1)
    assert res.status == -5 and np.all(np.isfinite(res.q))
    assert "non-finite" in res.message and res.stats["steps"] == 0


def test_module_docstring_example_runs():
    import doctest
    fails, _ = doctest.testmod(mjmod, verbose=False)
    assert fails == 0


@pytest.mark.parametrize("W, u, mu", [
    ([[-4.8e17, 0.0], [0.0, 1.0]], [-1.0, 0.5], 0.3),     # a diverged step's Delassus entry
    ([[np.inf, 0.0], [0.0, 1.0]], [-1.0, 0.5], 0.3),
    ([[1e75, np.nan], [0.0, 1.0]], [-1.0, 0.5], 0.3),
    ([[-1.0]], [-1.0], 0.0),                                # frictionless
    ([[0.0]], [-1.0], 0.0),                                 # a zero contact row
])
def test_a_broken_delassus_entry_is_a_numerical_failure_not_a_painleve_case(W, u, mu):
    # W_NN = w_N M^-1 w_N^T > 0 for every positive definite mass matrix: where it is not,
    # the state or the mass matrix broke down (found on the stress catalogue's stiff
    # flexible rod under SP and TDG, reported as Painlevé with W_NN = -4.8e17, inf, 1e75)
    from moreau.integrators.contact_problem import one_contact_impulse
    with pytest.raises(FloatingPointError, match=r"not a Painlevé case"):
        one_contact_impulse(W, u, mu)


def test_a_genuine_painleve_case_is_still_named_so():
    from moreau.errors import PainleveError
    from moreau.integrators.contact_problem import one_contact_impulse
    # W_NN > 0 but W_NN - mu W_NT < 0, sliding the paradoxical way, on a singular W (the
    # normal and tangential rows dependent): no stick, no slip, no solution
    with pytest.raises(PainleveError, match="discrete Painlevé condition .* singular Delassus"):
        one_contact_impulse([[1.0, 2.0], [2.0, 4.0]], [-1.0, 1.0], 0.9)
    # with W positive definite the same slip has its answer, the jam: p = -W^-1 (uN, uT)
    assert one_contact_impulse([[1.0, 2.0], [2.0, 5.0]], [-1.0, 1.0], 0.9) == (
        pytest.approx(7.0), pytest.approx(-3.0))
