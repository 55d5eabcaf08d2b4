"""The spatial Coulomb problem: exact cone and polyhedral LCP against closed forms.

The one-contact reference is a sphere (mass m, radius R, I = 2/5 m R^2) on a
plane. Its contact point moves with v + omega x (-R e_z), so the Delassus
matrix is diag(1/m, 1/m + R^2/I, 1/m + R^2/I) = diag(1, 7/2, 7/2) / m, and
with free velocity q = (q_N, q_T) the Coulomb law gives by hand:
lift-off (q_N >= 0): r = 0; otherwise r_N = -m q_N, stick when
|q_T| <= (7/2) mu (-q_N) with r_T = -(2m/7) q_T, else slip with
r_T = -mu r_N q_T / |q_T| and u_T = q_T (1 - (7/2) mu (-q_N) / |q_T|).
"""

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from moreau.contact.cone3d import (
    CONVERGED,
    NOT_CONVERGED,
    build_polyhedral_lcp,
    cone_residual,
    facet_directions,
    local_solve,
    project_cone,
    solve_exact,
    solve_polyhedral,
)
from moreau.errors import InputError

M_SPHERE = 2.0
W_SPHERE = np.diag([1.0, 3.5, 3.5]) / M_SPHERE


def sphere_closed_form(q, mu, m=M_SPHERE):
    qn, qt = q[0], np.asarray(q[1:])
    if qn >= 0:
        return np.zeros(3)
    rn = -m * qn
    if np.linalg.norm(qt) <= 3.5 * mu * (-qn):
        return np.array([rn, *(-(2.0 * m / 7.0) * qt)])
    return np.array([rn, *(-mu * rn * qt / np.linalg.norm(qt))])


def random_problem(rng, nc):
    # W = H M^-1 H^T from a random contact Jacobian with more freedoms than rows
    ndof = 3 * nc + 3
    H = rng.standard_normal((3 * nc, ndof))
    W = H @ np.diag(rng.uniform(0.5, 2.0, ndof)) @ H.T / ndof
    W = 0.5 * (W + W.T)
    q = rng.standard_normal(3 * nc)
    q[0::3] = -np.abs(q[0::3]) * rng.choice([1.0, 1.0, -1.0], nc)
    return W, q, rng.uniform(0.1, 0.8, nc)


@pytest.mark.parametrize("q, case", [
    ((0.3, 1.0, -2.0), "lift-off"),
    ((-1.0, 0.4, -0.3), "stick"),          # |q_T| = 0.5 <= 3.5 * 0.5 * 1
    ((-1.0, 3.0, -4.0), "slip"),            # |q_T| = 5 > 1.75
    ((-0.2, -0.01, 2.5), "slip"),
])
def test_sphere_on_plane_exact_cone_matches_the_closed_form(q, case):
    q = np.array(q)
    mu = 0.5
    ref = sphere_closed_form(q, mu)
    sol = solve_exact(W_SPHERE, q, mu, tol=1e-13)
    assert sol.status == CONVERGED
    np.testing.assert_allclose(sol.r, ref, rtol=0, atol=2e-15)
    np.testing.assert_allclose(local_solve(W_SPHERE, q, mu), ref, rtol=0, atol=2e-15)
    assert sol.residual == pytest.approx(cone_residual(W_SPHERE, q, mu, sol.r), abs=0)
    if case == "slip":
        # the impulse opposes the sliding velocity exactly, and u_T keeps q_T's direction
        rt, ut, qt = sol.r[1:], sol.u[1:], q[1:]
        assert abs(rt[0] * qt[1] - rt[1] * qt[0]) / (np.linalg.norm(rt) * np.linalg.norm(qt)) < 1e-15
        assert rt @ qt < 0
        assert np.linalg.norm(rt) == pytest.approx(mu * sol.r[0], rel=1e-15)
        np.testing.assert_allclose(ut, qt * (1 - 3.5 * mu * (-q[0]) / np.linalg.norm(qt)),
                                   rtol=0, atol=1e-14)
        assert sol.u[0] == pytest.approx(0.0, abs=1e-15)


def test_polyhedral_cone_is_exact_in_stick_and_lift_off_and_in_slip_along_a_facet_edge():
    mu = 0.5
    for d in (4, 8, 16):
        for q in ((0.3, 1.0, -2.0), (-1.0, 0.4, -0.3)):
            sol = solve_polyhedral(W_SPHERE, np.array(q), mu, d=d)
            assert sol.status == CONVERGED
            np.testing.assert_allclose(sol.r, sphere_closed_form(np.array(q), mu), atol=1e-13)
        # sliding against a direction D_k of the polygon: its vertex is on the round cone
        angle = 2 * np.pi * (d // 4 + 1) / d
        q = np.array([-1.0, -4.0 * math.cos(angle), -4.0 * math.sin(angle)])
        sol = solve_polyhedral(W_SPHERE, q, mu, d=d)
        np.testing.assert_allclose(sol.r, sphere_closed_form(q, mu), atol=1e-13)
        assert sol.residual < 1e-13


def _facet_errors(d, mu=0.5, n_angles=360):
    # worst over sliding directions of the angle between the polyhedral and
    # the exact tangential impulse, and of the shortfall |r_T| - mu r_N
    worst_angle = worst_short = 0.0
    for th in np.arange(n_angles) * 2 * np.pi / n_angles + 0.01:
        q = np.array([-1.0, 3.0 * math.cos(th), 3.0 * math.sin(th)])
        ref = sphere_closed_form(q, mu)
        sol = solve_polyhedral(W_SPHERE, q, mu, d=d)
        assert sol.status == CONVERGED
        a, b = sol.r[1:], ref[1:]
        worst_angle = max(worst_angle, abs(math.atan2(a[0] * b[1] - a[1] * b[0], a @ b)))
        worst_short = max(worst_short, (np.linalg.norm(b) - np.linalg.norm(a)) / np.linalg.norm(b))
        assert sol.r[0] == pytest.approx(ref[0], rel=1e-13)        # r_N is exact
    return worst_angle, worst_short


def test_polyhedral_slip_converges_to_the_exact_cone_with_measured_orders():
    ds = np.array([4, 8, 16, 32])
    errs = np.array([_facet_errors(int(d)) for d in ds])
    angle, short = errs[:, 0], errs[:, 1]
    order_angle = -np.polyfit(np.log(ds), np.log(angle), 1)[0]
    order_short = -np.polyfit(np.log(ds), np.log(short), 1)[0]
    # maximal dissipation on a polygon locks the impulse to a vertex over a
    # fan of sliding directions: the direction error is first order in 1/d
    # (measured 0.36, 0.17, 0.079, 0.039 rad), bounded by half a facet, pi/d
    assert np.all(angle <= np.pi / ds)
    assert 0.95 <= order_angle <= 1.15, order_angle
    # the magnitude lies on the polygon, at least cos(pi/d) of the radius: second order
    assert np.all(short <= 1 - np.cos(np.pi / ds) + 1e-14)
    assert 1.8 <= order_short <= 2.2, order_short


def test_random_multi_contact_problems_are_certified_by_both_solvers():
    rng = np.random.default_rng(20261127)
    for _ in range(12):
        W, q, mu = random_problem(rng, int(rng.integers(1, 7)))
        ex = solve_exact(W, q, mu, tol=1e-11)
        assert ex.status == CONVERGED, ex.detail
        assert ex.residual <= 1e-11 * np.linalg.norm(q)
        assert ex.residual == pytest.approx(cone_residual(W, q, mu, ex.r), rel=1e-12, abs=1e-300)
        r = ex.r.reshape(-1, 3)
        assert np.all(np.hypot(r[:, 1], r[:, 2]) <= mu * r[:, 0] * (1 + 1e-12))
        poly = solve_polyhedral(W, q, mu, d=8)
        assert poly.status == CONVERGED, poly.detail
        assert poly.lcp.residual <= 1e-9
        rp = poly.r.reshape(-1, 3)
        # the pyramid is inscribed in the cone, and Signorini holds
        assert np.all(np.hypot(rp[:, 1], rp[:, 2])
                      <= mu * rp[:, 0] * (1 + 1e-12) + 1e-13 * np.abs(rp).max())
        assert np.all(poly.u[0::3] >= -1e-12 * np.abs(q).max())


def test_a_budget_too_small_says_not_converged_with_its_true_residual():
    rng = np.random.default_rng(7)
    W, q, mu = random_problem(rng, 6)
    sol = solve_exact(W, q, mu, tol=1e-12, max_sweeps=1, max_newton=0)
    assert sol.status == NOT_CONVERGED and not sol.success
    assert math.isfinite(sol.residual)
    assert sol.residual == pytest.approx(cone_residual(W, q, mu, sol.r), rel=1e-12)
    assert sol.residual > 1e-12 * np.linalg.norm(q)
    assert sol.iterations == {"sweeps": 1, "newton": 0}
    # the same problem with the default budget converges
    assert solve_exact(W, q, mu, tol=1e-12).status == CONVERGED


def test_frictionless_contact_has_no_tangential_impulse():
    sol = solve_exact(W_SPHERE, np.array([-1.0, 3.0, 4.0]), 0.0)
    np.testing.assert_allclose(sol.r, [M_SPHERE, 0.0, 0.0], atol=1e-15)
    poly = solve_polyhedral(W_SPHERE, np.array([-1.0, 3.0, 4.0]), 0.0, d=4)
    np.testing.assert_allclose(poly.r, [M_SPHERE, 0.0, 0.0], atol=1e-13)


def test_the_lcp_rows_are_the_derived_ones():
    rng = np.random.default_rng(3)
    W, q, mu = random_problem(rng, 2)
    lcp = build_polyhedral_lcp(W, q, mu, d=5)
    D = facet_directions(5)
    z = rng.uniform(0.0, 1.0, lcp.M.shape[0])
    w = lcp.M @ z + lcp.q
    r = lcp.impulses(z)
    u = W @ r + q
    for i in range(2):
        b = 7 * i
        beta, lam = z[b + 1:b + 6], z[b + 6]
        np.testing.assert_allclose(r[3 * i:3 * i + 3], [z[b], *(D @ beta)], rtol=1e-14)
        assert w[b] == pytest.approx(u[3 * i], rel=1e-12)
        np.testing.assert_allclose(w[b + 1:b + 6], lam + D.T @ u[3 * i + 1:3 * i + 3], rtol=1e-12)
        assert w[b + 6] == pytest.approx(mu[i] * z[b] - beta.sum(), rel=1e-12)


def test_cone_projection_against_a_brute_force_minimiser():
    rng = np.random.default_rng(11)
    for _ in range(20):
        x = rng.standard_normal(3)
        mu = rng.uniform(0.1, 2.0)
        p = project_cone(x, mu)
        assert np.hypot(p[1], p[2]) <= mu * p[0] * (1 + 1e-14) + 1e-300
        # the projection's residual is normal to the cone at p: (x - p).p = 0 and
        # (x - p) in the polar cone, mu |t| <= -n
        e = x - p
        assert abs(e @ p) < 1e-14
        assert mu * np.hypot(e[1], e[2]) <= -e[0] + 1e-14


@pytest.mark.parametrize("call, name", [
    (lambda: solve_exact(W_SPHERE, [-1.0, 0.0, 0.0], -0.1), "`mu`"),
    (lambda: solve_polyhedral(W_SPHERE, [-1.0, 0.0, 0.0], 0.5, d=2), "`d`"),
    (lambda: solve_polyhedral(W_SPHERE, [-1.0, 0.0, 0.0], 0.5, d=8.0), "`d`"),
    (lambda: solve_exact(np.eye(4), np.zeros(4), 0.5), "`W`"),
    (lambda: solve_exact(np.eye(3), np.zeros(6), 0.5), "`q`"),
    (lambda: solve_exact(np.eye(6), np.zeros(6), [0.5, 0.5, 0.5]), "`mu`"),
    (lambda: solve_exact(np.array([[1.0, 0.1, 0], [0, 1, 0], [0, 0, 1]]), np.zeros(3), 0.5), "`W`"),
    (lambda: solve_exact(np.diag([1.0, -1.0, 1.0]), np.zeros(3), 0.5), "`W`"),
    (lambda: solve_exact(W_SPHERE, [np.nan, 0.0, 0.0], 0.5), "`q`"),
    (lambda: solve_exact(W_SPHERE, [-1.0, 0.0, 0.0], 0.5, max_sweeps=0), "`max_sweeps`"),
    (lambda: solve_exact(W_SPHERE, [-1.0, 0.0, 0.0], 0.5, tol=0.0), "`tol`"),
])
def test_bad_input_is_refused_by_name(call, name):
    with pytest.raises(InputError, match=name):
        call()


def test_local_solve_on_random_coupled_blocks_meets_the_coulomb_law():
    # W_ii with normal-tangential coupling; slip must oppose the sliding velocity
    rng = np.random.default_rng(99)
    n_slip = 0
    for _ in range(200):
        H = rng.standard_normal((3, 4))
        A = H @ H.T / 4 + 0.05 * np.eye(3)
        b = rng.standard_normal(3) * [1.0, 2.0, 2.0]
        mu = rng.uniform(0.05, 1.0)
        r = local_solve(A, b, mu)
        u = A @ r + b
        assert cone_residual(A, b, mu, r) <= 1e-13 * np.linalg.norm(b)
        ut, rt = u[1:], r[1:]
        if r[0] > 0 and np.linalg.norm(ut) > 1e-9 * np.linalg.norm(b):
            n_slip += 1
            assert abs(u[0]) <= 1e-14 * np.linalg.norm(b)
            assert np.linalg.norm(rt) == pytest.approx(mu * r[0], rel=1e-13)
            cos = rt @ ut / (np.linalg.norm(rt) * np.linalg.norm(ut))
            assert cos == pytest.approx(-1.0, abs=1e-13)
    assert n_slip > 30


def test_slipping_contacts_of_multi_contact_problems_oppose_their_sliding_velocity():
    rng = np.random.default_rng(5)
    for _ in range(10):
        W, q, mu = random_problem(rng, 5)
        sol = solve_exact(W, q, mu, tol=1e-12)
        assert sol.success
        r, u = sol.r.reshape(-1, 3), sol.u.reshape(-1, 3)
        for i in range(5):
            speed = np.linalg.norm(u[i, 1:])
            if r[i, 0] > 1e-8 and speed > 1e-6:
                # |r_T| = mu r_N and r_T = -mu r_N u_T / |u_T|, to the certified residual
                np.testing.assert_allclose(r[i, 1:], -mu[i] * r[i, 0] * u[i, 1:] / speed,
                                           atol=1e-9)


def test_the_cone_option_chooses_the_solver():
    from moreau.contact.cone3d import solve_cone
    q = np.array([-1.0, 3.0, 4.0])
    assert solve_cone(W_SPHERE, q, 0.5).method == "exact"
    assert solve_cone(W_SPHERE, q, 0.5, cone=16).method == "polyhedral-16"
    np.testing.assert_allclose(solve_cone(W_SPHERE, q, 0.5, cone="exact", tol=1e-12).r,
                               sphere_closed_form(q, 0.5), atol=1e-15)
    for bad in ("Exact", 2, True, 8.0, None):
        with pytest.raises(InputError, match="`cone`"):
            solve_cone(W_SPHERE, q, 0.5, cone=bad)


def test_newton_polish_finishes_from_the_gauss_seidel_handover_in_few_steps():
    rng = np.random.default_rng(2)
    for _ in range(6):
        W, q, mu = random_problem(rng, 12)
        plain = solve_exact(W, q, mu, tol=1e-12, max_newton=0, max_sweeps=100_000)
        polished = solve_exact(W, q, mu, tol=1e-12)
        assert plain.success and polished.success
        # measured: 20-69 sweeps alone; 10-34 sweeps to 1e-6, then 1-2 Newton steps
        assert polished.iterations["newton"] <= 3
        assert polished.iterations["sweeps"] < plain.iterations["sweeps"]


def _roll_billiard_ball(cone, h=1e-3, v0=2.0, angle=0.4, mu=0.2, T=0.6):
    # a sphere (m = 1, R = 0.5) launched without spin on a plane, Moreau-Jean
    # steps (theta = 1, e = 0); world-frame v and omega, rows [z, x, y]
    from moreau.contact.cone3d import solve_cone
    m, R, g = 1.0, 0.5, 9.81
    I = 0.4 * m * R * R
    H = np.array([[0, 0, 1, 0, 0, 0], [1, 0, 0, 0, -R, 0], [0, 1, 0, R, 0, 0]], dtype=float)
    Minv = np.diag([1 / m] * 3 + [1 / I] * 3)
    W = H @ Minv @ H.T
    x = np.zeros(2)
    v = np.array([v0 * math.cos(angle), v0 * math.sin(angle), 0.0, 0.0, 0.0, 0.0])
    t_roll = None
    for k in range(int(round(T / h))):
        vf = v + h * np.array([0.0, 0.0, -g, 0.0, 0.0, 0.0])
        sol = solve_cone(W, H @ vf, mu, cone=cone)
        assert sol.success
        v = vf + Minv @ H.T @ sol.r
        x += h * v[:2]
        if t_roll is None and np.linalg.norm(sol.u[1:]) <= 1e-12:
            t_roll = (k + 1) * h
    return x, v, t_roll


def test_a_billiard_ball_rolls_at_five_sevenths_of_its_launch_speed_with_either_cone():
    # closed form: slip decays at (7/2) mu g, so rolling starts at t = 2 v0 / (7 mu g)
    # (0.2913 s) at 5/7 v0; the contact-point angular momentum fixes that final
    # velocity whatever the friction impulses were, the exact cone keeps the path straight
    v0, angle, mu, g = 2.0, 0.4, 0.2, 9.81
    launch = np.array([math.cos(angle), math.sin(angle)])
    x, v, t_roll = _roll_billiard_ball("exact")
    np.testing.assert_allclose(v[:2], 5 / 7 * v0 * launch, rtol=1e-12)
    assert abs(x[0] * launch[1] - x[1] * launch[0]) < 1e-12            # straight path
    assert abs(t_roll - 2 * v0 / (7 * mu * g)) <= 1e-3                  # within one step
    lateral = []
    for d in (4, 8, 16):
        xd, vd, _ = _roll_billiard_ball(d)
        np.testing.assert_allclose(vd[:2], 5 / 7 * v0 * launch, rtol=1e-12)
        lateral.append(abs(xd[0] * launch[1] - xd[1] * launch[0]))
    # the facets bend the path while it slips (measured 2.3e-2, 6.5e-4, 5.9e-4 m;
    # 5.6e-4 at d = 32: the launch angle 0.4 lies 0.007 rad from the vertex
    # 2 pi/16 that d = 16 and 32 share, and the impulse locks to it)
    assert lateral[0] > 1e-2 and lateral[0] > 10 * lateral[1] and min(lateral) > 1e-4


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), mu=st.floats(0.0, 3.0), nc=st.integers(1, 6))
def test_property_both_solvers_certify_and_the_exact_answer_lies_in_the_cone(seed, mu, nc):
    # found by this test: mu = 2.25 made Gauss–Seidel cycle (now: stall
    # detection, Newton); mu = 2.8e-264 made |r_T|^2 underflow (now: hypot)
    rng = np.random.default_rng(seed)
    W, q, _ = random_problem(rng, nc)
    mus = np.full(nc, mu)
    sol = solve_exact(W, q, mus)
    assert sol.success, sol.detail
    assert math.isfinite(sol.residual) and sol.residual <= 1e-10 * np.linalg.norm(q)
    r = sol.r.reshape(-1, 3)
    assert np.all(r[:, 0] >= 0) and np.all(np.hypot(r[:, 1], r[:, 2]) <= mu * r[:, 0] * (1 + 1e-12))
    poly = solve_polyhedral(W, q, mus, d=6)
    assert poly.success, poly.detail


def test_hard_problems_with_large_mu_converge_through_stall_detection_and_the_restart():
    # Gauss–Seidel cycles here (its residual stays at 0.32 for 50 000 sweeps)
    W, q, _ = random_problem(np.random.default_rng(5), 5)
    sol = solve_exact(W, q, np.full(5, 2.25))
    assert sol.success and sol.iterations["sweeps"] < 100, sol.detail
    # Newton from the stalled point fails here; from the polyhedral solution it converges
    rng = np.random.default_rng(17)
    W, q, _ = random_problem(rng, 4)
    mu = np.full(4, 3.0 + 7.0 * rng.random())
    sol = solve_exact(W, q, mu)
    assert sol.success and "restarted from the 16-direction polyhedral" in sol.detail, sol.detail
    assert sol.residual <= 1e-10 * np.linalg.norm(q)


def _solved_found_case(seed, nc, mu_value):
    # a problem a search found: solved, and the residual reported is the one on the data
    W, q, _ = random_problem(np.random.default_rng(seed), nc)
    mu = np.full(nc, mu_value)
    sol = solve_exact(W, q, mu)
    assert sol.success, sol.detail
    assert sol.residual == cone_residual(W, q, mu, sol.r)
    return W, q, mu, sol


def test_a_stick_at_the_cone_s_edge_converges_from_a_finer_polygon():
    # found by the property test: in the answer every contact sticks (one at
    # |r_T| = 0.96 mu r_N), which also solves the 16-gon's LCP, but Lemke finds
    # another solution there with contact 2 slipping; Newton from it (and from
    # the same point at d = 32) stalls at 0.025, Gauss–Seidel at 3.6e-3; at
    # d = 64 Lemke returns the sticking answer itself
    W, q, mu, sol = _solved_found_case(7656, 4, 2.0)
    assert "64-direction polyhedral solution" in sol.detail
    assert sol.residual <= 1e-10 * np.linalg.norm(q)
    r = sol.r.reshape(-1, 3)
    assert np.all(r[:, 0] > 0) and np.all(np.hypot(r[:, 1], r[:, 2]) <= 2.0 * r[:, 0])
    u = sol.u.reshape(-1, 3)
    np.testing.assert_allclose(u, 0.0, rtol=0, atol=1e-9 * np.linalg.norm(q))   # all stick
    assert sol.iterations["newton"] <= 30


def test_the_qp_method_says_it_has_no_formulation_for_the_polyhedral_lcp():
    # M is copositive but not monotone (the row mu r_N - e^T beta has no
    # symmetric partner): the QP path refuses rather than guessing
    q = np.array([-1.0, 3.0, 4.0])
    sol = solve_polyhedral(W_SPHERE, q, 0.5, d=8, method="qp")
    assert not sol.success and sol.status.startswith("The method has no formulation")
    assert sol.residual == pytest.approx(cone_residual(W_SPHERE, q, 0.5, sol.r), abs=0)
    assert math.isfinite(sol.residual) and sol.residual > 0.5


def test_one_contact_s_closed_form_is_lemke_s_answer_on_random_problems():
    # the compiled spatial loop's (and the Python step's) closed form of one contact's
    # polyhedral LCP against Lemke (solve_polyhedral), on random SPD blocks and free
    # velocities: the same impulse where it certifies one, and it certifies most
    from moreau.contact.cone3d import polyhedral_one_contact
    rng = np.random.default_rng(20261128)
    certified = 0
    for k in range(300):
        d = (4, 8, 16)[k % 3]
        A = rng.normal(size=(3, 3))
        W = A @ A.T + 0.1 * np.eye(3) if k % 4 else np.diag([1.0, 3.5, 3.5])
        q = rng.normal(size=3)
        mu = (0.1, 0.5, 1.0, 2.0)[k % 4]
        r = np.zeros(3)
        if polyhedral_one_contact(W, q, mu, facet_directions(d), r):
            certified += 1
            ref = solve_polyhedral(W, q, mu, d)
            assert ref.success
            scale = max(np.max(np.abs(ref.r)), np.max(np.abs(q)) / np.max(np.abs(W)))
            assert np.max(np.abs(r - ref.r)) <= 1e-12 * scale, (k, r, ref.r)
        else:
            # refused (r untouched, for the caller's Lemke): never without coupling
            assert r.tolist() == [0.0, 0.0, 0.0] and W[0, 1] != 0.0
    assert certified >= 125


def test_an_isotropic_block_s_slip_in_closed_form_is_the_sampled_root():
    # a sphere's or a point's block diag(a, b, b) slides against b_T in closed form; the same
    # block with a negligible coupling (1e-300) takes the sampled and refined sliding angle
    rng = np.random.default_rng(37)
    for _ in range(20):
        A = np.diag([rng.uniform(0.5, 2.0), *[rng.uniform(0.5, 4.0)] * 2])
        mu = rng.uniform(0.05, 0.5)
        # |b_T| beyond the stick bound mu A_TT (-b_N) / A_NN, in a random direction
        phi = rng.uniform(0.0, 2.0 * math.pi)
        bn = -rng.uniform(0.1, 1.0)
        size = rng.uniform(1.5, 5.0) * mu * A[1, 1] * -bn / A[0, 0]
        b = np.array([bn, size * math.cos(phi), size * math.sin(phi)])
        nudged = A.copy()
        nudged[0, 1] = nudged[1, 0] = 1e-300
        r, ref = local_solve(A, b, mu), local_solve(nudged, b, mu)
        assert math.hypot(r[1], r[2]) == pytest.approx(mu * r[0], rel=1e-15)   # it slips
        np.testing.assert_allclose(r, ref, rtol=0, atol=2e-15 * np.max(np.abs(ref)))


def _slips_by_enumeration(A, b, mu, n=1 << 15):
    # every slip of one contact from the Coulomb law itself, independently of local_solve:
    # r = rho (1, -mu s) with s = (cos x, sin x), rho from u_N = 0, and u_T parallel to s;
    # the sign changes of s x u_T (times g = A_NN - mu A_NT.s, which keeps it finite) on a
    # grid of n angles, each refined by Brent's method
    from scipy.optimize import brentq

    def parts(x):
        s = np.array([np.cos(x), np.sin(x)])
        g = A[0, 0] - mu * (A[0, 1:] @ s)
        gut = -b[0] * (A[1:, 0][:, None] - mu * A[1:, 1:] @ s) + g * b[1:, None]
        return s, g, gut

    def cross(x):
        s, _, gut = parts(np.atleast_1d(x))
        return s[0] * gut[1] - s[1] * gut[0]

    grid = np.linspace(0.0, 2.0 * np.pi, n + 1)
    f = cross(grid)
    out = []
    for k in np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:])):
        x = brentq(lambda y: float(cross(y)[0]), grid[k], grid[k + 1], xtol=1e-15, rtol=1e-15)
        s, g, gut = parts(np.array([x]))
        if g[0] > 0 and s[:, 0] @ gut[:, 0] >= 0:
            rho = -b[0] / g[0]
            out.append(np.array([rho, *(-mu * rho * s[:, 0])]))
    return out


def _assert_coulomb_law(A, b, mu, r, rtol):
    # the law's cases checked on u = A r + b directly, to rtol of the problem's scale
    u = A @ r + b
    scale = np.linalg.norm(b) + np.linalg.norm(A, 2) * np.linalg.norm(r)
    tol = rtol * scale
    rt, ut = np.hypot(r[1], r[2]), np.hypot(u[1], u[2])
    assert r[0] >= 0 and rt <= mu * r[0] * (1 + 1e-12) and u[0] >= -tol
    if r[0] == 0:
        return "take-off"
    assert abs(u[0]) <= tol                                    # Signorini, in contact
    if ut <= tol:
        return "stick"
    assert rt == pytest.approx(mu * r[0], rel=rtol)            # on the cone's edge
    assert r[1:] @ u[1:] == pytest.approx(-rt * ut, rel=rtol)   # against the sliding velocity
    return "slip"


def test_one_contact_slip_under_strong_coupling_is_found_where_two_roots_share_a_sample():
    # found by a survey (seed 266869708, one contact, mu = 2.66, 2 mu |W_NT| = 6.2 W_NN):
    # the slip's two roots x = 2.8605 and 2.9249 lie within one of the 64 samples, beside
    # the angle where g changes sign; the samples missed them and the answer was the
    # frictionless impulse (residual 5.3e-4 |q|, reported "not converged")
    W, q, _ = random_problem(np.random.default_rng(266869708), 1)
    mu = 2.66
    r = local_solve(W, q, mu)
    assert _assert_coulomb_law(W, q, mu, r, 1e-13) == "slip"
    (ref,) = _slips_by_enumeration(W, q, mu)                    # the only slip; stick fails
    np.testing.assert_allclose(r, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert math.atan2(-r[2], -r[1]) == pytest.approx(2.8605, abs=1e-4)
    sol = solve_exact(W, q, mu)
    assert sol.success and sol.residual <= 1e-13 * np.linalg.norm(q), sol.detail
    np.testing.assert_allclose(sol.r, ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_local_solve_on_strongly_coupled_blocks_is_one_of_the_enumerated_solutions():
    # 2 mu |A_NT| from 1 to 6 A_NN (several slips can exist, two roots can lie close) and
    # b_N from 1e-4 to 1e-1 of its size: before the roots' isolation one of these 150
    # blocks (and about one in 150 for other seeds) had no answer; the law is checked on u
    # directly, and the impulse is the stick impulse or one of the slips found by
    # enumerating the angle
    rng = np.random.default_rng(0)
    kinds = {"take-off": 0, "stick": 0, "slip": 0}
    for _ in range(150):
        H = rng.standard_normal((3, 4))
        A = H @ H.T / 4 + 1e-2 * np.eye(3)
        b = rng.standard_normal(3)
        b[0] = -abs(b[0]) * 10.0 ** rng.uniform(-4, -1)
        mu = rng.uniform(1.0, 6.0) * A[0, 0] / (2 * math.hypot(A[0, 1], A[0, 2]))
        r = local_solve(A, b, mu)
        # the problem's conditioning: rho = -b_N / g grows as g -> 0 (measured to 1.2e-12)
        kind = _assert_coulomb_law(A, b, mu, r, 1e-11)
        kinds[kind] += 1
        if kind == "stick":
            np.testing.assert_allclose(r, np.linalg.solve(A, -b), rtol=1e-12)
        else:
            refs = _slips_by_enumeration(A, b, mu, n=1 << 11)
            gap = min(np.abs(r - ref).max() for ref in refs) / np.abs(r).max()
            assert gap <= 1e-8, (gap, A, b, mu)
    assert kinds["slip"] >= 100 and kinds["stick"] >= 5, kinds


def test_every_contact_sticking_converges_where_lemke_s_paths_miss_it():
    # found by the property test: seed 7656, mu = 1.965 (and 1.97): every polygon's LCP
    # answer (d = 16 to 256) has contact 1 slipping, Newton from each stalls at 7e-4, and
    # Gauss–Seidel at 4e-4; the answer is -W^-1 q, every contact inside its cone
    W, q, _ = random_problem(np.random.default_rng(7656), 4)
    stick = np.linalg.solve(W, -q).reshape(-1, 3)
    ratio = np.hypot(stick[:, 1], stick[:, 2]) / stick[:, 0]
    assert 1.9 < ratio.max() < 1.965 and np.all(stick[:, 0] > 0)
    sol = solve_exact(W, q, np.full(4, 1.965))
    assert sol.success and "sticking impulse" in sol.detail, sol.detail
    np.testing.assert_allclose(sol.r.reshape(-1, 3), stick, rtol=0,
                               atol=1e-12 * np.abs(stick).max())


def test_each_restart_has_its_own_newton_budget():
    # found by a survey (seed 1088256468, mu = 2.843): Newton from the 16-gon's answer spent
    # the budget, and the 32-gon's restart had none left (residual 5.6e-5, "not converged");
    # with its own budget it converges in 5 steps
    W, q, _ = random_problem(np.random.default_rng(1088256468), 4)
    sol = solve_exact(W, q, np.full(4, 2.8433434961272916))
    assert sol.success, sol.detail
    assert "32-direction polyhedral solution (37 Lemke pivots, 5 step(s))" in sol.detail
    assert sol.residual <= 1e-13 * np.linalg.norm(q)


def test_the_answer_lies_in_the_cone_and_its_residual_is_the_projection_s():
    # found by a survey (seed 1713186228, mu = 1.790): Newton's iterate met the bound
    # (9.5e-11 |q|) at 3.3e-10 relative outside a cone, and its projection missed it;
    # Newton now goes on before projecting, and the projection is the answer. Which path
    # the solve takes follows the BLAS kernel's rounding: OpenBLAS's SkylakeX kernel takes
    # that one (2.7e-15), its Haswell and Zen kernels end inside the cones at 3.7e-10,
    # within the bound. What holds on every machine: the answer is its own projection
    # and its residual is the returned answer's, within the bound
    W, q, _ = random_problem(np.random.default_rng(1713186228), 5)
    mu = np.full(5, 1.7898405722666122)
    sol = solve_exact(W, q, mu)
    assert sol.success, sol.detail
    r = sol.r.reshape(-1, 3)
    np.testing.assert_array_equal(sol.r, np.concatenate([project_cone(x, m) for x, m in
                                                         zip(r, mu)]))
    assert np.all(np.hypot(r[:, 1], r[:, 2]) <= mu * r[:, 0] * (1 + 1e-15))
    assert sol.residual == cone_residual(W, q, mu, sol.r)
    assert sol.residual <= 1e-10 * np.linalg.norm(q)


def test_four_contacts_sticking_and_one_open_are_found_without_the_finer_polygons():
    # found by a survey (k = 28735, seed 2839128055, mu = 2.551): Newton stalls near 1e-2
    # from every start, and the 128-gon's Lemke path took its exact-arithmetic path for
    # minutes; the answer has contacts 0-3 sticking inside their cones and contact 4 open
    W, q, mu, sol = _solved_found_case(2839128055, 5, 2.5510825666154826)
    assert "31 sets of sticking and open contacts (touching: [0, 1, 2, 3])" in sol.detail
    assert sol.residual <= 1e-13 * np.linalg.norm(q)
    r = sol.r.reshape(-1, 3)
    np.testing.assert_array_equal(r[4], 0.0)
    assert sol.u[12] > 1.0                                      # contact 4 lifts off
    stick = np.linalg.solve(W[:12, :12], -q[:12]).reshape(-1, 3)
    np.testing.assert_allclose(r[:4], stick, rtol=0, atol=1e-12 * np.abs(stick).max())
    assert np.all(np.hypot(r[:4, 1], r[:4, 2]) < 0.95 * mu[:4] * r[:4, 0])


def test_a_resting_stack_s_singular_problem_is_solved_by_the_least_norm_sticking_impulse():
    # box-stack-3d with three cubes, a step at rest (12 contacts, four a face; W of rank 18
    # of 36): Newton stalled (9.3e-13 against the bound 8e-13), the 16-gon's Lemke path
    # met exact arithmetic on W's rounding (294 exact pivots in 120 CPU s unfinished), and
    # -W^-1 q is noise (r_N < 0, |r_T| / r_N = 26); the least-norm -W^+ q is the answer
    d = np.load(Path(__file__).parents[1] / "data" / "box_stack_3_resting_step.npz")
    W, q, mu = d["W"], d["q"], d["mu"]
    assert np.linalg.matrix_rank(W) == 18
    sol = solve_exact(W, q, mu, r0=d["r0"])
    assert sol.success and "least-norm sticking impulse -W^+ q (W of rank 18 < 36)" in sol.detail
    assert sol.residual == cone_residual(W, q, mu, sol.r)
    assert sol.residual <= 1e-13 * np.linalg.norm(q)
    r = sol.r.reshape(-1, 3)
    # each cube (1 kg) weighs h g: the plane's four points carry three, each interface's
    # the cubes above, shared equally (the least norm), with no friction
    per_point = np.repeat([3.0, 2.0, 1.0], 4) * r[:, 0].sum() / 24.0
    np.testing.assert_allclose(r[:, 0], per_point, rtol=1e-10)
    np.testing.assert_allclose(r[:, 1:], 0.0, atol=1e-11 * r[:, 0].max())  # 4e-12 measured


@pytest.mark.slow
def test_one_contact_slip_under_strong_coupling_against_lemke_on_512_directions():
    # where the enumeration finds one slip and no stick, the 512-gon's LCP (Lemke) slides
    # within its facet bound pi/d of local_solve's direction (measured up to 5.9e-3 rad on
    # these 25; the impulse's size moves up to 6 % where g = A_NN - mu A_NT.s is small)
    rng = np.random.default_rng(1)
    done = 0
    while done < 25:
        H = rng.standard_normal((3, 4))
        A = H @ H.T / 4 + 1e-2 * np.eye(3)
        b = rng.standard_normal(3)
        b[0] = -abs(b[0]) * 10.0 ** rng.uniform(-4, 0)
        mu = rng.uniform(1.0, 6.0) * A[0, 0] / (2 * math.hypot(A[0, 1], A[0, 2]))
        stick = np.linalg.solve(A, -b)
        if (stick[0] >= 0 and math.hypot(stick[1], stick[2]) <= mu * stick[0]) \
                or len(_slips_by_enumeration(A, b, mu, n=1 << 14)) != 1:
            continue
        done += 1
        r = local_solve(A, b, mu)
        poly = solve_polyhedral(A, b, mu, 512)
        assert poly.success
        p = poly.r
        angle = math.atan2(r[1] * p[2] - r[2] * p[1], r[1] * p[1] + r[2] * p[2])
        assert abs(angle) <= np.pi / 512
        assert p[0] == pytest.approx(r[0], rel=0.1)
