"""Stick–slip motor: drives, scene formulas and the exact event-driven reference."""

import math
import re

import numpy as np
import pytest

import moreau.integrators.moreau_jean  # noqa: F401  (registers "moreau-jean")
from moreau.modes import mode_name
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.stick_slip_motor.exact import (_Walker, stick_slip_period_map,
                                                     stick_slip_steady_state)
from moreau.regimes import Regime
from moreau.scenes.stick_slip_motor import (SawtoothDrive, SineDrive, StickSlipMotor,
                                            StickSlipMotorParams)

TWO_PI = 2.0 * math.pi


def central(f, s=1e-5):
    return (f(s) - f(-s)) / (2.0 * s)


def velocity_level_stepper(scene, u0, nsteps, periods):
    """Independent check: first-order velocity-level time stepping of the slider.

    Each step the friction impulse is the one that makes the slider stick to
    the stator at the end of the step if it can (|impulse| <= mu n h), else
    the full sliding impulse towards it. Returns the slider displacement over
    the last period and its final velocity.
    """
    mun, fL, h = scene.friction_level, scene.fL, TWO_PI / nsteps
    ds = scene.drive(np.arange(1, nsteps + 1) * h)[1]
    x, u = 0.0, u0
    for _ in range(periods):
        x_start = x
        for k in range(nsteps):
            u_free = u - fL * h
            gap = ds[k] - u_free
            u_new = ds[k] if abs(gap) <= mun * h else u_free + math.copysign(mun * h, gap)
            x += 0.5 * h * (u + u_new)
            u = u_new
    return x - x_start, u


# -- input checks -------------------------------------------------------------
@pytest.mark.parametrize("kwargs, match", [
    ({"mass": 0.0}, r"`mass` must be > 0"),
    ({"normal_force": -1.0}, r"`normal_force` must be > 0"),
    ({"mu": 0.0}, r"`mu` must be > 0"),
    ({"amplitude": float("nan")}, r"`amplitude` must be finite"),
    ({"load": float("inf")}, r"`load` must be finite"),
    ({"restitution": 3.0}, r"`restitution` must be in \[0.0, 1.0\]"),
    ({"frequency": 0.0}, r"`frequency` must be > 0"),
    ({"drive": "square"}, r"`drive` must be 'sine', 'sawtooth'"),
    ({"preload": 1.0}, r"`preload` is not a parameter of StickSlipMotorParams"),
])
def test_bad_parameters_raise_input_error(kwargs, match):
    with pytest.raises(InputError, match=match):
        StickSlipMotor(**kwargs)


@pytest.mark.parametrize("make, match", [
    (lambda: SawtoothDrive(rise=1.0), r"`rise` must be in the open interval \(0.0, 1.0\)"),
    (lambda: SawtoothDrive(smoothing=0.0), r"`smoothing` must be in \(0, 1\]"),
    (lambda: SawtoothDrive(smoothing=1.5), r"`smoothing` must be in \(0, 1\]"),
    (lambda: SineDrive(harmonic2=float("nan")), r"`harmonic2` must be finite"),
])
def test_bad_drives_raise_input_error(make, match):
    with pytest.raises(InputError, match=match):
        make()


def test_a_drive_subclass_is_refused_and_the_methods_are_the_compiled_model():
    class Steeper(SineDrive):
        def _eval(self, t):
            s, ds, dds = super()._eval(t)
            return 2.0 * s, 2.0 * ds, 2.0 * dds

    # the compiled model, which the Python methods evaluate, would not know the subclass's s
    with pytest.raises(InputError, match=r"`drive` must be a SineDrive or a SawtoothDrive, "
                                         r"got a subclass Steeper"):
        StickSlipMotor(drive=Steeper())
    motor = StickSlipMotor(drive=SineDrive(0.3, 0.7))
    tau = 1.234
    _, ds, dds = motor.drive(tau)
    WN, wN, WT, wT = motor.contact_jacobians([0.0, 0.0], tau)
    assert WT.tolist() == [[1.0, 0.0]] and abs(wT[0] + ds) <= 1e-15
    assert abs(motor.contact_drift([0.0, 0.0], [0.0, 0.0], tau)[1][0] + dds) <= 1e-15


def test_reference_rejects_what_it_cannot_solve():
    with pytest.raises(InputError, match=r"`load` must be smaller in size than the sliding "
                                         r"friction `mu` \* `normal_force`"):
        stick_slip_steady_state(StickSlipMotor(load=0.25, mu=0.2, normal_force=1.0))
    with pytest.raises(InputError, match=r"`scene` must be a StickSlipMotor"):
        stick_slip_period_map(object(), 0.0)
    with pytest.raises(InputError, match=r"`q0` and `v0` must put the slider on the stator"):
        simulate(StickSlipMotor(), (0.0, 1.0), [0.0, 0.1], [0.0, 0.0], "stick-slip-exact")


# -- drives -------------------------------------------------------------------------
@pytest.mark.parametrize("drive", [SawtoothDrive(0.9, 0.5), SawtoothDrive(0.3, 1.0),
                                   SawtoothDrive(0.75, 0.2), SineDrive(0.3, 0.7)])
def test_drive_derivatives_periodicity_and_range(drive):
    tau = np.linspace(0.0, TWO_PI, 3001)[:-1] + 1e-3
    s, ds, dds = drive(tau)
    sp, dsp, ddsp = drive(tau + TWO_PI)
    assert np.max(np.abs(s - sp)) < 1e-12 and np.max(np.abs(ds - dsp)) < 1e-12
    # away from the breakpoints s' and s'' are the derivatives of s and s'
    far = np.ones_like(tau, bool)
    for b in drive.breakpoints:
        far &= np.abs((tau - b + math.pi) % TWO_PI - math.pi) > 1e-4
    h = 1e-6
    assert np.max(np.abs((drive(tau + h)[0] - drive(tau - h)[0]) / (2 * h) - ds)[far]) < 1e-8
    assert np.max(np.abs((drive(tau + h)[1] - drive(tau - h)[1]) / (2 * h) - dds)[far]) < 1e-7
    # s and s' are continuous across the breakpoints
    for b in drive.breakpoints:
        left, right = drive(b - 1e-12), drive(b + 1e-12)
        assert abs(left[0] - right[0]) < 1e-10 and abs(left[1] - right[1]) < 1e-10
    if isinstance(drive, SawtoothDrive):
        fine = drive(np.linspace(0.0, TWO_PI, 400001))[0]
        assert fine.min() == pytest.approx(-1.0, abs=1e-9)
        assert fine.max() == pytest.approx(1.0, abs=1e-9)
        # slow ramp at +V1 for the rise fraction, fast return at -V2
        assert drive.V1 * drive.rise == pytest.approx(drive.V2 * (1 - drive.rise))
        assert max(abs(a) for a in drive.acceleration_range()) == pytest.approx(drive.A)


@pytest.mark.parametrize("drive", [SawtoothDrive(0.9, 0.5), SawtoothDrive(0.3, 1.0),
                                   SawtoothDrive(0.75, 0.2), SawtoothDrive()])
def test_a_sawtooth_at_one_time_equals_its_array_evaluation_to_the_bit(drive):
    # the scalar path (used by the event-driven schemes, one time per call) and the
    # array path compute the same expression: same segment, same numbers
    tau = np.concatenate([np.linspace(-20.0, 20.0, 4001), drive._starts,
                          drive._starts + TWO_PI, np.nextafter(drive._starts, -1.0), [0.0, TWO_PI]])
    arrays = np.array(drive(tau))
    ones = np.array([drive(float(t)) for t in tau]).T
    np.testing.assert_array_equal(ones, arrays)
    assert all(type(x) is np.float64 for x in drive(1.0))


def test_sine_acceleration_crossings_are_all_found():
    drive = SineDrive(0.3, 0.7)
    tau = np.linspace(0.0, TWO_PI, 200001)
    dds = drive(tau)[2]
    for level in (-1.9, -1.0, 0.0, 0.5, 2.0):
        roots = drive.acceleration_crossings(level)
        changes = np.count_nonzero(np.diff(np.sign(dds - level)) != 0)
        assert len(roots) == changes
        assert np.max(np.abs(drive(roots)[2] - level), initial=0.0) < 1e-13
    lo, hi = drive.acceleration_range()
    assert lo == pytest.approx(dds.min(), abs=1e-8) and hi == pytest.approx(dds.max(), abs=1e-8)
    assert len(SineDrive().acceleration_crossings(5.0)) == 0


# -- scene formulas -------------------------------------------------------------------
@pytest.mark.parametrize("drive", ["sine", "sawtooth"])
def test_contact_kinematics_match_finite_differences(drive):
    motor = StickSlipMotor(drive=drive, load=0.05)
    q, v, t = np.array([0.4, 0.0]), np.array([0.3, -0.1]), 1.3
    WN, wN, WT, wT = motor.contact_jacobians(q, t)
    gdot = central(lambda s: motor.gaps(q + s * v, t + s)[0])
    assert WN[0] @ v + wN[0] == pytest.approx(gdot, abs=1e-9)
    # slip = rate of the slider position relative to the stator surface
    slip = central(lambda s: (q + s * v)[0] - motor.stator(t + s)[0])
    assert WT[0] @ v + wT[0] == pytest.approx(slip, abs=1e-9)
    wNbar, wTbar = motor.contact_drift(q, v, t)
    rate = central(lambda s: motor.contact_jacobians(q + s * v, t + s)[2][0] @ v
                   + motor.contact_jacobians(q + s * v, t + s)[3][0])
    assert wTbar[0] == pytest.approx(rate, abs=1e-8) and wNbar[0] == 0.0


def test_mass_forces_and_scales_from_the_si_model():
    # L = 1/2 m (X'^2 + Y'^2) - N Y - F_L X, stator X s(w t), time tau = w t
    p = StickSlipMotorParams(mass=0.02, normal_force=3.0, mu=0.3, amplitude=2e-6, load=0.4)
    motor = StickSlipMotor(p, frequency=500.0, drive="sine")
    w = TWO_PI * 500.0
    L, T, F = motor.length, motor.time, motor.force
    assert (L, T, F) == pytest.approx((2e-6, 1 / w, 0.02 * 2e-6 * w * w))
    S = np.diag([L, L])
    M_si, h_si = p.mass * np.eye(2), np.array([-p.load, -p.normal_force])
    assert motor.mass(None) == pytest.approx(S @ M_si @ S / (T ** 2 * F * L), rel=1e-14)
    assert motor.forces(None, None, 0.0) == pytest.approx(S @ h_si / (F * L), rel=1e-14)
    assert motor.n == pytest.approx(3.0 / F) and motor.friction_level == pytest.approx(0.9 / F)
    # SI slip velocity X' - X w s'(w t) at t = 0.1 ms for X' = 1 mm/s
    t_si, Xdot = 1e-4, 1e-3
    si_slip = Xdot - 2e-6 * w * math.cos(w * t_si)
    WT, wT = motor.contact_jacobians(None, w * t_si)[2:]
    v = motor.from_si(v=[Xdot, 0.0]).v
    assert motor.to_si(v=WT[0] @ v + wT[0]).v == pytest.approx(si_slip, rel=1e-12)


# -- exact reference ------------------------------------------------------------------
def test_sawtooth_steady_state_matches_a_hand_solution():
    # NSP cycle: stick on the ramp until the first corner (A > mu n), positive
    # slip at -mu n until the stator, accelerating at A in the second corner,
    # overtakes the slider, negative slip at +mu n until the slider is back
    # on the ramp speed V1.
    motor = StickSlipMotor(drive=SawtoothDrive(0.9, 0.5))
    d, mun = motor.drive, motor.friction_level
    V1, V2, A, Tb = d.V1, d.V2, d.A, d.Tb
    T1 = 0.9 * TWO_PI - Tb
    T3 = TWO_PI - Tb
    t_pn = (V1 + V2 + mun * T1 + A * T3) / (A + mun)
    u_pn = V1 - mun * (t_pn - T1)
    t_ns = t_pn + (V1 - u_pn) / mun
    assert T3 < t_pn < TWO_PI < t_ns < TWO_PI + T1          # the assumed cycle
    D = (V1 * (T1 - (t_ns - TWO_PI)) + V1 * (t_pn - T1) - 0.5 * mun * (t_pn - T1) ** 2
         + u_pn * (t_ns - t_pn) + 0.5 * mun * (t_ns - t_pn) ** 2)
    ss = stick_slip_steady_state(motor)
    assert ss.mode == "NSP"
    assert ss.displacement_per_period == pytest.approx(D, rel=1e-13)
    taus = [t for t, _ in ss.regimes]
    assert taus == pytest.approx([0.0, t_ns - TWO_PI, T1, t_pn], rel=1e-14)
    assert [r for _, r in ss.regimes] == ["N", "S", "P", "N"]
    assert ss.state0[0] == pytest.approx(u_pn + mun * (TWO_PI - t_pn), rel=1e-13)
    assert ss.periodic_residual < 1e-14
    assert ss.min_normal_force == motor.n


@pytest.mark.parametrize("kwargs, mode", [
    ({"drive": "sine", "normal_force": 1.5, "load": 0.1}, "NS"),
    ({"drive": "sine", "load": 0.1}, "NPS"),
    ({"drive": SineDrive(0.25, 0.5), "normal_force": 0.5}, "NPSP"),
])
def test_sine_steady_states_match_independent_time_stepping(kwargs, mode):
    motor = StickSlipMotor(**kwargs)
    ss = stick_slip_steady_state(motor)
    assert ss.mode == mode and ss.periodic_residual < 1e-13
    # first order where the slip reverses (P <-> N), second order otherwise
    D, u = velocity_level_stepper(motor, ss.state0[0], 20000, 2)
    reverses = mode != "NS"
    assert D == pytest.approx(ss.displacement_per_period, rel=2e-4 if reverses else 2e-8)
    assert u == pytest.approx(ss.state0[0], abs=2e-4 if reverses else 1e-8)


def test_symmetric_sine_without_load_has_zero_net_displacement():
    # s(tau + pi) = -s(tau) maps the steady state onto its mirror image
    motor = StickSlipMotor(drive="sine")
    ss = stick_slip_steady_state(motor)
    assert "P" in ss.mode and "N" in ss.mode          # it does slip both ways
    assert abs(ss.displacement_per_period) < 1e-14
    taus = [t for t, _ in ss.regimes]
    assert taus[2] - taus[1] == pytest.approx(math.pi, rel=1e-14)


def test_events_are_located_to_rounding_precision():
    motor = StickSlipMotor(drive="sine", load=0.1)
    walker = _Walker(motor)
    mun, fL = motor.friction_level, motor.fL
    ss = stick_slip_steady_state(motor)
    nodes = list(walker.walk(0.0, 0.0, ss.state0[0], 3 * TWO_PI))
    checked = 0
    for (t0, x0, u0, r0, _), (t1, x1, u1, r1, events) in zip(nodes, nodes[1:]):
        for te, before, after in events:
            s, ds, dds = motor.drive(te)
            if before == "S":        # stick broke: the friction needed hit the bound
                assert abs(abs(dds + fL) - mun) < 1e-13
            else:                    # slip ended: the explicit slip velocity is zero here
                acc = -mun - fL if before == "P" else mun - fL
                assert abs(u0 + acc * (te - t0) - ds) < 1e-13
            checked += 1
    assert checked == 9          # three periods of NPS


def test_period_map_in_pure_slip_is_explicit():
    motor = StickSlipMotor(drive="sawtooth", load=0.05)
    mun, fL = motor.friction_level, motor.fL
    u0 = 50.0                    # far faster than the stator: positive slip all period
    u1, dx = stick_slip_period_map(motor, u0)
    assert u1 == pytest.approx(u0 - TWO_PI * (mun + fL), rel=1e-14)
    assert dx == pytest.approx(TWO_PI * u0 - 0.5 * TWO_PI ** 2 * (mun + fL), rel=1e-14)


def test_integrator_converges_to_the_shooting_steady_state():
    motor = StickSlipMotor(drive="sawtooth", normal_force=0.5)
    ss = stick_slip_steady_state(motor)
    res = simulate(motor, (0.0, 8 * TWO_PI), [0.0, 0.0], [0.0, 0.0], "stick-slip-exact")
    assert res.status == 0 and res.t[-1] == pytest.approx(8 * TWO_PI)
    at = lambda tau: res.q[np.argmin(np.abs(res.t - tau)), 0]
    assert at(8 * TWO_PI) - at(7 * TWO_PI) == pytest.approx(ss.displacement_per_period, rel=1e-12)
    assert res.v[-1, 0] == pytest.approx(ss.state0[0], rel=1e-12)
    kinds = {(e.before, e.after) for e in res.events}
    assert (Regime.STICK, Regime.POSITIVE) in kinds and (Regime.NEGATIVE, Regime.STICK) in kinds
    # in stick the friction force is what moves the slider with the stator
    stick = res.regime[:, 0] == Regime.STICK
    assert np.allclose(res.force_T[stick, 0], motor.drive(res.t[stick])[2] + motor.fL)
    assert np.all(np.abs(res.force_T[:, 0]) <= motor.friction_level + 1e-15)
    si = motor.to_si(res)
    assert si["t"][-1] == pytest.approx(8e-3) and si["force_N"][0, 0] == pytest.approx(0.5)


# -- Moreau–Jean against the reference ---------------------------------------------
@pytest.mark.parametrize("kwargs", [
    {"drive": "sawtooth", "normal_force": 0.5},     # NSP
    {"drive": "sine", "load": 0.1},                 # NPS
])
def test_moreau_jean_net_displacement_matches_the_reference(kwargs):
    # 2000 steps per period, started on the reference's periodic state; the
    # first period absorbs the scheme's own transient, the last is measured
    motor = StickSlipMotor(**kwargs)
    ss = stick_slip_steady_state(motor)
    res = simulate(motor, (0.0, 3 * TWO_PI), [0.0, 0.0], [ss.state0[0], 0.0], "moreau-jean",
                   h=TWO_PI / 2000)
    assert res.status == 0
    k = np.argmin(np.abs(res.t - 2 * TWO_PI))
    assert res.t[k] == pytest.approx(2 * TWO_PI)
    D = res.q[-1, 0] - res.q[k, 0]
    assert D == pytest.approx(ss.displacement_per_period, rel=1e-3)
    # a reversal of the slip inside a step reads as one step of stick
    letters = res.regime_letters()[k:]
    runs = [(m.group()[0], len(m.group())) for m in re.finditer(r"(.)\1*", letters)]
    assert mode_name([r for r, n in runs if n > 1]) == ss.mode
    assert np.max(np.abs(res.gap)) < 1e-12          # the slider stays pressed on
