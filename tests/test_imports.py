"""Imports a newcomer can follow (issue 17, section 5).

* every module of the package imports on its own, in a fresh interpreter;
* no module imports a private name (``_name``) from a public module;
* imports sit at the top of a module, except those of optional dependencies;
* the modules' top-level imports form no cycle;
* ``python -m moreau compare`` runs on every registered scene.
"""

import ast
import functools
import json
import math
import os
import pathlib
import subprocess
import sys
import time

import pytest

import moreau
from moreau.model.registry import get_entry, scene_names

from test_layers import find_cycle

PACKAGE = pathlib.Path(moreau.__file__).resolve().parent


#: the child processes import this checkout, whatever an installed copy says
_ENV = {**os.environ,
        "PYTHONPATH": os.pathsep.join([str(PACKAGE.parent)]
                                      + [p for p in [os.environ.get("PYTHONPATH")] if p])}

#: what a function may import where it needs it: optional dependencies (the [dask], [data] and
#: [bench] extras, the tools of the tests and notebooks) and, as issue 17 lists them,
#: matplotlib and tqdm, core dependencies in pyproject.toml that stay lazy: a figure
#: function selects matplotlib's backend (Agg) when it draws, and pyplot costs ~0.5 s
OPTIONAL = {"matplotlib", "tqdm", "dask", "distributed", "siconos", "quantecon", "IPython",
            "nbformat", "nbclient", "hypothesis", "pandas", "xarray", "h5py"}

# -- the import statements of the package's files ------------------------------------------------
class _File:
    """One source file of the package: its module name and its import statements."""

    def __init__(self, path):
        self.path = path
        self.rel = path.relative_to(PACKAGE.parent).as_posix()
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        self.is_package = parts[-1] == "__init__"
        self.module = ".".join(parts[:-1] if self.is_package else parts)
        #: (node, inside a function) for every import statement, TYPE_CHECKING blocks left out
        self.imports = list(_imports(ast.parse(path.read_text(), str(path)), False))

    def source(self, node):
        """The absolute name of the module an ``ImportFrom`` reads from."""
        if node.level == 0:
            return node.module
        base = self.module.split(".")
        if not self.is_package:
            base = base[:-1]
        base = base[:len(base) - (node.level - 1)]
        return ".".join(base + ([node.module] if node.module else []))


def _type_checking(test):
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(node, in_function):
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.If) and _type_checking(child.test):
            # only for type checkers: never executed, so no dependency
            for c in child.orelse:
                yield from _imports(ast.Module(body=[c], type_ignores=[]), in_function)
            continue
        if isinstance(child, (ast.Import, ast.ImportFrom)):
            yield child, in_function
        yield from _imports(child, in_function or isinstance(
            child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))


@functools.cache
def _files():
    # parsed when a test asks, not at collection: each xdist worker collects every module
    return {f.module: f for f in map(_File, sorted(PACKAGE.rglob("*.py")))}


def _is_private_module(module):
    return module in _files() and _files()[module].path.name.startswith("_") and \
        not _files()[module].is_package


def _package_of(module):
    f = _files()[module]
    return module if f.is_package else module.rpartition(".")[0]


# -- (a) private names ------------------------------------------------------------------------------
def _private_imports(f):
    """``from X import _name`` of ``f`` where ``_name`` is not a package-internal helper."""
    bad = []
    for node, _ in f.imports:
        if not isinstance(node, ast.ImportFrom):
            continue
        src = f.source(node)
        if src != "moreau" and not src.startswith("moreau."):
            continue
        for alias in node.names:
            name = alias.name
            if not name.startswith("_") or name.startswith("__"):
                continue
            if f"{src}.{name}" in _files():
                # a private module itself (``from . import _certified``): a package-internal helper
                continue
            if _is_private_module(src) and f.module.startswith(_package_of(src) + "."):
                # a private module's names are for its own package
                continue
            bad.append(f"{f.rel}:{node.lineno}: {name} from {src}")
    return bad


def test_no_private_name_is_imported_from_a_public_module():
    bad = [b for f in _files().values() for b in _private_imports(f)]
    assert not bad, "private names imported across modules:\n" + "\n".join(bad)


# -- (b) imports inside functions ---------------------------------------------------------------------
def _function_imports(f):
    """Import statements inside ``f``'s functions of anything but :data:`OPTIONAL`."""
    bad = []
    for node, in_function in f.imports:
        if not in_function:
            continue
        if isinstance(node, ast.Import):
            roots = {a.name.split(".")[0] for a in node.names}
        else:
            roots = {None if node.level else node.module.split(".")[0]}
        if not roots <= OPTIONAL:
            bad.append(f"{f.rel}:{node.lineno}: {ast.unparse(node)}")
    return bad


def test_imports_are_at_the_top_except_optional_dependencies():
    bad = [b for f in _files().values() for b in _function_imports(f)]
    assert not bad, "imports inside functions (move them to the top):\n" + "\n".join(bad)


# -- (c) cycles ---------------------------------------------------------------------------------------
def _ancestors(module):
    parts = module.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts))}


def _dependencies(f):
    """The package's modules whose top level must run for ``f``'s top level to run.

    Importing ``a.b.c`` runs ``a``, ``a.b`` and ``a.b.c``; a package that
    contains ``f`` is already running (or done) then, so it counts only
    where ``f`` reads a name that package defines (``from .. import
    __version__``), not where it reaches a submodule through it.
    """
    deps = set()
    mine = _ancestors(f.module)

    def add(module, explicit):
        for m in _ancestors(module) | {module}:
            if m in _files() and m != f.module and (m == module and explicit or m not in mine):
                deps.add(m)

    for node, in_function in f.imports:
        if in_function:
            continue
        if isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name, True)
            continue
        src = f.source(node)
        for alias in node.names:
            sub = f"{src}.{alias.name}"
            if sub in _files():
                add(src, False)
                add(sub, True)
            else:
                add(src, True)
    return deps


def test_module_graph_has_no_cycle():
    graph = {m: _dependencies(f) for m, f in _files().items()}
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


# -- the command line on every scene ---------------------------------------------------------------------
#: scenes without a comparison case: the granular ones (tests/engine/test_conformance.py's
#: GRANULAR), whose physics runs on moreau.integrators.granular, out of any reference's reach
#: and the masonry arch (its NO_CASE: every contact closed at once, held to its statics instead)
_NO_CASE = {"granular-column", "silo", "masonry-arch"}


@pytest.mark.slow
@pytest.mark.parametrize("scene", [pytest.param(s, marks=pytest.mark.skip(
    reason="a granular scene or the arch: no comparison case")) if s in _NO_CASE else s
    for s in scene_names()])
def test_compare_runs_on_every_scene(scene, tmp_path):
    out = tmp_path / scene
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "moreau", "compare", "--scene", scene, "--quick",
                          "--no-plot", "--out", str(out), "--json"],
                         capture_output=True, text=True, env=_ENV, timeout=1800)
    wall = time.perf_counter() - t0
    assert run.returncode == 0, run.stderr[-3000:]
    report = json.loads(run.stdout)
    assert report["scene"] == scene and not report["interrupted"]
    rows = report["rows"]
    assert rows and any(r["scheme"] == "moreau-jean" for r in rows)
    assert any(r["scheme"] != "moreau-jean" for r in rows), "no reference row"
    for r in rows:
        if r["status"] == 0:
            # a finished run has a finite error and a run time
            assert r["error"] is not None and math.isfinite(r["error"]), r
            assert r["time_s"] is not None and r["time_s"] >= 0.0, r
        else:
            # a failed run says why
            assert r["status"] == -1 and r["message"].strip(), r
    # the errors are measured against the reference: at least one of its runs finished
    assert any(r["status"] == 0 and r["scheme"] != "moreau-jean" for r in rows)
    # and they mean something: Moreau–Jean (theta = 1, its own contact solve) converges
    mj = sorted((r["steps_per_period"], r["error"]) for r in rows if r["status"] == 0
                and r["scheme"] == "moreau-jean" and r["theta"] == 1.0 and r["lcp"] is None)
    assert len(mj) >= 2 and mj[-1][1] < mj[0][1], mj
    # the finest run is within the scene's stated tolerance of the reference
    assert mj[-1][1] <= get_entry(scene).mj_tolerance, mj
    for suffix in (".csv", ".json"):
        assert any(p.suffix == suffix for p in out.iterdir()), f"no {suffix} written"
    print(f"compare --scene {scene} --quick: {wall:.1f} s")
