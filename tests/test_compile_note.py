"""A first compile says so: one INFO note, on a terminal or through ``logging``; never a compile here.

The note is made in :mod:`moreau.integrators._loops`, the one place a
compiled loop is built, when a loop will compile (nothing in the process,
nothing fresh in numba's disk cache): a scheme's shared loop at its first
call, a model's specialised loop when it is chosen. The tests replace that
answer (``_jit_cache.has_cached_code``) instead of compiling, and never call
a loop that is not cached, except the command-line test, which loads the
shared Moreau–Jean loop (compiled once by any other test).
"""

import importlib.util
import inspect
import io
import logging

import pytest

from moreau import _jit_cache, _log
from moreau.cli import main
from moreau.integrators import _loops
from moreau.integrators._mj_kernels import mj_loop, new_lcp_control
from moreau.scenes import BidirectionalDrive, BouncingBall, FrictionDrive

NOTE = "compiling the Moreau–Jean loop specialised to scene friction-drive (about 5-20 s)..."
SHARED_NOTE = ("compiling the Moreau–Jean loop (first use on this machine, once for every scene, "
               "about 5-20 s)...")


class _Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.fixture
def fresh_loops(monkeypatch):
    # a process that has built no loop yet (the built loops are not compiled here)
    for name in ("_RUNNERS", "_CHOSEN", "_CORES"):
        monkeypatch.setattr(_loops, name, {})
    monkeypatch.setattr(_loops, "_ANNOUNCED", set())


class _FakeCore:
    # stands for a shared loop that is not compiled: records what the runner asks of it
    def __init__(self):
        self.signatures, self.compiled, self.calls = [], [], 0

    def compile(self, sig):
        self.compiled.append(sig)
        self.signatures.append(sig)

    def disable_compile(self):
        pass

    def __call__(self, *args):
        self.calls += 1
        return args


@pytest.fixture
def quiet_moreau_logger():
    # the state a program that configures no logging sees; the CLI tests change it
    root = logging.getLogger("moreau")
    saved = root.handlers[:], root.level
    root.handlers[:] = []
    root.setLevel(logging.NOTSET)
    yield root
    root.handlers[:], _ = saved[0], root.setLevel(saved[1])


def test_a_loop_that_will_compile_is_announced_once(fresh_loops, monkeypatch, caplog):
    monkeypatch.setattr(_jit_cache, "has_cached_code", lambda disp: False)
    scene = FrictionDrive(frequency=185.0)
    with caplog.at_level(logging.INFO, logger="moreau"):
        run = _loops.runner_for(scene.compiled_model(), scene=scene, specialise=True)
        again = _loops.runner_for(scene.compiled_model(), scene=scene, specialise=True)
    assert again is run and not run.signatures          # built, not compiled
    assert [r.getMessage() for r in caplog.records] == [NOTE]
    assert caplog.records[0].name == "moreau.integrators._loops"
    assert caplog.records[0].levelno == logging.INFO


def test_the_shared_loop_is_announced_at_its_first_call_once(fresh_loops, monkeypatch, caplog):
    monkeypatch.setattr(_jit_cache, "has_cached_code", lambda disp: False)
    fake = _FakeCore()
    monkeypatch.setattr(_loops, "shared_core", lambda template, argtypes: fake)
    scene = FrictionDrive(frequency=185.0)
    # stand-ins for the loop's arguments: only the contact problem's options are read
    names = list(inspect.signature(mj_loop).parameters)
    args = [0.0] * len(names)
    args[names.index("lcp_ctl")] = new_lcp_control(1)
    with caplog.at_level(logging.INFO, logger="moreau"):
        run = _loops.runner_for(scene.compiled_model(), scene=scene)
        assert isinstance(run, _loops.SharedRunner)
        assert caplog.records == []                     # nothing before the first call
        run(*args)
        run(*args)
        # another scene uses the same shared loop: no second note, no second compile
        other = BouncingBall()
        _loops.runner_for(other.compiled_model(), scene=other)(*args)
    assert [r.getMessage() for r in caplog.records] == [SHARED_NOTE]
    assert len(fake.compiled) == 1 and fake.calls == 3


def _loop_templates():
    # every scheme's loop template, found among the integrators' modules (none listed here)
    import pkgutil

    import moreau.integrators as pkg
    from moreau.integrators._driver import _Template
    found = {}
    for info in pkgutil.iter_modules(pkg.__path__):
        module = importlib.import_module(f"moreau.integrators.{info.name}")
        found.update({id(v): v for v in vars(module).values() if isinstance(v, _Template)})
    return list(found.values())


def test_every_loop_template_names_its_scheme_in_the_note(caplog):
    # the scheme's name comes with its template (loop_template's third argument), so a new
    # scheme's module is the only file that names it
    templates = _loop_templates()
    assert {t.__name__ for t in templates} >= {"mj_loop", "tdg_loop", "mjp_loop", "sp_loop",
                                                "nsga_loop", "studer_loop"}
    with caplog.at_level(logging.INFO, logger="moreau"):
        for t in templates:
            _loops._note_compile(t, None, shared=True)
    notes = [r.getMessage() for r in caplog.records]
    assert notes == [f"compiling the {t.scheme} loop (first use on this machine, once for every "
                     f"scene, about {_loops.COMPILE_SECONDS} s)..." for t in templates]
    assert len({t.scheme for t in templates}) == len(templates)
    assert "Moreau–Jean projected" in {t.scheme for t in templates}


def test_a_cached_loop_is_not_announced(fresh_loops, monkeypatch, caplog):
    monkeypatch.setattr(_jit_cache, "has_cached_code", lambda disp: True)
    scene = BouncingBall()
    with caplog.at_level(logging.DEBUG, logger="moreau"):
        _loops.runner_for(scene.compiled_model(), scene=scene)
    assert caplog.records == []


def test_without_logging_configured_a_terminal_gets_one_line(fresh_loops, monkeypatch,
                                                             quiet_moreau_logger):
    monkeypatch.setattr(_jit_cache, "has_cached_code", lambda disp: False)
    scene = FrictionDrive(frequency=185.0)
    monkeypatch.setattr("sys.stderr", _Terminal())
    _loops.runner_for(scene.compiled_model(), scene=scene, specialise=True)
    _loops.runner_for(scene.compiled_model(), scene=scene, specialise=True)
    assert __import__("sys").stderr.getvalue() == "moreau: " + NOTE + "\n"
    # and nothing where stderr is a file (a log)
    for name in ("_RUNNERS", "_CHOSEN"):
        monkeypatch.setattr(_loops, name, {})
    log_file = io.StringIO()
    monkeypatch.setattr("sys.stderr", log_file)
    _loops.runner_for(scene.compiled_model(), scene=scene, specialise=True)
    assert log_file.getvalue() == ""


def test_the_command_line_shows_the_note_with_verbose_only_in_a_log(fresh_loops, monkeypatch,
                                                                    capsys, tmp_path,
                                                                    quiet_moreau_logger):
    # the run loads the shared Moreau-Jean loop from the cache (compiled once by any
    # other test, or by the first run here)
    monkeypatch.setattr(_jit_cache, "has_cached_code", lambda disp: False)
    args = ["run", "--scene", "bouncing-ball", "--scheme", "moreau-jean", "--duration", "0.05",
            "--steps", "50", "--no-plot", "--quiet", "--out", str(tmp_path)]
    assert main(args) == 0
    assert capsys.readouterr().err == ""
    for name in ("_RUNNERS", "_CHOSEN", "_CORES"):
        monkeypatch.setattr(_loops, name, {})
    assert main(["-v"] + args + ["--force"]) == 0
    err = capsys.readouterr().err
    assert err == "moreau: " + SHARED_NOTE + "\n"


def _load(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_has_cached_code_sees_numba_disk_cache(tmp_path):
    src = tmp_path / "toy_kernel.py"
    src.write_text("from numba import njit\n\n\n@njit(cache=True)\ndef f(x):\n    return x + 1.0\n")
    first = _load(src, "toy_kernel")
    assert not _jit_cache.has_cached_code(first.f)
    assert first.f(1.0) == 2.0                       # compiles (a trivial function) and saves
    second = _load(src, "toy_kernel")                # a new dispatcher, as in a new process
    assert not second.f.signatures
    assert _jit_cache.has_cached_code(second.f)


class _FakeChild:
    returncode = 0

    def poll(self):
        return 0

    def wait(self):
        return 0


@pytest.mark.parametrize("spare, child_ok", [(0, None), (1, True), (1, False)])
def test_the_lcp_step_of_a_two_contact_scene_is_announced_once(fresh_loops, monkeypatch, caplog,
                                                               spare, child_ok):
    # passed to the shared loop as an argument, the LCP step compiles on its own: one note,
    # in this process (one CPU) or in a child beside the loop's compile (a spare CPU); a
    # child that left nothing on disk (it failed) is followed by the compile here, announced
    from moreau.integrators import _mj_kernels as mk
    children = []
    # nothing on disk, but the LCP step once a child has compiled it
    monkeypatch.setattr(_jit_cache, "has_cached_code",
                        lambda disp: disp is mk._lcp_step and bool(children) and child_ok)
    monkeypatch.setattr(_loops, "_spare_cpus", lambda: spare)
    # no other process's child at work (one may run in another test worker)
    monkeypatch.setattr(_jit_cache, "try_lock", lambda disp, purpose: io.StringIO())
    monkeypatch.setattr(_loops.subprocess, "Popen",
                        lambda cmd, **kw: children.append(cmd) or _FakeChild())
    compiled = []
    monkeypatch.setattr(mk._lcp_step, "compile", lambda sig: compiled.append(sig))
    monkeypatch.setattr(mk._lcp_step, "overloads", {})     # as in a fresh process
    monkeypatch.setattr(_loops, "shared_core", lambda template, argtypes: _FakeCore())
    scene = BidirectionalDrive()
    names = list(inspect.signature(mj_loop).parameters)
    args = [0.0] * len(names)
    args[names.index("lcp_ctl")] = new_lcp_control(2)
    with caplog.at_level(logging.INFO, logger="moreau"):
        run = _loops.runner_for(scene.compiled_model(), scene=scene)
        run(*args)
        run(*args)
    here = ("compiling the contact problem's LCP step (Lemke; first use on this machine, "
            "about 5-20 s)...")
    aside = "compiling the contact problem's LCP step (Lemke) alongside, in another process..."
    # with a child, its note comes first: it starts before the loop's compile
    expected = {None: [SHARED_NOTE, here], True: [aside, SHARED_NOTE],
                False: [aside, SHARED_NOTE, here]}[child_ok]
    assert [r.getMessage() for r in caplog.records] == expected
    # the parent takes the step itself: compiled here, or loaded from the child's cache entry
    assert compiled == [mk.LCP_STEP_SIGNATURE]
    assert len(children) == spare
    if spare:
        assert children[0][-1] == "moreau.integrators._mj_kernels"
