"""The scene registry: every scene is one entry, registered by its own module.

A scene module ends with one call to :func:`register_scene`; nothing else in
the package lists or names the scene. The registry discovers the modules of
:mod:`moreau.scenes` on first use (:func:`discover`), so a new file with a
registered scene is picked up by every command and analysis (``moreau
scenes``, ``moreau compare --scene NAME``, the conformance tests).

The registry sits on the ground floor (:mod:`moreau.model`): the schemes and
analyses below the scenes find them here by name and never import them. It
imports the scene and study packages by name only, on discovery.

An entry holds:

``name``
    the name commands take (``--scene NAME``);
``factory``
    builds the scene from keyword parameters (``factory(**params)``), in SI
    units where the scene has them;
``parameters``
    :class:`Parameter` tuples (name, unit, default, description), every
    keyword the factory takes; when the entry does not give them, those of
    the factory's parameter class ``factory.Params`` (a
    :class:`~moreau.model.scene.FromParams` scene's class attribute; a
    function factory is given it as ``factory.Params = ParamsClass``), by
    :func:`parameters_of`;
``description``
    one line for listings;
``case``
    the scene's comparison case (a :class:`moreau.analysis.cases.CompareCase`
    subclass) for ``moreau compare``, or None;
``reference``
    the name of the scene's own exact or high-precision reference scheme
    ("exact" for a closed form), or None where the generic event-driven
    scheme is the reference; when the entry does not give it, the case's
    ``listed_reference``;
``sweepable``
    the parameters a sweep may vary; when the entry does not give them,
    the ``sweepable`` of the factory's ``Params`` (none without one);
``aliases``
    former names that commands still accept;
``mj_tolerance``
    how close Moreau–Jean at the conformance test's step must come to the
    reference (relative to the motion's scale): the scene's stated
    tolerance for the conformance suite; when the entry does not give it,
    the case's ``mj_tolerance`` (:data:`MJ_TOLERANCE` without a case).
``default``
    the scene commands take when none is named (one scene: the paper's).
``stress``
    a function returning the scene's cases for the stress
    catalogue (:mod:`moreau.studies.paper.stress`): ``{case_id: {"title",
    "scene", "steps", "bound"}}`` with ``scene`` a callable building the
    scene, and optionally ``reference`` (a callable returning the steady
    state that stands for the event-driven one) with ``note`` saying what it
    is; None where the scene adds none.

A study of one scene registers its own hooks (:func:`register_hook`), and
the entry finds them by the scene's name (``entry.sweep``, ``entry.atlas``;
:func:`hook`):

``sweep``
    the scene's own study sweep, which ``moreau sweep --scene NAME`` runs
    with its parsed arguments instead of the generic one
    (:mod:`moreau.analysis.sweep`); None for the generic sweep.
``atlas``
    the scene's own atlas, which ``moreau atlas --scene NAME`` runs with its
    parsed arguments when no plane is given (``--x``, ``--y``: the generic
    atlas, :mod:`moreau.analysis.atlas`); None where the scene has none.

Examples
--------
>>> from moreau.model import registry
>>> "bouncing-ball" in registry.scene_names()
True
>>> ball = registry.make_scene("bouncing-ball", restitution=0.8)
>>> float(ball.restitution[0])
0.8
>>> registry.get_entry("no-such-scene")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
moreau.errors.InputError: `scene` must be one of 'ball-chain', ...; got 'no-such-scene'
"""

import dataclasses
import importlib
import inspect
import math
import pkgutil
from typing import Callable, NamedTuple, Optional

from ..errors import InputError
from .params import declaration

__all__ = ["Parameter", "SceneEntry", "register_scene", "get_entry", "scene_names", "entries",
           "make_scene", "discover", "scene_modules", "parameters_of", "describe", "default_scene",
           "register_hook", "hook", "resolve_hook", "HOOK_KINDS", "MJ_TOLERANCE"]


class Parameter(NamedTuple):
    """One keyword parameter of a scene: ``name``, SI ``unit`` ("" when
    dimensionless, "choice" for a name), ``default`` and a one-line ``doc``."""

    name: str
    unit: str
    default: object
    doc: str = ""


#: the conformance tolerance of a scene whose entry and case state none
MJ_TOLERANCE = 1e-2


@dataclasses.dataclass(frozen=True)
class SceneEntry:
    """A registered scene (see the module docstring for the fields).

    ``parameters``, ``sweepable``, ``reference`` and ``mj_tolerance`` left
    out (None) are read from the factory and the case; given, they win.

    Examples
    --------
    >>> from moreau.model.examples import Drop
    >>> SceneEntry(name="drop", factory=Drop, description="a point dropped")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `parameters` of scene 'drop' must be given: its factory Drop has no parameter class `Params` to read them from (a FromParams scene's class attribute, or a function factory's attribute)
    >>> SceneEntry(name="drop", factory=Drop, description="a point dropped",
    ...            parameters=()).mj_tolerance
    0.01
    """

    name: str
    factory: Callable
    parameters: Optional[tuple] = None
    description: Optional[str] = None
    case: Optional[type] = None
    reference: Optional[str] = None
    sweepable: Optional[tuple] = None
    mj_tolerance: Optional[float] = None
    #: former names that commands still accept
    aliases: tuple = ()
    default: bool = False
    stress: Optional[Callable] = None

    def __post_init__(self):
        if self.description is None:
            raise InputError(f"`description` of scene {self.name!r} must be given: one line "
                             f"for `moreau scenes`")
        derived = {}
        params_class = getattr(self.factory, "Params", None)
        if self.parameters is None:
            if params_class is None:
                name = getattr(self.factory, "__name__", repr(self.factory))
                raise InputError(f"`parameters` of scene {self.name!r} must be given: its "
                                 f"factory {name} has no parameter class `Params` to read them "
                                 f"from (a FromParams scene's class attribute, or a function "
                                 f"factory's attribute)")
            derived["parameters"] = parameters_of(params_class)
        if self.sweepable is None:
            derived["sweepable"] = getattr(params_class, "sweepable", ())
        if self.reference is None:
            derived["reference"] = getattr(self.case, "listed_reference", None)
        if self.mj_tolerance is None:
            derived["mj_tolerance"] = getattr(self.case, "mj_tolerance", MJ_TOLERANCE)
        for key, value in derived.items():
            # frozen: the derived fields are set once, here, as the constructor would
            object.__setattr__(self, key, value)

    @property
    def sweep(self):
        """The scene's own sweep, registered by its study (:func:`register_hook`), or None."""
        return hook(self.name, "sweep")

    @property
    def atlas(self):
        """The scene's own atlas, registered by its study (:func:`register_hook`), or None."""
        return hook(self.name, "atlas")

    def parameter_names(self):
        return tuple(p.name for p in self.parameters)

    def defaults(self):
        """``{name: default}`` of every parameter."""
        return {p.name: p.default for p in self.parameters}


_REGISTRY = {}
_ALIASES = {}


def register_scene(entry):
    """Add ``entry`` (a :class:`SceneEntry`) to the registry and return it.

    A second registration under the same name must come from the same
    module (a module reloaded); two different scenes under one name is an
    error.
    """
    if not isinstance(entry, SceneEntry):
        raise InputError(f"`entry` must be a SceneEntry, got {type(entry).__name__}")
    old = _REGISTRY.get(entry.name)
    if old is not None and getattr(old.factory, "__module__", None) != getattr(
            entry.factory, "__module__", None):
        raise InputError(f"a scene named {entry.name!r} is registered already "
                         f"(by {old.factory.__module__})")
    if entry.stress is not None and not callable(entry.stress):
        raise InputError(f"`stress` of scene {entry.name!r} must be a function, got "
                         f"{entry.stress!r}")
    names = [p.name for p in entry.parameters]
    if len(set(names)) != len(names):
        raise InputError(f"scene {entry.name!r} lists a parameter twice: {names}")
    _REGISTRY[entry.name] = entry
    for alias in entry.aliases:
        _ALIASES[alias] = entry.name
    return entry


#: the package whose public modules are the scenes; imported by name on discovery, so that
#: this module stays on the ground floor, below the scenes that register themselves here
SCENE_PACKAGE = "moreau.scenes"


def scene_modules():
    """Names of the public modules of :mod:`moreau.scenes` (private ``_name`` ones left out)."""
    package = importlib.import_module(SCENE_PACKAGE)
    return [f"{SCENE_PACKAGE}.{info.name}" for info in pkgutil.iter_modules(package.__path__)
            if not info.name.startswith("_")]


_discovered = False


def discover():
    """Import every public module of :mod:`moreau.scenes`, so that each registers its scene.

    Done once per process, lazily: by the first call of :func:`scene_names`,
    :func:`entries` or :func:`get_entry`, so that importing one scene module
    does not import all of them. Returns the sorted scene names.
    """
    global _discovered
    if not _discovered:
        _discovered = True
        for module in scene_modules():
            importlib.import_module(module)
    return sorted(_REGISTRY)


def scene_names():
    """Sorted names of the registered scenes."""
    return discover()


def entries():
    """The registered entries, sorted by name."""
    return [_REGISTRY[k] for k in discover()]


def get_entry(name):
    """The entry registered as ``name``; an unknown name lists the known ones."""
    discover()
    try:
        return _REGISTRY[_ALIASES.get(name, name)]
    except (KeyError, TypeError):
        known = ", ".join(repr(k) for k in scene_names())
        raise InputError(f"`scene` must be one of {known}; got {name!r}") from None


def default_scene():
    """The name of the scene commands take when none is named (the entry with ``default=True``)."""
    names = [e.name for e in entries() if e.default]
    if len(names) != 1:
        raise InputError(f"exactly one registered scene must be the default, found {names}")
    return names[0]


#: the kinds of hook a study registers for a scene (see the module docstring)
HOOK_KINDS = ("sweep", "atlas")

#: the package whose modules are the studies; imported by name when a hook is first asked for
STUDY_PACKAGE = "moreau.studies"

_HOOKS = {}
_studies_discovered = False


def register_hook(scene, kind, function):
    """Make ``function`` the ``kind`` hook (one of :data:`HOOK_KINDS`) of ``scene``; return it.

    A study module calls this once for the scene it studies, so that
    ``moreau sweep --scene NAME`` (or ``moreau atlas``) runs the study's
    own function. A second registration must come from the same module (a
    module reloaded).

    Examples
    --------
    >>> register_hook("bouncing-ball", "plot", print)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `kind` must be one of 'sweep', 'atlas'; got 'plot'
    """
    if kind not in HOOK_KINDS:
        known = ", ".join(repr(k) for k in HOOK_KINDS)
        raise InputError(f"`kind` must be one of {known}; got {kind!r}")
    if not callable(function):
        raise InputError(f"`function` must be callable, got {function!r}")
    name = get_entry(scene).name
    old = _HOOKS.get((name, kind))
    if old is not None and getattr(old, "__module__", None) != getattr(function, "__module__",
                                                                          None):
        raise InputError(f"scene {name!r} has a {kind} hook already (from {old.__module__})")
    _HOOKS[(name, kind)] = function
    return function


def _discover_studies():
    global _studies_discovered
    if not _studies_discovered:
        _studies_discovered = True
        package = importlib.import_module(STUDY_PACKAGE)
        for info in pkgutil.walk_packages(package.__path__, f"{STUDY_PACKAGE}."):
            importlib.import_module(info.name)


def hook(scene, kind):
    """The ``kind`` hook a study registered for ``scene`` (:func:`register_hook`), or None.

    The first call imports every module of :mod:`moreau.studies`, so that each
    registers its hooks.

    Examples
    --------
    >>> hook("friction-drive", "sweep").__module__
    'moreau.studies.paper.sweeps'
    >>> hook("bouncing-ball", "atlas") is None
    True
    """
    if kind not in HOOK_KINDS:
        known = ", ".join(repr(k) for k in HOOK_KINDS)
        raise InputError(f"`kind` must be one of {known}; got {kind!r}")
    name = get_entry(scene).name
    _discover_studies()
    return _HOOKS.get((name, kind))


def resolve_hook(function):
    """The function a hook stands for: the hook itself, checked to be callable.

    Examples
    --------
    >>> resolve_hook(abs)(-2.0)
    2.0
    """
    if not callable(function):
        raise InputError(f"a hook must be a function, got {function!r}")
    return function


def make_scene(name, **params):
    """Build the registered scene ``name`` from keyword parameters (unknown ones refused)."""
    entry = get_entry(name)
    known = entry.parameter_names()
    for key in params:
        if key not in known:
            raise InputError(f"`{key}` is not a parameter of scene {name!r}; "
                             f"its parameters: {', '.join(known)}")
    return entry.factory(**params)


def parameters_of(params_class, extra=()):
    """:class:`Parameter` tuples from a frozen parameter dataclass whose fields are declared
    (:mod:`moreau.model.params`): each field's name, default, unit and doc, in field order.

    ``extra`` are further :class:`Parameter` entries (e.g. the drive
    frequency) put first. A doc is plain text here (for the command line and
    JSON): the reST literal marks of the docstring's version go.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> from moreau.model.params import MASS, Declared
    >>> @dataclass(frozen=True)
    ... class BallParams(Declared):
    ...     mass: float = MASS(0.1, "Mass of the ball ``m``")
    >>> parameters_of(BallParams)
    (Parameter(name='mass', unit='kg', default=0.1, doc='Mass of the ball m'),)
    """
    out = list(extra)
    for f in dataclasses.fields(params_class):
        decl = declaration(f)
        if decl is None:
            raise InputError(f"the parameter `{f.name}` of {params_class.__name__} is not "
                             f"declared (moreau.model.params)")
        out.append(Parameter(f.name, decl.unit, f.default, decl.doc.replace("``", "")))
    return tuple(out)


def _jsonable(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    return repr(value)


def describe(entry):
    """JSON-ready description of ``entry``: ``name``, ``description``,
    ``parameters`` (name, unit, default, doc), ``reference``, ``sweepable``,
    ``compare`` (the parameters the comparison case takes besides the
    scene's, or None without a case)."""
    case_params = None
    if entry.case is not None:
        sig = inspect.signature(entry.case.__init__)
        own = entry.parameter_names()
        case_params = [p for p in sig.parameters if p != "self" and p not in own
                       and sig.parameters[p].kind is not inspect.Parameter.VAR_KEYWORD]
    return {
        "name": entry.name,
        "description": entry.description,
        "parameters": [{"name": p.name, "unit": p.unit, "default": _jsonable(p.default),
                        "doc": p.doc} for p in entry.parameters],
        "reference": entry.reference or "event-driven-generic",
        "sweepable": list(entry.sweepable),
        "compare": case_params,
    }
