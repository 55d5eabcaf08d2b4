"""What a new user meets in a fresh interpreter: every module imports alone
(``moreau compare --scene NAME --quick`` on every registered scene is in
``tests/test_imports.py``)."""

import json
import os
import pathlib
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor


import moreau

PACKAGE = pathlib.Path(moreau.__file__).parent
MODULES = sorted(
    ".".join(("moreau",) + p.relative_to(PACKAGE).with_suffix("").parts).removesuffix(".__init__")
    for p in PACKAGE.rglob("*.py") if p.name != "__main__.py")


def _import_alone(module):
    run = subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True,
                         text=True, timeout=300)
    return module, run.returncode, run.stderr.strip().splitlines()[-1:] if run.returncode else []


def test_every_module_imports_alone_in_a_fresh_interpreter():
    # import-order bugs (circles) hide inside one test process
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        failed = [r for r in pool.map(_import_alone, MODULES) if r[1] != 0]
    assert len(MODULES) > 40
    assert failed == []


def test_a_scene_reference_is_found_from_the_scene_module_alone():
    # the import that failed with "partially initialized module" before the registry
    code = ("from moreau.scenes.stick_slip_exact import stick_slip_steady_state\n"
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
