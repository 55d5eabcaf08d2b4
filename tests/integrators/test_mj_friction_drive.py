"""Moreau–Jean on the paper's friction drive: compiled path, steady states, accuracy."""

import math

import numpy as np
import pytest

import moreau.integrators.moreau_jean as mjmod
from moreau.integrators import simulate
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams

TWO_PI = 2.0 * math.pi


def mj(scene, periods, steps, **opts):
    q0, v0 = scene.rest_state()
    return simulate(scene, (0.0, periods * TWO_PI), q0, v0, "moreau-jean", h=TWO_PI / steps,
                    **opts)


# -- compiled path == generic path ------------------------------------------------------

@pytest.mark.parametrize("freq, theta, projection", [
    (185.0, 1.0, False), (185.0, 0.5, True), (20.0, 1.0, True), (2000.0, 0.5, False),
])
def test_compiled_path_equals_generic_path(freq, theta, projection):
    sc = FrictionDrive(frequency=freq)
    a = mj(sc, 1, 400, theta=theta, projection=projection, fast=False)
    b = mj(sc, 1, 400, theta=theta, projection=projection, fast=True)
    assert a.status == b.status == 0 and len(a.t) == len(b.t) == 401
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.regime, b.regime)
    vs = sc.u10          # velocity and displacement scale of the drive
    for x, y in ((a.q, b.q), (a.v, b.v), (a.slip_velocity, b.slip_velocity), (a.gap, b.gap)):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * vs)
    fs = np.max(np.abs(a.force_N))
    np.testing.assert_allclose(a.force_N, b.force_N, rtol=0, atol=1e-12 * fs)
    np.testing.assert_allclose(a.force_T, b.force_T, rtol=0, atol=1e-12 * fs)
    for key in ("steps", "lcp_solves", "direct_solves", "projection_iterations"):
        assert a.stats[key] == b.stats[key]
    assert a.stats["max_penetration"] == pytest.approx(b.stats["max_penetration"], abs=1e-15)


def test_compiled_blocks_join_seamlessly(monkeypatch):
    sc = FrictionDrive(frequency=185.0)
    whole = mj(sc, 1, 300, save_every=7)
    monkeypatch.setattr(mjmod, "FAST_BLOCK", 11)
    pieces = mj(sc, 1, 300, save_every=7)
    np.testing.assert_array_equal(whole.t, pieces.t)
    np.testing.assert_array_equal(whole.q, pieces.q)
    np.testing.assert_array_equal(whole.regime, pieces.regime)
    assert whole.stats == pieces.stats and whole.stats["steps"] == 300
    assert len(whole.t) == 1 + 300 // 7 + 1


@pytest.mark.parametrize("fast", [False, True])
def test_painleve_violation_in_the_drive(fast):
    # mu tan(phi) > 1: the paper's Painlevé condition fails as soon as the rod presses
    sc = FrictionDrive(FrictionDriveParams(mu=1.5), frequency=185.0)
    res = mj(sc, 1, 200, fast=fast)
    assert res.status == -1 and "Painlevé" in res.message
    assert np.all(np.isfinite(res.q))
