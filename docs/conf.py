"""Sphinx configuration of the API reference (``pip install -e ".[docs]"``).

Build: ``sphinx-build -W -b html docs docs/_build/html``. The reference is
read from the numpydoc docstrings; the notebooks are rendered by myst-nb
without being executed (they are committed without outputs; the tests run
them).
"""

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
# the checkout's package, also where it is not installed
sys.path.insert(0, str(ROOT))

import moreau  # noqa: E402

project = "moreau"
author = "the moreau developers"
copyright = "the moreau developers"
version = release = moreau.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "figures", "notebooks/.ipynb_checkpoints"]

# the notebooks are shown as committed: their cells run in the tests, not here
nb_execution_mode = "off"
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True}
# the members of a class are documented by autodoc; numpydoc's own table of them would
# list each twice
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# no autosummary stubs are generated (the pages name their modules): skip its scan of the sources
autosummary_generate = False


def _one_docstring_template():
    # numpydoc makes a new jinja2 environment, and so compiles its docstring template
    # again, for each of the ~1300 docstrings it renders (a quarter of the build's CPU
    # time); within one build the loader and the template file are the same every time,
    # so the first compile serves them all
    from numpydoc import docscrape_sphinx

    base = getattr(docscrape_sphinx, "SandboxedEnvironment", None)
    if base is None:
        return
    compiled = {}

    class Environment(base):
        def get_template(self, name, *args, **kwargs):
            if name not in compiled:
                compiled[name] = super().get_template(name, *args, **kwargs)
            return compiled[name]

    docscrape_sphinx.SandboxedEnvironment = Environment


_one_docstring_template()

html_theme = "furo"
html_title = f"moreau {release}"
