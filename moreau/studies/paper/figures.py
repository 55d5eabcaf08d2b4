"""Figures of the friction drive studies (matplotlib, Agg backend).

* :func:`sweep_figure`: displacement per period and average velocity against
  the swept parameter, operation modes as coloured bands, valid-range limits
  and the Moreau–Jean cross-check overlaid (the paper's Figs. 9–11).
* :func:`mode_figures`: one steady period of each of the paper's six
  operation modes, coloured by regime with the transitions marked (its
  Figs. 3–8).
* :func:`atlas_figure`: operation mode and displacement per period over a
  parameter plane, with the lift-off, Painlevé and contact-loss boundaries.
"""

import math
import pathlib

import numpy as np

from ...analysis.steady_state import find_steady_state
from ...analysis.sweep import stability_panel
from ...errors import MoreauError
from ...integrators import simulate
from ...regimes import REGIME_LETTERS
from ...scenes.friction_drive import FrictionDrive
from .tables import PARAM_COLUMNS, SWEPT_COLUMN

__all__ = ["MODE_COLORS", "REGIME_COLORS", "BAND_ALPHA", "EXTRA_COLORS", "mode_color", "sweep_figure",
           "draw_sweep", "zoom_side", "mode_figures", "draw_mode", "mode_points",
           "round_candidates", "steady_period", "atlas_figure", "save"]

#: the paper's six operation modes, in its order
PAPER_MODES = ("NS", "NSPS", "NPS", "NP", "NSP", "SP")
# NSPS in orange: its bands are narrow and sit between NS and NPS, so it must differ from both
MODE_COLORS = {"NS": "#4477aa", "NSPS": "#ee7733", "NPS": "#228833", "NP": "#ccbb44",
               "NSP": "#ee6677", "SP": "#aa3377"}
#: opacity of the operation-mode bands
BAND_ALPHA = 0.3
REGIME_COLORS = {"N": "#4477aa", "S": "#228833", "P": "#ee6677", "F": "#bbbbbb"}
# distinct from the six mode colours and from the grey/black/white of points without a mode,
# the most distinct first: flight and impact modes sit next to NP (e.g. NPF!P after NP)
#: colours of the modes other than the paper's six, in the order they are handed out
EXTRA_COLORS = ["#332288", "#009988", "#661100", "#33bbee", "#e69f00", "#882255", "#999933", "#cc79a7"]
_LETTER_NAME = {"N": "negative slip", "S": "stick", "P": "positive slip", "F": "flight"}


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def mode_color(mode, others=None):
    """Fixed colour of a paper mode; other modes (flight, impacts) cycle through extras."""
    if mode in MODE_COLORS:
        return MODE_COLORS[mode]
    if not mode:
        return "#000000"
    others = {} if others is None else others
    if mode not in others:
        others[mode] = EXTRA_COLORS[len(others) % len(EXTRA_COLORS)]
    return others[mode]


def save(fig, stem):
    """Save ``fig`` as ``stem.png`` and ``stem.svg``; return both paths."""
    stem = pathlib.Path(stem)
    # stem.name + suffix: with_suffix would cut a tag such as theta0.5_N400 at its dot
    paths = [stem.parent / (stem.name + ".png"), stem.parent / (stem.name + ".svg")]
    fig.savefig(paths[0], dpi=130)
    fig.savefig(paths[1])
    _plt().close(fig)
    return paths


def _runs(x, labels):
    """Contiguous runs of equal labels: ``(label, x_lo, x_hi)`` with edges halfway between points."""
    x = np.asarray(x, float)
    mid = np.concatenate([[x[0]], 0.5 * (x[1:] + x[:-1]), [x[-1]]])
    runs, start = [], 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            runs.append((labels[start], mid[start], mid[i]))
            start = i
    return runs


def _bands(ax, x, rows, others, log=False):
    labels = [r["mode"] if r["status"] == "ok" else "failed" for r in rows]
    if log:
        xl = np.log(np.asarray(x, float))
        runs = [(m, math.exp(a), math.exp(b)) for m, a, b in _runs(xl, labels)]
    else:
        runs = _runs(x, labels)
    seen = {}
    for m, a, b in runs:
        c = "#000000" if m == "failed" else mode_color(m, others)
        h = ax.axvspan(a, b, color=c, alpha=BAND_ALPHA if m != "failed" else 0.5, lw=0)
        seen.setdefault(m, h)
    return seen


_XLABEL = {"frequency": "drive frequency f [Hz]", "mu": "friction coefficient \u03bc [-]",
           "phi0": "initial tilt angle \u03c6\u2080 [rad]", "m": "rod mass m [kg]",
           "m2": "rotor mass m\u2082 [kg]", "k": "spring stiffness k [N/m]",
           "length": "rod length l [m]", "x10": "stator amplitude x\u2081\u2080 [m]",
           "load": "rotor load F_L [N]", "restitution": "restitution e [-]",
           "x10_a": "stator amplitude of rod a x\u2081\u2080\u1d43 [m]",
           "x10_b": "stator amplitude of rod b x\u2081\u2080\u1d47 [m]",
           "phase": "phase lag of stator b \u03b4 [rad]",
           "balance": "balance \u03b2 [-] (\u22121 rod a alone, +1 rod b alone)"}


def sweep_figure(rows, parameter, frequency, extra, stem, checks=(), title=None, log=None,
                 scheme_label="event-driven"):
    """Displacement per period and average velocity over a sweep (PNG + SVG).

    Draws with :func:`draw_sweep` (same arguments, ``stem`` aside) and saves
    ``stem.png`` and ``stem.svg``; returns both paths.
    """
    return save(draw_sweep(rows, parameter, frequency, extra, checks, title, log, scheme_label),
                 stem)


def draw_sweep(rows, parameter, frequency, extra, checks=(), title=None, log=None,
               scheme_label="event-driven"):
    """The figure of a sweep: displacement per period and average velocity, modes as bands.

    Scales follow the data so that a new reader can read them: a velocity
    that spans decades against a log frequency goes on a symmetric log scale
    with its minimum marked and a ``v`` proportional to ``f`` guide; values of
    one sign over a range where contact is lost (``inner_edges``) go on a log scale; a
    displacement whose smaller-signed side is flattened by the other gets an
    second panel that zooms on that side (:func:`zoom_side`).

    Parameters
    ----------
    rows : list of dict
        Tidy rows (see :func:`moreau.studies.paper.tables.tidy_rows`).
    parameter : str
    frequency : float or None
        Drive frequency of a mu/phi0 study (title only).
    extra : dict
        Valid-range limits to mark: ``lift_off_edge``, ``painleve_edge``,
        ``inner_edges``, ``contact_loss_Hz``.
    checks : tuple of Scheme
        Moreau–Jean cross-checks whose columns are overlaid.
    title : str, optional
    log : bool, optional
        Log-scaled x axis (default: for frequency sweeps over more than a decade).
    scheme_label : str
        Legend entry of the main curve (the scheme that computed it).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> rows = [{"mu": m, "displacement_per_period_m": 1e-6 * m, "average_velocity_m_per_s":
    ...          2e-3 * m, "mode": "NP", "status": "ok"} for m in (0.1, 0.2, 0.3)]
    >>> fig = draw_sweep(rows, "mu", 2000.0, {})
    >>> [ax.get_yscale() for ax in fig.axes[:2]]
    ['linear', 'linear']
    """
    plt = _plt()
    col = SWEPT_COLUMN.get(parameter, PARAM_COLUMNS.get(parameter, parameter))
    x = np.array([r[col] for r in rows], float)
    d = np.array([r["displacement_per_period_m"] for r in rows], float) * 1e6
    v = np.array([r["average_velocity_m_per_s"] for r in rows], float) * 1e3
    zoom = None if log else zoom_side(d)
    # a stability panel where the rows carry the orbits' multipliers (moreau sweep)
    mult = np.array([r.get("max_multiplier", np.nan) for r in rows], float)
    stab = bool(np.isfinite(mult).any())
    ratios = [1.0] + ([0.8] if zoom is not None else []) + [1.0] + ([0.7] if stab else [])
    fig, axes = plt.subplots(len(ratios), 1, figsize=(8, 2.2 + 2.0 * sum(ratios)),
                             sharex=True, gridspec_kw={"height_ratios": ratios})
    axes = list(axes)
    sax = axes.pop() if stab else None
    vax = axes[-1]
    others = {}
    if log is None:
        log = parameter == "frequency" and x.size > 1 and x.min() > 0 and x.max() / x.min() > 20
    handles, limit_h = {}, {}
    panels = [(axes[0], d, "displacement per period [\u00b5m]")]
    if zoom is not None:
        panels.append((axes[1], d, "displacement per period,\nzoom [\u00b5m]"))
    panels.append((vax, v, "average rotor velocity [mm/s]"))
    for ax, y, lab in panels:
        handles.update(_bands(ax, x, rows, others, log))
        # few points: show where they are
        ax.plot(x, y, "k.-" if x.size <= 40 else "k-", lw=1.3, label=scheme_label)
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3, lw=0.5)
        for chk, mk in zip(checks, ("o", "x")):
            c = f"{chk.label}_displacement_per_period_m"
            if rows and c in rows[0]:
                ym = np.array([r[c] for r in rows], float) * 1e6
                if ax is vax:
                    ym = ym * (x if parameter == "frequency" else frequency) * 1e-3
                ax.plot(x, ym, mk, ms=3.2, mfc="none", mew=0.8, alpha=0.8,
                        color="#cc3311" if chk.theta == 1.0 else "#0077bb",
                        label=f"Moreau\u2013Jean \u03b8 = {chk.theta:g} "
                              f"({chk.steps_per_period} steps/period)")
    if log:
        vax.set_xscale("log")
    _y_scales((axes[0], vax), x, d, v, log, bool(extra.get("inner_edges")))
    if zoom is not None:
        _zoom_panel(axes[1], x, d, zoom)
    limits = []
    if "lift_off_edge" in extra:
        limits.append((extra["lift_off_edge"], "lift-off edge", "--"))
    for e in extra.get("inner_edges", []):
        limits.append((e, "lift-off (contact lost)", ":"))
    if "painleve_edge" in extra:
        limits.append((extra["painleve_edge"], "Painlev\u00e9 edge", "-."))
    if "contact_loss_Hz" in extra:
        limits.append((extra["contact_loss_Hz"], "lift-off limit (max D = 0)", "--"))
    unit = {"frequency": " Hz", "phi0": " rad"}.get(parameter, "")
    lo, hi = (x.min(), x.max()) if x.size else (0, 1)
    if parameter == "phi0" and limits:
        # the valid range's edges are part of the picture
        lo, hi = min([lo] + [v for v, _, _ in limits]), max([hi] + [v for v, _, _ in limits])
        pad = 0.02 * (hi - lo)
        vax.set_xlim(lo - pad, hi + pad)
    span = hi - lo
    for xv, lab, ls in limits:
        if log or lo - 0.05 * span <= xv <= hi + 0.05 * span:
            for ax in axes:
                h = ax.axvline(xv, color="k", ls=ls, lw=1.1)
            limit_h[f"{lab} ({xv:.4g}{unit})"] = h
    if sax is not None:
        stability_panel(sax, x, rows)
        for xv, _, ls in limits:
            if log or lo - 0.05 * span <= xv <= hi + 0.05 * span:
                sax.axvline(xv, color="k", ls=ls, lw=1.1)
    (sax if sax is not None else vax).set_xlabel(
        _XLABEL.get(parameter, PARAM_COLUMNS.get(parameter, parameter)))
    lines, labels = axes[0].get_legend_handles_labels()
    axes[0].legend(lines + list(limit_h.values()), labels + list(limit_h), fontsize=7.5,
                   loc="best")
    mode_h, mode_l = list(handles.values()), list(handles)
    if any("!" in m or "F" in m for m in mode_l):
        # the letters of the flight and impact modes are not the paper's
        mode_h.append(plt.Line2D([], [], color="none"))
        mode_l.append("F: flight, !: contact entered by an impact")
    vax.legend(mode_h, mode_l, title="operation mode", fontsize=7.5,
                   ncol=min(4, len(mode_l)), loc="best", title_fontsize=8)
    if title is None:
        what = {"frequency": "drive frequency", "mu": "friction coefficient",
                "phi0": "initial tilt angle"}.get(parameter) or \
            _XLABEL.get(parameter, parameter).split(" [")[0]
        title = f"Friction drive: steady state against {what}"
        if parameter != "frequency" and frequency is not None:
            title += f" at f = {frequency:g} Hz"
    axes[0].set_title(title, fontsize=11)
    # fixed margins: tight_layout would cost one more full draw of a dense figure
    fig.subplots_adjust(left=0.125, right=0.98, top=0.95 if zoom is None else 0.96,
                        bottom=0.08 if zoom is None else 0.06, hspace=0.08)
    return fig


#: the smaller-signed side of a displacement gets an inset when its peak is below this
#: fraction of the other side's
INSET_FRACTION = 0.2


def _y_scales(axes, x, d, v, log, contact_lost):
    """Log or symmetric-log y scales where a linear one would hide part of the data."""
    ok = np.isfinite(d) & np.isfinite(v)
    if ok.sum() < 2:
        return
    for ax, y in ((axes[0], d[ok]), (axes[1], v[ok])):
        if contact_lost and np.all(y > 0):
            # past the contact loss flight and impacts multiply the displacement: on a
            # linear scale they would flatten the contact range
            ax.set_yscale("log")
    y = v[ok]
    big = float(np.abs(y).max())
    if log and np.any(y < 0) and np.any(y > 0) and big > 0:
        # against a log f the velocity spans decades (it grows like f): a symmetric log
        # scale shows the negative minimum and the slope-one growth together
        lin = 10.0 ** (math.floor(math.log10(big)) - 3)
        ax = axes[1]
        ax.set_yscale("symlog", linthresh=lin, linscale=0.5)
        i = int(np.argmin(y))
        xs = x[ok]
        ax.set_ylabel(f"average rotor velocity [mm/s]\n(symmetric log, linear within \u00b1{lin:g})",
                      fontsize=9)
        ax.annotate(f"minimum {y[i]:.3g} mm/s at {xs[i]:.4g} Hz", (xs[i], y[i]),
                    xytext=(14, 8), textcoords="offset points", fontsize=7.5, va="bottom",
                    arrowprops=dict(arrowstyle="-", lw=0.6))
        ax.plot(xs[i], y[i], "v", color="k", ms=5)
        if y[-1] > 0:
            # a guide of slope one over the last decade and a half, set above the curve so
            # that both stay visible
            f_ref = np.geomspace(xs[-1] / 30.0, xs[-1], 20)
            ax.plot(f_ref, 4.0 * y[-1] * f_ref / xs[-1], ls=(0, (4, 3)), color="0.3", lw=1.0)
            ax.annotate("slope one: v \u221d f", (f_ref[0], 4.0 * y[-1] * f_ref[0] / xs[-1]),
                        xytext=(-4, 0), textcoords="offset points", fontsize=7.5, ha="right",
                        va="center", color="0.3")


def zoom_side(d):
    """The sign (-1 or +1) of the side of zero that the other side's range flattens, or None.

    A displacement with values of both signs whose smaller-signed peak is
    below :data:`INSET_FRACTION` of the other's gets a second panel on that
    side (the 185 Hz phi0 sweep: -6.8 um before a rise to +88 um).

    Examples
    --------
    >>> zoom_side([-6.8, -3.0, 10.0, 88.0]), zoom_side([-6.8, 1.9]), zoom_side([1.0, 90.0])
    (-1, None, None)
    """
    d = np.asarray(d, float)
    d = d[np.isfinite(d)]
    if d.size < 3 or not (np.any(d < 0) and np.any(d > 0)):
        return None
    neg, pos = -float(d.min()), float(d.max())
    if min(neg, pos) >= INSET_FRACTION * max(neg, pos):
        return None
    return -1 if neg < pos else 1


def _zoom_panel(ax, x, d, small):
    """Limit ``ax`` to the ``small``-signed side of the displacement and mark its sign changes."""
    ok = np.isfinite(d)
    xs, ds = x[ok], d[ok]
    peak = float(np.abs(ds[small * ds > 0]).max())
    ax.set_ylim(*sorted((small * 1.25 * peak, -small * 0.6 * peak)))
    for k in np.flatnonzero(np.sign(ds[1:]) * np.sign(ds[:-1]) < 0):
        xc = xs[k] - ds[k] * (xs[k + 1] - xs[k]) / (ds[k + 1] - ds[k])
        ax.plot(xc, 0.0, "o", mfc="white", mec="k", ms=5, zorder=6)
        # below and right of a rising crossing (above for a falling one): off the curve
        ax.annotate(f"sign change near {xc:.4g}", (xc, 0.0), xytext=(9, small * 9),
                    textcoords="offset points", fontsize=7.5,
                    va="top" if small < 0 else "bottom")
    i = int(np.argmax(small * ds))
    ax.annotate(f"{'minimum' if small < 0 else 'maximum'} {ds[i]:.3g} \u00b5m", (xs[i], ds[i]),
                xytext=(0, small * 10), textcoords="offset points", fontsize=7.5, ha="center",
                va="bottom" if small > 0 else "top")


def steady_period(params, frequency, samples=1200):
    """One steady period (event-driven) starting at the Poincaré section.

    Returns ``(ss, res)``: the :class:`SteadyState` and the
    :class:`SimulationResult` of that period.
    """
    scene = FrictionDrive(params, frequency)
    ss = find_steady_state(scene, statistical=False)
    phi, dphi, du2 = ss.state0
    t0 = ss.section_tau
    res = simulate(scene, (t0, t0 + 2 * math.pi), [phi, 0.0], [dphi, du2], "event-driven",
                   samples_per_period=samples)
    return ss, res


#: where the paper's figures show each mode (study, value); used when the data agree
PREFERRED_POINTS = {"NS": ("frequency", 20.0), "NSPS": ("frequency", 158.0),
                    "NPS": ("frequency", 170.0), "NP": ("frequency", 185.0),
                    "NSP": ("mu_2000Hz", 0.92), "SP": ("mu_2000Hz", 0.98)}


def _mode_points(results):
    """A parameter point for each paper mode: the paper's point where the data show that
    mode there, else the middle of the mode's widest run in the studies.

    Returns ``{mode: (run length, parameter, value, row, lo, hi, preferred)}``: ``lo`` and
    ``hi`` are the nearest grid values outside the run, ``preferred`` the paper's value or
    None.
    """
    best = {}
    for mode, (name, value) in PREFERRED_POINTS.items():
        rows = results.get(name) or []
        if not rows:
            continue
        parameter = name.split("_")[0]
        col = SWEPT_COLUMN[parameter]
        r = min(rows, key=lambda r: abs(r[col] - value))
        if r["status"] == "ok" and r["mode"] == mode and abs(r[col] / value - 1) < 0.05:
            best[mode] = (math.inf, parameter, r[col], r, value / 1.05, value * 1.05, value)
    for name, rows in results.items():
        if name.startswith("_") or not rows:
            continue
        parameter = name.split("_")[0]
        col = SWEPT_COLUMN[parameter]
        labels = [r["mode"] if r["status"] == "ok" else "" for r in rows]
        start = 0
        for i in range(1, len(rows) + 1):
            if i == len(rows) or labels[i] != labels[start]:
                m = labels[start]
                if m in PAPER_MODES and (m not in best or i - start > best[m][0]):
                    mid = rows[(start + i - 1) // 2]
                    lo = rows[max(start - 1, 0)][col]
                    hi = rows[min(i, len(rows) - 1)][col]
                    best[m] = (i - start, parameter, mid[col], mid, lo, hi, None)
                start = i
    return best


def round_candidates(value, lo, hi, digits=4):
    """``value`` rounded to 1, 2, ... ``digits`` significant figures, those strictly in
    ``(lo, hi)``, without repeats.

    Examples
    --------
    >>> round_candidates(19.8837, 10.0, 156.3)
    [20.0, 19.9, 19.88]
    >>> round_candidates(158.6, 156.3, 160.9)
    [160.0, 159.0, 158.6]
    """
    out = []
    for n in range(1, digits + 1):
        c = float(f"{value:.{n}g}")
        if lo < c < hi and c not in out:
            out.append(c)
    return out


def mode_points(results, params):
    """Where each of the paper's modes is drawn: ``{mode: (params, frequency_Hz)}``.

    The point of :func:`_mode_points` moved to a round value of its swept
    parameter (the paper's value, else the fewest significant figures inside
    the mode's run) where the steady state is in that mode; the grid value
    where no round value is.
    """
    out = {}
    picks = _mode_points(results)
    for mode in PAPER_MODES:
        if mode not in picks:
            continue
        _, parameter, value, row, lo, hi, preferred = picks[mode]
        base = params.with_(mu=row["mu"], phi0=row["phi0_rad"])
        cands = ([preferred] if preferred is not None else []) + round_candidates(value, lo, hi)
        chosen = (base, row["frequency_Hz"])
        for c in cands:
            p, f = (base, c) if parameter == "frequency" else \
                (base.with_(**{parameter: c}), row["frequency_Hz"])
            try:
                if find_steady_state(FrictionDrive(p, f)).mode == mode:
                    chosen = (p, f)
                    break
            except MoreauError:
                continue
        out[mode] = chosen
    return out


def mode_figure_jobs(results, params, folder, points=None):
    """``[(function, args), ...]`` drawing the six operation modes (the paper's Figs. 3–8)
    at the points of :func:`mode_points` (computed unless given)."""
    points = mode_points(results, params) if points is None else points
    return [(mode_figure, (mode, p, f, folder)) for mode, (p, f) in points.items()]


def mode_figures(results, params, folder):
    """Draw the six operation modes; return the written paths."""
    return [path for fn, args in mode_figure_jobs(results, params, folder) for path in fn(*args)]


def mode_figure(mode, p, f, folder):
    """One steady period in ``mode`` at parameters ``p`` and frequency ``f`` (PNG + SVG)."""
    return save(draw_mode(mode, p, f), pathlib.Path(folder) / f"mode_{mode}")


#: regime segments shorter than this fraction of the period get a marker (else invisible)
SHORT_SEGMENT = 0.03
#: transitions closer than this (in tau) share one label, e.g. N\u2192S\u2192P
_CLUSTER_TAU = 0.35


def _clusters(events, t0):
    """Transitions within a period grouped where they follow each other closely:
    ``[(first tau, last tau, "N\u2192S\u2192P"), ...]``."""
    groups = []
    for e in events:
        te = e.t - t0
        if not 0.0 < te < 2 * math.pi:
            continue
        if groups and te - groups[-1][1] < _CLUSTER_TAU and groups[-1][2][-1] == \
                REGIME_LETTERS[e.before]:
            groups[-1][1] = te
            groups[-1][2].append(REGIME_LETTERS[e.after])
        else:
            groups.append([te, te, [REGIME_LETTERS[e.before], REGIME_LETTERS[e.after]]])
    return [(a, b, "\u2192".join(chain)) for a, b, chain in groups]


def draw_mode(mode, p, f):
    """The figure of one steady period: rotor displacement and slip velocity by regime.

    Transitions that follow each other closely share one label (``N\u2192S\u2192P``), and a
    regime that lasts less than :data:`SHORT_SEGMENT` of the period is marked
    with a dot, so that a short stick stays visible.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> fig = draw_mode("NS", PAPER_DEFAULTS, 20.0)
    >>> bool(fig.axes[0].get_xlim()[1] == 2 * math.pi)
    True
    """
    plt = _plt()
    ss, res = steady_period(p, f)
    tau = res.t - res.t[0]
    u2 = res.q[:, 1] - res.q[0, 1]
    vt = res.slip_velocity[:, 0]
    letters = np.array([REGIME_LETTERS[int(c)] for c in res.regime[:, 0]])
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.0), layout="constrained")
    clusters = _clusters(res.events, res.t[0])
    for ax, y, lab in ((axes[0], u2, "rotor displacement u\u2082 \u2212 u\u2082(0) [-]"),
                       (axes[1], vt, "tangential contact velocity d\u03b4_T/d\u03c4 [-]")):
        ax.plot(tau, y, color="0.75", lw=0.8, zorder=1)
        start = 0
        used = set()
        for i in range(1, len(tau) + 1):
            if i == len(tau) or letters[i] != letters[start]:
                L = letters[start]
                sl = slice(start, min(i + 1, len(tau)))
                ax.plot(tau[sl], y[sl], color=REGIME_COLORS[L], lw=2.2, zorder=2,
                        label=None if L in used else _LETTER_NAME[L])
                # a regime too short to see as a line: a dot at its middle
                if 0 < start and i < len(tau) and tau[i] - tau[start] < SHORT_SEGMENT * 2 * math.pi:
                    k = (start + i) // 2
                    ax.plot(tau[k], y[k], "o", ms=7, mfc=REGIME_COLORS[L], mec="k", mew=0.8,
                            zorder=4)
                used.add(L)
                start = i
        for e in res.events:
            if 0.0 < e.t - res.t[0] < 2 * math.pi:
                ax.axvline(e.t - res.t[0], color="k", ls=":", lw=0.9, zorder=0)
        for a, b, text in clusters:
            ax.annotate(text, (0.5 * (a + b), 1.0), xycoords=("data", "axes fraction"),
                        xytext=(0, 2), textcoords="offset points", fontsize=7.5,
                        ha="center", va="bottom")
        ax.set_xlabel("non-dimensional time \u03c4 \u2212 \u03c4\u2080 [-]")
        ax.set_ylabel(lab)
        ax.set_xlim(0, 2 * math.pi)
        ax.grid(alpha=0.3, lw=0.5)
    axes[1].axhline(0.0, color="0.5", lw=0.6)
    axes[0].legend(title="regime", fontsize=8, title_fontsize=8)
    fig.suptitle(f"Operation mode {mode}: one steady period at f = {f:g} Hz, "
                 f"\u03bc = {p.mu:.3g}, \u03c6\u2080 = {p.phi0:.4g} rad "
                 f"(\u03c4\u2080 = {ss.section_tau:.3f})", fontsize=10.5)
    return fig


#: colours of atlas points without a steady mode
_NO_MODE_COLORS = {"no contact": "#f4f4f4", "ill-posed (Painlev\u00e9)": "#777777",
                   "failed": "#000000"}


def atlas_figure(atlas, stem):
    """Mode map and displacement heat map over one parameter plane (PNG + SVG).

    ``atlas`` is a dict from :func:`moreau.studies.paper.atlas.compute_atlas`.
    """
    from matplotlib.colors import ListedColormap, TwoSlopeNorm
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    plt = _plt()
    f = np.asarray(atlas["frequency_Hz"])
    y = np.asarray(atlas["y"])
    labels = np.asarray(atlas["label"], dtype=object)
    present = set(labels.ravel())
    names = [m for m in PAPER_MODES if m in present]
    names += sorted(m for m in present if m not in names and m not in _NO_MODE_COLORS)
    names += [m for m in _NO_MODE_COLORS if m in present]
    others = {}
    colors = [_NO_MODE_COLORS.get(m) or mode_color(m, others) for m in names]
    code = np.zeros(labels.shape)
    for i, m in enumerate(names):
        code[labels == m] = i
    fig, axes = plt.subplots(1, 2, figsize=(14, 5.6))
    ax = axes[0]
    ax.pcolormesh(f, y, code.T, cmap=ListedColormap(colors), vmin=-0.5,
                  vmax=len(names) - 0.5, shading="nearest", rasterized=True)
    handles = [Patch(facecolor=c, edgecolor="0.6", lw=0.5, label=m) for m, c in zip(names, colors)]
    d = np.asarray(atlas["displacement_per_period_m"], float) * 1e6
    ax2 = axes[1]
    # a robust colour range: a few extreme points must not wash out the rest of the plane
    lim = float(np.nanpercentile(np.abs(d), 99.5)) if np.any(np.isfinite(d)) else 1.0
    lim = lim if lim > 0 else 1.0
    pc = ax2.pcolormesh(f, y, np.ma.masked_invalid(d).T, cmap="RdBu_r",
                        norm=TwoSlopeNorm(0.0, -lim, lim), shading="nearest", rasterized=True)
    ax2.set_facecolor("#dddddd")
    fig.colorbar(pc, ax=ax2, extend="both" if np.nanmax(np.abs(d), initial=0) > lim else "neither",
                 label="displacement per period [\u00b5m] (grey: no steady mode)")
    lines = []
    for a in axes:
        for key, style, lab in (("lift_off", dict(colors="k", linestyles="--"),
                                 "lift-off: min f_N = 0 (max D = 0)"),
                                ("painleve", dict(colors="k", linestyles="-."),
                                 "Painlev\u00e9: 1 \u2212 \u03bc tan \u03c6\u2080 = 0"),
                                ("contact_loss", dict(colors="#d62728", linestyles="-"),
                                 "contact loss (flight in the steady state)")):
            field = np.asarray(atlas[key + "_field"], float)
            if np.any(np.isfinite(field)) and np.nanmin(field) < 0 < np.nanmax(field) \
                    and min(field.shape) > 1:
                a.contour(f, y, field.T, levels=[0.0], linewidths=1.6, **style)
                if a is axes[0]:
                    lines.append(Line2D([], [], color=style["colors"], ls=style["linestyles"],
                                        label=lab, lw=1.6))
            elif a is axes[0] and key != "contact_loss":
                # say so rather than leave the reader looking for the curve
                vals = field[np.isfinite(field)]
                if key == "lift_off" and np.all(vals < 0):
                    lines.append(Line2D([], [], color="none",
                                        label="no lift-off in this plane (max D < 0 everywhere)"))
                if key == "painleve" and np.all(vals > 0):
                    lines.append(Line2D([], [], color="none",
                                        label="Painlev\u00e9 condition holds everywhere here"))
        a.set_xscale("log")
        a.set_xlabel("drive frequency f [Hz]")
        a.set_ylabel(atlas["y_label"])
    axes[0].set_title(f"Operation mode over (f, {atlas['y_name']})", fontsize=11)
    axes[1].set_title(f"Displacement per period over (f, {atlas['y_name']})", fontsize=11)
    fig.legend(handles=handles + lines, fontsize=8, loc="lower center",
               ncol=min(6, len(handles) + len(lines)), title="operation mode / boundary",
               title_fontsize=8.5, frameon=False)
    n = len(handles) + len(lines)
    rows = math.ceil(n / min(6, n))
    fig.subplots_adjust(left=0.06, right=0.97, top=0.93, bottom=0.17 + 0.04 * rows, wspace=0.18)
    return save(fig, stem)
