"""The friction drive's preload (FrictionDriveParams.preload): model, schemes, energy, stall."""

import math

import numpy as np
import pytest

from moreau.analysis.characteristic import motor_characteristic
from moreau.analysis.energy import RodEnergy, energy_audit, generic_event_driven_energy_audit
from moreau.analysis.steady_state import find_steady_state
from moreau.check import check_scene
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.friction_drive import FrictionDrive

#: a preload of the order of the spring's dynamic force k x10 (0.02 N)
FP = 0.02


def test_zero_preload_is_the_default_bit_for_bit():
    a, b = FrictionDrive(frequency=2000.0), FrictionDrive(frequency=2000.0, preload=0.0)
    assert a.fp == 0.0
    q0, v0 = a.rest_state()
    ra = simulate(a, (0.0, 2 * math.pi), q0, v0, "moreau-jean", h=2 * math.pi / 200)
    rb = simulate(b, (0.0, 2 * math.pi), q0, v0, "moreau-jean", h=2 * math.pi / 200)
    assert np.array_equal(ra.q, rb.q) and np.array_equal(ra.force_N, rb.force_N)
    # the walker's steady state and the compiled Moreau-Jean one equal what the code gave
    # before the preload existed (main at 9193e36). Same process: bit for bit. Against the
    # stored figures: to 1e-13 relative, because another CPU's compiled code (FMA
    # contraction, vector widths) moves the shooting's last digit (seen: ...361 vs ...362)
    ss, ss_default = find_steady_state(b), find_steady_state(a)
    assert ss.mode == "NP"
    assert ss.displacement_per_period == ss_default.displacement_per_period
    assert ss.displacement_per_period == pytest.approx(0.0018444601229275067, rel=1e-13)
    assert ss.state0[2] == pytest.approx(0.00030557097795165907, rel=1e-13)
    mj = find_steady_state(FrictionDrive(frequency=185.0, preload=0.0), scheme="moreau-jean",
                           steps_per_period=500)
    mj_default = find_steady_state(FrictionDrive(frequency=185.0), scheme="moreau-jean",
                                   steps_per_period=500)
    assert mj.displacement_per_period == mj_default.displacement_per_period
    assert mj.displacement_per_period == pytest.approx(-0.006626515764853361, rel=1e-13)


def test_preload_is_validated():
    with pytest.raises(InputError, match="`preload` must be >= 0"):
        FrictionDrive(preload=-1e-3)


def test_preload_force_is_minus_the_gradient_of_its_potential():
    # independent of the force code: central differences of the audit's energy at rest
    sc = FrictionDrive(frequency=185.0, preload=FP)
    re = RodEnergy(sc)
    tau = math.pi / 2        # u1'' = 0: the hinge's inertial torque vanishes
    for phi in (0.6, sc.phi0, 0.9):
        h = 1e-6
        dE = (re.energy([phi + h, 0.0], [0.0, 0.0], tau)
              - re.energy([phi - h, 0.0], [0.0, 0.0], tau)) / (2 * h)
        assert sc.forces(np.array([phi, 0.0]), np.zeros(2), tau)[0] == pytest.approx(
            -dE, rel=1e-8, abs=1e-9 * sc.fp)


def test_contact_carries_the_preload_at_rest():
    sc = FrictionDrive(frequency=185.0, preload=FP)
    A, B, C, D, E = sc.coefficients(sc.phi0, 0.0, math.pi / 2)
    # g_N'' = A f_N + D = 0 without friction, the rod at phi0 and at rest
    assert -D / A == pytest.approx(sc.fp, rel=1e-13)
    assert sc.fp * sc.force_scale == pytest.approx(FP, rel=1e-15)


def test_check_scene_and_compiled_model_with_preload():
    rep = check_scene(FrictionDrive(frequency=185.0, preload=FP))
    assert rep.ok, rep.problems


@pytest.fixture(scope="module")
def preloaded():
    sc = FrictionDrive(frequency=185.0, preload=FP)
    return sc, find_steady_state(sc)


def test_walker_audit_closes_and_generic_solver_agrees(preloaded):
    sc, ss = preloaded
    a = energy_audit(sc, ss, "event-driven")
    assert abs(a["closing_error"]) < 1e-9
    # the generic event-driven scheme integrates the scene's forces (not the walker's
    # closed forms) through the same period: same terms, 1.8e-12 closing measured
    g = generic_event_driven_energy_audit(sc, ss, {})
    assert abs(g["closing_error"]) < 1e-9
    for k in ("stator_work", "friction_positive_slip", "friction_negative_slip"):
        assert g[k] == pytest.approx(a[k], rel=1e-9, abs=1e-12 * a["stator_work"])
    # the preload changes the motion: the steady state differs from the unloaded one
    assert ss.mode == "NS"
    assert ss.displacement_per_period != pytest.approx(
        find_steady_state(FrictionDrive(frequency=185.0)).displacement_per_period, rel=1e-3)


def test_moreau_jean_agrees_with_the_reference(preloaded):
    sc, ss = preloaded
    mj = find_steady_state(sc, scheme="moreau-jean", steps_per_period=2000)
    # first order in h: 6.3e-5 relative measured at N = 2000 (1.5e-4 at N = 1000)
    assert mj.mode == ss.mode
    assert mj.displacement_per_period == pytest.approx(ss.displacement_per_period, rel=2e-4)
    a = energy_audit(sc, mj, "moreau-jean", {"steps_per_period": 2000, "theta": 1.0})
    # the scheme's own dissipation, first order: 50/N measured (2.58e-2 at N = 2000,
    # 1.31e-2 at N = 4000; without the preload 27/N, of a stator work twice as large)
    assert 0.0 < a["closing_error"] < 60.0 / 2000


def test_stall_force_grows_with_the_preload():
    stall = [motor_characteristic("friction-drive", frequency=2000.0, fixed={"preload": p},
                                  points=3, out=None, plot=False)["summary"]["stall_force_N"]
             for p in (0.0, 0.01, 0.02)]
    assert 0.0 < stall[0] < stall[1] < stall[2]
