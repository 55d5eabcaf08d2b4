"""The bidirectional drive in motion: mirror symmetry, steady states, Moreau–Jean cross-check."""

import math

import numpy as np
import pytest

from moreau.analysis.periodic_shooting import shoot_periodic
from moreau.analysis.steady_state import find_steady_state
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes import BidirectionalDrive, BidirectionalDriveParams, BouncingBall, FrictionDrive

TWO_PI = 2.0 * math.pi


def scene(f=185.0, **kw):
    return BidirectionalDrive(BidirectionalDriveParams(**kw), frequency=f)


@pytest.fixture(scope="module")
def steady():
    """The event-driven steady state of ``scene(f, **kw)``, computed once in the module: rod a
    alone at 185 Hz is the reference of four tests, the phase lag of two (1.2-1.5 CPU s each)."""
    memo = {}

    def get(f, **kw):
        key = (f, tuple(sorted(kw.items())))
        if key not in memo:
            memo[key] = find_steady_state(scene(f, **kw))
        return memo[key]
    return get


def run(sc, periods=2):
    q0, v0 = sc.rest_state()
    res = simulate(sc, (0.0, periods * TWO_PI), q0, v0, "event-driven")
    assert res.status == 0, res.message
    return res


def test_mirror_symmetry_of_the_two_rods():
    ra = run(scene(x10_b=0.0))
    rb = run(scene(x10_a=0.0))
    ua, ub = ra.q[-1, 2], rb.q[-1, 2]
    assert ua < 0.0 < ub          # 185 Hz: rod a alone drives the rotor backwards
    assert abs(ua + ub) <= 1e-9 * abs(ua)
    # the unexcited rod stays where its spring holds it, without force
    assert np.all(ra.force_N[:, 1] == 0.0) and ra.q[-1, 1] == pytest.approx(math.pi / 4, abs=1e-14)


def test_rod_a_alone_is_the_single_rod_drive():
    sc = scene(x10_b=0.0)
    res = run(sc)
    single = FrictionDrive(sc.params.rod("a"), frequency=185.0)
    ref = simulate(single, (0.0, 2 * TWO_PI), *single.rest_state(), "friction-drive-walker")
    assert abs(res.q[-1, 2] - ref.q[-1, 1]) <= 1e-9 * abs(ref.q[-1, 1])


def test_equal_excitation_in_phase_gives_no_net_motion():
    res = run(scene())
    assert np.max(np.abs(res.q[:, 2])) <= 1e-12
    # and the two contacts slip in opposite directions at every sample
    assert np.all(res.regime[:, 0] + res.regime[:, 1] == 3)


@pytest.mark.parametrize("f", [185.0, 2000.0])
def test_steady_state_of_rod_a_alone_matches_the_walker(f, steady):
    ss = steady(f, x10_b=0.0)
    ref = find_steady_state(FrictionDrive(frequency=f), rtol=1e-12)
    assert abs(ss.displacement_per_period - ref.displacement_per_period) <= \
        1e-8 * abs(ref.displacement_per_period)
    assert ss.mode.split("|") == [ref.mode, "F"]


def test_steady_state_mirror_and_phase_control(steady):
    a = steady(185.0, x10_b=0.0)
    b = steady(185.0, x10_a=0.0)
    assert abs(a.displacement_per_period + b.displacement_per_period) <= \
        1e-9 * abs(a.displacement_per_period)
    # a phase lag of stator b changes the net motion: no longer zero
    p = steady(185.0, phase=1.0)
    assert abs(p.displacement_per_period) > 1e-2 * abs(a.displacement_per_period)


def test_moreau_jean_agrees_with_the_event_driven_reference(steady):
    sc = scene(x10_b=0.0)
    ed = steady(185.0, x10_b=0.0)
    mj = find_steady_state(sc, "moreau-jean", steps_per_period=2000, theta=0.5)
    rel = abs(mj.displacement_per_period / ed.displacement_per_period - 1.0)
    assert rel <= 1e-3          # measured 2.0e-4


def test_shooting_needs_a_cyclic_coordinate():
    with pytest.raises(InputError, match="`cyclic`"):
        shoot_periodic(BouncingBall(), "event-driven")


@pytest.mark.parametrize("kw", [{"phase": 1.0}, {"x10_b": 1e-6}, {"x10_b": 0.0}])
def test_moreau_jean_names_every_contact_like_the_reference(kw, steady):
    # both rods' regimes, in the same canonical form as the event-driven shooting
    sc = BidirectionalDrive(BidirectionalDriveParams(**kw), frequency=185.0)
    ed = steady(185.0, **kw)
    mj = find_steady_state(sc, "moreau-jean", steps_per_period=2000)
    assert mj.mode == ed.mode and mj.mode.count("|") == 1
    assert all(len(key) == 2 for _, key in mj.regimes)
    assert mj.min_normal_force >= 0.0
