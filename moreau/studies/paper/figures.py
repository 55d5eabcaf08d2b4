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
from ...integrators import simulate
from ...regimes import REGIME_LETTERS
from ...scenes.friction_drive import FrictionDrive
from .tables import PARAM_COLUMNS, SWEPT_COLUMN

__all__ = ["MODE_COLORS", "REGIME_COLORS", "mode_color", "sweep_figure", "mode_figures",
           "steady_period", "atlas_figure", "save"]

#: the paper's six operation modes, in its order
PAPER_MODES = ("NS", "NSPS", "NPS", "NP", "NSP", "SP")
MODE_COLORS = {"NS": "#4477aa", "NSPS": "#66ccee", "NPS": "#228833", "NP": "#ccbb44",
               "NSP": "#ee6677", "SP": "#aa3377"}
REGIME_COLORS = {"N": "#4477aa", "S": "#228833", "P": "#ee6677", "F": "#bbbbbb"}
# distinct from the six mode colours and from the grey/black/white of points without a mode
_EXTRA = ["#999933", "#882255", "#44aa99", "#332288", "#e69f00", "#661100", "#cc79a7", "#56b4e9"]
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
        others[mode] = _EXTRA[len(others) % len(_EXTRA)]
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
        h = ax.axvspan(a, b, color=c, alpha=0.22 if m != "failed" else 0.5, lw=0)
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
    stem : path-like
        File name without suffix.
    checks : tuple of Scheme
        Moreau–Jean cross-checks whose columns are overlaid.
    title : str, optional
    log : bool, optional
        Log-scaled x axis (default: for frequency sweeps over more than a decade).
    scheme_label : str
        Legend entry of the main curve (the scheme that computed it).
    """
    plt = _plt()
    col = SWEPT_COLUMN.get(parameter, PARAM_COLUMNS.get(parameter, parameter))
    x = np.array([r[col] for r in rows], float)
    d = np.array([r["displacement_per_period_m"] for r in rows], float) * 1e6
    v = np.array([r["average_velocity_m_per_s"] for r in rows], float) * 1e3
    fig, axes = plt.subplots(2, 1, figsize=(8, 6.2), sharex=True)
    others = {}
    if log is None:
        log = parameter == "frequency" and x.size > 1 and x.min() > 0 and x.max() / x.min() > 20
    handles, limit_h = {}, {}
    for ax, y, lab in ((axes[0], d, "displacement per period [\u00b5m]"),
                       (axes[1], v, "average rotor velocity [mm/s]")):
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
                if ax is axes[1]:
                    ym = ym * (x if parameter == "frequency" else frequency) * 1e-3
                ax.plot(x, ym, mk, ms=3.2, mfc="none", mew=0.8, alpha=0.8,
                        color="#cc3311" if chk.theta == 1.0 else "#0077bb",
                        label=f"Moreau\u2013Jean \u03b8 = {chk.theta:g} "
                              f"({chk.steps_per_period} steps/period)")
    if log:
        axes[1].set_xscale("log")
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
        axes[1].set_xlim(lo - pad, hi + pad)
    span = hi - lo
    for xv, lab, ls in limits:
        if log or lo - 0.05 * span <= xv <= hi + 0.05 * span:
            for ax in axes:
                h = ax.axvline(xv, color="k", ls=ls, lw=1.1)
            limit_h[f"{lab} ({xv:.4g}{unit})"] = h
    axes[1].set_xlabel(_XLABEL.get(parameter, PARAM_COLUMNS.get(parameter, parameter)))
    lines, labels = axes[0].get_legend_handles_labels()
    axes[0].legend(lines + list(limit_h.values()), labels + list(limit_h), fontsize=7.5,
                   loc="best")
    axes[1].legend(list(handles.values()), list(handles), title="operation mode", fontsize=7.5,
                   ncol=4, loc="best", title_fontsize=8)
    if title is None:
        what = {"frequency": "drive frequency", "mu": "friction coefficient",
                "phi0": "initial tilt angle"}.get(parameter) or \
            _XLABEL.get(parameter, parameter).split(" [")[0]
        title = f"Friction drive: steady state against {what}"
        if parameter != "frequency" and frequency is not None:
            title += f" at f = {frequency:g} Hz"
    axes[0].set_title(title, fontsize=11)
    # fixed margins: tight_layout would cost one more full draw of a dense figure
    fig.subplots_adjust(left=0.09, right=0.98, top=0.94, bottom=0.08, hspace=0.08)
    return save(fig, stem)


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
    mode there, else the middle of the mode's widest run in the studies."""
    best = {}
    for mode, (name, value) in PREFERRED_POINTS.items():
        rows = results.get(name) or []
        if not rows:
            continue
        parameter = name.split("_")[0]
        col = SWEPT_COLUMN[parameter]
        r = min(rows, key=lambda r: abs(r[col] - value))
        if r["status"] == "ok" and r["mode"] == mode and abs(r[col] / value - 1) < 0.05:
            best[mode] = (math.inf, parameter, r[col], r)
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
                    best[m] = (i - start, parameter, mid[col], mid)
                start = i
    return best


def mode_figure_jobs(results, params, folder):
    """``[(function, args), ...]`` drawing the six operation modes (the paper's Figs. 3–8)."""
    jobs = []
    for mode, (_, parameter, value, row) in sorted(_mode_points(results).items(),
                                                   key=lambda kv: PAPER_MODES.index(kv[0])):
        p = params.with_(mu=row["mu"], phi0=row["phi0_rad"])
        jobs.append((mode_figure, (mode, p, row["frequency_Hz"], folder)))
    return jobs


def mode_figures(results, params, folder):
    """Draw the six operation modes; return the written paths."""
    return [path for fn, args in mode_figure_jobs(results, params, folder) for path in fn(*args)]


def mode_figure(mode, p, f, folder):
    """One steady period in ``mode`` at parameters ``p`` and frequency ``f`` (PNG + SVG)."""
    plt = _plt()
    folder = pathlib.Path(folder)
    if True:
        ss, res = steady_period(p, f)
        tau = res.t - res.t[0]
        u2 = res.q[:, 1] - res.q[0, 1]
        vt = res.slip_velocity[:, 0]
        letters = np.array([REGIME_LETTERS[int(c)] for c in res.regime[:, 0]])
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
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
                    used.add(L)
                    start = i
            last_te, level = -1.0, 0
            for e in res.events:
                te = e.t - res.t[0]
                if 0.0 < te < 2 * math.pi:
                    ax.axvline(te, color="k", ls=":", lw=0.9, zorder=0)
                    # stagger the labels of transitions that follow each other closely
                    level = (level + 1) % 2 if te - last_te < 0.35 else 0
                    last_te = te
                    ax.annotate(f"{REGIME_LETTERS[e.before]}\u2192{REGIME_LETTERS[e.after]}",
                                (te, 1.0 + 0.07 * level), xycoords=("data", "axes fraction"),
                                fontsize=7.5, ha="center", va="bottom")
            ax.set_xlabel("non-dimensional time \u03c4 \u2212 \u03c4\u2080 [-]")
            ax.set_ylabel(lab)
            ax.set_xlim(0, 2 * math.pi)
            ax.grid(alpha=0.3, lw=0.5)
        axes[1].axhline(0.0, color="0.5", lw=0.6)
        axes[0].legend(title="regime", fontsize=8, title_fontsize=8)
        fig.suptitle(f"Operation mode {mode}: one steady period at f = {f:g} Hz, "
                     f"\u03bc = {p.mu:.3g}, \u03c6\u2080 = {p.phi0:.3f} rad "
                     f"(\u03c4\u2080 = {ss.section_tau:.3f})", fontsize=10.5)
        fig.subplots_adjust(left=0.08, right=0.99, top=0.80, bottom=0.13, wspace=0.25)
        return save(fig, folder / f"mode_{mode}")


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
