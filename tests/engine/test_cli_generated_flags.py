"""The commands' scene and scheme flags are generated from the registries (issue 35)."""

import argparse
import dataclasses
import functools
import json

import pytest

from moreau.cli import build_parser, main, scene_parameter_flags, scheme_option_flags
from moreau.integrators.base import INTEGRATORS
from moreau.scenes import registry


@functools.lru_cache(maxsize=1)
def _subcommands():
    parser = build_parser()
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices


def _subcommand(name):
    return _subcommands()[name]


@pytest.mark.parametrize("command", ["run", "steady", "sweep", "atlas", "bifurcation"])
def test_every_scene_parameter_and_scheme_option_has_its_flag(command):
    flags = _subcommand(command)._option_string_actions
    registry.discover()
    for entry in registry.entries():
        for prm in entry.parameters:
            assert "--" + prm.name.replace("_", "-") in flags, (entry.name, prm.name)
    given_otherwise = {"theta", "rtol"}      # flags of their own (`--rtol`: the shooting's)
    scene_names = set(scene_parameter_flags())
    for name, cls in INTEGRATORS.items():
        for f in dataclasses.fields(cls.Options) if cls.Options is not None else ():
            flag = "--" + f.name.replace("_", "-")
            if f.name in scheme_option_flags():
                assert flags[flag].dest == "scheme_opt_" + f.name
            else:
                # a name a scene parameter has too (damping), an own flag, or an array
                assert f.name in scene_names | given_otherwise | {"closed0"}, (name, f.name)


def test_a_scheme_flag_acts_as_its_option_with_the_fields_type(tmp_path, capsys):
    assert main(["run", "--scene", "bouncing-ball", "--duration", "0.5", "--scheme",
                 "moreau-jean", "--h", "0.01", "--save-every", "5", "--projection", "true",
                 "--out", str(tmp_path), "--quiet", "--no-plot"]) == 0
    side = json.loads(next(tmp_path.glob("*.json")).read_text())
    opts = side["options"]
    assert opts["h"] == 0.01 and opts["save_every"] == 5 and opts["projection"] is True
    assert isinstance(opts["save_every"], int)


@pytest.mark.parametrize("argv, message", [
    (["--h", "0.01", "--option", "h=0.01"], "`h` is given twice (`--h` and `--option h=...`)"),
    (["--h", "0.01", "--lcp-method", "simplex"], "`lcp_method` must be one of"),
    (["--h", "0.01", "--save-every", "0"], "`save_every` must be an integer >= 1, got 0"),
    (["--h", "0.01", "--n-balls", "3"],
     "`--n-balls`: `n_balls` is not a parameter of scene 'bouncing-ball'"),
])
def test_generated_flags_are_checked_before_any_work(argv, message, tmp_path, capsys):
    base = ["run", "--scene", "bouncing-ball", "--duration", "0.5", "--scheme", "moreau-jean",
            "--out", str(tmp_path), "--quiet", "--no-plot"]
    assert main(base + argv) == 2
    assert message in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_a_bool_flag_refuses_a_word_it_cannot_read(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "--scene", "bouncing-ball", "--projection", "maybe"])
    assert exc.value.code == 2
    assert "expected true or false, got 'maybe'" in capsys.readouterr().err
