"""The compiled loops of the schemes: one shared by every model, and one per model for long runs.

A scheme's loop is a template (Moreau–Jean's
:func:`moreau.integrators._mj_kernels.mj_loop` by default) written against a
model's functions and sizes as globals (``mass_fn``, ``NDOF``, ...). It is
compiled in two forms from the same source:

- **shared** (:func:`shared_core`): the template rewritten to take the model
  as its leading arguments, with the model's functions as numba first-class
  functions (:data:`MODEL_SIGNATURES`). One compile per scheme serves every
  :class:`moreau.compiled.CompiledModel`, a user's included, and numba's disk
  cache keeps it: a new scene costs no compile of the loop.
- **specialised** (:func:`runner_for` with ``specialise=True``): the template
  compiled in a namespace that holds one model's functions, sizes and flags
  as globals, which numba freezes as constants, inlines and unrolls; faster
  per step, at a compile of 5-20 s per (model, scheme) pair.

:func:`runner_for` picks one (the specialised loop when asked, or when it
costs nothing because it is compiled already; the shared loop otherwise), and
a :class:`SharedRunner` moves a long run on to the specialised loop. Both
give the same numbers to the last bit.

Where the model's functions can be imported by name (every shipped scene,
and a user's scene kept in their own module), the specialised loop goes to
numba's disk cache under a name derived from those import paths, and later
processes load it in a fraction of a second. Every cache entry is tied to
the contents of every source file its machine code depends on
(:mod:`moreau._jit_cache`): the loop, Lemke, and for the specialised loop
and the model's own functions, the model's module and the modules of the
compiled functions it calls. An edit to any of them compiles again instead
of running stale machine code. Functions defined in ``__main__`` or a
notebook give a specialised loop compiled in memory, again in each process:
their names do not identify them across processes.
"""

import ast
import contextlib
import hashlib
import importlib
import inspect
import logging
import os
import subprocess
import sys
import textwrap
import threading
import time
import types

import numba
from numba import njit
from numba.core import types as nbtypes

from .. import _jit_cache
from .._jit_cache import compile_lock as _compile_lock, dependency_files
from .._log import note
from . import _mj_kernels
from ._mj_kernels import no_gaps

__all__ = ["runner_for", "dependency_files"]

_RUNNERS = {}
_LOCK = threading.Lock()
log = logging.getLogger(__name__)

#: seconds in a shared loop after which a model's own loop is compiled: with a compile
#: of C ~ 10 s and the specialised loop taking r ~ 1/2 of the shared one's time, the
#: compile pays for itself after C / (1 - r) more seconds of work; moving there bounds
#: a run's cost by about twice that of the best choice made in advance
TIER_UP_SECONDS = 20.0
#: the clock of that time: the calling thread's CPU time, the currency of the compile it
#: is weighed against; on a machine shared with other work, wall time would also count
#: the waits for a core, and compile a loop (10-25 CPU s) that the run does not repay
_SHARED_CLOCK = getattr(time, "thread_time", time.process_time)
#: what a first compile takes (README: 16-19 s for the first scene with Lemke and
#: the QP path, 5-10 s for each later one)
COMPILE_SECONDS = "5-20"


def _import_path(f):
    """``"module:name"`` by which ``f`` can be imported again, or None."""
    py = getattr(f, "py_func", f)
    module, qualname = getattr(py, "__module__", None), getattr(py, "__qualname__", "")
    if not module or module == "__main__" or not qualname.isidentifier():
        # defined in a script, a notebook, a function or a class: not importable by name
        return None
    try:
        obj = getattr(importlib.import_module(module), qualname)
    except (ImportError, AttributeError):
        return None
    return f"{module}:{qualname}" if obj is f else None


def _constants(model):
    return {"NDOF": model.ndof, "NCONTACTS": model.ncontacts, "CONST_MASS": model.const_mass,
            "HAS_JAC": model.has_jacobians, "HAS_GAPS": model.gaps is not None}


def _build(model, template, stub=False):
    consts = _constants(model)
    fns = model.functions()
    paths = {k: _import_path(f) for k, f in fns.items()}
    cacheable = all(p is not None for p in paths.values())
    # the template spliced first: splicing adds the driver's and the spliced helpers' names
    # to the module's globals, which the model's loop runs in a copy of
    code = template.__code__
    module = sys.modules[template.__module__]
    namespace = dict(vars(module))
    namespace.update(consts, mass_fn=model.mass, forces_fn=model.forces,
                     contacts_fn=model.contacts, gaps_fn=model.gaps or no_gaps)
    # kernels the template's module binds otherwise in a model's own loop (inlined ones)
    namespace.update(getattr(module, "SPECIALISED", {}))
    if stub:
        # the variant for runs that cannot reach these kernels (see SHARED_INDIRECT)
        namespace.update({name: getattr(module, spec[1])
                          for name, spec in _indirect(template).items()})
    # numba names a function's disk-cache files after its qualified name: one
    # per model, from the import paths of its functions and its constants
    tag = repr(sorted(paths.items())) + repr(sorted(consts.items())) + ("stub" if stub else "")
    name = template.__name__ + "_" + hashlib.sha256(tag.encode()).hexdigest()[:16]
    fn = types.FunctionType(code, namespace, name, template.__defaults__)
    fn.__qualname__ = name
    fn.__module__ = template.__module__
    fn.__doc__ = template.__doc__
    run = njit(cache=cacheable, error_model="numpy")(fn)
    if cacheable:
        _jit_cache.bind_cache_to_sources(
            [run], _template_sources(template) + dependency_files(list(fns.values())))
    return run


def _template_sources(template):
    """Every source file a loop of ``template`` compiles in: Lemke's, the template's
    module and the modules of every compiled kernel it calls (another scheme's, too)."""
    sources = list(_mj_kernels.KERNEL_SOURCES)
    # a driver's template runs the code of _driver.py in its scheme module's namespace
    module_file = sys.modules[template.__module__].__file__
    # and the files of the helpers and step rules spliced into it (moreau.integrators._driver)
    for path in [module_file] + list(getattr(template, "__moreau_sources__", ())) \
            + dependency_files([types.SimpleNamespace(py_func=template)]):
        if path not in sources:
            sources.append(path)
    return sources


#: the leading parameters of a scheme's shared loop: the model as run-time values, in
#: the order :func:`_model_prefix` gives them
SHARED_PARAMETERS = ("mass_fn", "forces_fn", "contacts_fn", "gaps_fn", "NDOF", "NCONTACTS",
                     "CONST_MASS", "HAS_JAC", "HAS_GAPS")

_F1 = nbtypes.float64[::1]
_F2 = nbtypes.float64[:, ::1]
_B = nbtypes.boolean
#: the numba signatures of a model's functions (:mod:`moreau.compiled`), as the loops call them
MODEL_SIGNATURES = {
    "mass": nbtypes.void(_F1, _F1, _F2),
    "forces": nbtypes.void(_F1, _F1, _F1, nbtypes.float64, _F2, _B),
    "contacts": nbtypes.void(_F1, _F1, nbtypes.float64, _F2, _B, _B),
    "gaps": nbtypes.void(_F1, _F1, nbtypes.float64, _F2),
}
_PREFIX_TYPES = tuple(nbtypes.FunctionType(MODEL_SIGNATURES[k])
                      for k in ("mass", "forces", "contacts", "gaps")) + (
    nbtypes.int64, nbtypes.int64, _B, _B, _B)
_CORES = {}


def _indirect(template):
    """The template module's kernels passed to its shared loop as arguments (name -> spec)."""
    return getattr(sys.modules[template.__module__], "SHARED_INDIRECT", {})


def _shared_function(template):
    """``template`` rewritten to take the model as its leading arguments (:data:`SHARED_PARAMETERS`).

    The same source as the specialised loop, so both compile the same
    arithmetic; the shared one reads the model's functions and sizes at run
    time, which lets one compiled loop serve every model.
    """
    # a driver's template keeps its spliced source (moreau.integrators._driver.loop_template)
    source = getattr(template, "__moreau_source__", None) or textwrap.dedent(
        inspect.getsource(template))
    tree = ast.parse(source)
    fdef = tree.body[0]
    fdef.decorator_list = []
    fdef.name = template.__name__ + "_shared"
    names = SHARED_PARAMETERS + tuple(_indirect(template))
    fdef.args.args = [ast.arg(arg=name) for name in names] + fdef.args.args
    ast.fix_missing_locations(tree)
    ast.increment_lineno(tree, template.__code__.co_firstlineno - 1)
    code = compile(tree, template.__code__.co_filename, "exec")
    module = sys.modules[template.__module__]
    namespace = dict(vars(module))
    # the lean variant's compile-time switches (_lean_template)
    namespace.update(getattr(template, "__moreau_switches__", {}))
    exec(code, namespace)  # noqa: S102  (the package's own template, transformed above)
    fn = namespace[fdef.name]
    fn.__module__ = template.__module__
    fn.__qualname__ = fdef.name
    return fn


_LEAN = {}


def _lean_template(template):
    """The lean variant of ``template``'s shared loop, or None where its module gives none.

    A scheme module's ``SHARED_LEAN`` is ``(switches, test, names)``: global
    names the step rule branches on, with the values that prune the branches a
    run passing ``test(ncontacts, *the loop's arguments named)`` cannot reach
    (Moreau–Jean: the several-contact LCP and the projection). The variant is
    the same template under another name (its own disk-cache files), compiled
    with those globals; it gives the same numbers to the last bit as the full
    loop on every run it takes.
    """
    spec = getattr(sys.modules[template.__module__], "SHARED_LEAN", None)
    if spec is None:
        return None
    with _LOCK:
        lean = _LEAN.get(template)
        if lean is None:
            name = template.__name__ + "_lean"
            lean = types.FunctionType(template.__code__, template.__globals__, name,
                                      template.__defaults__)
            lean.__qualname__ = name
            lean.__module__ = template.__module__
            lean.__doc__ = template.__doc__
            lean.__moreau_source__ = getattr(template, "__moreau_source__", None) or \
                textwrap.dedent(inspect.getsource(template))
            lean.__moreau_sources__ = getattr(template, "__moreau_sources__", ())
            lean.__moreau_switches__ = dict(spec[0])
            _LEAN[template] = lean
    return lean


def shared_core(template, argtypes):
    """The loop of ``template`` compiled once for every model, for the loop arguments ``argtypes``.

    Its first arguments are :data:`SHARED_PARAMETERS`, then the kernels the
    template's module lists in ``SHARED_INDIRECT``; the model's functions
    are passed as numba first-class functions (:data:`MODEL_SIGNATURES`), so
    no model is compiled into it and numba's disk cache serves every scene,
    a user's included. A kernel passed as an argument is compiled on its
    own, only when a run can call it (a single-contact scene never compiles
    Lemke), and is not optimised again inside the loop. Returns a
    dispatcher, compiled by :class:`SharedRunner` for one signature.
    """
    key = (template.__module__, template.__name__, tuple(argtypes))
    with _LOCK:
        core = _CORES.get(key)
        if core is None:
            core = njit(cache=True, error_model="numpy")(_shared_function(template))
            _jit_cache.bind_cache_to_sources([core], _template_sources(template))
            _CORES[key] = core
    return core


def _model_prefix(model):
    for f in model.functions().values():
        if not f.signatures and _import_path(f) is not None:
            # called through a pointer, each function is compiled (or loaded) on its own:
            # tie its cache to every file it calls into, as the specialised loop's is
            _jit_cache.bind_cache_to_sources([f], dependency_files([f]))
    return (model.mass, model.forces, model.contacts, model.gaps or no_gaps, model.ndof,
            model.ncontacts, model.const_mass, model.has_jacobians, model.gaps is not None)


class SharedRunner:
    """A model bound to its scheme's compiled loops: called with the template's own arguments.

    ``mode`` is ``"auto"``, ``"shared"`` or ``"specialised"``. Each call
    first picks its variant: with the stand-ins of the template's
    ``SHARED_INDIRECT`` kernels where the call cannot reach them (one
    contact, Lemke not forced), with the kernels otherwise; and the shared
    loop's lean variant where the call cannot reach what it leaves out
    (:func:`_lean_template`). Then:

    - ``"specialised"``: the model's own loop of that variant, compiled at
      its first call;
    - ``"shared"``: the scheme's shared loop, always;
    - ``"auto"``: the model's own loop where it costs nothing (compiled in
      this process or fresh in numba's disk cache), else the shared loop,
      keeping the CPU time spent there. Once that passes
      :data:`TIER_UP_SECONDS`, it compiles the model's own loop and runs
      that from then on: a long run pays at most about twice what it would
      have with the best choice made in advance, and a short one pays no
      compile beyond the scheme's.

    All of them give the same numbers to the last bit.
    """

    def __init__(self, model, template, scene=None, mode="auto"):
        if mode not in ("auto", "shared", "specialised"):
            raise ValueError(f"`mode` must be 'auto', 'shared' or 'specialised', got {mode!r}")
        self.model, self.template, self.scene, self.mode = model, template, scene, mode
        base = _model_prefix(model)
        module = sys.modules[template.__module__]
        indirect = _indirect(template)
        self._kernel_types = tuple(nbtypes.FunctionType(spec[0]) for spec in indirect.values())
        # the kernels as the loop calls them, and their stand-ins for runs that cannot
        self._prefix = base + tuple(getattr(module, name) for name in indirect)
        self._stub_prefix = base + tuple(getattr(module, spec[1]) for spec in indirect.values())
        params = list(inspect.signature(template).parameters)
        self._deciders = tuple((spec[2], params.index(spec[3])) for spec in indirect.values())
        self._core = None
        self._cores = {}        # lean or not -> the shared loop
        self._lean = _lean_template(template)
        lean_spec = getattr(module, "SHARED_LEAN", None)
        self._lean_test = None if self._lean is None else (
            lean_spec[1], tuple(params.index(name) for name in lean_spec[2]))
        self._specials = {}     # variant (stand-ins or not) -> the model's own loop
        self._looked = set()    # variants whose own loop has been considered
        self._kernels_ready = not self._deciders
        self.seconds = {False: 0.0, True: 0.0}   # CPU s in the shared loop, per variant

    @property
    def tier_up(self):
        """Whether a long run moves on to the model's own loop (``mode="auto"``)."""
        return self.mode == "auto"

    def _bind(self, args, lean=False):
        argtypes = tuple(numba.typeof(a) for a in args)
        core = shared_core(self._lean if lean else self.template, argtypes)
        if not core.signatures:
            with _compile_lock(core):
                if not _jit_cache.has_cached_code(core):
                    _note_compile(self.template, self.scene, shared=True)
                core.compile(_PREFIX_TYPES + self._kernel_types + argtypes)
            # one signature: a call with other argument types is an error, not a silent
            # compile of a loop specialised on the model's functions
            core.disable_compile()
        self._cores[lean] = self._core = core
        return core

    def _stub(self, args):
        """Whether this call cannot reach the kernels passed as arguments."""
        nc = self.model.ncontacts
        return bool(self._deciders) and not any(needed(nc, args[i])
                                                for needed, i in self._deciders)

    def _lean_for(self, args, stub):
        """Whether this call takes the lean shared loop (:func:`_lean_template`)."""
        if not stub or self._lean_test is None:
            return False
        test, at = self._lean_test
        return bool(test(self.model.ncontacts, *(args[i] for i in at)))

    def _prefix_for(self, args):
        return self._stub_prefix if self._stub(args) else self._prefix

    def _wants_own(self, stub):
        """At a variant's first call: run the model's own loop from the start?"""
        if self.mode != "auto":
            return self.mode == "specialised"
        own = runner_for(self.model, self.template, self.scene, specialise=True, stub=stub,
                         announce=False)
        return _jit_cache.has_cached_code(own)

    def _specialise(self, stub, args):
        own = runner_for(self.model, self.template, self.scene, specialise=True, stub=stub)
        if not own.signatures:
            # a sweep's workers reach this together: one compiles, the others load
            with _compile_lock(own):
                own.compile(tuple(numba.typeof(a) for a in args))
        self._specials[stub] = own
        return own

    def __call__(self, *args):
        stub = self._stub(args)
        own = self._specials.get(stub)
        if own is None and stub not in self._looked:
            self._looked.add(stub)
            if self._wants_own(stub):
                own = self._specialise(stub, args)
        if own is not None:
            return own(*args)
        lean = self._lean_for(args, stub)
        core = self._cores.get(lean)
        aside = None
        if core is None:
            if not stub and not self._kernels_ready:
                aside = self._kernels_aside(args, lean)
            try:
                core = self._bind(args, lean)
            except BaseException:
                _end_aside(aside)
                raise
        if not stub and not self._kernels_ready:
            try:
                self._compile_kernels()
            finally:
                _end_aside(aside)
        t0 = _SHARED_CLOCK()
        out = core(*(self._stub_prefix if stub else self._prefix), *args)
        self.seconds[stub] += _SHARED_CLOCK() - t0
        if self.tier_up and self.seconds[stub] > TIER_UP_SECONDS:
            # the model's own loop, with the same stand-ins as this call (a single-contact
            # run's compiles no Lemke either); a run that needs them gets the other variant
            self._specialise(stub, args)
        return out

    def _kernels_aside(self, args, lean):
        """Start compiling the kernels passed as arguments in a child process; it, or None.

        A several-contact run's first call compiles the shared loop and then Lemke's step
        (about 13 and 9 CPU s), one after the other: numba compiles under one lock per
        process. Where the loop is to be compiled, the kernels are not compiled yet, numba's
        disk cache is writable and a second CPU is free, a child process compiles the kernels
        into the cache under the compile lock while this one compiles the loop;
        :meth:`_compile_kernels` then waits on that lock and loads them. The same machine
        code either way; without the child, the same compiles in this process. One child
        at a time for a cache (:func:`moreau._jit_cache.try_lock`): a sweep's workers that
        start together do not each start one; the others wait on the compile lock.
        """
        core = shared_core(self._lean if lean else self.template,
                           tuple(numba.typeof(a) for a in args))
        # an embedded interpreter may have no executable to start a child with
        if _spare_cpus() < 1 or not sys.executable or _jit_cache.has_cached_code(core):
            return None
        module = sys.modules[self.template.__module__]
        kernels = [getattr(module, name) for name in _indirect(self.template)]
        for fn, spec in zip(kernels, _indirect(self.template).values()):
            if spec[0].args in fn.overloads or _jit_cache.has_cached_code(fn):
                return None
        # None also where the cache folder cannot be written: the child would write nothing
        held = _jit_cache.try_lock(kernels[0], "aside") if kernels else None
        if held is None:
            return None
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [root] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
        if getattr(numba.config, "CACHE_DIR", ""):
            # the cache folder this process uses, also where it was set in code
            env["NUMBA_CACHE_DIR"] = numba.config.CACHE_DIR
        try:
            child = subprocess.Popen(
                [sys.executable, "-c", "import sys\nfrom moreau.integrators._loops import "
                 "compile_indirect\ncompile_indirect(sys.argv[1])", self.template.__module__],
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                env=env)
        except OSError:
            held.close()
            return None
        note(log, "compiling the contact problem's LCP step (Lemke) alongside, in another "
             "process...")
        # the lock goes with the child, released when it is reaped (_end_aside)
        child.moreau_aside_lock = held
        return child

    def _compile_kernels(self):
        # the kernels passed as arguments compile on their own, at their first use; under
        # the lock, so that a sweep's (or pytest's) workers compile Lemke once, not each.
        # After a child of _kernels_aside they are on disk; if not (the child failed),
        # they compile here, and say so
        module = sys.modules[self.template.__module__]
        for name, spec in _indirect(self.template).items():
            fn = getattr(module, name)
            if spec[0].args not in fn.overloads:
                with _compile_lock(fn):
                    if not _jit_cache.has_cached_code(fn):
                        note(log, "compiling the contact problem's LCP step (Lemke; first "
                             "use on this machine, about %s s)...", COMPILE_SECONDS)
                    fn.compile(spec[0])
        self._kernels_ready = True

    @property
    def _special(self):
        # the model's own loop that runs now, if any (the full variant first)
        return self._specials.get(False) or self._specials.get(True)

    @property
    def dispatcher(self):
        """The numba dispatcher that runs now (None before the first call)."""
        return self._special if self._special is not None else self._core


#: environment variable: "1" runs every model in its own specialised loop, "0" always
#: in the scheme's shared loop; unset (or "auto"), :func:`runner_for` chooses
SPECIALISE_ENV = "MOREAU_SPECIALISE"
_CHOSEN = {}
_ANNOUNCED = set()


def specialise_default():
    """The setting of :data:`SPECIALISE_ENV`: True, False, or None (let :func:`runner_for` choose)."""
    value = os.environ.get(SPECIALISE_ENV, "").strip().lower()
    if value in ("1", "true", "yes", "on"):
        return True
    if value in ("0", "false", "no", "off"):
        return False
    return None


@contextlib.contextmanager
def specialised_loops():
    """Within this block, models run their own specialised loops from their first call.

    For work known in advance to be long, where the scene's own loop pays
    for its compile many times over (``moreau reproduce``: 1700 Moreau–Jean
    steady states of one scene). Worker processes started inside inherit
    it. A setting of :data:`SPECIALISE_ENV` by the user is left alone.

    Examples
    --------
    >>> import os
    >>> with specialised_loops():
    ...     inside = specialise_default()
    >>> inside or os.environ.get(SPECIALISE_ENV) is not None
    True
    """
    if os.environ.get(SPECIALISE_ENV) is not None:
        yield
        return
    os.environ[SPECIALISE_ENV] = "1"
    try:
        yield
    finally:
        os.environ.pop(SPECIALISE_ENV, None)


def runner_for(model, template=None, scene=None, specialise=None, stub=False, announce=True):
    """The compiled loop of ``model`` (a :class:`moreau.compiled.CompiledModel`).

    ``template`` is the loop of a scheme, written against the model's
    globals (default :func:`moreau.integrators._mj_kernels.mj_loop`, the
    Moreau–Jean loop); a scheme module passes its own. Two compiled forms
    run the same source:

    - the scheme's *shared* loop (:func:`shared_core`), compiled once for
      every model and kept in numba's disk cache: the model's functions are
      called through pointers, so a new scene costs no compile of the loop;
    - the model's *specialised* loop (``template`` compiled with the model's
      functions and sizes frozen in), which numba inlines and unrolls:
      faster per step (``benchmarks/bench_moreau_jean.py`` measures both),
      at a compile of 5-20 s per (model, scheme) pair.

    ``specialise=None`` (default) returns a :class:`SharedRunner` in the
    mode :func:`specialise_default` names (``"auto"`` unless
    :data:`SPECIALISE_ENV` says otherwise), which picks between the two at
    each call; ``False`` one that keeps the shared loop. ``specialise=True``
    returns the specialised loop's numba dispatcher itself, with the
    stand-ins of ``SHARED_INDIRECT`` compiled in where ``stub`` (for runs
    that cannot reach those kernels). Both forms give the same numbers to
    the last bit (tested). Where a specialised loop will compile, one INFO
    note says so (:func:`moreau._log.note`), naming ``scene`` (for the note
    only), unless ``announce`` is false.
    """
    template = template or _mj_kernels.mj_loop
    if specialise is None:
        specialise = specialise_default()
        mode = {None: "auto", True: "specialised", False: "shared"}[specialise]
    else:
        mode = "dispatcher" if specialise else "shared"
    key = (template.__module__, template.__name__,
           tuple(sorted(model.functions().items(), key=lambda kv: kv[0])),
           tuple(sorted(_constants(model).items())), bool(stub))
    chosen = _CHOSEN.get((key, mode))
    if chosen is None:
        if mode == "dispatcher":
            with _LOCK:
                chosen = _RUNNERS.get(key)
                if chosen is None:
                    chosen = _RUNNERS[key] = _build(model, template, stub)
        else:
            chosen = SharedRunner(model, template, scene, mode=mode)
        _CHOSEN[(key, mode)] = chosen
    if mode == "dispatcher" and announce and id(chosen) not in _ANNOUNCED:
        _ANNOUNCED.add(id(chosen))
        if not _jit_cache.has_cached_code(chosen):
            _note_compile(template, scene, shared=False)
    return chosen


def compile_indirect(module_name):
    """Compile the kernels that ``module_name``'s shared loops take as arguments, into the cache.

    What the child process of :meth:`SharedRunner._kernels_aside` runs: each
    kernel under the compile lock, so that the parent, which takes the same
    lock before it compiles them, waits and then loads them.
    """
    module = importlib.import_module(module_name)
    for name, spec in getattr(module, "SHARED_INDIRECT", {}).items():
        fn = getattr(module, name)
        with _compile_lock(fn):
            fn.compile(spec[0])


def _spare_cpus():
    """CPUs this process may run on, beyond one."""
    try:
        return len(os.sched_getaffinity(0)) - 1
    except AttributeError:  # not on Linux
        return (os.cpu_count() or 1) - 1


def _end_aside(child):
    """Reap the child of :meth:`SharedRunner._kernels_aside` (kill it if still running)."""
    if child is None:
        return
    try:
        if child.poll() is None:
            try:
                # the parent holds the compile lock once the child has released it: a
                # child still running here is one this call no longer waits for (an
                # interrupt)
                child.kill()
            except OSError:
                pass
        child.wait()
    finally:
        held = getattr(child, "moreau_aside_lock", None)
        if held is not None:
            held.close()


def _note_compile(template, scene, shared):
    # a template of loop_template names its scheme; another (a test's) is named by itself
    scheme = getattr(template, "scheme", template.__name__)
    if shared:
        note(log, "compiling the %s loop (first use on this machine, once for every scene, "
             "about %s s)...", scheme, COMPILE_SECONDS)
    else:
        note(log, "compiling the %s loop specialised to scene %s (about %s s)...", scheme,
             _scene_label(scene), COMPILE_SECONDS)


def _scene_label(scene):
    name = getattr(scene, "name", None)
    # "scene" is the base class's placeholder: a user's scene is named by its class
    if isinstance(name, str) and name and name != "scene":
        return name
    return "(unnamed)" if scene is None else type(scene).__name__
