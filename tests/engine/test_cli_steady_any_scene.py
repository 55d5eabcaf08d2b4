"""`moreau steady --scene NAME --set NAME=VALUE` for every registered periodically driven scene."""

import json

import pytest

from moreau.cli import main
from moreau.model.registry import make_scene
from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state


def steady(capsys, *args):
    rc = main(["steady", *args, "--json"])
    out = capsys.readouterr()
    return rc, (json.loads(out.out) if rc == 0 else out.err)


def test_stick_slip_motor_steady_state_equals_its_exact_one(capsys):
    rc, rep = steady(capsys, "--scene", "stick-slip-motor", "--frequency", "1000",
                     "--set", "mu=0.25", "--set", "drive=sine")
    assert rc == 0 and rep["scene"] == "stick-slip-motor"
    motor = make_scene("stick-slip-motor", frequency=1000.0, mu=0.25, drive="sine")
    exact = motor.displacement_to_si(stick_slip_steady_state(motor).displacement_per_period)
    # the generic event-driven shooting against the scene's closed-form walker
    assert rep["displacement_per_period_m"] == pytest.approx(exact, rel=1e-9)
    assert rep["parameters"]["mu"] == 0.25


def test_moreau_jean_steady_state_of_another_scene_is_close_to_the_reference(capsys):
    rc, ed = steady(capsys, "--scene", "stick-slip-motor", "--frequency", "1000")
    rc2, mj = steady(capsys, "--scene", "stick-slip-motor", "--frequency", "1000",
                     "--scheme", "moreau-jean", "--steps-per-period", "4000")
    assert rc == rc2 == 0 and mj["scheme"] == "moreau-jean"
    assert mj["displacement_per_period_m"] == pytest.approx(ed["displacement_per_period_m"],
                                                            rel=1e-2)


@pytest.mark.parametrize("args, message", [
    (["--scene", "sliding-block"], "scene 'sliding-block' has no periodic drive"),
    (["--scene", "pendulum"], "`scene` must be one of"),
    (["--frequency", "185", "--set", "zz=3"],
     "`--set zz`: `zz` is not a parameter of scene 'friction-drive'"),
    (["--frequency", "185", "--mu", "0.2", "--set", "mu=0.3"], "`mu` is given twice"),
    (["--scene", "stick-slip-motor", "--frequency", "1000", "--phi0", "0.5"],
     "`--phi0`: `phi0` is not a parameter of scene 'stick-slip-motor'"),
])
def test_bad_scene_settings_are_refused(capsys, args, message):
    rc, err = steady(capsys, *args)
    assert rc == 2 and message in err
