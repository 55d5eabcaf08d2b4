"""Stiff and extreme cases of the friction drive: what each scheme does (``moreau compare --stress``).

Every case of :data:`CASES` is run with every scheme of :data:`SCHEMES`:
the event-driven reference (``"event-driven"``), Moreau–Jean with ``theta =
1`` (``"mj-1"``) and with ``theta = 1/2`` (``"mj-1/2"``), both with position
projection, the package's default for the friction drive, and every other
registered time-stepping scheme (one with a step ``h``: Schatzman–Paoli,
the nonsmooth generalized-α, the time-discontinuous Galerkin scheme, ...)
under its registry name, with its default options. Each scheme's steady
state is its own discrete one (Moreau–Jean's compiled period map, the others
by Newton shooting on the period map they compute). Each run ends in one
outcome:

``stable``
    a finite result within the stated bound ``bound`` of the reference
    (``error <= bound``);
``inaccurate``
    a finite result outside the bound. The scheme itself does not know, so
    the catalogue says it: the row gives the error and the scheme's own
    step-halving estimate (:func:`halving_estimate`: Richardson's, from the
    steady states at ``N/2``, ``N`` and ``2N`` steps, shown only where their
    differences shrink geometrically; ``2 |d(N) - d(2N)|`` at first order);
``averaged``
    the flight cases, where impacts may leave no period-1 orbit: the
    periodic steady state where the shooting finds one, else the
    statistical steady state from rest (:mod:`moreau.analysis.statistical`:
    the transient detected and dropped, the long-run mean with a 95 %
    interval), compared with the event-driven value;
``failed``
    a clean failure whose message names the cause (the Painlevé condition,
    lost contact, ...), expected where the problem is ill-posed;
``n/a``
    the case does not apply to the scheme (the event-driven scheme takes no
    time steps);
``bug``
    anything else: a NaN, an unexpected exception. The tests require that no
    case ends in ``bug``.

The headline quantity is the displacement per period ``d`` (dimensionless,
``u2 = x2 / l``); errors are ``|d - d_ref| / max(|d_ref|, 0.01 u10)`` (the
floor, 1 % of the stator amplitude, keeps a motion with ``d_ref = 0``, a
permanent stick, measurable). The stated bound is ``BOUND = 0.05`` unless a
case says otherwise.

A registered scene adds its own steady-state cases through its entry's
``stress`` hook (:mod:`moreau.model.registry`); they join :data:`CASES`.

The 10^7-step case runs 10^7 steps in the command (``full=True``) and 10^6
in the quick catalogue that the tests run.

Examples
--------
>>> rep = run_catalogue(cases=["mu-zero"], schemes=["event-driven", "mj-1/2"], progress=False,
...                     fast=False)
>>> sorted({r["outcome"] for r in rep["rows"]})
['stable']
>>> [r["scheme"] for r in rep["rows"]]
['event-driven', 'mj-1/2']
"""

import json
import logging
import math
import os
import time

import numpy as np
from tqdm import tqdm

from ...outputs import write_csv
from ...analysis import engine
from ...analysis.compare import collect_rows
from ...analysis.mj_steady_state import moreau_jean_steady_state
from ...analysis.statistical import statistical_steady_state
from ...analysis.steady_state import find_steady_state
from ...errors import ConvergenceError, InputError, MoreauError
from ...provenance import provenance
from ...integrators import INTEGRATORS, simulate
from ...integrators.base import scheme_options
from ...model import registry
from ...scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive
from .valid_range import phi0_valid_range

__all__ = ["CASES", "SCHEMES", "CLASSIC", "check_schemes", "OUTCOMES", "BOUND", "run_case",
           "run_catalogue", "CellStore", "column_label", "halving_estimate",
           "write_stress_outputs", "format_stress_table", "plot_stability_map"]

TWO_PI = 2.0 * math.pi

log = logging.getLogger(__name__)


def _columns():
    """``key -> (registered scheme, options)`` of every column, in the map's order.

    The event-driven reference, then every registered time-stepping scheme
    (one whose constructor takes a step ``h``), read from the registry so
    that a new scheme gets its column without a list naming it: Moreau–Jean
    first, the others by name; a scheme with a ``theta`` twice, at ``theta =
    1`` and ``1/2`` (keys ``mj-1`` and ``mj-1/2`` for Moreau–Jean).
    """
    cols = {"event-driven": ("event-driven", {})}
    for name in sorted(INTEGRATORS, key=lambda n: (n != "moreau-jean", n)):
        takes = scheme_options(INTEGRATORS[name]) or ()
        if "h" not in takes:
            continue
        if "theta" in takes:
            short = "mj" if name == "moreau-jean" else name
            cols[f"{short}-1"] = (name, {"theta": 1.0})
            cols[f"{short}-1/2"] = (name, {"theta": 0.5})
        else:
            cols[name] = (name, {})
    return cols


_COLUMNS = _columns()
#: scheme keys, in the order of the map's columns
SCHEMES = tuple(_COLUMNS)
#: the catalogue's first columns: the reference and Moreau–Jean at theta = 1 and 1/2
CLASSIC = ("event-driven", "mj-1", "mj-1/2")
#: outcome -> colour of the stability map
OUTCOMES = {"stable": "#4daf4a", "averaged": "#a6d96a", "inaccurate": "#fdae61",
            "failed": "#abd9e9", "n/a": "#dddddd", "bug": "#d7191c"}
#: default bound on the relative error of a ``stable`` run
BOUND = 0.05
#: steps per period of the Moreau–Jean runs unless a case says otherwise
STEPS = 1000


def _scene(frequency=185.0, **params):
    return FrictionDrive(PAPER_DEFAULTS.with_(**params), frequency)


def _err(value, ref, scene):
    return abs(value - ref) / max(abs(ref), 0.01 * scene.u10)


def _row(case, scheme, outcome, **kw):
    row = {"case": case, "scheme": scheme, "outcome": outcome, "value": None, "reference": None,
           "error": None, "bound": None, "estimate": None, "mode": None, "time_s": None,
           "message": "", "interval": None}
    row.update(kw)
    return row


def _guard(case, scheme, fn):
    """Run ``fn() -> row``; a MoreauError becomes ``failed``, anything else ``bug``."""
    t0 = time.perf_counter()
    try:
        row = fn()
    except ConvergenceError as exc:
        row = _row(case, scheme, "failed", message=f"{type(exc).__name__}: {exc}")
    except MoreauError as exc:
        row = _row(case, scheme, "failed", message=f"{type(exc).__name__}: {exc}")
    except (KeyboardInterrupt, InputError):
        raise
    except Exception as exc:  # noqa: BLE001  (a traceback is exactly what the map must show)
        row = _row(case, scheme, "bug", message=f"{type(exc).__name__}: {exc}")
    row["time_s"] = time.perf_counter() - t0
    for key in ("value", "error", "estimate"):
        if row[key] is not None and not math.isfinite(row[key]):
            row.update(outcome="bug", message=f"non-finite {key}: {row[key]!r}. " + row["message"])
    return row


# -- the schemes of the columns ---------------------------------------------------------------
def _steady(scene, key, steps, fast, painleve="impulse"):
    """Steady state of column ``key`` at ``steps`` steps per period (``painleve``: Moreau–Jean's option)."""
    name, opts = _COLUMNS[key]
    if name == "moreau-jean":
        # the compiled discrete period map (projection, the friction drive's default)
        return moreau_jean_steady_state(scene, steps, theta=opts["theta"], painleve=painleve)
    opts = _run_options(key, fast)
    if painleve != "impulse":
        # a study of the Painlevé configuration: checked on the generic step
        opts.update(painleve=painleve)
        if "fast" in opts:
            opts["fast"] = False
    return find_steady_state(scene, scheme=name, steps_per_period=steps, rtol=1e-10,
                             scheme_options=opts)


def _run_options(key, fast):
    """Options of a run of column ``key`` besides its step (``fast`` where the scheme takes it)."""
    name, opts = _COLUMNS[key]
    out = dict(opts)
    if name == "moreau-jean":
        out["projection"] = True
    if fast != "auto" and "fast" in (scheme_options(INTEGRATORS[name]) or ()):
        out["fast"] = fast
    return out


def _stepping(schemes):
    return [k for k in schemes if k != "event-driven"]


# -- steady-state cases -----------------------------------------------------------------------
def _no_cache(case, scheme, compute, shown=True):
    """The cell store of a catalogue without a cache: compute every cell."""
    return compute()


def _reference_of(ed_row, *keys):
    """The event-driven row's ``keys`` where it has a value (else ``{}``: no reference)."""
    return {k: ed_row[k] for k in keys} if ed_row["value"] is not None else {}


def _steady_case(case, scene, schemes, fast, steps=STEPS, bound=BOUND, note="", reference=None,
                 cell=_no_cache):
    """Event-driven steady state as reference; each time-stepping scheme's at ``steps`` and 2x.

    ``reference``, where given, is a callable returning the steady state that
    stands for the event-driven one (a case whose own event-driven run is out
    of reach) and ``note`` says what it is. ``cell(case, scheme, compute,
    shown)`` gives each cell's row (:func:`run_case`).
    """
    rows = []

    def ed():
        ss = reference() if reference is not None else find_steady_state(scene, rtol=1e-12)
        return _row(case, "event-driven", "stable", value=ss.displacement_per_period,
                    mode=ss.mode, message=(note if reference is not None else
                                           "reference (shooting rtol 1e-12)" + note))

    # the reference is needed by every column, shown only where asked for (and kept either way)
    ed_row = cell(case, "event-driven", lambda: _guard(case, "event-driven", ed),
                  shown="event-driven" in schemes)
    ref = _reference_of(ed_row, "value", "mode")
    if "event-driven" in schemes:
        rows.append(ed_row)
    for scheme in _stepping(schemes):
        def ts(scheme=scheme):
            ss = _steady(scene, scheme, steps, fast)
            d = ss.displacement_per_period
            d2 = _steady(scene, scheme, 2 * steps, fast).displacement_per_period
            d_half = _guard_value(lambda: _steady(scene, scheme, max(steps // 2, 1),
                                                  fast).displacement_per_period)
            est, why = halving_estimate(d_half, d, d2, max(abs(d2), 0.01 * scene.u10))
            said = (f"step-halving estimate {est:.2g}" if est is not None else
                    f"no step-halving estimate: {why}")
            row = _row(case, scheme, "stable", value=d, mode=ss.mode, bound=bound, estimate=est)
            if not ref:
                # nothing to compare with: judge by the scheme's own estimate, where it has one
                row.update(outcome="stable" if est is not None and est <= bound else
                           "inaccurate", message=f"no reference; N = {steps}, {said}")
                return row
            e = _err(d, ref["value"], scene)
            row.update(reference=ref["value"], error=e)
            msg = f"N = {steps}; error {e:.2g} ({said})"
            if ss.mode != ref["mode"]:
                msg += f"; mode {ss.mode} instead of {ref['mode']}"
            if e > bound:
                row["outcome"] = "inaccurate"
            row["message"] = msg
            return row

        rows.append(cell(case, scheme, lambda ts=ts, scheme=scheme: _guard(case, scheme, ts)))
    return rows


#: observed convergence ratios |d(N/2) - d(N)| / |d(N) - d(2N)| a step-halving estimate trusts
#: (orders 0.5 .. 4): outside, the three steady states are not in the asymptotic range
HALVING_RATIOS = (2.0 ** 0.5, 2.0 ** 4)
#: differences below this (relative to the scale) are rounding: the value no longer changes
HALVING_ROUNDING = 1e-12


def halving_estimate(d_half, d, d2, scale):
    """The error of ``d`` (at ``N`` steps) estimated from ``N/2``, ``N`` and ``2N``, or why not.

    Richardson's estimate with the observed ratio ``r = |d(N/2) - d(N)| /
    |d(N) - d(2N)|`` (``2^p`` for a scheme of order ``p`` in its asymptotic
    range): ``error(N) ~ r |d(N) - d(2N)| / (r - 1)``, relative to
    ``scale``; ``2 |d(N) - d(2N)|`` for a first-order scheme. It is given
    only where ``r`` lies in :data:`HALVING_RATIOS`. A time-stepping steady
    state whose switches are locked to the grid moves in a staircase: at
    m2/m = 1e6 Moreau–Jean's ``d`` is the same at 1000 and 2000 steps to
    7e-9 (relative) and 4e-5 away at 500 and 4000, so ``2 |d(N) - d(2N)|``
    read 7.1e-6 where the error is 8.3e-3.

    Returns
    -------
    (float or None, str)
        The estimate (None where it is not reliable) and why not.

    Examples
    --------
    >>> round(halving_estimate(1.04, 1.02, 1.01, 1.0)[0], 12)
    0.02
    >>> halving_estimate(1.0, 1.02, 1.02, 1.0)
    (None, 'the steady states at N/2, N, 2N steps differ by 0.02 and 0 (relative): not a geometric convergence (ratio inf)')
    """
    if d_half is None:
        return None, "the steady state at N/2 steps failed"
    a, b = abs(d_half - d) / scale, abs(d - d2) / scale
    if a <= HALVING_ROUNDING and b <= HALVING_ROUNDING:
        return 2.0 * b, ""
    r = a / b if b > 0.0 else math.inf
    if not HALVING_RATIOS[0] <= r <= HALVING_RATIOS[1]:
        return None, (f"the steady states at N/2, N, 2N steps differ by {a:.2g} and {b:.2g} "
                      f"(relative): not a geometric convergence (ratio {r:.3g})")
    return r * b / (r - 1.0), ""


def _guard_value(fn):
    # a value, or None where the scheme fails there (a coarser grid may not resolve the case)
    try:
        return fn()
    except MoreauError:
        return None


def _ill_posed_case(case, scene, schemes, fast, cell=_no_cache):
    """Beyond the Painlevé limit: every scheme must fail and name the cause.

    Moreau–Jean takes tangential impacts by default (the velocity-level
    problem is always solvable); this case studies the Painlevé
    configuration itself, so it runs with ``painleve="stop"``.
    """
    def expect_failure(fn, scheme):
        def run():
            ss = fn()
            # a result here would be a false success
            return _row(case, scheme, "bug", value=ss.displacement_per_period, mode=ss.mode,
                        message="returned a steady state for an ill-posed problem")
        return run

    rows = []
    if "event-driven" in schemes:
        ed = expect_failure(lambda: find_steady_state(scene, rtol=1e-12), "event-driven")
        rows.append(cell(case, "event-driven", lambda: _guard(case, "event-driven", ed)))
    for scheme in _stepping(schemes):
        rows.append(cell(case, scheme, lambda scheme=scheme: _guard(case, scheme, expect_failure(
            lambda: _steady(scene, scheme, STEPS, fast, painleve="stop"), scheme))))
    return rows


# -- flight and impacts above the contact-loss limit ---------------------------------------
#: statistical steady states of the flight cases: (precision, budget in periods), full and quick
#: (the event-driven spin-up at e = 1 takes 14270 periods, the Moreau-Jean theta = 1/2 one 19660)
FLIGHT_STATISTICS = {True: (1e-2, 80000), False: (5e-2, 400)}


def _statistical_row(case, scheme, scene, note, full, run, **opts):
    """A flight case's statistical steady state as a row (value = the mean), from rest unless
    ``opts`` give ``q0`` and ``v0``.

    ``end_state`` is the run's last state at the section, ``(q, v)`` flattened
    (dimensionless), from which :func:`_other_attractor` starts the reference.
    """
    precision, budget = FLIGHT_STATISTICS[bool(full)]
    ss = statistical_steady_state(scene, run, precision=precision, max_periods=budget, **opts)
    lo, hi = ss.confidence_interval
    row = _row(case, scheme, "averaged", value=ss.displacement_per_period, mode=None,
               message=note + (f"statistical steady state: mean {ss.displacement_per_period:.5g} "
                               f"in [{lo:.5g}, {hi:.5g}] (95 %), {ss.periods_used} periods after "
                               f"a transient of {ss.stats['transient_periods']}"))
    row["interval"] = [lo, hi]
    row["end_state"] = [float(x) for x in ss.state0]
    return row


def _other_attractor(case, scene, full, row, bound):
    """The reference's statistical mean from a stepping run's last state, where it differs.

    The flight at 15 kHz, e = 1 has two attractors: the reference from rest
    spins the rotor up onto a chaotic one (mean 9.7e-6 m a period), while
    Moreau–Jean's runs from rest end on a regular one (5.66e-6 m a period
    by the reference), which the reference keeps when started there. A
    stepping scheme's mean that misses the reference from rest is then the
    right answer for another attractor, not an inaccurate one: this runs the
    reference from the scheme's last state and says which it is
    (``benchmarks/statistical_agreement.py`` measures both attractors).
    Returns ``(message, same)``, ``same`` true where the scheme's mean is
    within ``bound`` of the reference on its own attractor.
    """
    s = np.asarray(row["end_state"], float)
    n = scene.ndof
    try:
        alt = _statistical_row(case, "event-driven", scene, "", full, "event-driven",
                               q0=s[:n], v0=s[n:])
    except ConvergenceError as exc:
        return f"; the reference from this run's last state failed ({exc})", False
    e = _err(row["value"], alt["value"], scene)
    row["attractor_reference"], row["attractor_error"] = alt["value"], e
    lo, hi = alt["interval"]
    same = e <= bound
    return ((f"; {'another attractor: ' if same else ''}the reference from this run's last "
             f"state averages {alt['value']:.5g} in [{lo:.5g}, {hi:.5g}] (error {e:.2g} against "
             f"it)"), same)


def _flight_case(case, scene, full, schemes, fast, steps=2000, bound=0.05, cell=_no_cache):
    """Above the contact-loss limit: the periodic steady state where one exists, else the
    statistical one (:mod:`moreau.analysis.statistical`), never a fixed window of a transient.

    The full catalogue asks for a 95 % interval within 1 % of the mean and allows 80000
    periods; the quick one 5 % and 400 periods, which the spin-up of the restitution cases
    outlasts: those rows fail with the budget-exhausted status.
    """
    def ed():
        try:
            ss = find_steady_state(scene, rtol=1e-10, statistical=False)
            return _row(case, "event-driven", "averaged", value=ss.displacement_per_period,
                        mode=ss.mode, message=f"periodic steady state {ss.mode}")
        except ConvergenceError as exc:
            note = f"no periodic steady state ({str(exc).split(':')[0]}); "
        return _statistical_row(case, "event-driven", scene, note, full, "event-driven")

    ed_row = cell(case, "event-driven", lambda: _guard(case, "event-driven", ed),
                  shown="event-driven" in schemes)
    ref = _reference_of(ed_row, "value", "interval")
    rows = [ed_row] if "event-driven" in schemes else []
    for scheme in _stepping(schemes):
        def ts(scheme=scheme):
            name = _COLUMNS[scheme][0]
            ss = None
            note = ""
            try:
                ss = _steady(scene, scheme, steps, fast)
                if not ss.stats.get("periodic", True) or ss.stats.get("steady_state") == \
                        "statistical":
                    note, ss = f"no period-1 orbit of the {name} map; ", None
            except ConvergenceError as exc:
                note = f"no periodic steady state ({str(exc).split(':')[0]}); "
            if ss is not None:
                row = _row(case, scheme, "averaged", value=ss.displacement_per_period,
                           mode=ss.mode, bound=bound, message=f"periodic steady state {ss.mode}")
            else:
                opts = _run_options(scheme, fast)
                if name == "moreau-jean":
                    opts = {"theta": opts["theta"], "projection": True}
                row = _statistical_row(case, scheme, scene, note, full, name,
                                       steps_per_period=steps, **opts)
                row["bound"] = bound
            if ref:
                e = _err(row["value"], ref["value"], scene)
                row.update(reference=ref["value"], error=e)
                if e > bound:
                    row["outcome"] = "inaccurate"
                msg = (f"{'' if ss is None else '; '}N = {steps}; error {e:.2g} against the "
                       f"event-driven value")
                a, b = row.get("interval"), ref.get("interval")
                if a or b:
                    hw = sum((x[1] - x[0]) / 2.0 for x in (a, b) if x)
                    within = abs(row["value"] - ref["value"]) <= hw
                    msg += (f" ({'within' if within else 'outside'} the sum of the intervals' "
                            f"half-widths)")
                if e > bound and b and row.get("end_state") is not None:
                    more, same = _other_attractor(case, scene, full, row, bound)
                    msg += more
                    if same:
                        row["outcome"] = "averaged"
                row["message"] += msg
            return row

        rows.append(cell(case, scheme, lambda ts=ts, scheme=scheme: _guard(case, scheme, ts)))
    return rows


# -- long runs --------------------------------------------------------------------------------
def _energy(scene, q, v):
    # at tau = 2 pi k the stator is at rest (u1' = 0), so the energy is the rod's
    # kinetic and spring energy plus the rotor's kinetic energy
    return (v[:, 0] ** 2 / 6.0 + 0.5 * scene.P * (scene.sin_phi0 - np.sin(q[:, 0])) ** 2
            + 0.5 * scene.J * v[:, 1] ** 2)


def _section_state(ss):
    """``(q0, v0)`` at the section of a steady state: Moreau–Jean's map keeps ``(phi, phi',
    u2')`` (the rotor at 0), the generic shooting the full state."""
    x = np.asarray(ss.state0, float)
    if x.size == 3:
        return np.array([x[0], 0.0]), np.array([x[1], x[2]])
    n = x.size // 2
    q0 = x[:n].copy()
    q0[1] = 0.0
    return q0, x[n:].copy()


def _long_case(case, scene, full, schemes, fast, steps=1000, bound=1e-6, cell=_no_cache):
    total = 10 ** 7 if full else 10 ** 6
    periods = total // steps
    rows = []
    if "event-driven" in schemes:
        rows.append(cell(case, "event-driven", lambda: _row(
            case, "event-driven", "n/a", time_s=0.0,
            message="event-driven takes no time steps; its error does not grow with them")))
    for scheme in _stepping(schemes):
        def ts(scheme=scheme):
            name = _COLUMNS[scheme][0]
            ss = _steady(scene, scheme, steps, fast)
            q0, v0 = _section_state(ss)
            res = simulate(scene, (0.0, TWO_PI * periods), q0, v0, name,
                           h=TWO_PI / steps, save_every=steps, **_run_options(scheme, fast))
            if res.status != 0:
                raise MoreauError(f"long run stopped: {res.message}")
            if res.stats["steps"] != total:
                raise MoreauError(f"long run took {res.stats['steps']} steps, not {total}")
            if "max_penetration" not in res.stats:
                raise MoreauError(f"{name} does not report its penetration (stats "
                                  "'max_penetration')")
            d = np.diff(res.q[:, 1])
            E = _energy(scene, res.q, res.v)
            drift = float(np.max(np.abs(d - ss.displacement_per_period))
                          / max(abs(ss.displacement_per_period), 0.01 * scene.u10))
            e_spread = float((E.max() - E.min()) / E.max())
            pen = float(res.stats["max_penetration"]) / scene.u10
            worst = max(drift, e_spread, pen)
            out = "stable" if worst <= bound else "inaccurate"
            return _row(case, scheme, out, value=float(d[-1]),
                        reference=ss.displacement_per_period, error=worst, bound=bound,
                        mode=ss.mode,
                        message=(f"{total:.0e} steps ({periods} periods, N = {steps}): "
                                 f"displacement per period drift {drift:.1e}, energy spread "
                                 f"at period starts {e_spread:.1e}, max penetration / u10 "
                                 f"{pen:.1e}"))

        rows.append(cell(case, scheme, lambda ts=ts, scheme=scheme: _guard(case, scheme, ts)))
    return rows


# -- the catalogue ----------------------------------------------------------------------------
def _phi0_edges(frequency=185.0):
    r = phi0_valid_range(PAPER_DEFAULTS, frequency)
    return r["lift_off_edge"], r["painleve_edge"]


def _c(title, fn):
    return {"title": title, "run": fn}


def _steady_at(frequency=185.0, steps=STEPS, **params):
    """A steady-state case of ``_scene(frequency, **params)``; a callable parameter is
    evaluated when the case runs (the phi0 edges cost a computation)."""
    def run(c, full, schemes, fast, cell=_no_cache):
        values = {k: v() if callable(v) else v for k, v in params.items()}
        return _steady_case(c, _scene(frequency, **values), schemes, fast, steps=steps,
                            cell=cell)
    return run


def _flight(e):
    return lambda c, full, schemes, fast, cell=_no_cache: _flight_case(
        c, _scene(15000.0, restitution=e), full, schemes, fast, cell=cell)


#: case id -> {"title", "run": callable(case_id, full, schemes, fast, cell) -> rows}
CASES = {
    "stiff-1Hz-N50": _c("f = 1 Hz (P = 1.3e7), 50 steps per period",
                        _steady_at(1.0, steps=50)),
    "stiff-1Hz-N1000": _c("f = 1 Hz, 1000 steps per period", _steady_at(1.0, steps=1000)),
    "stiff-1Hz-N1e5": _c("f = 1 Hz, 1e5 steps per period", _steady_at(1.0, steps=100000)),
    "flight-15kHz-e0": _c("f = 15 kHz (contact lost above 12.3 kHz), e = 0", _flight(0.0)),
    "flight-15kHz-e0.5": _c("f = 15 kHz, e = 0.5", _flight(0.5)),
    "flight-15kHz-e1": _c("f = 15 kHz, e = 1", _flight(1.0)),
    "painleve-mu0.9": _c("mu = 0.9 (Painlevé limit 1/tan(phi0) = 1)", _steady_at(mu=0.9)),
    "painleve-mu0.99": _c("mu = 0.99", _steady_at(mu=0.99)),
    "painleve-mu0.999": _c("mu = 0.999", _steady_at(mu=0.999)),
    "painleve-mu1.2": _c("mu = 1.2, beyond the limit (ill-posed)",
                         lambda c, full, schemes, fast, cell=_no_cache: _ill_posed_case(
                             c, _scene(mu=1.2), schemes, fast, cell=cell)),
    "mu-zero": _c("mu = 0 (no friction)", _steady_at(mu=0.0)),
    "mass-ratio-1e-3": _c("m2/m = 1e-3", _steady_at(m2=2e-8)),
    "mass-ratio-1e6": _c("m2/m = 1e6", _steady_at(m2=20.0)),
    "phi0-lift-off-edge": _c("phi0 = lift-off edge + 1e-3",
                             _steady_at(phi0=lambda: _phi0_edges()[0] + 1e-3)),
    "phi0-painleve-edge": _c("phi0 = Painlevé edge - 1e-3",
                             _steady_at(phi0=lambda: _phi0_edges()[1] - 1e-3)),
    "coarse-N10": _c("10 steps per period (h = T/10)", _steady_at(steps=10)),
    "long-1e7-steps": _c("10^7 steps at N = 1000 (10^6 in the quick catalogue)",
                         lambda c, full, schemes, fast, cell=_no_cache: _long_case(
                             c, _scene(), full, schemes, fast, cell=cell)),
}


def _scene_case(spec):
    """A steady-state case of a scene's own (its registry entry's ``stress`` hook)."""
    make = spec["scene"]
    steps = int(spec.get("steps", STEPS))
    bound = float(spec.get("bound", BOUND))

    def run(c, full, schemes, fast, cell=_no_cache):
        return _steady_case(c, make(), schemes, fast, steps=steps, bound=bound,
                            note=spec.get("note", ""), reference=spec.get("reference"), cell=cell)
    return _c(spec["title"], run)


def _scene_cases():
    """The cases the registered scenes add (``stress`` of their entries), by case id."""
    out = {}
    for entry in registry.entries():
        if entry.stress is None:
            continue
        for key, spec in entry.stress().items():
            if key in CASES or key in out:
                raise InputError(f"scene {entry.name!r} adds the stress case {key!r}, "
                                 "which exists already")
            out[key] = _scene_case(spec)
    return out


CASES.update(_scene_cases())


def check_schemes(schemes):
    """The column keys ``schemes`` (all of :data:`SCHEMES` for None), in the map's order.

    Examples
    --------
    >>> check_schemes(["mj-1/2", "event-driven"])
    ('event-driven', 'mj-1/2')
    >>> check_schemes(["euler"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `schemes` must hold keys of SCHEMES ('event-driven', 'mj-1', ...); got 'euler'
    """
    if schemes is None:
        return SCHEMES
    if isinstance(schemes, str):
        schemes = [schemes]
    for k in schemes:
        if k not in SCHEMES:
            raise InputError(f"`schemes` must hold keys of SCHEMES {SCHEMES}; got {k!r}")
    if not schemes:
        raise InputError("`schemes` must name at least one column")
    return tuple(k for k in SCHEMES if k in schemes)


def _check_fast(fast):
    if fast not in ("auto", True, False):
        raise InputError(f"`fast` must be 'auto', True or False, got {fast!r}")
    return fast


def run_case(case, full=False, schemes=None, fast="auto", cell=None):
    """Rows (one per scheme of ``schemes``, all of :data:`SCHEMES` by default) of one case.

    Parameters
    ----------
    case : str
        A key of :data:`CASES`.
    full : bool
        See :func:`run_catalogue`.
    schemes : sequence of str, optional
        Column keys (of :data:`SCHEMES`); the rows follow the map's order.
    fast : {"auto", True, False}
        Passed to the time-stepping schemes that take it (compiled loop or
        the generic step); Moreau–Jean's steady states always use its compiled
        period map.
    cell : callable, optional
        ``cell(case, scheme, compute, shown=True) -> row`` gives the row of
        one cell, ``compute()`` being what computes it: the catalogue's
        :class:`CellStore` reads a kept cell instead. ``shown`` is False for
        the event-driven reference of a case that does not show its column
        (computed, and kept, all the same). Every cell is computed by default.

    Examples
    --------
    >>> [r["outcome"] for r in run_case("painleve-mu1.2", schemes=CLASSIC)]
    ['failed', 'failed', 'failed']
    """
    if case not in CASES:
        raise InputError(f"`case` must be one of {list(CASES)}, got {case!r}")
    schemes = check_schemes(schemes)
    fast = _check_fast(fast)
    rows = CASES[case]["run"](case, full, schemes, fast, cell=cell or _no_cache)
    for r in rows:
        r["title"] = CASES[case]["title"]
    return rows


def _kept_cell(case, scheme, full, fast, version, compute):
    """The row of one cell, ``compute()``: memoised on disk by :class:`CellStore`, keyed by
    everything but ``compute`` (the case, the column, ``full``, ``fast``, the code version)."""
    return compute()


class CellStore:
    """The cells of a catalogue run, each kept on disk as it finishes (``moreau compare --stress``).

    The cache is the sweep engine's (:mod:`moreau.analysis.engine`): a
    :class:`joblib.Memory` in ``cache_dir``, keyed by the case id, the column
    key, ``full``, ``fast`` and :func:`~moreau.analysis.engine.code_version`,
    so that a rerun of the same catalogue reads the cells it finished before
    (an interrupted run resumes), and an edit of the computing code computes
    them anew. Without ``cache_dir`` every cell is computed.

    Counts the cells it gives (``cached``, ``computed``), drives a tqdm bar
    over ``total`` cells (on a terminal only) and logs each computed cell at
    INFO (shown in a log file with ``moreau -v``).
    """

    def __init__(self, cache_dir=None, full=False, fast="auto", total=0, progress=False):
        self.cache_dir = None if cache_dir is None else str(cache_dir)
        if self.cache_dir is not None:
            engine.check_output_dir(self.cache_dir, "--out")
        self.func = engine.cache_memory(self.cache_dir).cache(_kept_cell, ignore=["compute"])
        self.full, self.fast, self.total = bool(full), fast, int(total)
        self.version = engine.code_version()
        self.cached = self.computed = 0
        # disable=None: a bar on a terminal only, never in a log file
        self.bar = (tqdm(total=self.total, desc="stress catalogue", unit="cell", disable=None)
                    if progress else None)

    @property
    def done(self):
        """Cells finished (computed or read from the cache)."""
        return self.cached + self.computed

    def __call__(self, case, scheme, compute, shown=True):
        ran = []

        def run():
            ran.append(True)
            if self.bar is not None and shown:
                self.bar.set_postfix_str(f"{case} / {scheme}", refresh=True)
            t0 = time.perf_counter()
            row = compute()
            log.info("stress catalogue: %s / %s: %s (%.1f s)", case, scheme, row["outcome"],
                     time.perf_counter() - t0)
            return row

        row = dict(self.func(case, scheme, self.full, self.fast, self.version, run))
        if shown:
            if ran:
                self.computed += 1
            else:
                self.cached += 1
            if self.bar is not None:
                self.bar.update(1)
        return row

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def run_catalogue(cases=None, full=False, progress=True, on_row=None, schemes=None,
                  fast="auto", cache_dir=None):
    """Run the stress catalogue.

    Parameters
    ----------
    cases : sequence of str, optional
        Case ids (keys of :data:`CASES`); all by default.
    full : bool
        The long run takes 10^7 steps (else 10^6) and the flight cases' statistical
        steady states aim at a 1 % interval within 80000 periods (else 5 % within 400).
    progress : bool
        tqdm progress bar over the cases.
    on_row : callable, optional
        Called with every finished row.
    schemes : sequence of str, optional
        Column keys of :data:`SCHEMES`; every one by default.
    fast : {"auto", True, False}
        See :func:`run_case`.
    cache_dir : path-like, optional
        Keep every finished cell (case, column) here as it finishes
        (:class:`CellStore`): a rerun with the same cache reads the cells
        instead of computing them, so an interrupted catalogue resumes.
        None (the default) keeps nothing.

    Returns
    -------
    dict
        ``rows`` (``case``, ``title``, ``scheme``, ``outcome``, ``value``,
        ``reference``, ``error``, ``bound``, ``estimate``, ``mode``,
        ``time_s``, ``message``; a cell read from the cache has the time it
        took when it was computed), ``schemes`` (the columns, with the
        registered scheme and options of each), ``full``, ``cells``
        (``total``, ``cached``, ``computed``, ``cache_dir``) and
        ``interrupted`` (an interrupted catalogue keeps the finished cases in
        ``rows``, and with ``cache_dir`` every finished cell on disk).
    """
    cases = list(CASES) if cases is None else list(cases)
    for c in cases:
        if c not in CASES:
            raise InputError(f"`cases` must hold keys of CASES ({list(CASES)}), got {c!r}")
    schemes = check_schemes(schemes)
    fast = _check_fast(fast)
    report = {"full": bool(full), "bound": BOUND,
              "schemes": [{"key": k, "scheme": _COLUMNS[k][0], "options": _COLUMNS[k][1]}
                          for k in schemes],
              "rows": [], "interrupted": False}
    # every case gives one row per column
    store = CellStore(cache_dir, full, fast, total=len(cases) * len(schemes), progress=progress)
    try:
        report["interrupted"] = collect_rows(
            cases, lambda c: run_case(c, full, schemes, fast, cell=store), report["rows"],
            on_row)
    finally:
        store.close()
    report["cells"] = {"total": store.total, "cached": store.cached,
                       "computed": store.computed, "cache_dir": store.cache_dir}
    report["provenance"] = provenance()
    return report


# -- output -----------------------------------------------------------------------------------
FIELDS = ("case", "scheme", "outcome", "value", "reference", "error", "bound", "estimate",
          "mode", "time_s", "message", "interval", "attractor_reference", "attractor_error")


def write_stress_outputs(report, out, plot=True):
    """Write ``stress.csv``, ``stress.json`` and (with ``plot``) ``stress.png`` to ``out``."""
    paths = {}
    p = os.path.join(out, "stress.csv")
    write_csv(p, report["rows"], FIELDS, extrasaction="ignore")
    paths["csv"] = p
    p = os.path.join(out, "stress.json")
    with open(p, "w") as fh:
        json.dump(report, fh, indent=1)
    paths["json"] = p
    if plot:
        p = os.path.join(out, "stress.png")
        plot_stability_map(report, p)
        paths["png"] = p
    return paths


def _cell_text(r):
    if r["outcome"] == "averaged" and r.get("attractor_error") is not None:
        return f"averaged,\nother attractor\n{r['attractor_error']:.1e}"
    if r["outcome"] in ("stable", "inaccurate", "averaged") and r["error"] is not None:
        return f"{r['outcome']}\n{r['error']:.1e}"
    return r["outcome"]


def column_label(key):
    r"""The map's heading of column ``key``.

    Examples
    --------
    >>> column_label("mj-1/2")
    'Moreau–Jean\nθ=1/2'
    >>> column_label("schatzman-paoli")
    'schatzman-\npaoli'
    """
    name, opts = _COLUMNS[key]
    if name == "moreau-jean":
        return "Moreau\u2013Jean\n\u03b8=" + ("1" if opts["theta"] == 1.0 else "1/2")
    if "theta" in opts:
        return f"{name}\n\u03b8={opts['theta']:g}"
    # one break after the first word keeps the long registry names readable
    head, _, tail = name.partition("-")
    return f"{head}-\n{tail}" if tail else head


def plot_stability_map(report, path):
    """The stability map: cases (rows) against schemes (columns), coloured by outcome."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    cases = list(dict.fromkeys(r["case"] for r in report["rows"]))
    present = {r["scheme"] for r in report["rows"]}
    columns = [k for k in SCHEMES if k in present]
    names = list(OUTCOMES)
    grid = np.full((len(cases), len(columns)), names.index("n/a"))
    text = {}
    for r in report["rows"]:
        i, j = cases.index(r["case"]), columns.index(r["scheme"])
        grid[i, j] = names.index(r["outcome"])
        text[i, j] = _cell_text(r)
    fig, ax = plt.subplots(figsize=(max(7.5, 1.25 * len(columns) + 2.0),
                                    0.42 * len(cases) + 1.9))
    ax.imshow(grid, cmap=ListedColormap(list(OUTCOMES.values())), vmin=-0.5,
              vmax=len(names) - 0.5, aspect="auto")
    for (i, j), s in text.items():
        ax.text(j, i, s, ha="center", va="center", fontsize=6.5)
    ax.set_xticks(range(len(columns)), [column_label(k) for k in columns], fontsize=7)
    ax.set_yticks(range(len(cases)), cases, fontsize=7)
    ax.xaxis.tick_top()
    ax.legend(handles=[Patch(color=c, label=k) for k, c in OUTCOMES.items()], fontsize=7,
              loc="upper center", bbox_to_anchor=(0.5, -0.01), ncol=len(OUTCOMES))
    ax.set_title(f"stress catalogue: outcome and error (bound {report.get('bound', BOUND):g} "
                 f"unless stated)", fontsize=9, pad=24)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def format_stress_table(report):
    """The catalogue as a fixed-width text table."""
    lines = [f"{'case':<20} {'scheme':<28} {'outcome':<10} {'error':>8} {'bound':>7} "
             f"{'estimate':>8} {'mode':<6} message"]

    def g(x):
        return f"{x:8.1e}" if x is not None else f"{'-':>8}"

    for r in report["rows"]:
        b = f"{r['bound']:7.0e}" if r["bound"] is not None else f"{'-':>7}"
        lines.append(f"{r['case']:<20} {r['scheme']:<28} {r['outcome']:<10} {g(r['error'])} {b} "
                     f"{g(r['estimate'])} {r['mode'] or '-':<6} {r['message']}")
    return "\n".join(lines)
