"""One compiled Moreau–Jean engine for every scene: models, agreement with the generic path,
default states, the multi-contact LCP path and the generic period map."""

import math

import numpy as np
import pytest

from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.moreau_jean import MoreauJean, compiled_model_of
from moreau.scenes import (BidirectionalDrive, BidirectionalDriveParams, BouncingBall,
                           FrictionDrive, FrictionDriveParams, PainleveRod, SawtoothDrive,
                           SineDrive, SlidingBlock, SlidingBox, StickSlipMotor)
from moreau.compiled import check_compiled_model

from _agreement import assert_forces_agree

TWO_PI = 2.0 * math.pi


def all_scenes():
    return {
        "friction-drive": FrictionDrive(frequency=185.0),
        "friction-drive-flight": FrictionDrive(FrictionDriveParams(k=10.0, restitution=0.5),
                                               frequency=2000.0),
        "friction-drive-mu0": FrictionDrive(FrictionDriveParams(mu=0.0), frequency=185.0),
        "bouncing-ball": BouncingBall(restitution=0.7),
        "sliding-block": SlidingBlock(mu=0.3, incline=0.2),
        "painleve-rod": PainleveRod(mu=0.5),
        "stick-slip-sawtooth": StickSlipMotor(drive=SawtoothDrive(rise=0.8)),
        "stick-slip-sine": StickSlipMotor(drive=SineDrive(harmonic2=0.3, phase2=0.4)),
        "bidirectional-drive": BidirectionalDrive(BidirectionalDriveParams(phase=1.0)),
        "sliding-box": SlidingBox(),
        "sliding-box-bouncing": SlidingBox(restitution=0.5),
    }


SCENES = all_scenes()


def step_of(sc):
    return TWO_PI / 400 if getattr(sc, "period", None) else 0.004


# -- the compiled model is the Python model ------------------------------------------------

@pytest.mark.parametrize("name", sorted(SCENES))
def test_compiled_model_equals_the_python_scene(name):
    sc = SCENES[name]
    rng = np.random.default_rng(7)
    q0, v0 = sc.initial_state()
    for _ in range(25):
        q = q0 + 0.3 * rng.standard_normal(sc.ndof)
        v = v0 + rng.standard_normal(sc.ndof)
        assert check_compiled_model(sc, q, v, rng.uniform(-3.0, 20.0)) <= 1e-12


def test_every_shipped_scene_has_a_compiled_model_and_a_subclass_loses_it():
    for sc in SCENES.values():
        assert compiled_model_of(sc) is not None

    class Heavier(SlidingBlock):
        def mass(self, q):
            return 2.0 * np.eye(2)

    assert compiled_model_of(Heavier()) is None
    with pytest.raises(InputError, match=r"`fast=True` needs a scene with a compiled model"):
        MoreauJean(Heavier(), 0.0, [0.0, 0.0], [1.0, 0.0], 1.0, h=0.1, fast=True)


# -- compiled run == generic run ---------------------------------------------------------

def _pair(sc, nsteps, **opts):
    q0, v0 = sc.initial_state()
    h = step_of(sc)
    a = simulate(sc, (0.0, nsteps * h), q0, v0, "moreau-jean", h=h, fast=False, **opts)
    b = simulate(sc, (0.0, nsteps * h), q0, v0, "moreau-jean", h=h, fast=True, **opts)
    return a, b


@pytest.mark.parametrize("name", sorted(SCENES))
@pytest.mark.parametrize("theta, projection", [(1.0, False), (0.5, True)])
def test_compiled_run_equals_generic_run_over_1000_steps(name, theta, projection):
    sc = SCENES[name]
    a, b = _pair(sc, 1000, theta=theta, projection=projection)
    assert a.status == b.status and a.message == b.message
    assert len(a.t) == len(b.t) and len(a.t) > 300
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.regime, b.regime)
    vs = max(1.0, float(np.max(np.abs(a.v))))
    qs = max(1.0, float(np.max(np.abs(a.q))))
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-12 * qs)
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=1e-12 * vs)
    np.testing.assert_allclose(b.slip_velocity, a.slip_velocity, rtol=0, atol=1e-12 * vs)
    np.testing.assert_allclose(b.gap, a.gap, rtol=0, atol=1e-12 * qs)
    assert_forces_agree(a, b, step_of(sc), vs)
    for key in ("steps", "lcp_solves", "direct_solves", "projection_iterations", "fallbacks"):
        assert a.stats[key] == b.stats[key], key


def test_forced_lemke_runs_compiled_and_agrees():
    sc = FrictionDrive(frequency=185.0)
    q0, v0 = sc.initial_state()
    h = TWO_PI / 400
    a = simulate(sc, (0.0, TWO_PI), q0, v0, "moreau-jean", h=h, lcp_method="lemke", fast=False)
    b = simulate(sc, (0.0, TWO_PI), q0, v0, "moreau-jean", h=h, lcp_method="lemke", fast=True)
    assert b.stats["direct_solves"] == 0 and b.stats["pivots"] > 0
    assert a.stats["lcp_solves"] == b.stats["lcp_solves"] == 400
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=1e-12 * sc.u10)
    with pytest.raises(InputError, match=r"`lcp_method='qp'` needs fast='auto' or False"):
        MoreauJean(sc, 0.0, q0, v0, 1.0, h=h, lcp_method="qp", fast=True)


def test_multi_contact_steps_go_through_lemke_in_the_compiled_loop():
    sc = SCENES["bidirectional-drive"]
    # without the warm start (tests/integrators/test_warm_lcp.py) every step pivots
    a, b = _pair(sc, 400, lcp_warm_start=False)
    assert b.stats["lcp_solves"] == 400 and b.stats["direct_solves"] == 0
    assert b.stats["pivots"] > 400 and b.stats["fallbacks"] == 0
    assert b.stats["max_residual"] < 1e-12


# -- initial_state ---------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(SCENES))
def test_initial_state_is_admissible(name):
    sc = SCENES[name]
    q0, v0 = sc.initial_state()
    assert q0.shape == v0.shape == (sc.ndof,)
    assert np.all(sc.gaps(q0, 0.0) >= -1e-15)
    res = simulate(sc, (0.0, 50 * step_of(sc)), q0, v0, "moreau-jean", h=step_of(sc))
    assert res.success


def test_resting_drives_start_on_their_contacts():
    for sc in (FrictionDrive(frequency=185.0), BidirectionalDrive()):
        q0, v0 = sc.initial_state()
        np.testing.assert_allclose(sc.gaps(q0, 0.0), 0.0, atol=1e-15)
        WN, wN, _, _ = sc.contact_jacobians(q0, 0.0)
        np.testing.assert_allclose(WN @ v0 + wN, 0.0, atol=1e-15)


# -- the multi-contact scene: exact solution, first order, through Lemke -----------------

def test_sliding_box_exact_solution_is_consistent():
    box = SlidingBox(mu=0.4, half_width=0.5, half_height=0.25)
    q0, v0 = box.initial_state()
    ts = box.stopping_time(v0)
    q, v = box.exact_solution([0.0, 0.5 * ts, ts, 2 * ts], q0, v0)
    assert v[2, 0] == 0.0 and q[2, 0] == pytest.approx(box.stopping_distance(v0))
    assert q[3, 0] == q[2, 0]
    nr, nf = box.normal_forces()
    assert nr + nf == pytest.approx(1.0) and nf > nr > 0.0
    with pytest.raises(InputError, match=r"`mu` \* half_height must be < half_width"):
        SlidingBox(mu=3.0).stopping_time(v0)


@pytest.mark.parametrize("lcp_method", ["auto", "lemke"])
def test_sliding_box_converges_at_first_order_through_lemke(lcp_method):
    box = SlidingBox(mu=0.4)
    q0, v0 = box.initial_state()
    ts = box.stopping_time(v0)
    T = 1.6 * ts
    errs, hs = [], []
    for n in (50, 100, 200, 400, 800):
        h = T / n
        res = simulate(box, (0.0, T), q0, v0, "moreau-jean", h=h, save_every=1,
                       lcp_method=lcp_method)
        st = res.stats
        # two active contacts on every step: each one an LCP solved in the compiled
        # loop. "lemke": by pivoting on every step. "auto": by Lemke where a regime
        # changes (first step, stop; measured 3 steps) and elsewhere by the regime
        # solve, certified as a solution of the same LCP
        assert res.success and st["lcp_solves"] == n and st["direct_solves"] == 0
        assert st["fallbacks"] == 0
        if lcp_method == "lemke":
            assert st["warm_starts"] == 0 and st["pivots"] >= 2 * n
        else:
            assert st["pivots"] >= 2 and st["warm_starts"] >= n - 5
        qe, ve = box.exact_solution(res.t, q0, v0)
        errs.append(max(np.max(np.abs(res.q - qe)), np.max(np.abs(res.v - ve))))
        hs.append(h)
        # the box stays flat on both corners; the loads match the exact ones while sliding
        assert np.max(np.abs(res.q[:, 2])) < 1e-12 and np.max(np.abs(res.gap)) < 1e-12
        sliding = res.t[1:] < ts - 2 * h
        nr, nf = box.normal_forces()
        fN = res.force_N[1:][sliding]
        np.testing.assert_allclose(fN, np.broadcast_to([nr, nf], fN.shape), rtol=1e-9)
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 0.9 < order < 1.1, (order, errs)


# -- the generic period map ---------------------------------------------------------------

def test_period_map_needs_a_period():
    from moreau.analysis.mj_steady_state import PeriodMap, moreau_jean_steady_state
    with pytest.raises(InputError, match=r"has no periodic drive \(`scene.period` is None\)"):
        PeriodMap(SlidingBlock(), 100)
    with pytest.raises(InputError, match=r"no periodic drive"):
        moreau_jean_steady_state(BouncingBall(), 100)


@pytest.mark.parametrize("scene", [BidirectionalDrive(BidirectionalDriveParams(x10_b=0.0)),
                                   StickSlipMotor()])
def test_steady_state_of_other_periodic_scenes(scene):
    from moreau.analysis.mj_steady_state import moreau_jean_steady_state
    ss = moreau_jean_steady_state(scene, 1000)
    assert ss.stats["periodic"] and ss.periodic_residual <= 1e-12
    # the orbit repeats in a plain simulation from the fixed point
    pm_q, pm_v = _full(scene, ss.state0)
    res = simulate(scene, (0.0, 2 * TWO_PI), pm_q, pm_v, "moreau-jean", h=TWO_PI / 1000,
                   projection=True, save_every=1000)
    k = scene.cyclic_coordinates[0]
    assert res.q[2, k] - res.q[1, k] == pytest.approx(ss.displacement_per_period, rel=1e-8,
                                                      abs=1e-12)


def _full(scene, x):
    from moreau.analysis.mj_steady_state import PeriodMap
    return PeriodMap(scene, 10).full_state(x)


def test_bidirectional_rod_a_alone_matches_the_single_rod_scene():
    from moreau.analysis.mj_steady_state import moreau_jean_steady_state
    two = moreau_jean_steady_state(BidirectionalDrive(BidirectionalDriveParams(x10_b=0.0)), 1000)
    one = moreau_jean_steady_state(FrictionDrive(frequency=185.0), 1000)
    # rod b rests on the rotor without exciting it, but its friction still acts
    assert np.sign(two.displacement_per_period) == np.sign(one.displacement_per_period)


def test_steady_state_with_flight_and_impacts_at_15_khz():
    # issue 11, defect 1: the rod is in flight at tau = 0; shooting from rest
    # stalls, the transient settles, and shooting finishes from there
    from moreau.analysis.mj_steady_state import moreau_jean_steady_state
    from moreau.analysis.steady_state import find_steady_state
    sc = FrictionDrive(frequency=15000.0)
    ref = find_steady_state(sc)
    ss = moreau_jean_steady_state(sc, 8000)
    assert ref.mode == ss.mode == "NF!P"
    assert ss.stats["periodic"] and ss.periodic_residual <= 1e-12
    rel = abs(ss.displacement_per_period / ref.displacement_per_period - 1.0)
    assert rel < 2e-2                       # measured 1.2e-2
    assert ss.min_normal_force == 0.0       # flight inside the period


def test_no_period_one_orbit_is_said_plainly():
    # elastic impacts at 15 kHz: the discrete motion does not settle on a
    # period-1 orbit; the answer says so and reports a long-run average
    from moreau.analysis.mj_steady_state import moreau_jean_steady_state
    sc = FrictionDrive(FrictionDriveParams(restitution=1.0), frequency=15000.0)
    ss = moreau_jean_steady_state(sc, 2000)
    assert ss.stats["periodic"] is False and ss.mode == "no period-1 orbit"
    assert "no period-1 orbit" in ss.stats["message"]
    assert "long-run average" in ss.stats["message"]
    assert math.isfinite(ss.displacement_per_period) and ss.displacement_per_period > 0.0
    assert ss.periodic_residual > 1e-6 and ss.regimes == []


def test_a_caller_that_wants_an_orbit_gets_a_failure_not_a_window_average():
    # sweeps and atlases call find_steady_state(statistical=False): where the
    # Moreau-Jean map has no period-1 orbit, a fixed window's average is not an
    # answer (it can sit inside a slow transient), so the point fails and says why
    from moreau.analysis.steady_state import find_steady_state
    from moreau.errors import ConvergenceError
    sc = FrictionDrive(FrictionDriveParams(restitution=1.0), frequency=15000.0)
    with pytest.raises(ConvergenceError, match="no period-1 orbit"):
        find_steady_state(sc, "moreau-jean", steps_per_period=2000, statistical=False)
