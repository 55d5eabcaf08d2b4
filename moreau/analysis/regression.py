"""Accuracy and speed regression cases: one per scheme and scene (``benchmarks/test_regression.py``).

Each case of :data:`CASES` is one row of :func:`moreau.analysis.compare.compare`
(a scheme at one setting on one scene) and measures its headline and
trajectory errors against the scene's tight reference. The accepted errors
are stored in ``benchmarks/baselines.json`` with, for speed, the case's run
time divided by a fixed numpy workload timed in the same process
(``time_ratio``), so that the stored figure does not depend on the machine.

A case *regresses in accuracy* when an error exceeds its baseline by more
than :data:`ACCURACY_SLACK` (relative) plus :data:`ACCURACY_FLOOR`
(absolute, for errors at rounding level); the quick subset
(``quick=True``) is checked by the normal test suite. A case *regresses in
time* when its current ratio exceeds the stored one by more than
:data:`TIME_FACTOR`; the benchmark suite reports those ratios.

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
from .compare import make_case, run_row

__all__ = ["CASES", "measure", "check_accuracy", "time_ratio_flag", "calibration_time",
           "load_baselines", "save_baselines", "ACCURACY_SLACK", "ACCURACY_FLOOR", "TIME_FACTOR",
           "QUICK"]

#: relative slack on a stored error before it counts as a regression
ACCURACY_SLACK = 0.10
#: absolute slack, for errors at rounding level
ACCURACY_FLOOR = 1e-12
#: a run time ratio this many times the stored one is flagged
TIME_FACTOR = 1.5

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


def default_baselines_path():
    return os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "benchmarks", "baselines.json")


def load_baselines(path=None):
    """The stored baselines: ``{key: {"error", "trajectory_error", "time_ratio"}}``."""
    path = path or default_baselines_path()
    with open(path) as fh:
        return json.load(fh)["cases"]


def save_baselines(cases, path=None):
    path = path or default_baselines_path()
    with open(path, "w") as fh:
        json.dump({"about": "accuracy and time baselines of moreau.analysis.regression; "
                            "update with: python -m pytest benchmarks/test_regression.py "
                            "--update-baselines",
                   "cases": {k: cases[k] for k in sorted(cases)}}, fh, indent=1)
        fh.write("\n")
