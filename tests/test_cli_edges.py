"""Issue 34: the command line's edges (provenance, refusals before work, --samples, the energy
audit on rounding, bifurcation marks, the characteristic's failures)."""

import csv
import json

import numpy as np
import pytest

from moreau import __version__
from moreau.analysis.atlas import run_scene_atlas
from moreau.analysis.bifurcation import bifurcation_marks
from moreau.analysis.characteristic import NO_MOTION_RTOL, motor_characteristic
from moreau.analysis.energy import ROUNDING_RTOL, energy_audit, energy_to_si
from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.errors import InputError, MoreauError
from moreau.scenes.friction_drive import FrictionDrive


def _code_version_ok(p):
    # the package version and a 16-digit hash of the computing sources
    version, _, digest = p["code_version"].partition("+")
    return version == __version__ and len(digest) == 16


def test_steady_takes_the_scene_s_default_frequency_and_records_the_code_version(capsys):
    # `moreau steady` demanded --frequency although the registry gives one
    assert main(["steady", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["frequency_Hz"] == 185.0 and rep["mode"] == "NP"
    assert _code_version_ok(rep["provenance"])


def test_run_writes_exactly_the_samples_asked_for(tmp_path, capsys):
    # --samples 1 wrote 51 rows (a sample a period and every event)
    base = ["run", "--periods", "2", "--out", str(tmp_path), "--no-plot", "--quiet", "--force"]
    assert main(base + ["--samples", "1"]) == 2
    assert "`samples` must be >= 2" in capsys.readouterr().err
    assert main(base + ["--samples", "7"]) == 0
    (path,) = tmp_path.glob("*.csv")
    t = [float(r["t [s]"]) for r in csv.DictReader(open(path))]
    assert np.allclose(t, np.linspace(0.0, 2 / 185.0, 7), rtol=1e-12, atol=0)
    side = json.loads(path.with_suffix(".json").read_text())
    assert side["samples"] == 7 and side["partial"] is False
    assert _code_version_ok(side["provenance"])


def test_atlas_refuses_a_degenerate_axis(tmp_path, capsys):
    argv = ["atlas", "--x", "mu", "0.1", "0.1", "--x-points", "2", "--y", "frequency", "20",
            "40", "--y-points", "2", "--out", str(tmp_path), "--quiet", "--no-plot"]
    assert main(argv) == 2
    assert capsys.readouterr().err.strip() == (
        "moreau: error: `--x START` and `--x STOP` must differ when `--x-points` > 1, got 0.1 "
        "twice")
    # the API refuses a repeated value on an axis (it collapsed the NetCDF grid)
    with pytest.raises(InputError, match=r"`x`: the values of 'mu' must be distinct"):
        run_scene_atlas("friction-drive", ("mu", [0.1, 0.1]), ("frequency", [20.0, 40.0]),
                        out=None)
    assert not list(tmp_path.iterdir())


def test_bifurcation_marks_name_the_motions_and_a_wrong_quantity_is_refused(tmp_path, capsys):
    pts = [{"value": 1.0, "period": 1, "motion": "period-1", "flight": False, "status": "ok"},
           {"value": 2.0, "period": 0, "motion": "non-periodic", "flight": False,
            "status": "ok"},
           {"value": 3.0, "period": 0, "flight": False, "status": "ok"}]
    marks = bifurcation_marks(pts, "a")
    assert [(m["kind"], m["from"], m["to"]) for m in marks] == [
        ("period change", "period-1", "non-periodic")]
    # without a motion name, a period of 0 still reads as no period
    assert bifurcation_marks(pts[::2], "a")[0]["to"] == "non-periodic"
    argv = ["bifurcation", "frequency", "1e4", "2e4", "--points", "2", "--quantity", "nope",
            "--out", str(tmp_path), "--quiet", "--no-plot"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "`quantities` (`--quantity`) must name section columns, one of ['q_0'," in err
    assert "'displacement_per_period']; got ['nope']" in err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("setting", [{"mu": 0.0}, {"m2": 1e-30}])
def test_energy_audit_says_no_work_is_exchanged_where_every_term_is_rounding(setting):
    # the closing error read 1.0 (100 %) on a stator work of 7e-23 J
    sc = FrictionDrive(frequency=185.0, **setting)
    ss = find_steady_state(sc, statistical=False)
    a = energy_audit(sc, ss, "event-driven")
    terms = [abs(a[k]) for k in ("stator_work", "load_work", "friction_positive_slip",
                                 "friction_negative_slip", "impact_loss",
                                 "stored_energy_change")]
    assert a["closing_error"] is None and a["work_exchanged"] is False
    assert 0.0 < max(terms) <= a["rounding_bound"]
    si = energy_to_si(sc, a)
    assert si["closing_error"] is None
    assert si["note"] == (f"no work exchanged: every term is below the rounding bound "
                          f"{si['rounding_bound_J']:.1e} J ({ROUNDING_RTOL:g} of the stored "
                          "energy)")
    # with friction the same drive exchanges work, and the balance closes to 1e-12
    b = energy_audit(FrictionDrive(frequency=185.0), find_steady_state(
        FrictionDrive(frequency=185.0), statistical=False), "event-driven")
    assert b["work_exchanged"] and abs(b["closing_error"]) < 1e-12


def test_characteristic_refuses_a_scheme_that_does_not_take_the_scene(tmp_path, capsys):
    # it exited 1 as "no steady state at no load: InputError ..."
    argv = ["characteristic", "--scheme", "stick-slip-exact", "--out", str(tmp_path),
            "--no-plot"]
    assert main(argv) == 2
    assert capsys.readouterr().err.strip() == (
        "moreau: error: scheme 'stick-slip-exact' on scene 'friction-drive': `scene` must be a "
        "StickSlipMotor, got FrictionDrive")


def test_efficiency_against_frequency_refuses_bad_points_and_fails_without_any_point(
        tmp_path, capsys):
    base = ["characteristic", "--out", str(tmp_path), "--no-plot", "--json"]
    assert main(base + ["--efficiency-vs-frequency", "185", "--points", "2"]) == 2
    assert capsys.readouterr().err.strip() == (
        "moreau: error: `--points` must be from 3 to 10000, got 2")
    assert not list(tmp_path.iterdir())
    # no steady contact motion at 1 MHz: the command fails, and its JSON has no NaN
    assert main(base + ["--efficiency-vs-frequency", "1e6"]) == 1
    cap = capsys.readouterr()
    d = json.loads(cap.out)
    assert d["rows"][0]["efficiency"] is None and d["summary"]["failed_frequencies"] == [1e6]
    assert _code_version_ok(d["summary"]["provenance"])
    assert cap.err.strip().startswith("moreau: failed: MoreauError: no frequency has a "
                                      "characteristic: all 1 failed (first: ")


def test_a_rotor_still_to_rounding_at_no_load_has_no_characteristic():
    # the two-rod drive's symmetric no-load velocity is 5.8e-20 m/s; `v0 == 0.0` let it
    # through to a stall force 0 and a false runaway claim
    with pytest.raises(MoreauError, match=r"the rotor does not move at no load: its mean "
                       rf"velocity -?\d\.\d+e-\d+ m/s is below {NO_MOTION_RTOL:g} of the "
                       r"velocity scale \(0.00232 m/s\)"):
        motor_characteristic("bidirectional-drive", out=None, plot=False)
