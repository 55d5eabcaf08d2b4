"""A scheme setting that would not act is refused before any work (exit 2, the option named)."""

import pytest

from moreau.cli import main


@pytest.mark.parametrize("argv, message", [
    (["steady", "--frequency", "185", "--theta", "0.5"], "`--theta` does not act with `--scheme event-driven`: it applies to schemes with a theta (moreau-jean, moreau-jean-projected)"),
    (["steady", "--frequency", "185", "--steps-per-period", "100"], "`--steps-per-period` does not act with `--scheme event-driven`: it applies to time-stepping schemes"),
    (["run", "--frequency", "185", "--scheme", "moreau-jean", "--rtol", "1e-3"],
     "`rtol` is not an option of scheme 'moreau-jean'"),
    (["run", "--scene", "bouncing-ball", "--duration", "1", "--theta", "0.5"],
     "`theta` is not an option of scheme 'event-driven'"),
    (["run", "--scene", "bouncing-ball", "--duration", "1", "--scheme", "moreau-jean",
      "--option", "hh=0.1", "--steps", "10"], "`hh` is not an option of scheme 'moreau-jean'"),
    (["run", "--scene", "bouncing-ball", "--steps", "100"], "`--duration` is required"),
    (["run", "--frequency", "185", "--steps", "100"], "`steps` applies to time-stepping schemes"),
    (["steady", "--scene", "bidirectional", "--frequency", "185", "--theta", "1"], "`--theta` does not act with `--scheme event-driven`"),
])
def test_unused_scheme_setting_is_refused(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_a_time_stepping_run_without_steps_takes_a_thousand(tmp_path):
    # `--duration` without `--steps`: the run's default step count, named in the file
    assert main(["run", "--scene", "bouncing-ball", "--duration", "1", "--scheme", "moreau-jean",
                 "--out", str(tmp_path)]) == 0
    assert (tmp_path / "history_bouncing-ball_moreau-jean_steps1000.csv").is_file()


def test_moreau_jean_steady_takes_its_tolerance(capsys):
    import json
    assert main(["steady", "--frequency", "185", "--scheme", "moreau-jean", "--steps-per-period",
                 "200", "--rtol", "1e-9", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["scheme"] == "moreau-jean" and rep["steps_per_period"] == 200
    assert rep["periodic_residual"] <= 1e-9


def test_run_takes_the_event_driven_tolerance(tmp_path, capsys):
    # the reference's tolerance acts in a time history: a looser one takes fewer events' iterations
    import json
    assert main(["run", "--scene", "bouncing-ball", "--duration", "1.5", "--rtol", "1e-6",
                 "--out", str(tmp_path), "--quiet", "--no-plot"]) == 0
    side = json.loads(next(tmp_path.glob("*.json")).read_text())
    assert side["options"]["rtol"] == 1e-6 and side["scheme"] == "event-driven"
