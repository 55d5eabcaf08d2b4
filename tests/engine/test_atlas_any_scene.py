"""`moreau atlas --scene NAME --x ... --y ...`: the mode map of any periodic scene."""

import csv

import pytest

from moreau.analysis.atlas import run_scene_atlas
from moreau.cli import main
from moreau.model.registry import make_scene
from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state


def test_every_point_is_the_scenes_steady_state():
    rows = run_scene_atlas("stick-slip-motor", ("load", [0.0, 0.05]), ("mu", [0.2, 0.3]),
                           frequency=1000.0, out=None, progress=False, plot=False,
                           n_jobs=1, log=lambda s: None)
    # x varies fastest
    assert [(r["load [N]"], r["mu"]) for r in rows] == [(0.0, 0.2), (0.05, 0.2), (0.0, 0.3),
                                                       (0.05, 0.3)]
    # each line of constant mu starts cold and continues its second point
    assert [r["start"] for r in rows] == ["cold", "continued"] * 2
    for r in rows:
        motor = make_scene("stick-slip-motor", frequency=1000.0, load=r["load [N]"], mu=r["mu"])
        # the motor's closed-form steady state (1 ms; the event-driven shooting on its own,
        # which this test ran for each point, took 0.6-1 s and agrees with it to 7e-15)
        ss = stick_slip_steady_state(motor)
        assert r["status"] == "ok" and r["mode"] == ss.mode
        assert r["displacement_per_period_m"] == pytest.approx(
            motor.displacement_to_si(ss.displacement_per_period), rel=1e-9)


def test_the_command_writes_table_sidecar_and_figure(tmp_path, capsys):
    # the command's files and grid, on the friction drive: with --x and --y it takes the
    # same generic atlas as any scene (the stick-slip motor's points are checked above), and
    # its steady states, the walker's, cost 0.3 s for the grid against 6 s for the motor's
    rc = main(["atlas", "--scene", "friction-drive", "--x", "frequency", "500", "2000",
               "--y", "mu", "0.2", "0.3", "--x-points", "3", "--y-points", "2", "--jobs", "1",
               "--out", str(tmp_path), "--quiet"])
    assert rc == 0, capsys.readouterr().err
    stem = tmp_path / "atlas_friction-drive_frequency-mu_event-driven"
    with open(f"{stem}.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 6 and {r["scheme"] for r in rows} == {"event-driven"}
    # log-spaced frequency by default
    assert [float(r["frequency [Hz]"]) for r in rows[:3]] == pytest.approx([500, 1000, 2000])
    assert (tmp_path / f"{stem.name}.json").exists() and (tmp_path / f"{stem.name}.png").exists()


@pytest.mark.parametrize("argv, message", [
    (["--scene", "stick-slip-motor", "--frequency", "1000"],
     "scene 'stick-slip-motor' has no atlas of its own"),
    (["--scene", "stick-slip-motor", "--x", "load", "0", "1"], "give both axes"),
    (["--scene", "stick-slip-motor", "--x", "load", "0", "1", "--y", "load", "0", "1",
      "--frequency", "1000"], "two different parameters"),
    (["--scene", "stick-slip-motor", "--x", "load", "0", "1", "--y", "mu", "0.1", "0.2",
      "--frequency", "1000", "--fmin", "10"], "`--fmin` belongs to a scene's own atlas"),
    (["--scene", "stick-slip-motor", "--x", "load", "0", "1", "--y", "drive", "0.1", "0.2",
      "--frequency", "1000"], "`PARAM` must be a numeric parameter of scene"),
    (["--scene", "stick-slip-motor", "--x", "load", "0", "1", "--y", "stiffness", "0.1", "0.2",
      "--frequency", "1000"], "`PARAM` must be a numeric parameter of scene"),
    (["--scene", "stick-slip-motor", "--x", "load", "0", "1", "--y", "mu", "0.1", "0.2"],
     "`--frequency` is required"),
    (["--set", "mu=0.2"], "`--set` applies with `--x` and `--y`"),
    (["--x-points", "4"], "`--x-points` applies with `--x` and `--y`"),
    (["--scene", "sliding-block", "--x", "mu", "0.1", "0.2", "--y", "speed", "1", "2"],
     "must be a periodically driven scene"),
])
def test_bad_atlas_settings_are_refused_before_work(argv, message, tmp_path, capsys):
    assert main(["atlas", *argv, "--out", str(tmp_path / "o")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
