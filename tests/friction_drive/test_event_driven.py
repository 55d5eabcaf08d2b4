"""The event-driven reference: steady states, sweeps, transient runs, ill-posed cases."""

import math

import numpy as np
import pytest

from moreau.analysis.steady_state import find_steady_state
from moreau.errors import InputError, MoreauError, PainleveError
from moreau.integrators import simulate
from moreau.integrators.result import Event
from moreau.scenes.friction_drive.walker import ContactState, FrictionDriveWalker
from moreau.regimes import Regime
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams
from moreau.model.registry import make_scene

TWO_PI = 2 * math.pi


def steady(f, **kw):
    return find_steady_state(FrictionDrive(FrictionDriveParams(**kw), frequency=f))


def sweep(values, f=None, name=None):
    out = []
    for x in values:
        if name is None:
            ss = steady(x)
        else:
            ss = steady(f, **{name: x})
        out.append(ss)
    return out


def mode_sequence(results):
    seq = []
    for r in results:
        if not seq or seq[-1] != r.mode:
            seq.append(r.mode)
    return seq


# -- acceptance 2: frequency sweep (paper section 4.3) --------------------------

@pytest.fixture(scope="module")
def frequency_sweep():
    fs = np.geomspace(10.0, 12500.0, 120)
    return fs, sweep(fs)


def test_frequency_sweep_modes(frequency_sweep):
    fs, res = frequency_sweep
    seq = mode_sequence(res)
    # NS at low frequency, through NPS to NP (a narrow NSPS band precedes NPS)
    assert seq[0] == "NS" and seq[-1] == "NP"
    assert "NPS" in seq and seq.index("NPS") < seq.index("NP")
    assert set(seq) <= {"NS", "NSPS", "NPS", "NP"}


def test_frequency_sweep_displacement_shape(frequency_sweep):
    fs, res = frequency_sweep
    d = np.array([r.displacement_per_period for r in res])
    i = int(np.argmin(d))
    assert 165.0 < fs[i] < 195.0  # paper: minimum near 180 Hz
    assert abs(d[0]) < 0.02 * abs(d[i])  # tends to zero as f -> 0
    neg = fs < 400
    assert np.all(d[neg] < 0)
    hi = d[fs > 3000]
    assert np.all(hi > 0)
    # positive plateau: the last decade varies by a few percent only
    assert np.ptp(hi) < 0.05 * hi.mean()
    # valid range: f_N > 0 all period and no flight over the whole sweep
    assert all(r.min_normal_force > 0 for r in res)
    assert all("F" not in r.mode for r in res)


def test_minimum_frequency_refined():
    from scipy.optimize import minimize_scalar
    r = minimize_scalar(lambda f: steady(f).displacement_per_period, bounds=(165, 195),
                        method="bounded", options={"xatol": 0.05})
    assert 178.0 < r.x < 183.0


# -- acceptance 3: mu and phi0 sweeps -------------------------------------------

MUS = np.linspace(0.01, 0.99, 50)


def test_mu_sweep_20Hz():
    res = sweep(MUS, 20.0, "mu")
    assert mode_sequence(res) == ["NS"]
    d = np.array([r.displacement_per_period for r in res])
    assert np.all(d < 0)
    assert np.all(np.diff(d) > 0)  # approaches zero monotonically as mu grows
    assert abs(d[-1]) < 1e-3 * abs(d[0])


def test_mu_sweep_185Hz():
    mus = np.linspace(0.01, 0.4, 40)
    res = sweep(mus, 185.0, "mu")
    assert mode_sequence(res) == ["NP", "NPS", "NSPS", "NS"]
    d = np.array([r.displacement_per_period for r in res])
    assert np.all(d < 0)
    # paper: minimum at mu = 0.13; this model gives 0.11 to 0.12
    assert 0.09 <= mus[int(np.argmin(d))] <= 0.14


def test_mu_sweep_2000Hz():
    res = sweep(MUS, 2000.0, "mu")
    assert mode_sequence(res) == ["NP", "NSP", "SP"]
    d = np.array([r.displacement_per_period for r in res])
    assert np.all(d > 0)
    assert 0.85 <= MUS[int(np.argmax(d))] <= 0.93  # paper: maximum at mu = 0.89


# valid phi0 range at mu = 0.1: f_N > 0 at tau = 0 needs D < 0 there, i.e.
# 3/2 cos^2(phi0) < 1, phi0 > arccos(sqrt(2/3)) = 0.6155; Painlevé needs
# phi0 < atan(1/mu) = 1.4711
PHI_LO = math.acos(math.sqrt(2.0 / 3.0))
PHI_HI = math.atan(10.0)


def test_phi0_sweep_20Hz():
    phis = np.linspace(0.63, 1.46, 40)
    res = sweep(phis, 20.0, "phi0")
    assert mode_sequence(res) == ["NS"]
    d = np.array([r.displacement_per_period for r in res])
    assert abs(phis[int(np.argmin(d))] - 1.42) < 0.04  # paper: minimum at 1.42


def test_phi0_sweep_185Hz():
    phis = np.linspace(0.64, 1.2, 57)
    res = sweep(phis, 185.0, "phi0")
    seq = mode_sequence(res)
    assert seq == ["NPS", "NP"]
    d = np.array([r.displacement_per_period for r in res])
    assert abs(phis[int(np.argmin(d))] - 0.84) < 0.03  # paper: minimum at 0.84


def test_phi0_sweep_2000Hz():
    phis = np.linspace(0.63, 1.36, 30)
    res = sweep(phis, 2000.0, "phi0")
    assert mode_sequence(res) == ["NP"]
    d = np.array([r.displacement_per_period for r in res])
    assert np.all(np.diff(d) > 0)  # increases monotonically with phi0


def test_valid_range_edges():
    # inside: contact all period with f_N > 0
    for f in (20.0, 185.0, 2000.0):
        assert steady(f, phi0=PHI_LO + 0.01).min_normal_force > 0
    # below the lower edge the rod lifts off near tau = 0: flight and an impact appear
    ss = steady(185.0, phi0=PHI_LO - 0.05)
    assert "F" in ss.mode and "!" in ss.mode and ss.min_normal_force == 0.0
    # above the Painlevé edge the run stops with an error that names the cause
    with pytest.raises(PainleveError, match="Painlevé condition 1 - mu\\*tan\\(phi\\) > 0 fails"):
        steady(185.0, phi0=PHI_HI + 0.01)
    with pytest.raises(PainleveError, match="Painlevé"):
        steady(20.0, mu=1.0 / math.tan(math.pi / 4) + 0.02)
    # at 2000 Hz contact is lost before phi0 reaches the Painlevé edge
    ss = steady(2000.0, phi0=1.38)
    assert "F" in ss.mode


# -- acceptance 4 and 5: tolerance and transient -------------------------------

@pytest.mark.parametrize("f", [20.0, 185.0, 2000.0, 12500.0])
def test_tolerance_tightening(f):
    sc = FrictionDrive(frequency=f)
    a = find_steady_state(sc, rtol=1e-10)
    b = find_steady_state(sc, rtol=1e-11)
    ref = find_steady_state(sc, rtol=1e-13)
    assert a.periodic_residual <= 1e-10 and b.periodic_residual <= 1e-11
    assert abs(a.displacement_per_period - b.displacement_per_period) <= \
        1e-9 * abs(b.displacement_per_period)
    # also against a much tighter run: the stopping test bounds the distance to the
    # fixed point, not only the residual, which matters where the map barely contracts
    assert abs(a.displacement_per_period - ref.displacement_per_period) <= \
        1e-9 * abs(ref.displacement_per_period)


@pytest.mark.parametrize("f, periods", [(20.0, 5), (185.0, 120)])
def test_transient_reaches_shooting_solution(f, periods):
    sc = FrictionDrive(frequency=f)
    ss = find_steady_state(sc, rtol=1e-12)
    w = FrictionDriveWalker(sc)
    q0, v0 = sc.rest_state()
    st = w.classify(ContactState(0.0, Regime.FLIGHT, q0[0], v0[0], q0[1], v0[1]))
    st = w.advance(st, TWO_PI * periods)
    u_start = st.u2
    st = w.advance(st, TWO_PI * (periods + 1))
    assert abs((st.u2 - u_start) - ss.displacement_per_period) <= 1e-8 * abs(ss.displacement_per_period)


def test_simulate_records_time_histories():
    sc = FrictionDrive(frequency=185.0)
    q0, v0 = sc.rest_state()
    res = simulate(sc, (0.0, 3 * TWO_PI), q0, v0, "event-driven", samples_per_period=64)
    assert res.success and res.status == 0 and res.scheme == "event-driven"
    assert res.t[0] == 0.0 and res.t[-1] == pytest.approx(3 * TWO_PI)
    assert np.all(np.diff(res.t) >= 0)
    assert len(res.events) >= 5
    # contact all the time: zero gap, positive normal force, Coulomb law in slip
    assert np.max(np.abs(res.gap)) < 1e-13
    assert np.all(res.force_N > 0)
    slip = res.slip_velocity[:, 0]
    reg = res.regime[:, 0]
    fT, fN = res.force_T[:, 0], res.force_N[:, 0]
    pos = reg == Regime.POSITIVE
    neg = reg == Regime.NEGATIVE
    assert np.all(slip[pos] >= -1e-15) and np.all(slip[neg] <= 1e-15)
    assert np.allclose(fT[pos], -0.1 * fN[pos]) and np.allclose(fT[neg], 0.1 * fN[neg])
    si = sc.to_si(res)
    assert si["t"][-1] == pytest.approx(3 / 185.0)
    assert np.all(np.isfinite(si["x2"]))


def test_event_times_are_roots_to_machine_precision():
    sc = FrictionDrive(frequency=185.0)
    w = FrictionDriveWalker(sc)
    q0, v0 = sc.rest_state()
    st = w.classify(ContactState(0.0, Regime.FLIGHT, q0[0], v0[0], q0[1], v0[1]))
    for _ in range(6):
        start = st.copy()
        st, ev = w.segment(st, 1e9)
        if start.regime in (Regime.POSITIVE, Regime.NEGATIVE):
            end = w.move_contact(start, ev.t)
            slip = end.du2 - w.vtip(ev.t)
            assert abs(slip) < 1e-14 * w.vscale * 10


def test_impacts_with_restitution_and_flight():
    # below the lower phi0 edge the rod lifts off every period; with e > 0 it bounces
    sc = FrictionDrive(FrictionDriveParams(phi0=0.5, restitution=0.5), frequency=185.0)
    q0, v0 = sc.rest_state()
    res = simulate(sc, (0.0, 3 * TWO_PI), q0, v0, "event-driven")
    assert res.success
    kinds = {e.kind for e in res.events}
    assert "impact" in kinds and "liftoff" in kinds
    assert np.min(res.gap) > -1e-12  # no penetration
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.v))
    # Newton's law: at each impact the normal velocity flips with factor e
    assert res.stats["impacts"] >= 2


def test_simulate_bad_input():
    sc = FrictionDrive(frequency=185.0)
    q0, v0 = sc.rest_state()
    with pytest.raises(InputError, match="`t_bound` must be > `t0`"):
        simulate(sc, (1.0, 0.0), q0, v0, "event-driven")
    with pytest.raises(InputError, match="`q0` must have shape"):
        simulate(sc, (0.0, 1.0), [1.0], v0, "event-driven")
    with pytest.raises(InputError, match="`v0` must contain only finite"):
        simulate(sc, (0.0, 1.0), q0, [np.nan, 0.0], "event-driven")
    with pytest.raises(InputError, match="`method` must be one of"):
        simulate(sc, (0.0, 1.0), q0, v0, "runge-kutta")
    with pytest.raises(InputError, match="penetrates"):
        simulate(sc, (0.0, 1.0), [sc.phi0 + 0.1, 0.0], v0, "event-driven")


@pytest.mark.parametrize("f", [20.0, 185.0])
def test_min_normal_force_is_the_analytic_value_at_tau_0(f):
    # in negative slip at tau = 0 (u1 = u1' = 0, u1'' = u10): f_N = u10 (1/(3c) - c/2) / (c - mu s)
    ss = steady(f)
    c = s = math.cos(math.pi / 4)
    exact = 2e-3 * (1 / (3 * c) - c / 2) / (c - 0.1 * s)
    assert ss.min_normal_force == pytest.approx(exact, rel=1e-9)


def test_steady_state_with_flight_at_the_first_section():
    # at 2000 Hz and phi0 = 1.43 the rod flies at the phase of strongest pressing;
    # the section moves into a contact segment and the orbit is still found
    sc = FrictionDrive(FrictionDriveParams(phi0=1.43), frequency=2000.0)
    ss = find_steady_state(sc)
    assert "F" in ss.mode and "!" in ss.mode
    assert ss.periodic_residual < 1e-10
    w = FrictionDriveWalker(sc)
    # the recorded start lies on the orbit: one more period reproduces the displacement
    phi, dphi, du2 = ss.state0
    t0 = ss.section_tau
    st = w.classify(ContactState(t0, Regime.FLIGHT, phi, dphi, 0.0, du2))
    end = w.advance(st, t0 + TWO_PI)
    assert end.u2 == pytest.approx(ss.displacement_per_period, rel=1e-9)
    assert end.du2 == pytest.approx(du2, rel=1e-9)


def test_grazing_return_inside_one_flight_step_is_found():
    # a flight whose gap dips below zero between 0.4 and 0.6 and is positive at both
    # ends of its only step: the step-end sign test sees nothing, the dense check does
    sc = FrictionDrive(frequency=185.0)
    w = FrictionDriveWalker(sc)

    def gap_wanted(t):
        return 1e-6 * (t - 0.4) * (t - 0.6)

    class FakeSolution:
        status = 0
        t = np.array([0.0, 1.0])

        @staticmethod
        def sol(t):
            t = np.asarray(t, float)
            phi = np.arcsin(sc.sin_phi0 - sc.u1(t) - gap_wanted(t))
            return np.array([phi, 0 * t, 0 * t, 0 * t])

    te, ye = w._missed_recontact(FakeSolution)
    # the root is as sharp as the gap's round-off (~1e-16) over its slope (2e-7)
    assert te == pytest.approx(0.4, abs=2e-9)
    assert abs(w._gap(te, ye)) < 1e-15
    # no dip: nothing reported
    FakeSolution.sol = staticmethod(lambda t: np.array(
        [np.arcsin(sc.sin_phi0 - sc.u1(np.asarray(t, float)) - 1e-6), 0 * np.asarray(t, float),
         0 * np.asarray(t, float), 0 * np.asarray(t, float)]))
    assert w._missed_recontact(FakeSolution) is None


def test_a_zeno_sequence_closes_the_contact_instead_of_sinking_into_the_rotor():
    # found by the bifurcation diagram across lift-off: 18 impacts accumulate at
    # tau = 0.354255 (e = 0.5); the last rebound's height, vN^2 / 2|D| ~ 2e-17, is below
    # the gap's rounding, so the flight after it never cleared the surface and, before
    # the fix, sank to a gap of -7.3e-4 without a re-contact, recorded as flight
    sc = make_scene("friction-drive", frequency=19932.0, restitution=0.5)
    q = np.array([0.7853952788115945, 0.0])
    v = np.array([-3.255885351047966e-05, 0.0001433357870032927])
    r = simulate(sc, (0.0, 2 * np.pi), q, v, "event-driven", samples_per_period=4096)
    assert r.success
    assert r.gap[:, 0].min() > -1e-15
    kinds = [e.kind for e in r.events]
    # how many rebounds are resolved before the accumulation point depends on the
    # last bits of the arithmetic (18 on one machine, 19 on another); the physics
    # asserted is: a run of impacts, then a touchdown at the accumulation time
    n = kinds.index("touchdown")
    assert 15 <= n <= 25 and kinds[:n] == ["impact"] * n
    assert r.events[n].t == pytest.approx(0.3542556, abs=5e-6)
    # the rod then rides the stator until it lifts off again
    assert kinds[n + 1] == "liftoff" and r.events[n + 1].t == pytest.approx(1.8043, abs=1e-3)


def test_a_walk_that_stops_advancing_time_fails_instead_of_growing_for_ever(monkeypatch):
    # the stress catalogue's flight at 15 kHz, e = 0.5 (full budget): the walk came back to
    # one time step after step, recording a sample and an event each time, and grew past
    # 10 GB; a run whose events stop advancing time now fails and says where
    sc = make_scene("friction-drive", frequency=185.0)
    q0, v0 = sc.rest_state()
    real = FrictionDriveWalker.segment

    def stuck(self, st, tau_end, on_segment=None):
        if st.tau > 1.0:
            # an event that leaves the state where it was
            return st.copy(), Event(st.tau, "touchdown", Regime(int(st.regime)), st.regime)
        return real(self, st, tau_end, on_segment)

    monkeypatch.setattr(FrictionDriveWalker, "segment", stuck)
    r = simulate(sc, (0.0, 2 * np.pi), q0, v0, "event-driven")
    assert not r.success
    assert "makes no progress: 1001 events in a row at tau = " in r.message
    assert len(r.events) < 1100
    # the walker's own advance (shooting, section runs) stops the same way, not after
    # its budget of 100 000 events
    w = FrictionDriveWalker(sc)
    st = w.classify(ContactState(0.0, Regime.FLIGHT, q0[0], v0[0], q0[1], v0[1]))
    seen = []
    with pytest.raises(MoreauError, match="makes no progress: 1001 events in a row"):
        w.advance(st, 2 * np.pi, on_event=seen.append)
    assert len(seen) < 1100


def test_a_rebound_of_zero_length_closes_the_contact_instead_of_starting_again():
    # the state where the stress catalogue's flight (15 kHz, e = 0.5, 80000-period budget)
    # stuck after 1574 impacts: the flight after the rebound met the surface where it began
    # (gap -6e-17), leaving vN = +4.7e-12, which started the same rebound again at every step
    sc = make_scene("friction-drive", frequency=15000.0, restitution=0.5)
    w = FrictionDriveWalker(sc)
    w._rebound_skip, w.n_impacts = 1.2773964195003628e-07, 1574
    st = ContactState(1434.6198036658463, Regime.FLIGHT, 0.7812652437144626,
                      -0.0024948997538827874, 1.6235401166723877, 0.0011394734980324718)
    end, ev = w.segment(st, 3141.592653589793)
    assert ev.kind == "touchdown" and end.tau == st.tau and end.regime != Regime.FLIGHT
    # and the walk goes on: a whole period, with its flights and impacts
    later = w.advance(end, end.tau + TWO_PI)
    assert later.tau == pytest.approx(end.tau + TWO_PI) and w.counters["impacts"] >= 1


def test_an_elastic_rod_that_bounces_every_period_runs_past_max_impacts():
    # 15 kHz, e = 1: one impact a drive period. The walker used to count `max_impacts`
    # over the whole run, so a walk of more than 10 000 periods failed (and its 10 000th
    # impact was silently made plastic); the count is now per drive period
    sc = make_scene("friction-drive", frequency=15000.0, restitution=1.0)
    q0, v0 = sc.rest_state()
    capped = FrictionDriveWalker(sc, max_impacts=3)
    free = FrictionDriveWalker(sc)
    a = capped.classify(ContactState(0.0, Regime.FLIGHT, q0[0], v0[0], q0[1], v0[1]))
    b = free.classify(ContactState(0.0, Regime.FLIGHT, q0[0], v0[0], q0[1], v0[1]))
    a = capped.advance(a, 40 * 2 * np.pi)
    b = free.advance(b, 40 * 2 * np.pi)
    assert capped.counters["impacts"] > 35
    assert capped.counters["impacts"] == free.counters["impacts"]
    assert (a.phi, a.dphi, a.u2, a.du2) == (b.phi, b.dphi, b.u2, b.du2)


def test_the_walker_steady_state_without_multipliers_is_the_same_orbit():
    # `floquet=False` (compare's references, which need the value only) used to reach the
    # walker's constructor as an unknown option: a bare TypeError
    sc = FrictionDrive(frequency=185.0)
    a = find_steady_state(sc)
    b = find_steady_state(sc, floquet=False)
    assert a.floquet_multipliers is not None and b.floquet_multipliers is None
    assert b.displacement_per_period == a.displacement_per_period
    np.testing.assert_array_equal(b.state0, a.state0)
