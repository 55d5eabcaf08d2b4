"""`moreau sweep`: any parameter, through the sweep engine; every accepted option acts."""

import csv

import pytest

from moreau import cli
from moreau.analysis import engine


def sweep(tmp_path, name, *args):
    out = tmp_path / name
    rc = cli.main(["sweep", *args, "--out", str(out), "--quiet", "--no-plot", "--jobs", "1"])
    assert rc == 0
    (path,) = out.glob("sweep_*.csv")
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def disp(rows):
    return [float(r["displacement_per_period_m"]) for r in rows]


ARGS = ("frequency", "185", "185", "--points", "1")


def test_scheme_options_change_the_computation(tmp_path):
    ed = sweep(tmp_path, "ed", *ARGS)
    assert ed[0]["status"] == "ok" and ed[0]["mode"] == "NP"
    # the event-driven reference at 185 Hz (tests/friction_drive)
    assert disp(ed)[0] == pytest.approx(-6.639079e-6, rel=1e-6)
    mj = sweep(tmp_path, "mj", *ARGS, "--scheme", "moreau-jean", "--steps-per-period", "400")
    mj2 = sweep(tmp_path, "mj2", *ARGS, "--scheme", "moreau-jean", "--steps-per-period", "1600")
    half = sweep(tmp_path, "half", *ARGS, "--scheme", "moreau-jean", "--steps-per-period", "400",
                 "--theta", "0.5")
    loose = sweep(tmp_path, "loose", *ARGS, "--rtol", "1e-2")
    mj_loose = sweep(tmp_path, "mjl", *ARGS, "--scheme", "moreau-jean", "--steps-per-period", "400",
                     "--rtol", "1e-2")
    ref = disp(ed)[0]
    # each setting gives another value, all close to the reference; more steps, closer
    e400, e1600 = abs(disp(mj)[0] / ref - 1), abs(disp(mj2)[0] / ref - 1)
    assert 0 < e1600 < e400 < 1e-2
    assert disp(half)[0] != disp(mj)[0] and abs(disp(half)[0] / ref - 1) < 1e-2
    # a loose shooting tolerance stops earlier, at another value
    assert int(loose[0]["shooting_iterations"]) < int(ed[0]["shooting_iterations"])
    assert disp(loose)[0] != ref
    assert int(mj_loose[0]["shooting_iterations"]) < int(mj[0]["shooting_iterations"])
    # the scheme and its settings are in the file name and in a column (issue 21)
    meta = (tmp_path / "half" / "sweep_frequency_mj_theta0.5_N400.json").read_text()
    assert '"theta": 0.5' in meta and '"steps_per_period": 400' in meta
    assert {r["scheme"] for r in half} == {"moreau-jean"} and ed[0]["scheme"] == "event-driven"
    assert (tmp_path / "ed" / "sweep_frequency.csv").exists()
    assert (tmp_path / "loose" / "sweep_frequency_ed_rtol0.01.csv").exists()


@pytest.mark.parametrize("args, match", [
    (["--theta", "0.5"], "`--theta` does not act with `--scheme event-driven`: it applies to schemes with a theta (moreau-jean, moreau-jean-projected)"),
    (["--steps-per-period", "100"], "`--steps-per-period` does not act with `--scheme event-driven`: it applies to time-stepping schemes"),
    (["--scheme", "moreau-jean", "--theta", "0.2"], "`theta` must be in [1/2, 1]"),
    (["--rtol", "0"], "`rtol` must be > 0"),
    (["--set", "frequency=185"], "fixes the swept parameter"),
    (["--set", "zeta=1"], "`--set` takes NAME=VALUE"),
    (["--frequency", "185"], "`--frequency` is the swept parameter"),
    (["--scale", "log", "--points", "3"], None),
])
def test_refused_options(tmp_path, capsys, monkeypatch, args, match):
    def no_work(*a, **k):
        raise AssertionError("work started before the options were checked")

    monkeypatch.setattr(engine, "run_points", no_work)
    if match is None:  # a valid command reaches the engine
        with pytest.raises(AssertionError, match="work started"):
            cli.main(["sweep", "frequency", "10", "100", *args, "--out", str(tmp_path), "--quiet"])
        return
    rc = cli.main(["sweep", *ARGS, *args, "--out", str(tmp_path), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and match in err


def test_fixing_the_swept_parameter_is_refused(tmp_path, capsys):
    rc = cli.main(["sweep", "mu", "0.1", "0.5", "--points", "2", "--frequency", "185",
                   "--mu", "0.3", "--out", str(tmp_path), "--quiet"])
    assert rc == 2 and "`--mu` fixes the swept parameter" in capsys.readouterr().err


def test_unwritable_output_folder_fails_before_work(tmp_path, capsys, monkeypatch):
    blocker = tmp_path / "a-file"
    blocker.write_text("x")

    def no_work(*a, **k):
        raise AssertionError("work started before the output folder was checked")

    monkeypatch.setattr(engine, "run_points", no_work)
    rc = cli.main(["sweep", *ARGS, "--out", str(blocker / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "`--out` folder" in err and "not writable" in err


def test_any_scene_parameter_with_set(tmp_path):
    rows = sweep(tmp_path, "k", "k", "5e3", "2e4", "--points", "2", "--scale", "log",
                 "--set", "frequency=185", "--set", "mu=0.2")
    assert list(rows[0])[0] == "k_N_per_m"
    assert [float(r["k_N_per_m"]) for r in rows] == pytest.approx([5e3, 2e4])
    assert all(r["status"] == "ok" and float(r["mu"]) == 0.2 for r in rows)
    assert all(float(r["frequency_Hz"]) == 185.0 for r in rows)
    # a stiffer spring presses the rod harder on the rotor
    assert float(rows[1]["min_normal_force_N"]) > float(rows[0]["min_normal_force_N"])


def test_old_invocations_still_work(tmp_path):
    rows = sweep(tmp_path, "mu", "mu", "--frequency", "185", "--num", "3")
    assert [float(r["mu"]) for r in rows] == pytest.approx([0.01, 0.5, 0.99])
    rows = sweep(tmp_path, "f", "frequency", "--num", "2", "--log", "--mu", "0.2")
    assert [float(r["frequency_Hz"]) for r in rows] == pytest.approx([10.0, 12500.0])
    assert all(float(r["mu"]) == 0.2 for r in rows)


def test_failed_point_is_a_status_and_the_sweep_goes_on(tmp_path):
    rows = sweep(tmp_path, "phi0", "phi0", "0.8", "1.5", "--points", "2", "--frequency", "185")
    assert rows[0]["status"] == "ok"
    assert rows[1]["status"].startswith("PainleveError") and rows[1]["mode"] == ""


def test_a_frequency_with_a_decimal_point_keeps_its_file_name(tmp_path):
    # Path.with_suffix used to cut "sweep_mu_12.5Hz" into "sweep_mu_12.csv"
    rows = sweep(tmp_path, "f", "mu", "0.1", "0.2", "--points", "2", "--frequency", "12.5")
    assert len(rows) == 2
    assert (tmp_path / "f" / "sweep_mu_12.5Hz.csv").exists()
    assert (tmp_path / "f" / "sweep_mu_12.5Hz.json").exists()
