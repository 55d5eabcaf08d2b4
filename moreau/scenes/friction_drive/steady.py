"""The friction drive's event-driven steady state: shooting on its walker's period map.

Registered as the steady-state solver of the scene's own reference,
``"friction-drive-walker"`` (:mod:`moreau.analysis.steady_solvers`):
:func:`moreau.analysis.steady_state.find_steady_state` with the event-driven
scheme uses it for the friction drive.
"""

import math
import time

import numpy as np
from scipy.optimize import minimize_scalar

from ..._validate import positive, positive_int
from ...analysis.energy import RodEnergy, balance, gauss_legendre, register_energy_audit
from ...analysis.section_runs import register_section_run
from ...analysis.steady_solvers import register_steady_solver
from ...errors import ConvergenceError
from ...integrators.result import SteadyState
from ...modes import mode_name
from ...regimes import REGIME_LETTERS, Regime
from ...analysis.floquet import sorted_multipliers
from .floquet import GrazingEvent, walker_monodromy, walker_period_map_slope
from .walker import ContactState, FrictionDriveWalker

__all__ = ["walker_steady_state", "walker_energy_audit"]

TWO_PI = 2.0 * math.pi


def _period_run(walker, state, record=False):
    """Advance one period from ``state``; return (end_state, segments, events)."""
    segs, evs = [], []
    # the walker changes a finished piece's end state in place (impact, manifold): copy
    on_seg = (lambda a, b, sol: segs.append((a.copy(), b.copy()))) if record else None
    end = walker.advance(state, state.tau + TWO_PI, on_segment=on_seg,
                         on_event=evs.append if record else None)
    return end, segs, evs


def _min_normal_force(walker, segments):
    sc = walker.scene
    best = math.inf
    for a, b in segments:
        if a.regime == Regime.FLIGHT:
            best = min(best, 0.0)
            continue
        n = max(16, int(256 * (b.tau - a.tau) / TWO_PI) + 2)
        tau = np.linspace(a.tau, b.tau, n)
        fN = sc.contact_forces(tau, a.regime)[0]
        i = int(np.argmin(fN))
        best = min(best, float(fN[i]))
        if 0 < i < n - 1:
            # refine the sampled minimum: f_N varies fast near the stator's lowest point
            r = minimize_scalar(lambda t: float(sc.contact_forces(t, a.regime)[0]),
                                bounds=(tau[i - 1], tau[i + 1]), method="bounded",
                                options={"xatol": 1e-12})
            best = min(best, float(r.fun))
    # the force at a located lift-off is zero up to round-off
    if -1e-12 * walker.fscale < best < 0.0:
        best = 0.0
    return best


#: periods run from a state in flight before the rod is declared never to touch
_FLIGHT_SEARCH_PERIODS = 50


def _shoot_scalar(walker, tau_s, v0, rtol, max_iter, slope=None):
    """Safeguarded secant iteration on the scalar period map ``u2'(tau_s) -> u2'(tau_s + 2 pi)``.

    Returns ``(start_state, iterations, last_end_state, walk)``;
    ``start_state`` is ``None`` when the rod is in flight at the section,
    where the map is not scalar. ``walk`` is the last period map's
    ``(segments, events)`` (:func:`_period_run` with ``record``): for a
    converged shooting, the steady period itself, which is then not walked
    again. ``slope``, an estimate of ``P' - 1`` (a neighbouring orbit's
    multiplier minus 1), makes the first step a Newton step instead of a
    fixed-point step, which covers only ``1 - P'`` of the distance on a
    barely contracting map.
    """
    vs = walker.vscale
    phi_s, dphi_s = walker.manifold(tau_s)

    def start_state(v):
        return walker.classify(ContactState(tau_s, Regime.FLIGHT, phi_s, dphi_s, 0.0, v))

    st = start_state(v0)
    if st.regime == Regime.FLIGHT:
        return None, 0, st, None
    end, *walk = _period_run(walker, st, record=True)
    it = 1
    xa, fa = v0, end.du2 - v0
    if fa == 0.0:
        return st, it, end, walk
    xb = end.du2
    if slope is not None and -2.5 < slope < -1e-6:
        xb = v0 - fa / slope
    while True:
        if end.regime == Regime.FLIGHT:
            return None, it, end, walk
        it += 1
        if it > max_iter:
            raise ConvergenceError(
                f"shooting did not converge in `max_iter`={max_iter} period maps "
                f"(residual {abs(fa) / vs:.3g} relative)")
        st = start_state(xb)
        end, *walk = _period_run(walker, st, record=True)
        if end.regime == Regime.FLIGHT:
            return None, it, end, walk
        fb = end.du2 - xb
        denom = fb - fa
        slope = denom / (xb - xa) if xb != xa else -1.0
        # stop on the estimated distance to the fixed point, |F| / |F'|: near a
        # barely contracting map (P' -> 1) the residual alone would understate it
        if abs(fb) <= rtol * vs * min(1.0, abs(slope)):
            return st, it, end, walk
        xn = xb - fb * (xb - xa) / denom if denom != 0.0 else xb + fb
        # the map is contracting, so F(x) = P(x) - x has slope in (-2, 0): a
        # secant slope far outside that range is a kink of the map; take a
        # fixed-point step instead
        if not (-2.5 < slope < 0.0) or not math.isfinite(xn):
            xn = xb + fb
        xa, fa, xb = xb, fb, xn




@register_section_run("friction-drive-walker")
def walker_section_states(scene, q, v, tau0, periods, options):
    """The walker's states at the ends of ``periods`` drive periods from ``(q, v)`` at ``tau0``.

    The run of :func:`moreau.analysis.classify.classify_long_run`, without
    the integrator's recording of every event and sample: the same walk
    (one walker for the whole run, as the integrator has), read at the
    sections only.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> from moreau.integrators import simulate
    >>> sc = FrictionDrive(frequency=185.0)
    >>> qs, vs = walker_section_states(sc, *sc.rest_state(), 0.0, 3, {})
    >>> r = simulate(sc, (0.0, 6 * np.pi), *sc.rest_state(), "event-driven")
    >>> qs.shape, bool(np.allclose(qs[3], r.q[-1], rtol=0, atol=1e-14))
    ((4, 2), True)
    """
    opts = dict(options)
    opts.pop("samples_per_period", None)
    walker = FrictionDriveWalker(scene, **opts)
    st = walker.classify(ContactState(tau0, Regime.FLIGHT, q[0], v[0], q[1], v[1]))
    qs = np.empty((periods + 1, 2))
    vs = np.empty((periods + 1, 2))
    qs[0], vs[0] = (st.phi, st.u2), (st.dphi, st.du2)
    for k in range(1, periods + 1):
        st = walker.advance(st, tau0 + k * TWO_PI)
        walker.checked_gap(st)
        qs[k], vs[k] = (st.phi, st.u2), (st.dphi, st.du2)
    return qs, vs


@register_steady_solver("friction-drive-walker")
def walker_steady_state(scene, rtol=1e-10, v_guess=None, max_iter=60, guess=None, floquet=True,
                        **options):
    """Event-driven periodic steady state of the friction drive (see ``find_steady_state``).

    The rotor position ``u2`` does not enter the dynamics, so the period map
    acts on ``(phi, phi', u2')`` at ``tau = 0``; when the rod touches the rotor
    there, ``phi`` and ``phi'`` are fixed by the constraint and the map is a
    scalar map of ``u2'``. Its fixed point is found by a safeguarded secant
    iteration (the map is contracting, often barely so at high frequency).
    ``rtol`` bounds the estimated distance of ``u2'`` from the fixed point
    relative to the tip-velocity scale; ``v_guess`` is the first ``u2'``,
    by default the rotor velocity of ``guess`` (a neighbouring point's
    steady state, continuation) or else the tip's velocity.
    The Floquet multiplier of the map comes from the saltation matrices of
    the period's events (:mod:`moreau.scenes.friction_drive.floquet`);
    ``floquet=False`` skips them (``floquet_multipliers`` stays unset).
    """
    rtol = positive("rtol", rtol)
    max_iter = positive_int("max_iter", max_iter)

    t_start = time.perf_counter()
    walker = FrictionDriveWalker(scene, rtol=min(1e-12, rtol * 1e-2), **options)
    vs = walker.vscale
    # Poincare section: the phase where the rotor is pressed hardest (most
    # negative free normal acceleration D on the contact manifold), so the
    # rod is in contact there and the period map is a scalar map of u2'
    tg = walker.tg
    phig, dphig = walker.g_phi, walker.g_dphi
    Dg = scene.coefficients(phig, dphig, tg)[3]
    tau_s = 0.0 if Dg[0] <= 0.5 * Dg.min() else float(tg[int(np.argmin(Dg))])
    slope = None
    if v_guess is None and guess is not None:
        v_guess = float(np.asarray(guess.state0, float)[-1])
        m = getattr(guess, "floquet_multipliers", None)
        if m is not None and len(m) == 1 and abs(complex(m[0]).imag) == 0.0:
            # the neighbour's multiplier: the slope of this point's scalar map, nearly
            slope = complex(m[0]).real - 1.0
    v0 = walker.vtip(tau_s) if v_guess is None else float(v_guess)
    st0, it, last, walk = _shoot_scalar(walker, tau_s, v0, rtol, max_iter, slope)
    if st0 is None:
        # the rod is in flight at this section in the steady state: move the
        # section into the longest contact segment of the settled motion
        # (with restitution the rod may fly through whole periods between
        # impacts, so look over several periods before concluding)
        contact = []
        for _ in range(_FLIGHT_SEARCH_PERIODS):
            last, segs, _ = _period_run(walker, last, record=True)
            contact = [(b.tau - a.tau, a.tau, b.tau) for a, b in segs
                       if a.regime != Regime.FLIGHT]
            if contact:
                break
        if not contact:
            raise ConvergenceError(
                f"the rod does not touch the rotor in {_FLIGHT_SEARCH_PERIODS} periods after the "
                "shooting's last state: no steady contact motion was found")
        _, ta, tb = max(contact)
        tau_s = 0.5 * (ta + tb) % TWO_PI
        st0, it2, last, walk = _shoot_scalar(walker, tau_s, walker.vtip(tau_s), rtol, max_iter)
        it += it2
        if st0 is None:
            raise ConvergenceError(
                f"no Poincare section with the rod in contact was found (last tried tau = "
                f"{tau_s:.4g}); the motion may not be 2 pi-periodic")
    # the converged shooting's last map walked the steady period from st0
    end = last
    segs, evs = walk
    residual = abs(end.du2 - st0.du2) / vs
    runs = []  # [tau_start, letter, entered_by_impact]
    impact_at = {e.t for e in evs if e.kind == "impact"}
    for a, b in segs:
        if b.tau - a.tau <= 0.0:
            continue
        letter = REGIME_LETTERS[a.regime]
        if runs and runs[-1][1] == letter:
            continue
        runs.append([a.tau, letter, a.tau in impact_at])
    mode = mode_name([r[1] for r in runs], [r[2] for r in runs])
    # report over [0, 2 pi): rotate so that the list starts with the regime active at tau = 0
    regimes = sorted(([t % TWO_PI, r] for t, r, _ in runs), key=lambda x: x[0])
    if regimes and regimes[0][0] > 0.0:
        regimes.insert(0, [0.0, regimes[-1][1]])
    merged = []
    for t, r in regimes:
        if not merged or merged[-1][1] != r:
            merged.append([t, r])
    regimes = merged
    ss = SteadyState(
        scheme="event-driven",
        displacement_per_period=float(end.u2 - st0.u2),
        state0=np.array([st0.phi, st0.dphi, st0.du2]),
        mode=mode,
        regimes=regimes,
        min_normal_force=_min_normal_force(walker, segs),
        periodic_residual=float(residual),
        iterations=it,
        wall_time=time.perf_counter() - t_start,
        stats=dict(walker.counters),
        section_tau=float(st0.tau),
    )
    # the multiplier of the scalar map: saltation matrices through the period's events,
    # or where an event grazes its surface (no derivative exists there) the map's own
    # central differences, which then measure its slope on a 1e-5 scale
    if not floquet:
        # the caller wants the orbit only (a reference value): no multipliers
        ss.wall_time = time.perf_counter() - t_start
        return ss
    try:
        # the period just walked from st0 is the one the monodromy walks: hand it on
        M = walker_monodromy(scene, ss, rtol=walker.rtol, walker=walker, walk=(segs, evs))
        ss.floquet_method = "saltation"
    except GrazingEvent:
        M = np.array([[walker_period_map_slope(scene, ss, rtol=walker.rtol, walker=walker)]])
        ss.floquet_method = "finite-differences"
    ss.floquet_multipliers = sorted_multipliers(np.linalg.eigvals(M))
    ss.wall_time = time.perf_counter() - t_start
    return ss




def _contact_power(walker, start, regime):
    """Stator, load and friction power along a contact piece that starts at ``start``."""
    sc = walker.scene
    ser = walker.series.get(regime)
    a0 = float(ser.A(np.array([start.tau]))[0]) if ser is not None else 0.0

    def power(tau):
        phi, dphi, ddphi = sc.contact_angle(tau)
        s, c = np.sin(phi), np.cos(phi)
        fN, fT = sc.contact_forces(tau, regime)
        if regime == Regime.STICK:
            du2 = -s * dphi
            slip = np.zeros_like(tau)
        else:
            du2 = start.du2 + ser.c0 * (tau - start.tau) + ser.A(tau) - a0
            slip = du2 + s * dphi
        stator = (sc.ddu1(tau) + 0.5 * (ddphi * c - dphi * dphi * s) + fN) * sc.du1(tau)
        return np.vstack([stator, sc.fL * du2, -fT * slip])
    return power


def _flight_power(sc, sol):
    def power(tau):
        y = np.asarray(sol(tau))
        phi, dphi, du2 = y[0], y[1], y[3]
        s, c = np.sin(phi), np.cos(phi)
        ddphi = 3.0 * (sc.P * c * (sc.sin_phi0 - s) - 0.5 * sc.ddu1(tau) * c + sc.fp * c)
        stator = (sc.ddu1(tau) + 0.5 * (ddphi * c - dphi * dphi * s)) * sc.du1(tau)
        return np.vstack([stator, sc.fL * du2, np.zeros_like(tau)])
    return power


def _flight_parts(sol, a, b):
    # (dense output, its step times) of the pieces a flight's dense output is joined from
    if hasattr(sol, "first"):
        return [(sol.first, a, sol.t_split), (sol.second, sol.t_split, b)]
    return [(sol, a, b)]


def _flight_integral(sc, sol, a, b):
    total = np.zeros(3)
    for part, lo, hi in _flight_parts(sol, a, b):
        if not hi > lo:
            continue
        ts = np.asarray(getattr(part, "ts", [lo, hi]), float)
        edges = np.unique(np.concatenate([[lo, hi], ts[(ts > lo) & (ts < hi)]]))
        # one 16-point rule per solver step: the dense output is one polynomial there
        mid, half = 0.5 * (edges[:-1] + edges[1:]), 0.5 * np.diff(edges)
        x, w = np.polynomial.legendre.leggauss(16)
        tau = (mid[:, None] + half[:, None] * x).ravel()
        total += _flight_power(sc, part)(tau) @ (half[:, None] * w).ravel()
    return total


def _qv(st):
    return np.array([st.phi, st.u2]), np.array([st.dphi, st.du2])


@register_energy_audit("friction-drive-walker")
def walker_energy_audit(scene, steady, options):
    """Energy audit of the walker's steady period (:mod:`moreau.analysis.energy`).

    The period is walked again from the steady state's section; the power
    terms are integrated along the exact contact pieces and the flights'
    dense output, and each jump of the state between pieces enters through
    its impulses. Closes to about 1e-12 of the stator's work.
    """
    walker = FrictionDriveWalker(scene, rtol=float(options.get("walker_rtol", 1e-12)))
    tau_s = float(getattr(steady, "section_tau", 0.0) or 0.0)
    phi, dphi, du2 = (float(x) for x in steady.state0)
    st0 = walker.classify(ContactState(tau_s, Regime.FLIGHT, phi, dphi, 0.0, du2))
    start = st0.copy()
    pieces = []
    # the walker changes a finished segment's end state in place (impact, manifold): copy
    end = walker.advance(st0, tau_s + TWO_PI,
                         on_segment=lambda a, b, sol: pieces.append((a.copy(), b.copy(), sol)))
    energy = RodEnergy(scene)
    stator = load = pos = neg = impact = 0.0
    prev = start
    for a, b, sol in pieces + [(end, None, None)]:
        # a jump of the state between the previous piece's end and this start
        qa, va = _qv(a)
        qp, vp = _qv(prev)
        if np.any(va != vp):
            w, loss = energy.jump(qp, vp, va, a.tau)
            stator += w
            impact += loss
        if b is None:
            break
        if a.regime == Regime.FLIGHT:
            I = _flight_integral(scene, sol, a.tau, b.tau)
        else:
            I = gauss_legendre(_contact_power(walker, a, a.regime), a.tau, b.tau)
        stator += I[0]
        load += I[1]
        if a.regime == Regime.POSITIVE:
            pos += I[2]
        elif a.regime == Regime.NEGATIVE:
            neg += I[2]
        prev = b
    e0, e1 = energy.energy(*_qv(start), start.tau), energy.energy(*_qv(end), end.tau)
    # the energy's size over the period (at the pieces' starts) scales the rounding bound
    levels = [e0, e1] + [energy.energy(*_qv(a), a.tau) for a, _, _ in pieces]
    return balance({"stator_work": stator, "load_work": load, "friction_positive_slip": pos,
                    "friction_negative_slip": neg, "impact_loss": impact,
                    "stored_energy_change": float(e1 - e0)}, levels)
