"""`moreau animate` and the scenes' shapes."""

import numpy as np
import pytest
from PIL import Image

from moreau.cli import main
from moreau.errors import InputError, MoreauError
from moreau.scenes import registry
from moreau.integrators.result import SimulationResult
from moreau.model.drawing import scene_state
from moreau.model.scene import Scene, velocity_count
from moreau.suite.animate import animate_run


#: with the long checks: the masonry arch, whose first drawing compiles its generated poses and
#: frames for four bodies (11 s on the loaded shared machine, about 2 s quiet), beyond the
#: default run's budget for a new scene; its model is checked there by check_scene
DRAWN_SLOWLY = {"masonry-arch"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow)
                                  if n in DRAWN_SLOWLY else n for n in registry.scene_names()])
def test_every_scene_draws_itself(name):
    scene = registry.make_scene(name)
    q, _ = scene.initial_state()
    # the SI coordinates the run table holds: lengths scaled, angles in rad
    nc = scene.ncontacts
    res = SimulationResult(t=np.zeros(1), q=q[None, :], v=np.zeros((1, velocity_count(scene))),
                           regime=np.zeros((1, nc), int), force_N=np.zeros((1, nc)),
                           force_T=np.zeros((1, nc)), slip_velocity=np.zeros((1, nc)),
                           gap=np.zeros((1, nc)))
    cols = dict((n, c) for n, _, c in scene.si_columns(res))
    q_si = np.array([cols[f"q_{i}"][0] for i in range(scene.ndof)])
    assert np.allclose(scene_state(scene, q_si, 0.0)[0], q, rtol=1e-12, atol=0.0)
    shapes = scene.shapes(q_si, 0.0)
    contacts = [s for s in shapes if s["kind"] == "contact"]
    assert sorted(c["index"] for c in contacts) == list(range(scene.ncontacts))
    for c in contacts:
        assert np.hypot(*c["normal"]) == pytest.approx(1.0)
    assert any(s["kind"] != "contact" for s in shapes)


def test_ball_contact_point_is_its_lowest_point():
    ball = registry.make_scene("bouncing-ball", radius=0.05)
    shapes = ball.shapes([0.3], 0.0)
    (c,) = [s for s in shapes if s["kind"] == "contact"]
    assert c["point"] == pytest.approx((0.0, 0.25))


def test_default_refuses_naming_the_scene():
    class Plain(Scene):
        name = "plain"
    with pytest.raises(MoreauError, match="scene 'plain' \\(Plain\\) cannot be drawn"):
        Plain().shapes([0.0])


def test_animate_a_run(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["run", "--scene", "bouncing-ball", "--scheme", "moreau-jean", "--duration",
                 "0.6", "--steps", "300", "--samples", "60", "--out", str(run), "--no-plot",
                 "--quiet"]) == 0
    gif = tmp_path / "ball.gif"
    assert main(["animate", str(run), "--out", str(gif), "--frames", "4"]) == 0
    assert "(4 frames)" in capsys.readouterr().out
    with Image.open(gif) as im:
        assert im.n_frames == 4
    # an existing file is not replaced without --force; a wrong suffix is refused
    with pytest.raises(InputError, match="exists"):
        animate_run(str(run), str(gif))
    with pytest.raises(InputError, match=".gif or .mp4"):
        animate_run(str(run), str(tmp_path / "x.avi"))
    with pytest.raises(InputError, match="no output of `moreau run`"):
        animate_run(str(tmp_path), str(tmp_path / "y.gif"))


@pytest.mark.slow
@pytest.mark.parametrize("name", registry.scene_names())
def test_animate_default_run_of_every_scene(tmp_path, name):
    scene = registry.make_scene(name)
    length = ["--periods", "0.5"] if scene.period is not None else ["--duration", "0.2"]
    run = tmp_path / "run"
    assert main(["run", "--scene", name, *length, "--samples", "50", "--out", str(run),
                 "--no-plot", "--quiet"]) == 0
    path, frames = animate_run(str(run), str(tmp_path / "a.gif"), max_frames=8)
    with Image.open(path) as im:
        assert im.n_frames == frames == 8


def test_the_suite_animates_a_spatial_problem_with_moreau_jean(tmp_path):
    # the event-driven reference refuses a spatial scene by name: the page's animation is
    # Moreau-Jean's run instead, not a "no animation" line
    from moreau.suite.report import animate_problem

    path, cause = animate_problem("puck-incline", str(tmp_path / "puck.gif"), frames=6)
    assert cause is None and path.endswith("puck.gif")
    with Image.open(path) as im:
        assert im.n_frames == 6


@pytest.mark.slow  # the spatial Moreau-Jean kernels' compile: 62 s on the loaded machine
def test_run_takes_a_scheme_that_steps_a_spatial_scene(tmp_path):
    # without --scheme the event-driven reference would refuse the spatial bodies by name
    import json
    run = tmp_path / "run"
    assert main(["run", "--scene", "billiard-backspin", "--duration", "0.05", "--steps", "20",
                 "--samples", "5", "--out", str(run), "--no-plot", "--quiet"]) == 0
    (side,) = run.glob("*.json")
    assert json.loads(side.read_text())["scheme"] == "moreau-jean"
    path, frames = animate_run(str(run), str(tmp_path / "b.gif"), max_frames=3)
    with Image.open(path) as im:
        assert im.n_frames == frames == 3
