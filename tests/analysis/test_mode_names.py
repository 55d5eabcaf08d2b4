"""Mode names are canonical across schemes (issue #11, defects 2 and 3)."""

import numpy as np
import pytest

from moreau.modes import impacts_after_flight, mode_name, step_letters
from moreau.analysis.mj_steady_state import moreau_jean_steady_state
from moreau.analysis.period_k import full_state_of
from moreau.analysis.periodic_shooting import period_mode
from moreau.analysis.steady_state import find_steady_state
from moreau.integrators import simulate
from moreau.regimes import Regime
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams


def test_rotation_is_fixed_by_letters_not_by_impact_marks():
    # the same cycle with and without its impact mark lines up letter by letter
    marked = mode_name("FNSN", impacts=[False, True, False, False])
    plain = mode_name("FNSN")
    assert marked == "!NSNF"
    assert plain == "NSNF"
    assert marked.replace("!", "") == plain


def test_rotation_ties_broken_by_impacts():
    # letters NFNF: two rotations share the letters; the unmarked one comes first
    assert mode_name("NFNF", impacts=[True, False, False, False]) == "NF!NF"


def test_paper_names_unchanged():
    for seq, name in [("SN", "NS"), ("PSNS", "NSPS"), ("SNP", "NPS"), ("PN", "NP"),
                      ("PNS", "NSP"), ("PS", "SP")]:
        assert mode_name(seq) == name


def test_frictionless_contact_is_never_stick():
    assert step_letters([3, 3, 0, 3], slip=[1e-3, -2.0, 0.0, -1e-9], mu=0.0) == ["P", "N", "F", "N"]
    # with friction the impulse decides
    assert step_letters([3, 1], slip=[0.0, 0.5], mu=0.1) == ["S", "P"]
    with pytest.raises(ValueError, match="`slip`"):
        step_letters([3], mu=0.0)


def test_impacts_after_flight_is_cyclic():
    assert impacts_after_flight("FNS") == [False, True, False]
    assert impacts_after_flight("NSF") == [True, False, False]
    assert impacts_after_flight("N") == [False]


# the generic (Python) map at 500 steps a period, a quarter of the compiled one's 2000:
# the same mode, displacement 3.7e-4 from the reference (5.5e-5 at 2000)
@pytest.mark.parametrize("fast, steps", [("auto", 2000), (False, 500)])
def test_flight_mode_same_name_both_schemes(fast, steps):
    # issue #11: at 185 Hz, phi0 = 0.3 event-driven said NF!NS and Moreau-Jean NSNF
    scene = FrictionDrive(FrictionDriveParams(phi0=0.3), frequency=185.0)
    ed = find_steady_state(scene)
    mj = moreau_jean_steady_state(scene, steps, fast=fast)
    assert ed.mode == "!NSNF"
    assert mj.mode == ed.mode
    assert abs(mj.displacement_per_period / ed.displacement_per_period - 1.0) < 1e-3


@pytest.mark.parametrize("frequency", [20.0, 185.0, 2000.0])
def test_mu_zero_mode_is_slip_not_stick(frequency):
    scene = FrictionDrive(FrictionDriveParams(mu=0.0), frequency=frequency)
    ed = find_steady_state(scene)
    mj = moreau_jean_steady_state(scene, 1000)
    assert ed.mode == "NP"
    assert mj.mode == "NP"
    assert "S" not in "".join(r for _, r in mj.regimes)
    # no friction: the rotor is not driven
    assert abs(mj.displacement_per_period) < 1e-12


# -- every scheme's samples named by the contact law (issue 34) ------------------------------

@pytest.fixture(scope="module")
def drive_185():
    scene = FrictionDrive(frequency=185.0)
    return scene, find_steady_state(scene)


@pytest.fixture(scope="module")
def stick_slip_motor():
    from moreau.model.registry import make_scene
    from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state
    scene = make_scene("stick-slip-motor")
    return scene, stick_slip_steady_state(scene)


# cheap settings: 200 steps a period, a soft compliant contact (the mode, not the accuracy)
H200 = {"h": 2 * np.pi / 200, "fast": False}
SOFT = {"stiffness": 1e4, "rtol": 1e-6, "friction_velocity": 1e-3}
PERIOD_RUNS = [("time-discontinuous-galerkin", H200), ("studer-extrapolation", {"tol": 1e-8}),
               ("schatzman-paoli", H200), ("nonsmooth-generalized-alpha", H200),
               ("moreau-jean", H200)]


def _start(scene, ref):
    if ref.state0.size == 1:
        # the exact stick-slip state: the slider's velocity, on the stator (x = y = 0)
        return np.zeros(2), np.array([ref.state0[0], 0.0])
    return full_state_of(scene, ref.state0)


def _period_mode(scene, ref, scheme, options):
    q0, v0 = _start(scene, ref)
    ts = ref.section_tau
    res = simulate(scene, (ts, ts + 2 * np.pi), q0, v0, scheme, **options)
    assert res.success, res.message
    return period_mode(scene, res, ts, 2 * np.pi)


@pytest.mark.parametrize("scheme, options", PERIOD_RUNS)
def test_every_scheme_names_a_period_of_the_stick_slip_motor_as_the_reference(
        stick_slip_motor, scheme, options):
    # the defect: TDG, Studer and the compliant schemes named their first sample flight on
    # a closed contact, and a step across a slip reversal stick: "NSPSNF" (TDG, Studer)
    # for the reference's NSP
    mode, regimes = _period_mode(*stick_slip_motor, scheme, options)
    assert mode == "NSP", (mode, regimes)


@pytest.mark.slow
@pytest.mark.parametrize("scheme, options", [("studer-extrapolation", {"tol": 1e-8}),
                                             ("compliant-rk45", SOFT),
                                             ("compliant-radau", SOFT)])
@pytest.mark.parametrize("case, mode", [("drive_185", "NP"), ("stick_slip_motor", "NSP")])
def test_the_adaptive_schemes_name_a_period_as_the_reference(case, mode, scheme, options,
                                                             request):
    # 185 Hz from the orbit's section (its normal force at its least, 1e-5 N: fixed steps
    # of 200 a period lift off there, which the shootings below avoid by their own orbits);
    # measured 0.2 s (Studer), 4-9 s (compliant; 57 s for Radau on the motor)
    got, regimes = _period_mode(*request.getfixturevalue(case), scheme, options)
    assert got == mode, (got, regimes)


def test_the_first_sample_of_a_run_on_a_closed_contact_is_not_flight(stick_slip_motor):
    scene, ref = stick_slip_motor
    q0, v0 = _start(scene, ref)
    for scheme, options in [PERIOD_RUNS[0], PERIOD_RUNS[1], ("compliant-rk45", SOFT)]:
        res = simulate(scene, (0.0, 0.1), q0, v0, scheme, **options)
        assert res.regime[0, 0] == Regime.NEGATIVE, scheme     # the reference's N at tau = 0


@pytest.mark.parametrize("scheme", ["time-discontinuous-galerkin", "schatzman-paoli",
                                    "nonsmooth-generalized-alpha"])
def test_the_shootings_name_the_drive_at_185_hz_as_the_reference(scheme):
    # 200 steps a period: TDG read "NSPSNF" before (measured 1.0 s)
    scene = FrictionDrive(frequency=185.0)
    ss = find_steady_state(scene, scheme, statistical=False, steps_per_period=200)
    assert ss.mode == "NP" and [r for _, r in ss.regimes] == ["N", "P", "N"]


def test_the_two_rod_drive_s_swap_is_not_a_stick():
    # both rods reverse at tau = pi with everything at rest there: TDG's step recorded
    # both in stick (a mode whose forces are not determined, so the LCP decides), and the
    # sample's own velocity scale (8.8e-17) took the contacts for open
    from moreau.model.registry import make_scene
    scene = make_scene("bidirectional-drive", frequency=185.0)
    ss = find_steady_state(scene, "time-discontinuous-galerkin", statistical=False,
                           steps_per_period=400)
    assert ss.mode == "NP|NP" and [r for _, r in ss.regimes] == ["NP", "PN"]
