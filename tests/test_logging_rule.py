"""Issue 21: messages go through ``logging``; ``print`` only writes a command's own output.

The package's source is read (not run): every ``print(...)`` call must sit in a
function of :data:`COMMAND_OUTPUT`, the functions whose printing *is* the
result of a command (the CLI's ``_cmd_*`` tables and JSON, the error line of
``main``, the study scripts' result tables). A new ``print`` anywhere else is a
message and must use a logger (``logging.getLogger(__name__)``; see
``moreau/_log.py``). The same scan holds every tqdm bar to ``disable=None``,
so that a bar is drawn on a terminal only, never into a log file.

Not scanned: docstring examples (``>>> print(...)`` in ``moreau/check.py``
is a doctest, not a call), and the ``log=print`` parameters of the functions
behind the commands (sweep, atlas, reproduce, ...): they pass ``print`` as a
value, the "wrote FILE" lines that are the command's output; a caller of the
API gives its own ``log``.
"""

import ast
import pathlib

import moreau

PACKAGE = pathlib.Path(moreau.__file__).parent

#: (file relative to the package, function) -> why its print calls are a command's output
COMMAND_OUTPUT = {
    ("cli.py", "_cmd_steady"): "moreau steady: the steady-state table or its JSON",
    ("cli.py", "_cmd_characteristic"): "moreau characteristic: the summary or its JSON",
    ("cli.py", "_efficiency_vs_frequency"): "moreau characteristic: the efficiency table",
    ("cli.py", "_cmd_bifurcation"): "moreau bifurcation: the points and marks or their JSON",
    ("cli.py", "_cmd_run"): "moreau run: the files written",
    ("cli.py", "_cmd_reproduce"): "moreau reproduce: the files written and the timings",
    ("cli.py", "_cmd_compare"): "moreau compare: the table or its JSON",
    ("cli.py", "_cmd_scenes"): "moreau scenes: the list or its JSON",
    ("suite/command.py", "_cmd_suite"): "moreau suite: the flags, the overview, the files written",
    ("suite/command.py", "_cmd_animate"): "moreau animate: the file written",
    ("cli.py", "main"): "the command's one-line error or interrupt note on stderr, its exit "
                        "status's reason",
    ("_log.py", "note"): "the logging fallback itself: an INFO note on a terminal's stderr "
                         "when no handler shows it",
    ("studies/bidirectional/direction_control.py", "main"): "the study script's result table",
    ("studies/piezo/loop_and_resonance.py", "main"): "the study script's result table",
}


def _calls(tree):
    """``(function qualname, call node)`` of every call in ``tree``."""
    found = []

    def visit(node, scope):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                visit(child, scope + [child.name])
                continue
            if isinstance(child, ast.Call):
                found.append((".".join(scope) or "<module>", child))
            visit(child, scope)

    visit(tree, [])
    return found


def _callee(call):
    f = call.func
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute):
        inner = f.value
        while isinstance(inner, ast.Attribute):
            inner = inner.value
        return ast.unparse(f) if isinstance(inner, ast.Name) else f.attr
    return ""


def prints_outside(source, module, allowed):
    """``["module:function:line"]`` of the writes to stdout/stderr outside ``allowed``."""
    out = []
    for scope, call in _calls(ast.parse(source)):
        name = _callee(call)
        if name in ("print", "sys.stdout.write", "sys.stderr.write") and \
                (module, scope) not in allowed:
            out.append(f"{module}:{scope}:{call.lineno}")
    return out


def _sources():
    for path in sorted(PACKAGE.rglob("*.py")):
        yield path.relative_to(PACKAGE).as_posix(), path.read_text()


def test_the_scan_finds_a_print_that_is_a_message():
    src = ("def work():\n    print('compiling')\n"
           "def command():\n    print('result')\n"
           "import sys\nsys.stderr.write('note')\n")
    assert prints_outside(src, "m.py", {("m.py", "command")}) == ["m.py:work:2",
                                                                   "m.py:<module>:6"]


def test_print_only_writes_a_command_s_own_output():
    offenders = [hit for module, src in _sources()
                 for hit in prints_outside(src, module, COMMAND_OUTPUT)]
    assert offenders == [], ("print is for a command's own output; log these with "
                             f"logging.getLogger(__name__) or allow them here: {offenders}")


def test_every_allowed_function_still_prints():
    # an entry whose function no longer prints would let a future message through unseen
    printing = {(module, scope) for module, src in _sources()
                for scope, call in _calls(ast.parse(src)) if _callee(call) == "print"}
    assert set(COMMAND_OUTPUT) <= printing, set(COMMAND_OUTPUT) - printing


def test_every_progress_bar_is_drawn_on_a_terminal_only():
    bars, bad = 0, []
    for module, src in _sources():
        for scope, call in _calls(ast.parse(src)):
            if _callee(call) != "tqdm":
                continue
            bars += 1
            disable = [k.value for k in call.keywords if k.arg == "disable"]
            # disable=None: tqdm draws only where stderr is a terminal
            if not (disable and isinstance(disable[0], ast.Constant) and disable[0].value is None):
                bad.append(f"{module}:{scope}:{call.lineno}")
    assert bars >= 5 and bad == []
