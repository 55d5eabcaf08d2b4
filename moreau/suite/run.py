"""Running the suite: every registered scheme on every problem, cell by cell, kept as it goes.

A *cell* is one problem, one scheme and one setting of the scheme (a step
count, a tolerance, a contact stiffness). Each cell ends in one outcome:

``ok``
    every headline quantity within the problem's tolerance;
``inaccurate``
    the run finished, but an error is above the tolerance (or a quantity
    could not be read from it, e.g. a ball that never comes to rest);
``failed``
    the run stopped with a status below zero or raised a
    :class:`~moreau.errors.MoreauError`; ``cause`` names it (a Painlevé
    stop, an LCP failure, a step that broke down). An exception that is not a
    :class:`~moreau.errors.MoreauError` is a failure too, its cause starting
    with ``unexpected``: the suite goes on and the table shows it;
``refused``
    the scheme refused the problem by name before running (an
    :class:`~moreau.errors.InputError`, e.g. a scene's own reference scheme
    given another scene; a stop outside the scene's valid region).

A finished cell is written to ``OUT/cells/`` at once; a rerun of the same
command reads the cells it finds there instead of computing them again, so
an interrupted suite resumes.
"""

import json
import math
import os
import re
import time

import numpy as np

from ..errors import InputError, Interrupted, MoreauError
from ..integrators.base import INTEGRATORS, get_integrator, propagate_interrupts, scheme_options, simulate
from ..scenes.registry import discover as discover_scenes
from .problem import get_problem, problem_names

__all__ = ["scheme_names", "settings_of", "run_cell", "run_suite", "OUTCOMES", "REFUSED_STATUS"]

#: the outcomes, best first
OUTCOMES = ("ok", "inaccurate", "failed", "refused")
#: a run's status that means "outside the scene's valid region": refused, not failed
REFUSED_STATUS = (-6,)
#: samples over the window asked of the schemes that choose their own steps
SAMPLES = 2000
#: tolerances of the schemes with an ``rtol`` (event-driven): quick, full
RTOLS = ((1e-6, 1e-10), (1e-4, 1e-7, 1e-10))


def scheme_names():
    """Every registered scheme, sorted (the scenes' own references included)."""
    discover_scenes()
    return sorted(INTEGRATORS)


def _options_of(name, scene):
    cls = get_integrator(name)
    if scene is not None and hasattr(cls, "resolve"):
        cls = cls.resolve(scene)
    return cls, scheme_options(cls) or ()


def settings_of(name, problem, scene, quick=False):
    """``[(label, options)]`` of scheme ``name`` on ``problem``, coarsest first.

    A time-stepping scheme (it takes ``h``) runs at the problem's step counts
    over its window; a scheme that states its own comparison settings
    (``Integrator.compare_settings``: a tolerance, a contact stiffness) at
    those; an event-driven scheme at :data:`RTOLS`; any other once with its
    defaults. Those that choose their own steps are asked for
    :data:`SAMPLES` samples over the window.

    Examples
    --------
    >>> from moreau.suite.problem import get_problem
    >>> p = get_problem("bouncing-ball")
    >>> [label for label, _ in settings_of("moreau-jean", p, p.make_scene(), quick=True)]
    ['N=400', 'N=4000']
    """
    cls, takes = _options_of(name, scene)
    extra = {}
    if "sample_dt" in takes:
        extra["sample_dt"] = problem.window / SAMPLES
    elif "samples_per_period" in takes and getattr(scene, "period", None):
        extra["samples_per_period"] = SAMPLES
    if "h" in takes:
        return [(f"N={n}", dict(extra, h=problem.window / n))
                for n in (problem.quick_steps if quick else problem.steps)]
    cs = getattr(cls, "compare_settings", None)
    if cs is not None and cs[0] in takes:
        key, values, quick_values, fixed = cs
        return [(f"{key}={v:g}", dict(extra, **dict(fixed), **{key: v}))
                for v in (quick_values if quick else values)]
    if "rtol" in takes:
        return [(f"rtol={r:g}", dict(extra, rtol=r)) for r in RTOLS[0 if quick else 1]]
    return [("default", extra)]


def _cause(exc):
    return f"{type(exc).__name__}: {exc}"


def run_cell(problem, scheme, label, options, scene=None, reference=None):
    """Run one cell and return its row (see the module docstring for the outcomes).

    The row holds ``problem``, ``scheme``, ``setting`` (the label),
    ``outcome``, ``cause``, ``status``, ``values`` and ``errors`` (per
    headline quantity), ``max_error``, ``tolerance``, ``cpu_s`` (the process
    time of the run and its measurement) and ``steps``.
    """
    row = {"problem": problem.name, "scheme": scheme, "setting": label, "outcome": None,
           "cause": "", "status": None, "values": {}, "errors": {}, "max_error": None,
           "tolerance": problem.tolerance, "cpu_s": None, "wall_s": None, "steps": None}
    try:
        scene = problem.make_scene() if scene is None else scene
        reference = problem.reference() if reference is None else reference
        q0, v0 = problem.start(scene)
        c0, w0 = time.process_time(), time.perf_counter()
        res = simulate(scene, (0.0, problem.window), q0, v0, scheme, **options)
        values = problem.measure(scene, res) if res.success else {}
        row["cpu_s"] = time.process_time() - c0
        row["wall_s"] = time.perf_counter() - w0
        row["status"] = int(res.status)
        row["steps"] = int((res.stats or {}).get("steps", len(res.t)))
        if not res.success:
            row["outcome"] = "refused" if res.status in REFUSED_STATUS else "failed"
            row["cause"] = f"status {res.status}: {res.message}"
            return row
        errors = problem.errors(values, reference)
        row["values"] = {k: (None if v is None else float(v)) for k, v in values.items()}
        row["errors"] = errors
        missing = [k for k, e in errors.items() if e is None]
        row["max_error"] = math.inf if missing else max(errors.values(), default=0.0)
        if missing:
            row["outcome"] = "inaccurate"
            row["cause"] = "no value for " + ", ".join(missing)
        elif row["max_error"] <= problem.tolerance:
            row["outcome"] = "ok"
        else:
            worst = max(errors, key=errors.get)
            row["outcome"] = "inaccurate"
            row["cause"] = f"{worst} off by {errors[worst]:.3g} > {problem.tolerance:g}"
    except InputError as exc:
        row.update(outcome="refused", cause=_cause(exc))
    except MoreauError as exc:
        row.update(outcome="failed", cause=_cause(exc))
    except (ArithmeticError, ValueError, TypeError, AttributeError, IndexError, KeyError,
            RuntimeError, NotImplementedError, np.linalg.LinAlgError) as exc:
        # a bug in a scheme or a scene: the table says so, the suite goes on
        row.update(outcome="failed", cause="unexpected " + _cause(exc))
    return row


def _safe(text):
    return re.sub(r"[^A-Za-z0-9_.=+-]", "_", text)


def cell_path(cache_dir, problem, scheme, label):
    return os.path.join(cache_dir, _safe(problem), _safe(scheme), _safe(label) + ".json")


def _warm_up(problem, scheme, options, scene):
    # numba compiles a scheme's loop for a scene on its first run: do it outside the timings
    q0, v0 = problem.start(scene)
    try:
        with np.errstate(all="ignore"):
            simulate(scene, (0.0, 0.05 * problem.window), q0, v0, scheme, **options)
    except Exception:   # noqa: BLE001  (the timed run reports whatever this one met)
        pass


def run_suite(problems=None, schemes=None, quick=False, cache_dir=None, progress=True):
    """Run every scheme on every problem; return ``{"rows", "problems", "cells"}``.

    Parameters
    ----------
    problems, schemes : sequence of str, optional
        Names (all registered ones by default).
    quick : bool
        The problems' quick step counts and the schemes' quick settings.
    cache_dir : str, optional
        Where each finished cell is kept (and read back on a rerun).
    progress : bool
        A tqdm bar on a terminal.

    Raises
    ------
    Interrupted
        On Ctrl-C, after the cells finished so far are kept.
    """
    known = problem_names()
    problems = list(known if problems is None else problems)
    for p in problems:
        get_problem(p)
    all_schemes = scheme_names()
    schemes = list(all_schemes if schemes is None else schemes)
    for s in schemes:
        if s not in INTEGRATORS:
            raise InputError(f"`schemes` must name registered schemes, from "
                             f"{', '.join(all_schemes)}; got {s!r}")
    plan = []
    insts = {}
    for pname in problems:
        prob = get_problem(pname)
        scene = prob.make_scene()
        insts[pname] = (prob, scene)
        for s in schemes:
            try:
                sets = settings_of(s, prob, scene, quick)
            except MoreauError:
                sets = [("default", {})]
            plan += [(pname, s, label, opts) for label, opts in sets]
    rows, done = [], 0
    refs = {}
    warmed = set()
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(plan), desc="suite", unit="cell", disable=None)
    try:
        with propagate_interrupts():
            for pname, s, label, opts in plan:
                path = cell_path(cache_dir, pname, s, label) if cache_dir else None
                row = None
                if path and os.path.exists(path):
                    try:
                        with open(path) as fh:
                            row = json.load(fh)
                        row["cached"] = True
                    except (OSError, ValueError):
                        row = None
                if row is None:
                    prob, scene = insts[pname]
                    if pname not in refs:
                        refs[pname] = prob.reference()
                    if (pname, s) not in warmed:
                        warmed.add((pname, s))
                        _warm_up(prob, s, opts, scene)
                    row = run_cell(prob, s, label, opts, scene, refs[pname])
                    row["cached"] = False
                    if path:
                        os.makedirs(os.path.dirname(path), exist_ok=True)
                        tmp = path + ".tmp"
                        with open(tmp, "w") as fh:
                            json.dump(row, fh, default=_json_default)
                        os.replace(tmp, path)
                rows.append(row)
                done += 1
                if bar is not None:
                    bar.update(1)
    except KeyboardInterrupt:
        raise Interrupted(done, len(plan), cache_dir, "suite", unit="cells") from None
    finally:
        if bar is not None:
            bar.close()
    return {"rows": rows, "problems": [insts[p][0].describe() for p in problems],
            "schemes": schemes, "cells": {"total": len(plan),
                                          "cached": sum(1 for r in rows if r.get("cached")),
                                          "computed": sum(1 for r in rows if not r.get("cached"))}}


def _json_default(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    return str(x)
