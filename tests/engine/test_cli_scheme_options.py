"""A scheme setting that would not act is refused before any work (exit 2, the option named)."""

import pytest

from moreau.cli import main


@pytest.mark.parametrize("argv, message", [
    (["steady", "--frequency", "185", "--theta", "0.5"], "`--theta` applies only to `--scheme moreau-jean`"),
    (["steady", "--frequency", "185", "--steps-per-period", "100"], "`--steps-per-period` applies only"),
    (["run", "--frequency", "185", "--rtol", "1e-3"], "`--rtol` does not act in `moreau run`"),
    (["run", "--frequency", "185", "--scheme", "moreau-jean", "--rtol", "1e-3"], "`--rtol` does not act"),
    (["steady", "--scene", "bidirectional", "--frequency", "185", "--theta", "1"], "`--theta` applies only"),
])
def test_unused_scheme_setting_is_refused(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_moreau_jean_steady_takes_its_tolerance(capsys):
    import json
    assert main(["steady", "--frequency", "185", "--scheme", "moreau-jean", "--steps-per-period",
                 "200", "--rtol", "1e-9", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["scheme"] == "moreau-jean" and rep["steps_per_period"] == 200
    assert rep["periodic_residual"] <= 1e-9
