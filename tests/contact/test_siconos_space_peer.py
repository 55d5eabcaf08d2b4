"""benchmarks/siconos_space_peer.py states the puck to Siconos as our scene states it.

Twenty Moreau–Jean steps (theta = 1, the exact cone, ``h = 0.016`` units) of
the default puck-incline in Siconos (``NewtonEulerDS``, ``SphereNEDSPlanR``
of radius 0, ``FrictionContact(3)``; the job built by the benchmark's
``scene_job``) and in ours (the Python step, the reference) agree to 1e-12 m in
position and 1e-11 m/s in velocity at every step (measured: 7e-14 m and 3e-13
m/s over 1000 steps). A wrong launch direction, gravity, inertia or friction
would miss by far more. Skipped where ``/usr/bin/python3`` has no Siconos.
"""

import pathlib
import runpy

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.scenes.puck_incline import puck_incline
from moreau.suite.peers import siconos_available

BENCH = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "siconos_space_peer.py"


@pytest.mark.skipif(not siconos_available(), reason="/usr/bin/python3 has no Siconos (Debian "
                    "python3-siconos)")
def test_siconos_puck_agrees_with_ours_over_twenty_steps():
    bench = runpy.run_path(str(BENCH), run_name="siconos_space_peer_under_test")
    sc = puck_incline()
    n, window = 20, 20 * sc.default_window / 1000
    job = bench["scene_job"](sc, window, n, 1.0, 1)
    peer, err = bench["call_siconos"](job)
    assert peer is not None, err
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, window), q0, v0, "moreau-jean", h=window / n, theta=1.0,
                   cone="exact", save_every=1, fast=False)
    theirs = np.asarray(peer["track"])
    assert theirs.shape == (n + 1, 13) and res.q.shape[0] == n + 1
    L, T = sc.length, sc.time
    assert np.max(np.abs(res.q[:, :3] * L - theirs[:, :3])) <= 1e-12
    assert np.max(np.abs(res.v[:, :3] * L / T - theirs[:, 7:10])) <= 1e-11
    # it slides: 20 steps move it well beyond the tolerance, down and across the slope
    assert theirs[-1, 1] > 0.01 and theirs[-1, 0] > 1e-4
