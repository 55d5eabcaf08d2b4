"""Statistical steady states: the long-run mean displacement per period of a non-periodic motion.

Where a periodically driven scene has no periodic orbit (the motion is
quasi-periodic or chaotic), or the scheme's period map has one only to a
residual floor (a time-stepping map whose switches are locked to its grid),
the quantity that still has a meaning is the long-run mean of the
displacement per period, with a statement of how well it is known.

Method
------
The scene is run period after period from a given state and the
displacement of its cyclic coordinate over each period, ``d_k``, is
recorded (the coordinate is reset to 0 between chunks of periods so that
its growth does not eat the digits of ``d_k``). After every doubling of the
run the series is examined:

1. **Transient**: MSER-5 (White 1997; Franklin and White 2008). The series
   is averaged in groups of 5; the truncation ``t`` minimises the marginal
   standard error ``sum_{i > t} (Y_i - mean_t)^2 / (n - t)^2`` over
   all ``t`` (the last few groups aside). A minimiser in the second half
   of the series means it is still drifting (the rule of the method): the
   run is doubled, never averaged.
2. **Stationarity and interval**: the retained series is cut into
   :data:`BATCHES` batches of equal length (non-overlapping batch means,
   Schmeiser 1982). The half-width of the interval is
   ``t_{B-1, (1+c)/2} s_B / sqrt(B)``, with ``s_B`` the standard deviation
   of the batch means and ``c`` the confidence, but never less than the
   resolution of the displacements themselves, :data:`RESOLUTION` times the
   scale below (a deterministic, converged series has no sampling error, but
   its ``d_k`` are only as good as the scheme's event location and
   rounding: the walker's long run and its shot orbit differ by 4.5e-13
   relative at 185 Hz, a grid-locked Schatzman–Paoli map's long run and its
   bracketed fixed point by 1.1e-9 at 2000 Hz). Batch means that are still
   correlated understate the variance of their mean: with a positive lag-1
   autocorrelation ``rho`` of the batch means the half-width is widened by
   ``sqrt((1 + rho) / (1 - rho))`` (the variance factor of an AR(1)
   series), and above :data:`MAX_LAG1` the batches are too short for the
   correlation time of the motion and the run is doubled.
3. **Stop**: when the half-width is at most ``precision`` times
   ``max(|mean|, 0.01 * 2 pi * velocity_scale)`` (the floor, 1 % of the
   displacement of the stator's speed over a period, keeps a zero mean
   measurable), the result is returned. After ``max_periods`` periods
   without that, :class:`~moreau.errors.BudgetExhaustedError` is raised
   (status ``"budget-exhausted"``), carrying the estimate so far.

The interval is statistical: it covers the sampling error of the scheme's
own long-run mean, not the scheme's discretisation error.

The mean is that of the attractor the run from the given state ends on. A
drive may have several: at 15 kHz with ``e = 1`` the friction drive's
reference from rest spins the rotor up, over about 20 000 periods, onto a
chaotic attractor (9.7e-6 m a period), while from the state where
Moreau–Jean's run from rest ends it stays on a regular one, one impact a
period (5.66e-6 m). Moreau–Jean there converges to the reference at first
order in the step; started on the chaotic attractor it leaves it for the
regular one after a number of periods that grows as the step shrinks
(``benchmarks/statistical_agreement.py`` measures all of this). Compare
schemes from the same state, and check which attractor a run ended on
(its ``state0``) before comparing means.

Examples
--------
>>> from moreau.scenes.friction_drive import FrictionDrive
>>> ss = statistical_steady_state(FrictionDrive(frequency=185.0), "moreau-jean",
...                               steps_per_period=200, theta=1.0)
>>> ss.statistical, ss.confidence_interval[0] <= ss.displacement_per_period <= ss.confidence_interval[1]
(True, True)
"""

import math
import time

import numpy as np
# the Student t quantile from scipy.special (loaded with scipy.optimize anyway), the
# function scipy.stats.t.ppf calls: importing scipy.stats costs 0.35 CPU s in every process
# that loads the command line
from scipy.special import stdtrit

from .._validate import positive, positive_int
from ..errors import BudgetExhaustedError, ConvergenceError, InputError, MoreauError, RunawayError
from ..integrators import get_integrator
from ..integrators.base import check_options, scheme_options as options_of
from ..integrators.result import SteadyState
from .periodic_shooting import period_map_options
from .runaway import runaway_in
from .section_runs import section_states

__all__ = ["statistical_steady_state", "mser5_truncation", "batch_means", "METHOD",
           "MAX_PERIODS", "BATCHES", "CHUNK", "RESOLUTION", "MAX_LAG1"]

TWO_PI = 2.0 * math.pi

#: default budget of drive periods
MAX_PERIODS = 40000
#: periods of the first look at the series (then doubled)
MIN_PERIODS = 200
#: number of batch means
BATCHES = 20
#: most periods simulated in one call (the cyclic coordinate is reset between calls)
CHUNK = 500
#: largest lag-1 autocorrelation of the batch means accepted (then widened, see above)
MAX_LAG1 = 0.7
#: smallest half-width claimed, relative to ``max(|mean|, 0.01 * 2 pi * velocity_scale)``
RESOLUTION = 1e-8
#: the method, as the JSON states it
METHOD = (f"MSER-5 transient truncation, {BATCHES} non-overlapping batch means, Student t "
          f"interval widened by the AR(1) factor of their lag-1 autocorrelation (at most "
          f"{MAX_LAG1})")


def mser5_truncation(d):
    """Number of leading entries of ``d`` that are transient (MSER-5), or None if still drifting.

    Parameters
    ----------
    d : array_like
        The series (displacements per period).

    Returns
    -------
    int or None
        A multiple of 5; None when the minimiser lies in the second half of
        the series: the series is taken as not yet stationary.

    Examples
    --------
    >>> d = np.r_[np.linspace(5.0, 1.0, 40), 1.0 + 0.01 * np.sin(np.arange(400))]
    >>> mser5_truncation(d)
    40
    >>> mser5_truncation(np.linspace(0.0, 1.0, 400)) is None
    True
    """
    d = np.asarray(d, float)
    nb = d.size // 5
    if nb < 4:
        return None
    y = d[:5 * nb].reshape(nb, 5).mean(axis=1)
    # tail sums from the end: mean and sum of squares of y[t:] for every t
    cs = np.cumsum(y[::-1])[::-1]
    cs2 = np.cumsum((y * y)[::-1])[::-1]
    m = nb - np.arange(nb)
    sse = cs2 - cs * cs / m
    limit = nb - 4          # leave at least a few groups to average
    stat = np.maximum(sse[:limit], 0.0) / m[:limit] ** 2
    t = int(np.argmin(stat))
    if t > nb // 2:
        return None
    return 5 * t


def batch_means(y, batches=BATCHES, confidence=0.95):
    """``(mean, half_width, lag1)`` of the non-overlapping batch means of ``y``.

    The leading ``len(y) % batches`` entries are dropped so that the batches
    have equal length; ``mean`` is the mean of the rest, ``half_width`` the
    Student-t half-width at ``confidence``, ``lag1`` the lag-1
    autocorrelation of the batch means (0 where they do not vary).

    Examples
    --------
    >>> m, hw, r1 = batch_means(np.ones(100))
    >>> m, hw, r1
    (1.0, 0.0, 0.0)
    """
    y = np.asarray(y, float)
    size = y.size // batches
    if size < 1:
        raise InputError(f"`y` must have at least {batches} entries, got {y.size}")
    y = y[y.size - size * batches:]
    bm = y.reshape(batches, size).mean(axis=1)
    mean = float(y.mean())
    s = float(np.std(bm, ddof=1))
    half = float(stdtrit(batches - 1, 0.5 * (1.0 + confidence))) * s / math.sqrt(batches)
    dev = bm - bm.mean()
    den = float(dev @ dev)
    lag1 = float(dev[:-1] @ dev[1:]) / den if den > 0.0 else 0.0
    return mean, half, lag1


def _sampling(scheme, takes, opts):
    # ask the scheme for one sample per drive period (plus whatever it records at events)
    out = dict(opts)
    if "h" in takes and "save_every" in takes:
        out["save_every"] = int(round(TWO_PI / out["h"]))
    elif "sample_dt" in takes:
        out["sample_dt"] = TWO_PI
    elif "samples_per_period" in takes:
        out["samples_per_period"] = 1
    return out


def _run_periods(scene, scheme, q, v, ts, m, cyclic, opts):
    """Displacements over ``m`` periods from ``(q, v)`` at ``ts``, and the end state."""
    q = np.array(q, float)
    q[cyclic] = 0.0
    try:
        qs, vs, vmax = section_states(scene, scheme, opts, ts, q, np.array(v, float), m)
    except MoreauError as exc:
        raise ConvergenceError(f"the run of the statistical steady state failed: {exc}") from exc
    return np.diff(qs[:, cyclic]), qs[-1].copy(), vs[-1].copy(), vmax


def statistical_steady_state(scene, scheme="event-driven", q0=None, v0=None, section_tau=0.0,
                             precision=1e-3, confidence=0.95, max_periods=MAX_PERIODS,
                             cyclic=None, scheme_options=None, **options):
    """Long-run mean displacement per period, with a confidence interval (see the module doc).

    Parameters
    ----------
    scene : Scene
        A ``2 pi``-periodic scene with a cyclic coordinate.
    scheme : str
        Any registered scheme.
    q0, v0 : array_like, optional
        Start at the section; the scene's ``initial_state()`` by default.
    section_tau : float
        Phase at which the periods start.
    precision : float
        Wanted half-width of the interval relative to
        ``max(|mean|, 0.01 * 2 pi * velocity_scale)``.
    confidence : float
        Level of the interval, in (0, 1).
    max_periods : int
        Budget: drive periods simulated at most (transient included).
    cyclic : int, optional
        The cyclic coordinate; the scene's one by default.
    scheme_options : dict, optional
        The scheme's options, merged with ``options``.
    **options
        Passed to the scheme; ``steps_per_period`` sets a time-stepping
        scheme's step (2000 by default, as for the shooting).

    Returns
    -------
    SteadyState
        ``statistical=True``, ``displacement_per_period`` the mean,
        ``confidence_interval`` its ``(low, high)``, ``periods_used`` the
        periods averaged, ``stats`` with ``transient_periods``,
        ``periods_simulated``, ``half_width``, ``lag1_autocorrelation``,
        ``method`` and ``status`` (``"converged"``); ``mode`` is
        ``"non-periodic"``, ``period`` 0, no Floquet multipliers,
        ``min_normal_force`` infinite (unknown: the runs are sampled once a
        period) and ``periodic_residual`` infinite (no orbit closes).

    Raises
    ------
    RunawayError
        At a look, the second half of the displacements shows a runaway
        (:func:`moreau.analysis.runaway.runaway_in`).
    BudgetExhaustedError
        The mean was not stationary within ``precision`` after ``max_periods``.
    ConvergenceError
        The scheme failed along the way.
    """
    if cyclic is None:
        cyc = tuple(getattr(scene, "cyclic_coordinates", ()))
        cyclic = cyc[0] if len(cyc) == 1 else None
    if cyclic is None or not 0 <= int(cyclic) < scene.ndof:
        raise InputError(f"`cyclic` must name a coordinate of the scene (0..{scene.ndof - 1}) "
                         f"that does not enter its dynamics, got {cyclic!r}")
    cyclic = int(cyclic)
    precision = positive("precision", precision)
    if not 0.0 < float(confidence) < 1.0:
        raise InputError(f"`confidence` must be in (0, 1), got {confidence!r}")
    confidence = float(confidence)
    max_periods = positive_int("max_periods", max_periods)
    if max_periods < MIN_PERIODS:
        raise InputError(f"`max_periods` must be at least {MIN_PERIODS}, got {max_periods}")
    get_integrator(scheme)
    clash = set(scheme_options or {}) & set(options)
    if clash:
        raise InputError(f"`{sorted(clash)[0]}` is given twice (in `scheme_options` and as a keyword)")
    opts = period_map_options(scheme, {**options, **(scheme_options or {})})
    check_options(scheme, opts, scene)
    opts = _sampling(scheme, options_of(get_integrator(scheme)) or (), opts)
    if q0 is None or v0 is None:
        q0, v0 = scene.initial_state()
    q, v = np.array(q0, float), np.array(v0, float)
    ts = float(section_tau)

    start = time.perf_counter()
    d = np.zeros(0)
    vmax = 0.0
    vs = getattr(scene, "velocity_scale", None)
    target = MIN_PERIODS
    why = "no look yet"
    est = (None, None)
    while True:
        while d.size < target:
            m = min(CHUNK, target - d.size)
            dk, q, v, vm = _run_periods(scene, scheme, q, v, ts, m, cyclic, opts)
            d = np.concatenate([d, dk])
            vmax = max(vmax, vm)
        if not np.all(np.isfinite(d)):
            raise ConvergenceError("the displacements per period are not finite: the run "
                                   "diverged")
        # the second half: the first may hold the transient from a far start
        runaway = runaway_in(d[d.size // 2:], scene)
        if runaway:
            raise RunawayError(f"{runaway}; statistical steady state stopped after {d.size} "
                               f"periods")
        scale_v = float(np.max(np.abs(vs))) if vs is not None else vmax
        floor_d = 0.01 * TWO_PI * scale_v
        cut = mser5_truncation(d)
        if cut is None:
            why = (f"the running mean still drifts after {d.size} periods (MSER-5 puts the end "
                   f"of the transient in its second half)")
        else:
            y = d[cut:]
            mean, half, lag1 = batch_means(y, BATCHES, confidence)
            ref_scale = max(abs(mean), floor_d)
            if lag1 > 0.0:
                half *= math.sqrt((1.0 + lag1) / (1.0 - lag1)) if lag1 < 1.0 else math.inf
            half = max(half, RESOLUTION * ref_scale)
            est = (mean, half)
            wanted = precision * ref_scale
            indep = lag1 <= MAX_LAG1
            if half <= wanted and indep:
                break
            why = (f"after {d.size} periods (transient {cut}) the interval half-width is "
                   f"{half:.3g} against {wanted:.3g} wanted" +
                   ("" if indep else f", and the batch means are correlated (lag 1: {lag1:.2f}"
                    f" > {MAX_LAG1})"))
        if d.size >= max_periods:
            raise BudgetExhaustedError(
                f"statistical steady state: budget exhausted (`max_periods`={max_periods}): "
                f"{why}", periods=d.size, mean=est[0], half_width=est[1], series=d)
        target = min(max_periods, 2 * d.size)

    used = d.size - (d.size - cut) % BATCHES - cut
    qs = q.copy()
    qs[cyclic] = 0.0
    return SteadyState(
        scheme=scheme,
        displacement_per_period=float(mean),
        state0=np.concatenate([qs, v]),
        mode="non-periodic",
        regimes=[],
        # the runs are sampled once a period: the forces within are not known
        min_normal_force=math.inf,
        periodic_residual=math.inf,
        iterations=0,
        wall_time=time.perf_counter() - start,
        stats={"periodic": False, "status": "converged", "transient_periods": int(cut),
               "periods_simulated": int(d.size), "half_width": float(half),
               "lag1_autocorrelation": float(lag1), "method": METHOD,
               "precision": precision},
        section_tau=ts,
        period=0,
        statistical=True,
        confidence_interval=(float(mean - half), float(mean + half)),
        confidence=confidence,
        periods_used=int(used),
    )
