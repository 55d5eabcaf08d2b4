"""Spatial rigid-body kinematics: the exponential map, Euler's equations, invariants.

References by hand: a body with isotropic inertia keeps a constant body rate,
so the exact orientation is q0 ⊗ exp(t omega / 2); a torque-free symmetric
body (J1 = J2) keeps omega_3 and turns (omega_1, omega_2) at
Omega = (J3 - J1)/J1 omega_3 in the body frame (Euler's equations
J1 omega_1' = (J1 - J3) omega_2 omega_3, J1 omega_2' = (J3 - J1) omega_3 omega_1),
while its symmetry axis precesses about the fixed world angular momentum L
at the rate |L| / J1, at the constant angle cos(theta) = J3 omega_3 / |L|.
"""


import numpy as np
import pytest

from moreau.errors import InputError
from moreau.model.spatial import (
    check_inertia,
    free_rigid_body,
    gyroscopic_torque,
    kinetic_energy,
    quat_exp,
    quat_multiply,
    rotate_body,
    rotation_matrix,
    world_angular_momentum,
)

Q0 = quat_exp([0.3, -0.2, 0.5])          # an arbitrary start


def test_exponential_map_is_exact_for_a_constant_rate_and_keeps_the_unit_norm():
    omega = np.array([0.7, -1.3, 2.1])
    n, h = 100_000, 1e-3
    qs, ws = free_rigid_body(Q0, omega, [1.5, 1.5, 1.5], h, n)
    assert np.all(ws == omega)                              # no gyroscopic term
    exact = quat_multiply(Q0, quat_exp(0.5 * n * h * omega))
    np.testing.assert_allclose(qs[-1], exact, rtol=0, atol=1e-12)
    assert np.max(np.abs(np.linalg.norm(qs, axis=1) - 1.0)) <= 1e-14


def test_rotation_matrix_is_the_quaternion_rotation():
    rng = np.random.default_rng(4)
    for _ in range(10):
        q = quat_exp(rng.standard_normal(3))
        v = rng.standard_normal(3)
        conj = q * [1, -1, -1, -1]
        rotated = quat_multiply(quat_multiply(q, np.r_[0.0, v]), conj)
        np.testing.assert_allclose(rotation_matrix(q) @ v, rotated[1:], atol=1e-14)
        R = rotation_matrix(q)
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)
    # d/dt R = R [omega]x for q' = 1/2 q ⊗ (0, omega): central difference
    omega, h = np.array([0.4, 1.1, -0.6]), 1e-5
    dR = (rotation_matrix(rotate_body(Q0, omega, h))
          - rotation_matrix(rotate_body(Q0, -omega, h))) / (2 * h)
    wx = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])
    np.testing.assert_allclose(dR, rotation_matrix(Q0) @ wx, atol=1e-9)


def test_gyroscopic_term_against_eulers_equations_written_out():
    J = np.array([1.0, 2.0, 2.5])
    w = np.array([0.3, -1.2, 0.8])
    expected = [(J[2] - J[1]) * w[1] * w[2], (J[0] - J[2]) * w[2] * w[0],
                (J[1] - J[0]) * w[0] * w[1]]
    np.testing.assert_allclose(gyroscopic_torque(J, w), expected, rtol=1e-15)


def _free_asymmetric(h, T=20.0):
    J = np.diag([1.0, 2.0, 2.5])
    qs, ws = free_rigid_body(Q0, [0.05, 2.0, 0.1], J, h, int(round(T / h)))
    return J, qs, ws


def test_free_asymmetric_body_keeps_energy_and_momentum_and_the_unit_norm():
    # near the intermediate axis: the body flips (Dzhanibekov), a hard test
    J, qs, ws = _free_asymmetric(1e-3)
    E = np.array([kinetic_energy(J, w) for w in ws])
    Lb = np.linalg.norm(ws @ J, axis=1)
    assert np.max(np.abs(E / E[0] - 1)) < 1e-12                 # midpoint: quadratic invariant
    assert np.max(np.abs(Lb / Lb[0] - 1)) < 1e-12
    assert np.max(np.abs(np.linalg.norm(qs, axis=1) - 1.0)) <= 1e-14
    assert ws[:, 1].min() < -1.9                               # it did flip
    # the world angular momentum vector: kept to the scheme's order 2
    errs = []
    for h in (4e-3, 2e-3, 1e-3):
        J, qs, ws = _free_asymmetric(h, T=5.0)
        L = world_angular_momentum(qs[[0, -1]], J, ws[[0, -1]])
        errs.append(np.linalg.norm(L[1] - L[0]) / np.linalg.norm(L[0]))
    order = np.log2(errs[0] / errs[1]), np.log2(errs[1] / errs[2])
    assert all(1.8 < p < 2.2 for p in order), (errs, order)


def test_symmetric_top_matches_eulers_closed_form_and_precesses_at_L_over_J1():
    J1, J3, a, w3 = 2.0, 3.0, 0.6, 4.0
    J = np.diag([J1, J1, J3])
    Omega = (J3 - J1) / J1 * w3
    T = 3.0
    errs = []
    for h in (2e-3, 1e-3, 5e-4):
        n = int(round(T / h))
        qs, ws = free_rigid_body(Q0, [a, 0.0, w3], J, h, n)
        t = np.arange(n + 1) * h
        exact = np.column_stack([a * np.cos(Omega * t), a * np.sin(Omega * t), np.full_like(t, w3)])
        errs.append(np.max(np.abs(ws - exact)))
        # space precession of the symmetry axis about L
        L = world_angular_momentum(qs[0], J, ws[0])
        Lh = L / np.linalg.norm(L)
        e1 = np.cross(Lh, [1.0, 0.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(Lh, e1)
        axes = np.array([rotation_matrix(q)[:, 2] for q in qs[:: n // 30]])
        assert np.allclose(axes @ Lh, J3 * w3 / np.linalg.norm(L), atol=1e-5)
        phi = np.unwrap(np.arctan2(axes @ e2, axes @ e1))
        rate = np.polyfit(t[:: n // 30], phi, 1)[0]
        assert rate == pytest.approx(np.linalg.norm(L) / J1, rel=1e-5)
    assert errs[-1] < 1e-5
    assert 1.9 < np.log2(errs[0] / errs[1]) < 2.1 and 1.9 < np.log2(errs[1] / errs[2]) < 2.1, errs


@pytest.mark.parametrize("call, name", [
    (lambda: free_rigid_body([1.0, 0.0, 0.1, 0.0], [0, 0, 1], [1, 1, 1], 1e-3, 10), "`q0`"),
    (lambda: free_rigid_body(Q0, [0, 0, 1], [1.0, -1.0, 1.0], 1e-3, 10), "`inertia`"),
    (lambda: check_inertia([1.0, 1.0, 2.5]), "triangle inequality"),
    (lambda: check_inertia([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]]), "symmetric"),
    (lambda: free_rigid_body(Q0, [0, 0, 1], [1, 1, 1], 0.0, 10), "`h`"),
    (lambda: free_rigid_body(Q0, [0, 0, 1], [1, 1, 1], 1e-3, 0), "`n_steps`"),
    (lambda: rotate_body(Q0, [0, np.nan, 1], 1e-3), "`omega`"),
])
def test_bad_input_is_refused_by_name(call, name):
    with pytest.raises(InputError, match=name):
        call()
