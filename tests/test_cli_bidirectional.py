"""`moreau steady --scene bidirectional` and the direction-control helpers."""

import json
import math

import pytest

from moreau.studies.bidirectional.direction_control import bidirectional_params, direction_sweep
from moreau.cli import main
from moreau.errors import InputError


def run_json(capsys, *args):
    rc = main(["steady", "--scene", "bidirectional", *args, "--json"])
    captured = capsys.readouterr()
    return rc, (json.loads(captured.out) if rc == 0 else captured.err)


def test_rod_b_alone_moves_the_rotor_forward_at_185_hz(capsys):
    rc, rep = run_json(capsys, "--frequency", "185", "--x10-a", "0")
    assert rc == 0 and rep["scene"] == "bidirectional-drive" and rep["mode"] == "F|NP"
    # the mirror image of the single rod's -6.639079e-6 m per period
    assert rep["displacement_per_period_m"] == pytest.approx(6.6390794203e-6, rel=1e-8)
    assert rep["average_velocity_m_per_s"] == pytest.approx(rep["displacement_per_period_m"] * 185)
    assert rep["parameters"]["x10_a"] == 0.0 and rep["parameters"]["x10_b"] == 2e-6


def test_bad_stator_amplitude_is_an_input_error(capsys):
    rc, err = run_json(capsys, "--frequency", "185", "--x10-b=-1e-6")
    assert rc == 2 and "`x10_b` must be >= 0" in err


def test_balance_knob_maps_to_the_two_amplitudes():
    p = bidirectional_params("balance", -0.5)
    assert (p.x10_a, p.x10_b) == (2e-6, 1e-6)
    p = bidirectional_params("phase", math.pi)
    assert (p.x10_a, p.x10_b, p.phase) == (2e-6, 2e-6, math.pi)
    with pytest.raises(InputError, match="`balance`"):
        direction_sweep("balance", [1.5])
    with pytest.raises(InputError, match="`knob`"):
        bidirectional_params("ratio", 0.5)


def test_balance_sweep_is_odd():
    rows = direction_sweep("balance", [-1.0, 0.0, 1.0], frequency=185.0)
    v = [r["velocity_m_per_s"] for r in rows]
    assert all(r["status"] == "ok" for r in rows)
    assert v[0] < 0.0 < v[2] and abs(v[0] + v[2]) <= 1e-9 * abs(v[0])
    assert abs(v[1]) <= 1e-12 * abs(v[0])
