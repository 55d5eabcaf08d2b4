"""Sweep engine: steady states at many parameter points, cached on disk, in parallel.

Every point is one call of :func:`evaluate_point`, a pure function of the
friction drive's parameters, the drive frequency, the scheme settings and the
package's code version. The calls are memoised with :class:`joblib.Memory`,
so a finished point is never computed twice: a run that was interrupted
resumes where it stopped, and a study that shares points with an earlier one
reuses them. Because the code version is part of the key, editing the package
invalidates the cache instead of serving stale numbers.

The points run on local processes (joblib's loky pool, all cores by
default) or, given a scheduler address, on a Dask distributed cluster. Both
call the same memoised function, so they write to and read from the same
cache and give the same rows. On a real cluster the cache folder must be on
storage the workers can reach (a shared file system), or each worker keeps
its own.

A point that fails (ill-posed model, no convergence, anything else) becomes a
row whose ``status`` names the cause; it never stops the run.
"""

import ctypes
import ctypes.util
import functools
import hashlib
import itertools
import json
import logging
import math
import os
import pathlib
import re
import signal
import sys
import time
import warnings

import joblib
from joblib.externals.loky import get_reusable_executor
from joblib.externals.loky.process_executor import BrokenProcessPool

from .. import __version__
from ..errors import ConvergenceError, InputError, Interrupted, PainleveError, WorkerError
# the cache key's code version lives with the provenance; named here too (engine.code_version)
from ..provenance import code_version
from ..model import registry
from .scheme_settings import ED_REFERENCE, Scheme, make_scheme, steady_of
from .energy import ENERGY_COLUMNS, ENERGY_TERMS, energy_audit, energy_to_si, has_energy_audit
from .classify import CLASSIFY_COLUMNS, classification_columns
from .floquet import floquet_report
from .continuation import solve_line
from .steady_state import implausible_steady_state

log = logging.getLogger(__name__)

__all__ = ["end_worker_pool", "audit_options", "make_scheme", "code_version", "evaluate_point", "evaluate_points", "run_points", "check_output_dir", "cache_memory", "Scheme", "steady_of", "worker_init", "worker_pool_config",
           "ED_REFERENCE", "mj_check_columns", "periodic_scene_names"]


def mj_check_columns(check):
    """CSV column names of one Moreau–Jean cross-check."""
    p = check.label
    return [f"{p}_displacement_per_period_m", f"{p}_relative_error", f"{p}_mode", f"{p}_status"]


def periodic_scene_names():
    """The registered scenes with a periodic drive (and SI conversions): the ones the engine evaluates.

    Decided on each scene built with its defaults: a drive period, a
    frequency parameter, and the displacement and force conversions the rows
    need.
    """
    names = tuple(registry.scene_names())
    if _PERIODIC.get("names") != names:
        out = []
        for e in registry.entries():
            if "frequency" not in e.parameter_names():
                continue
            sc = e.factory()
            if getattr(sc, "period", None) is not None and all(
                    hasattr(sc, a) for a in ("displacement_to_si", "force_to_si")):
                out.append(e.name)
        _PERIODIC.update(names=names, periodic=out)
    return list(_PERIODIC["periodic"])


# periodic_scene_names() of the registry as it was last seen (every point checks its scene)
_PERIODIC = {}


def _check_scene(scene):
    entry = registry.get_entry(scene)  # an unknown name lists the known ones
    if entry.name not in periodic_scene_names():
        raise InputError(f"`scene` must be a periodically driven scene, one of "
                         f"{periodic_scene_names()}; got {scene!r}")
    return entry


def _make_scene(params, frequency, scene):
    return registry.make_scene(_check_scene(scene).name, frequency=frequency, **params)


#: shooting iterations of a continued point: a neighbour's orbit converges in a few, and a
#: step that does not is halved or started cold rather than iterated on
CONTINUED_MAX_ITER = 12


def _steady(params, frequency, scheme, scene="friction-drive", guess=None):
    scene = _make_scene(params, frequency, scene)
    return scene, steady_of(scene, scheme, guess=guess,
                            max_iter=None if guess is None else CONTINUED_MAX_ITER)


def _implausible(params, scene, ss):
    """Why a converged steady state cannot be right, or None (any scheme, either drive)."""
    return implausible_steady_state(scene, ss)


def _checked_steady(params, frequency, scheme, scene, guess=None):
    """:func:`_steady`, refusing a steady state that cannot be right."""
    sc, ss = _steady(params, frequency, scheme, scene=scene, guess=guess)
    why = _implausible(params, sc, ss)
    if why:
        raise ConvergenceError(why)
    return sc, ss


def _status_of(exc):
    msg = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {msg}"


def evaluate_point(params, frequency, scheme, checks=(), version="", scene="friction-drive",
                   energy=False):
    """Steady state at one parameter point, as a row of SI values.

    Parameters
    ----------
    params : dict
        Every field of :class:`~moreau.scenes.friction_drive.FrictionDriveParams`
        (or, with ``scene="bidirectional"``, of
        :class:`~moreau.scenes.bidirectional_drive.BidirectionalDriveParams`).
    frequency : float
        Drive frequency [Hz].
    scheme : Scheme
        The scheme that gives the row's values.
    checks : tuple of Scheme
        Moreau–Jean cross-checks; each adds the columns of :func:`mj_check_columns`.
    version : str
        Code version (only a cache key here).
    scene : str
        A registered periodically driven scene (:func:`periodic_scene_names`),
        e.g. the paper's single-rod drive or the two-rod bidirectional drive.
    energy : bool
        Add the energy audit of the steady period
        (:data:`moreau.analysis.energy.ENERGY_COLUMNS`, joules per period and
        the closing error); a point whose scheme has no audit gets NaN there
        and the reason in ``energy_status``.

    Returns
    -------
    dict
        ``mode``, ``displacement_per_period_m``, ``average_velocity_m_per_s``,
        ``min_normal_force_N``, ``periodic_residual``, ``shooting_iterations``,
        ``max_multiplier`` (the largest Floquet multiplier's modulus, NaN where
        none was computed) and ``stable`` (True, False, or "" where unknown),
        ``compute_time_s``, ``status`` (``"ok"`` or the cause of the failure)
        and the cross-check columns. Never raises for a failed point.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> from dataclasses import asdict
    >>> row = evaluate_point(asdict(PAPER_DEFAULTS), 20.0, ED_REFERENCE)
    >>> row["status"], row["mode"]
    ('ok', 'NS')
    >>> bad = evaluate_point(asdict(PAPER_DEFAULTS.with_(phi0=1.5)), 185.0, ED_REFERENCE)
    >>> bad["status"].startswith("PainleveError")
    True
    >>> from moreau.scenes.bidirectional_drive import BidirectionalDriveParams
    >>> two = evaluate_point(asdict(BidirectionalDriveParams(x10_b=0.0)), 2000.0,
    ...                      Scheme.moreau_jean(1.0, 200), scene="bidirectional")
    >>> two["status"], two["displacement_per_period_m"] > 0     # rod a alone: forward at 2 kHz
    ('ok', True)
    """
    return _evaluate(params, frequency, scheme, checks, version, scene, energy)[0]


def _painleve_margin(params):
    # both rods of the bidirectional drive share mu and phi0: one margin for either scene
    return (1.0 - params["mu"] * math.tan(params["phi0"]) if "mu" in params and "phi0" in params
            else 1.0)


def _evaluate(params, frequency, scheme, checks=(), version="", scene="friction-drive",
              energy=False, steady=None):
    """:func:`evaluate_point`, and its steady state (None where it failed).

    ``steady`` is the point's steady state ``(scene, SteadyState)`` or the
    exception that stopped it, when already computed (continuation);
    otherwise it is computed from a cold start here.
    """
    t0 = time.perf_counter()
    row = {"mode": "", "displacement_per_period_m": math.nan, "average_velocity_m_per_s": math.nan,
           "min_normal_force_N": math.nan, "periodic_residual": math.nan,
           "shooting_iterations": 0, "max_multiplier": math.nan, "stable": "", "status": "ok"}
    ref = math.nan
    _check_scene(scene)
    margin = _painleve_margin(params)
    if margin <= 0:
        # in contact phi <= phi0 (the stator only lifts the rod's hinge), so the rest angle
        # is the worst case; saying so here spares building an integrator for nothing
        row["status"] = (f"PainleveError: 1 - mu*tan(phi0) = {margin:.6g} <= 0: the contact "
                         f"problem is ill-posed at the rod's rest angle (mu={params['mu']!r}, "
                         f"phi0={params['phi0']!r})")
        for chk in checks:
            d_col, e_col, m_col, s_col = mj_check_columns(chk)
            row.update({d_col: math.nan, e_col: math.nan, m_col: "", s_col: row["status"]})
        row["compute_time_s"] = time.perf_counter() - t0
        if energy:
            row.update(_energy_columns(None, None, scheme, row["status"]))
        row[INPUTS_KEY] = inputs_digest(params, frequency, scheme, checks, version, scene, energy)
        return row, None
    sc = ss = None
    try:
        if steady is None:
            sc, ss = _checked_steady(params, frequency, scheme, scene)
        elif isinstance(steady, BaseException):
            raise steady
        else:
            sc, ss = steady
        ref = sc.displacement_to_si(ss.displacement_per_period)
        rep = floquet_report(ss)
        row.update(max_multiplier=math.nan if rep["max_multiplier"] is None
                   else rep["max_multiplier"],
                   stable="" if rep["stable"] is None else bool(rep["stable"]))
        row.update(mode=ss.mode, displacement_per_period_m=ref,
                   average_velocity_m_per_s=ref * frequency,
                   min_normal_force_N=sc.force_to_si(ss.min_normal_force),
                   periodic_residual=ss.periodic_residual, shooting_iterations=ss.iterations)
    except Exception as exc:  # any failure becomes the status of this point
        row["status"] = _status_of(exc)
        sc = ss = None
    found = ss
    if energy:
        row.update(_energy_columns(sc, ss, scheme, row["status"]))
    for chk in checks:
        d_col, e_col, m_col, s_col = mj_check_columns(chk)
        row.update({d_col: math.nan, e_col: math.nan, m_col: "", s_col: "ok"})
        try:
            sc, ss = _checked_steady(params, frequency, chk, scene)
            d = sc.displacement_to_si(ss.displacement_per_period)
            row.update({d_col: d, m_col: ss.mode,
                        e_col: (d - ref) / abs(ref) if ref != 0 else math.nan})
        except Exception as exc:  # any failure becomes the status of this point
            row[s_col] = _status_of(exc)
    row["compute_time_s"] = time.perf_counter() - t0
    # the row carries what it was computed for: a cache entry is checked against it when read
    row[INPUTS_KEY] = inputs_digest(params, frequency, scheme, checks, version, scene, energy)
    return row, found


def _energy_columns(sc, ss, scheme, status):
    """The audit's columns of one point: SI terms and closing error, or NaN and the reason."""
    cols = dict.fromkeys(ENERGY_COLUMNS, math.nan)
    if ss is None:
        cols["energy_status"] = f"no steady state ({status.split(':')[0]})"
        return cols
    if not has_energy_audit(sc, scheme.name):
        cols["energy_status"] = f"no energy audit for scheme {scheme.name!r}"
        return cols
    try:
        audit = energy_to_si(sc, energy_audit(sc, ss, scheme.name, audit_options(scheme)))
    except Exception as exc:  # a failed audit is the point's energy_status, not a failure
        cols["energy_status"] = _status_of(exc)
        return cols
    for (_, si), col in zip(ENERGY_TERMS, ENERGY_COLUMNS):
        cols[col] = audit[si]
    if audit["closing_error"] is None:
        cols["energy_status"] = audit["note"]
        return cols
    cols["energy_closing_error"] = audit["closing_error"]
    cols["energy_status"] = "ok"
    return cols


def audit_options(scheme):
    """The settings of a :class:`Scheme` that its energy audit needs to redo the steady period."""
    out = dict(scheme.options)
    if scheme.steps_per_period is not None:
        out["steps_per_period"] = scheme.steps_per_period
    if scheme.theta is not None:
        out["theta"] = scheme.theta
    return out


def evaluate_points(points, scheme, checks=(), version="", scene="friction-drive",
                    energy=False, continuation=True, classify=None):
    """:func:`evaluate_point` over a line of ``(params, frequency)``: one cache entry for many points.

    With ``continuation`` the points are neighbours in this order and each
    one's shooting starts from the previous one's orbit
    (:func:`moreau.analysis.continuation.solve_line`: halved steps, a cold
    start where that fails). Every row says how it started (``start``, one
    of :data:`~moreau.analysis.continuation.START_VALUES`, and
    ``continuation_solves``). With ``classify`` (a budget of drive periods,
    0 for no run; None for no columns) every row gets the :data:`CLASSIFY_COLUMNS`
    (:mod:`moreau.analysis.classify`): a point without a periodic orbit is
    named period-k, non-periodic (with its mean), runaway, ... instead of
    only failed, from a plain run of at most ``classify`` periods.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> from dataclasses import asdict
    >>> rows = evaluate_points([(asdict(PAPER_DEFAULTS), 20.0)] * 2, ED_REFERENCE)
    >>> [(r["mode"], r["start"]) for r in rows]
    [('NS', 'cold'), ('NS', 'continued')]
    """
    points = [(dict(p), float(f)) for p, f in points]

    scenes = {}

    def solve(point, guess):
        p, f = point
        if _painleve_margin(p) <= 0:
            # _evaluate says so without building a scene
            raise PainleveError("1 - mu*tan(phi0) <= 0")
        sc, ss = _checked_steady(p, f, scheme, scene, guess=guess)
        scenes[id(ss)] = sc
        return ss

    rows = []
    for point, rec in zip(points, solve_line(points, solve, continuation)):
        p, f = point
        ss = rec["steady"]
        steady = (scenes[id(ss)], ss) if ss is not None else rec["error"]
        if _painleve_margin(p) <= 0:
            # ill-posed before any shooting: nothing was continued or started
            steady = None
            rec.update(start="cold", solves=0)
        row, ss = _evaluate(p, f, scheme, checks, version, scene, energy, steady=steady)
        row["compute_time_s"] += rec["seconds"]
        row["start"] = rec["start"]
        row["continuation_solves"] = rec["solves"]
        if classify is not None:
            t0 = time.perf_counter()
            row.update(classification_columns(row, p, f, scheme, scene, ss,
                                              budget=int(classify)))
            row["compute_time_s"] += time.perf_counter() - t0
        rows.append(row)
    return rows


def check_output_dir(path, option="--out"):
    """Create ``path`` if needed and make sure files can be written there.

    Raises
    ------
    InputError
        Naming the folder and the reason, before any work is done.

    Examples
    --------
    >>> import tempfile
    >>> check_output_dir(tempfile.mkdtemp()).is_dir()
    True
    """
    p = pathlib.Path(path)
    if p.exists() and not p.is_dir():
        # mkdir's "File exists" would not say that the name is taken by a file
        raise InputError(f"`{option}` folder {str(p)!r} is not writable: it is a file, not a "
                         "folder")
    try:
        p.mkdir(parents=True, exist_ok=True)
        probe = p / f".moreau-write-test-{os.getpid()}"
        probe.write_text("ok")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"`{option}` folder {str(p)!r} is not writable: {exc.strerror or exc}") from None
    return p


#: the most local worker processes per core that `--jobs` may ask for
MAX_JOBS_PER_CORE = 4
_SCHEMES = ("tcp://", "tls://", "inproc://", "ucx://", "ws://", "wss://")


def check_jobs(n_jobs, points):
    """The number of local worker processes to start, checked before any work.

    ``-1`` means one per core; anything else must be between 1 and
    :data:`MAX_JOBS_PER_CORE` times the cores. Never more workers than points.

    Examples
    --------
    >>> check_jobs(1, 10)
    1
    >>> check_jobs(0, 10)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `--jobs` must be -1 (one per core) or a whole number from 1 to ...
    """
    cores = os.cpu_count() or 1
    limit = MAX_JOBS_PER_CORE * cores
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, int) or not (
            n_jobs == -1 or 1 <= n_jobs <= limit):
        raise InputError(f"`--jobs` must be -1 (one per core) or a whole number from 1 to "
                         f"{limit} ({MAX_JOBS_PER_CORE} per core on this machine), got {n_jobs!r}")
    return max(1, min(cores if n_jobs == -1 else n_jobs, points))


#: the columns a line of continued points adds to its rows (:func:`evaluate_points`)
LINE_COLUMNS = ("start", "continuation_solves")


def line_columns(row):
    """``{start, continuation_solves}`` of a row; a point run alone (a task of one) started cold.

    Examples
    --------
    >>> line_columns({"mode": "NP"})
    {'start': 'cold', 'continuation_solves': 0}
    """
    return {"start": row.get("start", "cold"),
            "continuation_solves": row.get("continuation_solves", 0)}


#: most points of a continued segment: a task is also the unit that an interrupted run keeps
LINE_CHUNK_MAX = 10


def line_chunk(points, n_jobs=-1, continuation=True):
    """Points per task when ``points`` neighbours on a line are continued one from the next.

    A task's points are shot in order, each from the previous one's orbit;
    its first point starts cold. Two tasks per worker at least: fewer cold
    starts than one task per point, and a worker that drew the costly segment
    (flight, points without an orbit) is not left alone at the end of the
    run. At most :data:`LINE_CHUNK_MAX` points, because the cache keeps whole
    tasks: an interrupted run loses the unfinished part of at most one
    segment per worker. Without continuation every point is its own task.

    Examples
    --------
    >>> line_chunk(99, 2), line_chunk(15, 2), line_chunk(3, 2), line_chunk(99, 2, False)
    (10, 4, 1, 1)
    """
    if not continuation:
        return 1
    workers = check_jobs(n_jobs, max(1, int(points)))
    return max(1, min(LINE_CHUNK_MAX, math.ceil(int(points) / (2 * workers))))


def check_scheduler(scheduler):
    """Refuse a Dask scheduler address that cannot work, before any work.

    Examples
    --------
    >>> check_scheduler("garbage://x")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `--scheduler` must be a Dask scheduler address such as tcp://host:8786, got 'garbage://x'
    """
    if scheduler is None or hasattr(scheduler, "submit"):
        return scheduler
    if not isinstance(scheduler, str) or not scheduler.startswith(_SCHEMES) or \
            len(scheduler.split("://", 1)[1]) == 0:
        raise InputError("`--scheduler` must be a Dask scheduler address such as "
                         f"tcp://host:8786, got {scheduler!r}")
    try:
        import distributed  # noqa: F401  (optional dependency: the [dask] extra)
    except ImportError:
        raise InputError("`--scheduler` needs Dask, which is not installed: "
                         "pip install -e \".[dask]\"") from None
    return scheduler


#: seconds to wait for a Dask scheduler to answer before the run is refused
SCHEDULER_TIMEOUT_S = 10.0


def connect_scheduler(scheduler):
    """A Dask client for ``scheduler``, connected before any work, and whether it is ours to close.

    An address where no scheduler answers within :data:`SCHEDULER_TIMEOUT_S`
    is refused as bad input (the run has not started), not left to fail as a
    network traceback half-way through.

    Examples
    --------
    >>> connect_scheduler(None)
    (None, False)
    """
    scheduler = check_scheduler(scheduler)
    if scheduler is None or hasattr(scheduler, "submit"):
        return scheduler, False
    from distributed import Client  # optional dependency, checked by check_scheduler

    try:
        return Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s"), True
    except (OSError, TimeoutError) as exc:
        raise InputError(f"`--scheduler` {scheduler}: no Dask scheduler answered there within "
                         f"{SCHEDULER_TIMEOUT_S:g} s ({type(exc).__name__}); start one with "
                         "`dask scheduler` or check the address") from None


#: the key of a row's fingerprint of its inputs (removed before rows are returned)
INPUTS_KEY = "_inputs"


def inputs_digest(params, frequency, scheme, checks, version, scene, energy=False):
    """A fingerprint of everything a point's row depends on (its cache entry carries it).

    Examples
    --------
    >>> a = inputs_digest({"mu": 0.1}, 185.0, ED_REFERENCE, (), "v", "friction-drive")
    >>> a == inputs_digest({"mu": 0.1}, 185.0, ED_REFERENCE, (), "v", "friction-drive")
    True
    >>> a == inputs_digest({"mu": 0.2}, 185.0, ED_REFERENCE, (), "v", "friction-drive")
    False
    """
    text = repr((sorted((k, repr(v)) for k, v in dict(params).items()), repr(float(frequency)),
                 repr(tuple(scheme)), repr(tuple(tuple(c) for c in checks)), version, scene)
                + (("energy",) if energy else ()))
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _entry_matches(res, a, chunk):
    # the rows an entry holds against the inputs they are to answer
    if chunk == 1:
        return isinstance(res, dict) and res.get(INPUTS_KEY) == inputs_digest(*a)
    pts, rest = _line_points(a[0]), a[1:6]
    return (isinstance(res, list) and len(res) == len(pts)
            and all(isinstance(r, dict) and r.get(INPUTS_KEY) == inputs_digest(p, f, *rest)
                    for r, (p, f) in zip(res, pts)))


def _line_key(points):
    """The points of a line as one JSON text, or the points themselves where JSON would not round-trip.

    The cache hashes a task's arguments in the parent before any work
    (:func:`_run_points`); joblib's pure-Python pickling of a hundred
    parameter dicts cost 11-17 ms a line. One string hashes in microseconds.
    Parameters of other types than floats (numpy's included), ints, strings,
    booleans and None (which JSON would refuse or turn into others, a tuple
    into a list) keep the tuple form.
    """
    if not all(v is None or isinstance(v, (float, int, str)) for p, _ in points
               for v in p.values()):
        return points
    return json.dumps([[p, f] for p, f in points], separators=(",", ":"))


def _line_points(key):
    # the (params, frequency) pairs of a line from its _line_key
    if isinstance(key, str):
        return tuple((dict(p), f) for p, f in json.loads(key))
    return key


def _evaluate_line(key, *rest):
    """:func:`evaluate_points` on the line ``key`` (:func:`_line_key`): the cached task of a line."""
    return evaluate_points(_line_points(key), *rest)


def _recompute(func, a):
    out = func.call(*a)
    # joblib's MemorizedFunc.call returns (output, metadata) in recent versions
    if isinstance(out, tuple) and len(out) == 2 and isinstance(out[1], dict):
        return out[0]
    return out


def cache_memory(cache_dir):
    """The on-disk cache of computed results in ``cache_dir`` (None: nothing is kept).

    One :class:`joblib.Memory` for the points of sweeps and atlases and the
    cells of the stress catalogue.
    """
    return joblib.Memory(location=None if cache_dir is None else str(cache_dir), verbose=0)


def run_points(points, scheme=ED_REFERENCE, checks=(), cache_dir=None, n_jobs=-1, scheduler=None,
               progress=False, desc="points", chunk=1, scene="friction-drive", energy=False,
               continuation=True, classify=None):
    """Evaluate many points, reusing cached ones, in parallel.

    Parameters
    ----------
    points : list of (dict, float)
        ``(params, frequency)`` pairs (see :func:`evaluate_point`).
    scheme, checks : Scheme, tuple of Scheme
    cache_dir : path-like, optional
        joblib cache folder; None disables the cache.
    n_jobs : int
        Local processes (``-1``: all cores). Ignored with ``scheduler``.
    scheduler : str or distributed.Client, optional
        Address of a Dask scheduler (``"tcp://host:8786"``) or a client.
    progress : bool
        A tqdm bar (shown on a terminal only).
    scene : str
        A registered periodically driven scene; ``params`` are its parameters.
    chunk : int
        Points per task and per cache entry. Large grids (atlases) use a
        chunk of a grid line: tens of thousands of single-point entries
        would cost more in files and scheduling than in computing.
    energy : bool
        Add the energy audit's columns to every row (:func:`evaluate_point`).
    continuation : bool
        With ``chunk`` > 1: the points of a chunk are neighbours, each
        shot from the previous one's orbit (:func:`evaluate_points`).
    classify : int, optional
        With ``chunk`` > 1: the classification columns, naming the long-run
        motion of every point without an orbit from a plain run of at most
        this many periods (0: no run).

    Returns
    -------
    rows : list of dict
        In the order of ``points``.
    stats : dict
        ``cached`` (points found in the cache) and ``computed``.

    Examples
    --------
    >>> from dataclasses import asdict
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> rows, st = run_points([(asdict(PAPER_DEFAULTS), 20.0)], n_jobs=1)
    >>> rows[0]["mode"], st["computed"]
    ('NS', 1)
    """
    _check_scene(scene)
    n_jobs = check_jobs(n_jobs, max(1, len(points)))
    scheduler = check_scheduler(scheduler)
    if cache_dir is not None:
        check_output_dir(cache_dir, "--cache")
    client, own_client = connect_scheduler(scheduler)
    try:
        return _run_points(points, scheme, checks, cache_dir, n_jobs, client, progress, desc,
                           chunk, scene, energy, continuation, classify)
    finally:
        if own_client:
            client.close()


def _run_points(points, scheme, checks, cache_dir, n_jobs, scheduler, progress, desc, chunk,
                scene, energy, continuation=True, classify=None):
    version = code_version()
    chunk = max(1, int(chunk))
    if chunk == 1:
        func = cache_memory(cache_dir).cache(evaluate_point, ignore=[])
        args = [(dict(p), float(f), scheme, tuple(checks), version, scene, bool(energy))
                for p, f in points]
        sizes = [1] * len(args)
    else:
        func = cache_memory(cache_dir).cache(_evaluate_line, ignore=[])
        groups = [points[i:i + chunk] for i in range(0, len(points), chunk)]
        args = [(_line_key(tuple((dict(p), float(f)) for p, f in g)), scheme, tuple(checks),
                 version, scene, bool(energy), bool(continuation),
                 None if classify is None else int(classify))
                for g in groups]
        sizes = [len(g) for g in groups]
    out = [None] * len(args)
    todo = []
    notes = {"unreadable": 0, "mismatched": 0}
    for i, a in enumerate(args):
        if cache_dir is not None and func.check_call_in_cache(*a):
            caught = []
            # joblib reports an unreadable entry with a traceback through its
            # own logger, then recomputes: catch that, count it, say it once
            func.warn = caught.append
            try:
                res = func(*a)
            finally:
                del func.warn
            if any("loading" in str(m).lower() for m in caught):
                # joblib could not read the entry and recomputed it: not from the cache
                notes["unreadable"] += 1
                todo.append(i)
                continue
            if not _entry_matches(res, a, chunk):
                # an entry computed for other inputs (copied, or a hash collision): redo it
                notes["mismatched"] += 1
                todo.append(i)
                continue
            out[i] = res
        else:
            todo.append(i)
    n_cached = sum(sizes[i] for i in range(len(args)) if out[i] is not None)
    for what, k in notes.items():
        if k:
            why = ("could not be read" if what == "unreadable"
                   else "were computed for other parameters")
            log.warning("%d cache entr%s in %s %s; recomputed", k, "y" if k == 1 else "ies",
                        cache_dir, why)
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(points), initial=n_cached, desc=desc, unit="pt",
                   disable=None, leave=False)
    done = n_cached
    pooled = False
    interrupted = False
    try:
        if todo:
            if scheduler is not None:
                results = _dask_results(func, [args[i] for i in todo], scheduler)
            elif n_jobs == 1 or len(todo) == 1:
                results = ((k, func(*args[i])) for k, i in enumerate(todo))
            else:
                # the first task runs here: it compiles (or loads) the numba kernels
                # once and writes numba's on-disk cache, which the workers then load
                # instead of each compiling the same kernels at the same time
                first = (0, func(*args[todo[0]]))
                done += sizes[todo[0]]
                # the workers ignore Ctrl-C and SIGTERM: the parent alone stops the run and
                # ends them, so that an interrupt prints no worker tracebacks and leaves no
                # orphans; they die with a parent that is killed outright
                with worker_pool_config():
                    par = joblib.Parallel(n_jobs=n_jobs, return_as="generator_unordered",
                                          batch_size=1)
                pooled = True
                rest = par(joblib.delayed(_indexed)(func, k, args[i])
                           for k, i in enumerate(todo) if k > 0)
                results = itertools.chain([first], rest)
            for k, res in results:
                i = todo[k]
                if cache_dir is not None and not _entry_matches(res, args[i], chunk) and not (
                        chunk > 1 and isinstance(res, dict)):
                    res = _recompute(func, args[i])
                if chunk > 1 and isinstance(res, dict):  # a lost Dask task: every point fails
                    res = [dict(res) for _ in range(sizes[i])]
                out[i] = res
                if bar is not None:
                    bar.update(sizes[i])
                done = n_cached + sum(sizes[j] for j in todo if out[j] is not None)
    except KeyboardInterrupt:
        interrupted = True
        if bar is not None:
            bar.close()
            bar = None
        _end_workers(locals().get("rest"))
        raise Interrupted(done, len(points), None if cache_dir is None else str(cache_dir),
                          desc) from None
    except BaseException as exc:
        # an error ends the run now: busy workers are not waited for, and joblib is told
        # to stop handing out tasks (it would report each one refused by the closed pool)
        interrupted = True
        if bar is not None:
            bar.close()
            bar = None
        _end_workers(locals().get("rest"))
        if isinstance(exc, BrokenProcessPool):
            codes = re.search(r"exit codes of the workers are (\{[^}]*\})", str(exc))
            raise WorkerError(f"exit codes {codes.group(1)}" if codes else type(exc).__name__,
                              done, len(points), None if cache_dir is None else str(cache_dir),
                              desc) from None
        raise
    finally:
        if bar is not None:
            bar.close()
        if pooled:
            end_worker_pool(kill=interrupted)
    rows = out if chunk == 1 else [r for part in out for r in part]
    rows = [{k: v for k, v in r.items() if k != INPUTS_KEY} for r in rows]
    return rows, {"cached": n_cached, "computed": len(points) - n_cached}


def end_worker_pool(kill=False):
    """Shut down joblib's reusable pool of local worker processes once a run is over.

    joblib keeps its loky pool alive for the next call and leaves it to the
    interpreter's exit, where the pool's queues and locks may be torn down
    after loky's resource tracker has looked for them: it then reports
    "leaked semlock objects" on stderr. Shutting the pool down when the run
    ends releases them in order. ``kill=True`` ends workers still busy (after
    an interrupt).

    Examples
    --------
    >>> end_worker_pool()     # no pool: nothing to end
    """
    # reuse=True: the pool the run used, whatever its settings (a new, empty one if none)
    get_reusable_executor(reuse=True).shutdown(wait=True, kill_workers=kill)


def _indexed(func, k, a):
    return k, func(*a)


#: prctl's option that sends the calling process a signal when its parent dies (Linux)
_PR_SET_PDEATHSIG = 1


def worker_pool_config():
    """joblib's settings for a local worker pool: loky, each worker set up by :func:`worker_init`.

    Examples
    --------
    >>> with worker_pool_config():
    ...     joblib.Parallel(n_jobs=1)(joblib.delayed(abs)(x) for x in (-1, -2))
    [1, 2]
    """
    return joblib.parallel_config("loky", initializer=functools.partial(worker_init, os.getpid()))


def worker_init(parent_pid=None):
    """Initializer of a local worker process: the parent alone decides when it ends.

    Ctrl-C on a terminal and ``timeout``'s SIGTERM reach the whole process
    group; the workers ignore both, and the parent (which turns them into
    :class:`~moreau.errors.Interrupted`) ends its pool. On Linux a worker
    also asks to be killed when its parent dies without ending it (SIGKILL,
    a crash), instead of computing on as an orphan.

    Parameters
    ----------
    parent_pid : int, optional
        The process that starts the pool: a worker whose parent is already
        another one (the starter died before the request) ends at once.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError) as exc:  # no libc to ask: the parent still ends us
            log.debug("worker: no parent-death signal: %s", exc)
        if parent_pid is not None and os.getppid() != parent_pid:
            os._exit(1)  # the parent died before the request was made


def _end_workers(results):
    # closing joblib's generator aborts the run and ends its workers
    if results is not None and hasattr(results, "close"):
        try:
            with warnings.catch_warnings():
                # joblib counts the tasks it cancels in a UserWarning: the interrupt line says it
                warnings.simplefilter("ignore")
                results.close()
        except Exception as exc:  # ending the pool must not hide the interrupt
            log.debug("closing the worker pool after an interrupt: %s", exc)


def _dask_results(func, args, client):
    from distributed import as_completed  # optional dependency, checked by check_scheduler

    futures = {client.submit(func, *a, pure=False): k for k, a in enumerate(args)}
    for fut in as_completed(list(futures)):
        k = futures[fut]
        try:
            row = fut.result()
        except Exception as exc:  # a lost worker: the point fails, the run goes on
            row = {"status": _status_of(exc)}
        yield k, row
