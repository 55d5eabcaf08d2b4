"""The ball chain: closed forms, the two impact pictures, and what each scheme gives."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.ball_chain import (BallChain, sequential_impacts, simultaneous_impact,
                                      two_ball_impact)


def _after(chain, scheme, **options):
    if scheme in ("moreau-jean", "schatzman-paoli"):
        # a few hundred steps: the generic step, no compile of a loop per chain length
        options.setdefault("fast", False)
    q0, v0 = chain.initial_state()
    r = simulate(chain, (0.0, chain.impact_time + 2.0), q0, v0, scheme, **options)
    assert r.success, r.message
    return r


@pytest.mark.parametrize("e, ratio", [(1.0, 1.0), (0.5, 1.0), (0.0, 1.0), (0.8, 3.0)])
def test_two_balls_every_scheme_gives_the_closed_form(e, ratio):
    chain = BallChain(n_balls=2, restitution=e, striker_mass=0.1 * ratio)
    exact = two_ball_impact(ratio, 1.0, 1.0, e)
    # momentum m0 V and Newton's law v1 - v0 = e V, derived by hand:
    assert exact[0] * ratio + exact[1] == pytest.approx(ratio)
    assert exact[1] - exact[0] == pytest.approx(e)
    for scheme, opts in [("moreau-jean", {"h": 0.01}), ("schatzman-paoli", {"h": 0.01}),
                         ("event-driven", {})]:
        assert _after(chain, scheme, **opts).v[-1] == pytest.approx(exact, abs=1e-12), scheme


def test_newtons_cradle_sequential_against_simultaneous():
    m = np.ones(3)
    assert sequential_impacts(m, [1.0, 0.0, 0.0], 1.0) == pytest.approx([0.0, 0.0, 1.0])
    # simultaneous Newton impacts, solved by hand: 2 p1 - p2 = 2, 2 p2 - p1 = 0
    assert simultaneous_impact(m, [1.0, 0.0, 0.0], 1.0) == pytest.approx([-1 / 3, 2 / 3, 2 / 3])
    # e = 0: one block
    assert simultaneous_impact(m, [1.0, 0.0, 0.0], 0.0) == pytest.approx([1 / 3] * 3)


@pytest.mark.parametrize("n", [3, 10])
def test_time_stepping_and_the_reference_move_the_chain_as_a_block(n):
    # Newton's law at every contact at once: the striker rebounds at (2 - n) / n and the
    # rest of the chain leaves together at 2 / n, with the kinetic energy kept (e = 1)
    chain = BallChain(n_balls=n, restitution=1.0)
    block = np.full(n, 2.0 / n)
    block[0] = (2.0 - n) / n
    assert simultaneous_impact(chain.masses, chain.initial_state()[1], 1.0) == pytest.approx(block)
    for scheme, opts in [("moreau-jean", {"h": 0.01}), ("schatzman-paoli", {"h": 0.01}),
                         ("event-driven", {})]:
        r = _after(chain, scheme, **opts)
        assert r.v[-1] == pytest.approx(block, abs=1e-12), scheme
        assert chain.kinetic_energy(r.v[-1]) == pytest.approx(0.5, rel=1e-12)
        assert chain.masses @ r.v[-1] == pytest.approx(1.0, rel=1e-14)
    # the sequential picture sends the whole speed to the last ball instead
    seq = sequential_impacts(chain.masses, chain.initial_state()[1], 1.0)
    assert seq == pytest.approx(np.eye(n)[-1])


def test_a_compliant_contact_carries_a_wave_down_the_chain():
    # springs between the balls let the impacts happen one after another: the last ball
    # takes most of the speed (measured 0.878 at stiffness 1e4 for n = 10), far from the
    # rigid block's 0.2 and short of the sequential picture's 1
    chain = BallChain(n_balls=10, restitution=1.0)
    r = _after(chain, "compliant-rk45", stiffness=1e4)
    assert 0.8 < r.v[-1, -1] < 0.95
    assert chain.masses @ r.v[-1] == pytest.approx(1.0, rel=1e-9)


def test_moreau_jean_places_the_impact_to_first_order():
    chain = BallChain(n_balls=3, restitution=1.0, striker_gap=0.0123)
    q0, v0 = chain.initial_state()
    ts = chain.impact_time
    exact = q0[-1] + 2 / 3 * 2.0          # two time units after the impact at 2/3
    errs = []
    hs = [0.3 / 2**k for k in range(5)]
    for h in hs:
        r = simulate(chain, (0.0, ts + 2.0), q0, v0, "moreau-jean", h=h, fast=False)
        errs.append(abs(r.q[-1, -1] - exact))
    assert max(errs) <= 2 / 3 * max(hs) and max(errs) > 0
    assert math.isfinite(np.polyfit(np.log(hs), np.log(np.maximum(errs, 1e-16)), 1)[0])


def test_the_compiled_loop_runs_a_long_chain_like_the_generic_step():
    chain = BallChain(n_balls=10, restitution=0.5)
    fast = _after(chain, "moreau-jean", h=0.01, fast=True)
    slow = _after(chain, "moreau-jean", h=0.01, fast=False)
    assert np.max(np.abs(fast.q - slow.q)) < 1e-12 and np.max(np.abs(fast.v - slow.v)) < 1e-12


@pytest.mark.parametrize("params, name", [
    ({"n_balls": 1}, "n_balls"), ({"n_balls": 101}, "n_balls"), ({"n_balls": 2.5}, "n_balls"),
    ({"n_balls": True}, "n_balls"), ({"mass": -1.0}, "mass"), ({"restitution": 1.5}, "restitution"),
    ({"striker_speed": math.nan}, "striker_speed"), ({"striker_gap": -1e-3}, "striker_gap"),
])
def test_bad_parameters_are_refused_by_name(params, name):
    with pytest.raises(InputError, match=f"`{name}`"):
        BallChain(**params)


def test_si_units_come_back():
    chain = BallChain(n_balls=2, radius=0.02, striker_speed=2.0, mass=0.5)
    assert chain.time == pytest.approx(0.01) and chain.force == pytest.approx(0.5 * 4 / 0.02)
    assert chain.velocity_to_si(1.0) == pytest.approx(2.0)
