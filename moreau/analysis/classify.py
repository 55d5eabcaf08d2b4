"""What a parameter point without a periodic steady state does instead, on a small budget.

An atlas point whose period-1 shooting fails used to be only "failed". The
long-run motion there is usually one of: an orbit of period ``k`` (past a
period doubling), a non-periodic (quasi-periodic or chaotic) motion with a
well-defined mean displacement per period, a rotor running away (past
stall), or the rod never touching the rotor. :func:`classify_long_run` runs
the scheme's period map plainly from the start state for at most
``budget`` drive periods, sampling the state at the section once a period:

* **period-k**: the last section states repeat with period ``k <= 8``
  (:func:`sequence_period`, to ``rtol`` of each column's scale); the
  displacement per period is the mean over the last ``k`` periods;
* **runaway**: the scene's physics says so before any run, or the
  displacements per period over the second half of the run grow steadily
  beyond the drive's speed (:mod:`moreau.analysis.runaway`, the detector
  every analysis uses);
* **non-periodic**: no period within the budget; the mean displacement per
  period after the MSER-5 transient, with a batch-means confidence
  interval (:mod:`moreau.analysis.statistical`: the same estimator and the
  same AR(1) widening, here on a budget of a few hundred periods instead of
  tens of thousands). Where MSER-5 finds the series still drifting the
  mean of the second half is given and the half-width is NaN: the budget
  was too small to say more.

:func:`classification_columns` turns that into an atlas row's columns
(:data:`CLASSIFY_COLUMNS`); a point with an orbit is ``period-1`` (or its
``k``), and a point whose failure already names its cause (ill-posed, no
contact) keeps it without a run; a runaway the shooting reports is
checked by the run (a secant iteration on a motion without an orbit can run
off where the motion itself stays bounded).

Examples
--------
>>> x = np.array([[1.0], [2.0], [1.0], [2.0], [1.0], [2.0]])
>>> sequence_period(x)
2
"""

import math

import numpy as np

from .._validate import positive_int
from ..errors import InputError, MoreauError
from ..integrators import get_integrator
from ..integrators.base import scheme_options as options_of
from ..model import registry
from .periodic_shooting import one_sample_per_period, period_map_options
from .runaway import certain_runaway, runaway_in
from .section_runs import section_states
from .statistical import BATCHES, MAX_LAG1, batch_means, mser5_truncation

__all__ = ["classify_long_run", "classification_columns", "sequence_period", "CLASSIFY_COLUMNS",
           "CLASSIFY_PERIODS", "MAX_PERIOD_K"]

#: the longest period the sampled sequence is tested for
MAX_PERIOD_K = 8
#: drive periods a failed atlas point is run for at most
CLASSIFY_PERIODS = 100
#: periods per run between two looks at the samples
CHUNK = 100
#: the columns :func:`classification_columns` adds to a row
CLASSIFY_COLUMNS = ("classification", "classification_detail",
                    "classified_displacement_per_period_m", "classified_half_width_m")


def sequence_period(samples, rtol=1e-6, kmax=MAX_PERIOD_K):
    """The smallest ``k <= kmax`` with ``x_{j+k} = x_j`` over the samples, or 0.

    Parameters
    ----------
    samples : ndarray, shape (m, d)
        Section states, one row per period.
    rtol : float
        Tolerance relative to each column's scale (its largest magnitude
        over the samples, at least the largest column scale times 1e-12).

    Examples
    --------
    >>> x = np.array([[1.0], [2.0], [1.0], [2.0], [1.0], [2.0]])
    >>> sequence_period(x), sequence_period(x[:, 0][:, None] * [1, 0] + [0, 1])
    (2, 2)
    >>> sequence_period(np.arange(6.0)[:, None])
    0
    """
    x = np.asarray(samples, dtype=float)
    if x.ndim != 2 or x.shape[0] < 2:
        raise InputError(f"`samples` must have shape (m, d) with m >= 2, got {x.shape}")
    scale = np.max(np.abs(x), axis=0)
    scale = np.maximum(scale, 1e-12 * max(float(np.max(scale)), 1e-300))
    for k in range(1, min(kmax, x.shape[0] - 1) + 1):
        if np.all(np.abs(x[k:] - x[:-k]) <= rtol * scale):
            return k
    return 0


def _state_period(x, rtol):
    # sequence_period with one scale for all columns (the state's largest entry): a
    # coordinate that is zero at the section (a contact's velocity) holds only rounding
    scale = rtol * max(float(np.max(np.abs(x))), 1e-300)
    for k in range(1, min(MAX_PERIOD_K, x.shape[0] - 1) + 1):
        if np.all(np.abs(x[k:] - x[:-k]) <= scale):
            return k
    return 0


def _run_scheme(scene, scheme):
    # the scene's own reference stands for "event-driven" (the friction drive's walker)
    own = getattr(scene, "reference_integrator", None)
    if scheme == "event-driven":
        # the dispatcher states no sampling options of its own: the scheme it runs does
        return own if own is not None else "event-driven-generic"
    return scheme


def _sampled_options(run, options):
    opts = period_map_options(run, dict(options))
    return one_sample_per_period(options_of(get_integrator(run)) or (), opts)


def _start(scene, start):
    if start is not None:
        return (np.array(a, float) for a in start)
    if hasattr(scene, "rest_state"):
        return (np.array(a, float) for a in scene.rest_state())
    return (np.array(a, float) for a in scene.initial_state())


def classify_long_run(scene, scheme="event-driven", options=None, start=None, section_tau=0.0,
                      budget=CLASSIFY_PERIODS, rtol=1e-6, confidence=0.95):
    """Run the period map plainly and name the long-run motion (see the module doc).

    Parameters
    ----------
    scene : Scene
        Driven with period ``2 pi``, with one cyclic coordinate.
    scheme : str
        A registered scheme (``"event-driven"`` runs the scene's own reference).
    options : dict, optional
        The scheme's options (``steps_per_period`` for a time-stepping one).
    start : (q, v), optional
        Start at the section; the scene's rest state by default.
    section_tau : float
        Phase of the section where the periods start and end.
    budget : int
        Drive periods run at most.
    rtol : float
        Tolerance of the period test (:func:`sequence_period`).

    Returns
    -------
    dict
        ``classification`` (``"period-k"``, ``"non-periodic"`` or
        ``"runaway"``), ``detail`` (a sentence), ``displacement_per_period``
        (dimensionless; the mean over the orbit, or the long-run mean),
        ``half_width`` (of the interval at ``confidence``; 0 for an orbit,
        NaN where the budget could not give one), ``periods`` (run).

    Raises
    ------
    MoreauError
        The scheme failed along the way.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> classify_long_run(FrictionDrive(frequency=185.0))["classification"]
    'period-1'
    """
    budget = positive_int("budget", budget)
    cyc = tuple(getattr(scene, "cyclic_coordinates", ()))
    if len(cyc) != 1:
        raise InputError(f"`scene` must have one cyclic coordinate, got {cyc!r}")
    cyclic = int(cyc[0])
    run = _run_scheme(scene, scheme)
    # refuses a setting the scheme does not take, before any work
    opts = _sampled_options(run, options or {})
    q, v = _start(scene, start)
    ts = float(section_tau)
    keep = [i for i in range(scene.ndof) if i != cyclic]
    why = certain_runaway(scene)
    if why:
        return {"classification": "runaway", "displacement_per_period": math.nan,
                "half_width": math.nan, "periods": 0, "detail": why}
    d = np.zeros(0)
    xs = np.zeros((0, len(keep) + scene.ndof))
    while d.size < budget:
        m = min(CHUNK, budget - d.size)
        q[cyclic] = 0.0
        try:
            qs, vs_, _ = section_states(scene, run, opts, ts, q, v, m)
        except MoreauError as exc:
            raise MoreauError(f"the run failed after {d.size} periods ({exc})") from exc
        d = np.concatenate([d, np.diff(qs[:, cyclic])])
        xs = np.vstack([xs, np.hstack([qs[1:, keep], vs_[1:]])])
        q, v = qs[-1].copy(), vs_[-1].copy()
        if not (np.all(np.isfinite(d)) and np.all(np.isfinite(xs))):
            return {"classification": "runaway", "displacement_per_period": math.nan,
                    "half_width": math.nan, "periods": int(d.size),
                    "detail": f"the state is not finite after {d.size} periods"}
        runaway = runaway_in(d[d.size // 2:], scene)
        if runaway:
            return {"classification": "runaway", "displacement_per_period": float(d[-1]),
                    "half_width": math.nan, "periods": int(d.size),
                    "detail": f"{runaway} after {d.size} periods"}
        tail = xs[-min(len(xs), 3 * MAX_PERIOD_K + 1):]
        k = _state_period(tail, rtol) if len(tail) > 2 * MAX_PERIOD_K else 0
        if k:
            return {"classification": f"period-{k}",
                    "displacement_per_period": float(np.mean(d[-k:])), "half_width": 0.0,
                    "periods": int(d.size),
                    "detail": f"the section state repeats after {k} period"
                              f"{'s' if k > 1 else ''} (to {rtol:g}) after {d.size} periods"}
    cut = mser5_truncation(d) if d.size >= 2 * BATCHES else None
    if cut is None:
        tail = d[d.size // 2:]
        return {"classification": "non-periodic", "displacement_per_period": float(tail.mean()),
                "half_width": math.nan, "periods": int(d.size),
                "detail": f"no period <= {MAX_PERIOD_K} in {d.size} periods and the running "
                          f"mean still drifts (MSER-5): the mean of the second half is given, "
                          f"without an interval"}
    mean, half, lag1 = batch_means(d[cut:], BATCHES, confidence)
    if lag1 > 0.0:
        # the AR(1) factor of correlated batch means, as in the statistical steady state
        half *= math.sqrt((1.0 + lag1) / (1.0 - lag1)) if lag1 < 1.0 else math.inf
    note = "" if lag1 <= MAX_LAG1 else f"; the batch means are correlated (lag 1: {lag1:.2f})"
    return {"classification": "non-periodic", "displacement_per_period": float(mean),
            "half_width": float(half), "periods": int(d.size),
            "detail": f"no period <= {MAX_PERIOD_K} in {d.size} periods; mean after a "
                      f"{cut}-period transient, {BATCHES} batch means, {confidence:.0%} "
                      f"interval{note}"}


def _label_of_status(status):
    # a shooting's runaway is checked by the plain run too: a secant iteration on a
    # motion without an orbit can run off where the motion itself stays bounded
    if status.startswith("PainleveError"):
        return "ill-posed"
    if "does not touch the rotor" in status:
        return "no contact"
    return None


def classification_columns(row, params, frequency, scheme, scene, steady=None,
                           budget=CLASSIFY_PERIODS):
    """The :data:`CLASSIFY_COLUMNS` of one engine row (SI units).

    Parameters
    ----------
    row : dict
        The point's row (:func:`moreau.analysis.engine.evaluate_point`).
    params, frequency
        The point's parameters (SI) and drive frequency [Hz].
    scheme : moreau.analysis.scheme_settings.Scheme
    scene : str
        The registered scene.
    steady : SteadyState, optional
        The point's steady state, where it has one.
    budget : int
        Periods run for a point without one (:func:`classify_long_run`);
        0: no run, the point stays ``failed``.

    Returns
    -------
    dict
        ``classification``: ``period-k`` (an orbit: the shooting's, or one
        the run found), ``non-periodic``, ``runaway``, ``no contact``,
        ``ill-posed`` or ``failed`` (the run itself failed: the detail says
        why); ``classification_detail``; the displacement per period [m] it
        gives and the half-width of its interval [m].

    Examples
    --------
    >>> from dataclasses import asdict
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> from moreau.analysis.scheme_settings import ED_REFERENCE
    >>> row = {"status": "ConvergenceError: the rod does not touch the rotor", "mode": ""}
    >>> classification_columns(row, asdict(PAPER_DEFAULTS), 185.0, ED_REFERENCE,
    ...                        "friction-drive")["classification"]
    'no contact'
    """
    status = row.get("status", "")
    out = dict.fromkeys(CLASSIFY_COLUMNS[2:], math.nan)
    if status == "ok":
        k = int(getattr(steady, "period", 1) or 1) if steady is not None else 1
        out.update(classification=f"period-{k}", classification_detail="shooting",
                   classified_displacement_per_period_m=row.get("displacement_per_period_m",
                                                                math.nan),
                   classified_half_width_m=0.0)
        return out
    label = _label_of_status(status)
    if label is not None:
        out.update(classification=label, classification_detail=status)
        return out
    if not budget:
        out.update(classification="failed",
                   classification_detail=f"{status}; not run (a budget of 0 periods)")
        return out
    try:
        sc = registry.make_scene(scene, frequency=frequency, **params)
        opts = {}
        if scheme.steps_per_period is not None:
            opts["steps_per_period"] = scheme.steps_per_period
        if scheme.theta is not None:
            opts["theta"] = scheme.theta
        opts.update(scheme.options)
        found = classify_long_run(sc, scheme.name, opts, budget=budget)
    except Exception as exc:  # the run failing too is a genuine failure, with both causes
        why = " ".join(str(exc).split())
        out.update(classification="failed",
                   classification_detail=f"{status}; the plain run failed too: "
                                         f"{type(exc).__name__}: {why}")
        return out
    to_si = sc.displacement_to_si
    out.update(classification=found["classification"],
               classification_detail=f"{found['detail']} (shooting: {status})",
               classified_displacement_per_period_m=to_si(found["displacement_per_period"]),
               classified_half_width_m=(to_si(found["half_width"])
                                        if math.isfinite(found["half_width"]) else math.nan))
    return out
