"""Shared helpers of the LCP tests."""

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


_CACHE = {}


def instances():
    """The shared instance list (built once per session)."""
    if "all" not in _CACHE:
        _CACHE["all"] = all_instances(seed=0)
    return _CACHE["all"]


@pytest.fixture(scope="session")
def instance_list():
    return instances()
