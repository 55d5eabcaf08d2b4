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

With ``MOREAU_SUITE_TRACE=FILE`` in the environment, each process appends
one JSON line per task to ``FILE`` (its kind, process id, start and end
time, CPU seconds): where a run's time goes, compiles included.
"""

import concurrent.futures
import json
import os
import re
import time
import warnings

import joblib
import numpy as np
from tqdm import tqdm

from ..analysis.engine import connect_scheduler, end_worker_pool, worker_pool_config

from ..errors import InputError, Interrupted, MoreauError
from ..integrators.base import (INTEGRATORS, get_integrator, propagate_interrupts, scheme_options,
                                simulate)
from ..integrators.time_stepping import TimeStepping
from ..lcp import solve_lcp
from ..model.registry import discover as discover_scenes
from .peers import PEER_SETTING, is_peer, peer_names, run_peer_cell
from .problem import get_problem, judge, problem_names

__all__ = ["scheme_names", "settings_of", "run_cell", "run_suite", "same_runs", "OUTCOMES",
           "REFUSED_STATUS", "DECLINED"]

#: the outcomes, best first
OUTCOMES = ("ok", "inaccurate", "failed", "refused")
#: a run's status that means "outside the scene's valid region": refused, not failed
REFUSED_STATUS = (-6,)
#: samples over the window asked of the schemes that choose their own steps
SAMPLES = 2000
#: tolerances of the schemes with an ``rtol`` (event-driven): quick, full
RTOLS = ((1e-6, 1e-10), (1e-4, 1e-7, 1e-10))
#: cells to compute from which ``n_jobs=None`` takes every core (fewer: one process, no pool)
AUTO_POOL_CELLS = 40
#: the one setting of a scheme its problem declines by name (``Problem.declines``)
DECLINED = "declined"


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
    :data:`SAMPLES` samples over the window. In the quick suite a problem's
    ``quick_settings`` replace a scheme's quick values; a scheme the problem
    declines (``declines``, ``quick_declines``) has one setting,
    :data:`DECLINED`, whose cell is refused with the problem's reason.

    Examples
    --------
    >>> from moreau.suite.problem import get_problem
    >>> p = get_problem("bouncing-ball")
    >>> [label for label, _ in settings_of("moreau-jean", p, p.make_scene(), quick=True)]
    ['N=400', 'N=4000']
    """
    if problem.declined(name, quick) is not None:
        return [(DECLINED, {})]
    if is_peer(name):
        return [(PEER_SETTING, {})]
    own = problem.quick_settings.get(name) if quick else None
    cls, takes = _options_of(name, scene)
    extra = {}
    if "sample_dt" in takes:
        extra["sample_dt"] = problem.window / SAMPLES
    elif "samples_per_period" in takes and getattr(scene, "period", None):
        extra["samples_per_period"] = SAMPLES
    if "h" in takes:
        return [(f"N={n}", dict(extra, h=problem.window / n))
                for n in (own or (problem.quick_steps if quick else problem.steps))]
    cs = getattr(cls, "compare_settings", None)
    if cs is not None and cs[0] in takes:
        key, values, quick_values, fixed = cs
        return [(f"{key}={v:g}", dict(extra, **dict(fixed), **{key: v}))
                for v in (own or (quick_values if quick else values))]
    if "rtol" in takes:
        return [(f"rtol={r:g}", dict(extra, rtol=r))
                for r in (own or RTOLS[0 if quick else 1])]
    return [("default", extra)]


def _cause(exc):
    return f"{type(exc).__name__}: {exc}"


#: the exceptions of a bug in a scheme or a scene: its cell fails, the suite goes on
_BUGS = (ArithmeticError, ValueError, TypeError, AttributeError, IndexError, KeyError,
         RuntimeError, NotImplementedError, np.linalg.LinAlgError)


def run_cell(problem, scheme, label, options, scene=None, reference=None, judged=True):
    """Run one cell and return its row (see the module docstring for the outcomes).

    The row holds ``problem``, ``scheme``, ``setting`` (the label),
    ``outcome``, ``cause``, ``status``, ``values`` and ``errors`` (per
    headline quantity), ``max_error``, ``tolerance``, ``cpu_s`` (the process
    time of the run and its measurement) and ``steps``. With
    ``judged=False`` a run that finished is left for
    :func:`~moreau.suite.problem.judge` (its outcome None, no reference
    needed here).
    """
    row = {"problem": problem.name, "scheme": scheme, "setting": label, "outcome": None,
           "cause": "", "status": None, "values": {}, "errors": {}, "max_error": None,
           "tolerance": problem.tolerance, "cpu_s": None, "wall_s": None, "steps": None}
    if label == DECLINED:
        reason = problem.declines.get(scheme) or problem.quick_declines.get(scheme)
        row.update(outcome="refused", cause=f"the problem declines {scheme}: {reason}")
        return row
    try:
        scene = problem.make_scene() if scene is None else scene
        if judged and reference is None:
            reference = problem.reference()
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
        row["values"] = {k: (None if v is None else float(v)) for k, v in values.items()}
        if judged:
            judge(problem, row, reference)
    except InputError as exc:
        row.update(outcome="refused", cause=_cause(exc))
    except MoreauError as exc:
        row.update(outcome="failed", cause=_cause(exc))
    except _BUGS as exc:
        # a bug in a scheme or a scene: the table says so, the suite goes on
        row.update(outcome="failed", cause="unexpected " + _cause(exc))
    return row


def _safe(text):
    return re.sub(r"[^A-Za-z0-9_.=+-]", "_", text)


def cell_path(cache_dir, problem, scheme, label):
    return os.path.join(cache_dir, _safe(problem), _safe(scheme), _safe(label) + ".json")


#: steps over the whole window of a time-stepping scheme's warm-up run
WARM_UP_STEPS = 100


def _warm_up(problem, scheme, options, scene):
    # numba compiles a scheme's loop for a scene on its first run: do it outside the timings.
    # A kernel called first at an impact (Moreau-Jean projected's) compiles there: a scheme
    # that takes a step runs the whole window at a coarse one; the others a twentieth of it
    q0, v0 = problem.start(scene)
    window = 0.05 * problem.window
    if "h" in options:
        window = problem.window
        options = dict(options, h=max(options["h"], problem.window / WARM_UP_STEPS))
    try:
        with np.errstate(all="ignore"):
            simulate(scene, (0.0, window), q0, v0, scheme, **options)
    except Exception:   # noqa: BLE001  (the timed run reports whatever this one met)
        pass


#: per process: the problems' instances, scenes and references, and the (problem, scheme)
#: pairs already run once (compiled) in this process
_INSTANCES = {}
_WARMED = set()


def _problem_scene(pname):
    if pname not in _INSTANCES:
        prob = get_problem(pname)
        _INSTANCES[pname] = [prob, prob.make_scene(), None]
    return _INSTANCES[pname]


def reference_of(pname, reference=None):
    """The reference of problem ``pname``, computed once per process (or ``reference``, computed
    elsewhere: the parent of a worker, so that a worker does not compute it again)."""
    entry = _problem_scene(pname)
    if entry[2] is None:
        entry[2] = entry[0].reference() if reference is None else dict(reference)
    return entry[2]


def instance(pname, reference=None):
    """``(problem, scene, reference)`` of ``pname``, built once per process.

    ``reference``: the problem's reference computed elsewhere (the parent
    of a worker), so that a worker does not compute it again.
    """
    ref = reference_of(pname, reference)
    prob, scene, _ = _problem_scene(pname)
    return prob, scene, ref


def trace_task(kind, t0, c0, **kw):
    """Append one JSON line for a finished task where ``MOREAU_SUITE_TRACE`` names a file.

    ``t0`` and ``c0`` are the task's start by ``time.time()`` and
    ``time.process_time()``; ``kw`` adds fields (the module docstring).
    """
    path = os.environ.get("MOREAU_SUITE_TRACE")
    if path:
        with open(path, "a") as fh:
            fh.write(json.dumps(dict(kind=kind, pid=os.getpid(), t0=t0, t1=time.time(),
                                     cpu=time.process_time() - c0, **kw)) + "\n")


def cell_task(pname, scheme, label, options, reference=None, judged=True):
    _t0, _c0 = time.time(), time.process_time()
    row = _cell_task(pname, scheme, label, options, reference, judged)
    trace_task("cell", _t0, _c0, p=pname, s=scheme, l=label, cpu_s=row.get("cpu_s"))
    return row


def _cell_task(pname, scheme, label, options, reference=None, judged=True):
    """One cell, computed in this process (a worker's task): its row.

    The first cell of a (problem, scheme) pair in a process runs the scheme
    once first, untimed (over the window at :data:`WARM_UP_STEPS` steps, or
    over a twentieth of it for a scheme that takes no step), so that numba's
    compilation (or loading) is not counted in the cell's time. With
    ``judged=False`` the row is left for :func:`~moreau.suite.problem.judge`
    and the problem's reference is not computed here.
    """
    if judged:
        prob, scene, ref = instance(pname, reference)
    else:
        (prob, scene, _), ref = _problem_scene(pname), None
    if is_peer(scheme):
        row = run_peer_cell(prob, scheme, scene, ref, judged=judged)
        row["cached"] = False
        return row
    if label != DECLINED and (pname, scheme) not in _WARMED:
        _WARMED.add((pname, scheme))
        _warm_up(prob, scheme, options, scene)
    row = run_cell(prob, scheme, label, options, scene, ref, judged=judged)
    row["cached"] = False
    return row


def plan_cells(problems=None, schemes=None, quick=False, peers=True):
    """``[(problem, scheme, label, options)]`` of every cell, checked names first.

    Without ``schemes``: every registered scheme, and the Siconos peers where
    they are installed (``peers``).
    """
    known = problem_names()
    problems = list(known if problems is None else problems)
    for p in problems:
        get_problem(p)
    # asking the system interpreter for Siconos takes seconds: only where a peer may run
    wants_peers = peers and (schemes is None or any(is_peer(s) for s in schemes))
    all_schemes = scheme_names() + (peer_names() if wants_peers else [])
    schemes = list(all_schemes if schemes is None else schemes)
    for s in schemes:
        if s not in all_schemes:
            raise InputError(f"`schemes` must name registered schemes, from "
                             f"{', '.join(all_schemes)}; got {s!r}")
    plan = []
    for pname in problems:
        prob, scene, _ = _problem_scene(pname)
        for s in schemes:
            try:
                sets = settings_of(s, prob, scene, quick)
            except MoreauError:
                sets = [("default", {})]
            plan += [(pname, s, label, opts) for label, opts in sets]
    return problems, schemes, plan


def _read_cell(path):
    try:
        with open(path) as fh:
            row = json.load(fh)
    except (OSError, ValueError):
        return None
    row["cached"] = True
    return row


def _keep_cell(path, row):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + f".{os.getpid()}.tmp"
    with open(tmp, "w") as fh:
        json.dump(row, fh, default=_json_default)
    os.replace(tmp, path)


def _keyed_task(key, function, args):
    # a further task of the cells' pool (an animation): its result, marked by its key
    return (_TASK, key, function(*args))


_TASK = "task"


def _results(plan, todo, n_jobs, scheduler, tasks=(), done_tasks=None):
    """``(index, row)`` of the cells ``todo`` (indices into ``plan``), as they finish.

    ``tasks`` (``[(key, function, args)]``) run after the cells, on the same
    pool where there is one (else here, once the cells are done); their
    results go into ``done_tasks`` by key.
    """
    done_tasks = {} if done_tasks is None else done_tasks
    if scheduler is not None:
        from distributed import as_completed  # optional dependency, checked by the CLI
        client, own = connect_scheduler(scheduler)
        try:
            futures = {client.submit(cell_task, *plan[i], pure=False): i for i in todo}
            for fut in as_completed(list(futures)):
                i = futures[fut]
                try:
                    row = fut.result()
                except Exception as exc:   # noqa: BLE001  (a lost worker: the cell fails)
                    pname, s, label, _ = plan[i]
                    row = {"problem": pname, "scheme": s, "setting": label, "outcome": "failed",
                           "cause": "the Dask task failed: " + _cause(exc), "status": None,
                           "values": {}, "errors": {}, "max_error": None, "tolerance": None,
                           "cpu_s": None, "wall_s": None, "steps": None, "cached": False}
                yield i, row
        finally:
            if own:
                client.close()
        for key, function, args in tasks:
            done_tasks[key] = function(*args)
        return
    if n_jobs == 1 or len(todo) + len(tasks) <= 1:
        for i in todo:
            yield i, cell_task(*plan[i])
        for key, function, args in tasks:
            done_tasks[key] = function(*args)
        return
    # the workers run the cells and leave them unjudged; here a thread computes the problems'
    # references meanwhile, and each row is judged against its problem's as it comes back
    names = list(dict.fromkeys(plan[i][0] for i in todo))
    # the LCP-based schemes and references all call Lemke's compiled kernels: compiled (or loaded)
    # once here, before the pool, not by both workers and the thread at once (22 s each, cold)
    solve_lcp(np.array([[2.0, -1.0], [-1.0, 2.0]]), np.array([-1.0, -1.0]), method="lemke")
    refs = concurrent.futures.ThreadPoolExecutor(max_workers=1)
    ref_of = {p: refs.submit(reference_of, p) for p in names}
    pairs = _pairs(plan, todo)
    with worker_pool_config():
        par = joblib.Parallel(n_jobs=n_jobs, return_as="generator_unordered", batch_size=1)
    # the further tasks (the page's animations, seconds each) come last: they fill the
    # workers' tail, where a second pool would start after the last cell
    gen = par([joblib.delayed(pair_task)(pname, schemes) for pname, schemes in pairs]
              + [joblib.delayed(_keyed_task)(*t) for t in tasks])
    ok = False
    try:
        for out in gen:
            if isinstance(out, tuple) and out[0] == _TASK:
                done_tasks[out[1]] = out[2]
                continue
            for i, row in out:
                if row["outcome"] is None:
                    _judge_here(_problem_scene(plan[i][0])[0], row, ref_of[plan[i][0]].result())
                yield i, row
        ok = True
    finally:
        refs.shutdown(wait=ok, cancel_futures=True)
        if not ok:
            # closing joblib's generator stops handing out cells (Ctrl-C, an error)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                gen.close()
        end_worker_pool(kill=not ok)


def _judge_here(problem, row, reference):
    try:
        judge(problem, row, reference)
    except _BUGS as exc:
        row.update(outcome="failed", cause="unexpected " + _cause(exc))


#: the modules of the classes every scheme builds on: a class from them makes no family
_SHARED_BASES = {c.__module__ for c in TimeStepping.__mro__}


def scheme_family(name, scene):
    """The class whose compiled code scheme ``name`` shares with its relatives on ``scene``.

    The scheme's class as it runs ``scene`` (the scene's own reference for
    ``event-driven``), followed up its bases to the last one that is not
    common to every scheme: Moreau–Jean's projected variant is Moreau–Jean's,
    both compliant schemes are the compliant model's, ``event-driven`` on a
    scene without a reference of its own is ``event-driven-generic``. A
    peer, or a name no class answers to, is its own family.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> ball = make_scene("bouncing-ball")
    >>> scheme_family("moreau-jean-projected", ball) is scheme_family("moreau-jean", ball)
    True
    >>> [scheme_family(s, ball).__name__ for s in ("compliant-radau", "event-driven")]
    ['_Compliant', 'GenericEventDriven']
    """
    if is_peer(name):
        return name
    try:
        cls, _ = _options_of(name, scene)
    except MoreauError:
        return name
    own = [c for c in cls.__mro__ if c.__module__ not in _SHARED_BASES]
    return own[-1] if own else cls


def _pairs(plan, todo):
    """``[(problem, [(scheme, [(index, label, options)])])]``: the cells ``todo`` grouped by
    problem and scheme family (:func:`scheme_family`), one pool task each, so that the code a
    family compiles for a problem is compiled (or loaded) by one worker, not by both at once
    (Moreau–Jean and its projected variant on the granular column: 27-32 s of CPU each, cold).
    The first task of each family comes first: on a cold cache the workers compile different
    families side by side."""
    out = {}
    for i in todo:
        pname, s, label, options = plan[i]
        fam = scheme_family(s, _problem_scene(pname)[1])
        out.setdefault((pname, fam), {}).setdefault(s, []).append((i, label, options))
    first, seen = [], set()
    for (pname, fam), by_scheme in out.items():
        runs = any(label != DECLINED for cells in by_scheme.values() for _, label, _ in cells)
        if fam not in seen and runs and not is_peer(next(iter(by_scheme))):
            seen.add(fam)
            first.append((pname, fam))
    order = first + [key for key in out if key not in set(first)]
    return [(key[0], list(out[key].items())) for key in order]


def pair_task(pname, schemes):
    """The cells of one problem's schemes ``[(scheme, [(index, label, options)])]``, in this
    process (a worker's task), left unjudged: ``[(index, row)]``."""
    return [(i, cell_task(pname, scheme, label, options, judged=False))
            for scheme, cells in schemes for i, label, options in cells]


def same_runs(plan, todo):
    """``{i: j}``: cell ``i`` of ``todo`` is the run of cell ``j`` under another name.

    Two cells are one run where their schemes resolve to the same class on
    the problem's scene and their settings are the same: ``event-driven`` on
    a scene without a reference of its own is ``event-driven-generic``, and on
    the friction drive it is ``friction-drive-walker``. The cell of the
    scheme that is the class itself (``event-driven-generic``) is computed,
    the others take its row (:func:`_same_run_row`).

    Examples
    --------
    >>> plan = [("bouncing-ball", s, "rtol=1e-06", {"rtol": 1e-6})
    ...         for s in ("event-driven", "event-driven-generic", "moreau-jean")]
    >>> same_runs(plan, [0, 1, 2])
    {0: 1}
    """
    keys = []
    for i in todo:
        pname, s, label, options = plan[i]
        if label == DECLINED or is_peer(s):
            continue
        try:
            cls, _ = _options_of(s, _problem_scene(pname)[1])
        except MoreauError:
            continue
        # the scheme that is its class first: its cell is the one computed
        keys.append((get_integrator(s) is not cls, i, (pname, cls, label,
                                                        repr(sorted(options.items())))))
    first, out = {}, {}
    for _, i, key in sorted(keys):
        j = first.setdefault(key, i)
        if j != i:
            out[i] = j
    return out


def _same_run_row(row, scheme):
    # the row of scheme ``scheme``, whose run is ``row``'s (same_runs): it says whose
    note = f"the same run as {row['scheme']} (the same scheme on this scene)"
    return dict(row, scheme=scheme, cause="; ".join(c for c in (row["cause"], note) if c))


def run_suite(problems=None, schemes=None, quick=False, cache_dir=None, progress=True,
              n_jobs=1, scheduler=None, peers=True, tasks=()):
    """Run every scheme on every problem: ``{"rows", "problems", "schemes", "cells", "tasks"}``.

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
    peers : bool
        Without ``schemes``, add Siconos's OSIs as columns where Siconos is
        installed (:mod:`moreau.suite.peers`).
    n_jobs : int or None
        Local worker processes (the pool of ``moreau sweep``; 1: in this process;
        None: one per core where :data:`AUTO_POOL_CELLS` cells or more are
        to be computed, else 1). The report's ``jobs`` says how many ran.
    scheduler : str, optional
        A Dask scheduler's address: the cells run there instead.
    tasks : sequence of (key, function, args)
        Further work for the same workers, after the cells (the page's
        animations): ``function(*args)`` of each, in the report's ``tasks``
        by key. Where there is no pool they run here once the cells are done.

    Raises
    ------
    Interrupted
        On Ctrl-C, after the cells finished so far are kept.
    """
    _t0, _c0 = time.time(), time.process_time()
    problems, schemes, plan = plan_cells(problems, schemes, quick, peers)
    trace_task("plan", _t0, _c0)
    rows = [None] * len(plan)
    todo = []
    for i, (pname, s, label, _) in enumerate(plan):
        path = cell_path(cache_dir, pname, s, label) if cache_dir else None
        row = _read_cell(path) if path and os.path.exists(path) else None
        if row is None:
            todo.append(i)
        else:
            rows[i] = row
    done = len(plan) - len(todo)
    same = same_runs(plan, todo)
    copies = {}
    for i, j in same.items():
        copies.setdefault(j, []).append(i)
    todo = [i for i in todo if i not in same]
    if n_jobs is None:
        n_jobs = (os.cpu_count() or 1) if len(todo) >= AUTO_POOL_CELLS else 1
    bar = None
    done_tasks = {}
    if progress:
        bar = tqdm(total=len(plan), initial=done, desc="suite", unit="cell", disable=None)
    try:
        with propagate_interrupts():
            for i, row in _results(plan, todo, n_jobs, scheduler, list(tasks), done_tasks):
                for k in [i] + copies.get(i, []):
                    rows[k] = row if k == i else _same_run_row(row, plan[k][1])
                    if cache_dir:
                        _keep_cell(cell_path(cache_dir, *plan[k][:3]), rows[k])
                    done += 1
                    if bar is not None:
                        bar.update(1)
    except KeyboardInterrupt:
        raise Interrupted(done, len(plan), cache_dir, "suite", unit="cells") from None
    finally:
        if bar is not None:
            bar.close()
    return {"rows": rows, "problems": [instance(p)[0].describe(reference_of(p)) for p in problems],
            "schemes": schemes, "jobs": n_jobs, "cells": {"total": len(plan),
                                          "cached": sum(1 for r in rows if r.get("cached")),
                                          "computed": sum(1 for r in rows if not r.get("cached"))},
            "tasks": done_tasks}


def _json_default(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    return str(x)
