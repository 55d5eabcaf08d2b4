"""One compiled loop per (model, scheme), built when the pair is first used.

:func:`runner_for` compiles a scheme's loop template (Moreau–Jean's
:func:`moreau.integrators._mj_kernels.mj_loop` by default) for one
:class:`moreau.compiled.CompiledModel`: in a namespace that holds the
model's functions, sizes and flags as globals, which numba freezes as
constants. A process compiles only the models it runs, and each model once.

Where the model's functions can be imported by name (every shipped scene,
and a user's scene kept in their own module), the compiled loop goes to
numba's disk cache under a name derived from those import paths, and later
processes load it in a fraction of a second. The cache entry is tied to the
contents of every source file the loop depends on (:mod:`moreau._jit_cache`):
the loop, Lemke, the model's module and the modules of the compiled
functions it calls. An edit to any of them compiles the loop again instead
of running stale machine code. Functions defined in ``__main__`` or a
notebook give a loop compiled in memory, again in each process: their names
do not identify them across processes.
"""

import hashlib
import importlib
import logging
import sys
import threading
import types

from numba import njit

from .. import _jit_cache
from .._log import note
from . import _mj_kernels
from ._mj_kernels import no_gaps

__all__ = ["runner_for", "dependency_files"]

_RUNNERS = {}
_LOCK = threading.Lock()
_NOTED = set()
log = logging.getLogger(__name__)

#: the schemes' names of the loop templates, for the compile note
SCHEME_OF_TEMPLATE = {"mj_loop": "Moreau–Jean", "sp_loop": "Schatzman–Paoli",
                      "nsga_loop": "nonsmooth generalized-alpha",
                      "studer_loop": "Studer extrapolation"}
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


def dependency_files(functions):
    """Source files of ``functions`` and of every compiled function they call by name.

    Follows globals (``helper(...)``) and module attributes (``mod.helper(...)``)
    that are numba functions, recursively.
    """
    files, seen, todo = [], set(), list(functions)
    while todo:
        f = todo.pop()
        if id(f) in seen:
            continue
        seen.add(id(f))
        py = getattr(f, "py_func", None)
        if py is None:
            continue
        path = py.__code__.co_filename
        if path not in files:
            files.append(path)
        names, codes = set(), [py.__code__]
        while codes:
            code = codes.pop()
            names.update(code.co_names)
            codes.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
        for name in names:
            val = py.__globals__.get(name)
            if isinstance(val, types.ModuleType):
                todo.extend(getattr(val, n) for n in names
                            if hasattr(getattr(val, n, None), "py_func"))
            elif hasattr(val, "py_func"):
                todo.append(val)
    return sorted(files)


def _constants(model):
    return {"NDOF": model.ndof, "NCONTACTS": model.ncontacts, "CONST_MASS": model.const_mass,
            "HAS_JAC": model.has_jacobians, "HAS_GAPS": model.gaps is not None}


def _build(model, template):
    consts = _constants(model)
    fns = model.functions()
    paths = {k: _import_path(f) for k, f in fns.items()}
    cacheable = all(p is not None for p in paths.values())
    module = sys.modules[template.__module__]
    namespace = dict(vars(module))
    namespace.update(consts, mass_fn=model.mass, forces_fn=model.forces,
                     contacts_fn=model.contacts, gaps_fn=model.gaps or no_gaps)
    # numba names a function's disk-cache files after its qualified name: one
    # per model, from the import paths of its functions and its constants
    tag = repr(sorted(paths.items())) + repr(sorted(consts.items()))
    name = template.__name__ + "_" + hashlib.sha256(tag.encode()).hexdigest()[:16]
    fn = types.FunctionType(template.__code__, namespace, name, template.__defaults__)
    fn.__qualname__ = name
    fn.__module__ = template.__module__
    fn.__doc__ = template.__doc__
    run = njit(cache=cacheable, error_model="numpy")(fn)
    if cacheable:
        sources = list(_mj_kernels.KERNEL_SOURCES)
        if module.__file__ not in sources:
            sources.append(module.__file__)
        _jit_cache.bind_cache_to_sources([run], sources + dependency_files(list(fns.values())))
    return run


def runner_for(model, template=None, scene=None):
    """The compiled loop of ``model`` (a :class:`moreau.compiled.CompiledModel`), built once.

    ``template`` is the loop of a scheme, written against the model's
    globals (default :func:`moreau.integrators._mj_kernels.mj_loop`, the
    Moreau–Jean loop); a scheme module passes its own. Returns a numba
    function with the template's arguments. When its first call will compile
    (nothing in this process, nothing fresh in numba's disk cache), one INFO
    note says so (:func:`moreau._log.note`: on a terminal, or through
    ``logging``), naming ``scene`` (the scene being run, for the note only).
    """
    template = template or _mj_kernels.mj_loop
    key = (template.__module__, template.__name__,
           tuple(sorted(model.functions().items(), key=lambda kv: kv[0])),
           tuple(sorted(_constants(model).items())))
    with _LOCK:
        run = _RUNNERS.get(key)
        if run is None:
            run = _RUNNERS[key] = _build(model, template)
    if id(run) not in _NOTED:
        _NOTED.add(id(run))
        if not _jit_cache.has_cached_code(run):
            scheme = SCHEME_OF_TEMPLATE.get(template.__name__, template.__name__)
            note(log, "compiling the %s loop for scene %s (first use on this machine, about "
                 "%s s)...", scheme, _scene_label(scene), COMPILE_SECONDS)
    return run


def _scene_label(scene):
    name = getattr(scene, "name", None)
    # "scene" is the base class's placeholder: a user's scene is named by its class
    if isinstance(name, str) and name and name != "scene":
        return name
    return "(unnamed)" if scene is None else type(scene).__name__
