"""The motor characteristic (moreau characteristic) against independent computations."""

import csv
import json

import numpy as np
import pytest

import moreau.analysis.characteristic as mod
from moreau.analysis.characteristic import (EFFICIENCY_COLUMNS, efficiency_vs_frequency,
                                            motor_characteristic)
from moreau.analysis.energy import energy_audit, energy_to_si
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


@pytest.fixture(scope="module")
def eff(tmp_path_factory):
    out = tmp_path_factory.mktemp("eff")
    return efficiency_vs_frequency("friction-drive", [185.0, 2000.0], points=5, out=out,
                                   plot=False, log=lambda s: None), out


def test_efficiency_vs_frequency_against_a_direct_audit(eff, ch2000):
    d, _ = eff
    rows = d["rows"]
    assert [r["frequency_Hz"] for r in rows] == [185.0, 2000.0]
    assert all(r["status"] == "ok" and 0.0 < r["efficiency"] < 1.0 for r in rows)
    # independent: the steady state at the reported load and the audit's input power
    r = rows[1]
    F = r["load_at_max_power_N"]
    sc = FrictionDrive(frequency=2000.0, load=F)
    p_in = energy_to_si(sc, energy_audit(sc, find_steady_state(sc), "event-driven"))[
        "stator_work_J"] * 2000.0
    assert r["input_power_W"] == pytest.approx(p_in, rel=1e-12)
    assert r["efficiency"] == pytest.approx(F * _velocity(2000.0, F) / p_in, rel=1e-12)
    # the characteristic at that frequency (a finer grid) has the same operating point
    s = ch2000["summary"]
    assert r["load_at_max_power_N"] == pytest.approx(s["load_at_max_power_N"], rel=1e-4)
    assert r["efficiency"] == pytest.approx(s["efficiency_at_max_power"], rel=1e-4)
    # measured: 10.7 % at 185 Hz (backwards), 0.55 % at 2000 Hz
    assert rows[0]["efficiency"] == pytest.approx(0.1069, rel=0.01)
    assert rows[0]["load_at_max_power_N"] < 0
    assert d["summary"]["frequency_of_best_efficiency_Hz"] == 185.0


def test_efficiency_vs_frequency_files(eff):
    d, out = eff
    stem = out / "efficiency_friction-drive_185-2000Hz_event-driven"
    with open(stem.with_suffix(".csv")) as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == EFFICIENCY_COLUMNS and len(rows) == 2
    assert float(rows[1]["efficiency"]) == d["rows"][1]["efficiency"]
    side = json.loads(stem.with_suffix(".json").read_text())
    assert "maximum output power" in side["efficiency_definition"] and "provenance" in side


def test_cli_efficiency_vs_frequency_refuses_a_fixed_frequency(capsys):
    assert main(["characteristic", "--efficiency-vs-frequency", "185", "2000",
                 "--frequency", "185"]) == 2
    assert "`--frequency` and `--efficiency-vs-frequency` exclude each other" in (
        capsys.readouterr().err)


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
