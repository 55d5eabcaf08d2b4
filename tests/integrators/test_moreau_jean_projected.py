"""moreau-jean-projected: the gaps it holds against plain Moreau–Jean, its order, its options."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes import BouncingBall, registry

registry.discover()


def _ball_exact(sc, t):
    """The bouncing ball's height (scaled) at ``t`` up to its second impact: free fall from
    rest, Newton's impact law at the ground, free flight again."""
    p = sc.params
    g = p.gravity * sc.time ** 2 / sc.length
    q0 = float(sc.initial_state()[0][0])
    r = p.radius / sc.length
    t1 = math.sqrt(2.0 * (q0 - r) / g)
    if t <= t1:
        return q0 - 0.5 * g * t * t
    s = t - t1
    return r + sc.e * g * t1 * s - 0.5 * g * s * s


@pytest.mark.parametrize("fast", [True, False])
def test_the_ball_never_penetrates_where_moreau_jean_does(fast):
    sc = BouncingBall()
    q0, v0 = sc.initial_state()
    plain = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean", h=1e-3, fast=fast)
    proj = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean-projected", h=1e-3, fast=fast)
    assert plain.success and proj.success
    # the velocity-level impact law leaves the ball up to h |v| below the ground
    assert plain.gap.min() < -1e-4
    assert proj.gap.min() >= -1e-14 and proj.stats["max_penetration"] <= 1e-14
    assert proj.stats["projection_iterations"] > 0


def test_compiled_and_python_projections_agree_on_the_rocking_block():
    sc = registry.make_scene("rocking-block")
    q0, v0 = sc.initial_state()
    runs = [simulate(sc, (0.0, 1.5), q0, v0, "moreau-jean-projected", h=2e-3, fast=f)
            for f in (True, False)]
    plain = simulate(sc, (0.0, 1.5), q0, v0, "moreau-jean", h=2e-3)
    assert all(r.success for r in runs)
    np.testing.assert_allclose(runs[0].q, runs[1].q, rtol=0, atol=1e-10)
    assert runs[0].gap.min() >= -1e-13
    # the drift plain Moreau–Jean leaves on the block's corners, measured in the same run
    assert plain.gap.min() < -1e-6


def test_first_order_in_free_flight_and_within_h_across_an_impact():
    sc = BouncingBall()
    q0, v0 = sc.initial_state()
    hs = [4e-3, 2e-3, 1e-3, 5e-4]
    # free flight (the first impact is at t = 1.41): theta = 1 leaves the error g h t / 2
    errs = [abs(simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean-projected", h=h).q[-1, 0]
                - _ball_exact(sc, 1.0)) for h in hs]
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - 1.0) < 1e-6, (errs, slope)
    # across the impact the error depends on where it falls in the grid (slopes of 0.8-1.5
    # measured for both schemes); it stays below h (at most 0.65 h measured, h >= 2.5e-4)
    for h in hs:
        res = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean-projected", h=h)
        assert abs(res.q[-1, 0] - _ball_exact(sc, 2.0)) < h


def test_projection_is_refused_by_name():
    sc = BouncingBall()
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match="`projection`"):
        simulate(sc, (0.0, 0.1), q0, v0, "moreau-jean-projected", h=1e-3, projection=False)
