"""Shared helpers of the LCP tests."""

from fractions import Fraction

import numpy as np
import pytest

from moreau.lcp.instances import all_instances

#: bound on the scaled residual each method must meet when it reports success
TOL = {"lemke": 1e-9, "qp": 1e-6, "auto": 1e-6}


def assert_complementary(M, q, z, tol):
    """Check z >= 0, w >= 0 and z.w = 0 directly, each relative to the data's scale."""
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    z = np.asarray(z, dtype=float)
    w = M @ z + q
    assert np.all(np.isfinite(z)) and np.all(np.isfinite(w))
    scale = 1.0 + np.max(np.abs(q), initial=0.0) + np.max(np.abs(M), initial=0.0) * np.max(np.abs(z), initial=0.0)
    assert np.min(z, initial=0.0) >= -tol * scale, f"z has a negative entry {np.min(z)}"
    assert np.min(w, initial=0.0) >= -tol * scale, f"w has a negative entry {np.min(w)}"
    gap = np.max(np.abs(np.minimum(z, w)), initial=0.0)
    assert gap <= tol * scale, f"complementarity violated: max|min(z, w)| = {gap}"
    zs = np.max(np.abs(z), initial=0.0)
    ws = np.max(np.abs(w), initial=0.0)
    with np.errstate(over="ignore"):  # near-singular data: the bound may be inf, which is fine
        assert abs(z @ w) <= tol * scale * max(zs, ws, 1.0) * len(z)


def exact_w(M, q, z):
    """``M z + q`` in exact rational arithmetic on the given floats (an independent check)."""
    n = len(q)
    zf = [Fraction(float(v)) for v in z]
    return [Fraction(float(q[i])) + sum(Fraction(float(M[i, j])) * zf[j] for j in range(n) if zf[j])
            for i in range(n)]


def assert_certified(M, q, z, tol):
    """The certification of issue 7, written out: tolerances fixed by the data only.

    ``z >= -tol_z``, ``w >= -tol_w`` and, for every ``i``, ``z_i <= tol_z``
    or ``w_i <= tol_w``, with ``tol_w = tol max|q|`` and ``tol_z = tol_w /
    max|M|``. Nothing here grows with ``z``.
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    z = np.asarray(z, dtype=float)
    w = M @ z + q
    assert np.all(np.isfinite(z)) and np.all(np.isfinite(w))
    tol_w = tol * (np.max(np.abs(q), initial=0.0) or 1.0)
    tol_z = tol_w / (np.max(np.abs(M), initial=0.0) or 1.0)
    assert np.all(z >= -tol_z), f"z has a negative entry {np.min(z)} < -{tol_z:.3g}"
    if len(q) <= 24:
        # on the exact w: a float product can neither hide a violation nor make one up
        we = exact_w(M, q, z)
        tw, tz = Fraction(float(tol_w)), Fraction(float(tol_z))
        for i, wi in enumerate(we):
            zi = Fraction(float(z[i]))
            assert wi >= -tw, f"exact w_{i} = {float(wi):.3g} < -{float(tw):.3g}"
            assert zi <= tz or wi <= tw, f"exact complementarity violated at {i}"
        return
    assert np.all(w >= -tol_w), f"w has a negative entry {np.min(w)} < -{tol_w:.3g}"
    both = (z > tol_z) & (w > tol_w)
    assert not np.any(both), f"complementarity violated at {np.flatnonzero(both)}: z = {z[both]}, w = {w[both]}"


def assert_farkas(M, q, y, rtol=1e-9):
    """``y`` proves ``LCP(M, q)`` infeasible: ``y >= 0``, ``M^T y <= 0``, ``q.y < 0``.

    Checked in exact rational arithmetic on the given floats: ``q.y < 0``
    exactly, and ``max(M^T y)`` at most ``1e-12`` of ``max|M| |q.y| / max|q|``
    (the float image of a rational Farkas vector may miss ``M^T y <= 0`` by
    an ulp; the float check below keeps ``rtol``).
    """
    n = len(q)
    yf = [Fraction(float(v)) for v in y]
    qy = sum(Fraction(float(q[i])) * yf[i] for i in range(n))
    assert qy < 0, f"exact q.y = {float(qy)} is not negative"
    slack = Fraction(1e-12) * Fraction(float(np.max(np.abs(M)))) * (-qy) / Fraction(float(np.max(np.abs(q))))
    for j in range(n):
        gj = sum(Fraction(float(M[i, j])) * yf[i] for i in range(n) if yf[i])
        assert gj <= slack, f"exact (M^T y)_{j} = {float(gj):.3g} > 0"
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    assert y is not None, "no certificate"
    y = np.asarray(y, dtype=float)
    assert np.all(np.isfinite(y)) and np.all(y >= 0) and np.max(y) > 0
    qy = q @ y
    assert qy < 0, f"q.y = {qy} is not negative"
    g = np.max(M.T @ y)
    assert g <= rtol * np.max(np.abs(M)) * abs(qy) / np.max(np.abs(q)), f"max(M^T y) = {g} > 0"


_CACHE = {}


def instances():
    """The shared instance list (built once per session)."""
    if "all" not in _CACHE:
        _CACHE["all"] = all_instances(seed=0)
    return _CACHE["all"]


@pytest.fixture(scope="session")
def instance_list():
    return instances()
