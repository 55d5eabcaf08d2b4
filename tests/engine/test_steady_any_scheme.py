"""Steady states, sweeps and their settings under every registered scheme, not only two.

A scheme without a steady-state solver of its own gets Newton shooting on the
period map it computes; its settings are checked when they are made.
"""

import json

import pytest

from moreau.analysis.scheme_settings import Scheme, make_scheme
from moreau.analysis.steady_state import find_steady_state
from moreau.analysis.sweep import sweep_tag
from moreau.cli import main
from moreau.model.registry import make_scene
from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state


@pytest.fixture(scope="module")
def drive():
    return make_scene("friction-drive", frequency=185.0)


def test_generic_event_driven_shooting_agrees_with_the_walker(drive):
    walker = find_steady_state(drive)
    generic = find_steady_state(drive, "event-driven-generic", rtol=1e-10)
    assert generic.scheme == "event-driven-generic" and generic.mode == walker.mode == "NP"
    assert generic.displacement_per_period == pytest.approx(walker.displacement_per_period,
                                                            rel=1e-9)


def test_compliant_steady_state_through_the_command_line(capsys, drive):
    # a loose integration and shooting tolerance and a wide friction regularisation:
    # each period of RK45 on the stiff contact costs seconds in Python, and the point
    # here is the plumbing and the model (3.6 s; 60 s with friction_velocity 1e-3)
    rc = main(["steady", "--frequency", "185", "--scheme", "compliant-rk45",
               "--option", "stiffness=1e4", "--option", "rtol=1e-7",
               "--option", "friction_velocity=1e-2", "--rtol", "1e-5", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["scheme"] == "compliant-rk45"
    assert rep["options"] == {"stiffness": 1e4, "rtol": 1e-7, "friction_velocity": 1e-2}
    # measured -5.6855e-3 scene units (-5.628e-3 with friction_velocity 1e-3)
    assert rep["displacement_per_period_m"] == pytest.approx(
        drive.displacement_to_si(-5.6855e-3), rel=1e-3)
    # a soft contact (k = 1e4 in the scene's units) changes the answer: it is a
    # model error of about 15 % against the rigid reference, not a failure
    rigid = drive.displacement_to_si(find_steady_state(drive).displacement_per_period)
    assert 0.05 < abs(rep["displacement_per_period_m"] / rigid - 1) < 0.3


@pytest.mark.parametrize("args, message", [
    (["--scheme", "event-driven", "--option", "stiffness=1"],
     "`stiffness` is not an option of scheme 'event-driven'"),
    (["--scheme", "compliant-rk45", "--steps-per-period", "100"],
     "`--steps-per-period` does not act with `--scheme compliant-rk45`"),
    (["--scheme", "compliant-radau", "--theta", "0.5"],
     "`--theta` does not act with `--scheme compliant-radau`: it applies to schemes with a theta"),
    (["--scheme", "moreau-jean", "--option", "h=0.1"],
     "give the step as `steps_per_period`"),
    (["--scheme", "compliant-rk45", "--option", "stiffness"], "`--option` takes NAME=VALUE"),
])
def test_settings_the_scheme_does_not_take_are_refused_before_work(capsys, args, message):
    rc = main(["steady", "--frequency", "185", *args])
    err = capsys.readouterr().err
    assert rc == 2 and message in err


def test_sweep_files_and_columns_name_any_scheme():
    s = make_scheme("compliant-radau", rtol=1e-6, options={"stiffness": 1e5})
    assert sweep_tag("stick-slip-motor", "mu", 1000.0, s) == \
        "sweep_stick-slip-motor_mu_1000Hz_compliant-radau_stiffness100000_rtol1e-06"
    mj = make_scheme("moreau-jean", theta=0.5, steps_per_period=400)
    assert sweep_tag("friction-drive", "frequency", None, mj) == \
        "sweep_friction-drive_frequency_moreau-jean_theta0.5_N400"


def test_sweep_runs_a_scheme_beyond_the_two(tmp_path, capsys):
    rc = main(["sweep", "mu", "0.2", "0.25", "--points", "2", "--scene", "stick-slip-motor",
               "--frequency", "1000", "--scheme", "event-driven-generic", "--jobs", "1",
               "--out", str(tmp_path), "--quiet", "--no-plot"])
    assert rc == 0, capsys.readouterr().err
    csv = next(tmp_path.glob("sweep_stick-slip-motor_mu_1000Hz_event-driven-generic*.csv"))
    lines = csv.read_text().splitlines()
    header = lines[0].split(",")
    rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
    assert [r["scheme"] for r in rows] == ["event-driven-generic"] * 2
    assert all(r["status"] == "ok" for r in rows)
    for r in rows:
        motor = make_scene("stick-slip-motor", frequency=1000.0, mu=float(r["mu"]))
        # against the motor's closed-form steady state (1 ms; the event-driven shooting it
        # replaces here took 0.6-1 s a point and agrees with it to 4e-15)
        ref = motor.displacement_to_si(stick_slip_steady_state(motor).displacement_per_period)
        assert float(r["displacement_per_period_m"]) == pytest.approx(ref, rel=1e-8)


def test_scheme_settings_round_trip_their_options():
    s = Scheme("compliant-rk45", rtol=1e-6, options={"stiffness": 1e6})
    assert s.options == {"stiffness": 1e6} and s.description == \
        "compliant-rk45 (stiffness=1e+06)"
