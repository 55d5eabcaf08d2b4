"""The energy audit of a steady period (moreau.analysis.energy)."""

import json
import math
from dataclasses import asdict
from types import SimpleNamespace

import numpy as np
import pytest

from moreau.analysis.energy import (ENERGY_COLUMNS, ENERGY_TERMS, RodEnergy, energy_audit,
                                    energy_to_si)
from moreau.analysis.engine import ED_REFERENCE, Scheme, evaluate_point
from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.bidirectional_drive import BidirectionalDrive
from moreau.scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive

TERMS = [k for k, _ in ENERGY_TERMS]


def _ed(frequency, **params):
    sc = FrictionDrive(frequency=frequency, **params)
    ss = find_steady_state(sc)
    return sc, ss, energy_audit(sc, ss, "event-driven")


def _mj(sc, n, theta=1.0):
    ss = find_steady_state(sc, scheme="moreau-jean", steps_per_period=n, theta=theta)
    return energy_audit(sc, ss, "moreau-jean", {"steps_per_period": n, "theta": theta})


@pytest.mark.parametrize("frequency", [185.0, 2000.0])
def test_reference_audit_closes_to_1e_9(frequency):
    sc, ss, a = _ed(frequency)
    assert abs(a["closing_error"]) < 1e-9
    # no load, no impacts: the stator's work goes to friction, both slip directions (mode NP)
    assert a["load_work"] == 0.0
    assert a["friction_positive_slip"] > 0 and a["friction_negative_slip"] > 0
    assert abs(a["impact_loss"]) < 1e-12 * a["stator_work"]
    # a periodic orbit: the stored energy comes back (to the shooting's accuracy)
    assert abs(a["stored_energy_change"]) < 1e-10 * a["stator_work"]
    assert a["stator_work"] == pytest.approx(
        a["friction_positive_slip"] + a["friction_negative_slip"], rel=1e-9)


def test_reference_audit_with_flight_and_impacts_closes():
    # 2000 Hz, phi0 = 1.40: the rod flies and lands with a plastic impact (mode NF!P)
    sc, ss, a = _ed(2000.0, phi0=1.40)
    assert "F" in ss.mode and "!" in ss.mode
    assert abs(a["closing_error"]) < 1e-9
    assert a["impact_loss"] > 0.5 * a["stator_work"]


def test_load_work_is_load_times_displacement():
    # independent of the quadrature: F_L times the displacement per period
    sc, ss, a = _ed(2000.0, load=1e-4)
    exact = sc.fL * ss.displacement_per_period
    assert exact > 0        # the rotor still moves forward against the load
    assert a["load_work"] == pytest.approx(exact, rel=1e-10)
    assert abs(a["closing_error"]) < 1e-9


def test_impact_jump_energy_split():
    # stator work minus impact loss is exactly the jump of E at a velocity jump
    sc = FrictionDrive(frequency=2000.0)
    re = RodEnergy(sc)
    q = np.array([0.7, 0.3])
    v0, v1 = np.array([0.004, 0.001]), np.array([-0.002, 0.0012])
    w, loss = re.jump(q, v0, v1, 0.4)
    assert w - loss == pytest.approx(float(re.energy(q, v1, 0.4) - re.energy(q, v0, 0.4)),
                                     rel=1e-12)


def test_jump_refuses_two_rods():
    re = RodEnergy(BidirectionalDrive(frequency=185.0))
    with pytest.raises(InputError, match="single rod"):
        re.jump(np.zeros(3), np.zeros(3), np.ones(3), 0.0)


def test_moreau_jean_audit_first_order_and_converges_to_reference():
    sc, _, ref = _ed(185.0)
    a1, a2, a4 = (_mj(sc, n) for n in (1000, 2000, 4000))
    # stated accuracy: |closing error| <= 30 / N with theta = 1, first order
    for n, a in ((1000, a1), (2000, a2), (4000, a4)):
        assert 0.0 < a["closing_error"] <= 30.0 / n
    assert a1["closing_error"] / a2["closing_error"] == pytest.approx(2.0, rel=0.1)
    assert a2["closing_error"] / a4["closing_error"] == pytest.approx(2.0, rel=0.1)

    def dist(a):
        return max(abs(a[k] - ref[k]) for k in TERMS) / ref["stator_work"]
    assert dist(a4) < dist(a2) < dist(a1) < 0.05
    assert dist(a1) / dist(a4) > 3.5


def test_moreau_jean_midpoint_audit_closes_tighter():
    a = _mj(FrictionDrive(frequency=2000.0), 1000, theta=0.5)
    assert abs(a["closing_error"]) < 0.5 / 1000


@pytest.mark.slow
def test_two_rod_drive_moreau_jean_audit():
    sc = BidirectionalDrive(frequency=185.0, x10_b=1e-6)
    a = _mj(sc, 1000)
    assert 0.0 < a["closing_error"] < 30.0 / 1000
    assert a["friction_positive_slip"] > 0 and a["friction_negative_slip"] > 0


def test_steady_json_carries_energy(capsys):
    assert main(["steady", "--frequency", "185", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    e = rep["energy"]
    assert set(e) == {si for _, si in ENERGY_TERMS} | {"closing_error", "rounding_bound_J"}
    assert abs(e["closing_error"]) < 1e-9
    sc = FrictionDrive(frequency=185.0)
    # joules: m l^2 w^2 times the dimensionless work
    assert e["stator_work_J"] == pytest.approx(
        _ed(185.0)[2]["stator_work"] * sc.force_scale * sc.params.length, rel=1e-12)
    assert main(["steady", "--frequency", "185", "--scheme", "moreau-jean", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert 0.0 < rep["energy"]["closing_error"] < 0.03


def test_steady_json_of_the_two_rod_drive_carries_the_generic_audit(capsys):
    assert main(["steady", "--scene", "bidirectional-drive", "--frequency", "185", "--json"]) == 0
    e = json.loads(capsys.readouterr().out)["energy"]
    assert set(e) == {si for _, si in ENERGY_TERMS} | {"closing_error", "rounding_bound_J"}
    assert abs(e["closing_error"]) < 1e-9
    # both rods alike and in phase: the rotor stays, the stator work goes to friction,
    # equally to both slip directions (the mirror symmetry)
    assert e["stator_work_J"] > 0 and e["load_work_J"] == 0.0
    assert e["friction_loss_positive_slip_J"] == pytest.approx(
        e["friction_loss_negative_slip_J"], rel=1e-9)


def test_steady_json_says_when_no_audit(capsys):
    assert main(["steady", "--scene", "stick-slip-motor", "--frequency", "1000", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["energy"] is None
    assert rep["energy_note"] == ("no energy audit for scheme 'event-driven' on scene "
                                  "'stick-slip-motor'")


#: the section state of the two-rod drive's NSP|NP orbit at 185 Hz, x10_b = 1e-6 m (tau = 0,
#: both rods on the rotor), as the generic event-driven shooting found it (100 s): the audit
#: closes from any state, the stored energy change taking up what is not periodic
TWO_ROD_SECTION = (0.7853981633974483, 0.7853981633974483, 0.0, 0.0, 0.0, -0.00101636)


@pytest.mark.parametrize("load", [0.0, -2e-4])
def test_two_rod_drive_event_driven_audit_closes(load):
    sc = BidirectionalDrive(frequency=185.0, x10_b=1e-6, load=load)
    start = SimpleNamespace(state0=np.array(TWO_ROD_SECTION), section_tau=0.0)
    a = energy_audit(sc, start, "event-driven")
    # measured 6.4e-14 without load
    assert abs(a["closing_error"]) < 1e-9
    assert a["friction_positive_slip"] > 0 and a["friction_negative_slip"] > 0
    assert abs(a["impact_loss"]) < 1e-12 * a["stator_work"]
    # the load's work is the load times the rotor's displacement over the period, which
    # an independent run of the period gives
    r = simulate(sc, (0.0, 2 * math.pi), np.array(TWO_ROD_SECTION[:3]),
                 np.array(TWO_ROD_SECTION[3:]), "event-driven-generic")
    assert a["load_work"] == pytest.approx(sc.fL * (r.q[-1, 2] - r.q[0, 2]), rel=1e-9, abs=0.0)
    if load:
        assert a["load_work"] > 0      # a negative load opposes the backward motion


def test_generic_audit_agrees_with_the_walker_through_flight_and_impacts():
    # the generic scheme's phases, impacts and projections against the walker's closed forms
    sc, ss, a = _ed(2000.0, phi0=1.40)
    g = energy_audit(sc, ss, "event-driven-generic")
    assert abs(g["closing_error"]) < 1e-9
    for k in TERMS:
        assert g[k] == pytest.approx(a[k], abs=1e-9 * a["stator_work"])
    assert g["impact_loss"] > 0.5 * g["stator_work"]


def test_sweep_rows_carry_the_audit():
    row = evaluate_point(asdict(PAPER_DEFAULTS), 185.0, ED_REFERENCE, energy=True)
    assert set(ENERGY_COLUMNS) <= set(row)
    assert row["energy_status"] == "ok" and abs(row["energy_closing_error"]) < 1e-9
    sc = FrictionDrive(frequency=185.0)
    assert row["stator_work_J"] == pytest.approx(
        energy_to_si(sc, _ed(185.0)[2])["stator_work_J"], rel=1e-12)
    bad = evaluate_point(asdict(PAPER_DEFAULTS.with_(phi0=1.5)), 185.0, ED_REFERENCE,
                         energy=True)
    assert math.isnan(bad["stator_work_J"])
    assert bad["energy_status"] == "no steady state (PainleveError)"
    mj = evaluate_point(asdict(PAPER_DEFAULTS), 185.0, Scheme.moreau_jean(1.0, 500), energy=True)
    assert mj["energy_status"] == "ok" and 0 < mj["energy_closing_error"] < 30.0 / 500
