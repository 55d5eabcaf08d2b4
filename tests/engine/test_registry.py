"""The scene registry: every scene one entry, found by discovery, built by keyword, listed by the CLI."""

import json
import math
import subprocess
import sys

import pytest

from moreau.errors import InputError
from moreau.scenes import registry
from moreau.model.scene import Scene

NAMES = registry.scene_names()


def test_discovery_finds_every_scene_module_that_registers_one():
    # the shipped scenes, found without any list of them
    assert NAMES == ["ball-chain", "ball-chain-3d", "bidirectional-drive", "billiard-backspin", "bouncing-ball",
                     "box-incline", "box-stack-3d",
                     "disk-incline", "double-pendulum-stop", "flexible-rod-drive",
                     "friction-drive", "friction-drive-built", "granular-column", "masonry-arch",
                     "painleve-rod", "piezo-drive", "puck-incline", "rocking-block",
                     "rocking-block-built", "rolling-disk", "silo",
                     "slider-crank", "slider-crank-clearance", "sliding-block", "sliding-box",
                     "sphere-incline", "stick-slip-motor", "tippe-top", "woodpecker-toy"]


@pytest.mark.parametrize("name", NAMES)
def test_every_scene_is_built_by_keyword_from_its_listed_parameters(name):
    entry = registry.get_entry(name)
    scene = registry.make_scene(name, **entry.defaults())
    assert isinstance(scene, Scene) and scene.name == name
    # every listed parameter is a keyword of the constructor and changes the scene
    for p in entry.parameters:
        if isinstance(p.default, float) and p.default > 0:
            # 0.99: a default at the top of its range (a restitution of 1) stays valid
            other = registry.make_scene(name, **{p.name: p.default * 0.99})
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
    with pytest.raises(InputError, match="`scene` must be one of 'ball-chain', 'ball-chain-3d', 'bidirectional-drive'"):
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


def test_steady_state_solvers_come_from_their_registry():
    from moreau.analysis import steady_solvers
    from moreau.analysis.steady_state import find_steady_state
    from moreau.scenes.friction_drive import FrictionDrive

    names = steady_solvers.steady_solver_names()
    # the generic ones, and the friction drive's walker registered by its scene's module
    assert {"event-driven", "moreau-jean", "friction-drive-walker"} <= set(names)
    sc = FrictionDrive(frequency=20.0)
    # "event-driven" on a scene with its own reference takes that reference's solver
    a = find_steady_state(sc)
    b = find_steady_state(sc, scheme="friction-drive-walker")
    assert a.displacement_per_period == b.displacement_per_period and a.mode == "NS"
    with pytest.raises(ValueError, match=r"`scheme` must be a registered scheme, one of .*'moreau-jean'.*; got 'euler'"):
        find_steady_state(sc, scheme="euler")


def test_a_registered_steady_solver_is_used_by_find_steady_state():
    from moreau.analysis import steady_solvers
    from moreau.analysis.steady_state import find_steady_state
    from moreau.scenes.friction_drive import FrictionDrive

    calls = []

    def solver(scene, rtol=None, v_guess=None, max_iter=None, **options):
        calls.append(options)
        return find_steady_state(scene, scheme="moreau-jean", steps_per_period=200)

    steady_solvers.register_steady_solver("test-scheme")(solver)
    try:
        ss = find_steady_state(FrictionDrive(frequency=185.0), scheme="test-scheme", marker=1)
    finally:
        steady_solvers._SOLVERS.pop("test-scheme")
    assert calls == [{"marker": 1}] and ss.mode == "NP"


def _reference_class(name, scene):
    from moreau.integrators.base import get_integrator
    from moreau.integrators.event_driven_generic import EventDrivenReference
    cls = get_integrator(name)
    return cls.resolve(scene) if cls is EventDrivenReference else cls


@pytest.mark.parametrize("name", [n for n in NAMES if registry.get_entry(n).case is not None])
def test_the_listed_reference_is_what_compare_runs_as_the_reference(name):
    # `moreau scenes` lists the reference; `moreau compare` names its rows by the case's
    # ref_scheme: a scheme run on the scene (the same class as the listed one) or, where it
    # is no scheme ("exact", the Painleve rod's "sliding-ode"), the listed name itself
    entry = registry.get_entry(name)
    listed = registry.describe(entry)["reference"]
    ref = entry.case.ref_scheme
    try:
        ours = _reference_class(ref, registry.make_scene(name))
    except InputError:
        assert listed == ref
        return
    assert ours is _reference_class(listed, registry.make_scene(name))
