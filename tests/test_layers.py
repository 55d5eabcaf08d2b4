"""The package's floors: no import runs from a lower floor into a higher one, and no circles.

Every module of :mod:`moreau` is read with :mod:`ast` (not imported) and given
a floor by its path (:data:`FLOORS`, listed in the docstring of :mod:`moreau`).
Every import statement counts, at the top of a module, inside a function or
under ``TYPE_CHECKING``; the examples in docstrings are text, not statements,
so they may import any floor. The scenes and studies register themselves on
the ground floor (:mod:`moreau.model.registry`), which imports them by name on
discovery only.
"""

import ast
import functools
import pathlib
import re

import moreau

PACKAGE = pathlib.Path(moreau.__file__).resolve().parent

#: floor by floor, lowest first: (name, path prefixes inside the package); a module
#: takes the floor of the longest prefix its path starts with
FLOORS = (
    ("base", ("__init__.py", "errors.py", "_validate.py", "_log.py", "_jit_cache.py",
              "outputs.py", "provenance.py", "regimes.py", "modes.py")),
    ("model", ("model/", "compiled.py")),
    ("contact", ("lcp/", "contact/")),
    ("integrators", ("integrators/",)),
    ("analysis", ("analysis/", "check.py")),
    ("scenes", ("scenes/",)),
    ("studies", ("studies/", "suite/")),
    ("cli", ("cli.py", "__main__.py")),
)


def floor_of(rel):
    """``(index, name)`` of the floor of the file at ``rel`` (relative to the package), or None."""
    best = None
    for index, (name, prefixes) in enumerate(FLOORS):
        for prefix in prefixes:
            if rel == prefix or (prefix.endswith("/") and rel.startswith(prefix)):
                if best is None or len(prefix) > best[2]:
                    best = (index, name, len(prefix))
    return None if best is None else best[:2]


class Module:
    """One source file: its module name, floor and the package modules it imports."""

    def __init__(self, path):
        self.rel = path.relative_to(PACKAGE).as_posix()
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        self.is_package = parts[-1] == "__init__"
        self.name = ".".join(parts[:-1] if self.is_package else parts)
        self.floor = floor_of(self.rel)
        self.tree = ast.parse(path.read_text(), str(path))

    def imports(self, known):
        """``(line, statement, module)`` for every import of a package module, anywhere in the file.

        ``from a import b`` reads module ``a.b`` where that is a file of the
        package, else module ``a``.
        """
        key = frozenset(known)
        if getattr(self, "_imports", (None,))[0] != key:
            self._imports = (key, self._read_imports(known))
        return self._imports[1]

    def _read_imports(self, known):
        out = []
        for node in ast.walk(self.tree):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                source = self._source(node)
                targets = [f"{source}.{a.name}" if f"{source}.{a.name}" in known else source
                           for a in node.names]
            else:
                continue
            for target in targets:
                while target and target not in known:
                    target = target.rpartition(".")[0]
                if target:
                    out.append((node.lineno, ast.unparse(node), target))
        return out

    def _source(self, node):
        if node.level == 0:
            return node.module
        base = self.name.split(".")
        if not self.is_package:
            base = base[:-1]
        base = base[:len(base) - (node.level - 1)]
        return ".".join(base + ([node.module] if node.module else []))


@functools.cache
def _modules():
    # parsed when a test asks, not at collection: each xdist worker collects every module
    return {m.name: m for m in map(Module, sorted(PACKAGE.rglob("*.py")))}


def upward_imports(modules):
    """Messages for every import of a module on a higher floor than the importer's."""
    bad = []
    for m in modules.values():
        for line, statement, target in m.imports(modules):
            t = modules[target]
            if m.floor and t.floor and t.floor[0] > m.floor[0]:
                bad.append(f"{m.rel}:{line} (floor {m.floor[1]}) imports {target} (floor "
                           f"{t.floor[1]}): {statement}")
    return bad


def _ancestors(name):
    parts = name.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts))}


def import_graph(modules):
    """module -> the modules whose code runs when it is imported: each import's target and the
    target's enclosing packages, except those enclosing the importer (running already)."""
    graph = {}
    for m in modules.values():
        mine = _ancestors(m.name)
        deps = set()
        for _, _, target in m.imports(modules):
            deps |= {p for p in _ancestors(target) | {target}
                     if p in modules and p != m.name and (p == target or p not in mine)}
        graph[m.name] = deps
    return graph


def find_cycle(graph):
    """One cycle of ``graph`` as ``[a, b, ..., a]``, or None."""
    state, stack = {}, []

    def visit(v):
        state[v] = "open"
        stack.append(v)
        for w in sorted(graph[v]):
            if state.get(w) == "open":
                return stack[stack.index(w):] + [w]
            if w not in state:
                cycle = visit(w)
                if cycle:
                    return cycle
        stack.pop()
        state[v] = "done"
        return None

    for v in sorted(graph):
        if v not in state:
            cycle = visit(v)
            if cycle:
                return cycle
    return None


def test_every_module_has_a_floor():
    missing = [m.rel for m in _modules().values() if m.floor is None]
    assert not missing, "modules on no floor (add them to FLOORS and moreau's docstring): " \
        + ", ".join(missing)


def test_no_import_runs_up_a_floor():
    bad = upward_imports(_modules())
    assert not bad, "imports from a lower floor into a higher one:\n" + "\n".join(bad)


def test_the_import_graph_has_no_cycle():
    cycle = find_cycle(import_graph(_modules()))
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_the_package_docstring_lists_the_floors_in_order():
    rows = [line for line in moreau.__doc__.splitlines() if re.match(r"\d+\. ``", line)]
    named = [re.match(r"\d+\. ``(\w+)``", row).group(1) for row in rows]
    assert named == [name for name, _ in FLOORS], named


def _fake(name, rel, source):
    m = Module.__new__(Module)
    m.rel, m.name, m.is_package = rel, name, rel.endswith("__init__.py")
    m.floor, m.tree = floor_of(rel), ast.parse(source)
    return m


def test_the_checks_catch_an_upward_import_a_function_import_and_a_cycle():
    fakes = {m.name: m for m in (
        _fake("moreau.errors", "errors.py", ""),
        _fake("moreau.model.registry", "model/registry.py", "from ..errors import InputError\n"),
        _fake("moreau.integrators.base", "integrators/base.py",
              "def f():\n    from ..scenes.ball import Ball\n"),
        _fake("moreau.scenes.ball", "scenes/ball.py",
              "'''>>> from moreau.cli import main'''\nfrom ..integrators import base\n"),
    )}
    assert floor_of("scenes/friction_drive/walker.py") == (5, "scenes")
    assert floor_of("check.py") == (4, "analysis") and floor_of("nowhere.py") is None
    bad = upward_imports(fakes)
    # the function-level import is caught, the docstring's example is not
    assert bad == ["integrators/base.py:2 (floor integrators) imports moreau.scenes.ball "
                   "(floor scenes): from ..scenes.ball import Ball"]
    assert find_cycle(import_graph(fakes)) == ["moreau.integrators.base", "moreau.scenes.ball",
                                               "moreau.integrators.base"]


def test_the_presentation_modules_left_out_of_the_cache_key_exist():
    # a name left behind by a move or a deletion would leave the file it meant in the key
    from moreau.provenance import _PRESENTATION
    missing = sorted(rel for rel in _PRESENTATION if not (PACKAGE / rel).is_file())
    assert not missing, missing
