"""The version in one place, reachable from the command line and the installed metadata."""

import importlib.metadata
import pathlib
import subprocess
import sys

import pytest

import moreau

ROOT = pathlib.Path(__file__).parents[2]


def test_version_flag_prints_the_package_version(capsys):
    # the long flag through `python -m moreau` (the entry point), the short one through the
    # same parser in this process (a second interpreter start would check nothing more)
    run = subprocess.run([sys.executable, "-m", "moreau", "--version"], capture_output=True,
                         text=True)
    assert run.returncode == 0
    assert run.stdout.strip() == f"moreau {moreau.__version__}"
    from moreau.cli import main
    with pytest.raises(SystemExit) as stop:
        main(["-V"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"moreau {moreau.__version__}"


def test_the_version_is_written_once():
    assert importlib.metadata.version("moreau") == moreau.__version__
    assert 'dynamic = ["version"]' in (ROOT / "pyproject.toml").read_text()
    assert (ROOT / "moreau" / "py.typed").exists() and (ROOT / "LICENSE").exists()


def test_json_outputs_carry_their_provenance(tmp_path, capsys):
    import json
    # in a process of its own: the command line recorded is that process's
    run = subprocess.run([sys.executable, "-m", "moreau", "steady", "--frequency", "185", "--json"],
                         capture_output=True, text=True)
    prov = json.loads(run.stdout)["provenance"]
    assert prov["moreau_version"] == moreau.__version__
    assert prov["numpy_version"] and prov["scipy_version"] and prov["numba_version"]
    assert prov["cpu_count"] >= 1 and prov["cpu"]
    assert prov["command"].endswith("steady --frequency 185 --json")
    # the comparison's report, whose command line is not checked: in this process
    from moreau.cli import main
    assert main(["compare", "--scene", "sliding-block", "--quick", "--json", "--quiet",
                 "--no-plot", "--out", str(tmp_path)]) in (0, None)
    rep = json.loads(capsys.readouterr().out)
    assert rep["provenance"]["moreau_version"] == moreau.__version__
    assert "median wall time" in rep["time_s_meaning"]


def test_the_public_front_ends_are_annotated():
    # py.typed promises type hints: every parameter and the return of the front
    # ends that `import moreau` offers carry an annotation
    import inspect
    import moreau
    for name in ("simulate", "compare", "find_steady_state", "check_scene"):
        sig = inspect.signature(getattr(moreau, name))
        missing = [p for p, v in sig.parameters.items() if v.annotation is inspect.Parameter.empty]
        assert not missing, f"{name}: no annotation on {missing}"
        assert sig.return_annotation is not inspect.Signature.empty, f"{name}: no return annotation"


def test_changelog_notebook_extra_and_guide_links():
    # issue 21's packaging items: a changelog, a [notebook] extra with jupyter that the
    # notebooks name (not the empty [plot]), the tutorial and every notebook in the reference
    import tomllib
    assert (ROOT / "CHANGELOG.md").read_text().startswith("# Changelog")
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    assert any(d.startswith("jupyter") for d in extras["notebook"])
    index = (ROOT / "docs" / "index.md").read_text()
    assert "\ntutorial\n" in index
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        text = nb.read_text()
        assert '.[plot]' not in text, nb.name
        assert f"notebooks/{nb.stem}\n" in index, nb.name
