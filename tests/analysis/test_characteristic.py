"""The motor characteristic (moreau characteristic) against independent computations."""

import csv
import json

import numpy as np
import pytest

import moreau.analysis.characteristic as mod
from moreau.analysis.characteristic import motor_characteristic
from moreau.analysis.engine import make_scheme
from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.scenes.friction_drive import FrictionDrive

JSON_KEYS = {"stall_force_N", "no_load_velocity_m_per_s", "max_power_W", "load_at_max_power_N"}


def _velocity(frequency, load):
    sc = FrictionDrive(frequency=frequency, load=load)
    return sc.displacement_to_si(find_steady_state(sc).displacement_per_period) * frequency


@pytest.fixture(scope="module")
def ch2000():
    return motor_characteristic("friction-drive", frequency=2000.0, points=21, out=None,
                                plot=False)


def test_stall_force_gives_zero_mean_velocity(ch2000):
    s = ch2000["summary"]
    v0 = s["no_load_velocity_m_per_s"]
    assert v0 == pytest.approx(_velocity(2000.0, 0.0), rel=1e-12) and v0 > 0
    # a direct steady state at the reported stall force: zero mean velocity to the
    # shooting's tolerance, and the sign changes just either side
    F = s["stall_force_N"]
    assert F > 0
    assert abs(_velocity(2000.0, F)) < 1e-8 * v0
    assert _velocity(2000.0, F * (1 - 1e-4)) > 0 > _velocity(2000.0, F * (1 + 1e-4))


def test_max_power_against_a_fine_grid(ch2000):
    s = ch2000["summary"]
    loads = np.linspace(0.0, s["stall_force_N"], 201)
    p = np.array([f * _velocity(2000.0, f) for f in loads])
    i = int(np.argmax(p))
    # the reported maximum is at least the grid's and exceeds it by no more than the
    # grid can miss (curvature times half a grid step squared)
    assert s["max_power_W"] >= p[i] * (1 - 1e-12)
    assert s["max_power_W"] <= p[i] * (1 + 1e-3)
    assert abs(s["load_at_max_power_N"] - loads[i]) <= loads[1] - loads[0]
    assert s["max_power_W"] == pytest.approx(s["load_at_max_power_N"] * _velocity(
        2000.0, s["load_at_max_power_N"]), rel=1e-12)


def test_rows_report_reversal_and_efficiency(ch2000):
    rows = ch2000["rows"]
    s = ch2000["summary"]
    assert rows[0]["load_N"] == 0.0 and rows[-1]["load_N"] == pytest.approx(
        1.25 * s["stall_force_N"])
    rev = [r for r in rows if r["motion"] == "reversed"]
    assert rev and all(r["load_N"] > s["stall_force_N"] for r in rev)
    assert all(r["average_velocity_m_per_s"] < 0 for r in rev)
    assert s["reverses_motion"] is True and "reverse the motion" in s["reversal"]
    # efficiency = output power over the stators' input power from the energy audit
    best = max(rows, key=lambda r: r["output_power_W"])
    assert 0.0 < best["efficiency"] < 1.0
    assert best["efficiency"] == pytest.approx(best["output_power_W"] / best["input_power_W"])


def test_backward_drive_signs_in_the_load_convention():
    # 185 Hz: the paper's drive runs backwards; an opposing load is negative, power positive
    ch = motor_characteristic("friction-drive", frequency=185.0, points=9, out=None, plot=False)
    s = ch["summary"]
    assert s["no_load_velocity_m_per_s"] < 0 and s["stall_force_N"] < 0
    assert s["load_at_max_power_N"] < 0 and s["max_power_W"] > 0
    assert s["stall_force_N"] == pytest.approx(-7.883060558e-4, rel=1e-6)
    assert abs(_velocity(185.0, s["stall_force_N"])) < 1e-8 * abs(s["no_load_velocity_m_per_s"])


def test_moreau_jean_characteristic_near_the_reference():
    ch = motor_characteristic("friction-drive", frequency=185.0, points=9, out=None, plot=False,
                              scheme=make_scheme("moreau-jean", steps_per_period=1000))
    s = ch["summary"]
    assert s["stall_force_N"] == pytest.approx(-7.883e-4, rel=0.01)
    assert s["no_load_velocity_m_per_s"] == pytest.approx(-1.2282e-3, rel=0.01)
    assert s["max_power_W"] == pytest.approx(2.718e-7, rel=0.01)


def test_cli_json_and_files(tmp_path, capsys):
    assert main(["characteristic", "--frequency", "2000", "--points", "5", "--json",
                 "--out", str(tmp_path)]) == 0
    s = json.loads(capsys.readouterr().out)
    assert JSON_KEYS <= set(s)
    stem = tmp_path / "characteristic_friction-drive_2000Hz_event-driven"
    with open(stem.with_suffix(".csv")) as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["load_N", "average_velocity_m_per_s", "output_power_W",
                             "input_power_W", "efficiency", "motion", "mode", "status"]
    assert len(rows) == 5
    side = json.loads(stem.with_suffix(".json").read_text())
    assert side["stall_force_N"] == s["stall_force_N"] and "provenance" in side


@pytest.mark.parametrize("args, message", [
    (["--load", "0.1"], "`--load` is swept by the characteristic (from no load to beyond "
                        "stall); leave it out"),
    (["--points", "2"], "`--points` must be from 3 to 10000, got 2"),
    (["--frequency", "-5"], "`frequency` must be > 0"),
    (["--scene", "ball-chain"], "`--scene` must be a periodically driven scene"),
    (["--out", "/proc/no/such"], "`--out` folder '/proc/no/such' is not writable"),
])
def test_cli_refuses_bad_arguments_before_work(args, message, capsys, monkeypatch):
    def no_work(*a, **k):
        raise AssertionError("work started")
    monkeypatch.setattr(mod, "steady_of", no_work)
    assert main(["characteristic", *args]) == 2
    assert message in capsys.readouterr().err
