"""What a new user meets in a fresh interpreter: every module imports alone
(``moreau compare --scene NAME --quick`` on every registered scene is in
``tests/test_imports.py``)."""

import json
import os
import pathlib
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import pytest

import moreau

PACKAGE = pathlib.Path(moreau.__file__).parent
MODULES = sorted(
    ".".join(("moreau",) + p.relative_to(PACKAGE).with_suffix("").parts).removesuffix(".__init__")
    for p in PACKAGE.rglob("*.py") if p.name != "__main__.py")


# One interpreter loads the third-party libraries (numpy, scipy, numba: 0.45 s of
# every fresh start) by importing the package once, forgets every `moreau` module,
# then forks a child per module: each child imports its module into a state with
# no `moreau` module loaded, which is what a fresh interpreter sees of the package.
# Importing `a.b.c` imports `a`, then `a.b`, then `a.b.c` unless one of its parents
# loaded it: where a parent's child (run first: a parent sorts before its modules)
# loaded `a.b.c`, the import of `a.b.c` alone is that same run, statement for statement,
# and is not run again (71 of 206 children: a package whose __init__ imports its modules)
_FORK_IMPORTS = """
import importlib, json, os, sys
modules = json.loads(sys.argv[1])


def ours(k):
    return k == "moreau" or k.startswith("moreau.")


for m in modules:
    importlib.import_module(m)
for k in [k for k in sys.modules if ours(k)]:
    del sys.modules[k]
failed = []
loaded = {}
for m in modules:
    parts = m.split(".")
    if any(m in loaded.get(".".join(parts[:i]), ()) for i in range(1, len(parts))):
        continue
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        try:
            importlib.import_module(m)
            out = json.dumps({"loaded": sorted(k for k in sys.modules if ours(k))})
        except BaseException as exc:
            out = json.dumps({"error": f"{type(exc).__name__}: {exc}"[:4000]})
        data = out.encode()
        while data:
            data = data[os.write(w, data):]
        os._exit(0)
    os.close(w)
    chunks = []
    while True:
        chunk = os.read(r, 65536)
        if not chunk:
            break
        chunks.append(chunk)
    os.close(r)
    status = os.waitpid(pid, 0)[1]
    got = json.loads(b"".join(chunks).decode() or '{"error": "the child wrote nothing"}')
    if "error" in got or status:
        failed.append([m, got.get("error", f"exit status {status}")])
    else:
        loaded[m] = set(got["loaded"])
print(json.dumps(failed))
"""


def _import_alone(module):
    run = subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True,
                         text=True, timeout=300)
    return module, run.returncode, run.stderr.strip().splitlines()[-1:] if run.returncode else []


@pytest.mark.slow
def test_every_module_imports_alone_in_a_fresh_interpreter():
    # import-order bugs (circles) hide inside one test process. slow: a fork per module,
    # 8 CPU s; tests/test_layers.py reads every import statement for circles in the default
    # run
    assert len(MODULES) > 40
    if hasattr(os, "fork"):
        run = subprocess.run([sys.executable, "-c", _FORK_IMPORTS, json.dumps(MODULES)],
                             capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr
        assert json.loads(run.stdout.strip().splitlines()[-1]) == []
    else:
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
            failed = [r for r in pool.map(_import_alone, MODULES) if r[1] != 0]
        assert failed == []


def test_a_module_with_an_import_circle_is_caught(tmp_path):
    # the check itself: a circle that only one import order reveals (b first imports
    # both fine; a alone fails), the order the parent's warm-up does not take
    pkg = tmp_path / "moreau_circle_probe"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from . import b\nA = 1\n")
    (pkg / "b.py").write_text("from .a import A\nB = 2\n")
    code = _FORK_IMPORTS.replace('k == "moreau" or k.startswith("moreau.")',
                                 'k.startswith("moreau_circle_probe")')
    mods = ["moreau_circle_probe.b", "moreau_circle_probe.a"]
    run = subprocess.run([sys.executable, "-c", code, json.dumps(mods)],
                         capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    failed = json.loads(run.stdout.strip().splitlines()[-1])
    assert [m for m, _ in failed] == ["moreau_circle_probe.a"]
    assert "partially initialized module" in failed[0][1]


def test_a_scene_reference_is_found_from_the_scene_module_alone():
    # the import that failed with "partially initialized module" before the registry
    code = ("from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state\n"
            "from moreau.scenes.stick_slip_motor import StickSlipMotor\n"
            "print(round(stick_slip_steady_state(StickSlipMotor()).displacement_per_period, 6))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert float(out.stdout) != 0.0


def test_compare_set_takes_any_scene_parameter_and_refuses_an_unknown_one(tmp_path):
    base = [sys.executable, "-m", "moreau", "compare", "--scene", "bouncing-ball", "--quick",
            "--json", "--quiet", "--no-plot", "--out", str(tmp_path)]
    run = subprocess.run(base + ["--set", "restitution=0.9", "--set", "height=0.8"],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["parameters"]["restitution"] == 0.9
    bad = subprocess.run(base + ["--set", "stiffness=3"], capture_output=True, text=True,
                         timeout=600)
    assert bad.returncode == 2
    assert "`stiffness` is not a parameter of scene 'bouncing-ball'" in bad.stderr
