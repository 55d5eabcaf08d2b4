"""Moreau–Jean's Baumgarte option on the joints (module docstring of moreau_jean, *Baumgarte*).

With ``joint_baumgarte = alpha`` the joint rows hold ``G v + w = -(alpha / h)
gE(q_k, t_k)``: the drift obeys ``phi_{k+1} = (1 - alpha) phi_k + r_k`` with
``r_k`` the step's local error, so it stays bounded by ``max |r| / alpha``
instead of accumulating, and an initial drift decays by ``1 - alpha`` a step.
"""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.slider_crank import slider_crank, slider_kinematics

TURN = 2.0 * math.pi      # the crank's period in the scene's time


def _run(n, alpha, turns=10):
    """The largest drift in the first turn, over ``turns`` turns, and the slider's error."""
    sc = slider_crank()
    q0, v0 = sc.initial_state()
    out = []
    for span in (1, turns):
        res = simulate(sc, (0.0, span * TURN), q0, v0, "moreau-jean", h=TURN / n,
                       joint_baumgarte=alpha)
        assert res.status == 0, res.message
        out.append(res.constraint_drift)
    x, _, _ = slider_kinematics(res.t, 0.25, 1.0)
    return out[0], out[1], float(np.max(np.abs(res.q[:, 3] - x)))


def test_the_drift_is_bounded_by_the_local_error_and_no_longer_grows():
    # theta = 1, n steps a turn; measured (largest drift in the first turn, in ten):
    # alpha = 0: 1.56e-2, 3.64e-2 (n = 100), 7.8e-3, 1.8e-2 (200): it grows, order 1;
    # alpha = 1: 5.55e-4 in both (100), 1.39e-4 (200): one step's O(h^2)
    free100 = _run(100, 0.0)
    free200 = _run(200, 0.0)
    bg100 = _run(100, 1.0)
    bg200 = _run(200, 1.0)
    for one, ten, _ in (free100, free200):
        assert ten > 2.0 * one
    for one, ten, _ in (bg100, bg200):
        assert ten <= 1.01 * one
    assert abs(math.log2(free100[1] / free200[1]) - 1.0) < 0.1
    assert abs(math.log2(bg100[1] / bg200[1]) - 2.0) < 0.1
    assert bg100[1] < 0.05 * free100[1]
    # the slider follows the closed form closer (measured 6.3e-2 without, 6.2e-4 with)
    assert bg100[2] < 0.02 * free100[2]
    # half the alpha, twice the bound (measured 1.10e-3 at 0.5: 1.99 x)
    assert 1.9 <= _run(100, 0.5, turns=2)[1] / bg100[1] <= 2.0


@pytest.mark.parametrize("theta, rows, tol", [(1.0, "end", 5e-6), (0.5, "theta", 1e-9),
                                             (0.5, "end", 1e-9)])
def test_an_initial_drift_decays_as_derived(theta, rows, tol):
    # the slider put 1e-3 off its joints at the start (h = turn / 2000, alpha = 0.5): the
    # residual follows c_{k+1} = (1 - alpha) c_k ("theta" rows, and theta = 1), or on the
    # "end" rows c_{k+1} = c_k - alpha (theta c_k + (1 - theta) c_{k-1}) with c_{-1} = 0
    # (the start's velocity is on the joints), times its start; without it, it stays.
    # Measured off the recursion: 2.5e-6 (theta = 1: the O(h^2) local error, 1.4e-6 a
    # step), 1.5e-11 and 4e-11 (theta = 1/2: O(h^3))
    sc = slider_crank()
    q0, v0 = sc.initial_state()
    q0 = q0.copy()
    q0[3] += 1e-3
    g0 = float(np.max(np.abs(sc.joint_residuals(q0, 0.0))))
    h = TURN / 2000
    alpha = 0.5
    c = [1.0]
    prev = 0.0
    for _ in range(12):
        if rows == "theta" or theta == 1.0:
            nxt = (1.0 - alpha) * c[-1]
        else:
            nxt = c[-1] - alpha * (theta * c[-1] + (1.0 - theta) * prev)
        prev = c[-1]
        c.append(nxt)
    for a in (0.0, alpha):
        res = simulate(sc, (0.0, 12 * h), q0, v0, "moreau-jean", h=h, theta=theta,
                       joint_rows=rows, joint_baumgarte=a)
        assert res.status == 0, res.message
        g = np.array([np.max(np.abs(sc.joint_residuals(q, t))) for t, q in zip(res.t, res.q)])
        if a == 0.0:
            assert np.all(np.abs(g - g0) <= 1e-5)
        else:
            assert np.all(np.abs(g - np.abs(c) * g0) <= tol)


def test_the_option_is_checked_by_name():
    sc = slider_crank()
    q0, v0 = sc.initial_state()
    with pytest.raises(InputError, match=r"`joint_baumgarte` must be in \[0.0, 1.0\]"):
        simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.1, joint_baumgarte=1.5)
    from moreau.scenes.bouncing_ball import BouncingBall
    ball = BouncingBall()
    qb, vb = ball.initial_state()
    with pytest.raises(InputError, match="`joint_baumgarte` corrects the joints' drift"):
        simulate(ball, (0.0, 1.0), qb, vb, "moreau-jean", h=0.1, joint_baumgarte=0.5)
