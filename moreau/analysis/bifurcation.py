"""Bifurcation diagrams: a stroboscopic section of the long-run motion against a parameter.

``moreau bifurcation --scene NAME --param P START STOP`` runs, for every
value of the parameter ``P`` of a periodically driven scene, the motion for
``transient`` drive periods and then samples its state at the section
``tau = 0 (mod 2 pi)`` for ``samples`` more periods. Each point starts from
the previous point's last section state (natural continuation, the way a
slowly swept experiment moves); the first point, and any point whose
predecessor failed, from the scene's rest or initial state.

For every point it reports:

* the section samples in SI units (the common columns of
  :meth:`Scene.si_columns`, with the cyclic coordinate's position replaced
  by the ``displacement_per_period`` it gained);
* the period ``k`` of the sampled sequence (the smallest ``k <= 8`` with
  ``x_{j+k} = x_j`` to ``period_rtol`` of each column's scale over the
  samples), 0 when none: a non-periodic (quasi-periodic or chaotic) motion
  or a transient longer than the window;
* the largest Lyapunov exponent of the period map, per drive period, by
  Benettin's method: a companion started ``delta0`` away (relative to the
  state's scale) along a fixed direction of the free coordinates is carried
  along for the ``samples`` periods, its separation renormalised to
  ``delta0`` after every period, and the mean log growth taken. A stick
  phase erases a perturbation in one period (a multiplier 0), so a
  separation that collapses to rounding counts as ``log(1e-12)``: the
  exponent is then a bound, reported as ``<= ...``. A positive exponent with
  ``k = 0`` marks chaotic motion;
* whether the motion leaves contact during the last period (flight).

Between neighbouring points, a change of ``k`` from ``k`` to ``2 k`` is
marked as a period doubling, another change of ``k`` as a period change, a
change of the flight flag as grazing (contact lost or regained), first at
the midpoint of the two values. Where the period-1 orbit can be shot there
(``refine``, ``--refine``, :func:`refine_mark`), each mark is then located by root finding
between the two values on the orbit: regula falsi on ``lambda + 1`` of its
most negative real multiplier (period doubling), on ``lambda - 1`` of its
largest positive one (saddle-node: named apart from other period changes),
bisection on flight in the orbit (grazing). Where the orbit exists on one
side only, bisection on its existence finds its end, and the mark names
what ended it: its minimum normal force reaching 0 (grazing, lift-off) or
its largest multiplier reaching +1 (saddle-node); neither, and the mark
says so. A runaway point (:mod:`moreau.analysis.runaway`) gets the motion
``runaway`` and a ``RunawayError`` status.

Outputs: ``OUT/bifurcation_SCENE_P[_FREQ]_SCHEME.csv`` (one row per section
sample, units in the column names, the point's ``period``,
``lyapunov_per_period`` and ``status`` on each row), a JSON sidecar with the
marks and the provenance, and a figure: the chosen section quantities
against the parameter, the Lyapunov exponent below, the marks as lines.

Examples
--------
>>> d = bifurcation_diagram("stick-slip-motor", "load", [0.0, 0.05], frequency=1000.0,
...                         transient=10, samples=4, out=None, progress=False)
>>> [p["period"] for p in d["points"]], d["points"][0]["status"]
([1, 1], 'ok')
"""

import csv
import json
import math

import numpy as np

from .._validate import positive_int
from ..errors import InputError, MoreauError, RunawayError
from ..integrators.result import SimulationResult
from ..integrators.base import check_options, get_integrator, simulate
from ..integrators.base import scheme_options as options_of
from ..outputs import claim_outputs
from ..provenance import provenance
from ..regimes import Regime
from ..model import registry
from . import engine
from ._illinois import false_position, illinois_update
from ..integrators.event_driven_generic import project_positions
from .classify import MAX_PERIOD_K, sequence_period
from .engine import check_output_dir
from .period_k import full_state_of
from .periodic_shooting import free_bases, period_map_options, touching_contacts
from .runaway import certain_runaway, runaway_in
from .scheme_settings import make_scheme, steady_of
from .sweep import MAX_POINTS, plan_points

__all__ = ["bifurcation_diagram", "section_samples", "sequence_period", "classify_motion",
           "bifurcation_marks", "bifurcation_tag", "bifurcation_figure", "MAX_PERIOD_K",
           "refine_mark", "flip_scalar", "fold_scalar"]

TWO_PI = 2.0 * math.pi
#: separation of the Lyapunov companion, relative to the state's scale
LYAPUNOV_DELTA0 = 1e-7
#: a separation collapsed below this fraction of delta0 counts as this (a stick erased it)
LYAPUNOV_FLOOR = 1e-12
#: periods run from a shooting's orbit before sampling (to check it is an attractor)
ORBIT_SETTLE = 10
#: a Lyapunov exponent above this (per period) with no period found is called chaotic,
#: below minus this a contracting map still on its transient
LYAPUNOV_THRESHOLD = 1e-3
#: bound on transient + sampled periods of one point
MAX_PERIODS = 10**6


def bifurcation_tag(scene, parameter, frequency, scheme, options=None):
    """File stem of a bifurcation diagram: scene, parameter, fixed frequency, scheme and options.

    Examples
    --------
    >>> bifurcation_tag("friction-drive", "frequency", None, "event-driven")
    'bifurcation_friction-drive_frequency_event-driven'
    >>> bifurcation_tag("friction-drive", "phi0", 2000.0, "moreau-jean", {"h": 0.01})
    'bifurcation_friction-drive_phi0_2000Hz_moreau-jean_h0.01'
    """
    parts = [f"bifurcation_{scene}", parameter]
    if parameter != "frequency":
        parts.append(f"{frequency:g}Hz")
    parts.append(scheme)
    parts += [f"{k}{v:g}" if isinstance(v, float) else f"{k}{v}"
              for k, v in sorted((options or {}).items()) if k not in ("save_every", "sample_dt")]
    return "_".join(parts)


def _section_columns(scene, res, cyclic, disp):
    """The section state at the end of ``res`` as ``[(name, unit, value)]`` in SI."""
    out = []
    for name, unit, col in scene.si_columns(res):
        if name in ("t", "regime") or name.startswith("regime"):
            continue
        if cyclic is not None and name == f"q_{cyclic}":
            continue
        out.append((name, unit, float(np.asarray(col)[-1])))
    if cyclic is not None:
        to_si = getattr(scene, "displacement_to_si", None)
        # a scene without SI units keeps its own length unit
        out.append(("displacement_per_period", "m" if to_si else "1",
                    float(to_si(disp) if to_si else disp)))
    return out


def section_column_names(scene, cyclic):
    """The names of the section columns of ``scene`` (the ``--quantity`` choices), before a run.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> section_column_names(make_scene("stick-slip-motor"), 0)[-2:]
    ['gap_0', 'displacement_per_period']
    """
    q0, v0 = scene.initial_state()
    q0, v0 = np.asarray(q0, float), np.asarray(v0, float)
    nc = np.asarray(scene.contact_jacobians(q0, 0.0)[0]).shape[0]
    zeros = np.zeros((1, nc))
    # one sample at the start: si_columns names its columns from the shapes alone
    res = SimulationResult(t=np.zeros(1), q=q0[None, :], v=v0[None, :],
                           regime=zeros.astype(int), force_N=zeros, force_T=zeros,
                           slip_velocity=zeros, gap=zeros)
    return [name for name, _, _ in _section_columns(scene, res, cyclic, 0.0)]


def _one_period(scene, scheme, q, v, opts):
    res = simulate(scene, (0.0, TWO_PI), q, v, scheme, **opts)
    if not res.success:
        raise MoreauError(f"the period map failed ({scheme}): {res.message}")
    return res


def _tangent(scene, q, cyclic):
    """Basis (2 n, m) of the state changes that keep the touching contacts closed (first order)."""
    Bq, Bv = free_bases(scene, q, 0.0, cyclic, touching_contacts(scene, q, 0.0))
    n = q.size
    B = np.zeros((2 * n, Bq.shape[1] + Bv.shape[1]))
    B[:n, :Bq.shape[1]] = Bq
    B[n:, Bq.shape[1]:] = Bv
    return B


def _companion(scene, x, dz, B, cyclic):
    """``x`` moved by ``B dz``, its positions put back onto the touching contacts."""
    n = x.size // 2
    c = x + B @ dz
    touching = touching_contacts(scene, x[:n], 0.0)
    if touching.size:
        c[:n] = project_positions(scene, 0.0, c[:n], touching)
    if cyclic is not None:
        c[cyclic] = 0.0
    return c


def section_samples(scene, scheme, q, v, opts, transient, samples, cyclic, lyapunov,
                    progress_cb=None):
    """Run ``transient`` drive periods, then sample ``samples`` section states.

    Parameters
    ----------
    scene : Scene
        Driven with period ``2 pi`` in its time.
    scheme : str
        A registered scheme; ``opts`` its options (a time-stepping scheme's
        ``h`` must divide ``2 pi``).
    q, v : ndarray
        Start state at ``tau = 0``.
    cyclic : int or None
        The cyclic coordinate (its position is reset every period and
        reported as a displacement per period).
    lyapunov : bool
        Carry a companion along for the largest Lyapunov exponent (see the
        module docstring).

    Returns
    -------
    rows : list of list of (name, unit, value)
        One per sampled period: the SI section columns.
    q, v : ndarray
        The last section state.
    flight : bool
        The motion left contact during the last period.
    lyapunov : float
        Per drive period (NaN without ``lyapunov`` or without a free direction).
    bound : bool
        The exponent is an upper bound (a separation collapsed to rounding).
    """
    for _ in range(transient):
        res = _one_period(scene, scheme, q, v, opts)
        q, v = res.q[-1].copy(), res.v[-1].copy()
        if cyclic is not None:
            q[cyclic] = 0.0
    n = q.size
    rows = []
    flight = False
    lyap_sum = 0.0
    lyap_bound = False
    x = np.concatenate([q, v])
    free = np.ones(2 * n, dtype=bool)
    if cyclic is not None:
        free[cyclic] = False
    delta0 = LYAPUNOV_DELTA0 * max(float(np.max(np.abs(x[free]))), 1e-300)
    if lyapunov:
        B = _tangent(scene, q, cyclic)
        lyapunov = B.shape[1] > 0
    if lyapunov:
        # a fixed direction in the free coordinates, the same at every point of a sweep
        dz = np.ones(B.shape[1]) / math.sqrt(B.shape[1]) * delta0
        comp = _companion(scene, x, dz, B, cyclic)
    for _ in range(samples):
        res = _one_period(scene, scheme, q, v, opts)
        q1, v1 = res.q[-1].copy(), res.v[-1].copy()
        disp = q1[cyclic] - q[cyclic] if cyclic is not None else 0.0
        rows.append(_section_columns(scene, res, cyclic, disp))
        flight = bool(np.any(res.regime == int(Regime.FLIGHT)))
        if cyclic is not None:
            q1[cyclic] = 0.0
        if lyapunov:
            cres = _one_period(scene, scheme, comp[:n], comp[n:], opts)
            c1 = np.concatenate([cres.q[-1], cres.v[-1]])
            if cyclic is not None:
                c1[cyclic] = 0.0
            x1 = np.concatenate([q1, v1])
            B = _tangent(scene, q1, cyclic)
            dz = B.T @ (c1 - x1) if B.shape[1] else np.zeros(0)
            d = float(np.linalg.norm(dz))
            if d < LYAPUNOV_FLOOR * delta0:
                # a stick (or a closed contact) erased the separation in one period
                lyap_bound = True
                d = LYAPUNOV_FLOOR * delta0
                dz = np.ones(B.shape[1]) / math.sqrt(max(B.shape[1], 1)) * d
            lyap_sum += math.log(d / delta0)
            comp = _companion(scene, x1, dz * (delta0 / d), B, cyclic)
        q, v = q1, v1
        if progress_cb is not None:
            progress_cb()
    lyap = lyap_sum / samples if lyapunov else math.nan
    return rows, q, v, flight, lyap, lyap_bound


def bifurcation_diagram(scene, parameter, values, fixed=None, frequency=None,
                        scheme="event-driven", scheme_options=None, steps_per_period=None,
                        transient=200, samples=50, lyapunov=True, shoot=True, period_rtol=1e-6,
                        quantities=None, out="out", progress=True, plot=True, force=False,
                        log=print, refine=False):
    """Section samples of the long-run motion of ``scene`` against ``parameter``.

    Parameters
    ----------
    scene : str
        A registered scene with a periodic drive.
    parameter : str
        A numeric parameter of the scene, or ``"frequency"``; ``values`` in
        its SI unit, swept in the order given (the continuation follows it).
    fixed, frequency
        Other parameters (SI) and the drive frequency [Hz] when it is not swept.
    scheme : str
        Any registered scheme; ``steps_per_period`` (default 1000) sets the
        step of a time-stepping one; ``scheme_options`` its other options.
    transient, samples : int
        Periods run before sampling, and periods sampled.
    lyapunov : bool
        Estimate the largest Lyapunov exponent (doubles the cost).
    shoot : bool
        First look for a stable period-1 orbit
        (:func:`~moreau.analysis.steady_state.find_steady_state` by shooting;
        a period-k search costs minutes where it fails, the sampling finds
        period-k motion instead): where one is found, sampling starts on it after
        :data:`ORBIT_SETTLE` periods, which a slowly contracting map (the
        rotor's inertia: multipliers 0.98 .. 0.9997 above lift-off) would
        otherwise need thousands of transient periods to reach.
    period_rtol : float
        Tolerance of :func:`sequence_period`.
    quantities : list of str, optional
        Section columns drawn in the figure (default: the displacement per
        period and the first coordinate).
    out : path-like or None
        Output folder, checked writable before any work; None writes nothing.
    force : bool
        Replace the files of an earlier diagram with other settings.
    refine : bool
        With ``shoot``: locate every grazing, period doubling and period
        change between its grid neighbours by root finding on the
        period-1 orbit (:func:`refine_mark`), and name a saddle-node apart
        from other period changes. Off by default: up to
        :data:`REFINE_EVALS` shootings a mark, seconds each above lift-off.

    Returns
    -------
    dict
        ``points`` (one dict per value: ``value``, ``period``,
        ``lyapunov_per_period``, ``lyapunov_is_bound``, ``flight``,
        ``status``, ``samples`` as ``{column: list}``), ``marks``,
        ``columns`` (name -> unit) and ``parameter_column``.
    """
    transient = positive_int("transient", transient) if transient else 0
    samples = positive_int("samples", samples)
    if samples < 2:
        raise InputError(f"`samples` must be >= 2 (a period needs two samples), got {samples}")
    if (transient + samples) * (2 if lyapunov else 1) > MAX_PERIODS:
        raise InputError(f"`transient` + `samples` = {transient + samples} periods a point is "
                         f"more than the limit {MAX_PERIODS:.0e}")
    values = np.asarray(values, dtype=float).reshape(-1)
    if values.size > MAX_POINTS:
        raise InputError(f"{values.size} values are more than the limit {MAX_POINTS:.0e}")
    entry, columns, point, fixed_frequency = plan_points(scene, (parameter,), (values,), fixed,
                                                         frequency)
    first = point({parameter: values[0]})
    probe = registry.make_scene(entry.name, frequency=first[1], **first[0])
    cls = get_integrator(scheme)
    if hasattr(cls, "resolve"):
        cls = cls.resolve(probe)
    accepted = options_of(cls) or ()
    opts = dict(scheme_options or {})
    if steps_per_period is not None or "h" in accepted:
        opts["steps_per_period"] = 1000 if steps_per_period is None else steps_per_period
    opts = period_map_options(scheme, opts)
    if "h" in opts:
        # one sample a period: the section
        opts.setdefault("save_every", round(TWO_PI / opts["h"]))
    elif "sample_dt" in accepted:
        opts.setdefault("sample_dt", TWO_PI)
    check_options(scheme, opts, probe)
    steady_scheme = None
    if shoot:
        steady_scheme = make_scheme(
            scheme, steps_per_period=(round(TWO_PI / opts["h"]) if "h" in opts else None),
            options={k: v for k, v in opts.items() if k not in ("h", "save_every", "sample_dt")})
    cyc = tuple(getattr(probe, "cyclic_coordinates", ()))
    cyclic = cyc[0] if len(cyc) == 1 else None
    if quantities is not None:
        # the figure is drawn after all the work: a wrong name is refused before it
        known = section_column_names(probe, cyclic)
        unknown = [q for q in quantities if q not in known]
        if unknown:
            raise InputError(f"`quantities` (`--quantity`) must name section columns, one of "
                             f"{known}; got {unknown}")
    stem = settings = None
    if out is not None:
        out = check_output_dir(out)
        stem = out / bifurcation_tag(entry.name, parameter, fixed_frequency, scheme, opts)
        settings = claim_outputs(stem, {
            "scene": entry.name, "parameter": [parameter, values.tolist()],
            "frequency_Hz": fixed_frequency, "fixed": dict(fixed or {}), "scheme": scheme,
            "options": {k: v for k, v in opts.items()}, "transient": transient,
            "samples": samples, "lyapunov": bool(lyapunov)}, force)
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=values.size * samples, desc=f"bifurcation {parameter}", leave=False,
                   disable=None)
    points = []
    unit_of = {}
    state = None
    interrupted = False
    try:
        for val in values:
            params, f = point({parameter: val})
            rec = {"value": float(val), "period": 0, "motion": "", "lyapunov_per_period": math.nan,
                   "lyapunov_is_bound": False, "flight": False, "status": "ok",
                   "start": "continued" if state is not None else "rest", "samples": {}}
            try:
                sc = registry.make_scene(entry.name, frequency=f, **params)
                why = certain_runaway(sc)
                if why:
                    raise RunawayError(why)
                start, settle = state, transient
                if shoot:
                    orbit = _orbit(sc, steady_scheme)
                    if orbit is not None:
                        # a stable periodic orbit: its state needs no transient
                        start, settle = orbit, min(transient, ORBIT_SETTLE)
                        rec["start"] = "orbit"
                if start is None:
                    q0, v0 = (sc.rest_state() if hasattr(sc, "rest_state")
                              else sc.initial_state())
                    start = (np.array(q0, float), np.array(v0, float))
                rows, q, v, flight, lyap, bound = section_samples(
                    sc, scheme, start[0].copy(), start[1].copy(), opts, settle, samples,
                    cyclic, lyapunov, bar.update if bar is not None else None)
                state = (q, v)
                names = [name for name, _, _ in rows[0]]
                for name, unit, _ in rows[0]:
                    unit_of[name] = unit
                data = np.array([[x for _, _, x in r] for r in rows])
                rec["samples"] = {name: data[:, j].tolist() for j, name in enumerate(names)}
                k = sequence_period(data, period_rtol)
                rec.update(period=k, lyapunov_per_period=lyap, lyapunov_is_bound=bound,
                           flight=flight, motion=classify_motion(k, lyap))
                why = _runaway(sc, names, data) if cyclic is not None else None
                if why:
                    # the samples stay in the table; the next point starts afresh
                    rec.update(period=0, motion="runaway", status=f"RunawayError: {why}")
                    state = None
            except MoreauError as exc:
                rec["status"] = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
                if isinstance(exc, RunawayError):
                    rec["motion"] = "runaway"
                state = None
            points.append(rec)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if bar is not None:
            bar.close()
    marks = bifurcation_marks(points, parameter)
    if refine and steady_scheme is not None and not interrupted:
        shot = {}

        def orbit_at(val):
            # memoised: a grazing and a period change in one interval bisect the same orbits
            if val not in shot:
                p, f = point({parameter: val})
                try:
                    shot[val] = steady_of(registry.make_scene(entry.name, frequency=f, **p),
                                          steady_scheme)
                except MoreauError as exc:
                    shot[val] = exc
            if isinstance(shot[val], MoreauError):
                raise shot[val]
            return shot[val]
        marks = _merge_marks([refine_mark(m, orbit_at) if m["kind"] != "period halving" else m
                              for m in marks])
    result = {"points": points, "marks": marks, "columns": unit_of,
              "parameter_column": columns[parameter], "scene": entry.name, "scheme": scheme,
              "interrupted": interrupted}
    if interrupted and stem is not None:
        # never under the names of a finished diagram; no figure (work after the signal)
        stem, plot = stem.with_name(stem.name + ".partial"), False
    if stem is not None and points:
        _write(result, stem, entry, parameter, values, fixed_frequency, fixed, scheme, opts,
               transient, samples, settings, log)
        if plot:
            fig = stem.with_name(stem.name + ".png")
            bifurcation_figure(result, fig, quantities)
            log(f"wrote {fig}")
    if interrupted:
        raise KeyboardInterrupt(f"bifurcation: {len(points)} of {values.size} points finished"
                                + (f", kept in {stem}.csv" if stem is not None else ""))
    return result


def _runaway(scene, names, data):
    # the runaway detector on the sampled displacements per period, in scene units
    d = data[:, names.index("displacement_per_period")]
    to_si = getattr(scene, "displacement_to_si", None)
    return runaway_in(d / to_si(1.0) if to_si else d, scene)


def _merge_marks(marks):
    # one mechanism located once: a period change that a refinement found to be the lift-off
    # of the orbit, and the grazing mark of the same interval, are the same event
    out = []
    for m in marks:
        twin = next((o for o in out if o["kind"] == m["kind"] and "bracket" in o
                     and o.get("bracket") == m.get("bracket")), None)
        if twin is None:
            out.append(m)
        else:
            twin.setdefault("also", []).append({k: m[k] for k in ("from", "to") if k in m})
    return out


def _orbit(scene, steady_scheme):
    """``(q, v)`` of a stable periodic orbit at the section, or None."""
    try:
        ss = steady_of(scene, steady_scheme)
    except MoreauError:
        return None
    if getattr(ss, "floquet_multipliers", None) is not None and not ss.stable:
        return None
    q, v = full_state_of(scene, ss.state0)
    return np.array(q, float), np.array(v, float)


def classify_motion(period, lyapunov):
    """Name the long-run motion of a point from its period and Lyapunov exponent.

    Examples
    --------
    >>> classify_motion(2, -0.3), classify_motion(0, 0.05), classify_motion(0, -0.02)
    ('period-2', 'chaotic', 'converging')
    >>> classify_motion(0, float("nan"))
    'non-periodic'
    """
    if period:
        return f"period-{period}"
    if lyapunov > LYAPUNOV_THRESHOLD:
        return "chaotic"
    if lyapunov < -LYAPUNOV_THRESHOLD:
        # a contracting map whose samples still drift: the transient was too short
        return "converging"
    return "non-periodic"


def bifurcation_marks(points, parameter):
    """Period doublings, other period changes and grazings between neighbouring points.

    Examples
    --------
    >>> pts = [{"value": 1.0, "period": 1, "flight": False, "status": "ok"},
    ...        {"value": 2.0, "period": 2, "flight": True, "status": "ok"}]
    >>> [(m["kind"], m["from"], m["to"], m["at"]) for m in bifurcation_marks(pts, "a")]
    [('period doubling', 'period-1', 'period-2', 1.5), ('grazing', 'contact', 'flight', 1.5)]
    """
    marks = []
    for a, b in zip(points, points[1:]):
        if a["status"] != "ok" or b["status"] != "ok":
            continue
        where = {"between": [a["value"], b["value"]], "at": 0.5 * (a["value"] + b["value"]),
                 "parameter": parameter}
        ka, kb = a["period"], b["period"]
        if ka != kb:
            kind = ("period doubling" if ka and kb == 2 * ka else
                    "period halving" if kb and ka == 2 * kb else "period change")
            # the motions by name: a period of 0 is "no period", not a period
            marks.append({"kind": kind,
                          "from": a.get("motion") or classify_motion(ka, math.nan),
                          "to": b.get("motion") or classify_motion(kb, math.nan), **where})
        if a["flight"] != b["flight"]:
            marks.append({"kind": "grazing", "from": "flight" if a["flight"] else "contact",
                          "to": "flight" if b["flight"] else "contact", **where})
    return marks


#: a refined mark's bracket, relative to the grid interval it was found in
REFINE_XTOL = 1e-6
#: evaluations (orbits shot) a refinement may spend
REFINE_EVALS = 40


def _beyond(ss, side):
    """``lambda - side`` for the real Floquet multiplier of sign ``side`` (+1 or -1) farthest
    from 0 (NaN without one)."""
    m = ss.floquet_multipliers
    if m is None:
        return math.nan
    m = np.asarray(m, dtype=complex)
    r = m[np.abs(m.imag) <= 1e-9 * np.maximum(1.0, np.abs(m))].real
    r = r[side * r > 0]
    return side * float(np.max(side * r)) - side if r.size else math.nan


def flip_scalar(ss):
    """``lambda + 1`` for the most negative real Floquet multiplier of an orbit (NaN without one).

    It changes sign where the multiplier crosses -1: a period doubling.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> orbit = SimpleNamespace(floquet_multipliers=np.array([0.5, 0.3, -1.2]))
    >>> flip_scalar(orbit), fold_scalar(orbit)
    (-0.19999999999999996, -0.5)
    """
    return _beyond(ss, -1.0)


def fold_scalar(ss):
    """``lambda - 1`` for the largest positive real Floquet multiplier (NaN without one).

    It reaches 0 where the multiplier reaches +1: a saddle-node (fold), where
    the orbit meets another and both disappear. Example: :func:`flip_scalar`.
    """
    return _beyond(ss, 1.0)


def _try(orbit_at, v):
    try:
        return orbit_at(v)
    except MoreauError:
        return None


def _bisect(pred, a, b, pa, xtol, evals):
    # the last a with pred == pa and the first b without, to xtol (pred(b) != pa)
    n = 0
    while abs(b - a) > xtol and n < evals:
        m = 0.5 * (a + b)
        if pred(m) == pa:
            a = m
        else:
            b = m
        n += 1
    return a, b, n


def _brent(fun, a, b, fa, fb, xtol, evals):
    # Illinois regula falsi on a sign change of fun over [a, b]
    n, side = 0, 0
    while abs(b - a) > xtol and n < evals:
        c = false_position(a, b, fa, fb)
        fc = fun(c)
        n += 1
        if not math.isfinite(fc):
            return a, b, n, False
        if fc == 0.0:
            return c, c, n, True
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, c, fc, side, (fc > 0) == (fb > 0))
    return a, b, n, True


def refine_mark(mark, orbit_at, xtol=REFINE_XTOL, evals=REFINE_EVALS):
    """A mark located by root finding on the period-1 orbit between its grid neighbours.

    Parameters
    ----------
    mark : dict
        A mark of :func:`bifurcation_marks` (``kind``, ``between``, ``at``).
    orbit_at : callable
        ``orbit_at(value)``: the period-1 orbit (a SteadyState with its
        Floquet multipliers, stable or not) at a parameter value; raises
        :class:`~moreau.errors.MoreauError` where there is none.
    xtol : float
        Wanted bracket, relative to the grid interval.
    evals : int
        Orbits shot at most.

    Returns
    -------
    dict
        The mark with ``at`` the located point, ``bracket`` (the final
        interval), ``refined`` (the scalar whose sign change was followed,
        or why the midpoint stays), ``evaluations``; a period change whose
        period-1 orbit loses stability through +1, or ends, is renamed
        ``saddle-node``, one through -1 ``period doubling``.

    Notes
    -----
    * period doubling: ``flip_scalar`` (``lambda + 1``) changes sign between
      the neighbours; regula falsi on it;
    * saddle-node: ``fold_scalar`` (``lambda - 1``) changes sign; regula falsi;
    * grazing: bisection on whether the orbit has flight (``F`` in its mode);
    * the orbit exists on one side only: bisection on its existence (with
      the neighbour's flight flag), then at its last point the mechanism
      that ended it is named (``mechanism``): the minimum normal force down
      to :data:`END_FRACTION` of the neighbour's (grazing, lift-off) or
      ``|lambda - 1|`` down to that fraction (saddle-node); else the kind
      stays ``period change``, ``mechanism`` "not identified".
    """
    out = dict(mark)
    a, b = (float(x) for x in mark["between"])
    tol = xtol * abs(b - a)
    kind = mark["kind"]
    if kind == "grazing":
        def flies(v):
            ss = _try(orbit_at, v)
            return None if ss is None else "F" in ss.mode
        fa, fb = flies(a), flies(b)
        if (fa is None) != (fb is None) and not (fa or fb):
            # a contact orbit on one side only: it may end by lifting off
            end = _orbit_end(orbit_at, a, b, fa is not None, tol, evals)
            if end["kind"] == "grazing":
                out.update({k: v for k, v in end.items() if k != "kind"})
                return out
            out["refined"] = ("midpoint: the period-1 orbit in contact does not end by lift-off "
                              f"({end['refined']})")
            return out
        if fa is None or fb is None or fa == fb:
            out["refined"] = "midpoint: the period-1 orbits at the neighbours do not show the change"
            return out
        lo, hi, n = _bisect(flies, a, b, fa, tol, evals)
        out.update(at=0.5 * (lo + hi), bracket=[lo, hi], evaluations=n + 2,
                   refined="bisection on flight in the period-1 orbit")
        return out
    sa, sb = _try(orbit_at, a), _try(orbit_at, b)
    if sa is None and sb is None:
        out["refined"] = "midpoint: no period-1 orbit at either neighbour"
        return out
    if sa is not None and sb is not None:
        for scalar, name in ((flip_scalar, "period doubling"), (fold_scalar, "saddle-node")):
            fa, fb = scalar(sa), scalar(sb)
            if math.isfinite(fa) and math.isfinite(fb) and (fa > 0) != (fb > 0):
                lo, hi, n, ok = _brent(lambda v: scalar(orbit_at(v)), a, b, fa, fb, tol, evals)
                if ok:
                    out.update(kind=name, at=0.5 * (lo + hi), bracket=[lo, hi],
                               evaluations=n + 2,
                               refined=f"regula falsi on {scalar.__name__} "
                                       f"({'lambda + 1' if name == 'period doubling' else 'lambda - 1'})")
                    return out
        out["refined"] = "midpoint: no multiplier crosses the unit circle at a real +1 or -1"
        return out
    # the orbit exists on one side only: it ends by a fold (its multiplier reaches +1) or by
    # lift-off (its minimum normal force reaches 0); the end says which
    out.update(_orbit_end(orbit_at, a, b, sa is not None, tol, evals))
    return out


#: at the end of a period-1 orbit, its minimum normal force (or ``|lambda - 1|``) below this
#: fraction of its value at the grid neighbour names the mechanism
END_FRACTION = 0.05


def _orbit_end(orbit_at, a, b, exists_at_a, tol, evals):
    """Where a period-1 orbit seen at one neighbour only ends, and by which mechanism.

    Bisection on the existence of the orbit with the neighbour's flight flag
    (in contact, the sign of its minimum normal force), then at its last
    point the two quantities that can end it are read against their values
    at the neighbour: the minimum normal force reaching 0 is a grazing
    (lift-off), the largest real multiplier reaching +1 a saddle-node.
    """
    side = orbit_at(a if exists_at_a else b)
    flight = "F" in side.mode

    def holds(v):
        ss = _try(orbit_at, v)
        return ss is not None and ("F" in ss.mode) == flight

    lo, hi, n = _bisect(holds, a, b, exists_at_a, tol, evals)
    edge = orbit_at(lo if exists_at_a else hi)
    n0 = float(getattr(side, "min_normal_force", math.nan))
    n1 = float(getattr(edge, "min_normal_force", math.nan))
    f0, f1 = fold_scalar(side), fold_scalar(edge)
    g = n1 / n0 if n0 > 0.0 and math.isfinite(n0) and math.isfinite(n1) else math.nan
    f = abs(f1) / abs(f0) if math.isfinite(f0) and math.isfinite(f1) and f0 != 0.0 else math.nan
    lam = f"{1.0 + f1:.6g}" if math.isfinite(f1) else "none real positive"
    found = (f"the last orbit (at {(lo if exists_at_a else hi):.10g}) has its minimum normal "
             f"force at {g:.2g} of the neighbour's and its largest real multiplier {lam}")
    where = dict(at=0.5 * (lo + hi), bracket=[lo, hi], evaluations=n + 2)
    if not flight and g < END_FRACTION and not f < g:
        return dict(kind="grazing", **where, mechanism="lift-off: the minimum normal force of "
                    "the period-1 orbit reaches 0",
                    refined="bisection on the existence of the period-1 orbit in contact (the "
                            f"sign of its minimum normal force): {found}")
    if f < END_FRACTION:
        return dict(kind="saddle-node", **where, mechanism="fold: the largest multiplier of "
                    "the period-1 orbit reaches +1",
                    refined=f"bisection on the existence of the period-1 orbit: {found}")
    return dict(kind="period change", **where, mechanism="not identified",
                refined=f"bisection on the existence of the period-1 orbit; it ends with "
                        f"neither its normal force at 0 nor a multiplier at +1: {found}")


def _write(result, stem, entry, parameter, values, frequency, fixed, scheme, opts, transient,
           samples, settings, log):
    pcol = result["parameter_column"]
    names = list(result["columns"])
    header = [pcol, "sample"] + [f"{n} [{result['columns'][n]}]" for n in names] + [
        "period", "motion", "lyapunov_per_period", "lyapunov_is_bound", "flight", "start",
        "scheme", "status"]
    csv_path = stem.with_name(stem.name + ".csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for p in result["points"]:
            tail = [p["period"], p["motion"], p["lyapunov_per_period"], p["lyapunov_is_bound"],
                    p["flight"], p["start"], scheme, p["status"]]
            if not p["samples"]:
                w.writerow([p["value"], ""] + [""] * len(names) + tail)
                continue
            for j in range(len(next(iter(p["samples"].values())))):
                w.writerow([p["value"], j] + [p["samples"][n][j] for n in names] + tail)
    meta = {"scene": entry.name, "parameter": pcol, "values": values.tolist(),
            "frequency_Hz": frequency, "fixed_parameters": dict(fixed or {}),
            "scheme": scheme, "options": opts, "transient_periods": transient,
            "sampled_periods": samples, "section": "tau = 0 (mod 2 pi), after the transient",
            "continuation": "each point starts from the previous point's last section state",
            "marks": result["marks"], "interrupted": result["interrupted"],
            "partial": result["interrupted"],
            "lyapunov": {"delta0_relative": LYAPUNOV_DELTA0, "floor": LYAPUNOV_FLOOR,
                         "unit": "per drive period"},
            "motions": {str(p["value"]): p["motion"] for p in result["points"]},
            "provenance": provenance(engine.code_version()), "settings": settings}
    json_path = stem.with_name(stem.name + ".json")
    json_path.write_text(json.dumps(meta, indent=1, default=str))
    log(f"wrote {csv_path} ({len(result['points'])} points) and {json_path.name}")


def bifurcation_figure(result, path, quantities=None):
    """Section samples against the parameter, the Lyapunov exponent below, the marks as lines."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cols = result["columns"]
    if quantities is None:
        quantities = [n for n in ("displacement_per_period", "q_0") if n in cols][:2] or \
            list(cols)[:1]
    unknown = [q for q in quantities if q not in cols]
    if unknown:
        raise InputError(f"`quantities` must name section columns, one of {list(cols)}; got "
                         f"{unknown}")
    fig, axes = plt.subplots(len(quantities) + 1, 1, sharex=True,
                             figsize=(7.5, 2.3 * (len(quantities) + 1)))
    ok = [p for p in result["points"] if p["status"] == "ok"]
    for ax, name in zip(axes, quantities):
        for p in ok:
            ys = p["samples"][name]
            ax.plot([p["value"]] * len(ys), ys, ",", color="k", alpha=0.7)
            ax.plot([p["value"]] * len(ys), ys, ".", color="k", ms=1.5)
        ax.set_ylabel(f"{name} [{cols[name]}]")
    lx = [p["value"] for p in ok]
    ly = [p["lyapunov_per_period"] for p in ok]
    axes[-1].plot(lx, ly, "-o", ms=2, color="C3")
    axes[-1].axhline(0.0, color="0.5", lw=0.6)
    axes[-1].set_ylabel("Lyapunov exp.\n[per period]")
    axes[-1].set_xlabel(result["parameter_column"])
    styles = {"period doubling": ("C0", "--"), "period halving": ("C0", ":"),
              "period change": ("C1", "--"), "grazing": ("C2", "-."),
              "saddle-node": ("C4", "--")}
    seen = set()
    for m in result["marks"]:
        color, ls = styles[m["kind"]]
        for ax in axes:
            ax.axvline(m["at"], color=color, ls=ls, lw=0.8,
                       label=m["kind"] if (ax is axes[0] and m["kind"] not in seen) else None)
        seen.add(m["kind"])
    if seen:
        axes[0].legend(loc="best", fontsize=7)
    vals = [p["value"] for p in result["points"]]
    if len(vals) > 1 and min(vals) > 0 and max(vals) / min(vals) > 20:
        axes[-1].set_xscale("log")
    axes[0].set_title(f"{result['scene']}: section tau = 0 (mod 2 pi), {result['scheme']}",
                      fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
