"""Rolling resistance between disks (moreau.contact.rolling, the rolling rows of
moreau.model.granular, and simulate_disks's path with them): closed forms of a disk rolling on
a floor and resting on an incline, the cone's projection, and the step's problem against
Lemke on its LCP."""

import math

import numpy as np
import pytest

from moreau.contact.rolling import project_rolling_cone, rolling_residual, solve_nsgs_rolling
from moreau.errors import InputError
from moreau.integrators.granular import simulate_disks
from moreau.lcp import solve_lcp
from moreau.model.granular import DiskScene, DiskSystem, HalfPlane
from moreau.scenes.granular_column import collapse
from moreau.scenes.silo import fill


def _floor(mu, mu_r, R=0.5, alpha=0.0):
    n = (-math.sin(alpha), math.cos(alpha))
    return DiskSystem([R], [1.0], walls=[HalfPlane((0.0, 0.0), n)], mu=mu, mu_r=mu_r), n


def test_a_disk_rolling_on_a_floor_slows_at_the_closed_form_rate_and_stops_on_time():
    # m dv/dt = F (the floor's friction, at -R e_y), J dw/dt = R F + M, M = mu_r m g (the
    # couple against the roll w < 0), v = -R w: a = -mu_r m g R / (J + m R^2) = -(2/3) mu_r g / R
    # for J = m R^2 / 2 (F = m a needs mu >= (2/3) mu_r / R); it stops at t* = v0 / |a|
    R, mu_r, v0, h = 0.5, 0.1, 0.41, 0.02
    sys, _ = _floor(0.8, mu_r, R)
    a = -(2.0 / 3.0) * mu_r / R
    t_stop = v0 / -a                      # 3.075: between steps 153 and 154
    res = simulate_disks(sys, [[0.0, R]], [[v0, 0.0, -v0 / R]], 170, h, theta=0.5, tol=1e-12)
    assert res.status == 0
    t, vx, w = res.t, res.v[:, 0, 0], res.v[:, 0, 2]
    rolling = t < t_stop
    assert np.allclose(vx[rolling], v0 + a * t[rolling], rtol=0.0, atol=1e-10)
    assert np.allclose(w * R, -vx, rtol=0.0, atol=1e-10)           # no slip
    assert np.max(np.abs(res.v[~rolling, 0])) < 1e-12               # at rest from the next step
    assert np.flatnonzero(~rolling)[0] == math.ceil(t_stop / h)
    # the trapezoidal positions of a linear speed are exact: v0^2 / (2 |a|), less the half step
    # (h/2) v_k of the last step, in which the speed drops from v_k = v0 + a 3.06 to zero
    v_last = v0 + a * math.floor(t_stop / h) * h
    travel = v0 ** 2 / (-2.0 * a) - (v_last ** 2 / (-2.0 * a) - 0.5 * h * v_last)
    assert res.x[-1, 0, 0] == pytest.approx(travel, abs=1e-10)
    assert res.x[-1, 0, 1] == pytest.approx(R, abs=1e-12)


@pytest.mark.parametrize("ratio", [0.95, 1.05])
def test_a_disk_rests_on_an_incline_iff_tan_alpha_is_at_most_mu_r_over_r(ratio):
    # at rest: friction F = m g sin(alpha) up the slope, and the couple balances its moment,
    # M = R F <= mu_r m g cos(alpha): tan(alpha) <= mu_r / R (and <= mu). Beyond, it rolls
    # down at (2/3) g (sin(alpha) - (mu_r / R) cos(alpha))
    R, mu_r = 0.5, 0.05
    alpha = math.atan(ratio * mu_r / R)
    sys, n = _floor(0.8, mu_r, R, alpha)
    h, steps = 0.02, 80
    x0 = np.array([[R * n[0], R * n[1]]])
    res = simulate_disks(sys, x0, np.zeros((1, 3)), steps, h, theta=0.5, tol=1e-12)
    assert res.status == 0
    down = (x0[0] - res.x[-1, 0]) @ np.array([math.cos(alpha), math.sin(alpha)])
    if ratio < 1.0:
        assert np.max(np.abs(res.v)) < 1e-12 and abs(down) < 1e-12
    else:
        acc = (2.0 / 3.0) * (math.sin(alpha) - mu_r / R * math.cos(alpha))
        assert acc > 0.0
        assert down == pytest.approx(acc * (steps * h) ** 2 / 2, rel=1e-8)


def test_the_projection_onto_the_rolling_cone_is_moreaus_decomposition():
    # y = P_K(y) + P_K°(y) with the two orthogonal, P_K(y) in K and y - P_K(y) in the polar
    # cone -K* = {u : -u_N >= mu |u_T| + mu_r |u_R|}
    rng = np.random.default_rng(1)
    for k in range(400):
        mu, mu_r = rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.5)
        if k % 4 == 1:
            mu = 0.0
        if k % 4 == 2:
            mu_r = 0.0
        y = rng.standard_normal(3) * rng.uniform(0.1, 10.0)
        p = np.array(project_rolling_cone(mu, mu_r, *y))
        d = y - p
        scale = np.linalg.norm(y)
        assert abs(p[1]) <= mu * p[0] + 1e-14 * scale and abs(p[2]) <= mu_r * p[0] + 1e-14 * scale
        assert -d[0] >= mu * abs(d[1]) + mu_r * abs(d[2]) - 1e-12 * scale
        assert abs(p @ d) <= 1e-12 * scale ** 2
        if abs(y[1]) <= mu * y[0] and abs(y[2]) <= mu_r * y[0]:
            assert np.array_equal(p, y)


def _rolling_lcp(W, q, mu, mu_r):
    # per contact z = (p_N, pT+, pT-, bT, pR+, pR-, bR); r = E z; the rows
    # u_N, u_T + bT, -u_T + bT, mu p_N - pT+ - pT-, u_R + bR, -u_R + bR, mu_r p_N - pR+ - pR-
    nc = mu.size
    E = np.zeros((3 * nc, 7 * nc))
    S = np.zeros((7 * nc, 3 * nc))
    G = np.zeros((7 * nc, 7 * nc))
    for i in range(nc):
        z, r = 7 * i, 3 * i
        E[r, z], E[r + 1, z + 1], E[r + 1, z + 2] = 1.0, 1.0, -1.0
        E[r + 2, z + 4], E[r + 2, z + 5] = 1.0, -1.0
        S[z, r], S[z + 1, r + 1], S[z + 2, r + 1] = 1.0, 1.0, -1.0
        S[z + 4, r + 2], S[z + 5, r + 2] = 1.0, -1.0
        G[z + 1, z + 3] = G[z + 2, z + 3] = 1.0
        G[z + 3, z], G[z + 3, z + 1], G[z + 3, z + 2] = mu[i], -1.0, -1.0
        G[z + 4, z + 6] = G[z + 5, z + 6] = 1.0
        G[z + 6, z], G[z + 6, z + 4], G[z + 6, z + 5] = mu_r[i], -1.0, -1.0
    return S @ W @ E + G, S @ q, E


def test_the_steps_problem_solved_by_nsgs_is_lemkes_on_its_lcp():
    # two disks stacked on a tilted floor, moving at random: the step's problem of
    # simulate_disks (rows [N, T, R] from DiskSystem.jacobian) by NSGS and by Lemke on the
    # LCP of the same law (each rolling row a friction pair on the relative spin)
    alpha = 0.2
    n = np.array([-math.sin(alpha), math.cos(alpha)])
    sys = DiskSystem([0.5, 0.4], [1.0, 0.7], walls=[HalfPlane((0.0, 0.0), n)], mu=0.6,
                     mu_r=0.04)
    x = np.array([0.5 * n, 0.5 * n + 0.9 * np.array([math.sin(0.3), math.cos(0.3)])])
    cs = sys.contacts(x, margin=1e-9)
    H = sys.jacobian(cs, rolling=True).toarray()
    H2 = sys.jacobian(cs).toarray()
    assert np.array_equal(H[0::3], H2[0::2]) and np.array_equal(H[1::3], H2[1::2])
    # the rolling row is the rate of phi_b - phi_a
    assert np.array_equal(H[2::3], [[0, 0, -1, 0, 0, 1], [0, 0, 1, 0, 0, 0]])
    W = H @ np.diag(sys.inv_mass) @ H.T
    rng = np.random.default_rng(4)
    agree = 0
    for _ in range(12):
        v = rng.standard_normal(6) * 0.5
        v[1::3] -= 1.0
        q = H @ v
        sol = solve_nsgs_rolling(W, q, cs.mu, cs.mu_r, tol=1e-13, max_sweeps=100_000)
        assert sol.converged, sol.message
        M, ql, E = _rolling_lcp(W, q, cs.mu, cs.mu_r)
        lem = solve_lcp(M, ql, method="lemke")
        assert lem.success, lem.message
        r_lemke = E @ lem.z
        # Lemke's answer is a zero of the natural map (an independent check of the residual)
        assert rolling_residual(W, q, cs.mu, cs.mu_r, r_lemke)[0] < 1e-12
        # W is positive definite here (six rows, six coordinates): one answer
        assert np.allclose(sol.r, r_lemke, rtol=0.0, atol=1e-9)
        agree += bool(np.any(np.abs(sol.r[2::3]) > 0.0))
    assert agree >= 6       # cases where the couples act, not only take-offs


def test_negative_rolling_resistance_and_a_scene_with_it_are_refused_by_name():
    with pytest.raises(InputError, match="`mu_r` must be >= 0"):
        DiskSystem([0.5], [1.0], mu_r=-0.1)
    with pytest.raises(InputError, match=r"`walls\[0\]\.mu_r` must be >= 0"):
        DiskSystem([0.5], [1.0], walls=[HalfPlane((0, 0), (0, 1), mu_r=-1.0)])
    with pytest.raises(InputError, match="`mu_r` must be >= 0 for every contact"):
        solve_nsgs_rolling(np.eye(3), [-1.0, 0.0, 0.0], [0.5], [-0.01])
    rolling = DiskSystem([0.5], [1.0], walls=[HalfPlane((0, 0), (0, 1))], mu_r=0.01)
    with pytest.raises(InputError, match="`system` must have no rolling resistance"):
        DiskScene(rolling, [[0.0, 0.5]])
    # a wall's own resistance alone makes the system rolling
    assert DiskSystem([0.5], [1.0], walls=[HalfPlane((0, 0), (0, 1), mu_r=0.01)]).rolling
    assert not DiskSystem([0.5], [1.0], walls=[HalfPlane((0, 0), (0, 1))]).rolling


def test_the_studies_refuse_a_negative_scatter_and_mu_r_by_name_before_any_run():
    with pytest.raises(InputError, match="`scatter`"):
        fill(1, scatter=-0.1)
    with pytest.raises(InputError, match="`scatter`"):
        collapse(scatter=-0.1)
    with pytest.raises(InputError, match="`mu_r`"):
        fill(1, mu_r=-1e-4)
    with pytest.raises(InputError, match="`mu_r`"):
        collapse(mu_r=-1e-4)
