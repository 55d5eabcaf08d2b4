"""A problem of the benchmark suite: a registered scene with its reference and tolerance.

A problem lives in its own module under :mod:`moreau.suite.problems` and
ends with one call to :func:`register_problem`; :func:`discover` imports the
modules, so a new file is picked up by ``moreau suite`` with nothing else to
edit. A problem states:

``scene``
    the registered scene it runs (:mod:`moreau.model.registry`), with its
    parameters;
``start()`` and ``window``
    the start state and the time window, in the scene's own time;
``reference()``
    ``{quantity: value}`` of its headline quantities: from a closed form, a
    published value (with its source and stated accuracy) or the event-driven
    reference (``reference_kind`` says which, ``source`` cites it);
``measure(result)``
    the same quantities read from any scheme's :class:`SimulationResult`;
``scales`` and ``tolerance``
    the error of a quantity is ``|value - reference| / scale``; a run is
    accurate when every error is at most ``tolerance``;
``steps`` / ``quick_steps``
    the step counts over the window of the time-stepping schemes (the
    work-precision points), finest last;
``quick_settings``
    ``{scheme: values}``: where a scheme's usual quick settings cost the
    quick suite too much on this problem, the values it runs at instead
    (step counts for a scheme that takes ``h``, else values of its own
    comparison setting or ``rtol``); the full suite keeps its settings;
``declines`` / ``quick_declines``
    ``{scheme: reason}``: schemes the problem refuses by name, in every
    suite or in the quick one only; their row is *refused* with the reason.

Examples
--------
>>> from moreau.suite.problem import problem_names, get_problem
>>> "bouncing-ball" in problem_names()
True
>>> sorted(get_problem("bouncing-ball").reference())
['first_impact_time', 'rebound_height', 'rest_time']
"""

import importlib
import math
import pkgutil

import numpy as np

from ..errors import InputError
from ..model.registry import make_scene

__all__ = ["Problem", "register_problem", "get_problem", "problem_names", "problems",
           "discover", "PENDING", "crossing_time", "judge"]

#: problems whose scene has not landed yet: ``{name: what will state it}``. The suite's page
#: lists them; the module that registers the problem replaces the entry.
PENDING = {}


class Problem:
    """Base class of the suite's problems (one subclass per module, see the module docstring)."""

    name = ""
    title = ""
    scene = ""
    #: "closed form", "published value" or "event-driven reference"
    reference_kind = "closed form"
    source = ""
    tolerance = 1e-2
    steps = (100, 1000, 10000)
    #: ``{scheme: values}`` replacing the scheme's quick settings on this problem
    quick_settings = {}
    #: ``{scheme: reason}`` refused by name in every suite / in the quick suite
    declines = {}
    quick_declines = {}
    #: a problem built on a scene's comparison case (``moreau.analysis.cases``): its class
    case_class = None
    _case = None

    def case_parameters(self):
        """Keyword parameters of :attr:`case_class` (its defaults where empty)."""
        return {}

    def _the_case(self):
        # built once, on first use: a case's reference is computed lazily and kept
        if self._case is None:
            self._case = self.case_class(**self.case_parameters())
        return self._case

    def scene_parameters(self):
        """Keyword parameters of the registered scene (its defaults where empty)."""
        return {}

    def make_scene(self):
        if self.case_class is not None:
            return self._the_case().scene
        return make_scene(self.scene, **self.scene_parameters())

    def start(self, scene):
        """``(q0, v0)`` at ``t = 0``, in the scene's units: the case's start, for a
        problem built on a case, else the scene's initial state."""
        if self.case_class is not None:
            return self._the_case().start()
        return scene.initial_state()

    @property
    def quick_steps(self):
        """The quick suite's step counts: the two coarsest of :attr:`steps`, unless a problem
        sets its own."""
        return self.steps[:2]

    @property
    def window(self):
        """The time window, in the scene's units: the case's, for a problem built on a
        case, else 1 (a problem sets its own as a class attribute)."""
        if self.case_class is not None:
            return self._the_case().window
        return 1.0

    def reference(self):
        raise NotImplementedError

    def declined(self, scheme, quick=False):
        """The reason the problem refuses ``scheme`` by name (in the quick suite if ``quick``), or None."""
        reason = self.declines.get(scheme)
        if reason is None and quick:
            reason = self.quick_declines.get(scheme)
        return reason

    def scales(self):
        """``{quantity: scale}``: what an error is relative to."""
        raise NotImplementedError

    def measure(self, scene, res):
        raise NotImplementedError

    def errors(self, values, reference=None):
        """``{quantity: |value - reference| / scale}`` (None where the run gave no value)."""
        ref = self.reference() if reference is None else reference
        sc = self.scales()
        out = {}
        for k, r in ref.items():
            v = values.get(k)
            out[k] = (None if v is None or not math.isfinite(v)
                      else float(abs(v - r) / sc[k]))
        return out

    def describe(self, reference=None):
        """The problem's statement for the report (``reference``: computed already)."""
        return {"name": self.name, "title": self.title, "scene": self.scene,
                "scene_parameters": self.scene_parameters(), "window": self.window,
                "reference_kind": self.reference_kind, "source": self.source,
                "tolerance": self.tolerance,
                "reference": self.reference() if reference is None else dict(reference),
                "scales": self.scales()}


_PROBLEMS = {}


def register_problem(cls):
    """Class decorator: register a :class:`Problem` subclass under ``cls.name``."""
    if not (isinstance(cls, type) and issubclass(cls, Problem)) or not cls.name:
        raise InputError("`cls` must be a Problem subclass with a `name`")
    old = _PROBLEMS.get(cls.name)
    if old is not None and old.__module__ != cls.__module__:
        raise InputError(f"a problem named {cls.name!r} is registered already (by {old.__module__})")
    _PROBLEMS[cls.name] = cls
    PENDING.pop(cls.name, None)
    return cls


_discovered = False


def discover():
    """Import every module of :mod:`moreau.suite.problems` once; return the sorted names."""
    global _discovered
    if not _discovered:
        _discovered = True
        pkg = importlib.import_module(f"{__package__}.problems")
        for info in pkgutil.iter_modules(pkg.__path__):
            if not info.name.startswith("_"):
                importlib.import_module(f"{pkg.__name__}.{info.name}")
    return sorted(_PROBLEMS)


def problem_names():
    return discover()


def get_problem(name):
    """A new instance of the problem registered as ``name``; an unknown name lists the known ones."""
    discover()
    try:
        return _PROBLEMS[name]()
    except (KeyError, TypeError):
        raise InputError(f"`problems` must name problems of the suite, from "
                         f"{', '.join(sorted(_PROBLEMS))}; got {name!r}") from None


def problems():
    return [get_problem(n) for n in discover()]


def crossing_time(t, y, level, direction=-1, after=-math.inf):
    """First time after ``after`` at which ``y`` crosses ``level`` (linear between samples).

    ``direction`` -1: from above to at-or-below; +1: from below to at-or-above.
    None when it never does.

    Examples
    --------
    >>> crossing_time([0.0, 1.0, 2.0], [2.0, 1.0, 0.0], 0.5)
    1.5
    """
    t = np.asarray(t, dtype=float)
    y = (np.asarray(y, dtype=float) - level) * (-1.0 if direction < 0 else 1.0)
    for i in range(1, len(t)):
        if t[i] <= after:
            continue
        if y[i - 1] < 0.0 <= y[i]:
            if t[i] == t[i - 1]:
                return float(t[i])
            return float(t[i - 1] + (t[i] - t[i - 1]) * (-y[i - 1]) / (y[i] - y[i - 1]))
    return None


def judge(problem, row, reference=None):
    """Fill ``row``'s ``errors``, ``max_error``, ``outcome`` and ``cause`` from its ``values``.

    The outcome is ``ok`` when every headline quantity is within the
    problem's tolerance of ``reference`` (the problem's own by default),
    else ``inaccurate``, naming the quantity with no value or the worst one.
    Returns ``row``.

    Examples
    --------
    >>> p = get_problem("sliding-block")
    >>> ref = p.reference()
    >>> judge(p, {"values": dict(ref)}, ref)["outcome"]
    'ok'
    """
    errors = problem.errors(row["values"], reference)
    row["errors"] = errors
    missing = [k for k, e in errors.items() if e is None]
    row["max_error"] = math.inf if missing else max(errors.values(), default=0.0)
    if missing:
        row["outcome"] = "inaccurate"
        row["cause"] = "no value for " + ", ".join(missing)
    elif row["max_error"] <= problem.tolerance:
        row["outcome"] = "ok"
    else:
        worst = max(errors, key=errors.get)
        row["outcome"] = "inaccurate"
        row["cause"] = f"{worst} off by {errors[worst]:.3g} > {problem.tolerance:g}"
    return row
