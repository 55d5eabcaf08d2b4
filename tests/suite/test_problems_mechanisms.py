"""The suite's problems on the mechanisms with joints: their references from closed forms."""

import math

import pytest

from moreau.suite.problem import get_problem


def test_the_clearance_slider_cranks_reference_is_the_ideal_closed_form():
    prob = get_problem("slider-crank-clearance")
    # at theta = 3 pi / 2 the crank is vertical: x = sqrt(l^2 - r^2) (l = 1 in the units)
    r = 0.05 / 0.12
    assert prob.window == pytest.approx(1.5 * math.pi, rel=1e-15)
    assert prob.reference()["slider_position"] == pytest.approx(math.sqrt(1.0 - r * r),
                                                                abs=1e-15)
    assert prob.scales() == {"slider_position": pytest.approx(2.0 * r, rel=1e-15)}


def test_the_double_pendulums_reference_is_its_initial_energy():
    prob = get_problem("double-pendulum-stop")
    # released at rest horizontal: above the hanging rest, m g l / 2 + m g (l + l / 2) = 2
    # in the scene's units (m = g = l = 1)
    assert prob.reference() == {"energy_end": pytest.approx(2.0, rel=1e-14),
                                "energy_lowest": pytest.approx(2.0, rel=1e-14)}
    q0, v0 = prob.start(prob.make_scene())
    assert prob.measure(None, type("Run", (), {"q": q0[None], "v": v0[None]})()) == \
        prob.reference()
