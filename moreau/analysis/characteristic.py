"""The motor characteristic: mean rotor velocity, output power and efficiency against the load.

``moreau characteristic --scene NAME`` sweeps the load of a periodically
driven scene with a ``load`` parameter (the friction drive, the two-rod
drive, the stick–slip motor) from no load to beyond stall, each point a
periodic steady state under the chosen scheme, and gives what a motor
designer reads off the curve:

* the no-load velocity ``v0`` (the mean rotor velocity at ``F_L = 0``);
* the stall force: the load at which the mean velocity is zero, located by
  Brent's method on ``v(F_L)`` (bracketed by stepping the load along the
  secant of the curve), not read off the grid;
* the maximum mechanical output power ``P = F_L v`` and the load at which it
  occurs, refined by a bounded Brent minimisation around the best grid
  point.

Sign convention: the scenes' load ``F_L`` pushes the rotor towards ``-x``
(``J u2'' = f_T - f_L``), so a load opposes a forward motion when positive
and a backward one when negative; the power ``F_L v`` is positive when the
motor works against the load. Every force is reported signed in this
convention: at 185 Hz the paper's drive runs backwards and its stall force
is negative. Past the stall force the load reverses the motion (the rotor is
pushed back through the slipping contact); those rows say so in their
``motion`` column and the summary counts them. Further out the rotor runs
away (no steady state), which the rows report as their ``status``.

With an energy audit (:mod:`moreau.analysis.energy`) each row also has the
stators' input power and the efficiency ``P / P_in``, and the summary the
efficiency at the load of maximum output power.

Efficiency against frequency
  :func:`efficiency_vs_frequency` (``moreau characteristic
  --efficiency-vs-frequency F1 F2 ...``) traces the characteristic at each
  frequency and reports the efficiency at the load of maximum output power
  there (the operating point a designer sizes the motor for; at no load and
  at stall the output power, hence the efficiency, is zero): ``eta = F* v(F*)
  / P_in(F*)``, ``P_in`` the stators' mean input power from the energy audit.

Examples
--------
>>> ch = motor_characteristic("friction-drive", frequency=2000.0, points=5, out=None,
...                           plot=False)
>>> round(ch["summary"]["stall_force_N"], 6) > 0, ch["summary"]["no_load_velocity_m_per_s"] > 0
(True, True)
"""

import csv
import json
import math

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from ..outputs import write_csv
from .._validate import finite_scalar, positive, positive_int
from ..errors import ConvergenceError, InputError, MoreauError, RunawayError
from ..provenance import provenance
from ..model import registry
from .energy import energy_audit, energy_to_si, has_energy_audit
from .engine import audit_options, check_output_dir, periodic_scene_names
from .mj_steady_state import moreau_jean_steady_state
from .scheme_settings import ED_REFERENCE, steady_of
from .steady_state import implausible_steady_state

__all__ = ["motor_characteristic", "characteristic_tag", "efficiency_vs_frequency",
           "COLUMNS", "EFFICIENCY_COLUMNS", "MAX_POINTS"]

#: bound on the grid of one characteristic (each point a steady state)
MAX_POINTS = 10**4

#: the CSV columns (SI units in the names)
COLUMNS = ("load_N", "average_velocity_m_per_s", "output_power_W", "input_power_W",
           "efficiency", "motion", "mode", "status")

#: the CSV columns of the efficiency against frequency (one row a frequency, at the load of
#: maximum output power there)
EFFICIENCY_COLUMNS = ("frequency_Hz", "no_load_velocity_m_per_s", "stall_force_N",
                      "load_at_max_power_N", "max_power_W", "input_power_W", "efficiency",
                      "mode", "status")

#: first probe of the load, as a share of the scene's force unit
_FIRST_PROBE = 1e-3
#: load steps while bracketing the stall force, at most this factor at a time
_MAX_GROWTH = 4.0
_MAX_PROBES = 60
#: Newton and bracketing iterations of a Moreau–Jean steady state that failed with its default
_MJ_MAX_ITER = 300
#: a no-load mean velocity within this share of the stator's speed (the scene's
#: ``velocity_scale``) is no motion: 100 times the reference's shooting tolerance (1e-10
#: of that speed), far below any motor's (the two-rod drive's symmetric no-load
#: velocity is 5.8e-20 m/s, 2.5e-17 of it)
NO_MOTION_RTOL = 1e-8


def characteristic_tag(scene, frequency, scheme):
    """File stem of a characteristic: scene, frequency and the scheme's settings.

    Examples
    --------
    >>> characteristic_tag("friction-drive", 185.0, ED_REFERENCE)
    'characteristic_friction-drive_185Hz_event-driven'
    """
    return "_".join([f"characteristic_{scene}", f"{frequency:g}Hz", scheme.full_label])


class _Curve:
    """``v(F_L)`` of one scene and scheme, each load's steady state computed once."""

    def __init__(self, entry, frequency, fixed, scheme):
        self.entry, self.frequency, self.fixed, self.scheme = entry, frequency, fixed, scheme
        self.points = {}

    def scene(self, load):
        kw = dict(self.fixed, load=float(load))
        if self.frequency is not None:
            kw["frequency"] = self.frequency
        return registry.make_scene(self.entry.name, **kw)

    def at(self, load):
        """``(velocity [m/s] or None, status, scene, steady state or None)`` at ``load`` [N]."""
        load = float(load)
        if load not in self.points:
            sc = self.scene(load)
            try:
                ss = self._steady(sc)
                if not (ss.stats or {}).get("periodic", True):
                    raise MoreauError(ss.stats.get("message", "no period-1 orbit"))
                v = float(sc.displacement_to_si(ss.displacement_per_period)) / float(
                    sc.period * sc.time_unit_s)
                self.points[load] = (v, "ok", sc, ss)
            except MoreauError as exc:
                if isinstance(exc, InputError) and not self.points:
                    # the first point fails on the settings (a scheme that does not take
                    # the scene), not on its load: an input error, refused before more work
                    raise
                self.points[load] = (None, f"{type(exc).__name__}: {' '.join(str(exc).split())}",
                                     sc, None)
        return self.points[load]

    def _steady(self, sc):
        try:
            return steady_of(sc, self.scheme)
        except RunawayError:
            raise
        except ConvergenceError:
            if self.scheme.name != "moreau-jean":
                raise
        # near stall the discrete map's fixed point in u2' is found by bracketing, one
        # period map per step: give it the iterations it needs (65 at 185 Hz, N = 1000)
        kw = dict(self.scheme.options)
        if self.scheme.rtol is not None:
            kw["tol"] = self.scheme.rtol
        ss = moreau_jean_steady_state(sc, self.scheme.steps_per_period, self.scheme.theta,
                                      max_iter=_MJ_MAX_ITER, **kw)
        why = implausible_steady_state(sc, ss)
        if why:
            raise RunawayError(why)
        return ss

    def velocity(self, load):
        v, status, _, _ = self.at(load)
        if v is None:
            raise MoreauError(f"no steady state at load {load:.6g} N inside the stall bracket "
                              f"({status})")
        return v


def _stall(curve, v0, unit):
    """Signed stall force and how it was located: bracket the sign change of ``v(F)`` along
    the opposing load, then Brent (a linear interpolation where a load inside fails)."""
    s = math.copysign(1.0, v0)
    fa, va = 0.0, v0
    f = s * _FIRST_PROBE * unit
    bad = None
    for _ in range(_MAX_PROBES):
        v, status, _, _ = curve.at(f)
        if v is None:
            # past the reversal region already (a runaway): halve back towards the last good load
            bad = f
            f = 0.5 * (fa + bad)
            if abs(bad - fa) <= 1e-9 * abs(bad):
                raise MoreauError(f"no stall found: the steady state is lost at load {bad:.6g} N "
                                  f"({status}) while the motion has not reversed yet")
            continue
        if v * s <= 0.0:
            if v == 0.0:
                return f, "a grid probe with zero velocity"
            seen = [(fa, va), (f, v)]

            def velocity(x):
                out = curve.velocity(x)
                seen.append((x, out))
                return out

            try:
                root = brentq(velocity, fa, f, xtol=1e-12 * abs(f), rtol=1e-10, maxiter=100)
                return float(root), "Brent's method"
            except MoreauError as exc:
                # a load inside the bracket without a steady state: interpolate across the
                # tightest sign change the loads with one give
                lo = max((p for p in seen if p[1] * s > 0.0), key=lambda p: abs(p[0]))
                hi = min((p for p in seen if p[1] * s <= 0.0), key=lambda p: abs(p[0]))
                root = lo[0] - lo[1] * (hi[0] - lo[0]) / (hi[1] - lo[1])
                return float(root), (f"linear interpolation between the loads {lo[0]:.9g} and "
                                     f"{hi[0]:.9g} N (not refined: "
                                     f"{' '.join(str(exc).split())})")
        # the secant's zero, overshot by a tenth, at most _MAX_GROWTH times further out
        slope = (v - va) / (f - fa)
        target = abs(f) * _MAX_GROWTH
        if slope != 0.0 and (v / slope) * s > 0.0:
            target = min(target, 1.1 * abs(f - v / slope))
        fa, va = f, v
        f = s * max(target, 1.05 * abs(f))
        if bad is not None and abs(f) >= abs(bad):
            f = 0.5 * (fa + bad)
    raise MoreauError(f"no stall found within {_MAX_PROBES} loads up to {fa:.6g} N: the mean "
                      f"velocity keeps the no-load sign ({va:.6g} m/s there)")


def motor_characteristic(scene, frequency=None, fixed=None, scheme=ED_REFERENCE, points=41,
                         beyond=1.25, out="out", plot=True, log=print):
    """The load characteristic of the registered scene ``scene`` (module docstring).

    Parameters
    ----------
    scene : str
        A registered periodically driven scene with a ``load`` parameter.
    frequency : float, optional
        Drive frequency [Hz] (default: the scene's default).
    fixed : dict, optional
        Other parameters of the scene (SI); ``load`` is the swept one.
    scheme : moreau.analysis.engine.Scheme
        Event-driven reference (default) or any scheme with a steady state.
    points : int
        Loads on the grid, >= 3, from no load to ``beyond`` times the stall force.
    beyond : float
        The grid's end, as a multiple of the stall force, > 1.
    out : path-like or None
        Output folder (checked writable before any work); None writes nothing.
    plot : bool
        Write the figure (needs matplotlib).

    Returns
    -------
    dict
        ``summary`` (the ``--json`` output: ``stall_force_N``,
        ``no_load_velocity_m_per_s``, ``max_power_W``, ``load_at_max_power_N``,
        the reversal, the settings) and ``rows`` (the CSV).
    """
    entry = registry.get_entry(scene)
    if entry.name not in periodic_scene_names():
        raise InputError(f"`--scene` must be a periodically driven scene, one of "
                         f"{periodic_scene_names()}; got {scene!r}")
    names = entry.parameter_names()
    if "load" not in names:
        raise InputError(f"`--scene` {entry.name!r} has no `load` parameter to sweep")
    fixed = dict(fixed or {})
    if "load" in fixed:
        raise InputError("`load` is swept by the characteristic; do not fix it")
    if "frequency" in fixed:
        if frequency is not None:
            raise InputError("`frequency` is given twice (`--frequency` and `--set frequency=...`)")
        frequency = fixed.pop("frequency")
    if frequency is None:
        frequency = entry.defaults().get("frequency")
    if frequency is not None:
        frequency = positive("frequency", frequency)
    points = positive_int("points", points)
    if not 3 <= points <= MAX_POINTS:
        raise InputError(f"`--points` must be from 3 to {MAX_POINTS}, got {points}")
    beyond = finite_scalar("beyond", beyond)
    if not beyond > 1.0:
        raise InputError(f"`beyond` must be > 1 (the grid goes past the stall force), got {beyond!r}")
    curve = _Curve(entry, frequency, fixed, scheme)
    sc0 = curve.scene(0.0)   # the parameters make a valid scene before any work
    if out is not None:
        out = check_output_dir(out)

    rows = []
    try:
        try:
            v0, status, _, _ = curve.at(0.0)
        except InputError as exc:
            raise InputError(f"scheme {scheme.name!r} on scene {entry.name!r}: {exc}") from None
        if v0 is None:
            raise MoreauError(f"no steady state at no load: {status}")
        # the shooting's velocity scale (1 in the scene's units where it names none)
        vs = float(np.max(np.abs(getattr(sc0, "velocity_scale", 1.0))))
        still = NO_MOTION_RTOL * float(sc0.displacement_to_si(vs)) / float(sc0.time_unit_s)
        if abs(v0) <= still:
            raise MoreauError(f"the rotor does not move at no load: its mean velocity {v0:.3g} "
                              f"m/s is below {NO_MOTION_RTOL:g} of the velocity scale "
                              f"({still / NO_MOTION_RTOL:.3g} m/s), rounding; no characteristic "
                              "to trace")
        unit = float(sc0.force_to_si(1.0))
        stall, stall_by = _stall(curve, v0, unit)
        n_stall = len(curve.points)

        loads = np.linspace(0.0, beyond * stall, points)
        for f in loads:
            rows.append(_row(curve, f, v0, scheme))
        power = np.array([r["output_power_W"] if r["status"] == "ok" else -math.inf
                          for r in rows])
        i = int(np.argmax(power))
        lo, hi = loads[max(i - 1, 0)], loads[min(i + 1, points - 1)]
        lo, hi = sorted((lo, hi))
        refined = "Brent's method between the grid's neighbours of its best load"
        try:
            # the power curve is smooth near its maximum: Brent's bounded minimisation of -F v
            res = minimize_scalar(lambda f: -f * curve.velocity(f), bounds=(lo, hi),
                                  method="bounded", options={"xatol": 1e-10 * abs(stall)})
            f_best, p_best = (float(res.x), float(-res.fun)) if -res.fun >= power[i] else (
                float(loads[i]), float(power[i]))
        except MoreauError as exc:
            # a load without a steady state inside the bracket: the grid's best stands
            refined = (f"not refined (a load inside the bracket has no steady state: "
                       f"{' '.join(str(exc).split())}): the grid's best load")
            f_best, p_best = float(loads[i]), float(power[i])
        best = _row(curve, f_best, v0, scheme)
    except KeyboardInterrupt:
        if out is not None and curve.points:
            path = _write_partial(curve, out, entry, frequency, scheme)
            raise KeyboardInterrupt(f"characteristic: {len(curve.points)} loads finished, kept "
                                    f"in {path}") from None
        raise
    reversed_rows = [r for r in rows if r["motion"] == "reversed"]
    direction = "forward" if v0 > 0 else "backward"
    summary = {
        "scene": entry.name,
        "frequency_Hz": frequency,
        "scheme": scheme.name,
        "no_load_velocity_m_per_s": v0,
        "stall_force_N": stall,
        "max_power_W": p_best,
        "load_at_max_power_N": f_best,
        # NaN (None in JSON) without an energy audit for the scheme
        "input_power_at_max_power_W": _or_none(best["input_power_W"]),
        "efficiency_at_max_power": _or_none(best["efficiency"]),
        "mode_at_max_power": best["mode"],
        "no_load_direction": direction,
        "load_convention": ("a positive load pushes the rotor towards -x; a load opposing the "
                            f"no-load ({direction}) motion is {'positive' if v0 > 0 else 'negative'}"),
        "reverses_motion": bool(reversed_rows),
        "reversal": (f"loads beyond the stall force {stall:.6g} N reverse the motion: "
                     f"{len(reversed_rows)} of the {points} grid loads, e.g. {reversed_rows[-1]['load_N']:.6g} N "
                     f"moves the rotor at {reversed_rows[-1]['average_velocity_m_per_s']:.6g} m/s"
                     if reversed_rows else
                     "no grid load beyond the stall force has a steady state (the rotor runs away)"),
        "points": points,
        "failed_points": sum(r["status"] != "ok" for r in rows),
        "stall_located_by": stall_by,
        "max_power_located_by": refined,
        "steady_states_for_stall": n_stall,
        "parameters": {k: v for k, v in sc0.params.__dict__.items() if k != "load"}
        if hasattr(sc0, "params") else dict(fixed),
        "scheme_settings": {"theta": scheme.theta, "steps_per_period": scheme.steps_per_period,
                            "rtol": scheme.rtol, "options": scheme.options},
        "provenance": provenance(),
    }
    if summary["failed_points"]:
        summary["note"] = (f"{summary['failed_points']} of the {points} grid loads have no "
                           "steady state (their `status` in the table); the others are kept")
    if out is not None:
        _write_table(out / characteristic_tag(entry.name, frequency or 0.0, scheme), rows,
                     COLUMNS, summary, _load_panels if plot else None, log)
    return {"summary": summary, "rows": rows}


def _write_table(stem, rows, columns, summary, draw, log):
    # STEM.csv, its sidecar STEM.json (the summary) and, with `draw` (see _plot), STEM.png
    csv_path = stem.with_name(stem.name + ".csv")
    write_csv(csv_path, rows, columns)
    side = dict(summary, csv=csv_path.name)
    json_path = stem.with_name(stem.name + ".json")
    json_path.write_text(json.dumps(side, indent=1, default=str))
    log(f"wrote {csv_path} and {json_path.name}")
    if draw is not None:
        fig = stem.with_name(stem.name + ".png")
        if _plot(draw, rows, summary, fig):
            log(f"wrote {fig}")
        else:
            log("matplotlib is not installed: no figure (pip install matplotlib)")


def _or_none(x):
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else float(x)


def efficiency_vs_frequency(scene, frequencies, fixed=None, scheme=ED_REFERENCE, points=9,
                            out="out", plot=True, log=print):
    """Efficiency at the load of maximum output power against the drive frequency.

    At each frequency the load characteristic (:func:`motor_characteristic`)
    locates the stall force and the load ``F*`` of maximum output power; the
    row gives ``F*``, the power ``F* v(F*)``, the stators' mean input power
    ``P_in`` there from the energy audit and the efficiency ``F* v / P_in``
    (module docstring). A frequency without a characteristic (no steady
    state, no motion at no load, no stall) keeps its row with the cause in
    ``status``.

    Parameters
    ----------
    scene : str
        A registered periodically driven scene with a ``load`` parameter and
        an energy audit under ``scheme`` (the friction drive, the two-rod drive).
    frequencies : sequence of float
        Drive frequencies [Hz], each > 0, at most :data:`MAX_POINTS`.
    fixed : dict, optional
        Other parameters of the scene (SI).
    scheme : moreau.analysis.engine.Scheme
    points : int
        Grid loads of each characteristic (the maximum is refined by Brent's
        method from the grid's best point, so a coarse grid suffices).
    out : path-like or None
        Output folder for the CSV, its JSON sidecar and the figure; None
        writes nothing.
    plot : bool

    Returns
    -------
    dict
        ``summary`` (settings, the definition, the frequencies of the
        largest efficiency and power) and ``rows`` (:data:`EFFICIENCY_COLUMNS`).

    Examples
    --------
    >>> d = efficiency_vs_frequency("friction-drive", [2000.0], points=3, out=None, plot=False,
    ...                             log=lambda s: None)
    >>> 0.0 < d["rows"][0]["efficiency"] < 1.0
    True
    """
    entry = registry.get_entry(scene)
    try:
        freqs = [positive("frequencies", f) for f in frequencies]
    except TypeError:
        raise InputError(f"`frequencies` must be a sequence of frequencies [Hz], got "
                         f"{frequencies!r}") from None
    if not 1 <= len(freqs) <= MAX_POINTS:
        raise InputError(f"`frequencies` must hold 1 to {MAX_POINTS} values, got {len(freqs)}")
    fixed = dict(fixed or {})
    if "frequency" in fixed:
        raise InputError("`frequency` is swept by the efficiency against frequency; do not fix it")
    if "load" in fixed:
        raise InputError("`load` is chosen at each frequency (the load of maximum output "
                         "power); do not fix it")
    sc0 = registry.make_scene(entry.name, frequency=freqs[0],
                              **{k: v for k, v in fixed.items() if k != "load"})
    if not has_energy_audit(sc0, scheme.name):
        raise InputError(f"scene {entry.name!r} has no energy audit under scheme "
                         f"{scheme.name!r}: the input power, hence the efficiency, is unknown")
    points = positive_int("points", points)
    if not 3 <= points <= MAX_POINTS:
        raise InputError(f"`--points` must be from 3 to {MAX_POINTS}, got {points}")
    if out is not None:
        out = check_output_dir(out)
    rows = []
    for f in freqs:
        row = dict.fromkeys(EFFICIENCY_COLUMNS, math.nan)
        row.update(frequency_Hz=f, mode="", status="ok")
        try:
            s = motor_characteristic(entry.name, frequency=f, fixed=fixed, scheme=scheme,
                                     points=points, out=None, plot=False)["summary"]
        except InputError:
            # the settings, not the frequency (a scheme that does not take the scene)
            raise
        except KeyboardInterrupt:
            if out is None or not rows:
                raise
            stem = out / (f"efficiency_{entry.name}_{min(freqs):g}-{max(freqs):g}Hz_"
                          f"{scheme.full_label}.partial")
            csv_path = stem.with_name(stem.name + ".csv")
            write_csv(csv_path, rows, EFFICIENCY_COLUMNS)
            stem.with_name(stem.name + ".json").write_text(json.dumps(
                {"scene": entry.name, "scheme": scheme.name, "frequencies_Hz": freqs,
                 "partial": True, "frequencies_finished": len(rows), "csv": csv_path.name,
                 "provenance": provenance()}, indent=1, default=str))
            raise KeyboardInterrupt(f"efficiency against frequency: {len(rows)} of "
                                    f"{len(freqs)} frequencies finished, kept in "
                                    f"{csv_path}") from None
        except MoreauError as exc:
            row["status"] = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
            rows.append(row)
            log(f"  {f:g} Hz: {row['status']}")
            continue
        eff = s["efficiency_at_max_power"]
        row.update(no_load_velocity_m_per_s=s["no_load_velocity_m_per_s"],
                   stall_force_N=s["stall_force_N"], load_at_max_power_N=s["load_at_max_power_N"],
                   max_power_W=s["max_power_W"], mode=s["mode_at_max_power"],
                   input_power_W=(s["input_power_at_max_power_W"]
                                  if s["input_power_at_max_power_W"] is not None else math.nan),
                   efficiency=eff if eff is not None else math.nan)
        if eff is None:
            row["status"] = "no energy audit at the load of maximum power"
        rows.append(row)
        log(f"  {f:g} Hz: efficiency {row['efficiency']:.6g} at {row['load_at_max_power_N']:.6g} N")
    good = [r for r in rows if r["status"] == "ok"]
    best = max(good, key=lambda r: r["efficiency"]) if good else None
    summary = {
        "scene": entry.name,
        "scheme": scheme.name,
        "frequencies_Hz": freqs,
        "efficiency_definition": ("output power F* v(F*) over the stators' mean input power, at "
                                  "the load F* of maximum output power at each frequency"),
        "points_per_characteristic": points,
        "best_efficiency": best["efficiency"] if best else None,
        "frequency_of_best_efficiency_Hz": best["frequency_Hz"] if best else None,
        "failed_frequencies": [r["frequency_Hz"] for r in rows if r["status"] != "ok"],
        "provenance": provenance(),
        "parameters": {k: v for k, v in sc0.params.__dict__.items() if k != "load"}
        if hasattr(sc0, "params") else dict(fixed),
        "scheme_settings": {"theta": scheme.theta, "steps_per_period": scheme.steps_per_period,
                            "rtol": scheme.rtol, "options": scheme.options},
    }
    if out is not None:
        stem = out / f"efficiency_{entry.name}_{min(freqs):g}-{max(freqs):g}Hz_{scheme.full_label}"
        _write_table(stem, rows, EFFICIENCY_COLUMNS, summary, _efficiency_panels if plot else None,
                     log)
    return {"summary": summary, "rows": rows}


def _write_partial(curve, out, entry, frequency, scheme):
    """The loads an interrupted characteristic finished, as ``STEM.partial.csv`` (velocity
    and status only: the audit is work) with a sidecar saying ``partial: true``."""
    stem = out / (characteristic_tag(entry.name, frequency or 0.0, scheme) + ".partial")
    csv_path = stem.with_name(stem.name + ".csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(COLUMNS))
        w.writeheader()
        for load in sorted(curve.points):
            v, status, _, ss = curve.points[load]
            row = dict.fromkeys(COLUMNS, math.nan)
            row.update(load_N=load, motion="", mode=ss.mode if ss is not None else "",
                       status=status)
            if v is not None:
                row.update(average_velocity_m_per_s=v, output_power_W=load * v)
            w.writerow(row)
    stem.with_name(stem.name + ".json").write_text(json.dumps(
        {"scene": entry.name, "frequency_Hz": frequency, "scheme": scheme.name,
         "partial": True, "loads_finished": len(curve.points), "csv": csv_path.name,
         "provenance": provenance()}, indent=1, default=str))
    return csv_path


def _row(curve, load, v0, scheme):
    v, status, sc, ss = curve.at(load)
    row = dict.fromkeys(COLUMNS, math.nan)
    row.update(load_N=float(load), motion="", mode="", status=status)
    if v is None:
        return row
    row.update(average_velocity_m_per_s=v, output_power_W=float(load) * v, mode=ss.mode,
               motion="reversed" if v * v0 < 0.0 else ("stalled" if v == 0.0 else "driven"))
    if has_energy_audit(sc, scheme.name):
        try:
            audit = energy_to_si(sc, energy_audit(sc, ss, scheme.name, audit_options(scheme)))
        except MoreauError:
            return row
        p_in = audit["stator_work_J"] / float(sc.period * sc.time_unit_s)
        row.update(input_power_W=p_in, efficiency=row["output_power_W"] / p_in)
    return row


def _plot(draw, rows, summary, path):
    # two panels sharing x, drawn by `draw(ok_rows, summary, a1, a2)` and saved at `path`;
    # False without matplotlib
    try:
        import matplotlib  # noqa: PLC0415  (optional: figures only)
    except ImportError:
        return False
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    draw([r for r in rows if r["status"] == "ok"], summary, a1, a2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def _load_panels(ok, summary, a1, a2):
    f = np.array([r["load_N"] for r in ok]) * 1e3
    v = np.array([r["average_velocity_m_per_s"] for r in ok]) * 1e3
    p = np.array([r["output_power_W"] for r in ok]) * 1e6
    eff = np.array([r["efficiency"] for r in ok])
    a1.plot(f, v, "k.-", lw=0.8)
    a1.axhline(0.0, color="0.7", lw=0.5)
    a1.axvline(summary["stall_force_N"] * 1e3, color="C3", lw=0.8, ls="--",
               label=f"stall {summary['stall_force_N'] * 1e3:.4g} mN")
    a1.set_ylabel("mean rotor velocity [mm/s]")
    a1.legend(fontsize=8)
    a1.set_title(f"{summary['scene']} at {summary['frequency_Hz']:g} Hz ({summary['scheme']}): "
                 "load characteristic")
    a2.plot(f, p, "C0.-", lw=0.8, label="output power F_L v")
    a2.plot(summary["load_at_max_power_N"] * 1e3, summary["max_power_W"] * 1e6, "C3o",
            label=f"max {summary['max_power_W'] * 1e6:.4g} uW")
    a2.axhline(0.0, color="0.7", lw=0.5)
    a2.set_ylabel("output power [uW]")
    a2.set_xlabel("load F_L [mN] (positive pushes the rotor towards -x)")
    if np.any(np.isfinite(eff)):
        ax = a2.twinx()
        ax.plot(f, eff * 100, "C2--", lw=0.8, label="efficiency")
        ax.set_ylabel("efficiency [%]", color="C2")
    a2.legend(fontsize=8, loc="lower left")


def _efficiency_panels(ok, summary, a1, a2):
    f = np.array([r["frequency_Hz"] for r in ok])
    a1.plot(f, [100 * r["efficiency"] for r in ok], "C2o-", lw=0.8)
    a1.set_ylabel("efficiency at max. power [%]")
    eff = np.array([r["efficiency"] for r in ok])
    if eff.size and np.all(eff > 0) and eff.max() > 100 * eff.min():
        a1.set_yscale("log")    # 0.05 % to 45 % on the paper's drive, 20 Hz to 2 kHz
    a1.set_title(f"{summary['scene']} ({summary['scheme']}): efficiency at the load of "
                 "maximum output power", fontsize=10)
    a2.plot(f, [1e6 * r["max_power_W"] for r in ok], "C0o-", lw=0.8, label="max. output power")
    a2.plot(f, [1e6 * r["input_power_W"] for r in ok], "C3s--", lw=0.8, label="input power there")
    a2.set_ylabel("power [uW]")
    a2.set_xlabel("drive frequency [Hz]")
    if ok and min(min(r["max_power_W"], r["input_power_W"]) for r in ok) > 0:
        a2.set_yscale("log")    # the output is a small share of the input
    a2.legend(fontsize=8)
    for ax in (a1, a2):
        ax.set_xscale("log")
        ax.grid(True, which="both", lw=0.3, color="0.85")
