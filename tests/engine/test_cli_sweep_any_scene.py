"""``moreau sweep`` on a periodic scene without a study of its own: the generic sweep."""

import csv
import json

import pytest

from moreau.cli import main
from moreau.analysis.engine import periodic_scene_names
from moreau.scenes import registry
from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state


def test_generic_sweep_of_the_stick_slip_motor_matches_single_steady_states(tmp_path):
    # two points (the generic event-driven steady states of the motor cost about a
    # second each): the ends of the range
    assert main(["sweep", "load", "0", "0.1", "--points", "2", "--scene", "stick-slip-motor",
                 "--frequency", "1000", "--out", str(tmp_path), "--quiet", "--jobs", "1"]) == 0
    stem = tmp_path / "sweep_stick-slip-motor_load_1000Hz_event-driven"
    with open(stem.with_suffix(".csv")) as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["load [N]"]) for r in rows] == [0.0, 0.1]
    assert all(r["status"] == "ok" and r["scene"] == "stick-slip-motor" for r in rows)
    assert all(float(r["frequency [Hz]"]) == 1000.0 and r["drive"] == "sawtooth" for r in rows)
    # each point is the motor's steady state: its closed form (1 ms a point; the
    # event-driven shooting on its own, which it replaces here, took 0.6-1 s and agrees
    # with it to 7e-15 in the displacement, and in the mode)
    for r in rows:
        sc = registry.make_scene("stick-slip-motor", frequency=1000.0, load=float(r["load [N]"]))
        ss = stick_slip_steady_state(sc)
        assert float(r["displacement_per_period_m"]) == pytest.approx(
            sc.displacement_to_si(ss.displacement_per_period), rel=1e-9)
        assert r["mode"] == ss.mode
    d = [float(r["displacement_per_period_m"]) for r in rows]
    assert d[0] > d[1]                 # a load slows the slider
    meta = json.loads(stem.with_suffix(".json").read_text())
    assert meta["scene"] == "stick-slip-motor" and meta["swept_parameter"] == "load [N]"
    assert meta["engine"]["computed"] == 2 and meta["provenance"]["moreau_version"]
    assert stem.with_suffix(".png").exists()


@pytest.mark.parametrize("argv, message", [
    (["sweep", "bogus", "0", "1", "--scene", "stick-slip-motor", "--frequency", "1000"],
     "`PARAM` must be a numeric parameter of scene 'stick-slip-motor'"),
    (["sweep", "drive", "0", "1", "--scene", "stick-slip-motor", "--frequency", "1000"],
     "`PARAM` must be a numeric parameter"),
    (["sweep", "load", "0", "1", "--scene", "sliding-box"],
     "`--scene` must be a periodically driven scene, one of"),
    (["sweep", "load", "0", "1", "--scene", "stick-slip-motor"], "`--frequency` is required"),
    (["sweep", "load", "--scene", "stick-slip-motor", "--frequency", "1000"],
     "`START` and `STOP` are required"),
    (["sweep", "load", "0", "1", "--scene", "stick-slip-motor", "--frequency", "1000",
      "--set", "load=0.3"], "`load` is swept"),
    (["sweep", "load", "0", "1", "--scene", "stick-slip-motor", "--frequency", "1000",
      "--set", "stiffness=3"], "`stiffness` is not a parameter of scene 'stick-slip-motor'"),
])
def test_generic_sweep_refuses_bad_input_before_work(argv, message, tmp_path, capsys):
    assert main(argv + ["--out", str(tmp_path / "o")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").glob("*.csv"))


def test_study_sweeps_are_registered_by_their_studies():
    names = periodic_scene_names()
    assert {"friction-drive", "bidirectional-drive", "stick-slip-motor"} <= set(names)
    own = {name: registry.get_entry(name).sweep for name in names}
    assert own["friction-drive"].__module__ == "moreau.studies.paper.sweeps"
    assert own["bidirectional-drive"].__module__ == "moreau.studies.bidirectional.bidirectional_sweep"
    assert own["stick-slip-motor"] is None
    assert registry.get_entry("friction-drive").atlas.__module__ == "moreau.studies.paper.atlas"
    assert registry.get_entry("bidirectional").sweep is own["bidirectional-drive"]
    assert registry.default_scene() == "friction-drive"
    with pytest.raises(ValueError, match="must be a function"):
        registry.resolve_hook("moreau.nope:command")
    with pytest.raises(ValueError, match="has a sweep hook already"):
        registry.register_hook("friction-drive", "sweep", print)
    with pytest.raises(ValueError, match="`kind` must be one of"):
        registry.hook("friction-drive", "stress")
