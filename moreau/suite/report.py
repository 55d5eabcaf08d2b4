"""What ``moreau suite`` writes: the table, the figures and the page that links them.

``suite.csv`` / ``suite.json``
    one row per cell (problem, scheme, setting): outcome, cause, the error
    of each headline quantity, the largest, CPU time and steps; the JSON
    adds the problems (reference, source, tolerance), the overview and the
    provenance, as the other commands' sidecars do;
``problem_<name>.csv``
    the rows of one problem, one column per headline quantity's error;
``wp_<name>.png``
    the work–precision figure of one problem: largest error against CPU time,
    one line per scheme through its settings;
``overview.png``
    problems × schemes, each cell coloured by its outcome at the scheme's
    finest setting, with its largest error;
``index.md``
    the page: the overview, then one section per problem citing its source,
    with its table and figure.
"""

import csv
import json
import math
import os
import time

import joblib

from ..analysis.engine import end_worker_pool, worker_pool_config
from ..errors import InputError, MoreauError
from ..integrators.base import simulate
from ..provenance import provenance
from .animate import write_animation
from .problem import PENDING, get_problem
from .run import OUTCOMES, settings_of, trace_task

__all__ = ["overview", "write_report", "format_overview", "OUTCOME_COLOURS", "animation_tasks"]

#: colours of the outcomes in the overview (ok: shaded by error within the tolerance)
OUTCOME_COLOURS = {"ok": "#2ca25f", "inaccurate": "#fdae61", "failed": "#d7191c",
                   "refused": "#bdbdbd"}


def overview(rows):
    """``{problem: {scheme: row}}``: each cell's row at its finest (last) setting."""
    out = {}
    for r in rows:
        out.setdefault(r["problem"], {})[r["scheme"]] = r
    return out


def _fmt(x):
    if x is None:
        return "-"
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return f"{x:.2e}"


def format_overview(rows, schemes=None):
    """The overview as a Markdown table: outcome and largest error per problem and scheme."""
    ov = overview(rows)
    schemes = schemes or sorted({r["scheme"] for r in rows})
    lines = ["| problem | " + " | ".join(schemes) + " |",
             "|---|" + "---|" * len(schemes)]
    for p, cells in ov.items():
        items = []
        for s in schemes:
            r = cells.get(s)
            if r is None:
                items.append("")
            elif r["outcome"] in ("ok", "inaccurate"):
                items.append(f"{r['outcome']} {_fmt(r['max_error'])}")
            else:
                items.append(r["outcome"])
        lines.append(f"| {p} | " + " | ".join(items) + " |")
    return "\n".join(lines)


CSV_FIELDS = ("problem", "scheme", "setting", "outcome", "cause", "status", "max_error",
              "tolerance", "cpu_s", "steps", "errors")


def _write_csv(path, rows, quantities=None):
    fields = list(CSV_FIELDS)
    if quantities:
        fields.remove("errors")
        fields += [f"error_{q}" for q in quantities]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            out = dict(r)
            if quantities:
                for q in quantities:
                    out[f"error_{q}"] = (r.get("errors") or {}).get(q)
            else:
                out["errors"] = ";".join(f"{k}={v}" for k, v in (r.get("errors") or {}).items())
            w.writerow(out)


def plot_work_precision(problem, rows, path):
    """Largest error against CPU time, one line per scheme (its settings), the tolerance dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    by = {}
    for r in rows:
        if r["outcome"] in ("ok", "inaccurate") and r["cpu_s"] and r["max_error"] is not None \
                and math.isfinite(r["max_error"]):
            by.setdefault(r["scheme"], []).append(r)
    floor = 1e-16
    for i, (s, rs) in enumerate(sorted(by.items())):
        ax.loglog([max(r["cpu_s"], 1e-5) for r in rs], [max(r["max_error"], floor) for r in rs],
                  "o-", color=f"C{i % 10}", label=s)
    ax.axhline(problem["tolerance"], color="k", ls="--", lw=0.8, label="tolerance")
    ax.set_xlabel("CPU time [s]")
    ax.set_ylabel("largest relative error of the headline quantities")
    ax.set_title(f"{problem['title']} (reference: {problem['reference_kind']})", fontsize=9)
    if by:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_overview(rows, problems, schemes, path):
    """Problems × schemes coloured by outcome (the ok cells darker the smaller their error)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgb

    ov = overview(rows)
    fig, ax = plt.subplots(figsize=(1.1 * len(schemes) + 2.5, 0.55 * len(problems) + 2.2))
    for i, p in enumerate(problems):
        for j, s in enumerate(schemes):
            r = ov.get(p, {}).get(s)
            if r is None:
                continue
            colour = to_rgb(OUTCOME_COLOURS[r["outcome"]])
            text = r["outcome"]
            err = r.get("max_error")
            if r["outcome"] in ("ok", "inaccurate") and err is not None:
                text = _fmt(err)
                if r["outcome"] == "ok" and err > 0 and math.isfinite(err):
                    # lighter as the error nears the tolerance
                    shade = min(max(math.log10(r["tolerance"] / err) / 6.0, 0.0), 1.0)
                    colour = tuple(1.0 - (0.35 + 0.65 * shade) * (1.0 - c) for c in colour)
            ax.add_patch(plt.Rectangle((j, i), 1, 1, color=colour))
            ax.text(j + 0.5, i + 0.5, text, ha="center", va="center", fontsize=7)
    ax.set_xlim(0, len(schemes))
    ax.set_ylim(len(problems), 0)
    ax.set_xticks([j + 0.5 for j in range(len(schemes))])
    ax.set_xticklabels(schemes, rotation=40, ha="right", fontsize=8)
    ax.set_yticks([i + 0.5 for i in range(len(problems))])
    ax.set_yticklabels(problems, fontsize=8)
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in OUTCOME_COLOURS.values()]
    ax.legend(handles, list(OUTCOME_COLOURS), ncol=4, fontsize=7, loc="upper center",
              bbox_to_anchor=(0.5, -0.35), frameon=False)
    ax.set_title("outcome and largest relative error at each scheme's finest setting", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def animate_problem(name, path, frames=30):
    """A short animation of problem ``name``: its event-driven run over the window, drawn.

    Where the event-driven run stops (the Painlevé rod's jam, which it does
    not take), refuses the scene (a spatial one) or the problem declines it
    in the quick suite, Moreau–Jean's run at its
    finest quick step is drawn instead.
    Returns ``(path, None)``, or ``(None, cause)`` where both runs stop or
    the scene cannot draw itself.
    """
    _t0, _c0 = time.time(), time.process_time()
    try:
        return _animate_problem(name, path, frames)
    finally:
        trace_task("anim", _t0, _c0, p=name)


def _animate_problem(name, path, frames=30):
    prob = get_problem(name)
    scene = prob.make_scene()
    q0, v0 = prob.start(scene)
    causes = []
    try:
        for scheme in ("event-driven", "moreau-jean"):
            reason = prob.declined(scheme, quick=True)
            if reason is not None:
                causes.append(f"the problem declines {scheme}: {reason}")
                continue
            label, opts = settings_of(scheme, prob, scene, quick=True)[-1]
            if "sample_dt" in opts:
                # the frames are all that is drawn: a scheme that samples its own output is
                # asked for those samples only (the suite's cells ask for 2000)
                opts = dict(opts, sample_dt=prob.window / frames)
            try:
                res = simulate(scene, (0.0, prob.window), q0, v0, scheme, **opts)
            except InputError as exc:
                # a scheme that refuses the scene by name (the event-driven reference
                # steps no spatial scene): the next one draws it
                causes.append(f"{scheme} refused it: {exc}")
                continue
            if res.success:
                break
            causes.append(f"the {scheme} run stopped: {res.message}")
        else:
            return None, "; ".join(causes)
        cols = {n: c for n, _, c in scene.si_columns(res)}
        write_animation(scene, cols, path, f"{prob.title} ({scheme}, {label})",
                        fps=10, max_frames=frames)
    except MoreauError as exc:
        return None, f"{type(exc).__name__}: {exc}"
    return path, None


def _problem_figures(problem, rows, wp_path, anim_path, frames, drawn=None):
    # one problem's work-precision figure and animation (unless `drawn` already holds it, drawn
    # on the cells' pool): a task of the worker pool
    plot_work_precision(problem, rows, wp_path)
    if anim_path is None:
        return None, None
    if drawn is not None:
        return drawn
    return animate_problem(problem["name"], anim_path, frames)


def animation_tasks(problems, out, frames=30):
    """The page's animations as further tasks of the suite's pool.

    :func:`~moreau.suite.run.run_suite`'s ``tasks``: ``[(name,
    animate_problem, (name, path, frames))]``, one per problem.

    :func:`write_report` given their results (``animations``) draws no animation itself.

    Examples
    --------
    >>> [(k, a[1:]) for k, _, a in animation_tasks(["bouncing-ball"], "out", 5)]
    [('bouncing-ball', ('out/anim_bouncing-ball.gif', 5))]
    """
    return [(name, animate_problem, (name, os.path.join(out, f"anim_{name}.gif"), frames))
            for name in problems]


def _figures_all(jobs, n_jobs):
    # each animation reruns a scheme over its problem's window: on the worker pool, side by side
    if n_jobs == 1 or len(jobs) < 4:
        return [_problem_figures(*j) for j in jobs]
    with worker_pool_config():
        par = joblib.Parallel(n_jobs=n_jobs, batch_size=1)
    ok = False
    try:
        out = par(joblib.delayed(_problem_figures)(*j) for j in jobs)
        ok = True
    finally:
        end_worker_pool(kill=not ok)
    return out


def write_report(report, out, settings=None, plot=True, animation_frames=30, n_jobs=1,
                 animations=None):
    """Write the table, figures and ``index.md`` of a suite run to ``out``; return the paths.

    With ``plot``, each problem also gets a short animation (``anim_<name>.gif``,
    at most ``animation_frames`` frames; 0: none) of its event-driven run,
    drawn by ``n_jobs`` local worker processes; ``animations`` (``{name:
    (path, cause)}``, drawn on the cells' pool by :func:`animation_tasks`)
    holds them already drawn: the work-precision figures are then drawn here.
    """
    rows, probs, schemes = report["rows"], report["problems"], report["schemes"]
    _t0, _c0 = time.time(), time.process_time()
    paths = {}
    paths["csv"] = os.path.join(out, "suite.csv")
    _write_csv(paths["csv"], rows)
    doc = dict(report, settings=settings, outcomes=list(OUTCOMES),
               overview={p: {s: {"outcome": r["outcome"], "max_error": r["max_error"],
                                 "setting": r["setting"], "cause": r["cause"]}
                             for s, r in cells.items()} for p, cells in overview(rows).items()},
               pending=dict(PENDING), provenance=provenance())
    paths["json"] = os.path.join(out, "suite.json")
    with open(paths["json"], "w") as fh:
        json.dump(doc, fh, indent=1, default=lambda x: None if x != x else str(x))
    done_on_pool, figures, animations = animations, {}, {}
    jobs = []
    for p in probs:
        prow = [r for r in rows if r["problem"] == p["name"]]
        pcsv = os.path.join(out, f"problem_{p['name']}.csv")
        _write_csv(pcsv, prow, list(p["reference"]))
        paths[f"csv_{p['name']}"] = pcsv
        if plot:
            jobs.append((p, prow, os.path.join(out, f"wp_{p['name']}.png"),
                         os.path.join(out, f"anim_{p['name']}.gif") if animation_frames else None,
                         animation_frames, None if done_on_pool is None else
                         tuple(done_on_pool.get(p["name"], (None, "no animation was drawn")))))
    # with the animations drawn, a pool would start for a second of figures each: drawn here
    drawn = done_on_pool is not None
    drawn_jobs = _figures_all(jobs, 1 if drawn else n_jobs)
    for (p, _, _, anim, _, _), (done, cause) in zip(jobs, drawn_jobs):
        figures[p["name"]] = f"wp_{p['name']}.png"
        if anim is not None:
            animations[p["name"]] = f"anim_{p['name']}.gif" if done else cause
    if plot:
        plot_overview(rows, [p["name"] for p in probs], schemes, os.path.join(out, "overview.png"))
        figures["overview"] = "overview.png"
    paths.update({f"png_{k}": os.path.join(out, v) for k, v in figures.items()})
    paths.update({f"gif_{k}": os.path.join(out, v) for k, v in animations.items()
                  if v.endswith(".gif")})
    trace_task("report", _t0, _c0)
    paths["page"] = os.path.join(out, "index.md")
    with open(paths["page"], "w") as fh:
        fh.write(_page(report, figures, doc["provenance"], settings, animations))
    return paths


def _page(report, figures, prov, settings, animations=None):
    rows, probs, schemes = report["rows"], report["problems"], report["schemes"]
    quick = bool((settings or {}).get("quick"))
    lines = ["# moreau benchmark suite", "",
             f"{'Quick run' if quick else 'Full run'} of {len(schemes)} schemes on "
             f"{len(probs)} problems; moreau {prov.get('moreau_version', '?')} "
             f"({prov.get('code_version', '?')}), {prov.get('time_utc', '')}, "
             f"{prov.get('cpu', '?')} ({prov.get('cpu_count', '?')} cores), "
             f"{prov.get('platform', '?')}.", "",
             "Outcomes: **ok** (every headline quantity within the problem's tolerance), "
             "**inaccurate** (an error above it), **failed** (the run stopped; the cause is "
             "named), **refused** (the scheme declined the problem by name). The overview "
             "shows each scheme at its finest setting; errors are relative to each "
             "quantity's scale. Data: [suite.csv](suite.csv), [suite.json](suite.json).", ""]
    if report.get("flags") is not None:
        flags = report["flags"]
        lines += ["## Flags against the history", ""]
        lines += ([f"- **{f['kind']}**: {f['text']}" for f in flags] if flags
                  else ["None: no cell regressed."])
        lines.append("")
    if "overview" in figures:
        lines += [f"![overview]({figures['overview']})", ""]
    lines += [format_overview(rows, schemes), ""]
    for p in probs:
        lines += [f"## {p['title']} (`{p['name']}`)", "",
                  f"Scene `{p['scene']}`, window {p['window']:.6g} (scene time). Reference: "
                  f"{p['reference_kind']}. Source: {p['source']}. Tolerance "
                  f"{p['tolerance']:g}.", "",
                  "| quantity | reference | scale |", "|---|---|---|"]
        for q, v in p["reference"].items():
            lines.append(f"| {q} | {v:.10g} | {p['scales'][q]:.4g} |")
        lines.append("")
        if p["name"] in figures:
            lines += [f"![work-precision of {p['name']}]({figures[p['name']]})", ""]
        anim = (animations or {}).get(p["name"])
        if anim is not None:
            lines += ([f"![animation of {p['name']}]({anim})", ""] if anim.endswith(".gif")
                      else [f"No animation: {anim}.", ""])
        lines += [f"Table: [problem_{p['name']}.csv](problem_{p['name']}.csv)", "",
                  "| scheme | setting | outcome | largest error | CPU [s] | steps | cause |",
                  "|---|---|---|---|---|---|---|"]
        for r in rows:
            if r["problem"] == p["name"]:
                cpu = "-" if r["cpu_s"] is None else f"{r['cpu_s']:.3g}"
                cause = (r["cause"] or "").replace("|", "/").replace("\n", " ")[:160]
                lines.append(f"| {r['scheme']} | {r['setting']} | {r['outcome']} | "
                             f"{_fmt(r['max_error'])} | {cpu} | {r['steps'] or '-'} | {cause} |")
        lines.append("")
    if PENDING:
        lines += ["## Pending problems", ""]
        lines += [f"- `{k}`: {v}" for k, v in PENDING.items()]
        lines.append("")
    return "\n".join(lines)
