"""The flexible-rod drive: mode shapes, the model against independent computations, N = 0.

The conformance suite (tests/engine/test_conformance.py) runs check_scene,
the compiled model and Moreau–Jean against the event-driven reference at the
scene's defaults; here the derivation itself is checked against quadratures
of the displacement field, the closed-form Euler–Bernoulli eigenvalues and
the rigid scene.
"""

import json
import math
from dataclasses import fields

import numpy as np
import pytest

from moreau.analysis.mj_steady_state import moreau_jean_steady_state
from moreau.check import check_scene
from moreau.cli import main
from moreau.compiled import evaluate_compiled
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.flexible_rod_drive import (MAX_MODES, FlexibleRodDrive, mode_shape,
                                              pinned_free_modes)
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams

# roots of tan b = tanh b (hinged-free beam; Blevins, Formulas for natural frequency, table 8-1)
LITERATURE = [3.926602312, 7.068582745, 10.21017612, 13.35176878, 16.49336143, 19.63495408]

# Gauss-Legendre on [0, 1]: exact for the smooth shapes at this order, and not the
# closed forms the module uses
_X, _W = np.polynomial.legendre.leggauss(80)
XI, WQ = 0.5 * (_X + 1.0), 0.5 * _W


def _shapes(n):
    b, c, r, psi, beta = pinned_free_modes(n)
    return np.array([mode_shape(XI, b[i], c[i], r[i]) for i in range(n)]), b, c, r


def test_eigenvalues_are_the_hinged_free_beams():
    b = pinned_free_modes(MAX_MODES)[0]
    assert np.allclose(b, LITERATURE, rtol=0, atol=2e-8)
    assert np.all(np.abs(np.tan(b) - np.tanh(b)) < 1e-12)


def test_mode_shapes_against_quadrature():
    n = MAX_MODES
    phi, b, c, r = _shapes(n)
    _, _, _, psi, beta = pinned_free_modes(n)
    gram = (phi * WQ) @ phi.T
    assert np.allclose(gram, np.eye(n), atol=1e-12)
    # orthogonal to the rigid rotation xi: phi is the mean axis, M is diagonal
    assert np.allclose(phi @ (WQ * XI), 0.0, atol=1e-12)
    assert np.allclose(phi @ WQ, beta, atol=1e-12)
    # bending energy: int Phi_i'' Phi_j'' = b^4 delta_ij
    dd = np.array([c[i] * b[i] ** 2 * (-np.sin(b[i] * XI) + r[i] * np.sinh(b[i] * XI))
                   for i in range(n)])
    assert np.allclose((dd * WQ) @ dd.T / np.outer(b ** 2, b ** 2), np.eye(n), atol=1e-10)
    # hinge (no moment) and free tip (no moment, no shear), from the derivatives of the shape
    for i in range(n):
        bb, cc, rr = b[i], c[i], r[i]
        d2 = lambda x: cc * bb ** 2 * (-math.sin(bb * x) + rr * math.sinh(bb * x))
        d3 = lambda x: cc * bb ** 3 * (-math.cos(bb * x) + rr * math.cosh(bb * x))
        assert float(mode_shape(0.0, bb, cc, rr)) == 0.0 and d2(0.0) == 0.0
        assert abs(float(mode_shape(1.0, bb, cc, rr)) - psi[i]) < 1e-13
        assert abs(d2(1.0)) < 1e-13 * bb ** 2 and abs(d3(1.0)) < 1e-13 * bb ** 3


def _field(scene, q, t, xi=XI):
    """Positions (over l) of the material points of the beam, from the displacement field."""
    n = scene.N
    b, c, r, _, _ = pinned_free_modes(n)
    w = sum(mode_shape(xi, b[i], c[i], r[i]) * q[1 + i] for i in range(n)) if n else 0.0 * xi
    phi = q[0]
    x = xi * math.cos(phi) - w * math.sin(phi)
    y = scene.u1(t) + xi * math.sin(phi) + w * math.cos(phi)
    return x, y


@pytest.mark.parametrize("n", [1, 3])
def test_mass_matrix_is_the_kinetic_energy_of_the_field(n):
    s = FlexibleRodDrive(modes=n)
    rng = np.random.default_rng(1)
    q = np.concatenate([[0.7], 1e-3 * rng.standard_normal(n), [0.3]])
    v = rng.standard_normal(n + 2)
    dt = 1e-6
    # at t = 0 the stator is at rest: T is 1/2 v M v plus the dropped 1/2 |eta|^2 phi'^2
    xp, yp = _field(s, q + dt * v, dt)
    xm, ym = _field(s, q - dt * v, -dt)
    vx, vy = (xp - xm) / (2 * dt), (yp - ym) / (2 * dt)
    T_rod = 0.5 * WQ @ (vx ** 2 + vy ** 2)
    T_model = 0.5 * v @ s.mass(q) @ v - 0.5 * s.J * v[-1] ** 2
    dropped = 0.5 * float(q[1:1 + n] @ q[1:1 + n]) * v[0] ** 2
    assert abs(T_rod - T_model - dropped) < 1e-9 * T_rod


@pytest.mark.parametrize("t", [0.0, 0.4, 2.5])
def test_forces_are_minus_the_gradient_of_the_potential(t):
    # the spring, the bending energy and the base acceleration as the body force -u1'' e_y
    n = 2
    s = FlexibleRodDrive(modes=n, damping=0.0)
    q = np.array([0.76, 2e-3, -1e-3, 0.1])

    def V(q):
        _, y = _field(s, q, t)
        return (0.5 * s.P * (s.sin_phi0 - math.sin(q[0])) ** 2
                + 0.5 * float(np.sum(s.Omega ** 2 * q[1:1 + n] ** 2))
                + float(s.ddu1(t)) * float(WQ @ y))

    grad = np.empty(n + 2)
    for j in range(n + 2):
        e = np.zeros(n + 2)
        e[j] = 1e-6
        grad[j] = (V(q + e) - V(q - e)) / 2e-6
    h = s.forces(q, np.zeros(n + 2), t)
    h[-1] += s.fL
    assert np.allclose(h, -grad, rtol=1e-7, atol=1e-7 * np.max(np.abs(h)))


def test_damping_is_modal():
    s = FlexibleRodDrive(modes=2, damping=0.03)
    q, v = np.zeros(4), np.array([0.0, 1.0, -2.0, 0.0])
    q[0] = s.phi0
    dh = s.forces(q, v, 1.0) - s.forces(q, 0 * v, 1.0)
    assert np.allclose(dh[1:3], -2 * 0.03 * s.Omega * v[1:3], rtol=1e-14)


def test_gap_is_the_tip_of_the_field():
    s = FlexibleRodDrive(modes=3)
    q = np.array([0.75, 1e-3, -2e-3, 5e-4, 0.2])
    x, y = _field(s, q, 0.9, xi=np.array([1.0]))
    assert abs(s.gaps(q, 0.9)[0] - (s.sin_phi0 - y[0])) < 1e-15
    WN, wN, WT, wT = s.contact_jacobians(q, 0.9)
    # the slip velocity is d/dt (x2 - tip_x) along the motion
    v = np.array([0.3, -1.0, 2.0, 0.5, 0.7])
    dt = 1e-6
    tip = lambda sgn: _field(s, q + sgn * dt * v, 0.9, xi=np.array([1.0]))[0][0]
    slip = v[-1] - (tip(1) - tip(-1)) / (2 * dt)
    assert abs(WT[0] @ v + wT[0] - slip) < 1e-8
    assert abs(s.slip_velocity(q, v) - slip) < 1e-8


@pytest.mark.parametrize("n", range(0, 4))
def test_check_scene(n):
    # the modal stiffness W^2 ~ 1e5..1e7 makes central differences of h lose
    # digits to rounding: the Jacobian check takes 1e-5 beyond one mode
    rep = check_scene(FlexibleRodDrive(modes=n), fd_tol=1e-6 if n <= 1 else 1e-5)
    assert rep.ok, rep.summary()
    assert rep.errors["compiled model"] <= 1e-12


def test_contact_frequencies_converge_to_the_pinned_pinned_beam():
    # tip held on the rotor, no spring: Rayleigh-Ritz from above onto pi^2, (2 pi)^2
    rows = []
    for n in (1, 2, 4, 6):
        s = FlexibleRodDrive(modes=n, k=1e-9)
        unit = math.sqrt(s.params.EI / (s.params.m * s.params.length ** 3)) / (2 * math.pi)
        rows.append(s.contact_frequencies() / unit)
    first = [r[0] for r in rows]
    assert all(a > b > math.pi ** 2 for a, b in zip(first, first[1:]))
    assert abs(first[-1] / math.pi ** 2 - 1) < 1e-3
    assert abs(rows[-1][1] / (2 * math.pi) ** 2 - 1) < 2e-3


def test_first_bending_frequency_is_the_closed_form():
    s = FlexibleRodDrive(modes=2, EI=3e-6, frequency=500.0)
    p = s.params
    f1 = 3.926602312 ** 2 / (2 * math.pi) * math.sqrt(p.EI / (p.m * p.length ** 3))
    assert abs(s.bending_frequency / f1 - 1) < 1e-9
    assert abs(s.Omega[0] - f1 / 500.0) < 1e-9 * s.Omega[0]
    d = s.derived_quantities()
    assert d["first_bending_frequency_Hz"] == s.bending_frequency
    assert len(d["bending_frequencies_Hz"]) == 2
    # the same with no mode kept: the frequency belongs to the rod, not to the reduction
    assert FlexibleRodDrive(modes=0, EI=3e-6).bending_frequency == s.bending_frequency


def test_rigid_limit_has_the_rigid_scenes_compiled_model():
    flex, rigid = FlexibleRodDrive(modes=0, frequency=300.0), FrictionDrive(frequency=300.0)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, v, t = rng.standard_normal(2) * 0.3 + [0.7, 0], rng.standard_normal(2), rng.random() * 6
        a = evaluate_compiled(flex.compiled_model(), q, v, t)
        b = evaluate_compiled(rigid.compiled_model(), q, v, t)
        for key in a:
            assert np.allclose(a[key], b[key], rtol=1e-15, atol=1e-15), key


def test_preload_acts_on_the_rigid_rotation_as_in_the_rigid_scene():
    if "preload" not in {f.name for f in fields(FrictionDriveParams)}:
        # a rigid rod without a preload: the flexible one refuses one, by name
        with pytest.raises(InputError, match="`preload`"):
            FlexibleRodDrive(preload=1e-3)
        return
    flex = FlexibleRodDrive(modes=0, preload=1e-3)
    rigid = FrictionDrive(frequency=185.0, preload=1e-3)
    q, v = np.array([0.7, 0.1]), np.array([0.2, -0.1])
    a = evaluate_compiled(flex.compiled_model(), q, v, 0.3)
    b = evaluate_compiled(rigid.compiled_model(), q, v, 0.3)
    for key in a:
        assert np.allclose(a[key], b[key], rtol=1e-15, atol=1e-15), key
    rep = check_scene(FlexibleRodDrive(modes=2, preload=1e-3), fd_tol=1e-5)
    assert rep.ok, rep.summary()


def test_rigid_limit_reproduces_the_rigid_trajectory():
    flex, rigid = FlexibleRodDrive(modes=0), FrictionDrive()
    out = []
    for sc in (flex, rigid):
        q0, v0 = sc.rest_state()
        out.append(simulate(sc, (0.0, 4 * math.pi), q0, v0, "moreau-jean", h=2 * math.pi / 500))
    assert np.max(np.abs(out[0].q - out[1].q)) <= 1e-12 * np.max(np.abs(out[1].q))
    assert np.max(np.abs(out[0].v - out[1].v)) <= 1e-12 * np.max(np.abs(out[1].v))


@pytest.mark.parametrize("bad, word", [
    (dict(modes=-1), "`modes`"), (dict(modes=MAX_MODES + 1), "`modes`"),
    (dict(modes=1.5), "`modes`"), (dict(modes=float("nan")), "`modes`"), (dict(EI=0.0), "`EI`"), (dict(EI=float("nan")), "`EI`"),
    (dict(damping=-0.1), "`damping`"), (dict(mu=-1.0), "`mu`"), (dict(x10=1e-3), "`x10`"),
])
def test_bad_parameters_raise_named_errors(bad, word):
    with pytest.raises(InputError, match=word):
        FlexibleRodDrive(**bad)


def test_a_whole_float_is_a_number_of_modes():
    # the command line passes --set modes=2 as 2.0
    assert FlexibleRodDrive(modes=2.0).N == 2


def test_to_si_gives_the_tip_deflection():
    s = FlexibleRodDrive(modes=2)
    q0, v0 = s.rest_state()
    # the generic step: a question of units, and no loop to compile for two modes
    res = simulate(s, (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, fast=False)
    si = s.to_si(res)
    assert np.allclose(si["tip_deflection"], (res.q[:, 1:3] @ s.psi) * s.params.length,
                       rtol=1e-15)
    assert np.array_equal(si["x2"], si["q"][:, -1])
    assert np.max(np.abs(si["tip_deflection"])) > 0.0


def test_steady_state_converges_to_the_rigid_rods_as_one_over_EI():
    # the static deflection under the contact force falls as 1/EI, so does the
    # difference of the steady displacements; Moreau–Jean at a step that resolves
    # the bending mode (W1 h <= 0.4), against the rigid rod at the same step
    steps = 8000
    rigid = moreau_jean_steady_state(FrictionDrive(), steps).displacement_per_period
    EI = np.array([3e-6, 3e-5])
    diff = []
    for e in EI:
        scene = FlexibleRodDrive(EI=e)
        assert scene.Omega[0] * 2 * math.pi / steps <= 0.41
        d = moreau_jean_steady_state(scene, steps).displacement_per_period
        diff.append(abs(d - rigid) / abs(rigid))
    slope = math.log(diff[1] / diff[0]) / math.log(EI[1] / EI[0])
    assert -1.15 < slope < -0.85, (diff, slope)
    assert diff[0] < 0.02


def test_steady_json_reports_the_bending_frequencies(capsys):
    assert main(["steady", "--scene", "flexible-rod-drive", "--frequency", "185", "--scheme",
                 "moreau-jean", "--steps-per-period", "1000", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    p = FlexibleRodDrive().params
    f1 = 3.926602312 ** 2 / (2 * math.pi) * math.sqrt(p.EI / (p.m * p.length ** 3))
    assert abs(out["derived"]["first_bending_frequency_Hz"] / f1 - 1) < 1e-9
    assert out["parameters"]["modes"] == 1 and out["mode"] == "NP"
