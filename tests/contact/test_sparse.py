"""The block-sparse problem's pieces against independent computations.

* :func:`disk_jacobian` against the contact-point velocity computed with a 3D
  cross product, ``v + omega e_z x (p - c)``, projected on ``n`` and ``t``;
* :func:`delassus` (``M^-1`` per body, CSR) against the dense product;
* the chain's block result against the project's Lemke solution of the same
  impact (:func:`moreau.scenes.ball_chain.simultaneous_impact`) and against
  its own residual (zero);
* the cone projection against its defining property (the closest point of
  the cone, checked against a fine sampling of the cone's boundary).
"""

import numpy as np
import pytest

from moreau.contact._sparse import (chain_impact_problem, delassus, disk_jacobian,
                                    problem_residual, project_cone)
from moreau.scenes.ball_chain import simultaneous_impact


def test_disk_jacobian_is_the_contact_point_velocity():
    rng = np.random.default_rng()
    nb = 4
    centres = rng.standard_normal((nb, 2))
    contacts = []
    for _ in range(5):
        a, b = rng.choice(np.arange(-1, nb), size=2, replace=False)
        ang = rng.uniform(0, 2 * np.pi)
        contacts.append((int(a), int(b), rng.standard_normal(2), (np.cos(ang), np.sin(ang))))
    H = disk_jacobian(contacts, centres, nb).toarray()
    v = rng.standard_normal(3 * nb)
    got = H @ v
    for i, (a, b, p, n) in enumerate(contacts):
        n3 = np.array([n[0], n[1], 0.0])
        t3 = np.cross([0.0, 0.0, 1.0], n3)           # t = e_z x n = (-n_y, n_x)
        rel = np.zeros(3)
        for body, sign in ((a, -1.0), (b, 1.0)):
            if body >= 0:
                vb = np.array([v[3 * body], v[3 * body + 1], 0.0])
                d = np.array([p[0] - centres[body, 0], p[1] - centres[body, 1], 0.0])
                rel += sign * (vb + np.cross([0.0, 0.0, v[3 * body + 2]], d))
        assert got[2 * i] == pytest.approx(rel @ n3, abs=1e-12)
        assert got[2 * i + 1] == pytest.approx(rel @ t3, abs=1e-12)


def test_delassus_per_body_equals_dense_product():
    rng = np.random.default_rng()
    nb, k = 6, 3
    H = rng.standard_normal((8, nb * k))
    H[rng.random(H.shape) < 0.5] = 0.0
    blocks = []
    for _ in range(nb):
        A = rng.standard_normal((k, k))
        blocks.append(A @ A.T + np.eye(k))
    Minv_dense = np.zeros((nb * k, nb * k))
    for b, B in enumerate(blocks):
        Minv_dense[b * k:(b + 1) * k, b * k:(b + 1) * k] = B
    W = delassus(H, np.array(blocks))
    assert np.allclose(W.toarray(), H @ Minv_dense @ H.T, rtol=1e-13, atol=1e-13)
    diag = rng.uniform(0.5, 2.0, (nb, k))
    W = delassus(H, diag)
    assert np.allclose(W.toarray(), H @ np.diag(diag.ravel()) @ H.T, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("N, e", [(2, 1.0), (3, 0.0), (10, 1.0), (25, 0.6)])
def test_chain_block_result_matches_lemke_and_has_zero_residual(N, e):
    W, q, mu, r = chain_impact_problem(N, e=e)
    assert problem_residual(W, q, mu, r)[0] <= 1e-15
    # velocities from the impulses: ball i gets -P_i, ball i + 1 gets +P_i (unit masses)
    v = np.zeros(N)
    v[0] = 1.0
    P = r[0::2]
    v[:-1] -= P
    v[1:] += P
    ref = simultaneous_impact(np.ones(N), np.eye(N)[0], e)
    assert np.allclose(v, ref, rtol=0, atol=1e-12)
    assert v[1:] == pytest.approx(np.full(N - 1, (1 + e) / N), abs=1e-14)


def test_cone_projection_is_the_closest_point():
    rng = np.random.default_rng()
    for _ in range(200):
        mu = float(rng.choice([0.0, rng.uniform(0.05, 2.0)]))
        x = rng.standard_normal(2) * 3
        p = np.array(project_cone(mu, x[0], x[1]))
        assert abs(p[1]) <= mu * p[0] + 1e-15
        # closer than every sampled point of the cone (both edges, the apex)
        t = np.linspace(0.0, 10.0, 2001)
        pts = np.concatenate([np.column_stack([t, mu * t]), np.column_stack([t, -mu * t])])
        assert np.linalg.norm(x - p) <= np.min(np.linalg.norm(pts - x, axis=1)) + 1e-12
