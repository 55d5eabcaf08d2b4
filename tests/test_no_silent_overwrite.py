"""Issue 21: an output of a run with other settings is never replaced silently."""

import csv
import json

from moreau import cli
from moreau.cli import main

SWEEP = ["sweep", "frequency", "20", "40", "--points", "2", "--jobs", "1", "--quiet", "--no-plot"]


def _no_run(*args, **kwargs):
    raise RuntimeError("the run started before its outputs were checked")


def _refusal(name, differ):
    return (f"moreau: error: `--out` already holds {name}.csv/.json from a run with other settings "
            f"({differ}): give `--force` to replace them, or another `--out`\n")


def test_a_sweep_with_other_settings_is_refused_then_forced(tmp_path, capsys):
    out = ["--out", str(tmp_path)]
    assert main(SWEEP + out) == 0
    assert main(SWEEP + out) == 0  # the same settings: a rerun, allowed
    capsys.readouterr()
    first = (tmp_path / "sweep_frequency.csv").read_text()
    assert main(SWEEP + out + ["--mu", "0.3"]) == 2
    assert capsys.readouterr().err == _refusal("sweep_frequency", "parameters_SI")
    assert (tmp_path / "sweep_frequency.csv").read_text() == first
    assert main(["sweep", "frequency", "20", "50", "--points", "2", "--jobs", "1", "--quiet",
                 "--no-plot"] + out) == 2
    assert capsys.readouterr().err == _refusal("sweep_frequency", "values")
    assert main(SWEEP + out + ["--mu", "0.3", "--force"]) == 0
    rows = list(csv.DictReader(open(tmp_path / "sweep_frequency.csv")))
    assert {r["mu"] for r in rows} == {"0.3"} and {r["scheme"] for r in rows} == {"event-driven"}
    assert json.loads((tmp_path / "sweep_frequency.json").read_text())["settings"][
        "parameters_SI"]["mu"] == 0.3


def test_a_sweep_by_another_scheme_gets_its_own_files(tmp_path, capsys):
    out = ["--out", str(tmp_path)]
    assert main(SWEEP + out) == 0
    assert main(SWEEP + out + ["--scheme", "moreau-jean", "--steps-per-period", "100"]) == 0
    names = sorted(p.name for p in tmp_path.glob("*.csv"))
    assert names == ["sweep_frequency.csv", "sweep_frequency_mj_theta1_N100.csv"]
    rows = list(csv.DictReader(open(tmp_path / names[1])))
    assert {r["scheme"] for r in rows} == {"moreau-jean"}


def test_the_paper_atlas_names_its_scheme_and_refuses_other_settings(tmp_path, capsys):
    argv = ["atlas", "--plane", "f-mu", "--f-points", "2", "--y-points", "2", "--fmin", "20",
            "--fmax", "40", "--jobs", "1", "--quiet", "--no-plot", "--out", str(tmp_path)]
    assert main(argv) == 0
    assert main(argv + ["--scheme", "moreau-jean", "--steps-per-period", "100"]) == 0
    assert sorted(p.name for p in tmp_path.glob("*.csv")) == [
        "atlas_f-mu.csv", "atlas_f-mu_mj_theta1_N100.csv"]
    assert {r["scheme"] for r in csv.DictReader(open(tmp_path / "atlas_f-mu.csv"))} == {
        "event-driven"}
    capsys.readouterr()
    assert main(argv + ["--mu", "0.3"]) == 2
    assert capsys.readouterr().err == _refusal("atlas_f-mu", "parameters_SI")
    prov = json.loads((tmp_path / "atlas_f-mu.json").read_text())["provenance"]
    assert {"numpy_version", "numba_version", "cpu", "threads", "time_utc", "command"} <= set(prov)


def test_a_run_of_another_length_is_refused_then_forced(tmp_path, capsys, monkeypatch):
    argv = ["run", "--scene", "bouncing-ball", "--duration", "0.1", "--quiet", "--no-plot",
            "--out", str(tmp_path)]
    assert main(argv) == 0
    capsys.readouterr()
    with monkeypatch.context() as m:
        # the refusal comes before the run: a run here would be work thrown away
        m.setattr(cli, "run_history", _no_run)
        assert main(argv[:3] + ["--duration", "0.2"] + argv[5:]) == 2
    assert capsys.readouterr().err == _refusal("history_bouncing-ball_event-driven", "duration")
    assert main(argv[:3] + ["--duration", "0.2"] + argv[5:] + ["--force"]) == 0


def test_a_comparison_with_other_settings_is_refused_then_forced(tmp_path, capsys):
    base = ["compare", "--scene", "bouncing-ball", "--quick", "--quiet", "--no-plot",
            "--out", str(tmp_path)]
    assert main(base) == 0
    assert main(base) == 0  # the same settings: a rerun, allowed
    first = (tmp_path / "compare_bouncing-ball.json").read_text()
    assert json.loads(first)["settings"]["quick"] is True
    capsys.readouterr()
    assert main(base + ["--set", "restitution=0.8"]) == 2
    assert capsys.readouterr().err == _refusal("compare_bouncing-ball", "parameters")
    assert (tmp_path / "compare_bouncing-ball.json").read_text() == first
    assert main(base + ["--set", "restitution=0.8", "--force"]) == 0
    rep = json.loads((tmp_path / "compare_bouncing-ball.json").read_text())
    assert rep["parameters"]["restitution"] == 0.8
