"""The version in one place, reachable from the command line and the installed metadata."""

import importlib.metadata
import pathlib
import subprocess
import sys

import moreau

ROOT = pathlib.Path(__file__).parents[2]


def test_version_flag_prints_the_package_version():
    for flag in ("--version", "-V"):
        run = subprocess.run([sys.executable, "-m", "moreau", flag], capture_output=True, text=True)
        assert run.returncode == 0
        assert run.stdout.strip() == f"moreau {moreau.__version__}"


def test_the_version_is_written_once():
    assert importlib.metadata.version("moreau") == moreau.__version__
    assert 'dynamic = ["version"]' in (ROOT / "pyproject.toml").read_text()
    assert (ROOT / "moreau" / "py.typed").exists() and (ROOT / "LICENSE").exists()


def test_json_outputs_carry_their_provenance(tmp_path):
    import json
    run = subprocess.run([sys.executable, "-m", "moreau", "steady", "--frequency", "185", "--json"],
                         capture_output=True, text=True)
    prov = json.loads(run.stdout)["provenance"]
    assert prov["moreau_version"] == moreau.__version__
    assert prov["numpy_version"] and prov["scipy_version"] and prov["numba_version"]
    assert prov["cpu_count"] >= 1 and prov["cpu"]
    assert prov["command"].endswith("steady --frequency 185 --json")
    run = subprocess.run([sys.executable, "-m", "moreau", "compare", "--scene", "sliding-block",
                          "--quick", "--json", "--quiet", "--no-plot", "--out", str(tmp_path)],
                         capture_output=True, text=True)
    rep = json.loads(run.stdout)
    assert rep["provenance"]["moreau_version"] == moreau.__version__
    assert "median wall time" in rep["time_s_meaning"]
