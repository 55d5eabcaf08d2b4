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
