"""The friction drive stated with the planar builder against the hand-written drive: one set of equations."""

import math

import numpy as np
import pytest

from moreau.analysis.steady_state import find_steady_state
from moreau.integrators import simulate
from moreau.scenes.friction_drive import FrictionDrive
from moreau.scenes.friction_drive_built import friction_drive_built

#: the paper's two drive frequencies [Hz]
FREQUENCIES = (185.0, 2000.0)


def _pair(frequency, **params):
    return FrictionDrive(frequency=frequency, **params), friction_drive_built(frequency=frequency,
                                                                                **params)


def _agree(ra, rb, tol, times=0.0):
    # q and v each to its largest value, the contact forces (f_N, f_T) to the largest f_N
    assert ra.success and rb.success, (ra.message, rb.message)
    assert ra.t.shape == rb.t.shape
    assert np.max(np.abs(ra.t - rb.t)) <= times * ra.t[-1]
    scale = np.max(np.abs(ra.force_N))
    for a, b, s in ((ra.q, rb.q, np.max(np.abs(ra.q))), (ra.v, rb.v, np.max(np.abs(ra.v))),
                    (ra.force_N, rb.force_N, scale), (ra.force_T, rb.force_T, scale)):
        assert np.max(np.abs(a - b)) <= tol * s
    np.testing.assert_array_equal(ra.regime, rb.regime)


def test_the_built_model_states_the_hand_written_equations():
    # away from rest, with a load and a preload: every term of the scene interface
    hand, built = _pair(185.0, load=2e-3, preload=0.05, mu=0.3)
    rng = np.random.default_rng(36)
    for _ in range(5):
        q = np.array([hand.phi0 + 1e-3 * rng.standard_normal(), rng.standard_normal()])
        v = 1e-3 * rng.standard_normal(2)
        t = 2 * math.pi * rng.random()
        np.testing.assert_array_equal(built.mass(q), hand.mass(q))
        np.testing.assert_allclose(built.forces(q, v, t), hand.forces(q, v, t), rtol=1e-14,
                                   atol=1e-16)
        np.testing.assert_allclose(built.force_jacobians(q, v, t)[0],
                                   hand.force_jacobians(q, v, t)[0], rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(built.gaps(q, t), hand.gaps(q, t), rtol=0, atol=1e-16)
        for a, b in zip(built.contact_jacobians(q, t), hand.contact_jacobians(q, t)):
            np.testing.assert_allclose(a, b, rtol=1e-15, atol=1e-18)
        for a, b in zip(built.contact_drift(q, v, t), hand.contact_drift(q, v, t)):
            np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-18)
    q0, v0 = built.initial_state()
    np.testing.assert_array_equal(q0, hand.rest_state()[0])
    np.testing.assert_array_equal(v0, hand.rest_state()[1])
    # the stator starts at rest: exactly, so that the contact is closed at t = 0 in both
    assert built.contact_jacobians(q0, 0.0)[1][0] == 0.0


@pytest.mark.parametrize("frequency", FREQUENCIES)
def test_moreau_jean_runs_the_built_drive_as_the_hand_written_one(frequency):
    # from rest through the first periods (stick, slip, flight at 2 kHz), compiled loop
    hand, built = _pair(frequency)
    q0, v0 = hand.rest_state()
    h = 2 * math.pi / 400
    ra = simulate(hand, (0.0, 4 * math.pi), q0, v0, "moreau-jean", h=h)
    rb = simulate(built, (0.0, 4 * math.pi), q0, v0, "moreau-jean", h=h)
    _agree(ra, rb, 1e-12)
    assert len(set(ra.regime.ravel().tolist())) >= 2


#: the fixed-step schemes whose step solves velocity-level contact problems: to 1e-12 in
#: q, v and the forces (measured at most 3.5e-13 over two periods at 185 and 2000 Hz)
VELOCITY_LEVEL = ("moreau-jean", "moreau-jean-projected", "nonsmooth-generalized-alpha",
                  "time-discontinuous-galerkin")


@pytest.mark.slow
@pytest.mark.parametrize("frequency", FREQUENCIES)
@pytest.mark.parametrize("scheme", VELOCITY_LEVEL + ("schatzman-paoli", "event-driven-generic"))
def test_every_scheme_runs_the_built_drive_as_the_hand_written_one(scheme, frequency):
    hand, built = _pair(frequency)
    q0, v0 = hand.rest_state()
    h = 2 * math.pi / 500
    options = {} if scheme == "event-driven-generic" else {"h": h}
    ra = simulate(hand, (0.0, 4 * math.pi), q0, v0, scheme, **options)
    rb = simulate(built, (0.0, 4 * math.pi), q0, v0, scheme, **options)
    if scheme in VELOCITY_LEVEL:
        _agree(ra, rb, 1e-12)
    elif scheme == "schatzman-paoli":
        # its step solves for the position: the impulse is the gap's correction over h^2 and
        # the velocity a difference of positions over h, so the two models' last-bit
        # difference in the gap (sin phi0 - sin phi - u1 summed in another order, 1e-16 of
        # sin phi) comes out 1/h and 1/h^2 larger there: q to 1e-12 (measured 6.6e-14),
        # v and the forces to 1e-9 (measured 5.6e-12 and 1.4e-10)
        _agree(ra, rb, 1e-9)
        assert np.max(np.abs(ra.q - rb.q)) <= 1e-12 * np.max(np.abs(ra.q))
    else:
        # the events are roots of the gap found by a root solver, to its tolerance: the
        # event times to 1e-12 (measured 2.6e-12 at t = 5.3, 2e-13 relative), the states
        # and forces to 1e-11 (measured 1.5e-12)
        _agree(ra, rb, 1e-11, times=1e-12)


@pytest.mark.slow
def test_studers_extrapolation_runs_both_drives_to_its_tolerance():
    # the adaptive scheme chooses its steps from error estimates, which carry the two
    # models' last-bit differences into its step sizes (the step sequences part after a few
    # steps at 185 Hz): the runs agree to the scheme's tolerance, not to rounding. Measured
    # at the end of two periods, tol = 1e-8: q 3.3e-9, v 7.8e-8 (tol 1e-6: 1.4e-7, 3.3e-5)
    hand, built = _pair(185.0)
    q0, v0 = hand.rest_state()
    ra = simulate(hand, (0.0, 4 * math.pi), q0, v0, "studer-extrapolation", tol=1e-8)
    rb = simulate(built, (0.0, 4 * math.pi), q0, v0, "studer-extrapolation", tol=1e-8)
    assert ra.success and rb.success and ra.t[-1] == rb.t[-1]
    assert np.max(np.abs(ra.q[-1] - rb.q[-1])) <= 1e-7 * np.max(np.abs(ra.q))
    assert np.max(np.abs(ra.v[-1] - rb.v[-1])) <= 1e-6 * np.max(np.abs(ra.v))


@pytest.mark.slow
@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_the_built_drives_steady_state_is_the_hand_written_ones(theta):
    # Moreau-Jean's periodic steady state at 185 Hz, shooting on both scenes (measured: the
    # displacement per period to 9e-16 at theta = 1, 2.4e-15 at theta = 1/2)
    hand, built = _pair(185.0)
    sa = find_steady_state(hand, "moreau-jean", steps_per_period=1000, theta=theta,
                           statistical=False)
    sb = find_steady_state(built, "moreau-jean", steps_per_period=1000, theta=theta,
                           statistical=False)
    assert sa.mode == sb.mode
    # (phi, phi', u2'): the angle to its value, the rates to the velocity scale u10 (phi' is
    # 7e-19 there: the section's rod is at rest)
    scale = np.array([abs(sa.state0[0]), hand.u10, hand.u10])
    assert np.all(np.abs(np.asarray(sb.state0) - np.asarray(sa.state0)) <= 1e-12 * scale)
    assert abs(sb.displacement_per_period - sa.displacement_per_period) <= \
        1e-12 * abs(sa.displacement_per_period)


@pytest.mark.slow
def test_the_generic_reference_on_the_built_drive_meets_the_walker():
    # two methods on the two statements: the walker's closed-form contact segments on the
    # hand-written drive, the generic event-driven scheme (ODE segments, root-found events)
    # on the built one; the steady displacement per period to 1e-10 (measured 6.7e-12)
    hand, built = _pair(185.0)
    sa = find_steady_state(hand, statistical=False)
    sb = find_steady_state(built, statistical=False)
    assert sa.mode == sb.mode == "NP"
    assert abs(sb.displacement_per_period - sa.displacement_per_period) <= \
        1e-10 * abs(sa.displacement_per_period)
