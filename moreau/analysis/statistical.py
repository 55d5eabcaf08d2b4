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
2. **Interval**: the retained series is cut into :data:`BATCHES` batches
   of equal length (non-overlapping batch means, Schmeiser 1982). The
   half-width of the interval is ``t_{B-1, (1+c)/2} s_B / sqrt(B)``, with
   ``s_B`` the standard deviation of the batch means and ``c`` the
   confidence. Batch means that are still correlated understate the
   variance of their mean: with a positive lag-1 autocorrelation ``rho`` of
   the batch means the half-width is widened by ``sqrt((1 + rho) / (1 -
   rho))`` (the variance factor of an AR(1) series), and above
   :data:`MAX_LAG1` the run is doubled. Twenty batch means estimate their
   own correlation poorly, so the half-width is also at least
   ``t s sqrt(tau / n)`` for the ``n`` periods averaged, their standard
   deviation ``s`` and ``tau`` the largest variance inflation of batch
   means of any length with at least 20 batches (:func:`correlation_time`).
   It is never less than the resolution of the displacements themselves,
   :data:`RESOLUTION` times the scale below (a deterministic, converged
   series has no sampling error, but its ``d_k`` are only as good as the
   scheme's event location and rounding: the walker's long run and its
   shot orbit differ by 4.5e-13 relative at 185 Hz, a grid-locked
   Schatzman–Paoli map's long run and its bracketed fixed point by 1.1e-9
   at 2000 Hz).
3. **Stationarity**: the periods averaged must span at least
   :data:`MIN_TAUS` times ``tau`` (so that a batch spans five), and the
   means of their two halves must agree (a t test of their difference
   with the batch means of each half, at the level
   :data:`HALVES_LEVEL`); otherwise the run is doubled. Both checks are
   about honesty, not precision: a slow motion (the friction drive's
   chaotic flight at 15 kHz, ``e = 1``, whose displacement per period is
   correlated over thousands of periods) is run until it has shown its
   slow variation, whatever precision is asked. Without them the estimate
   claimed 1 % over 86 000 periods there, 9.739e-6 +- 6.4e-8 m, against
   9.635e-6 m over 720 000.
4. **Stop**: when the half-width is at most ``precision`` times
   ``max(|mean|, 0.01 * 2 pi * velocity_scale)`` (the floor, 1 % of the
   displacement of the stator's speed over a period, keeps a zero mean
   measurable) and the checks pass, the result is returned. After
   ``max_periods`` periods without that,
   :class:`~moreau.errors.BudgetExhaustedError` is raised (status
   ``"budget-exhausted"``), carrying the estimate so far.

The interval is statistical: it covers the sampling error of the scheme's
own long-run mean, not the scheme's discretisation error. No check can see
a variation slower than the run: a motion that switches between regimes
every few ten thousand periods (the friction drive with a 2e-8 kg rotor at
15 kHz, ``e = 1``: means 7.8e-6 and 8.5e-6 m a period in turns) gets,
from a run that saw one regime, an interval of that regime.

Starts and attractors
---------------------
The mean is that of the attractor the run from its start ends on, and a
drive may have several: at 15 kHz with ``e = 1`` the friction drive's
reference from rest spins the rotor up, over about 15 000 periods, onto a
chaotic attractor (9.7e-6 m a period), while from the state where
Moreau–Jean's run from rest ends it stays on a regular one, one impact a
period (5.65e-6 m). Every result says where its averaging started
(``start``: how, from rest, from a given state or from the best state of a
failed period-1 search, and the state itself). With ``starts`` = K the
mean is also taken from K - 1 more starts, the rest state with the rotor
spun up to fractions of the tip's speed amplitude; the means whose
intervals overlap are grouped into ``attractors``, and more than one
attractor is logged as a warning. Compare schemes from the same state.

Examples
--------
>>> from moreau.scenes.friction_drive import FrictionDrive
>>> ss = statistical_steady_state(FrictionDrive(frequency=185.0), "moreau-jean",
...                               steps_per_period=200, theta=1.0)
>>> ss.statistical, ss.confidence_interval[0] <= ss.displacement_per_period <= ss.confidence_interval[1]
(True, True)
"""

import logging
import math
import time

import numpy as np
# the Student t quantile from scipy.special (loaded with scipy.optimize anyway), the
# function scipy.stats.t.ppf calls: importing scipy.stats costs 0.35 CPU s in every process
# that loads the command line
from scipy.special import stdtrit

from .._validate import cyclic_coordinate, finite_scalar, positive, positive_int
from ..errors import BudgetExhaustedError, ConvergenceError, InputError, MoreauError, RunawayError
from ..integrators import get_integrator
from ..integrators.base import SchemeOptions, check_options, scheme_options as options_of
from ..integrators.result import SteadyState
from .periodic_shooting import one_sample_per_period, period_map_options
from .runaway import runaway_in
from .section_runs import section_states

__all__ = ["statistical_steady_state", "mser5_truncation", "batch_means",
           "correlation_time", "state_to_si", "check_statistical_options", "METHOD",
           "MAX_PERIODS", "PRECISION", "BATCHES", "CHUNK", "RESOLUTION", "MAX_LAG1", "MIN_TAUS", "START_KINDS"]

log = logging.getLogger(__name__)

TWO_PI = 2.0 * math.pi

#: default budget of drive periods (of each start)
MAX_PERIODS = 40000
#: default wanted half-width, relative (see ``precision``)
PRECISION = 1e-2
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
#: fewest integrated autocorrelation times the averaged periods must span (a batch of
#: ``MIN_TAUS / BATCHES`` of them)
MIN_TAUS = 100
#: two-sided level of the test that the two halves of the averaged periods have one mean
HALVES_LEVEL = 0.01
#: the method, as the JSON states it
METHOD = (f"MSER-5 transient truncation, {BATCHES} non-overlapping batch means, Student t "
          f"interval widened by the AR(1) factor of their lag-1 autocorrelation (at most "
          f"{MAX_LAG1}); the periods averaged span at least {MIN_TAUS} integrated "
          f"autocorrelation times and the means of their halves agree (t test at "
          f"{HALVES_LEVEL:g})")


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


def _run_periods(scene, scheme, q, v, ts, m, cyclic, opts):
    """Displacements over ``m`` periods from ``(q, v)`` at ``ts``, and the end state."""
    q = np.array(q, float)
    q[cyclic] = 0.0
    try:
        qs, vs, vmax = section_states(scene, scheme, opts, ts, q, np.array(v, float), m)
    except MoreauError as exc:
        raise ConvergenceError(f"the run of the statistical steady state failed: {exc}") from exc
    return np.diff(qs[:, cyclic]), qs[-1].copy(), vs[-1].copy(), vmax


def correlation_time(y, batches=BATCHES):
    """``(tau, size)``: the largest variance inflation of batch means of ``y``, and its batch size.

    For batches of ``b = 1, 2, 4, ...`` entries (at least ``batches`` of
    them), ``tau_b = b var(batch means) / var(y)``: the variance of a mean of
    ``b`` entries in units of that of independent ones, which grows with
    ``b`` to the integrated autocorrelation time ``1 + 2 sum rho(t)`` of the
    series once the batches span its correlations (for a series whose
    correlations oscillate, a quasi-periodic one, ``tau_b`` falls instead).
    The largest ``tau_b`` is returned, at least 1: the slowest variation the
    series shows, where an estimate from the autocorrelation function
    (Sokal's window) stops at the first sign change of a correlation that
    oscillates before it decays (the friction drive's flights at 15 kHz:
    0.2 against a largest ``tau_b`` of 16).

    Examples
    --------
    >>> correlation_time(np.ones(50))
    (1.0, 1)
    >>> rng = np.random.default_rng(0)
    >>> x = np.zeros(40000)
    >>> for k in range(1, x.size):                 # AR(1), rho = 0.9: tau = 19
    ...     x[k] = 0.9 * x[k - 1] + rng.standard_normal()
    >>> 15.0 < correlation_time(x)[0] < 26.0
    True
    """
    y = np.asarray(y, float)
    var = float(np.var(y))
    best, size = 1.0, 1
    if var == 0.0:
        return best, size
    b = 2
    while y.size // b >= batches:
        n = y.size // b
        tau = b * float(np.var(y[y.size - n * b:].reshape(n, b).mean(axis=1), ddof=1)) / var
        if tau > best:
            best, size = tau, b
        b *= 2
    return best, size


def state_to_si(scene, q, v):
    """A state of ``scene`` in SI units: ``{"q", "v", "q_units", "v_units"}``, or None.

    Angles (the scene's ``angle_coordinates``) stay in rad, their rates go to
    rad/s; every other coordinate is a length (m, m/s). None where the scene
    has no SI conversions (``displacement_to_si``, ``velocity_to_si``,
    ``time_unit_s``).

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> si = state_to_si(FrictionDrive(frequency=185.0), [0.5, 2.0], [1.0, 1.0])
    >>> si["q"], si["q_units"], si["v_units"]
    ([0.5, 0.002], ['rad', 'm'], ['rad/s', 'm/s'])
    """
    unit_s = getattr(scene, "time_unit_s", None)
    if unit_s is None or not hasattr(scene, "displacement_to_si") or \
            not hasattr(scene, "velocity_to_si"):
        return None
    angles = set(getattr(scene, "angle_coordinates", ()))
    q = np.asarray(q, float)
    v = np.asarray(v, float)
    return {"q": [float(x) if i in angles else float(scene.displacement_to_si(x))
                  for i, x in enumerate(q)],
            "v": [float(x) / float(unit_s) if i in angles else float(scene.velocity_to_si(x))
                  for i, x in enumerate(v)],
            "q_units": ["rad" if i in angles else "m" for i in range(q.size)],
            "v_units": ["rad/s" if i in angles else "m/s" for i in range(v.size)]}


#: how a statistical run's start was reached -> its description
START_KINDS = {
    "rest": "from rest (the scene's initial state)",
    "initial-state": "from the scene's initial state",
    "given": "from the given state",
    "period-1-search": "from the best state of the failed period-1 search",
    "rotor-speed": "from rest with the rotor at {fraction:g} of the tip's speed amplitude",
}


def _start_record(scene, kind, q, v, fraction=None):
    rec = {"how": kind, "description": START_KINDS[kind].format(fraction=fraction),
           "q": [float(x) for x in q], "v": [float(x) for x in v]}
    if fraction is not None:
        rec["rotor_speed_fraction"] = float(fraction)
    si = state_to_si(scene, q, v)
    if si is not None:
        rec.update(q_si=si["q"], v_si=si["v"], q_units=si["q_units"], v_units=si["v_units"])
    return rec


def _rest_of(scene):
    # the scene's rest state where it names one, else its initial state
    rest = getattr(scene, "rest_state", None)
    q, v = rest() if callable(rest) else scene.initial_state()
    return np.array(q, float), np.array(v, float)


def _is_rest(scene, q, v):
    if not callable(getattr(scene, "rest_state", None)):
        return False
    rq, rv = scene.rest_state()
    return bool(np.array_equal(np.asarray(rq, float), q) and np.array_equal(np.asarray(rv, float), v))


def _starts(scene, q0, v0, kind, count, spread, cyclic):
    """``[(kind, q, v, fraction)]``: the first start, then rest with the rotor spun up."""
    out = [(kind, q0, v0, None)]
    if count == 1:
        return out
    scale = getattr(scene, "velocity_scale", None)
    tip = float(np.max(np.abs(scale))) if scale is not None else 0.0
    rq, rv = _rest_of(scene)
    if kind == "rest":
        fractions = spread * np.arange(1, count) / (count - 1)
    else:
        # rest itself is one of the spread starts when the first start is another state
        fractions = spread * np.arange(count - 1) / max(count - 2, 1)
    for f in fractions:
        v = rv.copy()
        v[cyclic] += float(f) * tip
        out.append(("rotor-speed" if f else "rest", rq.copy(), v, float(f) if f else None))
    return out


def _halves_statistic(y, batches=BATCHES):
    """``(|mean of the second half - mean of the first|, its standard error)`` (batch means)."""
    size = y.size // batches
    bm = y[y.size - size * batches:].reshape(batches, size).mean(axis=1)
    a, b = bm[:batches // 2], bm[batches // 2:]
    se = math.sqrt(float(np.var(a, ddof=1)) / a.size + float(np.var(b, ddof=1)) / b.size)
    diff = abs(float(b.mean() - a.mean()))
    return diff, se


def _estimate(scene, scheme, q, v, ts, opts, cyclic, precision, confidence, max_periods, bar):
    """One start's statistical run (the module doc's method); a dict, or BudgetExhaustedError."""
    d = np.zeros(0)
    vmax = 0.0
    vs = getattr(scene, "velocity_scale", None)
    target = MIN_PERIODS
    why = "no look yet"
    est = (None, None)
    t_halves = float(stdtrit(BATCHES - 2, 1.0 - 0.5 * HALVES_LEVEL))
    while True:
        while d.size < target:
            m = min(CHUNK, target - d.size)
            dk, q, v, vm = _run_periods(scene, scheme, q, v, ts, m, cyclic, opts)
            d = np.concatenate([d, dk])
            vmax = max(vmax, vm)
            if bar is not None:
                bar.update(m)
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
            # batches of n / 20 may be shorter than the motion's slowest variation that a
            # smaller batch size shows: the interval is at least the one from that size
            tau, _ = correlation_time(y)
            half = max(half, float(stdtrit(BATCHES - 1, 0.5 * (1.0 + confidence)))
                       * math.sqrt(tau * float(np.var(y)) / y.size))
            resolution = RESOLUTION * ref_scale
            half = max(half, resolution)
            diff, se = _halves_statistic(y)
            est = (mean, half)
            wanted = precision * ref_scale
            problems = []
            if half > wanted:
                problems.append(f"the interval half-width is {half:.3g} against {wanted:.3g} "
                                f"wanted")
            if lag1 > MAX_LAG1:
                problems.append(f"the batch means are correlated (lag 1: {lag1:.2f} > "
                                f"{MAX_LAG1})")
            if y.size < MIN_TAUS * tau:
                problems.append(f"the {y.size} periods averaged span fewer than {MIN_TAUS} "
                                f"correlation times ({tau:.4g} periods each)")
            if diff > t_halves * se + resolution:
                problems.append(f"the means of its two halves differ by {diff:.3g}, "
                                f"{diff / se if se else math.inf:.3g} standard errors")
            if not problems:
                break
            why = f"after {d.size} periods (transient {cut}) " + ", and ".join(problems)
        if d.size >= max_periods:
            raise BudgetExhaustedError(
                f"statistical steady state: budget exhausted (`max_periods`={max_periods}): "
                f"{why}", periods=d.size, mean=est[0], half_width=est[1], series=d)
        target = min(max_periods, 2 * d.size)
    used = d.size - (d.size - cut) % BATCHES - cut
    return {"mean": float(mean), "half_width": float(half), "lag1": float(lag1),
            "tau": float(tau), "halves": float(diff / se) if se else 0.0,
            "transient": int(cut), "simulated": int(d.size), "used": int(used),
            "q": q, "v": v}


def _group(runs):
    """Attractors: the converged runs whose intervals overlap, chained in order of their means."""
    order = sorted(range(len(runs)), key=lambda i: runs[i]["mean"])
    groups = []
    for i in order:
        r = runs[i]
        if groups:
            p = runs[groups[-1][-1]]
            if abs(r["mean"] - p["mean"]) <= r["half_width"] + p["half_width"]:
                groups[-1].append(i)
                continue
        groups.append([i])
    out = []
    for g in groups:
        # inverse-variance weights: the starts are independent estimates of one mean
        w = np.array([runs[i]["half_width"] ** -2.0 for i in g])
        m = np.array([runs[i]["mean"] for i in g])
        mean = float(w @ m / w.sum()) if len(g) > 1 else float(m[0])
        half = float(w.sum() ** -0.5) if len(g) > 1 else runs[g[0]]["half_width"]
        out.append({"mean": mean, "confidence_interval": (mean - half, mean + half),
                    "half_width": half, "starts": len(g), "members": sorted(g)})
    return out


def _in_si(scene, x):
    conv = getattr(scene, "displacement_to_si", None)
    return (f"{float(conv(x)):.5g} m" if conv is not None else f"{x:.5g}")


def check_statistical_options(precision=PRECISION, confidence=0.95, max_periods=MAX_PERIODS,
                              starts=1, spread=1.0):
    """The options of :func:`statistical_steady_state`, checked (InputError naming the first bad one).

    Examples
    --------
    >>> check_statistical_options(starts=0)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `starts` must be an integer >= 1, got 0
    """
    precision = positive("precision", precision)
    if not 0.0 < finite_scalar("confidence", confidence) < 1.0:
        raise InputError(f"`confidence` must be in (0, 1), got {confidence!r}")
    max_periods = positive_int("max_periods", max_periods)
    if max_periods < MIN_PERIODS:
        raise InputError(f"`max_periods` must be at least {MIN_PERIODS}, got {max_periods}")
    starts = positive_int("starts", starts)
    spread = finite_scalar("spread", spread)
    if spread == 0.0:
        raise InputError("`spread` must be nonzero (the largest fraction of the velocity scale "
                         "given to the rotor), got 0.0")
    return precision, float(confidence), max_periods, starts, spread


def statistical_steady_state(scene, scheme="event-driven", q0=None, v0=None, section_tau=0.0,
                             precision=PRECISION, confidence=0.95, max_periods=MAX_PERIODS,
                             cyclic=None, scheme_options=None, starts=1, spread=1.0,
                             start_kind=None, progress=False, **options):
    """Long-run mean displacement per period, with a confidence interval (see the module doc).

    Parameters
    ----------
    scene : Scene
        A ``2 pi``-periodic scene with a cyclic coordinate.
    scheme : str or SchemeOptions
        Any registered scheme, or its options object (its options join
        ``scheme_options``; the step comes from ``steps_per_period``).
    q0, v0 : array_like, optional
        Start at the section; the scene's ``initial_state()`` by default.
    section_tau : float
        Phase at which the periods start.
    precision : float
        Wanted half-width of the interval relative to
        ``max(|mean|, 0.01 * 2 pi * velocity_scale)`` (default 1e-2).
    confidence : float
        Level of the interval, in (0, 1).
    max_periods : int
        Budget of each start: drive periods simulated at most (transient
        included).
    cyclic : int, optional
        The cyclic coordinate; the scene's one by default.
    scheme_options : dict, optional
        The scheme's options, merged with ``options``.
    starts : int
        Number of starts: the first (``q0, v0`` or the initial state), then
        the scene's rest state with the cyclic coordinate's velocity (the
        rotor's) raised by fractions of the velocity scale (the tip's speed
        amplitude) spread evenly up to ``spread``: for a first start at
        rest ``spread * j / (starts - 1)``, ``j = 1 .. starts - 1``; for
        another first start rest itself and then up to ``spread``.
    spread : float
        The largest fraction of the velocity scale given to the rotor (any
        nonzero number; negative spins it backwards).
    start_kind : str, optional
        How the first start was reached, for the record: a key of
        :data:`START_KINDS` (default ``"given"`` where ``q0, v0`` are given,
        else ``"rest"`` or ``"initial-state"``).
    progress : bool
        Show a tqdm bar of the periods simulated (on a terminal only).
    **options
        Passed to the scheme; ``steps_per_period`` sets a time-stepping
        scheme's step (2000 by default, as for the shooting). Moreau–Jean
        runs with ``projection=True`` unless told otherwise, as its
        steady-state shooting does.

    Returns
    -------
    SteadyState
        That of the first start that converged: ``statistical=True``,
        ``displacement_per_period`` the mean, ``confidence_interval`` its
        ``(low, high)``, ``periods_used`` the periods averaged, ``start``
        where the averaging started (``how``, ``description``, ``q``, ``v``
        in the scene's units, ``q_si``, ``v_si`` and their units where the
        scene converts to SI), ``attractors`` (the converged starts grouped
        by overlapping intervals, each with ``mean``,
        ``confidence_interval``, ``half_width``, ``starts`` and ``members``,
        the indices of its starts), ``stats`` with ``transient_periods``,
        ``periods_simulated``, ``half_width``, ``lag1_autocorrelation``,
        ``autocorrelation_time`` (periods), ``halves_statistic``,
        ``method``, ``status`` (``"converged"``), ``precision``, ``options``
        (the scheme's) and ``starts`` (every start's record, its ``status``,
        ``mean``, ``confidence_interval``, ``attractor``, ``cpu_time_s``);
        ``mode`` is ``"non-periodic"``, ``period`` 0, no Floquet
        multipliers, ``min_normal_force`` infinite (unknown: the runs are
        sampled once a period) and ``periodic_residual`` infinite (no orbit
        closes). With more than one attractor a warning is logged.

    Raises
    ------
    RunawayError
        At a look, the second half of the displacements shows a runaway
        (:func:`moreau.analysis.runaway.runaway_in`).
    BudgetExhaustedError
        No start's mean was stationary within ``precision`` after
        ``max_periods`` (the first start's error).
    ConvergenceError
        The scheme failed along the way (on every start).
    """
    if isinstance(scheme, SchemeOptions):
        scheme_options = {**scheme.without_step("`steps_per_period`"), **(scheme_options or {})}
        scheme = scheme.scheme
    cyclic = cyclic_coordinate(scene, cyclic)
    precision, confidence, max_periods, starts, spread = check_statistical_options(
        precision, confidence, max_periods, starts, spread)
    if starts > 1 and getattr(scene, "velocity_scale", None) is None:
        raise InputError(f"`starts` > 1 needs a scene with a `velocity_scale` (the rotor's "
                         f"speeds are spread over fractions of it), got {starts}")
    if start_kind is not None and start_kind not in START_KINDS:
        raise InputError(f"`start_kind` must be one of {', '.join(map(repr, START_KINDS))}, "
                         f"got {start_kind!r}")
    get_integrator(scheme)
    clash = set(scheme_options or {}) & set(options)
    if clash:
        raise InputError(f"`{sorted(clash)[0]}` is given twice (in `scheme_options` and as a keyword)")
    opts = period_map_options(scheme, {**options, **(scheme_options or {})})
    takes = options_of(get_integrator(scheme)) or ()
    if scheme == "moreau-jean" and "projection" in takes:
        opts.setdefault("projection", True)
    check_options(scheme, opts, scene)
    run_opts = one_sample_per_period(takes, opts)
    given = q0 is not None and v0 is not None
    if not given:
        q0, v0 = scene.initial_state()
    q0, v0 = np.array(q0, float), np.array(v0, float)
    if start_kind is None:
        start_kind = "given" if given else ("rest" if _is_rest(scene, q0, v0)
                                            else "initial-state")
    ts = float(section_tau)

    start = time.perf_counter()
    plan = _starts(scene, q0, v0, start_kind, starts, spread, cyclic)
    runs, records, errors = [], [], []
    for k, (kind, q, v, frac) in enumerate(plan):
        rec = {"start": _start_record(scene, kind, q, v, frac)}
        bar = None
        if progress:
            from tqdm.auto import tqdm
            desc = "statistical steady state" + (f", start {k + 1}/{len(plan)}"
                                                 if len(plan) > 1 else "")
            bar = tqdm(total=max_periods, desc=desc, unit="period", leave=False,
                       disable=None)  # terminals only
        cpu = time.process_time()
        try:
            r = _estimate(scene, scheme, q, v, ts, run_opts, cyclic, precision, confidence,
                          max_periods, bar)
        except ConvergenceError as exc:
            if len(plan) == 1:
                raise
            errors.append(exc)
            rec.update(status=getattr(exc, "status", "failed"), message=str(exc),
                       cpu_time_s=time.process_time() - cpu)
            records.append(rec)
            continue
        finally:
            if bar is not None:
                bar.close()
        rec.update(status="converged", mean=r["mean"],
                   confidence_interval=(r["mean"] - r["half_width"], r["mean"] + r["half_width"]),
                   half_width=r["half_width"], transient_periods=r["transient"],
                   periods_simulated=r["simulated"], cpu_time_s=time.process_time() - cpu)
        r["index"] = k
        runs.append(r)
        records.append(rec)
    if not runs:
        raise errors[0]
    attractors = _group(runs)
    for a, group in enumerate(attractors):
        group["members"] = [runs[i]["index"] for i in group["members"]]
        for k in group["members"]:
            records[k]["attractor"] = a
    if len(attractors) > 1:
        log.warning("statistical steady state: %d attractors among %d starts, means %s; the "
                    "result is start %d's (%s)", len(attractors), len(plan),
                    ", ".join(f"{_in_si(scene, g['mean'])} ({g['starts']} start"
                              f"{'s' if g['starts'] > 1 else ''})" for g in attractors),
                    runs[0]["index"] + 1, records[runs[0]["index"]]["start"]["description"])

    r = runs[0]
    mean, half, cut = r["mean"], r["half_width"], r["transient"]
    qs = r["q"].copy()
    qs[cyclic] = 0.0
    return SteadyState(
        scheme=scheme,
        displacement_per_period=float(mean),
        state0=np.concatenate([qs, r["v"]]),
        mode="non-periodic",
        regimes=[],
        # the runs are sampled once a period: the forces within are not known
        min_normal_force=math.inf,
        periodic_residual=math.inf,
        iterations=0,
        wall_time=time.perf_counter() - start,
        stats={"periodic": False, "status": "converged", "transient_periods": int(cut),
               "periods_simulated": r["simulated"], "half_width": float(half),
               "lag1_autocorrelation": r["lag1"], "autocorrelation_time": r["tau"],
               "halves_statistic": r["halves"], "method": METHOD, "precision": precision,
               "options": {k: v for k, v in opts.items() if k != "h"} | (
                   {"steps_per_period": int(round(TWO_PI / opts["h"]))} if "h" in opts else {}),
               "starts": records},
        section_tau=ts,
        period=0,
        statistical=True,
        confidence_interval=(float(mean - half), float(mean + half)),
        confidence=confidence,
        periods_used=r["used"],
        start=records[r["index"]]["start"],
        attractors=attractors,
    )
