"""Problem generators shared by the contact-solver tests (imported by name, not a conftest)."""

import numpy as np
from moreau.lcp import solve_lcp
from moreau.lcp.friction import build_friction_lcp, friction_impulses


def random_problem(nc, rng, mu_max=0.5, frictionless=0.25):
    """A random FCLib-form 2D problem with a positive definite ``W`` and feasible ``q``.

    ``W = J M^-1 J^T`` with more degrees of freedom than contact rows (so
    ``W`` is positive definite) and ``q = J v`` for a random ``v``.
    """
    ndof = 2 * nc + int(rng.integers(1, 4))
    A = rng.standard_normal((ndof, ndof))
    Mass = A @ A.T / ndof + 0.2 * np.eye(ndof)
    J = rng.standard_normal((2 * nc, ndof))
    W = J @ np.linalg.solve(Mass, J.T)
    W = 0.5 * (W + W.T)
    v = rng.standard_normal(ndof)
    q = J @ v
    mu = rng.uniform(0.05, mu_max, nc)
    mu[rng.random(nc) < frictionless] = 0.0
    return W, q, mu


def lemke_reference(W, q, mu):
    """The same problem through the project's friction LCP and Lemke: ``(r, u)`` interleaved."""
    nc = mu.shape[0]
    fr = np.flatnonzero(mu > 0.0)
    rows = np.concatenate([2 * np.arange(nc), 2 * fr + 1])   # [N all; T frictional]
    Ws = W[np.ix_(rows, rows)]
    M, qq, layout = build_friction_lcp(Ws, q[rows], mu, 0.0, np.zeros(nc))
    res = solve_lcp(M, qq, method="lemke")
    assert res.success, res.message
    p = friction_impulses(res.z, layout, stacked=True)
    r = np.zeros(2 * nc)
    r[rows] = p
    return r, W @ r + q
