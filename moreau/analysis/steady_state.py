"""Periodic steady states of periodically driven scenes.

A scene whose state is invariant under translation of one coordinate (the
rotor position of the friction drive) has a period map on the remaining
state; its fixed point is the periodic steady state, found by shooting.
"""

import math
import time

import numpy as np
from scipy.optimize import minimize_scalar

from .._validate import positive, positive_int
from ..errors import ConvergenceError, InputError, RunawayError
# SteadyState is defined with the other scheme results (below this layer)
# and re-exported here, where callers have always found it
from ..integrators.result import SteadyState
from ..scenes.base import Scene
from ..scenes.friction_drive_walker import ContactState, FrictionDriveWalker
from ..modes import mode_name
from ..regimes import REGIME_LETTERS, Regime
from .mj_steady_state import moreau_jean_steady_state
from .periodic_shooting import shoot_periodic

__all__ = ["SteadyState", "find_steady_state"]


# -- event-driven steady state of the friction drive ------------------------------

TWO_PI = 2.0 * math.pi


def _period_run(walker, state, record=False):
    """Advance one period from ``state``; return (end_state, segments, events)."""
    segs, evs = [], []
    on_seg = (lambda a, b, sol: segs.append((a, b))) if record else None
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


def _shoot_scalar(walker, tau_s, v0, rtol, max_iter):
    """Safeguarded secant iteration on the scalar period map ``u2'(tau_s) -> u2'(tau_s + 2 pi)``.

    Returns ``(start_state, iterations, last_end_state)``; ``start_state`` is
    ``None`` when the rod is in flight at the section, where the map is not
    scalar.
    """
    vs = walker.vscale
    phi_s, dphi_s = walker.manifold(tau_s)

    def start_state(v):
        return walker.classify(ContactState(tau_s, Regime.FLIGHT, phi_s, dphi_s, 0.0, v))

    st = start_state(v0)
    if st.regime == Regime.FLIGHT:
        return None, 0, st
    end, _, _ = _period_run(walker, st)
    it = 1
    xa, fa = v0, end.du2 - v0
    if fa == 0.0:
        return st, it, end
    xb = end.du2
    while True:
        if end.regime == Regime.FLIGHT:
            return None, it, end
        it += 1
        if it > max_iter:
            raise ConvergenceError(
                f"shooting did not converge in `max_iter`={max_iter} period maps "
                f"(residual {abs(fa) / vs:.3g} relative)")
        st = start_state(xb)
        end, _, _ = _period_run(walker, st)
        if end.regime == Regime.FLIGHT:
            return None, it, end
        fb = end.du2 - xb
        denom = fb - fa
        slope = denom / (xb - xa) if xb != xa else -1.0
        # stop on the estimated distance to the fixed point, |F| / |F'|: near a
        # barely contracting map (P' -> 1) the residual alone would understate it
        if abs(fb) <= rtol * vs * min(1.0, abs(slope)):
            return st, it, end
        xn = xb - fb * (xb - xa) / denom if denom != 0.0 else xb + fb
        # the map is contracting, so F(x) = P(x) - x has slope in (-2, 0): a
        # secant slope far outside that range is a kink of the map; take a
        # fixed-point step instead
        if not (-2.5 < slope < 0.0) or not math.isfinite(xn):
            xn = xb + fb
        xa, fa, xb = xb, fb, xn


def find_steady_state(scene, scheme="event-driven", rtol=1e-10, v_guess=None, max_iter=60,
                      **options):
    """Periodic steady state of a periodically driven scene, found by shooting, and checked.

    The one entry point for every scheme and every caller: what the shooting
    returns is refused (:class:`~moreau.errors.RunawayError`) when it cannot
    be a steady state (:func:`implausible_steady_state`): a rotor faster
    than the rod's tip can drive it, loaded or not (a runaway past stall,
    whose state is so large that rounding hides the change a period makes,
    so the periodic residual reads 0). See :func:`_find_steady_state` for
    the parameters.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> find_steady_state(FrictionDrive(frequency=20.0)).mode
    'NS'
    >>> find_steady_state(FrictionDrive(frequency=185.0, load=0.01))
    Traceback (most recent call last):
    ...
    moreau.errors.RunawayError: no steady state: past stall (load F_L = 0.01 N); the rotor runs away backwards, ...
    """
    if not isinstance(scene, Scene):
        raise InputError(f"`scene` must be a Scene instance, got {type(scene).__name__}")
    ss = _find_steady_state(scene, scheme, rtol, v_guess, max_iter, **options)
    why = implausible_steady_state(scene, ss)
    if why:
        raise RunawayError(why)
    return ss


def _find_steady_state(scene, scheme="event-driven", rtol=1e-10, v_guess=None, max_iter=60,
                       **options):
    """Periodic steady state of the friction drive, found by shooting.

    The rotor position ``u2`` does not enter the dynamics, so the period map
    acts on ``(phi, phi', u2')`` at ``tau = 0``; when the rod touches the rotor
    there, ``phi`` and ``phi'`` are fixed by the constraint and the map is a
    scalar map of ``u2'``. Its fixed point is found by a safeguarded secant
    iteration (the map is contracting, often barely so at high frequency);
    with the rod in flight at ``tau = 0`` a Newton iteration on the full
    three-dimensional map is used.

    Parameters
    ----------
    scene : Scene
        A ``2 pi``-periodic scene with ``cyclic_coordinates``. The friction
        drive's event-driven steady state uses its walker (below); other
        scenes' event-driven steady states are found by
        :func:`moreau.analysis.periodic_shooting.shoot_periodic`, and every
        scene's Moreau–Jean steady state by the compiled period map of
        :func:`moreau.analysis.mj_steady_state.moreau_jean_steady_state`.
    scheme : str
        ``"event-driven"`` (this function) or ``"moreau-jean"`` (delegates to
        :func:`moreau.analysis.mj_steady_state.moreau_jean_steady_state`,
        which takes ``steps_per_period`` and ``theta`` in ``options``).
    rtol : float
        Tolerance on the estimated distance of ``u2'`` from the fixed point
        (residual over the secant slope of ``P(x) - x``), relative to the
        tip-velocity scale.
    v_guess : float, optional
        Initial guess of ``u2'`` at ``tau = 0`` (dimensionless).
    max_iter : int

    Returns
    -------
    SteadyState

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> ss = find_steady_state(FrictionDrive(frequency=20.0))
    >>> ss.mode
    'NS'
    """
    if scheme == "moreau-jean":
        return moreau_jean_steady_state(scene, **options)
    if scheme != "event-driven":
        raise InputError(f"`scheme` must be one of ['event-driven', 'moreau-jean'], got {scheme!r}")
    if getattr(scene, "reference_integrator", None) != "friction-drive-walker":
        # any other periodic scene: Newton shooting on the generic event-driven period map
        return shoot_periodic(scene, scheme, rtol=rtol, max_iter=max_iter, **options)
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
    v0 = walker.vtip(tau_s) if v_guess is None else float(v_guess)
    st0, it, last = _shoot_scalar(walker, tau_s, v0, rtol, max_iter)
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
        st0, it2, last = _shoot_scalar(walker, tau_s, walker.vtip(tau_s), rtol, max_iter)
        it += it2
        if st0 is None:
            raise ConvergenceError(
                f"no Poincare section with the rod in contact was found (last tried tau = "
                f"{tau_s:.4g}); the motion may not be 2 pi-periodic")
    end, segs, evs = _period_run(walker, st0, record=True)
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
    return ss


def implausible_steady_state(scene, ss):
    """Why a converged steady state of a driven scene cannot be right, or None.

    Two checks, for any scheme:

    * the state must resolve the change a period makes: with a velocity
      scale ``vs`` (the scene's ``velocity_scale``, the stator's speed),
      ``eps max|x| <= 1e-6 vs`` for the periodic state ``x``; a runaway orbit
      (|u2'| ~ 1e14) rounds every change away and its residual reads 0;
    * the rotor cannot on average outrun the rod's tip by far: friction has
      to change sign for a periodic motion (with a load too: a rotor always
      faster than the tip takes one-signed friction, which balances a load
      only by coincidence), so its average speed stays below the largest tip
      speed. Every sound point of the atlases stays below 1.0 times it; past
      stall the shooting can settle on orbits far above it.

    Returns
    -------
    str or None
        The reason, naming the stall side when the scene has a load.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=185.0)
    >>> implausible_steady_state(sc, find_steady_state(sc)) is None
    True
    """
    x = np.asarray(ss.state0, dtype=float)
    vs = getattr(scene, "velocity_scale", None)
    if vs is not None:
        vs = float(np.max(np.abs(vs)))
    load = getattr(getattr(scene, "params", None), "load", 0.0) or 0.0
    speed = abs(ss.displacement_per_period) / TWO_PI
    direction = "forwards" if ss.displacement_per_period > 0 else "backwards"
    side = (f"past stall (load F_L = {load:g} N); the rotor runs away {direction}, "
            if load else f"the rotor runs away {direction} with no load to drive it, ")
    if not np.all(np.isfinite(x)):
        return f"no steady state: {side}its periodic state is not finite"
    if vs and np.finfo(float).eps * float(np.max(np.abs(x))) > 1e-6 * vs:
        return (f"no steady state: {side}its periodic state ({float(np.max(np.abs(x))):.3g} in "
                f"the scene's units) is too large for a period's change to be resolved: the "
                f"periodic residual {ss.periodic_residual:.2g} only reflects rounding")
    if not hasattr(scene, "rest_state") and not hasattr(scene, "tip_velocity"):
        return None
    tip = _max_tip_speed(scene)
    if tip == 0.0:
        return None
    if not speed <= 2.0 * tip:
        return (f"no steady state: {side}{speed / tip:.3g} times faster on average than the "
                f"rod's tip can move, which friction cannot sustain (mode {ss.mode!r}; the "
                f"shooting converged on a runaway rotor)")
    return None


def _max_tip_speed(scene):
    # the single rod's tip velocity, or for several rods (the bidirectional
    # drive) the fastest tip on their contact manifolds, u_i' = sin(phi_i) phi_i'
    tau = np.linspace(0.0, TWO_PI, 257)
    if hasattr(scene, "tip_velocity"):
        return float(np.max(np.abs(scene.tip_velocity(tau))))
    tip = 0.0
    for t in tau:
        q, v = scene.rest_state(t)
        tip = max(tip, float(np.max(np.abs(np.sin(q[:2]) * v[:2]))))
    return tip
