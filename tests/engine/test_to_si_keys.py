"""Every registered scene's ``to_si(result)`` gives the same keys, shapes and units.

The common keys (``moreau.model.units.COMMON_KEYS``) with their shapes for
a short run of each scene at its defaults, values checked against the
scene's own scales; the drives keep their named coordinates as extras, equal
to the matching columns of ``q`` and ``v``.
"""

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.model.scene import velocity_count
from moreau.scenes import registry
from moreau.scenes.friction_drive import FrictionDrive
from moreau.scenes.bidirectional_drive import BidirectionalDrive

NAMES = registry.scene_names()
COMMON = ("t", "q", "v", "force_N", "force_T", "slip_velocity", "gap", "regime")


#: scenes whose short run is a tenth (20 steps of the same h): the box on the incline, whose
#: Python step solves the exact cone at its four corners (12 ms a step: 2.5 of the file's CPU
#: s over 200 steps); it slides down (regime POSITIVE) on all four loaded contacts from the
#: first step on, in 20 steps as in 200, so every check below sees the same kinds of values
TENTH = {"box-incline"}


def _short_run(scene):
    q0, v0 = scene.initial_state()
    # a few hundred steps: shapes and scales, not accuracy. The generic step, because the
    # compiled loop returns the same result object (tests/integrators/test_compiled_engine.py)
    # and compiling it for every scene here cost a minute of CI
    span = 0.05 if scene.name in TENTH else 0.5
    return simulate(scene, (0.0, span), q0, v0, "moreau-jean", h=0.5 / 200, fast=False)


#: with the long checks: the masonry arch, whose 200 generic (Python) steps solve a degenerate
#: friction LCP each (ten contacts closed at once; about 1.5 s of CPU); its SI table is
#: checked in the default run by tests/engine/test_cli_run_any_scene.py's Moreau–Jean run
SLOW = {"masonry-arch"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n
                                  for n in NAMES])
def test_to_si_has_the_common_keys_with_their_shapes(name):
    scene = registry.make_scene(name)
    res = _short_run(scene)
    si = scene.to_si(res)
    assert set(COMMON) <= set(si)
    n, ndof = res.q.shape
    nv = res.v.shape[1]          # a spatial scene: 7 coordinates, 6 velocities a body
    nc = res.force_N.shape[1]
    assert si["t"].shape == (n,)
    assert si["q"].shape == (n, ndof) and si["v"].shape == (n, nv)
    assert nv == velocity_count(scene)
    for key in ("force_N", "force_T", "slip_velocity", "gap", "regime"):
        assert si[key].shape == (n, nc), key
    # the SI values are the dimensionless ones times the scene's own scales
    ratio = si["t"][1:] / res.t[1:]
    assert np.allclose(ratio, scene.time_unit_s, rtol=1e-14)
    assert np.allclose(si["force_N"], scene.force_to_si(res.force_N), rtol=1e-14)
    assert np.array_equal(si["regime"], res.regime)
    # and the run's table has one column per coordinate and per contact
    names = [c[0] for c in scene.si_columns(res)]
    assert names == (["t"] + [f"q_{i}" for i in range(ndof)] + [f"v_{i}" for i in range(nv)]
                     + [f"{k}_{j}" for k in COMMON[3:] for j in range(nc)])


@pytest.mark.parametrize("scene, extras", [
    (FrictionDrive(frequency=185.0), {"phi": ("q", 0), "x2": ("q", 1), "v2": ("v", 1)}),
    (BidirectionalDrive(frequency=185.0),
     {"phi_a": ("q", 0), "phi_b": ("q", 1), "x2": ("q", 2), "v2": ("v", 2)}),
])
def test_the_drives_keep_their_named_coordinates_as_extras(scene, extras):
    res = _short_run(scene)
    si = scene.to_si(res)
    for name, (key, col) in extras.items():
        assert np.array_equal(si[name], si[key][:, col]), name
    l, w = scene.params.length, scene.omega
    assert np.allclose(si["x2"], res.q[:, -1] * l, rtol=1e-15)
    assert np.allclose(si["v2"], res.v[:, -1] * l * w, rtol=1e-15)
    # angles stay in rad, their rates in rad/s
    assert np.array_equal(si["q"][:, 0], res.q[:, 0])
    assert np.allclose(si["v"][:, 0], res.v[:, 0] * w, rtol=1e-15)
    assert np.allclose(si["gap"], res.gap * l, rtol=1e-15)
