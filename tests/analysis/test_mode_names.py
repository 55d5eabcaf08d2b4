"""Mode names are canonical across schemes (issue #11, defects 2 and 3)."""

import pytest

from moreau.analysis.modes import impacts_after_flight, mode_name, step_letters
from moreau.analysis.mj_steady_state import moreau_jean_steady_state
from moreau.analysis.steady_state import find_steady_state
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
