"""Glocker's woodpecker toy: its equations against the Lagrangian, its limit cycle against the published state.

Published: Glocker's state on the limit cycle (Glocker 1995, pp. 162ff.; the
start of the published trajectories), four significant digits: at the bird
angle ``phi_S = -0.2788`` (swinging out) the sleeve is jammed on its lower
edge (``phi_M = -0.1036``, ``phi_M' = 0``) and falls at ``y' = -0.3411 m/s``
while the bird turns at ``phi_S' = -7.4583 rad/s``.

Leine, Glocker and van Campen, "Nonlinear dynamics of the woodpecker toy",
ASME DETC2001/VIB-21608 (2001), same parameters (``LEINE_2001``): the period
``T = 0.1452 s`` and the least bird angle ``-0.53 rad`` (text, pp. 4 and 6),
the eigenfrequency, the equilibrium and its friction threshold, and Fig. 4
(p. 4), two periods of ``y``, ``phi_M``, ``phi_S`` against ``t``. Fig. 4 is
vector art: its curves were read from the PDF's drawing commands (axes
calibrated on the grid lines; PDF coordinates to 0.01 pt, i.e. 13 us, 8 um
and 0.15 mrad), resampled every 0.5 ms into
``tests/data/leine2001_woodpecker_fig4.npz``. The reading is far finer than
the plotted line (0.26 pt wide: 0.33 ms, 0.21 mm in ``y``, 3.9 mrad in
``phi_S``), which is the tolerance of a comparison with the figure. Read from
it: the sleeve drops 18.88 mm from the first jam to the second (the flat
parts of ``y``, -16.77 and -35.65 mm) and 19.53 mm over the first period from
the figure's start; fitted cycle by cycle to our runs, the figure's cycle
lasts 0.14520 s (the text's ``T``).
"""

import math
import pathlib

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.suite.problem import get_problem
from moreau.scenes.woodpecker_toy import (GLOCKER_STATE, LEINE_2001, WoodpeckerToy,
                                          WoodpeckerToyParams, limit_cycle, section_event)

P = WoodpeckerToyParams()
FIG4 = pathlib.Path(__file__).parents[1] / "data" / "leine2001_woodpecker_fig4.npz"
#: Fig. 4's sleeve drop per cycle [m]: jam to jam, and over the figure's first period
FIG4_DROPS = (0.01888, 0.01953)
#: Fig. 4's line width in y [m] and phi_S [rad]
FIG4_LINE = (0.21e-3, 3.9e-3)
#: Fig. 5 (p. 4, phi_M' against phi_M, read from its vector paths as Fig. 4): after the lower
#: edge's impact the sleeve lifts off the pole and strikes it again 2.7 ms later, a loop of
#: largest phi_M -0.1028 rad, largest phi_M' 0.532 rad/s and phi_M' -1.537 rad/s before the
#: second strike; the line is 0.26 pt wide: 0.092 rad/s and 5e-4 rad
FIG5_BOUNCE = (-0.1028, 0.532, -1.537)
FIG5_LINE = (5e-4, 0.092)


def _fit_to_fig4(toy, res):
    """Each period of Fig. 4 against the run's samples, shifted in time (and ``y`` in height).

    Returns ``(shift [s], rms phi_S [rad], rms y [m])`` for the figure's two
    periods, the shift putting the figure's time on the run's: a coarse grid
    of 0.1 ms on every fourth point, then 0.5 us about the best.
    """
    fig = np.load(FIG4)
    t, q = res.t * toy.time, res.q
    out = []
    for a in (0.0, LEINE_2001["period"]):
        m = (fig["t"] >= a) & (fig["t"] < a + LEINE_2001["period"])
        tf, pf, yf = fig["t"][m], fig["phi_S"][m], fig["y"][m]

        def rms(shifts, every=1):
            x = tf[None, ::every] + shifts[:, None]
            return np.sqrt(np.mean((np.interp(x, t, q[:, 2]) - pf[::every]) ** 2, axis=1))
        # starts within less than a period, the run's last 0.3 s: one run cycle for both
        coarse = np.arange(t[-1] - 0.30 - a, t[-1] - 0.16 - a, 1e-4)
        s0 = coarse[np.argmin(rms(coarse, 4))]
        fine = np.arange(s0 - 1e-4, s0 + 1e-4, 5e-7)
        r = rms(fine)
        s = fine[np.argmin(r)]
        dy = np.interp(tf + s, t, q[:, 0]) * toy.length - yf
        out.append((s, float(r.min()), float(np.sqrt(np.mean((dy - dy.mean()) ** 2)))))
    return out


def _fig4_period(fits, lc):
    """Fig. 4's own period [s]: its second cycle's shift against its first, modulo the run's."""
    d = fits[0][0] - fits[1][0]
    return d + round((LEINE_2001["period"] - d) / lc["period"]) * lc["period"]


def _least_bird_angle(toy, res):
    t = res.t * toy.time
    return float(res.q[t > t[-1] - LEINE_2001["period"], 2].min())


def _bounce(toy, res):
    """Largest phi_M, largest and least phi_M' in the 4 ms after the last lower-edge impact."""
    t, pm, w = res.t * toy.time, res.q[:, 1], res.v[:, 1] / toy.time
    last = np.flatnonzero(t > t[-1] - LEINE_2001["period"])
    # the impact: phi_M' jumps from about -11 rad/s to about 0, the sleeve on its lower edge
    i0 = [i for i in last[1:] if w[i - 1] < -5.0 and w[i] > -2.0 and pm[i] < -0.1][-1]
    k = (t > t[i0]) & (t < t[i0] + 0.004)
    return float(pm[k].max()), float(w[k].max()), float(w[k].min())


def _check_against_leine_2001(toy, res, lc):
    """The run's limit cycle against the paper's text and Fig. 4; returns the figures."""
    fits = _fit_to_fig4(toy, res)
    for _, rms_phi, rms_y in fits:
        assert rms_phi <= FIG4_LINE[1] and rms_y <= FIG4_LINE[0]
    least = _least_bird_angle(toy, res)
    # -0.53 as printed: two digits
    assert abs(least - LEINE_2001["min_bird_angle"]) <= 5e-3
    # the drop per period between the figure's two cycles, widened by its line
    assert FIG4_DROPS[0] - FIG4_LINE[0] <= lc["descent"] <= FIG4_DROPS[1] + FIG4_LINE[0]
    # the sleeve's bounce on its lower edge, Fig. 5
    top, w_top, w_low = _bounce(toy, res)
    assert abs(top - FIG5_BOUNCE[0]) <= FIG5_LINE[0]
    assert abs(w_top - FIG5_BOUNCE[1]) <= FIG5_LINE[1]
    assert abs(w_low - FIG5_BOUNCE[2]) <= FIG5_LINE[1]
    return fits, least


def _lagrangian_terms(q, v):
    """``T`` and ``V`` (SI) of the toy with the exact (unlinearised) positions of the bodies."""
    y, pm, ps = q
    dy, dpm, dps = v
    # the spring's joint D and the bird's centre of mass S (sleeve centre on the axis)
    dDx, dDy = -P.spring_offset * math.sin(pm) * dpm, dy + P.spring_offset * math.cos(pm) * dpm
    dSx = dDx - P.bird_offset * math.sin(ps) * dps
    dSy = dDy + P.bird_offset * math.cos(ps) * dps
    T = 0.5 * (P.sleeve_mass * dy ** 2 + P.sleeve_inertia * dpm ** 2
               + P.bird_mass * (dSx ** 2 + dSy ** 2) + P.bird_inertia * dps ** 2)
    Sy = y + P.spring_offset * math.sin(pm) + P.bird_offset * math.sin(ps)
    V = (P.sleeve_mass * P.gravity * y + P.bird_mass * P.gravity * Sy
         + 0.5 * P.spring * (ps - pm) ** 2)
    return T, V


def _si_model(toy):
    # the scene's mass matrix and forces in SI (scene units: l_M, sqrt(l_M / g), m_S)
    L, m, g = P.spring_offset, P.bird_mass, P.gravity
    s = np.array([L, 1.0, 1.0])
    M = toy.mass(np.zeros(3)) * m * L * L / np.outer(s, s)

    def h(q_si):
        return toy.forces(q_si / s, np.zeros(3), 0.0) * m * g * L / s
    return M, h


def test_mass_and_forces_are_the_lagrangian_of_the_linearised_kinematics():
    toy = WoodpeckerToy()
    M, h = _si_model(toy)
    # the mass matrix: the Hessian of the exact T in the velocities at zero angles
    # (T is quadratic in them: central differences are exact to rounding)
    d = 1e-3
    H = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            def T(a, b):
                v = np.zeros(3)
                v[i] += a
                v[j] += b
                return _lagrangian_terms(np.zeros(3), v)[0]
            H[i, j] = (T(d, d) - T(d, -d) - T(-d, d) + T(-d, -d)) / (4 * d * d)
    np.testing.assert_allclose(M, H, rtol=1e-9, atol=0.0)
    # the forces: -grad V of the exact V, to first order in the angles
    for ang in (1e-3, 1e-4):
        q = np.array([0.01, -ang, 2.0 * ang])
        grad = np.empty(3)
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1e-7
            grad[k] = (_lagrangian_terms(q + e, np.zeros(3))[1]
                       - _lagrangian_terms(q - e, np.zeros(3))[1]) / 2e-7
        scale = P.bird_mass * P.gravity * P.bird_offset
        assert np.max(np.abs(h(q) + grad)) <= 1e-4 * scale + 4.0 * ang ** 2 * scale


def test_gaps_are_the_exact_geometry_to_first_order_in_the_angles():
    toy = WoodpeckerToy()
    for ang in (1e-2, 1e-3):
        pm, ps = -ang, 3.0 * ang
        # the hole's corners (r_M, -+h_M) and the beak, rotated exactly, against the pole x = r_0
        lower = P.sleeve_radius * math.cos(pm) + P.sleeve_half_height * math.sin(pm)
        upper = P.sleeve_radius * math.cos(pm) - P.sleeve_half_height * math.sin(pm)
        Dx = P.spring_offset * math.cos(pm)
        Sx = Dx + P.bird_offset * math.cos(ps)
        beak = Sx - P.beak_offset * math.cos(ps) - P.beak_height * math.sin(ps)
        exact = np.array([lower, upper, beak]) - P.pole_radius
        g = toy.gaps(np.array([0.0, pm, ps]), 0.0) * toy.length
        assert np.max(np.abs(g - exact)) <= 0.05 * ang ** 2


def test_the_limit_cycle_passes_through_glockers_published_state():
    # Moreau-Jean at 1.5e4 steps a cycle (h = 9.6 us) from the published state, eight cycles;
    # the limit cycle's state where the bird swings out through -0.2788 rad: measured
    # 0.145 % (y') and 0.086 % (phi_S') off the published values (the event-driven
    # reference: 0.49 % and 0.054 %)
    toy = WoodpeckerToy()
    q0, v0 = toy.initial_state()
    res = simulate(toy, (0.0, 40.0), q0, v0, "moreau-jean", h=3e-4)
    assert res.status == 0, res.message
    lc = limit_cycle(toy, res)
    (_, _, _), (ydot, _, phidot) = GLOCKER_STATE
    assert abs(lc["ydot"] / ydot - 1.0) <= 1e-2 and abs(lc["phidot"] / phidot - 1.0) <= 2e-3
    # one jam a cycle: the cycle is 0.146 s long and drops the toy by 19.5 mm
    assert 0.14 < lc["period"] < 0.15 and 0.018 < lc["descent"] < 0.021
    # Leine et al. (2001): T = 0.1452 s; measured 0.146142 s, 0.65 % longer (the reference
    # 0.53 %); Fig. 4 cycle by cycle: phi_S within 0.40 and 1.9 mrad rms, y within 0.017
    # and 0.15 mm, the figure's cycle 0.14517 s; drop 19.56 mm; least phi_S -0.5296; the
    # bounce (Fig. 5): phi_M up to -0.10285, phi_M' from 0.521 to -1.469 rad/s
    assert abs(lc["period"] / LEINE_2001["period"] - 1.0) <= 1e-2
    fits, _ = _check_against_leine_2001(toy, res, lc)
    assert abs(_fig4_period(fits, lc) - LEINE_2001["period"]) <= 2e-4
    # the suite's problem reads the same run against the published values
    prob = get_problem("woodpecker-toy")
    errors = prob.errors(prob.measure(toy, res))
    assert max(errors.values()) <= prob.tolerance
    assert errors["section_sleeve_velocity"] == pytest.approx(abs(lc["ydot"] / ydot - 1.0))


@pytest.mark.slow
def test_moreau_jean_converges_to_the_event_driven_limit_cycle():
    toy = WoodpeckerToy()
    q0, v0 = toy.initial_state()
    ref = limit_cycle(toy, simulate(toy, (0.0, 40.0), q0, v0, "event-driven",
                                    events=[section_event()]))
    # measured: period 0.145974 s, descent 19.443 mm (mean speed 0.1332 m/s); Moreau-Jean
    # 0.36 % and 1.9 % off at h = 1e-3 (32 us), 0.040 % and 0.19 % at h = 1e-4
    errs = []
    for h in (1e-3, 1e-4):
        res = simulate(toy, (0.0, 40.0), q0, v0, "moreau-jean", h=h)
        lc = limit_cycle(toy, res)
        errs.append((abs(lc["period"] / ref["period"] - 1.0),
                     abs(lc["descent"] / ref["descent"] - 1.0)))
    # first order: ten times finer, about ten times closer
    assert errs[1][0] <= 5e-4 and errs[1][1] <= 5e-3
    assert errs[1][0] < 0.3 * errs[0][0] and errs[1][1] < 0.3 * errs[0][1]
    # and the reference passes through Glocker's published state too
    (_, _, _), (ydot, _, phidot) = GLOCKER_STATE
    assert abs(ref["ydot"] / ydot - 1.0) <= 1e-2 and abs(ref["phidot"] / phidot - 1.0) <= 2e-3


@pytest.mark.slow
def test_the_reference_limit_cycle_against_leine_glocker_van_campen_2001():
    # the reference on the cycle: eight cycles from Glocker's state, then its last two
    # sampled every 16 us for the comparison with Fig. 4 (20 s)
    toy = WoodpeckerToy()
    q0, v0 = toy.initial_state()
    res = simulate(toy, (0.0, 40.0), q0, v0, "event-driven", events=[section_event()],
                   t_eval=np.linspace(0.0, 40.0, 80001))
    assert res.status == 0, res.message
    lc = limit_cycle(toy, res)
    # measured: T 0.145974 s, 0.53 % longer than the published 0.1452 s; drop 19.44 mm
    # (Fig. 4: 18.88 jam to jam, 19.53 over its first period); least phi_S -0.5296;
    # Fig. 4 cycle by cycle: phi_S within 0.45 and 1.5 mrad rms, y within 0.03 and 0.12 mm,
    # the figure's cycle 0.14522 s; the bounce (Fig. 5): phi_M up to -0.10280, phi_M' from
    # 0.535 to -1.549 rad/s
    assert abs(lc["period"] / LEINE_2001["period"] - 1.0) <= 6e-3
    fits, _ = _check_against_leine_2001(toy, res, lc)
    assert abs(_fig4_period(fits, lc) - LEINE_2001["period"]) <= 2e-4


def test_eigenfrequency_equilibrium_and_jamming_threshold_are_the_published_ones():
    # Leine et al. (2001): the free toy's eigenfrequency 72.91 Hz, the jammed equilibrium
    # (-0.1034, -0.2216) and mu >= 0.285 to hold it, from the scene's own model
    toy = WoodpeckerToy()
    # the sleeve's tilt on its lower edge's contact, as the scene's start puts it (gap 0.0)
    phi_M = toy.initial_state()[0][1]
    q = np.array([0.0, phi_M, 0.0])
    assert toy.gaps(q, 0.0)[0] == 0.0
    M = toy.mass(q)
    K, _ = toy.force_jacobians(q, np.zeros(3), 0.0)
    # free flight: M q'' = K q; one nonzero frequency (the spring), measured 72.9085 Hz
    f = math.sqrt(np.linalg.eigvals(np.linalg.solve(M, -K)).real.max()) / toy.time / (2 * math.pi)
    assert abs(f - LEINE_2001["eigenfrequency"]) <= 5e-3
    # jammed on the lower edge at rest: h + wN lamN + wT lamT = 0, linear in phi_S
    WN, _, WT, _ = toy.contact_jacobians(q, 0.0)
    A = np.column_stack([K[:, 2], WN[0], WT[0]])
    phi_S, lam_N, lam_T = np.linalg.solve(A, -toy.forces(q, np.zeros(3), 0.0))
    pub_M, pub_S = LEINE_2001["equilibrium"]
    assert abs(phi_M - pub_M) <= 5e-5
    # the spring's twist phi_S - phi_M = -m_S g l_G / c_phi: -0.118246 (printed: -0.1182)
    assert abs((phi_S - phi_M) - (pub_S - pub_M)) <= 1e-4
    # measured 0.28519 (printed 0.285)
    assert lam_N > 0.0 and abs(lam_T / lam_N - LEINE_2001["jamming_mu"]) <= 5e-4
    # and Moreau-Jean holds the toy there just above the threshold, lets it slide just below
    q0 = np.array([0.0, phi_M, phi_S])
    for mu, holds in ((0.29, True), (0.28, False)):
        res = simulate(WoodpeckerToy(mu=mu), (0.0, 2.0), q0, np.zeros(3), "moreau-jean", h=1e-3)
        assert res.status == 0, res.message
        drop = q0[0] - res.q[-1, 0]
        assert (abs(drop) <= 1e-14) if holds else (drop > 0.1)


def test_bad_geometry_is_refused_naming_it():
    from moreau.errors import InputError
    with pytest.raises(InputError, match="`sleeve_radius`"):
        WoodpeckerToy(sleeve_radius=0.002)
    with pytest.raises(InputError, match="`beak_restitution`"):
        WoodpeckerToy(beak_restitution=1.5)
