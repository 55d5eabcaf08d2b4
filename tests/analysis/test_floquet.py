"""Floquet multipliers of periodic steady states, and period-k orbits (issue 20, items 1-2)."""

import json
import math

import numpy as np
import pytest

from moreau.analysis.floquet import period_map_jacobian, sorted_multipliers, stability
from moreau.analysis.period_k import minimal_period
from moreau.analysis.periodic_shooting import shoot_periodic
from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.errors import InputError
from moreau.scenes.friction_drive import FrictionDrive
from moreau.scenes.friction_drive.floquet import walker_monodromy, walker_period_map_slope

from periodic_scenes import DampedOscillator, TableBall


@pytest.mark.parametrize("frequency, mode, expected", [
    # saltation multipliers measured on this branch (the FD check below is the test)
    (20.0, "NS", 0.0),                   # stick wipes out any change of u2'
    (185.0, "NP", 0.0513784),
    (2000.0, "NP", 0.9870025),           # barely contracting: the 2 kHz remark
    (15000.0, "NF!P", 0.9996600),        # flight and a plastic impact in the period
])
def test_saltation_multiplier_agrees_with_differences_of_the_period_map(frequency, mode,
                                                                       expected):
    sc = FrictionDrive(frequency=frequency)
    ss = find_steady_state(sc)
    assert ss.mode == mode and ss.floquet_method == "saltation"
    m = walker_monodromy(sc, ss)
    assert m.shape == (1, 1)
    assert abs(m[0, 0] - walker_period_map_slope(sc, ss)) < 1e-6
    assert ss.floquet_multipliers[0].real == pytest.approx(expected, abs=1e-6)
    assert ss.stable and ss.stability_margin == pytest.approx(1.0 - abs(m[0, 0]), abs=1e-15)


def test_generic_shooting_multipliers_agree_with_the_walker():
    sc = FrictionDrive(frequency=2000.0)
    walker = find_steady_state(sc).floquet_multipliers
    generic = find_steady_state(sc, "event-driven-generic").floquet_multipliers
    assert generic.shape == (1,) and abs(generic[0] - walker[0]) < 1e-6


def test_damped_oscillator_multipliers_are_exact():
    sc = DampedOscillator(w0=1.3, zeta=0.1, c=0.2)
    ss = shoot_periodic(sc, "event-driven-generic")
    exact = sorted_multipliers(sc.multipliers())
    assert ss.floquet_multipliers.shape == (3,)
    assert np.max(np.abs(ss.floquet_multipliers - exact)) < 1e-7
    assert ss.stable and ss.stability_margin == pytest.approx(1.0 - abs(exact[0]), abs=1e-7)


@pytest.mark.parametrize("frequency, coarse, fine", [(2000.0, 1000, 64000), (185.0, 1000, 16000)])
def test_moreau_jean_multiplier_approaches_the_reference(frequency, coarse, fine):
    sc = FrictionDrive(frequency=frequency)
    ref = find_steady_state(sc).floquet_multipliers[0].real
    err = {n: abs(find_steady_state(sc, "moreau-jean", steps_per_period=n)
                  .floquet_multipliers[0] - ref) for n in (coarse, fine)}
    # measured: 1.8e-4 -> 5.8e-6 at 2 kHz, 6.0e-4 -> 3.4e-4 at 185 Hz (the discrete map's
    # event quantisation makes the decrease irregular)
    assert err[fine] < 0.6 * err[coarse]
    assert err[fine] < 1e-2 * abs(ref)


def test_table_ball_period_doubling():
    # Gamma = 1.6 is past the flip of the period-1 orbit (1.527 for e = 1/2)
    sc = TableBall(gamma=1.6, e=0.5)
    theta = math.acos(math.pi * 0.5 / (1.5 * 1.6))      # impact phase of the period-1 orbit
    start = dict(section_tau=theta + math.pi, q0=np.array([math.sin(theta) + sc.g * math.pi ** 2 / 2,
                                                          0.0]), v0=np.zeros(2))
    one = shoot_periodic(sc, "event-driven-generic", **start)
    assert one.period == 1 and not one.stable
    assert one.floquet_multipliers[0].real < -1.0           # a flip
    ss = find_steady_state(sc, "event-driven-generic", max_period=8, **start)
    assert ss.period == 2 and ss.stable
    assert minimal_period(sc, "event-driven-generic", ss) == 2
    # the second iterate returns to itself, the first does not
    again = shoot_periodic(sc, "event-driven-generic", section_tau=ss.section_tau,
                           q0=ss.state0[:2], v0=ss.state0[2:], periods=2, max_iter=1)
    assert again.iterations == 0
    assert abs(ss.state0[0] - one.state0[0]) > 0.1


def test_max_period_is_checked_before_work():
    with pytest.raises(InputError, match=r"`max_period` must be at most 8, got 9"):
        find_steady_state(FrictionDrive(frequency=185.0), max_period=9)


def test_steady_json_has_the_multipliers(capsys):
    assert main(["steady", "--frequency", "2000", "--json"]) in (0, None)
    rep = json.loads(capsys.readouterr().out)
    assert rep["period"] == 1 and rep["floquet_method"] == "saltation"
    (re, im), = rep["floquet_multipliers"]
    assert re == pytest.approx(0.9870025, abs=1e-6) and im == 0.0
    assert rep["stable"] is True and rep["stability_margin"] == pytest.approx(1 - re, abs=1e-12)
    assert rep["max_multiplier"] == pytest.approx(re, abs=1e-15)


def test_helpers():
    A = np.array([[0.5, 2.0], [0.0, -1.5]])
    J = period_map_jacobian(lambda z: A @ z + z ** 2, np.zeros(2), 1e-4)
    assert np.allclose(J, A, atol=1e-12)
    m = sorted_multipliers(np.linalg.eigvals(A))
    assert m.tolist() == [-1.5, 0.5] and stability(m) == (False, -0.5)
    assert stability([]) == (True, 1.0)
