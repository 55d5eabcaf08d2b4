"""The API reference builds from the docstrings without a warning, so that it cannot rot."""

import importlib.util
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).parents[1]
DOCS = ROOT / "docs"


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("sphinx") is None,
                    reason='sphinx is not installed: pip install -e ".[docs]"')
def test_the_reference_builds_without_warnings(tmp_path):
    # slow: the whole reference read by Sphinx, 10 CPU s (the default run's largest check
    # of its own; tests/test_readme.py holds the guide's pages to the program meanwhile)
    # the dummy builder reads and resolves every page (autodoc, numpydoc, the README, the
    # notebooks) like the html one, without writing pages: a warning is an error (-W)
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "dummy",
                           "-q", "-d", str(tmp_path / "doctrees"), str(DOCS), str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-4000:]


def test_every_public_module_has_a_page():
    # a module named on no page would be missing from the reference without a warning
    pages = "\n".join(p.read_text() for p in (DOCS / "api").glob("*.rst"))
    for name in ("moreau.integrators.base", "moreau.integrators.result", "moreau.model.registry",
                 "moreau.analysis.steady_state", "moreau.lcp", "moreau.errors"):
        assert f".. automodule:: {name}\n" in pages, name
    schemes = sorted(p.stem for p in (ROOT / "moreau" / "integrators").glob("[!_]*.py")
                     if p.stem not in ("__init__",))
    for stem in schemes:
        assert f".. automodule:: moreau.integrators.{stem}\n" in pages, stem
