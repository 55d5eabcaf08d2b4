"""Friction drive formulas against independent computations.

Layer 1: the closed-form coefficients A..E and regime forces against the
generic computation from the scene's mass matrix, contact Jacobians and free
accelerations (to 1e-12 relative). Layer 2: the scene's mass matrix, forces,
Jacobians and drift terms against the Lagrangian written from the geometry
(rod centre, tip, spring), differentiated numerically.
"""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.regimes import Regime
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams

rng = np.random.default_rng(12345)


def random_scene():
    p = FrictionDriveParams(phi0=rng.uniform(0.3, 1.3), mu=rng.uniform(0.0, 0.6),
                            load=rng.uniform(-1e-3, 1e-3), m2=rng.uniform(1e-4, 1e-2),
                            k=rng.uniform(1e3, 1e5))
    return FrictionDrive(p, frequency=float(np.exp(rng.uniform(np.log(10), np.log(12500)))))


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def generic_coefficients(sc, q, v, t):
    M = sc.mass(q)
    h = sc.forces(q, v, t)
    WN, _, WT, _ = sc.contact_jacobians(q, t)
    wNb, wTb = sc.contact_drift(q, v, t)
    Minv = np.linalg.inv(M)
    A = (WN @ Minv @ WN.T)[0, 0]
    B = -(WN @ Minv @ WT.T)[0, 0]
    C = (WT @ Minv @ WT.T)[0, 0]
    D = (WN @ Minv @ h)[0] + wNb[0]
    E = (WT @ Minv @ h)[0] + wTb[0]
    return A, B, C, D, E


@pytest.mark.parametrize("trial", range(40))
def test_coefficients_match_generic_computation(trial):
    sc = random_scene()
    if sc.mu[0] == 0:
        return
    phi = rng.uniform(0.05, 1.5)
    q = np.array([phi, rng.normal()])
    v = np.array([rng.normal() * 0.1, rng.normal()])
    t = rng.uniform(0, 2 * np.pi)
    closed = sc.coefficients(phi, v[0], t)
    generic = generic_coefficients(sc, q, v, t)
    for name, a, b in zip("ABCDE", closed, generic):
        assert rel(a, b) < 1e-12 or abs(a - b) < 1e-14 * (1 + sc.P), (name, a, b)


@pytest.mark.parametrize("trial", range(30))
def test_regime_forces_match_constrained_dynamics(trial):
    """Solve M a = h + WN fN + WT fT with the regime's constraints as one linear system."""
    sc = random_scene()
    mu = float(sc.mu[0])
    t = rng.uniform(0, 2 * np.pi)
    phi, dphi, _ = sc.contact_angle(t)
    q = np.array([phi, 0.3])
    v = np.array([dphi, 0.01])
    M, h = sc.mass(q), sc.forces(q, v, t)
    WN = np.array([-math.cos(phi), 0.0])
    WT = np.array([math.sin(phi), 1.0])
    wNb = dphi ** 2 * math.sin(phi) - sc.ddu1(t)
    wTb = dphi ** 2 * math.cos(phi)
    # stick: unknowns (a1, a2, fN, fT)
    K = np.zeros((4, 4))
    K[:2, :2] = M
    K[:2, 2] = -WN
    K[:2, 3] = -WT
    K[2, :2] = WN
    K[3, :2] = WT
    sol = np.linalg.solve(K, np.r_[h, -wNb, -wTb])
    fN, fT = sc.contact_forces(t, Regime.STICK)
    assert rel(fN, sol[2]) < 1e-12 and rel(fT, sol[3]) < 1e-12
    for reg, sgn in ((Regime.POSITIVE, -1.0), (Regime.NEGATIVE, 1.0)):
        K = np.zeros((3, 3))
        K[:2, :2] = M
        K[:2, 2] = -(WN + sgn * mu * WT)
        K[2, :2] = WN
        sol = np.linalg.solve(K, np.r_[h, -wNb])
        fN, fT = sc.contact_forces(t, reg)
        assert rel(fN, sol[2]) < 1e-12
        assert abs(fT - sgn * mu * sol[2]) <= 1e-12 * abs(sol[2])


# -- layer 2: the Lagrangian from the geometry ----------------------------------

def lagrangian_pieces(sc):
    """T(q, v, tau) and V(q) of the physical system, in dimensionless units."""
    u10, phi0, P, J = sc.u10, sc.phi0, sc.P, sc.J

    def kinetic(q, v, tau):
        phi, _ = q
        dphi, du2 = v
        du1 = u10 * np.sin(tau)
        # rod centre (cos(phi)/2, u1 + sin(phi)/2), rod inertia about its centre 1/12
        xc_dot = -0.5 * np.sin(phi) * dphi
        yc_dot = du1 + 0.5 * np.cos(phi) * dphi
        return 0.5 * (xc_dot ** 2 + yc_dot ** 2) + 0.5 * dphi ** 2 / 12.0 + 0.5 * J * du2 ** 2

    def potential(q):
        return 0.5 * P * (np.sin(phi0) - np.sin(q[0])) ** 2

    return kinetic, potential


def fd(f, x, i, h=1e-5):
    """Central 6th-order difference of f along coordinate i."""
    e = np.zeros_like(x)
    e[i] = h
    c = (f(x + 3 * e) - 9 * f(x + 2 * e) + 45 * f(x + e) - 45 * f(x - e) + 9 * f(x - 2 * e) - f(x - 3 * e))
    return c / (60 * h)


@pytest.mark.parametrize("trial", range(10))
def test_scene_matches_lagrangian(trial):
    sc = FrictionDrive(FrictionDriveParams(phi0=rng.uniform(0.4, 1.2), mu=0.3, load=1e-4),
                       frequency=rng.uniform(20, 3000))
    T, V = lagrangian_pieces(sc)
    q = np.array([rng.uniform(0.3, 1.2), 0.2])
    v = np.array([rng.normal() * 0.01, rng.normal() * 0.01])
    tau = rng.uniform(0, 2 * np.pi)
    # mass matrix: Hessian of T in v (T is quadratic in v)
    M = np.array([[fd(lambda vv: fd(lambda w: T(q, w, tau), vv, j), v, i) for j in range(2)]
                  for i in range(2)])
    assert np.allclose(M, sc.mass(q), rtol=1e-7, atol=1e-7)
    # forces: h = dL/dq - d/dt(dT/dv) + M a, i.e. everything but the inertia of a
    X = np.r_[q, v, tau]

    def p_i(x, i):
        return fd(lambda w: T(x[:2], w, x[4]), x[2:4], i)

    dLdq = np.array([fd(lambda x: T(x[:2], x[2:4], x[4]) - V(x[:2]), X, i) for i in range(2)])
    d_dt_p = np.array([sum(fd(lambda x: p_i(x, i), X, j) * X[2 + j] for j in range(2))
                       + fd(lambda x: p_i(x, i), X, 4) for i in range(2)])
    h_lagr = dLdq - d_dt_p + np.array([0.0, -sc.fL])
    assert np.allclose(h_lagr, sc.forces(q, v, tau), rtol=1e-6, atol=1e-8 * (1 + sc.P))
    # contact jacobians from the gap and slip positions
    gN = lambda x: np.sin(sc.phi0) - np.sin(x[0]) - sc.u10 * (1 - np.cos(x[2]))
    gT = lambda x: x[1] - np.cos(x[0])
    Y = np.r_[q, tau]
    WN, wN, WT, wT = sc.contact_jacobians(q, tau)
    assert np.allclose([fd(gN, Y, 0), fd(gN, Y, 1)], WN[0], atol=1e-9)
    assert np.isclose(fd(gN, Y, 2), wN[0], atol=1e-9)
    assert np.allclose([fd(gT, Y, 0), fd(gT, Y, 1)], WT[0], atol=1e-9)
    # drift: second derivative of the gap along the motion with zero acceleration
    path = lambda s: np.array([gN(np.r_[q + s * v, tau + s]), gT(np.r_[q + s * v, tau + s])])
    d2 = (path(1e-3) - 2 * path(0.0) + path(-1e-3)) / 1e-6
    wNb, wTb = sc.contact_drift(q, v, tau)
    assert np.allclose(d2, [wNb[0], wTb[0]], rtol=1e-5, atol=1e-8)


def test_paper_dimensionless_constants():
    sc = FrictionDrive(frequency=20.0)
    w = 2 * math.pi * 20.0
    assert sc.J == pytest.approx(100.0)
    assert sc.P == pytest.approx(1e4 / (2e-5 * w * w), rel=1e-14)
    assert sc.u10 == pytest.approx(2e-3)
    assert 3e4 < sc.P < 3.3e4


def test_coefficient_signs():
    sc = FrictionDrive()
    for phi in np.linspace(0.05, 1.5, 20):
        A, B, C, _, _ = sc.coefficients(phi, 0.0, 0.0)
        assert A > 0 and B > 0 and C > 0 and A * C > B * B


@pytest.mark.parametrize("kw, match", [
    (dict(m=-1.0), r"`m` must be > 0"),
    (dict(m2=0.0), r"`m2` must be > 0"),
    (dict(k=float("nan")), r"`k` must be finite"),
    (dict(length=-1e-3), r"`length` must be > 0"),
    (dict(mu=-0.1), r"`mu` must be >= 0"),
    (dict(phi0=0.0), r"`phi0` must be in the open interval \(0, pi/2\)"),
    (dict(phi0=1.6), r"`phi0` must be in the open interval"),
    (dict(x10=0.0), r"`x10` must be > 0"),
    (dict(x10=1e-3), r"`x10` must be < length\*sin\(phi0\)/2"),
    (dict(load=float("inf")), r"`load` must be finite"),
    (dict(restitution=1.5), r"`restitution` must be in \[0.0, 1.0\]"),
])
def test_bad_parameters(kw, match):
    with pytest.raises(InputError, match=match):
        FrictionDriveParams(**kw)


@pytest.mark.parametrize("f", [0.0, -5.0, float("nan"), float("inf")])
def test_bad_frequency(f):
    with pytest.raises(InputError, match="`frequency`"):
        FrictionDrive(frequency=f)
