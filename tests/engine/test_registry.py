"""The scene registry: every scene one entry, found by discovery, built by keyword, listed by the CLI."""

import json
import math
import subprocess
import sys

import pytest

from moreau.errors import InputError
from moreau.scenes import registry
from moreau.scenes.base import Scene

NAMES = registry.scene_names()


def test_discovery_finds_every_scene_module_that_registers_one():
    # the seven shipped scenes, found without any list of them
    assert NAMES == ["bidirectional-drive", "bouncing-ball", "friction-drive", "painleve-rod",
                     "sliding-block", "sliding-box", "stick-slip-motor"]


@pytest.mark.parametrize("name", NAMES)
def test_every_scene_is_built_by_keyword_from_its_listed_parameters(name):
    entry = registry.get_entry(name)
    scene = registry.make_scene(name, **entry.defaults())
    assert isinstance(scene, Scene) and scene.name == name
    # every listed parameter is a keyword of the constructor and changes the scene
    for p in entry.parameters:
        if isinstance(p.default, float) and p.default > 0:
            other = registry.make_scene(name, **{p.name: p.default * 1.01})
            assert other is not scene


@pytest.mark.parametrize("name", NAMES)
def test_bad_parameters_are_refused_by_name_before_any_work(name):
    entry = registry.get_entry(name)
    with pytest.raises(InputError, match="`no_such_parameter` is not a parameter"):
        registry.make_scene(name, no_such_parameter=1.0)
    for p in entry.parameters:
        if isinstance(p.default, float):
            with pytest.raises(InputError, match=f"`{p.name}`"):
                registry.make_scene(name, **{p.name: math.nan})


def test_unknown_scene_lists_the_known_ones():
    with pytest.raises(InputError, match="`scene` must be one of 'bidirectional-drive'"):
        registry.get_entry("belt")


def test_a_second_scene_under_a_taken_name_is_refused():
    entry = registry.get_entry("bouncing-ball")
    clash = registry.SceneEntry(name="bouncing-ball", factory=lambda: None, parameters=(),
                                description="")
    with pytest.raises(InputError, match="registered already"):
        registry.register_scene(clash)
    assert registry.get_entry("bouncing-ball") is entry


def test_moreau_scenes_json_lists_every_scene_with_its_parameters_and_units():
    out = subprocess.run([sys.executable, "-m", "moreau", "scenes", "--json"], check=True,
                         capture_output=True, text=True).stdout
    listed = json.loads(out)
    assert [d["name"] for d in listed] == NAMES
    fd = next(d for d in listed if d["name"] == "friction-drive")
    params = {p["name"]: p for p in fd["parameters"]}
    assert params["frequency"]["unit"] == "Hz" and params["frequency"]["default"] == 185.0
    assert params["k"]["unit"] == "N/m" and params["mu"]["unit"] == ""
    ball = next(d for d in listed if d["name"] == "bouncing-ball")
    assert ball["compare"] == ["height"] and ball["reference"] == "exact"


def test_the_package_exposes_the_scene_classes_without_a_list():
    from moreau.scenes import BouncingBall, FrictionDriveParams, SawtoothDrive
    assert BouncingBall.name == "bouncing-ball"
    assert FrictionDriveParams().mu == 0.1
    assert SawtoothDrive.name == "sawtooth"
    with pytest.raises(ImportError):
        from moreau.scenes import NoSuchScene  # noqa: F401
