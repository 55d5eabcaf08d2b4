"""The built rocking block under a constant base acceleration: the onset of rocking.

Closed forms (derived in :mod:`moreau.scenes.rocking_block_built`): rocking
starts above ``A = g b / h``, with ``theta''(0+) = 3 (A h - g b) / (4 (b^2 + h^2))``.
"""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.event_driven_generic import GenericEventDriven
from moreau.scenes.rocking_block_built import (initial_angular_acceleration,
                                               rocking_block_built, rocking_block_model,
                                               rocking_onset_acceleration)

W, H, G = 0.2, 0.4, 9.81
A_ON = rocking_onset_acceleration(W, H, G)


def _block(ratio):
    return rocking_block_built(width=W, height=H, gravity=G, tilt=0.0,
                               base_acceleration=ratio * A_ON)


def test_onset_closed_forms():
    assert A_ON == pytest.approx(G * 0.1 / 0.2, rel=1e-15)
    # Newton-Euler about the left corner by hand at A = 2 A_on: I_O = m (b^2 + h^2) 4/3,
    # moment m (A h - g b) = m g b
    assert initial_angular_acceleration(W, H, 2 * A_ON, G) == pytest.approx(
        G * 0.1 / (4.0 / 3.0 * 0.05), rel=1e-14)
    assert initial_angular_acceleration(W, H, -2 * A_ON, G) < 0.0
    assert initial_angular_acceleration(W, H, 0.5 * A_ON, G) == 0.0


def test_base_acceleration_validated_by_name():
    with pytest.raises(InputError, match="`base_acceleration`"):
        rocking_block_built(base_acceleration=math.nan)


@pytest.mark.parametrize("method", ["event-driven-generic", "moreau-jean"])
def test_below_onset_the_block_stays_put(method):
    sc = _block(0.95)
    q0, v0 = sc.initial_state()
    opts = {"h": 1e-2} if method == "moreau-jean" else {}
    res = simulate(sc, (0.0, 0.5), q0, v0, method, **opts)
    assert res.status == 0
    assert np.max(np.abs(res.q[:, 2])) < 1e-14
    assert np.max(np.abs(res.q - q0)) < 1e-14


def test_above_onset_the_reference_rocks_at_the_closed_forms_rate():
    sc = _block(1.05)
    q0, v0 = sc.initial_state()
    ref = GenericEventDriven(sc, 0.0, q0, v0, 1.0)
    # the reference's start: pivot corner sticking, the other corner lifting
    assert ref.ms.letters(ref.mode) == "SF"
    a = ref.ms.solve(0.0, q0, v0, ref.mode)[0]
    exact = initial_angular_acceleration(W, H, 1.05 * A_ON, G) * sc.time ** 2
    assert a[2] == pytest.approx(exact, rel=1e-8)
    # and it rocks: the tilt's growth at small t is theta''(0+) t^2 / 2
    res = simulate(sc, (0.0, 0.01), q0, v0, "event-driven-generic")
    assert res.q[-1, 2] == pytest.approx(0.5 * exact * 0.01 ** 2, rel=1e-3)
    # Moreau-Jean rocks too
    mj = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=1e-2)
    assert mj.q[-1, 2] == pytest.approx(simulate(sc, (0.0, 1.0), q0, v0,
                                                  "event-driven-generic").q[-1, 2], rel=2e-2)


def test_moreau_jeans_threshold_is_the_onset():
    h = 1e-2

    def rocks(ratio):
        sc = _block(ratio)
        q0, v0 = sc.initial_state()
        return simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=h).q[-1, 2] > 1e-12

    lo, hi = 0.5, 1.5
    assert not rocks(lo) and rocks(hi)
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if rocks(mid) else (mid, hi)
    assert abs(0.5 * (lo + hi) - 1.0) <= h


@pytest.mark.slow
def test_floor_frame_is_the_moving_floor():
    # the same block with the floor a driven body (ground frame): same tilt, x shifted by A t^2/2
    built = _block(1.05)
    moving = rocking_block_model(width=W, height=H, gravity=G, tilt=0.0,
                                 base_acceleration=1.05 * A_ON, moving_floor=True).build()
    t = np.linspace(0.0, 1.0, 5)
    r1 = simulate(built, (0.0, 1.0), *built.initial_state(), "event-driven-generic", t_eval=t)
    r2 = simulate(moving, (0.0, 1.0), *moving.initial_state(), "event-driven-generic", t_eval=t)
    shift = 0.5 * 1.05 * A_ON * (t * built.time) ** 2 / built.length
    assert np.allclose(r2.q[:, 2], r1.q[:, 2], rtol=1e-9, atol=1e-13)
    assert np.allclose(r2.q[:, 0] - shift, r1.q[:, 0], rtol=1e-9, atol=1e-13)
