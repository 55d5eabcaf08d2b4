"""Peers in the suite: Siconos's one-step integrators as columns, where Siconos is installed.

Siconos runs under the system interpreter (``/usr/bin/python3`` with Debian's
``python3-siconos``), not the project's, through the checkout's peer script
``benchmarks/siconos_osis.py`` (one OSI per process: a Siconos assertion
aborts its interpreter). A peer column is ``siconos:<OSI>``. A problem states
its Siconos model by ``siconos_case(scene)`` (the peer script's case and
arguments, or None) and reads its headline quantities from the script's
output by ``siconos_values(output)``; on a problem without one the cell is
refused by name. The peer's step is the script's own (``h = 2 pi / 1000`` on
the friction drive), so a peer column has one setting; its time is the wall
time of Siconos's stepping loop as the script measures it.

Examples
--------
>>> from moreau.suite.problem import get_problem
>>> p = get_problem("bouncing-ball")
>>> run_peer_cell(p, "siconos:MoreauJeanOSI", p.make_scene())["outcome"]
'refused'
"""

import functools
import json
import os
import pathlib
import subprocess

from .problem import judge

__all__ = ["SICONOS_PYTHON", "SICONOS_OSIS", "peer_script", "siconos_available", "peer_names",
           "is_peer", "run_peer_cell", "PEER_SETTING"]

SICONOS_PYTHON = "/usr/bin/python3"
#: the OSIs of the peer script that take the suite's problems (MoreauJeanBilbaoOSI needs a
#: linear modal system: none of them)
SICONOS_OSIS = ("MoreauJeanOSI", "MoreauJeanCombinedProjectionOSI",
                "MoreauJeanDirectProjectionOSI", "MoreauJeanGOSI", "LsodarOSI")
#: the one setting of a peer column
PEER_SETTING = "peer"
#: seconds a peer run may take
PEER_TIMEOUT_S = 600


def peer_script():
    """The checkout's ``benchmarks/siconos_osis.py``, or None outside a checkout."""
    path = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "siconos_osis.py"
    return path if path.exists() else None


@functools.lru_cache(maxsize=1)
def siconos_available():
    """Whether the system interpreter imports Siconos and the peer script is there."""
    if peer_script() is None or not os.path.exists(SICONOS_PYTHON):
        return False
    try:
        done = subprocess.run([SICONOS_PYTHON, "-c", "import siconos.kernel"],
                              capture_output=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done.returncode == 0


def peer_names():
    """The peer columns available here (none without Siconos)."""
    return [f"siconos:{osi}" for osi in SICONOS_OSIS] if siconos_available() else []


def is_peer(name):
    return isinstance(name, str) and name.startswith("siconos:")


def _row(problem, scheme):
    return {"problem": problem.name, "scheme": scheme, "setting": PEER_SETTING, "outcome": None,
            "cause": "", "status": None, "values": {}, "errors": {}, "max_error": None,
            "tolerance": problem.tolerance, "cpu_s": None, "wall_s": None, "steps": None}


def run_peer_cell(problem, scheme, scene, reference=None, judged=True):
    """One peer cell: the Siconos OSI of ``scheme`` on ``problem`` (a row as ``run_cell``'s;
    ``judged=False``: a finished run left for :func:`~moreau.suite.problem.judge`)."""
    row = _row(problem, scheme)
    osi = scheme.split(":", 1)[1]
    case = getattr(problem, "siconos_case", lambda s: None)(scene)
    if case is None:
        row.update(outcome="refused", cause=f"Siconos: the problem {problem.name!r} states no "
                                            "Siconos model")
        return row
    script = peer_script()
    if script is None or not siconos_available():
        row.update(outcome="refused", cause="Siconos is not installed here")
        return row
    name, args = case
    try:
        done = subprocess.run([SICONOS_PYTHON, str(script), name, osi, *args],
                              capture_output=True, text=True, timeout=PEER_TIMEOUT_S,
                              cwd=str(script.parent))
        out = json.loads(done.stdout.strip().splitlines()[-1])
    except subprocess.TimeoutExpired:
        row.update(outcome="failed", cause=f"Siconos {osi}: no result in {PEER_TIMEOUT_S} s")
        return row
    except (ValueError, IndexError):
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        row.update(outcome="failed", cause=f"Siconos {osi}: exit {done.returncode}: {tail}")
        return row
    if "error" in out:
        row.update(outcome="failed", cause=f"Siconos {osi}: {out['error']}")
        return row
    values = problem.siconos_values(out)
    row.update(values=values, cpu_s=out.get("seconds"), wall_s=out.get("seconds"),
               steps=out.get("steps"), status=0)
    return judge(problem, row, reference) if judged else row
