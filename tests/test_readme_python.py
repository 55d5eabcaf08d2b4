"""Every Python snippet of the README runs, each in its own fresh copy of an interpreter.

A snippet that names what an earlier paragraph defines (an LCP's ``M`` and
``q``, a user's ``scene``) gets those names from a preamble here; a snippet
added to the README without an entry fails
``test_the_table_covers_every_python_snippet``.
"""

import json
import os
import pathlib
import re
import subprocess
import sys

import pytest

import moreau

ROOT = pathlib.Path(moreau.__file__).resolve().parent.parent
README = ROOT / "README.md"


def python_snippets():
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


#: first line of a snippet -> the preamble that defines what it takes from the prose
PREAMBLES = {
    "from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams": "",
    "from moreau.integrators import simulate": "",
    "from moreau.scenes.piezo_drive import PiezoDrive, identify_hysteresis": "",
    "from moreau.lcp import solve_lcp, build_friction_lcp": (
        "import numpy as np\n"
        "M = np.array([[2.0, 1.0], [1.0, 2.0]])\n"
        "q = np.array([-5.0, -6.0])\n"),
    "import moreau": (
        "import sys\n"
        f"sys.path.insert(0, {str(ROOT / 'tests' / 'engine')!r})\n"
        "from belt_scene import BeltBlock\n"
        "scene = BeltBlock()\n"
        "q0, v0 = scene.initial_state()\n"),
}

#: what each snippet's last names must hold after it ran (a check that could fail)
CHECKS = {
    "from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams":
        "assert ss.mode == 'NP' and res.success and si['t'][-1] > 0 and len(df) == len(res.t)",
    "from moreau.integrators import simulate":
        "assert res.success and res.stats['lcp_solves'] > 0 and ss.mode",
    "from moreau.scenes.piezo_drive import PiezoDrive, identify_hysteresis":
        "assert abs(fit.alpha - 0.3) < 1e-6 and abs(fit.beta - 0.02) < 1e-8 and ss.mode",
    "from moreau.lcp import solve_lcp, build_friction_lcp":
        "assert res.success and abs(res.z @ res.w) < 1e-12",
    "import moreau":
        "assert res.success and ref.success and rep['rows']",
}


def test_the_table_covers_every_python_snippet():
    firsts = [s.splitlines()[0] for s in python_snippets()]
    assert len(firsts) >= 4
    assert sorted(firsts) == sorted(PREAMBLES) == sorted(CHECKS)


# One interpreter imports the package and its libraries once (0.8 s of every fresh start),
# then forks a child per snippet: each snippet runs in a copy of that interpreter, which
# holds nothing a snippet or a test made (import-order bugs of a really fresh interpreter
# are tests/engine/test_fresh_processes.py's).
_FORK_SERVER = """
import json, os, sys, traceback
import moreau, moreau.analysis.steady_state, moreau.integrators, moreau.lcp
import moreau.scenes.friction_drive, moreau.scenes.piezo_drive
for line in sys.stdin:
    code = json.loads(line)
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        os.dup2(w, 2)
        os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
        try:
            exec(compile(code, "<snippet>", "exec"), {"__name__": "__main__"})
            rc = 0
        except BaseException:
            traceback.print_exc()
            rc = 1
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(rc)
    os.close(w)
    with os.fdopen(r, "rb") as fh:
        err = fh.read().decode(errors="replace")
    status = os.waitpid(pid, 0)[1]
    print(json.dumps([status, err]), flush=True)
"""


@pytest.fixture(scope="module")
def run_snippet():
    if not hasattr(os, "fork"):
        def run(code):
            run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                 timeout=600, cwd=ROOT)
            return run.returncode, run.stderr
        yield run
        return
    server = subprocess.Popen([sys.executable, "-c", _FORK_SERVER], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True, cwd=ROOT)

    def run(code):
        server.stdin.write(json.dumps(code) + "\n")
        server.stdin.flush()
        return json.loads(server.stdout.readline())
    yield run
    server.stdin.close()
    server.wait(timeout=60)


@pytest.mark.parametrize("i", range(len(python_snippets())))
def test_every_python_snippet_runs(i, run_snippet):
    snippet = python_snippets()[i]
    first = snippet.splitlines()[0]
    code = PREAMBLES[first] + snippet + "\n" + CHECKS[first] + "\n"
    status, stderr = run_snippet(code)      # exit status: 0 only if the snippet ran through
    assert status == 0, stderr[-3000:]
