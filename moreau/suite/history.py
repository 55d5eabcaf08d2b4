"""The suite's regression history: each run recorded per machine, the next one compared to it.

``moreau suite --compare-to HISTORY`` reads ``HISTORY`` (a JSON file; the
format of ``benchmarks/baselines.json``, whose per-machine entries gain a
``"suite_runs"`` list beside the regression cases' ``"runs"``, so the same
file can hold both), flags the cells that regressed, and then records the run
in it. A cell is keyed ``problem/scheme/setting``. The flags:

``outcome``
    its outcome differs from the latest recorded run's (this machine's latest,
    or any machine's where this one has none);
``error``
    its largest error is above the problem's tolerance and grew beyond the
    latest recorded one (by more than the regression cases' slack: 10 %
    plus 1e-12);
``time``
    its CPU time, divided by a fixed workload timed in the same process
    (:func:`moreau.analysis.regression.calibration_time`), is above 1.5x the
    median of this machine's last five recorded runs. The cell is rerun first
    and flagged only if the rerun is slow as well. Cells under
    :data:`TIME_FLOOR_S` are not timed against the history (their times are
    scheduler noise). Another machine's times are never a reference.

Examples
--------
>>> hist = {"machines": {"m": {"suite_runs": [{"cells": {
...     "p/s/N=10": {"outcome": "ok", "max_error": 1e-3, "tolerance": 1e-2,
...                  "time_ratio": 1.0}}}]}}}
>>> row = {"problem": "p", "scheme": "s", "setting": "N=10", "outcome": "inaccurate",
...        "max_error": 0.2, "tolerance": 1e-2, "cpu_s": 0.1}
>>> [f["kind"] for f in compare_to_history([row], hist, "m", calibration=0.01)]
['outcome', 'error', 'time']
>>> fast = dict(row, cpu_s=0.005)         # the rerun is fast: no time flag
>>> [f["kind"] for f in compare_to_history([row], hist, "m", 0.01, rerun=lambda r: fast)]
['outcome', 'error']
"""

import json
import os
import statistics

from ..analysis.regression import (ACCURACY_FLOOR, ACCURACY_SLACK, HISTORY_KEEP, HISTORY_RUNS,
                                   TIME_FACTOR, calibration_time, machine_id)
from ..errors import InputError
from ..provenance import machine, provenance

__all__ = ["load_history", "compare_to_history", "record_run", "cell_key", "TIME_FLOOR_S"]

#: cells faster than this are not compared in time
TIME_FLOOR_S = 5e-3


def cell_key(row):
    return f"{row['problem']}/{row['scheme']}/{row['setting']}"


def load_history(path):
    """The history at ``path`` (an empty one where the file does not exist yet)."""
    if not os.path.exists(path):
        return {"about": "moreau suite history (per machine: suite_runs)", "machines": {}}
    try:
        with open(path) as fh:
            hist = json.load(fh)
    except (OSError, ValueError) as exc:
        raise InputError(f"`--compare-to` {path!r} cannot be read as a history: {exc}") from None
    if not isinstance(hist, dict) or not isinstance(hist.get("machines", {}), dict):
        raise InputError(f"`--compare-to` {path!r} is not a history (no `machines` mapping)")
    hist.setdefault("machines", {})
    return hist


def _runs(hist, mid):
    return ((hist.get("machines") or {}).get(mid) or {}).get("suite_runs") or []


def _latest(hist, mid):
    """The latest recorded run's cells: this machine's, else the newest of any machine."""
    own = _runs(hist, mid)
    if own:
        return own[-1]["cells"]
    runs = [r for m in (hist.get("machines") or {}) for r in _runs(hist, m)]
    if not runs:
        return {}
    return max(runs, key=lambda r: (r.get("provenance") or {}).get("time_utc", ""))["cells"]


def compare_to_history(rows, hist, mid=None, calibration=None, rerun=None):
    """The flags of ``rows`` against ``hist`` (see the module docstring), time flags after a rerun.

    ``rerun(row)`` returns a fresh row of the same cell (None: no rerun, the
    first measurement decides). Returns a list of ``{"cell", "kind", "text"}``.
    """
    mid = machine_id() if mid is None else mid
    last = _latest(hist, mid)
    recent = _runs(hist, mid)[-HISTORY_RUNS:]
    calibration = calibration_time() if calibration is None else calibration
    flags = []
    for row in rows:
        key = cell_key(row)
        old = last.get(key)
        if old is not None and old.get("outcome") != row["outcome"]:
            flags.append({"cell": key, "kind": "outcome",
                          "text": f"{key}: outcome {old.get('outcome')} -> {row['outcome']}"
                                  + (f" ({row['cause']})" if row.get("cause") else "")})
        new_err, old_err = row.get("max_error"), (old or {}).get("max_error")
        tol = row.get("tolerance")
        if (new_err is not None and old_err is not None and tol is not None and new_err > tol
                and new_err > old_err * (1.0 + ACCURACY_SLACK) + ACCURACY_FLOOR):
            flags.append({"cell": key, "kind": "error",
                          "text": f"{key}: error {old_err:.3g} -> {new_err:.3g}, above the "
                                  f"tolerance {tol:g}"})
        past = [r["cells"][key]["time_ratio"] for r in recent
                if (r["cells"].get(key) or {}).get("time_ratio")]
        cpu = row.get("cpu_s")
        if not past or cpu is None or cpu < TIME_FLOOR_S:
            continue
        median = statistics.median(past)
        if cpu / calibration <= TIME_FACTOR * median:
            continue
        if rerun is not None:
            again = rerun(row)
            if again.get("cpu_s") is not None:
                cpu = min(cpu, again["cpu_s"])
        if cpu / calibration > TIME_FACTOR * median:
            flags.append({"cell": key, "kind": "time",
                          "text": f"{key}: {cpu / calibration / median:.2f}x the median of this "
                                  f"machine's last {len(past)} run(s) (rerun: slow again)"})
    return flags


def record_run(path, hist, rows, calibration, quick, keep=HISTORY_KEEP):
    """Append this run's cells to this machine's ``suite_runs`` in ``hist`` and write ``path``."""
    mid = machine_id()
    entry = hist["machines"].setdefault(mid, {"machine": machine()})
    entry.setdefault("machine", machine())
    cells = {cell_key(r): {"outcome": r["outcome"], "max_error": r.get("max_error"),
                           "tolerance": r.get("tolerance"),
                           "time_ratio": (None if r.get("cpu_s") is None
                                          else r["cpu_s"] / calibration)}
             for r in rows}
    runs = entry.setdefault("suite_runs", [])
    runs.append({"provenance": provenance(), "quick": bool(quick), "cells": cells})
    del runs[:-int(keep)]
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as fh:
        json.dump(hist, fh, indent=1, default=lambda x: None if x != x else str(x))
    os.replace(tmp, path)
    return mid
