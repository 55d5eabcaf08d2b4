"""Every Python snippet of the README runs, in a fresh interpreter.

A snippet that names what an earlier paragraph defines (an LCP's ``M`` and
``q``, a user's ``scene``) gets those names from a preamble here; a snippet
added to the README without an entry fails
``test_the_table_covers_every_python_snippet``.
"""

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


@pytest.mark.parametrize("i", range(len(python_snippets())))
def test_every_python_snippet_runs(i):
    snippet = python_snippets()[i]
    first = snippet.splitlines()[0]
    code = PREAMBLES[first] + snippet + "\n" + CHECKS[first] + "\n"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600, cwd=ROOT)
    assert run.returncode == 0, run.stderr[-3000:]
