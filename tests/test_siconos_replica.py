"""benchmarks/siconos_replica.py: Siconos's Moreau–Jean linearisation replayed on our scenes."""

import json
import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.scenes import BouncingBall, FrictionDrive
from moreau.suite.peers import siconos_available

BENCH = pathlib.Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
from siconos_replica import replay  # noqa: E402


@pytest.mark.parametrize("scene, h, steps", [(FrictionDrive(frequency=185.0), 2 * math.pi / 1000, 300),
                                             (BouncingBall(), 1e-3, 2000)])
def test_at_the_start_point_it_is_our_generic_step(scene, h, steps):
    # the harness itself: linearised at q_k it is moreau's Moreau–Jean (theta = 1), contact
    # rows, index set and impacts included (the ball bounces twice in 2 time units)
    q0, v0 = scene.initial_state()
    ref = simulate(scene, (0.0, steps * h), q0, v0, "moreau-jean", h=h, theta=1.0,
                   save_every=steps, fast=False)
    q, v = replay(scene, q0, v0, h, steps, at="start")
    np.testing.assert_allclose(q, ref.q[-1], rtol=0, atol=1e-14)
    np.testing.assert_allclose(v, ref.v[-1], rtol=0, atol=1e-13)


def test_the_predictor_moves_the_answer_by_the_schemes_order():
    # the two linearisations are both first order: over a fixed time they part by O(h)
    sc = FrictionDrive(frequency=2000.0)
    q0, v0 = sc.initial_state()
    gaps = []
    for n in (250, 500):
        h = 2 * math.pi / n
        a, _ = replay(sc, q0, v0, h, n, at="start")
        b, _ = replay(sc, q0, v0, h, n, at="predictor")
        gaps.append(abs(a[1] - b[1]))
    assert 1.6 < gaps[0] / gaps[1] < 2.4


def test_a_bad_point_is_refused_by_name():
    sc = BouncingBall()
    with pytest.raises(ValueError, match="`at` must be 'start' or 'predictor', got 'end'"):
        replay(sc, *sc.initial_state(), 1e-3, 1, at="end")


@pytest.mark.slow
@pytest.mark.skipif(not siconos_available(), reason="Siconos is not installed (/usr/bin/python3)")
def test_siconos_lands_on_its_replayed_linearisation():
    # Siconos's MoreauJeanOSI on the friction drive (C plugins written apart from the scene):
    # replayed at the predictor, our scene ends where Siconos does to rounding; at the start
    # point it ends 4e-4 of the displacement away (measured over 20 000 steps)
    sc = FrictionDrive(frequency=2000.0)
    q0, v0 = sc.initial_state()
    par = {"label": "2000 Hz", "J": sc.J, "P": sc.P, "u10": sc.u10, "fL": sc.fL,
           "sin_phi0": sc.sin_phi0, "mu": float(sc.mu[0]), "e": float(sc.restitution[0]),
           "q0": [float(x) for x in q0], "v0": [float(x) for x in v0]}
    steps = 2000
    out = subprocess.run(["/usr/bin/python3", str(BENCH / "siconos_peer.py"), "--case",
                          "friction-drive", "--steps", str(steps), "--repeats", "1",
                          "--fd-params", json.dumps([par])],
                         capture_output=True, text=True, timeout=300, check=True)
    ref = json.loads(out.stdout)["friction_drive"]
    if "measured" in ref:
        pytest.skip(ref["reason"])
    qs = np.asarray(ref["2000 Hz"]["q_end"])
    h = 2 * math.pi / 1000
    q_pred, _ = replay(sc, q0, v0, h, steps, at="predictor")
    q_start, _ = replay(sc, q0, v0, h, steps, at="start")
    assert abs(q_pred[1] - qs[1]) <= 1e-11 * abs(qs[1])
    assert abs(q_pred[0] - qs[0]) <= 1e-12
    assert abs(q_start[1] - qs[1]) > 1e-6 * abs(qs[1])
