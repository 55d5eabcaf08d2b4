"""Painlevé rod: input checks, scene formulas, the paradox condition and its report."""

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import moreau.integrators.moreau_jean  # noqa: F401  (registers "moreau-jean")
from moreau.errors import InputError, PainleveError
from moreau.integrators import simulate
from moreau.scenes.painleve_rod import (PAINLEVE_MU_MIN, PainleveRod, PainleveRodParams,
                                        painleve_critical_mu)

PHI_STAR = math.atan(2.0)          # angle of the smallest critical mu, 4/3


def central(f, s=1e-5):
    return (f(s) - f(-s)) / (2.0 * s)


def tip(q):
    """Lower tip of the rod, computed from the geometry (half-length 1)."""
    return np.array([q[0] - math.cos(q[2]), q[1] - math.sin(q[2])])


# -- input checks -------------------------------------------------------------
@pytest.mark.parametrize("kwargs, match", [
    ({"mass": 0.0}, r"`mass` must be > 0"),
    ({"length": -1.0}, r"`length` must be > 0"),
    ({"mu": -2.0}, r"`mu` must be >= 0"),
    ({"mu": float("inf")}, r"`mu` must be finite"),
    ({"restitution": 1.5}, r"`restitution` must be in \[0.0, 1.0\]"),
])
def test_bad_parameters_raise_input_error(kwargs, match):
    with pytest.raises(InputError, match=match):
        PainleveRod(**kwargs)


def test_bad_states_raise_input_error():
    rod = PainleveRod()
    with pytest.raises(InputError, match=r"`phi` must be in the open interval \(0, pi\)"):
        rod.sliding_state(phi=-0.1, tip_speed=1.0)
    with pytest.raises(InputError, match=r"`tip_speed` must be finite"):
        rod.sliding_state(phi=1.0, tip_speed=float("nan"))
    with pytest.raises(InputError, match=r"`q` must have shape \(3\)"):
        rod.painleve_indicator([0.0, 1.0], [0.0, 0.0, 0.0])
    q0, v0 = rod.sliding_state(1.0, 0.0)
    with pytest.raises(InputError, match=r"`v` must give the tip a nonzero slip velocity"):
        rod.sliding_accelerations(q0, v0)


# -- scene formulas -------------------------------------------------------------
@pytest.mark.parametrize("q, v", [
    ([0.3, 0.8, 0.9], [0.4, -0.2, 1.3]),
    ([-1.0, 0.2, 2.5], [-0.7, 0.5, -2.0]),
])
def test_contact_kinematics_match_the_tip_geometry(q, v):
    rod = PainleveRod(mu=0.7)
    q, v, t = np.array(q), np.array(v), 0.0
    WN, wN, WT, wT = rod.contact_jacobians(q, t)
    assert rod.gaps(q, t)[0] == pytest.approx(tip(q)[1], abs=1e-15)
    tip_velocity = central(lambda s: tip(q + s * v))
    assert WN[0] @ v + wN[0] == pytest.approx(tip_velocity[1], abs=1e-9)
    assert WT[0] @ v + wT[0] == pytest.approx(tip_velocity[0], abs=1e-9)
    # with zero acceleration the contact accelerations are the drift terms
    tip_accel = (tip(q + 1e-4 * v) - 2 * tip(q) + tip(q - 1e-4 * v)) / 1e-8
    wNbar, wTbar = rod.contact_drift(q, v, t)
    assert wNbar[0] == pytest.approx(tip_accel[1], abs=1e-6)
    assert wTbar[0] == pytest.approx(tip_accel[0], abs=1e-6)


def test_mass_and_forces_from_the_si_lagrangian():
    # L = 1/2 m (X'^2 + Y'^2) + 1/2 (m l^2 / 12) Phi'^2 - m g Y
    p = PainleveRodParams(mass=0.7, length=1.6, gravity=9.8, mu=1.0)
    rod = PainleveRod(p)
    L, T, F = rod.length, rod.time, rod.force
    assert L == pytest.approx(0.8)
    S = np.diag([L, L, 1.0])            # q = S q_dimensionless, angle unscaled
    M_si = np.diag([p.mass, p.mass, p.mass * p.length ** 2 / 12.0])
    h_si = np.array([0.0, -p.mass * p.gravity, 0.0])
    q = np.array([0.1, 0.5, 0.7])
    assert rod.mass(q) == pytest.approx(S @ M_si @ S / (T ** 2 * F * L), rel=1e-14)
    assert rod.forces(q, q, 0.0) == pytest.approx(S @ h_si / (F * L), abs=1e-15)
    si = rod.to_si(q=q, v=[1.0, 1.0, 1.0])
    assert si.q == pytest.approx([0.08, 0.4, 0.7]) and si.v[2] == pytest.approx(1.0 / T)


# -- the paradox -------------------------------------------------------------------
def test_indicator_closed_form_and_critical_mu():
    rng = np.random.default_rng(4)
    for phi, mu, u in zip(rng.uniform(0.05, 3.0, 20), rng.uniform(0.0, 3.0, 20),
                          rng.choice([-1.0, 1.0], 20)):
        rod = PainleveRod(mu=mu)
        q, v = rod.sliding_state(phi, u)
        c, s = math.cos(phi), math.sin(phi)
        expected = 1 + 3 * c * c + 3 * mu * np.sign(u) * s * c
        assert rod.painleve_indicator(q, v) == pytest.approx(expected, abs=1e-13)
    # at the critical friction the indicator of the bad slip direction vanishes
    for phi in (0.4, PHI_STAR, 1.4):
        rod = PainleveRod(mu=painleve_critical_mu(phi))
        q, v = rod.sliding_state(phi, -1.0)
        assert rod.painleve_indicator(q, v) == pytest.approx(0.0, abs=1e-13)
    # the smallest critical friction is 4/3, at tan(phi) = 2
    grid = np.linspace(0.01, math.pi / 2 - 0.01, 20001)
    mus = np.array([painleve_critical_mu(p) for p in grid])
    assert mus.min() == pytest.approx(PAINLEVE_MU_MIN, rel=1e-8)
    assert grid[mus.argmin()] == pytest.approx(PHI_STAR, abs=1e-4)
    assert painleve_critical_mu(0.0) == math.inf


def test_sliding_accelerations_solve_newton_and_keep_the_tip_on_the_floor():
    rod = PainleveRod(mu=0.6)
    q, v = rod.sliding_state(0.8, 1.2, dphi=0.3)
    a, lamN, lamT = rod.sliding_accelerations(q, v)
    WN, _, WT, _ = rod.contact_jacobians(q, 0.0)
    wNbar, _ = rod.contact_drift(q, v, 0.0)
    assert WN[0] @ a + wNbar[0] == pytest.approx(0.0, abs=1e-14)
    residual = rod.mass(q) @ a - rod.forces(q, v, 0.0) - WN[0] * lamN - WT[0] * lamT
    assert residual == pytest.approx(np.zeros(3), abs=1e-14)
    assert lamN > 0 and lamT == pytest.approx(-0.6 * lamN)
    # independent closed form: lambdaN = (1 - sin(phi) dphi^2) / A
    A = 1 + 3 * math.cos(0.8) ** 2 + 3 * 0.6 * math.sin(0.8) * math.cos(0.8)
    assert lamN == pytest.approx((1 - math.sin(0.8) * 0.09) / A, rel=1e-13)


def test_paradox_without_solution_is_reported_with_its_cause():
    rod = PainleveRod(mu=2.0)
    q, v = rod.sliding_state(PHI_STAR, -1.0)      # friction torque drives the tip down
    assert rod.painleve_indicator(q, v) == pytest.approx(1 + 3 / 5 - 12 / 5)
    A, b, lamN = rod.sliding_contact_problem(q, v)
    assert (A, b, lamN) == pytest.approx((-0.8, -1.0, -1.25))
    with pytest.raises(PainleveError, match=r"A = .* = -0\.8 <= 0 with `mu` = 2, "
                                            r"`phi` = 1\.10715 rad \(63\.43 deg\)") as info:
        rod.check_well_posed(q, v, 0.25)
    msg = str(info.value)
    assert "t = 0.25" in msg and "critical 1.33333" in msg
    assert "no solution" in msg and "-b/A = -1.25 < 0" in msg
    with pytest.raises(PainleveError, match=r"-0\.8 <= 0"):
        rod.sliding_accelerations(q, v)


def test_paradox_with_two_solutions_is_reported_as_such():
    rod = PainleveRod(mu=2.0)
    q, v = rod.sliding_state(PHI_STAR, -1.0, dphi=2.0)   # sin(phi) dphi^2 > 1
    with pytest.raises(PainleveError, match=r"two solutions: lift-off, or sliding contact"):
        rod.check_well_posed(q, v)


@pytest.mark.parametrize("mu, tip_speed, lift", [
    (2.0, +1.0, 0.0),     # the harmless slip direction
    (1.3, -1.0, 0.0),     # below 4/3 no angle is paradoxical
    (2.0, 0.0, 0.0),      # sticking tip
    (2.0, -1.0, 1e-3),    # tip above the floor
])
def test_well_posed_states_pass_the_check(mu, tip_speed, lift):
    rod = PainleveRod(mu=mu)
    q, v = rod.sliding_state(PHI_STAR, tip_speed)
    q[1] += lift
    assert rod.check_well_posed(q, v, 0.0) is None


# -- Moreau–Jean: well-posed sliding converges, the paradox is reported -----------------
def test_moreau_jean_sliding_rod_converges_at_first_order():
    # reference: the sliding-contact ODE a = sliding_accelerations(q, v), which
    # holds while the normal force stays positive and the tip keeps slipping
    rod = PainleveRod(mu=0.5)
    q0, v0 = rod.sliding_state(0.9, -1.0, dphi=0.4)
    t_end = 0.5

    def rhs(t, y):
        a, lamN, _ = rod.sliding_accelerations(y[:3], y[3:])
        return np.concatenate([y[3:], a])

    ref = solve_ivp(rhs, (0.0, t_end), np.concatenate([q0, v0]), method="DOP853",
                    rtol=1e-12, atol=1e-12, dense_output=True)
    for t in np.linspace(0.0, t_end, 6):
        y = ref.sol(t)
        _, lamN, _ = rod.sliding_accelerations(y[:3], y[3:])
        assert lamN > 0.5 and rod.contact_velocities(y[:3], y[3:], t)[1][0] < -0.9
    hs = 0.02 * 2.0 ** -np.arange(5)
    errors = []
    for h in hs:
        res = simulate(rod, (0.0, t_end), q0, v0, "moreau-jean", h=h)
        assert res.status == 0 and set(res.regime_letters()) == {"N"}
        errors.append(np.max(np.abs(res.q - ref.sol(res.t).T[:, :3])))
    assert 0.8 <= np.polyfit(np.log(hs), np.log(errors), 1)[0] <= 1.3


def test_moreau_jean_stops_with_a_painleve_diagnosis_when_asked():
    # by default the step takes the tangential impact (tests/integrators/test_tangential_impact.py)
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, -1.0)
    res = simulate(rod, (0.0, 1.0), q0, v0, "moreau-jean", h=1e-3, painleve="stop")
    assert res.status == -1 and not res.success
    assert re.search(r"Painlev[ée] condition .* violated", res.message)
    assert re.search(r"\bmu`? = 2\b", res.message)
    # nothing past the ill-posed state was integrated
    assert len(res.t) == 0 or res.t[-1] == 0.0


def test_moreau_jean_runs_the_harmless_slip_direction():
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, +1.0)
    assert rod.painleve_indicator(q0, v0) == pytest.approx(4.0)
    res = simulate(rod, (0.0, 0.05), q0, v0, "moreau-jean", h=1e-3)
    assert res.status == 0 and res.success
    assert np.all(np.isfinite(res.q))
