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


def test_a_failed_load_inside_the_stall_bracket_leaves_an_interpolated_stall():
    # Brent's search hit a load without a steady state and the whole characteristic
    # failed; the stall is now interpolated across the tightest sign change around it
    from moreau.analysis.characteristic import _stall

    class Curve:
        # v(F) = -1e-3 (1 + F / 7.5e-4) m/s, without a steady state within 1e-5 N of stall
        stall = -7.5e-4

        def at(self, load):
            if abs(load - self.stall) < 1e-5:
                return None, "ConvergenceError: no orbit", None, None
            return -1e-3 * (1.0 + load / -self.stall), "ok", None, None

        def velocity(self, load):
            v, status, _, _ = self.at(load)
            if v is None:
                raise MoreauError(f"no steady state at load {load:.6g} N ({status})")
            return v

    stall, how = _stall(Curve(), -1e-3, 1.0)
    # linear: the interpolation is exact to rounding
    assert stall == pytest.approx(Curve.stall, rel=1e-12)
    # the first probe (-1e-3 N) brackets the stall; Brent's first secant lands on it
    assert how == ("linear interpolation between the loads 0 and -0.001 N (not refined: no "
                   "steady state at load -0.00075 N (ConvergenceError: no orbit))")


@pytest.mark.slow
@pytest.mark.parametrize("scheme, refined", [
    # the power maximum's Brent search meets a load without an orbit (before: exit 1)
    ("schatzman-paoli", "max_power_located_by"),
    # a load inside the stall bracket has no orbit (before: exit 1)
    ("nonsmooth-generalized-alpha", "stall_located_by"),
])
def test_the_characteristic_keeps_its_points_where_one_load_fails(scheme, refined, tmp_path,
                                                                   capsys):
    argv = ["characteristic", "--scheme", scheme, "--json", "--out", str(tmp_path),
            "--no-plot"]
    assert main(argv) == 0
    s = json.loads(capsys.readouterr().out)
    assert "not refined" in s[refined]
    assert s["stall_force_N"] == pytest.approx(-7.9e-4, rel=0.01)
    with open(next(tmp_path.glob("*.csv"))) as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 41
    assert sum(r["status"] != "ok" for r in rows) == s["failed_points"]


@pytest.mark.slow
def test_studer_s_no_load_shooting_reaches_its_tolerance(capsys, tmp_path):
    # it aimed at 1e-8 with a map accurate to its tol = 1e-6 and stalled at 6.3e-7
    from moreau.analysis.scheme_settings import make_scheme, steady_of
    sc = FrictionDrive(frequency=185.0)
    ss = steady_of(sc, make_scheme("studer-extrapolation"))
    ref = find_steady_state(sc, statistical=False)
    assert ss.displacement_per_period == pytest.approx(ref.displacement_per_period, rel=1e-4)


def test_the_stress_map_and_the_bifurcation_json_carry_the_provenance(tmp_path, capsys,
                                                                       monkeypatch):
    # compare --stress's JSON had no provenance; bifurcation --json printed none
    import moreau.studies.paper.stress as st
    monkeypatch.setattr(st, "CASES", {"mu-zero": st.CASES["mu-zero"]})
    assert main(["compare", "--stress", "--quick", "--schemes", "event-driven", "--quiet",
                 "--no-plot", "--json", "--out", str(tmp_path / "s")]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert _code_version_ok(rep["provenance"])
    assert json.loads((tmp_path / "s" / "stress.json").read_text())["provenance"] == \
        rep["provenance"]
    assert main(["bifurcation", "frequency", "1e4", "2e4", "--points", "2", "--transient", "2",
                 "--samples", "2", "--no-lyapunov", "--no-shoot", "--quiet", "--no-plot",
                 "--json", "--out", str(tmp_path / "b")]) == 0
    assert _code_version_ok(json.loads(capsys.readouterr().out)["provenance"])


def test_an_interrupted_efficiency_sweep_keeps_its_finished_frequencies(tmp_path, capsys,
                                                                        monkeypatch):
    import moreau.analysis.characteristic as ch
    real, calls = ch.motor_characteristic, []

    def second_interrupted(*a, **k):
        calls.append(k["frequency"])
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(ch, "motor_characteristic", second_interrupted)
    assert main(["characteristic", "--efficiency-vs-frequency", "2000", "1000", "--points", "3",
                 "--out", str(tmp_path), "--no-plot", "--json"]) == 130
    table = tmp_path / "efficiency_friction-drive_1000-2000Hz_event-driven.partial.csv"
    assert capsys.readouterr().err.strip() == (
        f"moreau: interrupted: efficiency against frequency: 1 of 2 frequencies finished, "
        f"kept in {table}")
    with open(table) as fh:
        (row,) = list(csv.DictReader(fh))
    assert float(row["frequency_Hz"]) == 2000.0 and row["status"] == "ok"
    assert json.loads(table.with_suffix(".json").read_text())["partial"] is True
    assert sorted(p.name for p in tmp_path.iterdir()) == [table.name,
                                                          table.with_suffix(".json").name]


def test_an_interrupted_bifurcation_keeps_its_points_under_partial_names(tmp_path, capsys,
                                                                          monkeypatch):
    import moreau.analysis.bifurcation as bif
    real, calls = bif.section_samples, []

    def second_interrupted(*a, **k):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(bif, "section_samples", second_interrupted)
    assert main(["bifurcation", "frequency", "1e4", "2e4", "--points", "3", "--transient", "2",
                 "--samples", "2", "--no-lyapunov", "--no-shoot", "--quiet", "--out",
                 str(tmp_path)]) == 130
    (table,) = tmp_path.glob("*.csv")
    assert table.name.endswith(".partial.csv")
    assert capsys.readouterr().err.strip() == (
        f"moreau: interrupted: bifurcation: 1 of 3 points finished, kept in {table}")
    side = json.loads(table.with_suffix(".json").read_text())
    assert side["partial"] is True and side["interrupted"] is True
    # no figure drawn after the signal
    assert not list(tmp_path.glob("*.png"))


@pytest.mark.slow
def test_the_two_rod_drive_without_friction_exchanges_no_work(capsys):
    # at rest at the ends of its phases: the rounding bound samples the energy inside them
    assert main(["steady", "--scene", "bidirectional-drive", "--set", "mu=0", "--json"]) == 0
    e = json.loads(capsys.readouterr().out)["energy"]
    assert e["closing_error"] is None and e["note"].startswith("no work exchanged")
    assert 0.0 < abs(e["stator_work_J"]) <= e["rounding_bound_J"]


def test_an_interrupted_characteristic_keeps_its_finished_loads_under_partial_names(
        tmp_path, capsys, monkeypatch):
    import moreau.analysis.characteristic as ch
    real, calls = ch.steady_of, []

    def third_interrupted(*a, **k):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(ch, "steady_of", third_interrupted)
    assert main(["characteristic", "--frequency", "2000", "--points", "3", "--out",
                 str(tmp_path), "--no-plot"]) == 130
    table = tmp_path / "characteristic_friction-drive_2000Hz_event-driven.partial.csv"
    assert capsys.readouterr().err.strip() == (
        f"moreau: interrupted: characteristic: 2 loads finished, kept in {table}")
    with open(table) as fh:
        rows = list(csv.DictReader(fh))
    # no load (the rotor runs forwards at 2000 Hz), then the stall search's first probe,
    # past the stall (no orbit there: the search halves back), kept with its status
    assert len(rows) == 2 and float(rows[0]["load_N"]) == 0.0 and rows[0]["status"] == "ok"
    sc = FrictionDrive(frequency=2000.0)
    v0 = sc.displacement_to_si(find_steady_state(sc).displacement_per_period) / (
        sc.period * sc.time_unit_s)
    assert float(rows[0]["average_velocity_m_per_s"]) == pytest.approx(v0, rel=1e-12)
    assert float(rows[1]["load_N"]) > 0.0 and rows[1]["status"].startswith("ConvergenceError")
    assert json.loads(table.with_suffix(".json").read_text())["partial"] is True
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [table.name, table.with_suffix(".json").name])


def test_an_interrupted_comparison_keeps_its_rows_under_partial_names(tmp_path, capsys,
                                                                      monkeypatch):
    # it wrote the finished rows (and a figure) under the names of a finished comparison
    import moreau.analysis.compare as cmp
    real, calls = cmp.run_row, []

    def second_interrupted(*a, **k):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(cmp, "run_row", second_interrupted)
    assert main(["compare", "--scene", "bouncing-ball", "--quick", "--quiet", "--json", "--out",
                 str(tmp_path)]) == 130
    table = tmp_path / "compare_bouncing-ball.partial.csv"
    assert capsys.readouterr().err.strip() == (
        f"moreau: interrupted: compare: 1 row finished, kept in {table}")
    side = json.loads(table.with_suffix(".json").read_text())
    assert side["partial"] is True and side["interrupted"] is True and len(side["rows"]) == 1
    assert _code_version_ok(side["provenance"])
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [table.name, table.with_suffix(".json").name])
