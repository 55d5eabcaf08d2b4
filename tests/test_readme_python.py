"""Every Python snippet of the README and of the guide's pages in docs/ runs, each in its own
fresh copy of an interpreter.

A snippet that names what an earlier paragraph defines (an LCP's ``M`` and
``q``; the README's compiled model, its user's scene of the snippet before)
gets those names from a preamble here; a snippet added to the guide without
an entry fails ``test_the_table_covers_every_python_snippet``.
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
#: the README and the guide's pages (tutorial.md only includes the README)
GUIDE = [README] + sorted(p for p in (ROOT / "docs").glob("*.md")
                          if p.name not in ("index.md", "tutorial.md"))

#: the README's own tour of the API: the front ends, a user's scene, its compiled model
README_FIRSTS = {"from moreau import find_steady_state, simulate", "from moreau import compare",
                 "import numpy as np", "from numba import njit", "import math"}


def python_snippets(*pages):
    text = "\n".join(p.read_text() for p in (pages or GUIDE))
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


#: first line of a snippet -> the preamble that defines what it takes from the prose
PREAMBLES = {
    "from moreau import find_steady_state, simulate": "",
    "from moreau import compare": "",
    "import numpy as np": "",
    # the README's compiled model extends the scene of the snippet before it
    "from numba import njit": None,
    "from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams": "",
    "from moreau.integrators import simulate": "",
    "import math": "",
    "from moreau.scenes.piezo_drive import PiezoDrive, identify_hysteresis": "",
    "from moreau.lcp import solve_lcp, build_friction_lcp": (
        "import numpy as np\n"
        "M = np.array([[2.0, 1.0], [1.0, 2.0]])\n"
        "q = np.array([-5.0, -6.0])\n"),
    # the guide's short registration: a ball scene and its case under the guide's names
    "register_scene(SceneEntry(": (
        "from moreau.model.registry import SceneEntry, get_entry, register_scene\n"
        "from moreau.scenes.bouncing_ball import BouncingBall as Ball\n"
        "from moreau.scenes.bouncing_ball import BouncingBallCase as BallCase\n"),
}

#: what each snippet's last names must hold after it ran (a check that could fail)
CHECKS = {
    "register_scene(SceneEntry(":
        "e, ref = get_entry('ball'), get_entry('bouncing-ball')\n"
        "assert e.parameters == ref.parameters and e.sweepable == ref.sweepable\n"
        "assert e.reference == 'exact' and e.mj_tolerance == BallCase.mj_tolerance == 5e-2",
    "import math":
        "assert res.success and abs(down / (9.81 * math.sin(slope) / 3.0 * si['t'][-1] ** 2)"
        " - 1.0) < 0.01",
    "from moreau import find_steady_state, simulate":
        "assert ss.mode == 'NP' and res.success and res.stats['lcp_solves'] > 0\n"
        "assert abs(si['t'][-1] - 10 / 185.0) < 1e-9",
    "from moreau import compare":
        "assert {r['scheme'] for r in rep['rows']} >= {'exact', 'moreau-jean'}\n"
        "assert all(r['status'] == 0 for r in rep['rows']) and rep['orders']",
    "import numpy as np":
        "assert report.ok and res.success and ref.success\n"
        "assert res.stats['lcp_solves'] > 0 and abs(res.q[-1, 1]) < 1e-12",
    # the compiled loop and the generic Python step of the same scene agree to rounding
    "from numba import njit":
        "slow = simulate(BeltBlock(), (0.0, 4.0), q0, v0, 'moreau-jean', h=0.01, fast=False)\n"
        "assert res.success and np.allclose(res.q, slow.q, rtol=0, atol=1e-12)",
    "from moreau.scenes.friction_drive import FrictionDrive, FrictionDriveParams":
        "assert ss.mode == 'NP' and res.success and si['t'][-1] > 0 and len(df) == len(res.t)",
    "from moreau.integrators import simulate":
        "assert res.success and res.stats['lcp_solves'] > 0 and ss.mode",
    "from moreau.scenes.piezo_drive import PiezoDrive, identify_hysteresis":
        "assert abs(fit.alpha - 0.3) < 1e-6 and abs(fit.beta - 0.02) < 1e-8 and ss.mode",
    "from moreau.lcp import solve_lcp, build_friction_lcp":
        "assert res.success and abs(res.z @ res.w) < 1e-12",
}


def _snippet(first):
    (code,) = [s for s in python_snippets(README) if s.startswith(first + "\n")]
    return code


PREAMBLES["from numba import njit"] = _snippet("import numpy as np")


def test_the_table_covers_every_python_snippet():
    firsts = [s.splitlines()[0] for s in python_snippets()]
    assert len(firsts) >= 4
    assert sorted(firsts) == sorted(PREAMBLES) == sorted(CHECKS)


def test_the_readme_tours_the_front_ends():
    # simulate, compare, find_steady_state, check_scene, a user's scene and CompiledModel
    firsts = {s.splitlines()[0] for s in python_snippets(README)}
    assert firsts == README_FIRSTS
    code = "\n".join(python_snippets(README))
    for name in ("simulate(", "compare(", "find_steady_state(", "check_scene(", "(Scene)",
                 "CompiledModel("):
        assert name in code, name


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
