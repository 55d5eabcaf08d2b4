"""Scheme comparison: error against run time for every shipped scene (``moreau compare``).

For one scene, :func:`compare` runs

- the scene's reference at several tolerances (the event-driven reference of
  the friction drive; the exact solutions of the other scenes, which have no
  tolerance and give one row);
- Moreau–Jean with ``theta = 1/2`` and ``theta = 1`` at step counts spanning
  two decades, with the scheme's own contact solve (closed form for one
  contact, the compiled Lemke for two; ``lcp = None`` in the table);
- Moreau–Jean (``theta = 1``) with the contact problem of every step forced
  through Lemke and through the QP path (``lcp = "lemke"``, ``"qp"``), so that
  the solvers are compared as well as the schemes.

Errors are measured against the reference at its tightest setting, three ways:

``error``
    the scene's headline quantity, relative (the friction drive and the
    stick–slip motor: the displacement per period; the bouncing ball: the
    height at the end of the window; the sliding block: the stopping
    distance; the Painlevé rod: the horizontal position of its centre at the
    end of the window; the sliding box (two contacts): its exact stopping
    distance; the bidirectional drive (two contacts): the displacement per
    period against the generic event-driven steady state);
``trajectory_error``
    the max over one period (the comparison window) of the main coordinate's
    distance from the reference, both started from the same state (for the
    periodic scenes the reference's periodic state), on a common grid;
``switching_error``
    the largest shift of a regime switching time (or an impact time), when
    the two regime sequences agree (``None`` where they do not, or where the
    motion has no switch); on the two-contact scenes each contact's switches
    are matched separately.

The fitted ``order`` of each Moreau–Jean series is the slope of
``log(trajectory_error)`` against ``log(steps_per_period)``; the headline
error converges at the same rate but erratically (each slip reversal's
``O(h)`` error depends on where it falls inside its step), so its slope is
given as well (``order_headline``) but not used as the order.

On a periodically driven scene every row's headline is the steady state of
the row's own scheme (the fixed point of its period map), the Lemke and QP
rows included, and its time is the time to compute that steady state: one
meaning of ``time_s`` for every row (the report's ``time_s_meaning``). The
QP path costs about 6.5 ms per step on the friction drive, so its steady
state at 50 steps per period takes about 7.5 s against 4 ms with the
compiled Lemke.

Plateaus of the Moreau–Jean steady state (the ``notes`` of the report)
----------------------------------------------------------------------
At 2000 Hz the friction drive's Moreau–Jean steady state gives the same
relative error, -1.34e-3, at 5000, 10000 and 20000 steps per period with
``theta = 1/2`` (and -1.31e-3, -1.32e-3 with ``theta = 1`` at 5000 and
10000), then -3.0e-4 at 40000 with both. Measured cause (neither the
treatment of the moving constraint inside the step nor the projection):

* In the steady motion (mode ``NP``, the rod pinned by the closed contact)
  the rotor velocity ``u2'`` at ``tau = 0`` is the only free state. Over a
  period of pure slip the friction impulses do not depend on ``u2'`` as long
  as every step keeps its slip sign, so the *discrete* period map has slope
  exactly 1 in ``u2'`` (neutral) with jumps where a slip reversal moves from
  one step to the next. Only inside a window of width ~1e-9 the reversal
  step sticks, which sets ``u2'`` to the tip velocity at the end of that
  step (slope 0). The fixed point therefore sits in such a window: the
  discrete steady state puts the N -> P slip reversal exactly on a grid time
  ``tau_j``, while the continuous one has it at ``tau* = 2.98557``.
* The rotor velocity, and the displacement per period with it, is then off
  by ``K (tau_j - tau*)`` with ``K = -6.7`` (relative error per unit of
  ``tau``; the continuous period map is barely contracting, slope 0.987,
  so the reversal time and the rotor velocity are tightly coupled). The
  grid point ``tau_j = 2 pi 2376/5000 = 2.98577`` lies 2.0e-4 after
  ``tau*`` and is a grid point of N = 5000, 10000 and 20000 alike, so all
  three give ``-6.7 x 2.0e-4 = -1.34e-3``; N = 40000 adds a grid point
  0.5e-4 after ``tau*`` (``-3.0e-4``). With N = 4999 and 5001 (no shared
  grid point) the same formula gives the measured -5.3e-3 and -5.7e-3;
  ``theta = 1`` often settles on the grid point *before* ``tau*`` (20000
  steps: ``+7.5e-4``), which is why it seemed to keep converging.

So the error is first order in the worst case (``|tau_j - tau*| <= h``) but
erratic: it depends on where the reversal falls on the grid, and doubling N
keeps the old grid point. A variant of the step that locates the reversal
inside the step (splits the step where the slip velocity changes sign) would
remove it; it belongs to the integrator and is not part of this module.
:func:`compare` flags such plateaus in the report's ``notes`` and gives the
signed relative error of every row (``signed_error``).

Examples
--------
>>> rep = compare("sliding-block", steps=[20, 40, 80], lcp_steps=[], thetas=[1.0],
...               repeat=1, progress=False)
>>> [r["scheme"] for r in rep["rows"]][:2], rep["orders"][0]["theta"]
(['exact', 'moreau-jean'], 1.0)
>>> round(rep["orders"][0]["order"], 1)
1.0
"""


from __future__ import annotations

import csv
import inspect
import json
import math
import os
import statistics
import time
from typing import Any, Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike
from tqdm import tqdm

from .._validate import in_closed_interval, positive_int
from ..errors import InputError, MoreauError
from ..integrators.base import INTEGRATORS, SchemeOptions, propagate_interrupts
from ..provenance import provenance
from ..model.scene import Scene, is_spatial
from ..model.registry import get_entry
from .cases import GRID, SceneCase, switching_error

__all__ = ["pareto", "PARETO_TARGETS", "compare", "DEFAULT_STEPS", "write_outputs", "plot_work_precision",
           "check_out_dir", "make_case", "case_parameters", "fit_order", "facet_order", "plateaus",
           "switching_error", "run_row", "run_other_row", "other_schemes"]

TWO_PI = 2.0 * math.pi
#: Moreau–Jean steps per period of the full comparison (two decades)
DEFAULT_STEPS = (50, 100, 200, 500, 1000, 2000, 5000)
#: the same span with fewer points, for quick runs
QUICK_STEPS = (50, 150, 500, 1500, 5000)
#: steps per period of the forced-Lemke / forced-QP rows (QP costs ~16 ms a step)
DEFAULT_LCP_STEPS = (50, 100, 200)
QUICK_LCP_STEPS = (50,)
#: the friction cones of a spatial scene's facet rows: the polyhedral LCP's directions, and
#: the exact cone (issue 37)
FACET_CONES = (4, 8, 16, 32, "exact")
#: steps over the window of the facet rows (quick: the first)
FACET_STEPS = (1000, 100)


def fit_order(steps, errors):
    """Convergence order: minus the slope of ``log(error)`` against ``log(steps)``.

    Points with zero or missing error are left out; fewer than three points
    give None.

    Examples
    --------
    >>> round(fit_order([10, 20, 40], [1e-2, 5e-3, 2.5e-3]), 12)
    1.0
    """
    pts = [(n, e) for n, e in zip(steps, errors) if e is not None and e > 0 and math.isfinite(e)]
    if len(pts) < 3:
        return None
    n, e = np.array(pts, dtype=float).T
    return float(-np.polyfit(np.log(n), np.log(e), 1)[0])


def _median_time(fn, repeat, cheap=1.0):
    """Median run time of ``fn()`` and its output; runs slower than ``cheap`` seconds run once."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if times[0] > cheap:
            break
    return statistics.median(times), out


def make_case(scene, **params):
    """The comparison case of ``scene``: a registered scene's name, with its parameters.

    The case class is the scene's registry entry's ``case``; it takes the
    scene's parameters and its own (a start speed, a drop height). ``None``
    values are dropped; a name the case does not take is refused, listing
    the ones it does.
    """
    entry = get_entry(scene)
    if entry.case is None:
        raise InputError(f"scene {scene!r} has no comparison case; pass a Scene instance with "
                         "`t_span`, `q0` and `v0` instead")
    params = {k: v for k, v in params.items() if v is not None}
    allowed = case_parameters(entry)
    bad = sorted(set(params) - set(allowed))
    if bad:
        raise InputError(f"`{bad[0]}` is not a parameter of scene {scene!r}; its parameters: "
                         + ", ".join(allowed))
    case = entry.case(**params)
    case.name = scene
    return case


def case_parameters(entry):
    """Every keyword the comparison case of registry entry ``entry`` takes (its own, then the scene's)."""
    sig = inspect.signature(entry.case.__init__)
    own = [p for p, v in sig.parameters.items()
           if p != "self" and v.kind is not inspect.Parameter.VAR_KEYWORD]
    return tuple(own + [p for p in entry.parameter_names() if p not in own])


def _relative(value, ref):
    return abs(value - ref) / abs(ref) if ref != 0.0 else abs(value)


def _signed(value, ref):
    return (value - ref) / abs(ref) if ref != 0.0 else value


def plateaus(rows, rel=0.02, min_error=1e-6):
    """Runs of Moreau–Jean rows whose headline error stays put while the step count doubles.

    Returns one note per run of at least two rows of one series
    (``theta``, ``lcp``) with ``steps_per_period`` growing by 2x or more at
    each step and signed errors within ``rel`` of each other (errors below
    ``min_error`` are left out). See the module docstring for what causes them
    on the friction drive.

    Examples
    --------
    >>> rows = [dict(scheme="moreau-jean", theta=0.5, lcp=None, status=0, steps_per_period=n,
    ...              signed_error=e) for n, e in [(1000, -3e-2), (5000, -1.34e-3),
    ...                                           (10000, -1.338e-3), (20000, -1.339e-3)]]
    >>> plateaus(rows)[0]["steps_per_period"]
    [5000, 10000, 20000]
    """
    series = {}
    for r in rows:
        if (r["scheme"] == "moreau-jean" and r["status"] == 0
                and r.get("signed_error") is not None):
            series.setdefault((r["theta"], r["lcp"]), []).append(r)
    notes = []
    for (theta, lcp), rs in series.items():
        rs = sorted(rs, key=lambda r: r["steps_per_period"])
        run = [rs[0]] if rs else []
        for r in rs[1:] + [None]:
            prev = run[-1] if run else None
            if (r is not None and prev is not None
                    and r["steps_per_period"] >= 2 * prev["steps_per_period"]
                    and abs(prev["signed_error"]) >= min_error
                    and abs(r["signed_error"] - prev["signed_error"])
                    <= rel * abs(prev["signed_error"])):
                run.append(r)
                continue
            if len(run) >= 2:
                e = run[0]["signed_error"]
                n = [x["steps_per_period"] for x in run]
                notes.append({
                    "theta": theta, "lcp": lcp, "steps_per_period": n, "signed_error": e,
                    "text": (f"theta={theta:g}: the headline error stays at {e:+.3g} for N = "
                             + ", ".join(map(str, n)) + ": a switch of the discrete motion "
                             "(a slip reversal, an impact) falls on a grid time that these N "
                             "share (see moreau.analysis.compare, 'Plateaus')")})
            run = [r] if r is not None else []
    return notes


def compare(scene: str | Scene, steps: Sequence[int] | None = None,
            lcp_steps: Sequence[int] | None = None, thetas: Sequence[float] = (0.5, 1.0),
            repeat: int = 3, quick: bool = False, progress: bool = True,
            on_row: Callable[[dict], None] | None = None, *,
            t_span: tuple[float, float] | None = None, q0: ArrayLike | None = None,
            v0: ArrayLike | None = None, schemes: Sequence[str | SchemeOptions] | None = None,
            **params: Any) -> dict:
    """Error against run time of every scheme on one scene.

    Parameters
    ----------
    scene : str or Scene
        The name of a registered scene (``moreau scenes`` lists them), or a
        :class:`~moreau.model.scene.Scene` instance (a user's own scene,
        registered or not), which then needs ``t_span``, ``q0`` and ``v0``:
        its reference is the event-driven scheme at tight tolerance
        (:class:`moreau.analysis.cases.SceneCase`).
    steps : sequence of int, optional
        Moreau–Jean steps per period (per comparison window for the
        non-periodic scenes); :data:`DEFAULT_STEPS` (two decades; the
        friction drive adds 10000 and 20000), or
        :data:`QUICK_STEPS` with ``quick=True``.
    lcp_steps : sequence of int, optional
        Steps per period of the forced-Lemke and forced-QP rows.
    thetas : sequence of float
        Values of theta for the default Moreau–Jean rows.
    repeat : int
        Run-time samples per row (the median is reported); rows slower than
        one second are timed once.
    quick : bool
        Fewer points, one timing per row.
    progress : bool
        Show a progress bar (tqdm, on stderr).
    on_row : callable, optional
        Called with each finished row (the caller can save as it goes).
    t_span, q0, v0 : optional
        The window and start state, for a Scene instance only.
    schemes : sequence of str or SchemeOptions, optional
        Other registered schemes to run beside the reference and Moreau–Jean
        (those that state how, ``Integrator.compare_settings``, e.g.
        ``"compliant-radau"``); none by default. A scheme given as its
        options object (``TimeDiscontinuousGalerkin.Options(degree=1)``) runs
        its rows with those options. On a periodic scene each
        row is that scheme's own steady state, as for Moreau–Jean.
    **params
        Parameters of a registered scene and of its comparison case
        (:func:`case_parameters`).

    Returns
    -------
    dict
        ``scene``, ``parameters``, ``headline``, ``reference`` (scheme and
        tightest setting), ``rows`` (one per run: ``scheme``, ``theta``,
        ``lcp``, ``steps_per_period``, ``rtol``, ``time_s``, ``error``,
        ``trajectory_error``, ``switching_error``, ``mode``, ``status``,
        ``message``, ``signed_error``), ``orders`` (``scheme``, ``theta``,
        ``lcp``, ``order``, ``order_headline``), ``notes`` (plateaus of the
        headline error, :func:`plateaus`) and ``interrupted``.

    Examples
    --------
    A user's own scene (here a built-in class, used as an unregistered instance):

    >>> from moreau.scenes.sliding_block import SlidingBlock
    >>> rep = compare(SlidingBlock(mu=0.5), t_span=(0.0, 0.6), q0=[0.0, 0.0], v0=[2.0, 0.0],
    ...               steps=[20, 40, 80], lcp_steps=[], thetas=[1.0], repeat=1, progress=False)
    >>> rep["reference"]["scheme"], round(rep["orders"][0]["order"])
    ('event-driven', 1)
    """
    if isinstance(scene, Scene):
        if params:
            raise InputError(f"`{sorted(params)[0]}` applies to a registered scene's name; a "
                             "Scene instance carries its own parameters")
        if t_span is None or q0 is None or v0 is None:
            raise InputError("a Scene instance needs `t_span`, `q0` and `v0`")
        case = SceneCase(scene, t_span, q0, v0)
        scene = case.name
    else:
        if t_span is not None or q0 is not None or v0 is not None:
            raise InputError("`t_span`, `q0` and `v0` apply to a Scene instance; a registered "
                             "scene's case sets its own start")
        case = make_case(scene, **params)
    if quick:
        steps = QUICK_STEPS if steps is None else steps
        lcp_steps = QUICK_LCP_STEPS if lcp_steps is None else lcp_steps
        repeat = 1
    if steps is None:
        steps = getattr(case, "default_steps", DEFAULT_STEPS)
    steps = [positive_int("steps", n) for n in steps]
    lcp_steps = [positive_int("lcp_steps", n)
                 for n in (DEFAULT_LCP_STEPS if lcp_steps is None else lcp_steps)]
    repeat = positive_int("repeat", repeat)
    thetas = [in_closed_interval("theta", th, 0.5, 1.0) for th in thetas]

    tight = case.tight_rtol if case.tight_rtol is not None else None
    ref_value, ref_switches = case.reference(tight)
    # compile (numba) and load everything once, outside the timings
    case.mj(min(steps + lcp_steps, default=GRID), 1.0, None)
    if lcp_steps:
        case.mj(min(lcp_steps), 1.0, "lemke")
    others = other_schemes(case, quick, schemes or [])
    # the other step-count and tolerance schemes too (at their cheapest setting): their
    # compiled loops would otherwise be built inside their first row's time (measured:
    # Schatzman-Paoli's bouncing-ball row at 100 steps per period took 98 s, at 1000 0.7 ms)
    cheapest = {"steps_per_period": min, "tol": max}
    for name, key, values, fixed in others:
        if key in cheapest and values:
            try:
                case.scheme(name, dict(fixed, **{key: cheapest[key](values)}))
            except MoreauError:
                pass        # the row reports the failure
    report = {
        "scene": scene,
        "parameters": case.parameters(),
        "headline": case.headline_name,
        "reference": {"scheme": case.ref_scheme, "rtol": tight, "headline_value": ref_value},
        "rows": [],
        "orders": [],
        "pareto": [],
        "notes": [],
        "interrupted": False,
        # what a run time means here, and on what machine it was taken
        "time_s_meaning": ("median wall time of the computation that gives the row's headline "
                           "value: for a periodic scene the steady state of the row's scheme "
                           "(the fixed point of its period map, whatever its contact solver); "
                           "for other scenes one run over the window; numba compilation "
                           "excluded"),
        "provenance": provenance(),
    }
    jobs = [("ref", None, None, rtol) for rtol in case.ref_rtols]
    jobs += [("mj", th, None, n) for th in thetas for n in steps]
    spatial = is_spatial(getattr(case, "scene", None))
    if spatial:
        # a spatial step solves the friction cone, not an LCP the option `lcp_method`
        # picks: its rows force the cone instead, at one step count (the facets' error)
        jobs += [("mj", 1.0, f"cone={c}", FACET_STEPS[1 if quick else 0]) for c in FACET_CONES]
    else:
        jobs += [("mj", 1.0, lcp, n) for lcp in ("lemke", "qp") for n in lcp_steps]
    jobs += [("other", name, key, value, fixed)
             for name, key, values, fixed in others
             for value in values]

    def run(job):
        if job[0] == "other":
            return [run_other_row(case, *job[1:], repeat, ref_value, ref_switches)]
        return [run_row(case, *job, repeat, ref_value, ref_switches)]

    report["interrupted"] = collect_rows(jobs, run, report["rows"], on_row, progress,
                                         desc=f"compare {scene}", unit="run")
    report["orders"] = _orders(report["rows"])
    if spatial:
        report["facet_order"] = facet_order(report["rows"])
    report["pareto"] = pareto(report["rows"])
    report["notes"] = plateaus(report["rows"])
    return report


def collect_rows(items, run, rows, on_row=None, progress=False, desc="", unit="item"):
    """Append ``run(item)``'s rows for each item, with a progress bar; keep them on Ctrl-C.

    Returns True when interrupted: the rows finished so far stay in ``rows``.
    """
    bar = None
    if progress:
        # disable=None: a bar on a terminal only, never in a log file
        bar = tqdm(total=len(items), desc=desc, unit=unit, disable=None)
    try:
        # a run's own Ctrl-C handling (simulate's status -4) would let the batch go on
        with propagate_interrupts():
            for item in items:
                for row in run(item):
                    rows.append(row)
                    if on_row is not None:
                        on_row(row)
                if bar is not None:
                    bar.update(1)
    except KeyboardInterrupt:
        return True
    finally:
        if bar is not None:
            bar.close()
    return False


def run_row(case, kind, theta, lcp, setting, repeat, ref_value, ref_switches):
    """One row of the comparison table: run one scheme at one setting and measure its errors.

    Parameters
    ----------
    case : CompareCase
        From :func:`make_case`.
    kind : {"ref", "mj"}
        The scene's reference, or Moreau–Jean.
    theta : float or None
        Moreau–Jean's theta (None for the reference).
    lcp : {None, "lemke", "qp"}
        Contact solver forced on every Moreau–Jean step (None: the scheme's own).
    setting : float or int
        The reference's tolerance, or Moreau–Jean's steps per period.
    repeat : int
        Run-time samples (the median is reported).
    ref_value, ref_switches
        The reference's headline value and switching times at its tightest setting.

    Returns
    -------
    dict
        The keys of :data:`CSV_FIELDS`; a run that fails with a
        :class:`~moreau.errors.MoreauError` has ``status`` -1 and the error in
        ``message``.
    """
    row = {"scheme": case.ref_scheme if kind == "ref" else "moreau-jean", "theta": theta,
           "lcp": lcp, "steps_per_period": None if kind == "ref" else int(setting),
           "rtol": setting if kind == "ref" else None, "setting": None, "time_s": None,
           "error": None,
           "signed_error": None,
           "trajectory_error": None, "switching_error": None, "mode": None, "status": 0,
           "message": ""}
    try:
        if kind == "ref":
            t, (value, sw) = _median_time(lambda: case.reference(setting), repeat)
            row.update(time_s=t, error=_relative(value, ref_value),
                       signed_error=_signed(value, ref_value),
                       switching_error=switching_error(ref_switches, sw))
        else:
            t, out = _median_time(lambda: case.mj(setting, theta, lcp), repeat)
            value = out[0]
            traj, sw, mode = case.measure(setting, theta, lcp, out)
            row.update(time_s=t, error=_relative(value, ref_value), trajectory_error=traj,
                       signed_error=_signed(value, ref_value),
                       switching_error=switching_error(ref_switches, sw), mode=mode)
    except MoreauError as exc:
        row.update(status=-1, message=f"{type(exc).__name__}: {exc}")
    return row


def facet_order(rows):
    """The polyhedral cone's rows (``lcp`` ``"cone=d"``): the errors' fitted order in ``1/d``.

    Returns ``{"d": [...], "error": [...], "trajectory_error": [...], "order": p,
    "order_headline": p}`` over the integer ``d`` of the rows that finished
    (the error of each against the scene's reference).

    Examples
    --------
    >>> rows = [dict(scheme="moreau-jean", lcp=f"cone={d}", status=0, error=1.0 / d ** 2,
    ...              trajectory_error=1.0 / d) for d in (4, 8, 16)]
    >>> f = facet_order(rows)
    >>> round(f["order_headline"], 12), round(f["order"], 12)
    (2.0, 1.0)
    """
    pts = sorted((int(r["lcp"].split("=", 1)[1]), r) for r in rows
                 if r["scheme"] == "moreau-jean" and r["status"] == 0
                 and str(r.get("lcp") or "").startswith("cone=")
                 and r["lcp"].split("=", 1)[1].isdigit())
    d = [p[0] for p in pts]
    err = [p[1]["error"] for p in pts]
    traj = [p[1]["trajectory_error"] for p in pts]
    return {"d": d, "error": err, "trajectory_error": traj,
            "order": fit_order(d, traj) if len(d) >= 2 else None,
            "order_headline": fit_order(d, err) if len(d) >= 2 else None}


def other_schemes(case, quick=False, names=None):
    """``(name, setting, values, fixed_options)`` of the registered schemes that compare runs.

    Every registered scheme with ``compare_settings`` (the reference and
    Moreau–Jean have rows of their own), or those of ``names`` (``["all"]``:
    every one).
    """
    registered = {n: cls for n, cls in INTEGRATORS.items()
                  if getattr(cls, "compare_settings", None) is not None}
    if names is not None and list(names) == ["all"]:
        names = None
    # a scheme given as its options object: its options join the fixed ones of its rows
    given = {}
    if names is not None:
        names = list(names)
        for i, n in enumerate(names):
            if isinstance(n, SchemeOptions):
                names[i] = n.scheme
                given[n.scheme] = n.without_step("compare's rows")
    if names is not None:
        for n in names:
            if n not in registered:
                raise InputError(f"`schemes` must name schemes that compare can run, from "
                                 f"{sorted(registered)}; got {n!r}")
        registered = {n: registered[n] for n in names}
    out = []
    for name in sorted(registered):
        key, values, quick_values, fixed = registered[name].compare_settings
        extra = given.get(name, {})
        if key in extra:
            raise InputError(f"`{key}` is the setting compare varies for scheme {name!r}; "
                             f"give its options without it")
        out.append((name, key, quick_values if quick else values, {**dict(fixed), **extra}))
    return out


def run_other_row(case, name, key, value, fixed, repeat, ref_value, ref_switches):
    """One row of another registered scheme at ``key = value`` (see :func:`other_schemes`)."""
    row = {"scheme": name, "theta": None, "lcp": None, "steps_per_period": None, "rtol": None,
           "setting": f"{key}={value:g}", "time_s": None, "error": None, "signed_error": None,
           "trajectory_error": None, "switching_error": None, "mode": None, "status": 0,
           "message": ""}
    try:
        opts = dict(fixed, **{key: value})
        t, (value_, res) = _median_time(lambda: case.scheme(name, opts), repeat)
        row.update(time_s=t, error=_relative(value_, ref_value),
                   signed_error=_signed(value_, ref_value),
                   trajectory_error=case.measure_scheme(name, opts, (value_, res)))
        if getattr(res, "statistical", False):
            lo, hi = res.confidence_interval
            row["message"] = (f"statistical steady state (no period-1 orbit: "
                              f"{res.stats.get('why_not_periodic', '')}): mean in [{lo:.6g}, "
                              f"{hi:.6g}] ({res.confidence:.0%})")
    except MoreauError as exc:
        row.update(status=-1, message=f"{type(exc).__name__}: {exc}")
    return row


def _orders(rows):
    series = {}
    for r in rows:
        if r["status"] != 0:
            continue
        if r["scheme"] == "moreau-jean":
            series.setdefault(("moreau-jean", r["theta"], r["lcp"]), []).append(
                (r["steps_per_period"], r))
        elif (r.get("setting") or "").startswith("steps_per_period="):
            n = int(float(r["setting"].split("=", 1)[1]))
            series.setdefault((r["scheme"], None, None), []).append((n, r))
    out = []
    for (name, theta, lcp), pairs in series.items():
        n = [p[0] for p in pairs]
        rs = [p[1] for p in pairs]
        out.append({"scheme": name, "theta": theta, "lcp": lcp,
                    "order": fit_order(n, [r["trajectory_error"] for r in rs]),
                    "order_headline": fit_order(n, [r["error"] for r in rs])})
    return out


#: the errors at which :func:`pareto` names the fastest row
PARETO_TARGETS = (1e-2, 1e-4, 1e-6)


def pareto(rows, targets=PARETO_TARGETS):
    """For each target error, the fastest row whose headline error reaches it.

    Returns a list of ``{"target", "scheme", "label", "time_s", "error"}``;
    ``scheme`` is None where no row reaches the target. An event-driven
    reference's rows count (they show what the target costs with it); a
    closed-form reference (``"exact"``) does not.

    Examples
    --------
    >>> rows = [dict(scheme="a", theta=None, lcp=None, setting="", status=0, time_s=1.0,
    ...              error=1e-3),
    ...         dict(scheme="b", theta=None, lcp=None, setting="", status=0, time_s=0.1,
    ...              error=5e-3)]
    >>> [(p["target"], p["scheme"]) for p in pareto(rows)]
    [(0.01, 'b'), (0.0001, None), (1e-06, None)]
    """
    out = []
    # a closed-form reference ("exact") is the yardstick, not a scheme to choose
    ok = [r for r in rows if r["status"] == 0 and r.get("error") is not None
          and r.get("time_s") is not None and r["scheme"] != "exact"]
    for target in targets:
        hits = [r for r in ok if r["error"] <= target]
        best = min(hits, key=lambda r: r["time_s"]) if hits else None
        out.append({"target": target, "scheme": best and best["scheme"],
                    "label": best and _label(best) + _setting_suffix(best),
                    "time_s": best and best["time_s"], "error": best and best["error"]})
    return out


def _setting_suffix(r):
    if r.get("steps_per_period"):
        return f", {r['steps_per_period']} steps"
    if r.get("rtol"):
        return f", rtol {r['rtol']:g}"
    if r.get("setting"):
        return f", {r['setting']}"
    return ""


# -- output ---------------------------------------------------------------------------------
CSV_FIELDS = ("scheme", "theta", "lcp", "steps_per_period", "rtol", "setting", "time_s", "error",
              "signed_error", "trajectory_error", "switching_error", "mode", "status", "message")


def check_out_dir(out):
    """Create ``out`` if needed and check that files can be written there (before any work)."""
    if os.path.exists(out) and not os.path.isdir(out):
        raise InputError(f"`--out` must be a folder, but {out!r} is a file")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise InputError(f"`--out` folder {out!r} cannot be created: {exc.strerror}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise InputError(f"`--out` folder {out!r} is not writable")
    return out


def write_outputs(report, out, tag=None, plot=True):
    """Write ``<tag>.csv``, ``<tag>.json`` and (with matplotlib) ``<tag>.png``; return the paths."""
    tag = tag or f"compare_{report['scene']}"
    paths = {}
    csv_path = os.path.join(out, tag + ".csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in report["rows"]:
            w.writerow(r)
    paths["csv"] = csv_path
    json_path = os.path.join(out, tag + ".json")
    with open(json_path, "w") as fh:
        json.dump(report, fh, indent=1)
    paths["json"] = json_path
    if plot:
        try:
            png = os.path.join(out, tag + ".png")
            plot_work_precision(report, png)
            paths["png"] = png
        except ImportError:
            paths["png"] = None
    return paths


def _label(r):
    if r["scheme"] != "moreau-jean":
        return r["scheme"] + (f" ({r['setting'].split('=')[0]})" if r.get("setting") else "")
    th = "1/2" if r["theta"] == 0.5 else f"{r['theta']:g}"
    return f"Moreau–Jean θ={th}" + (f", {r['lcp']}" if r["lcp"] else "")


def plot_work_precision(report, path, ax=None):
    """Log–log figure: headline error (filled) and trajectory error (open) against run time."""
    import matplotlib
    if ax is None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(7, 5))
    groups = {}
    for r in report["rows"]:
        if r["status"] == 0 and r["time_s"]:
            groups.setdefault(_label(r), []).append(r)
    floor = 1e-16
    for i, (label, rs) in enumerate(groups.items()):
        color = f"C{i}"
        t = [r["time_s"] for r in rs]
        ax.loglog(t, [max(r["error"], floor) for r in rs], "o-", color=color, label=label)
        tr = [(r["time_s"], r["trajectory_error"]) for r in rs if r["trajectory_error"]]
        if tr:
            ax.loglog(*zip(*tr), "o:", color=color, mfc="none")
    ax.set_xlabel("run time [s] (median)")
    ax.set_ylabel(f"relative error: {report['headline']} (filled), trajectory (open)")
    params = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                       for k, v in report["parameters"].items())
    ax.set_title(f"{report['scene']} ({params})", fontsize=9)
    ax.legend(fontsize=7)
    if own:
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)


def format_table(report):
    """The rows as a fixed-width text table."""
    lines = [f"{report['scene']}: {report['headline']} "
             f"(reference {report['reference']['scheme']}"
             + (f", rtol {report['reference']['rtol']:g}" if report['reference']['rtol'] else "")
             + ")",
             f"{'scheme':>17} {'theta':>5} {'lcp':>5} {'steps':>6} {'rtol':>7} {'time [ms]':>10} "
             f"{'error':>9} {'traj.':>9} {'switch':>9} mode"]

    def g(x, fmt):
        return format(x, fmt) if x is not None else "-"

    for r in report["rows"]:
        if r["status"] != 0:
            lines.append(f"{r['scheme']:>17} {g(r['theta'], '5g')} {r['lcp'] or '-':>5} "
                         f"{g(r['steps_per_period'], '6d')} {g(r['rtol'], '7.0e')} failed: "
                         f"{r['message']}")
            continue
        lines.append(f"{r['scheme']:>17} {g(r['theta'], '5g'):>5} {r['lcp'] or '-':>5} "
                     f"{g(r['steps_per_period'], '6d'):>6} {g(r['rtol'], '7.0e'):>7} "
                     f"{r['time_s'] * 1e3:10.2f} {g(r['error'], '9.2e'):>9} "
                     f"{g(r['trajectory_error'], '9.2e'):>9} {g(r['switching_error'], '9.2e'):>9} "
                     f"{r['mode'] or r.get('setting') or ''}")
    for o in report["orders"]:
        th = o["theta"]
        lines.append(f"order  {o['scheme']}" + (f" theta={th:g} lcp={o['lcp'] or '-'}"
                                                 if th is not None else "")
                     + f": {g(o['order'], '.2f')} (trajectory), "
                     f"{g(o['order_headline'], '.2f')} (headline)")
    if report.get("facet_order"):
        f = report["facet_order"]
        lines.append(f"facets (polyhedral cone, d = {f['d']}): order in 1/d "
                     f"{g(f['order'], '.2f')} (trajectory), {g(f['order_headline'], '.2f')} "
                     "(headline)")
    for p in report.get("pareto", []):
        lines.append(f"fastest to error {p['target']:g}: "
                     + (f"{p['label']} ({p['time_s'] * 1e3:.3g} ms, error {p['error']:.2e})"
                        if p["scheme"] else "no row"))
    for note in report.get("notes", []):
        lines.append("note: " + note["text"])
    return "\n".join(lines)
