"""Coulomb–Contensou friction: the ellipsoid's projection, the 4-row cone solve, a spinning disk.

The ellipsoid |F|^2/(mu N)^2 + M^2/(mu N r*)^2 <= 1 (Leine and Glocker 2003, r* = 2 r / 3
for a uniform pressure on a patch of radius r) is held to a constrained minimisation by
scipy (SLSQP), the 4-row solve to the Coulomb law's own conditions and to the 3-row exact
solver where the drilling row is decoupled, and a flat disk spun on a plane to its closed
form: the drilling torque mu m g r* brings omega down linearly to rest at C omega0 / (mu m g r*).
"""

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from moreau.contact.cone3d import (
    local_solve_contensou,
    project_contensou,
    solve_exact,
    solve_exact_contensou,
)
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.model.space import DRILLING_LEVER, Disk, Puck, SpaceModel, Sphere


def _metric_projection_by_minimisation(x, mu, lever):
    # nearest point of the ellipsoidal cone in the metric diag(1, 1, 1, 1/lever^2), by SLSQP
    # on the cone's own inequality (squared, smooth), from the cone's axis
    G = np.array([1.0, 1.0, 1.0, 1.0 / lever ** 2])
    cons = [{"type": "ineq", "fun": lambda z: (mu * z[0]) ** 2 - z[1] ** 2 - z[2] ** 2
             - (z[3] / lever) ** 2},
            {"type": "ineq", "fun": lambda z: z[0]}]
    best = None
    for start in (np.array([max(x[0], 0.0) + 1.0, 0.0, 0.0, 0.0]),):
        out = minimize(lambda z: float(G @ (z - x) ** 2), start, jac=lambda z: 2.0 * G * (z - x),
                       constraints=cons, method="SLSQP", options={"ftol": 1e-15, "maxiter": 500})
        if best is None or out.fun < best.fun:
            best = out
    return best.x


def test_the_ellipsoids_projection_against_a_constrained_minimisation():
    rng = np.random.default_rng(37)
    worst = 0.0
    for _ in range(12):
        x = rng.normal(size=4) * np.array([1.0, 1.0, 1.0, 0.2])
        mu, lever = rng.uniform(0.1, 1.0), rng.uniform(0.05, 0.5)
        p = project_contensou(x, mu, lever)
        ref = _metric_projection_by_minimisation(x, mu, lever)
        worst = max(worst, float(np.max(np.abs(p - ref))))
        # on the cone, and the residual orthogonal to it in the metric (a projection)
        assert math.hypot(math.hypot(p[1], p[2]), p[3] / lever) <= mu * p[0] * (1 + 1e-12) + 1e-15
    # measured 2.5e-7: SLSQP's own tolerance
    assert worst < 1e-6
    # inside stays, the polar cone goes to the apex
    assert project_contensou([1.0, 0.1, 0.0, 0.01], 0.5, 0.1).tolist() == [1.0, 0.1, 0.0, 0.01]
    assert project_contensou([-1.0, 0.1, 0.0, 0.01], 0.5, 0.1).tolist() == [0.0] * 4
    with pytest.raises(InputError, match="`lever`"):
        project_contensou([1.0, 0.0, 0.0, 0.0], 0.5, 0.0)


def _random_block(rng, coupled):
    J = rng.normal(size=(4, 6))
    A = J @ np.diag(rng.uniform(0.5, 2.0, 6)) @ J.T + 0.1 * np.eye(4)
    if not coupled:
        A[0, 1:] = A[1:, 0] = 0.0
    return 0.5 * (A + A.T)


@pytest.mark.parametrize("coupled", [False, True])
def test_the_four_row_solve_meets_the_coulomb_law_conditions_to_rounding(coupled):
    rng = np.random.default_rng(5 + coupled)
    kinds = set()
    for _ in range(60):
        A = _random_block(rng, coupled)
        b = rng.normal(size=4) * np.array([1.0, *[rng.uniform(0.02, 2.0)] * 3])
        mu = rng.uniform(0.1, 1.5)
        r = local_solve_contensou(A, b, mu)
        u = A @ r + b
        scale = float(np.max(np.abs(b)))
        if b[0] >= 0.0:
            assert r.tolist() == [0.0] * 4
            kinds.add("take-off")
            continue
        assert abs(u[0]) < 1e-12 * scale and r[0] > 0.0
        rt, ut = r[1:], u[1:]
        if np.linalg.norm(ut) < 1e-12 * scale:
            assert np.linalg.norm(rt) <= mu * r[0] * (1 + 1e-12)
            kinds.add("stick")
        else:
            # slip: on the cone's edge, the friction opposite the generalized slip
            assert np.linalg.norm(rt) == pytest.approx(mu * r[0], rel=1e-12)
            assert np.allclose(rt / np.linalg.norm(rt), -ut / np.linalg.norm(ut), atol=1e-11)
            kinds.add("slip")
    assert kinds == {"take-off", "stick", "slip"}


def test_a_decoupled_drilling_row_leaves_the_three_row_exact_solution():
    # the spin's row neither couples nor moves: the 4-row answer is the 3-row solver's
    rng = np.random.default_rng(11)
    for _ in range(20):
        A3 = _random_block(rng, True)[:3, :3]
        W = np.zeros((4, 4))
        W[:3, :3] = A3
        W[3, 3] = 1.3
        q3 = rng.normal(size=3) - np.array([0.5, 0.0, 0.0])
        q = np.append(q3, 0.0)
        r4 = solve_exact_contensou(W, q, 0.4, [4]).r
        r3 = solve_exact(A3, q3, 0.4).r
        assert np.max(np.abs(r4[:3] - r3)) < 1e-10 * max(1.0, np.max(np.abs(r3)))
        assert r4[3] == 0.0


def test_two_contacts_one_with_drilling_converge_by_gauss_seidel():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(7, 12))
    W = J @ J.T / 12.0 + 0.05 * np.eye(7)
    q = rng.normal(size=7) - np.array([1.0, 0, 0, 0, 1.0, 0, 0])
    sol = solve_exact_contensou(W, q, [0.3, 0.5], [4, 3])
    assert sol.success and sol.relative_residual <= 1e-10
    r, u = sol.r, sol.u
    for a, b, mu in ((0, 4, 0.3), (4, 7, 0.5)):
        if r[a] > 0.0:
            assert abs(u[a]) < 1e-8
            assert np.linalg.norm(r[a + 1:b]) <= mu * r[a] * (1 + 1e-9)
    with pytest.raises(InputError, match="`sizes`"):
        solve_exact_contensou(W, q, [0.3, 0.5], [3, 3])


def _spinning_disk(spin, speed=0.0, mu=0.4, a=0.05, m=0.2):
    # a thin uniform disk (C = m a^2 / 2) lying on the plane, touching through its face's
    # centre with the face as its patch
    model = SpaceModel(gravity=(0.0, 0.0, -9.81), length=a, mass=m)
    floor = model.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    C = 0.5 * m * a * a
    disk = model.add_body(m, [0.5 * C, 0.5 * C, C], velocity=(speed, 0.0, 0.0),
                          angular_velocity=(0.0, 0.0, spin))
    model.add_contact(disk, Puck(a, 0.0, rim_points=1), floor, mu=mu, contact_radius=a)
    return model.build("disk"), C


def test_a_flat_disk_spun_on_the_plane_stops_at_the_drilling_torques_rate():
    mu, a, m, g, w0 = 0.4, 0.05, 0.2, 9.81, 30.0
    sc, C = _spinning_disk(w0, mu=mu, a=a, m=m)
    rate = mu * m * g * DRILLING_LEVER * a / C           # rad/s^2, the closed form
    t_stop = w0 / rate
    res = simulate(sc, (0.0, 1.5 * t_stop / sc.time), *sc.initial_state(), "moreau-jean",
                   h=t_stop / sc.time / 40.5, cone="exact", theta=1.0)
    assert res.status == 0
    t, w = res.t * sc.time, res.v[:, 5] / sc.time
    moving = t < t_stop
    # theta = 1: each step's impulse is the torque's exactly, so omega is the line to rounding
    assert np.max(np.abs(w[moving] - (w0 - rate * t[moving]))) < 1e-11 * w0
    assert np.all(w[t > t_stop + res.t[1] * sc.time] == 0.0)
    # the centre does not move, the weight stays on the patch
    assert np.max(np.abs(res.v[:, :3])) < 1e-12


def test_sliding_and_spin_decay_together_on_the_ellipsoids_curve():
    # both rates come from the same |(v, r* omega)|: m v' = -mu N v / |.|, C omega' =
    # -mu N r*^2 omega / |.|, so d ln(r* omega) = (m r*^2 / C) d ln v = (8/9) d ln v for
    # the thin disk: r* omega / v^(8/9) keeps its initial value (to the step's order)
    sc, C = _spinning_disk(20.0, speed=0.5)
    q0, v0 = sc.initial_state()
    errs = []
    for h in (0.02, 0.01):
        res = simulate(sc, (0.0, 4.0), q0, v0, "moreau-jean", h=h, cone="exact")
        assert res.status == 0
        lever = sc.drilling_levers[0]
        v, w = res.v[:, 0], res.v[:, 5]
        keep = v > 0.2 * v[0]
        inv = lever * w[keep] / v[keep] ** (8.0 / 9.0)
        errs.append(float(np.max(np.abs(inv / inv[0] - 1.0))))
    # measured 1.21e-3, 6.05e-4 (3.06e-4 at h = 0.005): order one in h
    assert errs[0] < 3e-3 and 1.7 < errs[0] / errs[1] < 2.3


def test_a_bad_contact_radius_is_refused_by_name():
    model = SpaceModel(gravity=(0.0, 0.0, -9.81))
    floor = model.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b = model.add_body(1.0, [0.1, 0.1, 0.1], position=(0.0, 0.0, 0.5),
                       orientation=(math.cos(0.2), math.sin(0.2), 0.0, 0.0))
    with pytest.raises(InputError, match="`contact_radius`"):
        model.add_contact(b, Sphere(0.5), floor, mu=0.3, contact_radius=-1e-3)
    with pytest.raises(InputError, match="`contact_radius` must be 0 on a Disk"):
        model.add_contact(b, Disk(0.5), floor, mu=0.3, contact_radius=1e-3)
    model.add_contact(b, Sphere(0.5), floor, mu=0.3, contact_radius=1e-3)
    sc = model.build("ball")
    with pytest.raises(InputError, match='`cone` must be "exact"'):
        simulate(sc, (0.0, 0.1), *sc.initial_state(), "moreau-jean", h=0.01, cone=8)
    # the compiled loop takes the patch (its drilling row): fast=True is accepted
    assert sc.contact_table() is not None
    res = simulate(sc, (0.0, 0.1), *sc.initial_state(), "moreau-jean", h=0.01, cone="exact",
                   fast=True)
    assert res.status == 0


def test_the_event_driven_reference_spins_the_disk_down_and_stops_at_rest_by_name():
    mu, a, m, g, w0 = 0.4, 0.05, 0.2, 9.81, 30.0
    sc, C = _spinning_disk(w0, mu=mu, a=a, m=m)
    t_stop = C * w0 / (mu * m * g * DRILLING_LEVER * a)
    res = simulate(sc, (0.0, 2.0 * t_stop / sc.time), *sc.initial_state(),
                   "event-driven-space", sample_dt=0.1 * t_stop / sc.time)
    # the drilling torque's line to rounding while it spins; at rest it would roll (stick
    # under the patch), which this reference refuses by name
    t, w = res.t * sc.time, res.v[:, 5] / sc.time
    assert np.max(np.abs(w - (w0 - w0 * t / t_stop))) < 1e-9 * w0
    assert res.status == -5 and "`contact_radius`" in res.message
    t_end = float(res.message.split("reaches zero at t = ")[1].split(":")[0]) * sc.time
    assert t_end == pytest.approx(t_stop, rel=1e-9)
