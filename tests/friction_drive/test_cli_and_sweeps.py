"""The `moreau` command and the sweep helpers."""

import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from moreau.modes import mode_name
from moreau.studies.paper.sweeps import sweep, write_csv
from moreau.cli import main

KEYS = {"displacement_per_period_m", "average_velocity_m_per_s", "mode", "regimes",
        "min_normal_force_N", "periodic_residual", "scheme", "wall_time_s"}


def run_json(capsys, *args):
    rc = main(["steady", *args, "--json"])
    out = capsys.readouterr().out
    return rc, json.loads(out)


def test_steady_json_keys_and_units(capsys):
    rc, rep = run_json(capsys, "--frequency", "185")
    assert rc == 0
    assert KEYS <= set(rep)
    assert rep["scheme"] == "event-driven" and rep["mode"] == "NP"
    # SI: about -6.64 um per period, velocity = displacement * f
    assert rep["displacement_per_period_m"] == pytest.approx(-6.639079e-6, rel=1e-6)
    assert rep["average_velocity_m_per_s"] == pytest.approx(rep["displacement_per_period_m"] * 185)
    assert all(0.0 <= t < 2 * math.pi for t, _ in rep["regimes"])
    assert [r for _, r in rep["regimes"]] == ["N", "P", "N"]
    assert rep["min_normal_force_N"] > 0 and rep["periodic_residual"] < 1e-10


def test_steady_parameters_are_used(capsys):
    _, a = run_json(capsys, "--frequency", "2000", "--mu", "0.98")
    assert a["mode"] == "SP" and a["parameters"]["mu"] == 0.98
    _, b = run_json(capsys, "--frequency", "185", "--length", "2e-3", "--x10", "4e-6")
    assert b["parameters"]["length"] == 2e-3


@pytest.mark.parametrize("args, match", [
    (["--frequency", "0"], "`frequency` must be > 0"),
    (["--frequency", "100", "--mu", "-1"], "`mu` must be >= 0"),
    (["--frequency", "100", "--phi0", "1.7"], "`phi0` must be in the open interval"),
    (["--frequency", "100", "--m2", "nan"], "`m2` must be finite"),
    (["--frequency", "100", "--k", "-5"], "`k` must be > 0"),
])
def test_steady_bad_input(capsys, args, match):
    rc = main(["steady", *args, "--json"])
    err = capsys.readouterr().err
    assert rc == 2 and match in err and err.count("\n") == 1


def test_steady_painleve_failure(capsys):
    rc = main(["steady", "--frequency", "185", "--phi0", "1.5"])
    err = capsys.readouterr().err
    assert rc == 1 and "PainleveError" in err and "1 - mu*tan(phi)" in err


def test_console_entry_point_human_output():
    out = subprocess.run([sys.executable, "-m", "moreau", "steady", "--frequency", "20"],
                         capture_output=True, text=True, check=True).stdout
    assert "operation mode            NS" in out and "m/s" in out


def test_sweep_rows_and_errors(tmp_path):
    rows = sweep("phi0", [0.8, 1.5], frequency=185.0)
    assert rows[0]["mode"] == "NP" and rows[0]["error"] == ""
    assert rows[1]["mode"] == "" and rows[1]["error"].startswith("PainleveError")
    assert math.isnan(rows[1]["displacement_per_period_m"])
    path = tmp_path / "s.csv"
    write_csv(rows, path)
    text = path.read_text().splitlines()
    assert len(text) == 3 and text[0].startswith("value,mode")


def test_sweep_bad_input():
    with pytest.raises(ValueError, match="`parameter` must be one of"):
        sweep("k", [1.0])
    with pytest.raises(ValueError, match="`frequency` must be"):
        sweep("mu", [0.1])
    with pytest.raises(ValueError, match="`values` must be"):
        sweep("frequency", [np.nan])


@pytest.mark.parametrize("seq, name", [
    ("SN", "NS"), ("SPSN", "NSPS"), ("PSN", "NPS"), ("PN", "NP"), ("PNS", "NSP"), ("PS", "SP"),
    ("NNPPN", "NP"), ("S", "S"), ("FSNF", "NFS"),
])
def test_mode_names(seq, name):
    assert mode_name(seq) == name


def test_mode_name_marks_impacts():
    assert mode_name("NFS", impacts=[False, False, True]) == "NF!S"
    with pytest.raises(ValueError, match="`sequence` may contain only"):
        mode_name("NX")


def test_steady_moreau_jean_json(capsys):
    rc, rep = run_json(capsys, "--frequency", "185", "--scheme", "moreau-jean",
                       "--steps-per-period", "2000")
    assert rc == 0
    assert KEYS | {"steps", "lcp_solves", "fallbacks", "max_penetration"} <= set(rep)
    assert rep["scheme"] == "moreau-jean" and rep["mode"] == "NP"
    # within 1e-3 of the event-driven reference at 2000 steps per period
    assert rep["displacement_per_period_m"] == pytest.approx(-6.639079e-6, rel=1e-3)
    assert rep["steps"] > 0 and rep["fallbacks"] == 0


def test_steady_moreau_jean_without_period_one_orbit_says_so(capsys):
    # above the contact-loss limit with restitution the Moreau-Jean map has no
    # period-1 orbit: the report says so and gives the statistical steady state (the
    # long-run mean after the transient, with its interval); its JSON holds no NaN
    rc = main(["steady", "--frequency", "15000", "--restitution", "0.5", "--scheme",
               "moreau-jean", "--steps-per-period", "2000", "--json"])
    out = capsys.readouterr().out
    assert rc == 0 and "NaN" not in out and "Infinity" not in out
    rep = json.loads(out)
    assert rep["periodic"] is False and rep["mode"] == "non-periodic"
    assert rep["steady_state"] == "statistical" and rep["statistical_status"] == "converged"
    assert "no period-1 orbit" in rep["why_not_periodic"]
    assert rep["min_normal_force_N"] is None and rep["periodic_residual"] is None
    lo, hi = rep["confidence_interval_m"]
    assert 0 < lo <= rep["displacement_per_period_m"] <= hi
    # measured: 6.7839e-3 (dimensionless) after a transient of 4875 periods
    assert rep["transient_periods"] > 1000 and rep["periods_used"] >= 1000


def test_steady_moreau_jean_finds_flight_orbit(capsys):
    # issue 11, defect 1: at 15 kHz the event-driven reference finds NF!P; so must Moreau-Jean
    # (1.2 % off at N = 8000: first order, the impact is located to a step)
    rc, rep = run_json(capsys, "--frequency", "15000", "--scheme", "moreau-jean",
                       "--steps-per-period", "8000")
    assert rc == 0 and rep["periodic"] is True and rep["mode"] == "NF!P"
    rc, ref = run_json(capsys, "--frequency", "15000")
    assert ref["mode"] == "NF!P"
    assert rep["displacement_per_period_m"] == pytest.approx(ref["displacement_per_period_m"],
                                                             rel=2e-2)


def test_run_command_writes_history(tmp_path, capsys):
    rc = main(["run", "--frequency", "185", "--periods", "2", "--out", str(tmp_path), "--quiet",
               "--no-plot"])
    assert rc == 0
    path = tmp_path / "history_friction-drive_frequency185_event-driven.csv"
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    # the columns every scene's table has, units in the names, regimes by name
    assert list(rows[0]) == ["t [s]", "q_0 [rad]", "q_1 [m]", "v_0 [rad/s]", "v_1 [m/s]",
                             "force_N_0 [N]", "force_T_0 [N]", "slip_velocity_0 [m/s]",
                             "gap_0 [m]", "regime_0"]
    assert float(rows[-1]["t [s]"]) == pytest.approx(2 / 185.0)
    assert all(float(r["force_N_0 [N]"]) > 0 for r in rows)
    assert {r["regime_0"] for r in rows} <= {"stick", "positive", "negative", "flight"}
    assert {"positive", "negative"} <= {r["regime_0"] for r in rows}
    # two periods from rest: the rotor has moved backwards by a few micrometres
    assert -2e-5 < float(rows[-1]["q_1 [m]"]) < -5e-6
    side = json.loads(path.with_suffix(".json").read_text())
    assert side["scene"] == "friction-drive" and side["scheme"] == "event-driven"
    assert side["parameters"] == {"frequency": 185.0} and side["status"] == 0
    assert {"name": "q_1", "unit": "m"} in side["columns"]
    assert side["coordinates"] == {"q_0": "phi", "q_1": "x2"}
    assert side["provenance"]["numpy_version"] and side["provenance"]["command"]


def test_histories_of_both_schemes_agree():
    from moreau.analysis.history import run_history
    from moreau.scenes.friction_drive import FrictionDrive
    sc = FrictionDrive(frequency=185.0)
    ed, ed_cols = run_history(sc, periods=3, samples=300)
    mj, mj_cols = run_history(sc, periods=3, scheme="moreau-jean", steps=12000, samples=300)
    assert ed.status == mj.status == 0
    x2 = {name: dict((n, a) for n, _, a in cols)["q_1"] for name, cols in
          (("ed", ed_cols), ("mj", mj_cols))}
    assert x2["mj"][-1] == pytest.approx(x2["ed"][-1], rel=2e-3)
    with pytest.raises(ValueError, match="`periods` must be > 0"):
        run_history(sc, periods=0)