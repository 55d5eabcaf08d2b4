"""The friction drive's flights by compiled Taylor series, against SciPy's DOP853.

The Taylor coefficients come from the recurrences of automatic
differentiation (``moreau/scenes/friction_drive/_flight_taylor.py``); the independent
computation is SciPy's DOP853 on the walker's own right-hand side at its
tightest tolerance.
"""

import math
from dataclasses import asdict

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from moreau.regimes import Regime
from moreau.scenes import make_scene
from moreau.scenes.friction_drive import PAPER_DEFAULTS
from moreau.scenes.friction_drive.walker import ContactState, FrictionDriveWalker

F = Regime.FLIGHT
TWO_PI = 2.0 * math.pi


def _reference(w, st, tau_end, events=True):
    def gap(t, y):
        return w._gap(t, y)

    gap.terminal, gap.direction = True, -1
    return solve_ivp(w._flight_rhs, (st.tau, tau_end), [st.phi, st.dphi, st.u2, st.du2],
                     method="DOP853", rtol=1e-13, atol=1e-18, dense_output=True,
                     events=gap if events else None)


def test_a_long_flight_matches_dop853_at_its_tightest_tolerance():
    # thrown clear of the rotor, the rod swings out and back: the flight is compared up
    # to 90 % of the time of its return
    sc = make_scene("friction-drive", frequency=15000.0)
    w = FrictionDriveWalker(sc)
    st = ContactState(0.3, F, sc.phi0 - 0.05, 0.02, 0.1, -0.003)
    back = _reference(w, st, 0.3 + 100 * TWO_PI).t_events[0][0]
    t_end = 0.3 + 0.9 * (back - 0.3)
    assert t_end - 0.3 > 1.0
    end, hit, sol = w.flight(st, t_end, dense=True)
    ref = _reference(w, st, t_end, events=False)
    assert not hit and end.tau == t_end
    np.testing.assert_allclose([end.phi, end.dphi, end.u2, end.du2], ref.y[:, -1],
                               rtol=0, atol=2e-12)
    # the dense output between the steps, scalar and vector calls alike
    ts = np.linspace(st.tau, end.tau, 57)
    np.testing.assert_allclose(sol(ts), ref.sol(ts), rtol=0, atol=2e-12)
    np.testing.assert_allclose(sol(ts[7]), ref.sol(ts[7]), rtol=0, atol=2e-12)


def test_a_return_is_located_where_dop853_s_dense_output_crosses_zero():
    sc = make_scene("friction-drive", frequency=15000.0)
    w = FrictionDriveWalker(sc)
    phi_c, dphi_c = w.manifold(1.0)
    st = ContactState(1.0, F, phi_c - 2e-4, dphi_c + 0.004, 0.0, 0.0)
    end, hit, _ = w.flight(st, 1.0 + TWO_PI)
    ref = _reference(w, st, 1.0 + TWO_PI)
    assert hit and ref.status == 1
    te = brentq(lambda t: w._gap(t, ref.sol(t)), ref.t_events[0][0] - 1e-3,
                ref.t_events[0][0] + 1e-9, xtol=1e-15)
    assert end.tau == pytest.approx(te, abs=1e-11)
    assert abs(w._gap(end.tau, [end.phi, end.dphi])) < 1e-15
    assert end.dphi == pytest.approx(ref.sol(te)[1], abs=1e-11)


@pytest.mark.parametrize("method", ["taylor", "dop853"])
def test_twenty_periods_in_flight_agree_between_the_two_flight_methods(method):
    # 15 kHz at the paper's parameters: a lift-off and an impact every period
    sc = make_scene("friction-drive", frequency=15000.0)
    q0, v0 = sc.rest_state()
    runs = {}
    for m in ("taylor", method):
        w = FrictionDriveWalker(sc, flight_method=m)
        st = w.classify(ContactState(0.0, F, q0[0], v0[0], q0[1], v0[1]))
        evs = []
        end = w.advance(st, 20 * TWO_PI, on_event=evs.append)
        runs[m] = (end, evs)
    (a, ea), (b, eb) = runs["taylor"], runs[method]
    assert [e.kind for e in ea] == [e.kind for e in eb]
    # a lift-off and an impact every period; the 20th impact comes after the end
    assert sum(e.kind == "impact" for e in ea) == 19
    np.testing.assert_allclose([e.t for e in ea], [e.t for e in eb], rtol=0, atol=1e-10)
    np.testing.assert_allclose([a.phi, a.dphi, a.u2, a.du2], [b.phi, b.dphi, b.u2, b.du2],
                               rtol=0, atol=1e-12)


def test_a_lift_off_that_dop853_took_for_a_touchdown_for_ever_is_a_hop():
    # an atlas point (6724 Hz, phi0 = 1.1) where DOP853's first microseconds after a
    # lift-off read the gap's rounding as a return, and the walk alternated touchdown and
    # lift-off at one time 100 000 times (87 s) before failing; the Taylor flight hops
    sc = make_scene("friction-drive", frequency=6723.779,
                    **asdict(PAPER_DEFAULTS.with_(phi0=1.1)))
    q0, v0 = sc.rest_state()
    w = FrictionDriveWalker(sc)
    st = w.classify(ContactState(0.0, F, q0[0], v0[0], q0[1], v0[1]))
    evs = []
    w.advance(st, 20 * TWO_PI, on_event=evs.append)
    kinds = [e.kind for e in evs]
    assert kinds[:38] == ["liftoff", "impact"] * 19 and set(kinds[38:]) <= {"liftoff"}
    assert all(b.t - a.t > 1.0 for a, b in zip(evs, evs[1:]))


def test_an_unknown_flight_method_is_refused_by_name():
    with pytest.raises(ValueError, match="`flight_method` must be one of"):
        FrictionDriveWalker(make_scene("friction-drive", frequency=185.0), flight_method="rk4")


def test_the_walker_s_section_run_is_the_integrator_s_run_read_at_the_sections():
    # the classification's own run (no recording) against simulate's samples, in flight
    from moreau.integrators import simulate
    from moreau.scenes.friction_drive.steady import walker_section_states
    sc = make_scene("friction-drive", frequency=15000.0)
    q0, v0 = sc.rest_state()
    qs, vs = walker_section_states(sc, q0, v0, 0.0, 20, {})
    r = simulate(sc, (0.0, 20 * TWO_PI), q0, v0, "event-driven", samples_per_period=1)
    at = [int(np.argmin(abs(r.t - k * TWO_PI))) for k in range(21)]
    np.testing.assert_allclose(r.t[at], TWO_PI * np.arange(21), rtol=0, atol=1e-12)
    np.testing.assert_allclose(qs, r.q[at], rtol=0, atol=1e-13)
    np.testing.assert_allclose(vs, r.v[at], rtol=0, atol=1e-13)


def test_event_driven_section_runs_of_the_friction_drive_use_the_walker_s_own_run(monkeypatch):
    # "event-driven" names the scene's own reference: the statistical steady state and the
    # classification read the walker at the sections instead of simulate's recording
    import moreau.analysis.section_runs as runs

    def refuse(*a, **k):
        raise AssertionError("simulate was called")

    monkeypatch.setattr(runs, "simulate", refuse)
    sc = make_scene("friction-drive", frequency=15000.0)
    qs, vs, vmax = runs.section_states(sc, "event-driven", {"samples_per_period": 1}, 0.0,
                                       *sc.rest_state(), 5)
    assert qs.shape == vs.shape == (6, 2) and vmax == np.max(np.abs(vs))
