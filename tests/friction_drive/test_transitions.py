"""Every generic regime transition of the friction drive, located and checked at the event.

Eleven of the paper's twelve transitions occur for generic data. Stick to flight
needs f_N and f_T to vanish at the same instant (otherwise the friction cone,
which shrinks with f_N, is left first and stick turns into slip before lift-off),
so it does not occur generically.
"""

import math

import pytest

from moreau.scenes.friction_drive.walker import ContactState, FrictionDriveWalker
from moreau.regimes import Regime
from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams

F, P, N, S = Regime.FLIGHT, Regime.POSITIVE, Regime.NEGATIVE, Regime.STICK


def events_from_rest(periods, f, **kw):
    sc = FrictionDrive(FrictionDriveParams(**kw), frequency=f)
    w = FrictionDriveWalker(sc)
    st = w.classify(ContactState(0.0, F, sc.phi0, 0.0, 0.0, 0.0))
    evs = []
    w.advance(st, 2 * math.pi * periods, on_event=evs.append)
    return sc, w, evs


def events_from_flight(du2, f=185.0, mu=0.5, tau=1.0):
    sc = FrictionDrive(FrictionDriveParams(mu=mu), frequency=f)
    w = FrictionDriveWalker(sc)
    phi_c, _ = w.manifold(tau)
    st = w.classify(ContactState(tau, F, phi_c - 1e-5, 0.05, 0.0, w.vtip(tau) + du2))
    assert st.regime == F
    evs = []
    w.advance(st, tau + 1.5, on_event=evs.append)
    return sc, w, evs


def pairs(evs):
    return {(e.before, e.after): e for e in evs}


def test_contact_transitions_and_liftoff_at_low_tilt():
    sc, w, evs = events_from_rest(2, 20.0, phi0=0.3)
    p = pairs(evs)
    for key in [(F, N), (N, F), (N, S), (S, N)]:
        assert key in p, key
    # lift-off: the normal force of the regime vanishes at the event
    e = p[(N, F)]
    assert e.kind == "liftoff"
    assert abs(w.fN(e.t, N)) < 1e-12 * w.fscale
    # stick end towards negative slip: f_T reaches +mu f_N
    e = p[(S, N)]
    fN, _, margin = w.stick_margins(e.t)
    assert abs(margin) < 1e-12 * w.fscale and fN > 0
    # impact back into contact: plastic, so the rod ends on the contact manifold
    assert p[(F, N)].kind == "impact"


def test_slip_reversals_and_liftoff_from_positive_slip():
    _, w, evs = events_from_rest(2, 2000.0, phi0=0.3)
    p = pairs(evs)
    assert (N, P) in p and (P, F) in p
    _, _, evs = events_from_rest(2, 185.0, phi0=0.8)
    assert (P, N) in pairs(evs)


def test_stick_and_positive_slip_exchange():
    _, w, evs = events_from_rest(20, 2000.0, mu=0.98)
    p = pairs(evs)
    assert (S, P) in p and (P, S) in p
    e = p[(S, P)]
    _, margin, _ = w.stick_margins(e.t)
    assert abs(margin) < 1e-12 * w.fscale  # f_T = -mu f_N when positive slip starts


@pytest.mark.parametrize("du2, after", [(0.05, P), (-0.05, N), (0.0, S)])
def test_impacts_into_each_contact_regime(du2, after):
    sc, w, evs = events_from_flight(du2)
    first = evs[0]
    assert first.kind == "impact" and first.before == F and first.after == after


def test_a_lift_off_at_the_lower_edge_is_a_hop_that_ends_in_an_impact():
    # just below the lower phi0 edge the rod leaves near tau = 0 with zero normal
    # velocity, hops by about 1e-11 and comes back with an impact 3.2e-3 later. With
    # SciPy's DOP853 the hop's first microseconds, where the gap is at its rounding
    # (1e-17), once read as a touchdown; the Taylor flight and DOP853 agree on the impacts
    sc, _, evs = events_from_rest(3, 20.0, phi0=0.6)
    lifts = [i for i, e in enumerate(evs) if e.kind == "liftoff"]
    assert len(lifts) >= 2
    for i in lifts[:-1]:        # the last lift-off is within 1e-3 of the run's end
        nxt = evs[i + 1]
        assert nxt.kind == "impact" and 0.0 < nxt.t - evs[i].t < 1e-2
    w = FrictionDriveWalker(sc, flight_method="dop853")
    st = w.classify(ContactState(0.0, F, sc.phi0, 0.0, 0.0, 0.0))
    ref = []
    w.advance(st, 2 * math.pi * 3, on_event=ref.append)
    impacts = [e.t for e in evs if e.kind == "impact"]
    # the return of a 1e-11 hop is ill-conditioned: DOP853's impact times move by 1e-8
    # between rtol 1e-12 and 1e-14, while the Taylor series' do not move at all
    assert impacts == pytest.approx([e.t for e in ref if e.kind == "impact"], abs=2e-8)


def test_returning_point():
    # the paper's returning point: the rod comes back to the rotor tangentially (zero
    # normal velocity) where the free normal acceleration D > 0 holds it off, so the
    # touchdown leaves it in flight. A tangential return is not generic, so the flight
    # that ends on it is given: at 15 kHz, tau = pi, where D is largest
    sc = FrictionDrive(frequency=15000.0)
    w = FrictionDriveWalker(sc)
    tau = math.pi
    phi, dphi = w.manifold(tau)
    assert sc.coefficients(phi, dphi, tau)[3] > 1e-4
    start = ContactState(tau - 0.1, F, phi, dphi, 0.0, 0.0)

    def flight(st, tau_end, dense=False):
        return ContactState(tau, F, phi, dphi, 0.0, 0.0), True, None

    w.flight = flight
    end, ev = w.segment(start, tau + 1.0)
    assert ev.kind == "touchdown" and ev.before == F and ev.after == F
    assert end.regime == F and end.tau == tau


def test_painleve_at_the_start_is_a_status():
    from moreau.integrators import simulate
    sc = FrictionDrive(FrictionDriveParams(phi0=1.5), frequency=185.0)
    q0, v0 = sc.rest_state()
    res = simulate(sc, (0.0, 1.0), q0, v0, "event-driven")
    assert res.status == -1 and not res.success
    assert "Painlevé condition" in res.message and len(res.t) == 0
