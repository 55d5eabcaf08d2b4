"""Accuracy and speed regression cases: one per scheme and scene (``benchmarks/test_regression.py``).

Each case of :data:`CASES` is one row of :func:`moreau.analysis.compare.compare`
(a scheme at one setting on one scene) and measures its headline and
trajectory errors against the scene's tight reference. The accepted errors
are stored in ``benchmarks/baselines.json`` with, for speed, the case's run
time divided by a fixed numpy workload timed in the same process
(``time_ratio``), which takes out most of the machine's load at the time.

A case *regresses in accuracy* when an error exceeds its baseline by more
than :data:`ACCURACY_SLACK` (relative) plus :data:`ACCURACY_FLOOR`
(absolute, for errors at rounding level); the quick subset
(``quick=True``) is checked by the normal test suite.

A case *regresses in time* when its current ratio exceeds the median of the
same machine's last :data:`HISTORY_RUNS` recorded ratios by more than
:data:`TIME_FACTOR` (:func:`compare_times`). The division by the workload
does not make ratios portable (a case and the workload use the CPU
differently), so the time ratios are kept per machine
(``baselines.json`` ``"machines"``, keyed by :func:`machine_id`: CPU model,
cores, architecture, system, not the host name), each run with its
provenance (versions, threads, time). A machine without a history is not
compared with another one's: the summary says so, and ``--update-baselines``
starts its history.

Noise of the time flags, measured on the machine of the stored history
(AMD EPYC, 2 cores, x86_64, Linux, shared with other jobs, load average
1.6 to 2.0): two back-to-back runs of the suite on an unchanged checkout
gave per-case ratios (second run over first) from 0.62 to 1.50, median
1.02, standard deviation 0.18; 23 of the 31 cases within 0.85 to 1.20, the
widest spreads on the sub-millisecond Painlevé-rod cases (0.62 to 0.82),
the forced QP at 185 Hz (0.75), fd185 Lemke (1.43) and the stick-slip
motor at theta = 1/2 (1.50). That one case of 31 reached the 1.5x flag on
unchanged code: on such a machine a single flag is noise until a rerun
repeats it. The reference, a median over up to :data:`HISTORY_RUNS` runs,
keeps one odd recorded run from moving it.

Examples
--------
>>> m = measure("sliding-block/mj-theta1/N100")
>>> round(m["error"], 3), m["trajectory_error"] > 0
(0.015, True)
>>> check_accuracy(m, {"error": m["error"], "trajectory_error": m["trajectory_error"]})
[]
"""

import json
import math
import os
import statistics
import time

import numpy as np

from ..errors import InputError, MoreauError
from ..provenance import machine, provenance
from .compare import make_case, run_row
from .engine import code_version

__all__ = ["CASES", "measure", "check_accuracy", "time_ratio_flag", "calibration_time",
           "load_baselines", "save_baselines", "load_time_history", "machine_id",
           "reference_time_ratios", "compare_times", "record_times", "ACCURACY_SLACK",
           "ACCURACY_FLOOR", "TIME_FACTOR", "HISTORY_RUNS", "HISTORY_KEEP", "QUICK"]

#: relative slack on a stored error before it counts as a regression
ACCURACY_SLACK = 0.10
#: absolute slack, for errors at rounding level
ACCURACY_FLOOR = 1e-12
#: a run time ratio this many times the machine's reference is flagged
TIME_FACTOR = 1.5
#: the machine's reference ratio is the median over this many of its latest runs
HISTORY_RUNS = 5
#: runs kept per machine in ``benchmarks/baselines.json``
HISTORY_KEEP = 20

_SCENES = {
    "fd20": ("friction-drive", {"frequency": 20.0}),
    "fd185": ("friction-drive", {"frequency": 185.0}),
    "fd2000": ("friction-drive", {"frequency": 2000.0}),
    "stick-slip": ("stick-slip-motor", {}),
    "ball": ("bouncing-ball", {}),
    "sliding-block": ("sliding-block", {}),
    "painleve": ("painleve-rod", {}),
}
# scene key -> (reference rtol, [(theta, lcp, steps)], quick subset)
_PLAN = {
    "fd20": (1e-8, [(1.0, None, 1000), (0.5, None, 1000), (1.0, "lemke", 100)]),
    "fd185": (1e-8, [(1.0, None, 200), (1.0, None, 1000), (1.0, None, 5000), (0.5, None, 1000),
                     (1.0, "lemke", 100), (1.0, "qp", 50)]),
    "fd2000": (1e-8, [(1.0, None, 1000), (0.5, None, 1000), (1.0, "lemke", 100)]),
    "stick-slip": (None, [(1.0, None, 200), (0.5, None, 200), (1.0, "lemke", 100)]),
    "ball": (None, [(1.0, None, 104), (0.5, None, 104), (1.0, "lemke", 52)]),
    "sliding-block": (None, [(1.0, None, 100), (0.5, None, 100), (1.0, "qp", 50)]),
    "painleve": (1e-8, [(1.0, None, 100), (0.5, None, 100), (1.0, "lemke", 50)]),
}
#: cases run by the normal test suite (a few seconds in all)
QUICK = ("fd185/reference", "fd185/mj-theta1/N1000", "fd185/mj-theta0.5/N1000",
         "fd2000/mj-theta0.5/N1000", "fd185/lemke/N100", "sliding-block/mj-theta1/N100",
         "ball/mj-theta1/N104", "painleve/mj-theta1/N100", "stick-slip/mj-theta1/N200")


def _key(scene, theta, lcp, n):
    if lcp is not None:
        return f"{scene}/{lcp}/N{n}"
    return f"{scene}/mj-theta{theta:g}/N{n}"


def _build():
    cases = {}
    for scene, (rtol, runs) in _PLAN.items():
        if rtol is not None or scene in ("stick-slip", "ball", "sliding-block"):
            cases[f"{scene}/reference"] = dict(scene=scene, kind="ref", theta=None, lcp=None,
                                               setting=rtol)
        for theta, lcp, n in runs:
            cases[_key(scene, theta, lcp, n)] = dict(scene=scene, kind="mj", theta=theta,
                                                     lcp=lcp, setting=n)
    return cases


#: case key -> dict(scene, kind ("ref" or "mj"), theta, lcp, setting)
CASES = _build()
_CACHE = {}


def _setup(scene_key):
    """The compare case of a scene and its tight reference (cached per process)."""
    if scene_key not in _CACHE:
        name, params = _SCENES[scene_key]
        case = make_case(name, **params)
        ref_value, ref_switches = case.reference(case.tight_rtol)
        _CACHE[scene_key] = (case, ref_value, ref_switches)
    return _CACHE[scene_key]


def runner(key):
    """A zero-argument callable doing the timed work of case ``key`` (for the benchmarks)."""
    c = _spec(key)
    case, _, _ = _setup(c["scene"])
    if c["kind"] == "ref":
        return lambda: case.reference(c["setting"])
    return lambda: case.mj(c["setting"], c["theta"], c["lcp"])


def _spec(key):
    if key not in CASES:
        raise InputError(f"`key` must be one of the regression cases ({len(CASES)}; e.g. "
                         f"{next(iter(CASES))!r}), got {key!r}")
    return CASES[key]


def measure(key):
    """Errors of case ``key``: ``{"error", "trajectory_error", "switching_error"}``.

    Raises :class:`~moreau.errors.MoreauError` if the run fails.
    """
    c = _spec(key)
    case, ref_value, ref_switches = _setup(c["scene"])
    row = run_row(case, c["kind"], c["theta"], c["lcp"], c["setting"], 1, ref_value,
                  ref_switches)
    if row["status"] != 0:
        raise MoreauError(f"regression case {key} failed: {row['message']}")
    return {k: row[k] for k in ("error", "trajectory_error", "switching_error")}


def check_accuracy(measured, baseline):
    """Messages for every error of ``measured`` worse than its ``baseline`` (empty if none)."""
    out = []
    for k in ("error", "trajectory_error"):
        b, m = baseline.get(k), measured.get(k)
        if b is None:
            continue
        if m is None or not np.isfinite(m):
            out.append(f"{k}: {m!r} where the baseline is {b:.3e}")
        elif m > b * (1.0 + ACCURACY_SLACK) + ACCURACY_FLOOR:
            out.append(f"{k}: {m:.3e} is worse than the baseline {b:.3e} "
                       f"({m / b if b else float('inf'):.2f}x)")
    return out


def calibration_time(repeat=15):
    """Median time of a fixed workload: the in-process time baseline.

    Interpreted Python and small numpy calls, like the schemes' generic
    paths; no BLAS, whose threads make timings erratic on a shared machine.
    """
    x = np.linspace(0.0, 1.0, 64)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        acc = 0.0
        for i in range(2000):
            acc += float(np.dot(np.sin(x + i), x)) + math.fmod(i, 7.0)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def time_ratio_flag(ratio, baseline_ratio):
    """``(slowdown, flagged)``: current over stored time ratio, and whether it exceeds 1.5x.

    Examples
    --------
    >>> time_ratio_flag(3.0, 1.5)
    (2.0, True)
    """
    if not baseline_ratio:
        return None, False
    slow = ratio / baseline_ratio
    return slow, slow > TIME_FACTOR


def machine_id(info=None):
    """The key of a machine's time history: CPU model, cores, architecture and system.

    Parameters
    ----------
    info : dict, optional
        As returned by :func:`moreau.provenance.machine` (this machine's by default).

    Examples
    --------
    >>> machine_id({"cpu": "AMD EPYC", "cpu_count": 2, "architecture": "x86_64",
    ...             "system": "Linux"})
    'AMD EPYC / 2 cores / x86_64 / Linux'
    """
    info = machine() if info is None else info
    return f"{info['cpu']} / {info['cpu_count']} cores / {info['architecture']} / {info['system']}"


def reference_time_ratios(machines, mid, runs=HISTORY_RUNS):
    """Per case, the median time ratio of the machine ``mid`` over its last ``runs`` runs.

    Parameters
    ----------
    machines : dict
        The time histories (:func:`load_time_history`).
    mid : str
        A machine's key (:func:`machine_id`).
    runs : int
        How many of its latest runs the median is over.

    Returns
    -------
    dict or None
        ``{case key: ratio}``; None when the machine has no recorded run (its
        times are then not compared: another machine's ratios would be no
        reference).

    Examples
    --------
    >>> hist = {"m": {"runs": [{"time_ratios": {"a": 1.0}}, {"time_ratios": {"a": 3.0}},
    ...                        {"time_ratios": {"a": 2.5, "b": 4.0}}]}}
    >>> reference_time_ratios(hist, "m"), reference_time_ratios(hist, "m", runs=1)
    ({'a': 2.5, 'b': 4.0}, {'a': 2.5, 'b': 4.0})
    >>> reference_time_ratios(hist, "another machine") is None
    True
    """
    recent = (machines or {}).get(mid, {}).get("runs", [])[-int(runs):]
    if not recent:
        return None
    keys = sorted({k for r in recent for k in r.get("time_ratios", {})})
    out = {}
    for key in keys:
        vals = [r["time_ratios"][key] for r in recent if r["time_ratios"].get(key)]
        if vals:
            out[key] = statistics.median(vals)
    return out


def compare_times(ratios, machines, mid=None):
    """Each case's time ratio against this machine's history: slowdowns, flags and a summary.

    Parameters
    ----------
    ratios : dict
        ``{case key: time ratio}`` of the run at hand.
    machines : dict
        The time histories (:func:`load_time_history`).
    mid : str, optional
        The machine that took ``ratios`` (this one by default).

    Returns
    -------
    dict
        ``flags`` (``{key: (slowdown or None, flagged)}``), ``flagged`` (the
        keys over :data:`TIME_FACTOR`), ``compared`` (whether the machine
        had a history) and ``note`` (one line for the summary).

    Examples
    --------
    >>> hist = {"A / 2 cores / x86_64 / Linux": {"runs": [{"time_ratios": {"k": 1.0}}]}}
    >>> compare_times({"k": 2.0}, hist, "A / 2 cores / x86_64 / Linux")["flagged"]
    ['k']
    >>> compare_times({"k": 2.0}, hist, "B / 8 cores / arm64 / Darwin")["note"]
    'no time history for this machine (B / 8 cores / arm64 / Darwin): times not compared (the history holds 1 other machine); --update-baselines starts one'
    """
    mid = machine_id() if mid is None else mid
    ref = reference_time_ratios(machines, mid)
    if ref is None:
        others = len([m for m in (machines or {}) if m != mid])
        note = (f"no time history for this machine ({mid}): times not compared (the history "
                f"holds {others} other machine{'' if others == 1 else 's'}); "
                "--update-baselines starts one")
        return {"flags": {k: (None, False) for k in ratios}, "flagged": [], "compared": False,
                "note": note}
    flags = {k: time_ratio_flag(r, ref.get(k)) for k, r in ratios.items()}
    flagged = sorted(k for k, (_, f) in flags.items() if f)
    n = min(len(machines[mid]["runs"]), HISTORY_RUNS)
    note = (f"{len(flagged)} time regression(s) over {TIME_FACTOR}x the median of this "
            f"machine's last {n} run{'' if n == 1 else 's'} ({mid})")
    return {"flags": flags, "flagged": flagged, "compared": True, "note": note}


def record_times(machines, ratios, info=None, run_provenance=None, keep=HISTORY_KEEP):
    """The time histories with one more run of this machine (a new dict; ``machines`` is kept).

    Parameters
    ----------
    machines : dict
        The time histories (:func:`load_time_history`).
    ratios : dict
        ``{case key: time ratio}`` of the run.
    info : dict, optional
        The machine (:func:`moreau.provenance.machine`; this one by default).
    run_provenance : dict, optional
        Versions, threads and time of the run (:func:`moreau.provenance.provenance`
        by default).
    keep : int
        The latest runs kept per machine.

    Examples
    --------
    >>> info = {"cpu": "A", "cpu_count": 2, "architecture": "x86_64", "system": "Linux"}
    >>> h = {}
    >>> for r in (1.0, 2.0, 3.0):
    ...     h = record_times(h, {"k": r}, info, run_provenance={}, keep=2)
    >>> [run["time_ratios"]["k"] for run in h["A / 2 cores / x86_64 / Linux"]["runs"]]
    [2.0, 3.0]
    """
    info = machine() if info is None else dict(info)
    mid = machine_id(info)
    out = json.loads(json.dumps(machines or {}))
    mine = out.setdefault(mid, {"machine": info, "runs": []})
    mine["machine"] = info
    if run_provenance is None:
        run_provenance = provenance(code_version())
    mine["runs"].append({"provenance": run_provenance,
                         "time_ratios": dict(sorted(ratios.items()))})
    mine["runs"] = mine["runs"][-int(keep):]
    return out


def default_baselines_path():
    return os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "benchmarks", "baselines.json")


def _read(path):
    with open(path or default_baselines_path()) as fh:
        return json.load(fh)


def load_baselines(path=None):
    """The stored accuracy baselines: ``{key: {"error", "trajectory_error"}}``."""
    return _read(path)["cases"]


def load_time_history(path=None):
    """The stored time histories: ``{machine id: {"machine": dict, "runs": [...]}}``.

    Each run holds its provenance (versions, threads, time) and
    ``time_ratios`` (``{case key: ratio}``). A file without histories gives ``{}``.
    """
    try:
        return _read(path).get("machines", {})
    except FileNotFoundError:
        return {}


def save_baselines(cases, path=None, machines=None):
    """Write the accuracy baselines ``cases`` and the time histories ``machines``.

    A ``time_ratio`` of an older file is dropped: it was stored without the
    machine that measured it, and is no reference for any machine.
    """
    path = path or default_baselines_path()
    cases = {k: {f: v for f, v in cases[k].items() if f != "time_ratio"} for k in sorted(cases)}
    with open(path, "w") as fh:
        json.dump({"about": "accuracy baselines (cases) and per-machine time histories "
                            "(machines) of moreau.analysis.regression; update with: python -m "
                            "pytest benchmarks/test_regression.py -n 0 --update-baselines",
                   "cases": cases, "machines": machines or {}}, fh, indent=1)
        fh.write("\n")
