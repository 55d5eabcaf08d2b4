"""The slider-crank with a revolute clearance joint (Flores and Ambrósio 2004): limits and regimes."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.slider_crank import slider_kinematics
from moreau.scenes.slider_crank_clearance import slider_crank_clearance

R = 0.05 / 0.12                    # r / l at the defaults, in the scene's units (l = 1)


def _slider_error(clearance, n, window):
    sc = slider_crank_clearance(clearance=clearance)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, window), q0, v0, "moreau-jean", h=window / n, theta=0.5)
    assert res.status == 0, res.message
    x, dx, _ = slider_kinematics(res.t, R, 1.0)
    return float(np.max(np.abs(res.q[:, 3] - x))), float(np.max(np.abs(res.v[:, 3] - dx)))


def test_as_the_clearance_closes_the_slider_tends_to_the_ideal_closed_form_at_order_one():
    # clearance c = 0.4, 0.2, 0.1 mm with h proportional to c (50, 100, 200 steps over an
    # eighth of a turn): the slider's position differs from x = r cos + sqrt(l^2 - r^2 sin^2)
    # by about c (the rod is l + c long while the pin bears on the far wall). Measured
    # (scene units, l = 1): position 3.87e-3, 1.89e-3, 9.50e-4 (1.16 c, 1.13 c, 1.14 c; order
    # 1.04, 0.99), velocity order 1.00, 1.00
    window = 0.25 * math.pi
    runs = [_slider_error(c, n, window) for c, n in ((4e-4, 50), (2e-4, 100), (1e-4, 200))]
    for k in range(2):
        for what in range(2):
            rate = math.log2(runs[k][what] / runs[k + 1][what])
            assert abs(rate - 1.0) < 0.1, (k, what, runs)
    for (pos, _), c in zip(runs, (4e-4, 2e-4, 1e-4)):
        assert 1.0 < pos / (c / 0.12) < 1.3


@pytest.fixture(scope="module")
def half_turn():
    # Flores and Ambrosio's defaults (5000 rpm, c = 0.5 mm, e = 0.9, frictionless), half
    # a crank turn in 500 steps of Moreau-Jean (theta = 1)
    sc = slider_crank_clearance()
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, math.pi), q0, v0, "moreau-jean", h=math.pi / 500, theta=1.0)
    assert res.status == 0, res.message
    return sc, res


def test_the_contact_regimes_continuous_contact_free_flight_and_impact(half_turn):
    sc, res = half_turn
    c = 5e-4 / 0.12
    deg = np.degrees(res.t)
    closed = res.force_N[:, 0] > 0.0
    normal = np.array([sc.contact_frames(q, t)[0, 2:4] for q, t in zip(res.q, res.t)])
    turn = np.degrees(np.unwrap(np.arctan2(normal[:, 1], normal[:, 0])))
    # the ideal slider's acceleration changes sign at 70.2 degrees (closed form): the joint's
    # force turns round, and the pin, kept on the wall, slides round the bearing (measured:
    # contact at every sample from the first step to 101.9 degrees, the normal turned by 262
    # degrees)
    _, _, ddx = slider_kinematics(res.t, R, 1.0)
    assert 70.0 < deg[np.flatnonzero(np.diff(np.sign(ddx)))[0] + 1] < 70.5
    # (the first step needs no force: the rod's free motion leaves the wall at rest)
    first = np.flatnonzero(~closed[2:])[0] + 2
    assert closed[2:first].all() and 95.0 < deg[first] < 110.0
    assert abs(turn[first - 1] - turn[2]) > 180.0
    # free flight: no force over several samples, the gap opens (measured 102.2 to 106.9
    # degrees, 14 samples, the gap up to 8e-4 c)
    back = first + np.flatnonzero(closed[first:])[0]
    assert back - first >= 5 and deg[back] < 115.0
    assert np.max(res.gap[first:back, 0]) > 0.0
    # impact: the pin comes back onto the wall (normal velocity < 0 before the step) and
    # continuous contact follows to the half turn (measured 107.3 to 180 degrees)
    WN, wN, _, _ = sc.contact_jacobians(res.q[back - 1], res.t[back - 1])
    assert (WN @ res.v[back - 1] + wN)[0] < 0.0
    assert closed[back:].all()
    # the pin stays within the clearance to the scheme's accuracy (measured 2.8e-2 c)
    assert np.min(res.gap[:, 0]) > -0.05 * c


def test_the_slider_acceleration_follows_the_ideal_then_oscillates_with_peaks(half_turn):
    sc, res = half_turn
    deg = np.degrees(res.t)
    _, dx, ddx = slider_kinematics(res.t, R, 1.0)
    acc = np.diff(res.v[:, 3]) / np.diff(res.t)
    ideal = 0.5 * (ddx[1:] + ddx[:-1])
    peak = np.max(np.abs(ddx))                               # r w^2 (1 + r / l) = 0.590
    # with the pin pulled against the wall (5 to 60 degrees) the acceleration is the ideal
    # one's (measured within 0.026 = 4.4 % of the peak)
    pulled = (deg[1:] > 5.0) & (deg[1:] < 60.0)
    assert np.max(np.abs(acc[pulled] - ideal[pulled])) < 0.06 * peak
    # after the flight the pin oscillates round the bearing: the acceleration swings about
    # the ideal with peaks of 2.75 times its maximum (measured 1.62), the character of
    # Flores and Ambrosio's figures, while the slider's velocity stays within 0.0254 of the
    # ideal (5.6 % of its peak 0.452)
    assert np.max(np.abs(acc)) > 2.0 * peak
    assert np.max(np.abs(res.v[:, 3] - dx)) < 0.1 * np.max(np.abs(dx))
    # over each 20 degrees of the oscillating part the velocity's change is the ideal one's
    for a in range(110, 170, 20):
        i, j = np.searchsorted(deg, [a, a + 20])
        assert abs((res.v[j, 3] - res.v[i, 3]) - (dx[j] - dx[i])) < 0.01, a


def test_bad_parameters_and_schemes_without_joints_are_refused_by_name():
    with pytest.raises(InputError, match=r"`clearance` must be finite and > 0"):
        slider_crank_clearance(clearance=0.0)
    with pytest.raises(InputError, match=r"`clearance` \(0.05\) must be less than a tenth"):
        slider_crank_clearance(clearance=0.05)
    sc = slider_crank_clearance()
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match="scheme 'schatzman-paoli' solves no joints"):
        simulate(sc, (0.0, 1.0), q0, v0, "schatzman-paoli", h=0.01)
