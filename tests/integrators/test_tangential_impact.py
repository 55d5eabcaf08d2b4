"""The tangential impact (dynamic jamming): every time-stepping contact step is solved.

Where a sliding contact meets the discrete Painlevé condition failing the way
it slides, the one-contact velocity-level problem still has exactly one
solution, the impulsive stick (``contact_problem.one_contact_impulse``'s
Notes). The schemes take it and record it, or stop with ``painleve="stop"``.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moreau.errors import InputError
from moreau.integrators import simulate
import moreau.contact.solvers._friction_lcp as friction_lcp
import moreau.integrators.contact_problem as cp
from moreau.integrators.contact_problem import (friction_pieces, one_contact_impulse,
                                                one_contact_residual, tangential_impact)
from moreau.lcp import (SECONDARY_RAY, LCPResult, build_friction_lcp, friction_impulses,
                        lcp_violation, solve_lcp)
from moreau.lcp.lemke import DEFAULT_TOL
from moreau.scenes.painleve_rod import PainleveRod

PHI_STAR = math.atan(2.0)


def rod_jam_closed_form(q, v):
    """Post-jam velocity of the rod from Newton-Euler with the tip's impulse (PT, PN).

    Half-length 1, unit mass, centroidal inertia 1/3, tip at (-cos phi, -sin phi)
    from the centre: m dv = (PT, PN), I dw = (-cos phi) PN - (-sin phi) PT; the
    impulse brings the tip's velocity (vx + w sin phi, vy - w cos phi) to zero.
    """
    c, s = math.cos(q[2]), math.sin(q[2])

    def tip_change(PT, PN):
        dv = np.array([PT, PN, 3.0 * (-c * PN + s * PT)])
        return np.array([dv[0] + s * dv[2], dv[1] - c * dv[2]])

    A = np.column_stack([tip_change(1.0, 0.0), tip_change(0.0, 1.0)])
    PT, PN = np.linalg.solve(A, -np.array([v[0] + s * v[2], v[1] - c * v[2]]))
    return v + np.array([PT, PN, 3.0 * (-c * PN + s * PT)]), PN, PT


@settings(deadline=None, max_examples=100)
@given(st.floats(-1.0, 1.0), st.floats(0.05, 3.0), st.floats(0.05, 3.0), st.floats(0.0, 0.99),
       st.floats(-2.0, 2.0), st.floats(-2.0, 2.0), st.floats(0.01, 20.0))
def test_one_contact_problem_always_has_its_solution(rho, a, d, frac, uN, uT, mu):
    # any positive definite W: W_NT = rho sqrt(W_NN W_TT) frac-scaled, |rho frac| < 1
    Wnt = rho * frac * math.sqrt(a * d)
    W = [[a, Wnt], [Wnt, d]]
    pN, pT = one_contact_impulse(W, [uN, uT], mu)
    res = one_contact_residual(a, Wnt, Wnt, d, uN, uT, mu, 0.0, 0.0, pN, pT)
    assert res <= 1e-12


def test_the_jam_is_the_stick_and_lemke_agrees():
    # W_NN - mu W_NT = -1 with positive slip: no sliding solution; stick p = -W^-1 (b, uT)
    W = np.array([[1.0, 2.0], [2.0, 5.0]])
    pN, pT = one_contact_impulse(W, [-1.0, 1.0], 1.0)
    assert (pN, pT) == (pytest.approx(7.0), pytest.approx(-3.0))
    M, q, layout = build_friction_lcp(W, [-1.0, 1.0], [1.0], 0.0)
    zN, zT = friction_impulses(solve_lcp(M, q, method="lemke").z, layout)
    assert (zN[0], zT[0]) == (pytest.approx(7.0), pytest.approx(-3.0))
    assert tangential_impact(W, [-1.0, 1.0], 1.0, 0.0, 0.0, 1.0)
    assert not tangential_impact(W, [-1.0, 1.0], 1.0, 0.0, 0.0, -1.0)   # the harmless way
    assert not tangential_impact(W, [0.1, 1.0], 1.0, 0.0, 0.0, 1.0)     # separating


@pytest.mark.parametrize("fast", [True, False])
@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_moreau_jean_takes_the_rods_jam_against_the_closed_form(h, fast):
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, -1.0)
    assert rod.painleve_indicator(q0, v0) == pytest.approx(-0.8)
    v_jam, PN, PT = rod_jam_closed_form(q0, v0)
    # closed form: PN = 3/10, PT = 2/5 (|PT| = 1.33 PN <= mu PN)
    assert (PN, PT) == (pytest.approx(0.3), pytest.approx(0.4))
    res = simulate(rod, (0.0, 5 * h), q0, v0, "moreau-jean", h=h, fast=fast)
    assert res.status == 0
    assert res.stats["tangential_impacts"] == 1 and res.stats["tangential_impact_times"] == [0.0]
    # the step adds gravity over h: O(h) from the impulsive limit (measured 0.335 h)
    assert np.max(np.abs(res.v[1] - v_jam)) <= 0.5 * h
    assert res.regime_letters()[1:] == "S" * 5


def test_painleve_stop_ends_the_run_there_and_bad_values_are_refused():
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, -1.0)
    res = simulate(rod, (0.0, 0.01), q0, v0, "moreau-jean", h=1e-3, painleve="stop")
    assert res.status == -1 and "tangential impact at t = 0.0 (painleve='stop')" in res.message
    with pytest.raises(InputError, match=r"`painleve` must be one of \['impulse', 'stop'\]"):
        simulate(rod, (0.0, 0.01), q0, v0, "moreau-jean", h=1e-3, painleve="jam")
    for scheme in ("schatzman-paoli", "nonsmooth-generalized-alpha"):
        for fast in (True, False):
            res = simulate(rod, (0.0, 0.01), q0, v0, scheme, h=1e-3, painleve="stop", fast=fast)
            assert res.status == -1 and "tangential impact" in res.message, (scheme, fast)


@pytest.mark.parametrize("scheme", ["schatzman-paoli", "nonsmooth-generalized-alpha"])
def test_other_schemes_take_the_jam(scheme):
    # before: SP stopped on the discrete Painlevé condition, NSGA raised FloatingPointError
    # naming the mass matrix (its consistent start acceleration met the indicator -0.8)
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, -1.0)
    h = 1e-3
    res = simulate(rod, (0.0, 10 * h), q0, v0, scheme, h=h, fast=False)
    assert res.status == 0
    assert res.stats["tangential_impacts"] == 1
    assert set(res.regime_letters()[1:]) == {"S"}
    if scheme == "nonsmooth-generalized-alpha":
        # (Schatzman-Paoli records the mean of the step's two velocities, not v_{n+1})
        v_jam, _, _ = rod_jam_closed_form(q0, v0)
        assert np.max(np.abs(res.v[1] - v_jam)) <= 2 * h


def test_event_driven_names_the_painleve_configuration():
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, -1.0)
    res = simulate(rod, (0.0, 0.05), q0, v0, "event-driven")
    assert res.status == -1
    assert res.message.startswith("Painlevé configuration at t = 0: contact 0 slides (N)")
    assert "-0.8 <= 0" in res.message and "tangential impact" in res.message


SIXTEENTHS = st.integers(-16, 16).map(lambda k: k / 16.0)


@settings(deadline=None, max_examples=30)
@given(st.lists(SIXTEENTHS, min_size=12, max_size=12), st.floats(0.05, 10.0),
       st.lists(SIXTEENTHS, min_size=3, max_size=3))
def test_the_piece_enumeration_solves_every_frictional_problem(entries, mu, v):
    # two frictional contacts on three dof (W = J M^-1 J^T singular, as a block on two
    # corners), e = 0, no rheonomic term: a solution exists; the enumeration finds it
    # and certifies it on the friction LCP (what Lemke's answer must pass). The theorem
    # is about exact data: J and v on a grid of sixteenths make W and U = J v exact in
    # floating point. Off the grid, rows 4e-16 apart give a W whose rounding alone
    # leaves the problem without a solution (the exact one needs an impulse of 1e15).
    J = np.array(entries).reshape(4, 3)
    J[0, 1] = J[1, 1] = 1.0             # normal rows that can push
    Minv = np.diag([1.0, 1.0, 3.0])
    W = J @ Minv @ J.T
    U = J @ np.array(v)
    z = friction_pieces(W, U, [mu, mu], [0.0, 0.0], [0.0, 0.0])
    assert z is not None
    M, q, _ = build_friction_lcp(W, U, [mu, mu], 0.0)
    assert lcp_violation(M, q, z) <= DEFAULT_TOL


@pytest.mark.parametrize("scheme", ["compliant-rk45"])
def test_compliant_schemes_note_the_paradoxical_configuration(scheme):
    rod = PainleveRod(mu=2.0)
    q0, v0 = rod.sliding_state(PHI_STAR, -1.0)
    res = simulate(rod, (0.0, 0.002), q0, v0, scheme)
    assert res.status == 0 and len(res.stats["painleve_paradox_times"]) == 1
    assert "slid in a Painlevé configuration" in res.message
    q0, v0 = rod.sliding_state(PHI_STAR, +1.0)          # the harmless way: no note
    res = simulate(rod, (0.0, 0.002), q0, v0, scheme)
    assert res.status == 0 and "painleve_paradox_times" not in res.stats


def test_a_secondary_ray_is_followed_by_the_certified_enumeration(monkeypatch):
    # the block flat on two corners (W singular), Lemke ending on a secondary ray (as a
    # float Lemke did on it, issue 33): the contact problem is still solved, by the
    # enumeration of the pieces, and certified

    def ray(M, q, **kw):
        r = solve_lcp(M, q, method="lemke", max_iter=1)
        return LCPResult(r.z, r.w, SECONDARY_RAY, r.pivots, r.residual, "lemke")

    monkeypatch.setattr(friction_lcp, "solve_lcp", ray)
    J = np.array([[0.0, 1.0, -0.5], [0.0, 1.0, 0.5], [1.0, 0.0, 1.0], [1.0, 0.0, 1.0]])
    W = J @ np.diag([1.0, 1.0, 2.4]) @ J.T
    c = cp.new_contact_counters()
    p, pN, pT = cp.solve_contact_problem(W, np.array([-0.1, -0.1, 0.0, 0.0]),
                                         np.array([10.0, 10.0]), np.zeros(2), np.zeros(2),
                                         lcp_method="lemke", counters=c)
    assert c["piece_enumerations"] == 1 and c["max_residual"] <= 1e-12
    U = np.array([-0.1, -0.1, 0.0, 0.0]) + W @ p
    assert np.max(np.abs(U)) <= 1e-14 and pN.sum() == pytest.approx(0.1)
