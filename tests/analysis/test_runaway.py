"""Issue 34: one runaway detector for steady, statistical, bifurcation and the atlas classes."""

import math

import numpy as np
import pytest

from moreau.analysis.bifurcation import bifurcation_diagram
from moreau.analysis.classify import classify_long_run
from moreau.analysis.runaway import runaway_in
from moreau.analysis.statistical import statistical_steady_state
from moreau.analysis.steady_state import find_steady_state
from moreau.errors import RunawayError
from moreau.scenes.friction_drive import FrictionDrive
from moreau.scenes.stick_slip_motor import StickSlipMotor

TWO_PI = 2.0 * math.pi


def test_the_trend_test_takes_a_steady_growth_and_leaves_bounded_motions():
    sc = FrictionDrive(frequency=185.0, load=0.005)
    bound = 0.002
    k = np.arange(200.0)
    rng = np.random.default_rng(34)
    # constant acceleration beyond the tip's speed, with noise: a runaway
    grow = -TWO_PI * (0.01 + 1e-3 * k) + 1e-3 * rng.standard_normal(k.size)
    why = runaway_in(grow, sc, bound=bound)
    assert why is not None and "past stall (load F_L = 0.005 N)" in why
    assert "runs away backwards" in why
    # the same growth below the drive's speed bound is not (yet) a runaway
    assert runaway_in(grow, sc, bound=1e3) is None
    # a transient relaxing onto a fast bounded motion slows down: not a runaway
    relax = -TWO_PI * (1.0 - np.exp(-k / 30.0)) + 1e-6 * rng.standard_normal(k.size)
    assert runaway_in(relax, sc, bound=bound) is None
    # a decelerating motion (back towards rest) is not either
    assert runaway_in(-TWO_PI * (1.0 - 1e-3 * k), sc, bound=bound) is None
    # a stationary noisy motion beyond the bound has no significant trend
    assert runaway_in(-TWO_PI * (0.5 + 0.01 * rng.standard_normal(k.size)), sc,
                      bound=bound) is None
    # an overflowed state is one
    assert "not finite" in runaway_in(np.r_[grow, np.inf], sc, bound=bound)


def test_the_load_between_the_secant_runaways_is_named_not_budget_exhausted():
    # 0.004 and 0.01 N were named by the orbit check, 0.005 N ran 40000 periods and ended
    # with BudgetExhaustedError: the statistical steady state had no runaway check
    with pytest.raises(RunawayError, match=r"past stall \(load F_L = 0.005 N\); the rotor runs "
                                           r"away backwards, its mean speed grows by 0.0075\d "
                                           r"m/s every period"):
        find_steady_state(FrictionDrive(frequency=185.0, load=0.005))


def test_a_load_beyond_the_sliding_friction_is_named_at_once_and_by_the_run():
    sc = StickSlipMotor(frequency=1000.0, load=0.3)
    # the physics: |F_L| > mu N, the slider's velocity changes by 2 pi (fL - mu n) a period
    with pytest.raises(RunawayError, match=r"the load \|F_L\| = 0.3 N exceeds the sliding "
                                           r"friction mu N = 0.2 N"):
        find_steady_state(sc)
    # the generic detector on a plain run says the same, with the growth the physics gives
    dv = TWO_PI * (sc.fL - sc.friction_level) * sc.length / sc.time
    with pytest.raises(RunawayError, match="runs away backwards") as info:
        statistical_steady_state(sc, "moreau-jean", steps_per_period=200)
    grow = float(str(info.value).split("grows by ")[1].split(" m/s")[0])
    assert grow == pytest.approx(dv, rel=1e-2)
    assert classify_long_run(sc, "moreau-jean", {"steps_per_period": 200})[
        "classification"] == "runaway"
    # the bifurcation labelled it "non-periodic", status ok
    (p,) = bifurcation_diagram("stick-slip-motor", "load", [0.3], frequency=1000.0,
                               transient=5, samples=4, out=None, progress=False)["points"]
    assert p["motion"] == "runaway" and "exceeds the sliding friction" in p["status"]


def test_the_bifurcation_and_the_atlas_class_name_the_runaway():
    d = bifurcation_diagram("friction-drive", "load", [0.005], frequency=185.0, transient=5,
                            samples=20, lyapunov=False, shoot=False, out=None, progress=False)
    (p,) = d["points"]
    assert p["motion"] == "runaway" and p["status"].startswith("RunawayError: no steady state: "
                                                                 "past stall (load F_L = 0.005")
    assert d["marks"] == []
    found = classify_long_run(FrictionDrive(frequency=185.0, load=0.005), budget=40)
    assert found["classification"] == "runaway" and "past stall" in found["detail"]
    # and a point below stall is not
    assert classify_long_run(FrictionDrive(frequency=185.0, load=-1e-4), budget=40)[
        "classification"] == "period-1"


@pytest.mark.slow
def test_the_generic_event_driven_run_is_sampled_and_its_runaway_named():
    # without the scene's own statement the statistical run of the event-driven scheme on
    # the stick-slip motor failed with "did not sample the run at the ends of the drive
    # periods" (the dispatcher states no sampling option); 16 s unloaded
    from moreau.analysis.steady_state import _statistical
    with pytest.raises(RunawayError, match="its mean speed grows by 0.01 m/s every period"):
        _statistical(StickSlipMotor(frequency=1000.0, load=0.3), "event-driven", None, 40000,
                     {})
