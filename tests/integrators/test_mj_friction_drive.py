"""Moreau–Jean on the paper's friction drive: compiled path, steady states, accuracy."""

import math

import numpy as np
import pytest

import moreau.integrators._blocks as blocks
from moreau.integrators import simulate
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams

TWO_PI = 2.0 * math.pi


def mj(scene, periods, steps, **opts):
    q0, v0 = scene.rest_state()
    return simulate(scene, (0.0, periods * TWO_PI), q0, v0, "moreau-jean", h=TWO_PI / steps,
                    **opts)


# -- compiled path == generic path ------------------------------------------------------

@pytest.mark.parametrize("freq, theta, projection, params", [
    (185.0, 1.0, False, {}), (185.0, 0.5, True, {}), (20.0, 1.0, True, {}),
    (2000.0, 0.5, False, {}), (185.0, 1.0, False, {"mu": 0.0}),
    # a soft spring: the rod flies and comes back with restitution 0.5
    (2000.0, 1.0, True, {"k": 10.0, "restitution": 0.5}),
])
def test_compiled_path_equals_generic_path(freq, theta, projection, params):
    sc = FrictionDrive(FrictionDriveParams(**params), frequency=freq)
    a = mj(sc, 1, 400, theta=theta, projection=projection, fast=False)
    b = mj(sc, 1, 400, theta=theta, projection=projection, fast=True)
    assert a.status == b.status == 0 and len(a.t) == len(b.t) == 401
    if "k" in params:
        letters = a.regime_letters()
        assert "F" in letters and len(set(letters)) > 1
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.regime, b.regime)
    vs = sc.u10          # velocity and displacement scale of the drive
    for x, y in ((a.q, b.q), (a.v, b.v), (a.slip_velocity, b.slip_velocity), (a.gap, b.gap)):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * vs)
    fs = np.max(np.abs(a.force_N))
    np.testing.assert_allclose(a.force_N, b.force_N, rtol=0, atol=1e-12 * fs)
    np.testing.assert_allclose(a.force_T, b.force_T, rtol=0, atol=1e-12 * fs)
    for key in ("steps", "lcp_solves", "direct_solves", "projection_iterations"):
        assert a.stats[key] == b.stats[key]
    assert a.stats["max_penetration"] == pytest.approx(b.stats["max_penetration"], abs=1e-15)


def test_compiled_blocks_join_seamlessly(monkeypatch):
    sc = FrictionDrive(frequency=185.0)
    whole = mj(sc, 1, 300, save_every=7)
    monkeypatch.setattr(blocks, "FAST_BLOCK", 11)
    pieces = mj(sc, 1, 300, save_every=7)
    np.testing.assert_array_equal(whole.t, pieces.t)
    np.testing.assert_array_equal(whole.q, pieces.q)
    np.testing.assert_array_equal(whole.regime, pieces.regime)
    assert whole.stats == pieces.stats and whole.stats["steps"] == 300
    assert len(whole.t) == 1 + 300 // 7 + 1


@pytest.mark.parametrize("fast", [False, True])
def test_painleve_violation_in_the_drive(fast):
    # mu tan(phi) > 1: the paper's Painlevé condition fails as soon as the rod presses.
    # The study of the configuration stops there (painleve="stop", the former default)
    sc = FrictionDrive(FrictionDriveParams(mu=1.5), frequency=185.0)
    res = mj(sc, 1, 200, fast=fast, painleve="stop")
    assert res.status == -1 and "Painlevé" in res.message
    assert np.all(np.isfinite(res.q))
    # by default the step's contact problem has its answer: the rod, pressed from rest,
    # sticks (self-locking) all period, with no slip to jam
    res = mj(sc, 1, 200, fast=fast)
    assert res.status == 0 and set(res.regime_letters()) == {"S"}
    assert res.stats["tangential_impacts"] == 0


# -- mode naming from per-step regimes ------------------------------------------------

from moreau.analysis.mj_steady_state import merge_step_regimes, moreau_jean_steady_state  # noqa: E402
from moreau.errors import ConvergenceError, InputError  # noqa: E402


def _names(letters):
    h = TWO_PI / len(letters)
    runs = merge_step_regimes(letters, [k * h for k in range(len(letters))], h)
    from moreau.modes import mode_name
    return runs, mode_name([s for _, s in runs])


def test_one_step_stick_between_opposite_slips_is_a_reversal():
    runs, mode = _names("NNNNSPPPPN")
    assert mode == "NP"
    h = TWO_PI / 10
    assert runs == [[0.0, "N"], [pytest.approx(4.5 * h), "P"], [pytest.approx(9 * h), "N"]]
    assert _names("PPPSNNNN")[1] == "NP"


def test_real_sticks_are_kept():
    assert _names("NNNSSPPP")[1] == "NSP"      # two steps of stick
    assert _names("NNNSNNNN")[1] == "NS"       # one-step stick between slips of equal sign
    # the long stick stays, the reversal P -> S -> N (across the period end) goes
    assert _names("NNSSPPSN")[1] == "NSP"


def test_reversal_across_the_period_start():
    runs, mode = _names("SPPPNNNN")
    h = TWO_PI / 8
    assert mode == "NP"
    # the N run of the previous period reaches tau = 0, the reversal is mid-step
    assert runs == [[0.0, "N"], [pytest.approx(0.5 * h), "P"], [pytest.approx(4 * h), "N"]]


def test_merge_step_regimes_rejects_mismatched_times():
    with pytest.raises(InputError, match=r"`taus` must have one entry per step"):
        merge_step_regimes("NNP", [0.0, 1.0], 1.0)


# -- discrete-map steady state ----------------------------------------------------------

@pytest.fixture(scope="module")
def ss185():
    return moreau_jean_steady_state(FrictionDrive(frequency=185.0), 1000)


def test_steady_state_is_a_fixed_point_of_the_simulated_map(ss185):
    sc = FrictionDrive(frequency=185.0)
    x = ss185.state0
    assert ss185.scheme == "moreau-jean" and ss185.periodic_residual <= 1e-12
    res = simulate(sc, (0.0, 3 * TWO_PI), [x[0], 0.0], x[1:], "moreau-jean", h=TWO_PI / 1000,
                   projection=True, save_every=1000)
    # the integrator starts with the contact flag open, so compare from period 1 on
    per = res.q[1:, 1]
    np.testing.assert_allclose(np.diff(per), ss185.displacement_per_period, rtol=1e-10)
    np.testing.assert_allclose(res.v[-1], x[1:], atol=1e-12 * sc.u10)
    st = ss185.stats
    assert st["steps"] == st["period_maps"] * 1000 and 0.9 * st["steps"] < st["lcp_solves"] <= st["steps"]
    assert st["lcp_solves"] > 0 and st["fallbacks"] == 0 and st["max_penetration"] < 1e-14
    assert 0.0 <= st["period_map_slope"] < 0.2
    assert ss185.mode == "NP" and ss185.regimes[0] == [0.0, "N"]
    assert ss185.min_normal_force > 0.0


def test_compiled_and_generic_period_maps_give_the_same_steady_state():
    sc = FrictionDrive(frequency=185.0)
    a = moreau_jean_steady_state(sc, 150, fast=True)
    b = moreau_jean_steady_state(sc, 150, fast=False)
    assert a.mode == b.mode
    assert a.displacement_per_period == pytest.approx(b.displacement_per_period, rel=1e-10)
    np.testing.assert_allclose(a.state0, b.state0, rtol=0, atol=1e-12)


def test_steady_state_argument_checks():
    sc = FrictionDrive(frequency=185.0)
    with pytest.raises(InputError, match=r"`steps_per_period` must be an integer >= 1"):
        moreau_jean_steady_state(sc, 0)
    with pytest.raises(InputError, match=r"`theta` must be in \[0.5, 1.0\]"):
        moreau_jean_steady_state(sc, 100, theta=2.0)
    with pytest.raises(InputError, match=r"`tol` must be > 0"):
        moreau_jean_steady_state(sc, 100, tol=-1.0)
    with pytest.raises(InputError, match=r"`x_guess` must have shape \(3\)"):
        moreau_jean_steady_state(sc, 100, x_guess=[0.7, 0.0])


def test_without_projection_the_map_has_no_fixed_point():
    # the closed contact's gap creeps open by O(h) per period, so phi never repeats
    with pytest.raises(ConvergenceError, match=r"try projection=True"):
        moreau_jean_steady_state(FrictionDrive(frequency=20.0), 200, projection=False)


def test_iteration_limit_is_reported():
    with pytest.raises(ConvergenceError, match=r"did not converge in `max_iter`"):
        moreau_jean_steady_state(FrictionDrive(frequency=2000.0), 500, max_iter=2)


def test_docstring_examples_run():
    import doctest

    import moreau.analysis.mj_steady_state as mss
    import moreau.compiled as cm
    for mod in (mss, cm):
        assert doctest.testmod(mod, verbose=False).failed == 0


# -- acceptance against the event-driven reference (issue #4) ---------------------------

from moreau.analysis.steady_state import find_steady_state  # noqa: E402


@pytest.fixture(scope="module")
def references():
    return {f: find_steady_state(FrictionDrive(frequency=f)) for f in (20.0, 185.0, 2000.0)}


def _rel(ss, ref):
    return abs(ss.displacement_per_period - ref.displacement_per_period) / abs(
        ref.displacement_per_period)


@pytest.mark.parametrize("freq", [20.0, 185.0])
def test_steady_state_matches_the_reference_at_2000_steps(references, freq):
    ref = references[freq]
    ss = moreau_jean_steady_state(FrictionDrive(frequency=freq), 2000)
    assert ss.mode == ref.mode            # NS at 20 Hz, NP at 185 Hz
    assert _rel(ss, ref) < 1e-3           # measured 8.2e-4 and 3.0e-4
    # regime changes within a few steps of the reference's event times
    assert [s for _, s in ss.regimes] == [s for _, s in ref.regimes]
    h = TWO_PI / 2000
    for (t, _), (tr, _) in zip(ss.regimes, ref.regimes):
        assert abs(t - tr) < 3 * h


def test_2000_hz_is_barely_contracting_and_converges_slowly(references):
    ref = references[2000.0]
    sc = FrictionDrive(frequency=2000.0)
    errs = {}
    for n in (2000, 4000, 8000, 16000):
        ss = moreau_jean_steady_state(sc, n)
        assert ss.mode == ref.mode == "NP"
        errs[n] = _rel(ss, ref)
        # slope of the period map on the continuous scale: about 0.987
        assert 0.95 < ss.stats["period_map_slope"] < 1.0
    # measured 7.1e-3, 3.4e-3, 1.8e-3, 8.1e-4
    assert errs[2000] < 2e-2 and errs[4000] < 2e-2
    assert errs[8000] < 5e-3 and errs[16000] < 5e-3


def test_first_order_convergence_of_the_trajectory_at_185_hz():
    # the displacement per period converges erratically (the O(h) error of
    # each slip reversal depends on where it falls inside its step), so the
    # order is fitted on the trajectory error over one period from a common
    # start state, sampled on the coarsest grid
    sc = FrictionDrive(frequency=185.0)
    x0 = moreau_jean_steady_state(sc, 1000).state0
    q0, v0 = [x0[0], 0.0], x0[1:]
    m = 250
    ref = simulate(sc, (0.0, TWO_PI), q0, v0, "event-driven", samples_per_period=m)
    grid = np.arange(m + 1) * TWO_PI / m
    idx = np.searchsorted(ref.t, grid - 1e-12)
    np.testing.assert_allclose(ref.t[idx], grid, atol=1e-12)
    ns = np.array([250, 500, 1000, 2000, 4000, 8000])
    errs = []
    for n in ns:
        r = simulate(sc, (0.0, TWO_PI), q0, v0, "moreau-jean", h=TWO_PI / n, projection=True,
                     save_every=n // m)
        errs.append(np.max(np.abs(r.q[:, 1] - ref.q[idx, 1])) / sc.u10)
    order = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
    assert 0.8 < order < 1.3              # measured 1.00
    assert errs[-1] < 2e-3


@pytest.mark.parametrize("theta, bound", [(1.0, 0.15), (0.5, 0.05)])
def test_stiff_spring_at_20_hz_with_100_steps_per_period(references, theta, bound):
    # P ~ 3.2e4: h^2 P ~ 125 per step, yet both theta stay bounded
    sc = FrictionDrive(frequency=20.0)
    assert sc.P > 3e4
    res = mj(sc, 20, 100, theta=theta, projection=True)
    assert res.success and np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.v))
    vtip = sc.u10 / math.cos(sc.phi0)
    assert np.max(np.abs(res.v)) < 2.0 * vtip
    ref = references[20.0]
    ss = moreau_jean_steady_state(sc, 100, theta=theta)
    assert ss.mode == ref.mode == "NS"
    assert _rel(ss, ref) < bound          # measured 13 % (theta = 1) and 3.5 % (theta = 1/2)
    per = res.q[::100, 1]
    assert abs(per[-1] - per[-2] - ss.displacement_per_period) < 1e-9
