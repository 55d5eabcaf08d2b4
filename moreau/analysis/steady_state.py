"""Periodic steady states of periodically driven scenes.

A scene whose state is invariant under translation of one coordinate (the
rotor position of the friction drive) has a period map on the remaining
state; its fixed point is the periodic steady state, found by shooting.
"""


from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._validate import positive_int
from ..errors import ConvergenceError, InputError, RunawayError
# SteadyState is defined with the other scheme results (below this layer)
# and re-exported here, where callers have always found it
from ..integrators import INTEGRATORS, get_integrator
from ..integrators.base import SchemeOptions
from ..integrators.result import SteadyState
from ..model.scene import Scene
# the package's generic solvers register themselves on import (a scene's own with its scene)
from . import mj_steady_state  # noqa: F401
from .period_k import find_period_k, full_state_of
from .periodic_shooting import guess_options, shoot_periodic
from .runaway import certain_runaway, runaway_side
from .statistical import (MAX_PERIODS, MIN_PERIODS, check_statistical_options,
                          statistical_steady_state)
from .steady_solvers import get_steady_solver, has_solver

__all__ = ["SteadyState", "find_steady_state"]


TWO_PI = 2.0 * math.pi


def find_steady_state(scene: Scene, scheme: str | SchemeOptions = "event-driven", rtol: float = 1e-10,
                      v_guess: float | None = None, max_iter: int = 60, max_period: int = 1,
                      statistical: bool = True, statistical_budget: int = MAX_PERIODS,
                      guess: ArrayLike | None = None,
                      statistical_options: dict | None = None, **options: Any) -> SteadyState:
    """Periodic steady state of a periodically driven scene, found by shooting, and checked.

    The one entry point for every scheme and every caller: what the shooting
    returns is refused (:class:`~moreau.errors.RunawayError`) when it cannot
    be a steady state (:func:`implausible_steady_state`): a rotor faster
    than the rod's tip can drive it, loaded or not (a runaway past stall,
    whose state is so large that rounding hides the change a period makes,
    so the periodic residual reads 0). See :func:`_find_steady_state` for
    the parameters.

    With ``max_period`` > 1, where the period-1 shooting fails
    (:class:`~moreau.errors.ConvergenceError`) or its orbit is unstable (a
    Floquet multiplier outside the unit circle), orbits of period ``k = 2 ..
    max_period`` are sought by shooting on the ``k``-th iterate of the
    period map (:func:`moreau.analysis.period_k.find_period_k`); the first
    stable one is returned (``period = k``). Without one the period-1
    result (or its error) stands.

    With ``statistical`` (the default), where no periodic orbit was found
    (the shootings failed with a :class:`~moreau.errors.ConvergenceError`
    other than a runaway, or Moreau–Jean's discrete map settled on no
    period-1 orbit), the result is the statistical steady state
    (:func:`moreau.analysis.statistical.statistical_steady_state`): the
    long-run mean displacement per period with its confidence interval,
    from the best state the shooting reached (a time-stepping map's
    residual floor; its ``start`` says ``"period-1-search"``) or the
    scene's initial state, within ``statistical_budget`` drive periods
    (else :class:`~moreau.errors.BudgetExhaustedError`).
    ``statistical_options`` are passed on to it: ``precision``,
    ``confidence``, ``starts``, ``spread``, ``progress``.

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
    if isinstance(scheme, SchemeOptions):
        scheme, options = _scheme_object(scheme, options)
    max_period = positive_int("max_period", max_period)
    if max_period > MAX_PERIOD:
        raise InputError(f"`max_period` must be at most {MAX_PERIOD}, got {max_period}")
    if not isinstance(statistical, (bool, np.bool_)):
        raise InputError(f"`statistical` must be True or False, got {statistical!r}")
    statistical_budget = positive_int("statistical_budget", statistical_budget)
    statistical_options = dict(statistical_options or {})
    unknown = sorted(set(statistical_options) - set(STATISTICAL_OPTIONS))
    if unknown:
        raise InputError(f"`statistical_options` takes {', '.join(STATISTICAL_OPTIONS)}; got "
                         f"`{unknown[0]}`")
    check_statistical_options(max_periods=max(statistical_budget, MIN_PERIODS),
                              **{k: v for k, v in statistical_options.items() if k != "progress"})
    why = certain_runaway(scene)
    if why:
        # the physics says so: no shooting and no long run can find a steady state
        raise RunawayError(why)
    if guess is not None:
        _check_guess(scene, guess)
        options["guess"] = guess
    try:
        ss = _find_steady_state(scene, scheme, rtol, v_guess, max_iter, **options)
        failure = None
    except RunawayError:
        raise
    except ConvergenceError as exc:
        if max_period == 1 and not statistical:
            raise
        ss, failure = None, exc
    if ss is not None and not (ss.stats or {}).get("periodic", True):
        # Moreau-Jean's map settled on no period-1 orbit: its fixed-window average is
        # replaced by the statistical steady state, from where that run ended; without
        # ``statistical`` the caller wants an orbit or a failure, and a fixed window's
        # average is neither (it can sit inside a slow transient: a sweep row reading
        # 3.61 mm/s where the orbit gives 4.61, on the flexible rod at 2 kHz)
        failure = ConvergenceError(ss.stats.get("message", "no period-1 orbit"))
        failure.state = full_state_of(scene, ss.state0)
        start = ss
        ss = None
        if max_period == 1 and not statistical:
            raise failure
    else:
        start = ss
    if max_period > 1 and (ss is None or ss.stable is False):
        if start is None and options.get("q0") is not None and options.get("v0") is not None:
            start = (options["q0"], options["v0"])
        alt = find_period_k(scene, scheme, max_period, start=start,
                            section_tau=float(options.get("section_tau", 0.0)),
                            rtol=max(rtol, 1e-10), options=_shooting_options(scheme, options))
        if alt is not None:
            ss = alt
        elif failure is not None and not statistical:
            raise failure
    if ss is None:
        ss = _statistical(scene, scheme, failure, statistical_budget, options,
                          statistical_options)
    why = implausible_steady_state(scene, ss)
    if why:
        raise RunawayError(why)
    return ss


def _check_guess(scene, guess):
    # a continuation starts only from a period-1 orbit whose state fits this scene
    state = getattr(guess, "state0", None)
    if state is None or getattr(guess, "statistical", False) or getattr(guess, "period", 1) != 1:
        raise InputError("`guess` must be the period-1 SteadyState of a neighbouring point, got "
                         + (type(guess).__name__ if state is None else
                            f"a steady state of period {getattr(guess, 'period', '?')}"))
    full_state_of(scene, state)   # the right size for the scene, else a clear error
    if not np.all(np.isfinite(np.asarray(state, float))):
        raise InputError("`guess` must have a finite state")


#: the options of the statistical steady state that ``find_steady_state`` passes on
STATISTICAL_OPTIONS = ("precision", "confidence", "starts", "spread", "progress")


def _scheme_object(scheme, options):
    """``(name, options)`` of a scheme given as its options object, as a call by name takes them.

    Moreau–Jean's own solver takes its options as keywords (``theta``, ...);
    the shooting of any other scheme takes them as ``scheme_options``. The
    step is ``steps_per_period``, not ``h``.
    """
    given = scheme.without_step("`steps_per_period`")
    if scheme.scheme == "moreau-jean":
        return scheme.scheme, {**given, "theta": scheme.theta, **options}
    merged = {**given, **(options.get("scheme_options") or {})}
    return scheme.scheme, {**options, **({"scheme_options": merged} if merged else {})}


def _statistical(scene, scheme, failure, budget, options, extra=None):
    """The statistical steady state where the shooting found no orbit (``failure`` says why)."""
    state = getattr(failure, "state", None)
    kind = "period-1-search" if state is not None else None
    if state is None and options.get("x_guess") is not None:
        state, kind = full_state_of(scene, options["x_guess"]), "given"
    if state is None and options.get("q0") is not None and options.get("v0") is not None:
        state, kind = (options["q0"], options["v0"]), "given"
    q0, v0 = state if state is not None else (None, None)
    own = getattr(scene, "reference_integrator", None)
    run = own if scheme == "event-driven" and own is not None else scheme
    if run == "event-driven":
        # the dispatcher states no options of its own, so the run was not sampled once a
        # period ("did not sample the run at the ends of the drive periods", stick-slip motor)
        run = "event-driven-generic"
    opts = _shooting_options(scheme, options)
    if scheme == "moreau-jean":
        opts.setdefault("projection", options.get("projection", True))
    ss = statistical_steady_state(scene, run, q0=q0, v0=v0, start_kind=kind,
                                  section_tau=float(options.get("section_tau", 0.0)),
                                  max_periods=budget, **(extra or {}), **opts)
    ss.scheme = scheme
    ss.stats["why_not_periodic"] = str(failure)
    return ss


#: the longest orbit period find_steady_state looks for
MAX_PERIOD = 8

#: options of the steady-state solvers that are not options of the scheme itself
_SOLVER_ONLY = ("tol", "x_guess", "transient_periods", "fast", "section_tau", "q0", "v0",
                "cyclic", "scheme_options", "guess")


def _shooting_options(scheme, options):
    # the scheme's own settings, for shooting on an iterate of its period map
    out = {k: v for k, v in options.items() if k not in _SOLVER_ONLY}
    out.update(options.get("scheme_options") or {})
    return out


def _find_steady_state(scene, scheme="event-driven", rtol=1e-10, v_guess=None, max_iter=60,
                       **options):
    """Periodic steady state of a periodic scene by the solver registered for ``scheme``.

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
        :func:`find_steady_state` also takes a scheme's options object
        (``MoreauJean.Options(theta=0.5)``; its step is ``steps_per_period``).
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
    if not isinstance(scheme, str):
        raise InputError(f"`scheme` must be a scheme name, got {type(scheme).__name__}")
    own = getattr(scene, "reference_integrator", None)
    if scheme == "event-driven" and own is not None and has_solver(own):
        # the scene's own reference has a steady-state solver of its own (its walker)
        scheme = own
    if not has_solver(scheme):
        # any other registered scheme: Newton shooting on the period map it computes
        try:
            get_integrator(scheme)
        except InputError:
            known = ", ".join(repr(k) for k in sorted(INTEGRATORS))
            raise InputError(f"`scheme` must be a registered scheme, one of {known}; "
                             f"got {scheme!r}") from None
        if v_guess is not None:
            raise InputError(f"`v_guess` is not taken by the shooting of scheme {scheme!r}; "
                             "give `q0` and `v0`")
        options = guess_options(scene, options)
        return shoot_periodic(scene, scheme, rtol=rtol, max_iter=max_iter, **options)
    solver = get_steady_solver(scheme)
    return solver(scene, rtol=rtol, v_guess=v_guess, max_iter=max_iter, **options)
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
    speed = abs(ss.displacement_per_period) / TWO_PI
    side = runaway_side(scene, ss.displacement_per_period)
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
