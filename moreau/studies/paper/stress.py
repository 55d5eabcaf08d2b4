"""Stiff and extreme cases of the friction drive: what each scheme does (``moreau compare --stress``).

Every case of :data:`CASES` is run with three schemes: the event-driven
reference (``"event-driven"``), Moreau–Jean with ``theta = 1`` (``"mj-1"``)
and with ``theta = 1/2`` (``"mj-1/2"``), both with position projection, the
package's default for the friction drive. Each run ends in one outcome:

``stable``
    a finite result within the stated bound ``bound`` of the reference
    (``error <= bound``);
``inaccurate``
    a finite result outside the bound. The scheme itself does not know, so
    the catalogue says it: the row gives the error and the scheme's own
    step-halving estimate ``estimate = 2 |d(N) - d(2N)|`` (same scale);
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

The 10^7-step case runs 10^7 steps in the command (``full=True``) and 10^6
in the quick catalogue that the tests run.

Examples
--------
>>> rep = run_catalogue(cases=["mu-zero"], progress=False)
>>> sorted({r["outcome"] for r in rep["rows"]})
['stable']
"""

import csv
import json
import math
import os
import time

import numpy as np

from ...analysis.compare import collect_rows
from ...analysis.mj_steady_state import moreau_jean_steady_state
from ...analysis.statistical import statistical_steady_state
from ...analysis.steady_state import find_steady_state
from ...errors import ConvergenceError, InputError, MoreauError
from ...integrators import simulate
from ...scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive
from .valid_range import phi0_valid_range

__all__ = ["CASES", "SCHEMES", "OUTCOMES", "BOUND", "run_case", "run_catalogue",
           "write_stress_outputs", "format_stress_table", "plot_stability_map"]

TWO_PI = 2.0 * math.pi
#: scheme keys, in the order of the map's columns
SCHEMES = ("event-driven", "mj-1", "mj-1/2")
_THETA = {"mj-1": 1.0, "mj-1/2": 0.5}
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


# -- steady-state cases -----------------------------------------------------------------------
def _steady_case(case, scene, steps=STEPS, bound=BOUND, note=""):
    """Event-driven steady state as reference; Moreau–Jean steady states at ``steps`` and 2x."""
    rows = []
    ref = {}

    def ed():
        ss = find_steady_state(scene, rtol=1e-12)
        ref.update(value=ss.displacement_per_period, mode=ss.mode)
        return _row(case, "event-driven", "stable", value=ss.displacement_per_period,
                    mode=ss.mode, message="reference (shooting rtol 1e-12)" + note)

    rows.append(_guard(case, "event-driven", ed))
    for scheme in ("mj-1", "mj-1/2"):
        theta = _THETA[scheme]

        def mj():
            ss = moreau_jean_steady_state(scene, steps, theta=theta)
            d = ss.displacement_per_period
            d2 = moreau_jean_steady_state(scene, 2 * steps, theta=theta).displacement_per_period
            est = 2.0 * abs(d - d2) / max(abs(d2), 0.01 * scene.u10)
            row = _row(case, scheme, "stable", value=d, mode=ss.mode, bound=bound, estimate=est)
            if not ref:
                # nothing to compare with: judge by the scheme's own estimate
                row.update(outcome="stable" if est <= bound else "inaccurate",
                           message=f"no reference; N = {steps}, step-halving estimate {est:.2g}")
                return row
            e = _err(d, ref["value"], scene)
            row.update(reference=ref["value"], error=e)
            msg = f"N = {steps}; error {e:.2g} (step-halving estimate {est:.2g})"
            if ss.mode != ref["mode"]:
                msg += f"; mode {ss.mode} instead of {ref['mode']}"
            if e > bound:
                row["outcome"] = "inaccurate"
            row["message"] = msg
            return row

        rows.append(_guard(case, scheme, mj))
    return rows


def _ill_posed_case(case, scene):
    """Beyond the Painlevé limit: every scheme must fail and name the cause."""
    def expect_failure(fn, scheme):
        def run():
            ss = fn()
            # a result here would be a false success
            return _row(case, scheme, "bug", value=ss.displacement_per_period, mode=ss.mode,
                        message="returned a steady state for an ill-posed problem")
        return run

    rows = [_guard(case, "event-driven",
                   expect_failure(lambda: find_steady_state(scene, rtol=1e-12), "event-driven"))]
    for scheme in ("mj-1", "mj-1/2"):
        th = _THETA[scheme]
        rows.append(_guard(case, scheme, expect_failure(
            lambda: moreau_jean_steady_state(scene, STEPS, theta=th), scheme)))
    return rows


# -- flight and impacts above the contact-loss limit ---------------------------------------
#: statistical steady states of the flight cases: (precision, budget in periods), full and quick
#: (the event-driven spin-up at e = 1 takes 14270 periods, the Moreau-Jean theta = 1/2 one 19660)
FLIGHT_STATISTICS = {True: (1e-2, 80000), False: (5e-2, 400)}


def _statistical_row(case, scheme, scene, note, full, run, **opts):
    """A flight case's statistical steady state from rest as a row (value = the mean)."""
    precision, budget = FLIGHT_STATISTICS[bool(full)]
    ss = statistical_steady_state(scene, run, precision=precision, max_periods=budget, **opts)
    lo, hi = ss.confidence_interval
    row = _row(case, scheme, "averaged", value=ss.displacement_per_period, mode=None,
               message=note + (f"statistical steady state: mean {ss.displacement_per_period:.5g} "
                               f"in [{lo:.5g}, {hi:.5g}] (95 %), {ss.periods_used} periods after "
                               f"a transient of {ss.stats['transient_periods']}"))
    row["interval"] = [lo, hi]
    return row


def _flight_case(case, scene, full, steps=2000, bound=0.05):
    """Above the contact-loss limit: the periodic steady state where one exists, else the
    statistical one (:mod:`moreau.analysis.statistical`), never a fixed window of a transient.

    The full catalogue asks for a 95 % interval within 1 % of the mean and allows 80000
    periods; the quick one 5 % and 400 periods, which the spin-up of the restitution cases
    outlasts: those rows fail with the budget-exhausted status.
    """
    ref = {}

    def ed():
        try:
            ss = find_steady_state(scene, rtol=1e-10, statistical=False)
            ref.update(value=ss.displacement_per_period, interval=None)
            return _row(case, "event-driven", "averaged", value=ss.displacement_per_period,
                        mode=ss.mode, message=f"periodic steady state {ss.mode}")
        except ConvergenceError as exc:
            note = f"no periodic steady state ({str(exc).split(':')[0]}); "
        row = _statistical_row(case, "event-driven", scene, note, full, "event-driven")
        ref.update(value=row["value"], interval=row["interval"])
        return row

    rows = [_guard(case, "event-driven", ed)]
    for scheme in ("mj-1", "mj-1/2"):
        th = _THETA[scheme]

        def mj():
            ss = None
            try:
                ss = moreau_jean_steady_state(scene, steps, theta=th)
                if not ss.stats.get("periodic", True):
                    note, ss = "no period-1 orbit of the Moreau–Jean map; ", None
            except ConvergenceError as exc:
                note = f"no periodic steady state ({str(exc).split(':')[0]}); "
            if ss is not None:
                row = _row(case, scheme, "averaged", value=ss.displacement_per_period,
                           mode=ss.mode, bound=bound, message=f"periodic steady state {ss.mode}")
            else:
                row = _statistical_row(case, scheme, scene, note, full, "moreau-jean",
                                       steps_per_period=steps, theta=th, projection=True)
                row["bound"] = bound
            if ref:
                e = _err(row["value"], ref["value"], scene)
                row.update(reference=ref["value"], error=e)
                if e > bound:
                    row["outcome"] = "inaccurate"
                msg = f"{'' if ss is None else '; '}N = {steps}; error {e:.2g} against the event-driven value"
                a, b = row.get("interval"), ref.get("interval")
                if a or b:
                    hw = sum((x[1] - x[0]) / 2.0 for x in (a, b) if x)
                    within = abs(row["value"] - ref["value"]) <= hw
                    msg += (f" ({'within' if within else 'outside'} the sum of the intervals' "
                            f"half-widths)")
                row["message"] += msg
            return row

        rows.append(_guard(case, scheme, mj))
    return rows


# -- long runs --------------------------------------------------------------------------------
def _energy(scene, q, v):
    # at tau = 2 pi k the stator is at rest (u1' = 0), so the energy is the rod's
    # kinetic and spring energy plus the rotor's kinetic energy
    return (v[:, 0] ** 2 / 6.0 + 0.5 * scene.P * (scene.sin_phi0 - np.sin(q[:, 0])) ** 2
            + 0.5 * scene.J * v[:, 1] ** 2)


def _long_case(case, scene, full, steps=1000, bound=1e-6):
    total = 10 ** 7 if full else 10 ** 6
    periods = total // steps
    rows = [_row(case, "event-driven", "n/a", time_s=0.0,
                 message="event-driven takes no time steps; its error does not grow with them")]
    for scheme in ("mj-1", "mj-1/2"):
        th = _THETA[scheme]

        def mj():
            ss = moreau_jean_steady_state(scene, steps, theta=th)
            x = ss.state0
            q0, v0 = np.array([x[0], 0.0]), np.array([x[1], x[2]])
            res = simulate(scene, (0.0, TWO_PI * periods), q0, v0, "moreau-jean",
                           h=TWO_PI / steps, theta=th, projection=True, save_every=steps)
            if res.status != 0:
                raise MoreauError(f"long run stopped: {res.message}")
            if res.stats["steps"] != total:
                raise MoreauError(f"long run took {res.stats['steps']} steps, not {total}")
            d = np.diff(res.q[:, 1])
            E = _energy(scene, res.q, res.v)
            drift = float(np.max(np.abs(d - ss.displacement_per_period))
                          / max(abs(ss.displacement_per_period), 0.01 * scene.u10))
            e_spread = float((E.max() - E.min()) / E.max())
            pen = float(res.stats.get("max_penetration", 0.0)) / scene.u10
            worst = max(drift, e_spread, pen)
            out = "stable" if worst <= bound else "inaccurate"
            return _row(case, scheme, out, value=float(d[-1]),
                        reference=ss.displacement_per_period, error=worst, bound=bound,
                        mode=ss.mode,
                        message=(f"{total:.0e} steps ({periods} periods, N = {steps}): "
                                 f"displacement per period drift {drift:.1e}, energy spread "
                                 f"at period starts {e_spread:.1e}, max penetration / u10 "
                                 f"{pen:.1e}"))

        rows.append(_guard(case, scheme, mj))
    return rows


# -- the catalogue ----------------------------------------------------------------------------
def _phi0_edges(frequency=185.0):
    r = phi0_valid_range(PAPER_DEFAULTS, frequency)
    return r["lift_off_edge"], r["painleve_edge"]


def _c(title, fn):
    return {"title": title, "run": fn}


#: case id -> {"title", "run": callable(case_id, full) -> rows}
CASES = {
    "stiff-1Hz-N50": _c("f = 1 Hz (P = 1.3e7), 50 steps per period",
                        lambda c, full: _steady_case(c, _scene(1.0), steps=50)),
    "stiff-1Hz-N1000": _c("f = 1 Hz, 1000 steps per period",
                          lambda c, full: _steady_case(c, _scene(1.0), steps=1000)),
    "stiff-1Hz-N1e5": _c("f = 1 Hz, 1e5 steps per period",
                         lambda c, full: _steady_case(c, _scene(1.0), steps=100000)),
    "flight-15kHz-e0": _c("f = 15 kHz (contact lost above 12.3 kHz), e = 0",
                          lambda c, full: _flight_case(c, _scene(15000.0, restitution=0.0), full)),
    "flight-15kHz-e0.5": _c("f = 15 kHz, e = 0.5",
                            lambda c, full: _flight_case(c, _scene(15000.0, restitution=0.5),
                                                         full)),
    "flight-15kHz-e1": _c("f = 15 kHz, e = 1",
                          lambda c, full: _flight_case(c, _scene(15000.0, restitution=1.0), full)),
    "painleve-mu0.9": _c("mu = 0.9 (Painlevé limit 1/tan(phi0) = 1)",
                         lambda c, full: _steady_case(c, _scene(mu=0.9))),
    "painleve-mu0.99": _c("mu = 0.99", lambda c, full: _steady_case(c, _scene(mu=0.99))),
    "painleve-mu0.999": _c("mu = 0.999", lambda c, full: _steady_case(c, _scene(mu=0.999))),
    "painleve-mu1.2": _c("mu = 1.2, beyond the limit (ill-posed)",
                         lambda c, full: _ill_posed_case(c, _scene(mu=1.2))),
    "mu-zero": _c("mu = 0 (no friction)", lambda c, full: _steady_case(c, _scene(mu=0.0))),
    "mass-ratio-1e-3": _c("m2/m = 1e-3", lambda c, full: _steady_case(c, _scene(m2=2e-8))),
    "mass-ratio-1e6": _c("m2/m = 1e6", lambda c, full: _steady_case(c, _scene(m2=20.0))),
    "phi0-lift-off-edge": _c("phi0 = lift-off edge + 1e-3",
                             lambda c, full: _steady_case(c, _scene(phi0=_phi0_edges()[0] + 1e-3))),
    "phi0-painleve-edge": _c("phi0 = Painlevé edge - 1e-3",
                             lambda c, full: _steady_case(c, _scene(phi0=_phi0_edges()[1] - 1e-3))),
    "coarse-N10": _c("10 steps per period (h = T/10)",
                     lambda c, full: _steady_case(c, _scene(), steps=10)),
    "long-1e7-steps": _c("10^7 steps at N = 1000 (10^6 in the quick catalogue)",
                         lambda c, full: _long_case(c, _scene(), full)),
}


def run_case(case, full=False):
    """Rows (one per scheme of :data:`SCHEMES`) of one case of :data:`CASES`.

    Examples
    --------
    >>> [r["outcome"] for r in run_case("painleve-mu1.2")]
    ['failed', 'failed', 'failed']
    """
    if case not in CASES:
        raise InputError(f"`case` must be one of {list(CASES)}, got {case!r}")
    rows = CASES[case]["run"](case, full)
    for r in rows:
        r["title"] = CASES[case]["title"]
    return rows


def run_catalogue(cases=None, full=False, progress=True, on_row=None):
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

    Returns
    -------
    dict
        ``rows`` (``case``, ``title``, ``scheme``, ``outcome``, ``value``,
        ``reference``, ``error``, ``bound``, ``estimate``, ``mode``,
        ``time_s``, ``message``), ``full`` and ``interrupted`` (an interrupted
        catalogue keeps the finished cases).
    """
    cases = list(CASES) if cases is None else list(cases)
    for c in cases:
        if c not in CASES:
            raise InputError(f"`cases` must hold keys of CASES ({list(CASES)}), got {c!r}")
    report = {"full": bool(full), "bound": BOUND, "rows": [], "interrupted": False}
    report["interrupted"] = collect_rows(cases, lambda c: run_case(c, full), report["rows"],
                                         on_row, progress, desc="stress catalogue", unit="case")
    return report


# -- output -----------------------------------------------------------------------------------
FIELDS = ("case", "scheme", "outcome", "value", "reference", "error", "bound", "estimate",
          "mode", "time_s", "message", "interval")


def write_stress_outputs(report, out, plot=True):
    """Write ``stress.csv``, ``stress.json`` and (with ``plot``) ``stress.png`` to ``out``."""
    paths = {}
    p = os.path.join(out, "stress.csv")
    with open(p, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        w.writerows(report["rows"])
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
    if r["outcome"] in ("stable", "inaccurate", "averaged") and r["error"] is not None:
        return f"{r['outcome']}\n{r['error']:.1e}"
    return r["outcome"]


def plot_stability_map(report, path):
    """The stability map: cases (rows) against schemes (columns), coloured by outcome."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    cases = list(dict.fromkeys(r["case"] for r in report["rows"]))
    names = list(OUTCOMES)
    grid = np.full((len(cases), len(SCHEMES)), names.index("n/a"))
    text = {}
    for r in report["rows"]:
        i, j = cases.index(r["case"]), SCHEMES.index(r["scheme"])
        grid[i, j] = names.index(r["outcome"])
        text[i, j] = _cell_text(r)
    fig, ax = plt.subplots(figsize=(7.5, 0.42 * len(cases) + 1.6))
    ax.imshow(grid, cmap=ListedColormap(list(OUTCOMES.values())), vmin=-0.5,
              vmax=len(names) - 0.5, aspect="auto")
    for (i, j), s in text.items():
        ax.text(j, i, s, ha="center", va="center", fontsize=6.5)
    ax.set_xticks(range(len(SCHEMES)), ["event-driven", "Moreau–Jean θ=1", "Moreau–Jean θ=1/2"],
                  fontsize=8)
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
    lines = [f"{'case':<20} {'scheme':<13} {'outcome':<10} {'error':>8} {'bound':>7} "
             f"{'estimate':>8} {'mode':<6} message"]

    def g(x):
        return f"{x:8.1e}" if x is not None else f"{'-':>8}"

    for r in report["rows"]:
        b = f"{r['bound']:7.0e}" if r["bound"] is not None else f"{'-':>7}"
        lines.append(f"{r['case']:<20} {r['scheme']:<13} {r['outcome']:<10} {g(r['error'])} {b} "
                     f"{g(r['estimate'])} {r['mode'] or '-':<6} {r['message']}")
    return "\n".join(lines)
