"""Stress catalogue (issue #11): one test per stiff or extreme case, asserting each scheme's outcome.

The quick catalogue is run (10^6 steps in the long-run case, flight averages
over periods 10..30); ``moreau compare --stress`` runs 10^7 steps.
"""

import json
import math

import pytest

from moreau.studies.paper.stress import CASES, SCHEMES, run_case, run_catalogue
from moreau.cli import main
from moreau.errors import InputError

# case -> expected outcome of (event-driven, Moreau–Jean theta=1, theta=1/2)
EXPECTED = {
    "stiff-1Hz-N50": ("stable", "inaccurate", "inaccurate"),
    "stiff-1Hz-N1000": ("stable", "stable", "stable"),
    "stiff-1Hz-N1e5": ("stable", "stable", "stable"),
    "flight-15kHz-e0": ("averaged", "averaged", "averaged"),
    # the quick catalogue's 400 periods do not reach the end of the spin-up with restitution:
    # the statistical steady state gives up with its status rather than average a transient
    "flight-15kHz-e0.5": ("failed", "failed", "failed"),
    "flight-15kHz-e1": ("failed", "failed", "failed"),
    "painleve-mu0.9": ("stable", "stable", "stable"),
    "painleve-mu0.99": ("stable", "stable", "stable"),
    "painleve-mu0.999": ("stable", "stable", "stable"),
    "painleve-mu1.2": ("failed", "failed", "failed"),
    "mu-zero": ("stable", "stable", "stable"),
    "mass-ratio-1e-3": ("stable", "stable", "stable"),
    "mass-ratio-1e6": ("stable", "stable", "stable"),
    "phi0-lift-off-edge": ("stable", "stable", "stable"),
    "phi0-painleve-edge": ("stable", "stable", "stable"),
    "coarse-N10": ("stable", "inaccurate", "inaccurate"),
    "long-1e7-steps": ("n/a", "stable", "stable"),
}

# case -> expected mode of the event-driven reference and of both Moreau–Jean runs
MODES = {
    "stiff-1Hz-N50": ("NS", "S"),          # 50 steps: the short slip is lost
    "stiff-1Hz-N1000": ("NS", "NS"),
    "stiff-1Hz-N1e5": ("NS", "NS"),
    "painleve-mu0.9": ("NS", "NS"),
    "painleve-mu0.999": ("S", "S"),
    "mu-zero": ("NP", "NP"),                # never stick without friction
    "mass-ratio-1e-3": ("S", "S"),
    "mass-ratio-1e6": ("NP", "NP"),
    "phi0-lift-off-edge": ("NSPS", "NSPS"),
    "phi0-painleve-edge": ("NP", "NP"),
    "coarse-N10": ("NP", "NP"),
}


def test_every_case_has_an_expectation():
    assert set(EXPECTED) == set(CASES)


def _check_common(rows):
    assert [r["scheme"] for r in rows] == list(SCHEMES)
    for r in rows:
        assert r["outcome"] != "bug", r["message"]
        for key in ("value", "error", "estimate"):
            assert r[key] is None or math.isfinite(r[key])
        if r["outcome"] == "stable" and r["error"] is not None:
            assert r["error"] <= r["bound"]
        if r["outcome"] == "inaccurate":
            # never a false success: outside the bound is said so, with the error
            assert r["error"] > r["bound"] and "error" in r["message"]
        if r["outcome"] == "failed":
            assert "Error" in r["message"]


@pytest.mark.parametrize("case", list(EXPECTED))
def test_case(case):
    rows = run_case(case)
    _check_common(rows)
    assert tuple(r["outcome"] for r in rows) == EXPECTED[case], [r["message"] for r in rows]
    ed, mj1, mj05 = rows
    if case in MODES:
        ref_mode, mj_mode = MODES[case]
        assert ed["mode"] == ref_mode
        assert mj1["mode"] == mj05["mode"] == mj_mode
    if case == "stiff-1Hz-N1e5":
        # the stiff spring (P = 1.3e7) does not limit the step: first order all the way
        assert mj1["error"] < 3e-4 and mj05["error"] < 3e-4
    if case == "painleve-mu1.2":
        assert all("Painlev" in r["message"] for r in rows)
    if case == "mu-zero":
        assert mj1["error"] < 1e-10 and mj05["error"] < 1e-10
    if case.startswith("flight"):
        # flight and impacts: at e = 0 both schemes find the period-1 orbit NF!P; with
        # restitution none is periodic and the quick budget ends the statistical run
        if case == "flight-15kHz-e0":
            assert "NF!P" in ed["message"] and mj05["error"] < 1e-2 and mj1["error"] < 5e-2
            assert "periodic steady state NF!P" in mj1["message"]
            assert "periodic steady state NF!P" in mj05["message"]
        else:
            assert all(r["message"].startswith("BudgetExhaustedError: statistical steady "
                                               "state: budget exhausted (`max_periods`=400)")
                       for r in rows)
    if case == "coarse-N10":
        # h = T/10: both step sizes still give the right mode, theta = 1/2 within 6 %
        assert mj1["error"] < 1.0 and mj05["error"] < 0.06
        assert mj1["estimate"] > mj1["bound"] and mj05["estimate"] > mj05["bound"]
    if case == "long-1e7-steps":
        assert "1e+06 steps" in mj1["message"]
        # theta = 1/2: the steady period repeats to rounding; theta = 1 to 1e-7
        assert mj05["error"] < 1e-9 and mj1["error"] < 2e-7


def test_stress_command_writes_map_and_table(tmp_path, capsys, monkeypatch):
    import moreau.studies.paper.stress as st
    keep = {k: st.CASES[k] for k in ("mu-zero", "painleve-mu1.2")}
    monkeypatch.setattr(st, "CASES", keep)
    assert main(["compare", "--stress", "--quick", "--quiet", "--json",
                 "--out", str(tmp_path)]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert {r["case"] for r in rep["rows"]} == set(keep)
    for f in ("stress.csv", "stress.json", "stress.png"):
        assert (tmp_path / f).stat().st_size > 0
    assert main(["compare", "--stress", "--quick", "--quiet", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "painleve-mu1.2" in out and "PainleveError" in out


def test_unknown_case_is_refused():
    with pytest.raises(InputError, match="`case`"):
        run_case("nope")
    with pytest.raises(InputError, match="`cases`"):
        run_catalogue(cases=["nope"], progress=False)
