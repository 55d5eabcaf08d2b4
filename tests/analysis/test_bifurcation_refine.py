"""Bifurcation marks located by root finding between grid neighbours (refine_mark)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from periodic_scenes import TableBall

from moreau.analysis.bifurcation import _merge_marks, flip_scalar, fold_scalar, refine_mark
from moreau.analysis.periodic_shooting import shoot_periodic
from moreau.errors import ConvergenceError


def _orbit(multipliers, mode="NP", min_normal_force=math.nan):
    return SimpleNamespace(floquet_multipliers=np.asarray(multipliers, complex), mode=mode,
                           min_normal_force=min_normal_force)


def test_an_orbit_that_ends_by_lifting_off_is_a_grazing_not_a_saddle_node():
    # issue 34: at 12612.7 Hz (e = 1) the orbit's minimum normal force was 6.6e-8 N and its
    # multiplier 0.99966 when it ended; bisection on its existence was called a saddle-node,
    # and the grazing mark of the same interval stayed at the midpoint, 300 Hz off.
    # Here N_min = 0.7 - p reaches 0 at p = 0.7 with the multiplier at 0.9997 throughout
    def orbit_at(p):
        if p > 0.7:
            raise ConvergenceError("no period-1 orbit")
        return _orbit([0.9997, 0.2], "NP", min_normal_force=0.7 - p)
    m = refine_mark({"kind": "period change", "between": [0.5, 0.9], "at": 0.7, "from": 1,
                     "to": 0}, orbit_at)
    assert m["kind"] == "grazing" and m["mechanism"].startswith("lift-off")
    assert m["bracket"][0] <= 0.7 <= m["bracket"][1] and m["at"] == pytest.approx(0.7, abs=1e-6)
    assert "largest real multiplier 0.9997" in m["refined"]
    g = refine_mark({"kind": "grazing", "between": [0.5, 0.9], "at": 0.7, "from": "contact",
                     "to": "flight"}, orbit_at)
    assert g["kind"] == "grazing" and g["bracket"] == m["bracket"]
    # the diagram keeps one mark for the one event
    (one,) = _merge_marks([m, g])
    assert one["from"] == 1 and one["also"] == [{"from": "contact", "to": "flight"}]
    # an orbit that ends with neither quantity at its critical value is not named either
    n = refine_mark({"kind": "period change", "between": [0.5, 0.9], "at": 0.7, "from": 1,
                     "to": 0}, lambda p: orbit_at(p) if p <= 0.6 else orbit_at(1.0))
    assert n["kind"] == "period change" and n["mechanism"] == "not identified"


def test_saddle_node_told_apart_and_located():
    # a fold at p = 0.3: the orbit exists below it, its multiplier 1 - sqrt(0.3 - p) -> +1
    def orbit_at(p):
        if p > 0.3:
            raise ConvergenceError("no orbit")
        return _orbit([1.0 - math.sqrt(0.3 - p), 0.1])
    m = refine_mark({"kind": "period change", "between": [0.2, 0.4], "at": 0.3, "from": 1,
                     "to": 0}, orbit_at)
    assert m["kind"] == "saddle-node" and m["at"] == pytest.approx(0.3, abs=1e-6)
    assert "existence" in m["refined"]


def test_flip_located_on_lambda_plus_one_and_grazing_by_bisection():
    # lambda = -0.5 - 2 p crosses -1 at p = 0.25 exactly
    m = refine_mark({"kind": "period change", "between": [0.0, 1.0], "at": 0.5, "from": 1,
                     "to": 2}, lambda p: _orbit([-0.5 - 2.0 * p, 0.2]))
    assert m["kind"] == "period doubling" and m["at"] == pytest.approx(0.25, abs=1e-9)
    g = refine_mark({"kind": "grazing", "between": [1.0, 2.0], "at": 1.5},
                    lambda p: _orbit([0.5], "NPF" if p > 1.7 else "NP"))
    assert g["at"] == pytest.approx(1.7, abs=2e-6) and g["bracket"][0] <= 1.7 <= g["bracket"][1]
    # no crossing at +-1 between the neighbours: the midpoint stays, and says why
    k = refine_mark({"kind": "period change", "between": [0.0, 1.0], "at": 0.5},
                    lambda p: _orbit([0.5 + 0.1j, 0.5 - 0.1j]))
    assert k["at"] == 0.5 and k["refined"].startswith("midpoint")
    assert math.isnan(flip_scalar(_orbit([0.5]))) and fold_scalar(_orbit([0.5])) == -0.5


@pytest.mark.slow
def test_table_ball_flip_at_its_closed_form():
    # the period-1 orbit of the table ball (one impact a period) flips at
    # Gamma_c^2 = (pi (1 - e) / (1 + e))^2 + (2 (1 + e^2) / (1 + e)^2)^2, 1.52682370 for
    # e = 1/2; shot by the generic event-driven scheme, its multiplier + 1 is followed
    # between neighbours of a grid 0.01 apart. Measured: 5.6e-11 off with a bracket of
    # 1.5e-6 of [1.45, 1.6] (8 shootings, 60 s); here a bracket of 1e-3 of the interval
    e = 0.5
    exact = math.sqrt((math.pi * (1 - e) / (1 + e)) ** 2 + (2 * (1 + e * e) / (1 + e) ** 2) ** 2)

    def orbit_at(gamma):
        sc = TableBall(gamma=gamma, e=e)
        theta = math.acos(math.pi * 0.5 / (1.5 * gamma))
        return shoot_periodic(sc, "event-driven-generic", section_tau=theta + math.pi,
                              q0=np.array([math.sin(theta) + sc.g * math.pi ** 2 / 2, 0.0]),
                              v0=np.zeros(2))
    m = refine_mark({"kind": "period doubling", "between": [1.52, 1.53], "at": 1.525},
                    orbit_at, xtol=1e-3)
    assert m["kind"] == "period doubling"
    assert m["bracket"][0] - 1e-12 <= exact <= m["bracket"][1] + 1e-12
    assert abs(m["at"] - exact) < 1e-5


def test_a_walk_stalled_at_a_grazing_touchdown_says_so(monkeypatch):
    # at 12612.72 Hz, e = 1 (just past the lift-off above) the walk stalled with 1001
    # touchdowns F -> F at one time and only said "an accumulation of events"
    from moreau.integrators.result import Event
    from moreau.regimes import Regime
    from moreau.scenes import make_scene
    from moreau.scenes.friction_drive.walker import ContactState, FrictionDriveWalker
    from moreau.errors import MoreauError
    sc = make_scene("friction-drive", frequency=185.0)
    q0, v0 = sc.rest_state()
    real = FrictionDriveWalker.segment

    def grazing(self, st, tau_end, on_segment=None):
        if st.tau > 1.0:
            out = st.copy()
            out.regime = Regime.FLIGHT
            return out, Event(st.tau, "touchdown", Regime.FLIGHT, Regime.FLIGHT)
        return real(self, st, tau_end, on_segment)

    monkeypatch.setattr(FrictionDriveWalker, "segment", grazing)
    w = FrictionDriveWalker(sc)
    st = w.classify(ContactState(0.0, Regime.FLIGHT, q0[0], v0[0], q0[1], v0[1]))
    with pytest.raises(MoreauError, match="makes no progress: 1001 events in a row .* a grazing "
                                          "contact: the rod meets the rotor with no normal "
                                          "velocity and no normal force"):
        w.advance(st, 2 * np.pi)


def test_the_walk_at_the_measured_lift_off_names_the_grazing():
    from moreau.analysis.steady_state import find_steady_state
    from moreau.errors import MoreauError
    from moreau.scenes.friction_drive import FrictionDrive
    with pytest.raises(MoreauError, match="a grazing contact"):
        find_steady_state(FrictionDrive(frequency=12612.72, restitution=1.0), statistical=False)
