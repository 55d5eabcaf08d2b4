"""The rocking block: Housner's impacts accumulating on two frictional corners, settling flat.

Before: Moreau-Jean with theta = 1/2 stopped at the first impacts (t = 0.95 to 2.0)
on the discrete Painlevé condition (a pivot corner in stick with a slip of rounding
size), theta = 1 at h = 1e-5 and 1e-6 at the settling (t = 3.08); the event-driven
reference ran into `max_impacts`.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from moreau.integrators import simulate
from moreau.integrators.event_driven_generic import GenericEventDriven
from moreau.lcp import build_friction_lcp, friction_impulses, solve_lcp
from moreau.scenes.rocking_block import RockingBlock, housner_ratio

R = 0.7          # 1 - 3/2 sin^2(atan(1/2))


@pytest.fixture(scope="module")
def block():
    return RockingBlock()


def test_housner_ratio_is_the_impact_laws_answer(block):
    # independent: the velocity-level impact problem of both corners at theta = 0, turning
    # about the left corner at w = -1, through the scene's Jacobians and the friction LCP
    assert housner_ratio(block.alpha) == pytest.approx(R, abs=1e-15)
    q, v = block.state_on_corner(0.0, -1.0)
    WN, wN, WT, wT = block.contact_jacobians(q, 0.0)
    J = np.vstack([WN, WT])
    Minv = np.linalg.inv(block.mass(q))
    W = J @ Minv @ J.T
    lcp = build_friction_lcp(W, J @ v, block.mu, 0.0, WN @ v)
    p = friction_impulses(solve_lcp(lcp.M, lcp.q).z, lcp.layout, stacked=True)
    v1 = v + Minv @ J.T @ p
    assert v1[2] / v[2] == pytest.approx(R, rel=1e-12)
    assert (WN @ v1)[0] == pytest.approx(2 * block.a * R, rel=1e-12)    # the old corner lifts


def test_phase_time_is_the_pendulums(block):
    # the quadrature against the pendulum about the corner, I_O theta'' = -sin(alpha - theta)
    def fall(_, y):
        return y[0]

    fall.terminal = True
    for th0 in (0.05, 0.3, 1e-4):
        sol = solve_ivp(lambda t, y: [y[1], -0.75 * math.sin(block.alpha - y[0])], (0, 10),
                        [th0, 0.0], events=fall, rtol=1e-12, atol=1e-14)
        assert block.phase_time(th0) == pytest.approx(sol.t_events[0][0], rel=1e-9)


def _impacts(res):
    on = res.regime != 0
    k = np.flatnonzero((on[1:, 0] & ~on[:-1, 0]) | (on[1:, 1] & ~on[:-1, 1])) + 1
    return k


@pytest.mark.parametrize("theta", [1.0, 0.5])
@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_moreau_jean_rocks_down_and_settles_flat(block, h, theta):
    q0, v0 = block.initial_state()
    res = simulate(block, (0.0, 4.0), q0, v0, "moreau-jean", h=h, theta=theta)
    assert res.status == 0
    k = _impacts(res)
    t_exact = block.impact_times(5)
    assert len(k) >= 5
    # the impacts where the exact ones are (the error adds up: measured 0.4 h, 1.2 h,
    # 2.8 h at the first three), and Housner's ratio to O(h) (measured 1.8 h at the
    # first impact to 8.0 h at the fifth, both thetas)
    assert np.max(np.abs(res.t[k[:3]] - t_exact[:3])) <= 5 * h
    ratios = res.v[k[:5], 2] / res.v[k[:5] - 1, 2]
    assert np.max(np.abs(ratios - R)) <= 10 * h
    # decaying amplitude: the largest tilt between successive impacts
    amp = [np.max(np.abs(res.q[a:b, 2])) for a, b in zip(k[:5], k[1:6])]
    assert np.all(np.diff(amp) < 0)
    # flat and at rest on both corners after the Zeno time 3.0907
    end = res.t >= 3.2
    assert np.max(np.abs(res.q[end, 2])) <= 1e-6 and np.max(np.abs(res.v[end])) <= 1e-5
    assert set(res.regime_letters(0)[-10:]) == set(res.regime_letters(1)[-10:]) == {"S"}


@pytest.mark.parametrize("lcp_method", ["lemke"])
def test_moreau_jean_with_lemke_settles_too(block, lcp_method):
    q0, v0 = block.initial_state()
    res = simulate(block, (0.0, 4.0), q0, v0, "moreau-jean", h=1e-4, theta=0.5,
                   lcp_method=lcp_method)
    assert res.status == 0 and abs(res.q[-1, 2]) <= 1e-6


def test_event_driven_settles_at_the_zeno_time(block):
    q0, v0 = block.initial_state()
    integ = GenericEventDriven(block, 0.0, q0, v0, 4.0, zeno_rtol=1e-8, record_pieces=True)
    while integ.status == "running":
        integ.step()
    res = integ.result()
    assert res.status == 0
    t_inf = block.settling_time()
    assert t_inf == pytest.approx(3.0906679331, abs=1e-9)
    (t_acc,) = res.stats["accumulation_times"]
    # the closure cuts the series where the lifting corner leaves below zeno_rtol times its
    # approach speeds: the rest of the Zeno sum, O(zeno_rtol) (measured -7.5e-8)
    assert -10 * 1e-8 * t_inf <= t_acc - t_inf < 0.0
    jumps = [j for j in integ.jumps if j[6] == "impact"]
    n = len(jumps) - 1                      # the last one is the closure
    assert n >= 45
    t_exact = block.impact_times(n)
    # measured: 3e-13 over the first ten, 1.2e-8 at worst in the last ones (the phase
    # time of a tiny amplitude is sensitive to the state at the impact)
    err = np.abs(np.array([j[0] for j in jumps[:n]]) - t_exact)
    assert np.max(err[:10]) <= 1e-12 and np.max(err) <= 3e-8
    # Housner's ratio on every impact of the series (measured 7.8e-16 at worst)
    ratios = np.array([j[3][2] / j[2][2] for j in jumps[:n]])
    assert np.max(np.abs(ratios - R)) <= 1e-12
    assert abs(res.q[-1, 2]) <= 1e-14 and np.max(np.abs(res.v[-1])) <= 1e-14
    assert res.regime_letters(0)[-1] == res.regime_letters(1)[-1] == "S"


@pytest.mark.slow
@pytest.mark.parametrize("lcp_method", ["auto", "lemke"])
@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_moreau_jean_converges_to_housners_ratio_at_first_order(block, theta, lcp_method):
    # the runs the schemes used to stop: theta = 1/2 at its first impacts, h = 1e-5 and
    # 1e-6 at the settling (t = 3.08)
    q0, v0 = block.initial_state()
    errors = []
    for h in (1e-4, 1e-5, 1e-6):
        res = simulate(block, (0.0, 4.0), q0, v0, "moreau-jean", h=h, theta=theta,
                       lcp_method=lcp_method, save_every=1000)
        assert res.status == 0 and abs(res.q[-1, 2]) <= 1e-6
        # every step over the first three impacts
        res = simulate(block, (0.0, 1.9), q0, v0, "moreau-jean", h=h, theta=theta,
                       lcp_method=lcp_method)
        k = _impacts(res)[:3]
        errors.append(np.max(np.abs(res.v[k, 2] / res.v[k - 1, 2] - R)))
    rates = np.log10(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((rates > 0.9) & (rates < 1.1))
