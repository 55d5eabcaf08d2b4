"""Scene parameters declared once: default, SI unit, rule and doc of each field in one place.

A scene's parameter class is a frozen dataclass deriving from
:class:`Declared`, whose fields are made by a :class:`Declaration`
(a shared one such as :data:`MASS`, or :func:`param` for a scene's own). From
each field's declaration come

- its check: :meth:`Declared.__post_init__` replaces every field by
  ``rule(name, value)``, in field order (the messages of
  :mod:`moreau._validate`); checks across fields are the class's own
  ``__post_init__``, after ``super().__post_init__()``;
- its entry in the numpydoc "Attributes" section of the class docstring,
  which is generated (at the line ``{attributes}``, or at the end);
- its :class:`~moreau.model.registry.Parameter` (unit and doc) for the scene
  registry: :func:`moreau.model.registry.parameters_of` reads them here.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class DropParams(Declared):
...     '''SI parameters of a dropped ball.'''
...     mass: float = MASS(0.1, "Mass of the ball")
...     height: float = param(1.0, "m", POSITIVE, "Initial height")
>>> DropParams(height=2).height
2.0
>>> DropParams(mass=0)
Traceback (most recent call last):
...
moreau.errors.InputError: `mass` must be > 0, got 0.0
>>> print(DropParams.__doc__)  # doctest: +NORMALIZE_WHITESPACE
SI parameters of a dropped ball.
    Attributes
    ----------
    mass : float
        Mass of the ball [kg], > 0.
    height : float
        Initial height [m], > 0.
"""

import dataclasses
import math
import textwrap
from typing import Callable, ClassVar, NamedTuple, Optional, get_origin

from .. import _validate as V

__all__ = ["Rule", "Declaration", "Declared", "param", "declaration", "open_interval",
           "whole_number", "POSITIVE", "NONNEGATIVE", "FINITE", "UNIT_INTERVAL", "MASS", "RADIUS",
           "LENGTH", "GRAVITY", "MU", "RESTITUTION", "SLOPE", "SPEED", "LOAD"]

#: the key of a field's :class:`Declaration` in its ``metadata``
KEY = "moreau.param"


class Rule(NamedTuple):
    """A check of one value: ``check(name, value, *args)`` returns the value kept (or raises),
    and ``text`` states the rule in the docs ("> 0")."""

    check: Callable
    text: str
    args: tuple = ()

    def __call__(self, name, value):
        return self.check(name, value, *self.args)


POSITIVE = Rule(V.positive, "> 0")
NONNEGATIVE = Rule(V.nonnegative, ">= 0")
FINITE = Rule(V.finite_scalar, "finite")
UNIT_INTERVAL = Rule(V.restitution, "in [0, 1]")


def open_interval(lo, hi, text, message=None):
    """The rule ``lo < value < hi``, stated ``in (text)`` in the docs; ``message`` is the
    rule's words in the error (by default the bounds' values)."""
    return Rule(V.in_open_interval, f"in ({text})", (lo, hi, message))


def whole_number(lo, hi):
    """The rule: a whole number in ``[lo, hi]`` (an integer-valued float taken)."""
    return Rule(V.whole_number, f"a whole number in [{lo}, {hi}]", (lo, hi))


@dataclasses.dataclass(frozen=True)
class Declaration:
    """The SI ``unit`` ("" when dimensionless), the ``rule`` (a :class:`Rule`, or None where
    the class checks the field itself), a one-line ``doc`` and a further ``note`` (the
    docstring's only) of a parameter.

    Calling it with a default (and optionally a ``doc``, ``note``, ``rule`` or ``unit`` of
    the scene's own) makes the dataclass field.
    """

    unit: str = ""
    rule: Optional[Rule] = None
    doc: str = ""
    note: str = ""

    def __call__(self, default, doc=None, **changes):
        if doc is not None:
            changes["doc"] = doc
        own = dataclasses.replace(self, **changes)
        return dataclasses.field(default=default, metadata={KEY: own})

    def describe(self):
        """The field's text in the docstring: "doc [unit], rule." and the note."""
        words = [w for w in (self.doc, f"[{self.unit}]" if self.unit else "") if w]
        text = " ".join(words)
        if self.rule is not None:
            text = f"{text}, {self.rule.text}" if text else self.rule.text
        if text and not text.endswith("."):
            text += "."
        return f"{text} {self.note}".strip()


def param(default, unit="", rule=None, doc="", note=""):
    """A field of a :class:`Declared` class declared on the spot:
    ``Declaration(unit, rule, doc, note)(default)``."""
    return Declaration(unit, rule, doc, note)(default)


def declaration(field):
    """The :class:`Declaration` of the dataclass ``field``, or None."""
    return field.metadata.get(KEY)


MASS = Declaration("kg", POSITIVE, "Mass")
RADIUS = Declaration("m", POSITIVE, "Radius")
LENGTH = Declaration("m", POSITIVE, "Reference length that fixes the units")
GRAVITY = Declaration("m/s^2", POSITIVE, "Gravitational acceleration")
MU = Declaration("", NONNEGATIVE, "Coulomb friction coefficient")
RESTITUTION = Declaration("", UNIT_INTERVAL, "Newton restitution coefficient")
SLOPE = Declaration("rad", open_interval(0.0, 0.5 * math.pi, "0, pi/2"), "Inclination")
SPEED = Declaration("m/s", NONNEGATIVE)
LOAD = Declaration("N", FINITE, "Load")


def _fields_in_order(cls):
    """``{name: (annotation, Declaration or None)}`` of the fields ``dataclass`` will give
    ``cls``, in its order (a base's fields first; a field declared again keeps its place)."""
    bases = [b for b in cls.__mro__[1:] if dataclasses.is_dataclass(b)]
    inherited = dataclasses.fields(bases[0]) if bases else ()
    out = {f.name: (f.type, declaration(f)) for f in inherited}
    for name, annotation in cls.__dict__.get("__annotations__", {}).items():
        if get_origin(annotation) is ClassVar or annotation is ClassVar:
            continue
        value = cls.__dict__.get(name)
        if not (isinstance(value, dataclasses.Field) and declaration(value) is not None):
            raise TypeError(f"the field `{name}` of {cls.__name__} must be declared (a "
                            f"Declaration, or moreau.model.params.param)")
        out[name] = (annotation, declaration(value))
    return out


def _attributes(cls, indent):
    lines = ["Attributes", "----------"]
    for name, (annotation, decl) in _fields_in_order(cls).items():
        lines.append(f"{name} : {getattr(annotation, '__name__', annotation)}")
        lines += textwrap.wrap(decl.describe(), 92 - len(indent), initial_indent="    ",
                               subsequent_indent="    ", break_on_hyphens=False)
    return ("\n" + indent).join(lines)


class Declared:
    """Base of a frozen parameter dataclass whose fields are declared (:class:`Declaration`).

    Its docstring gets the fields' "Attributes" section; each instance's
    fields are checked by their rules (replaced by the values the rules
    return: a float for an int given, say).
    """

    #: the names of the parameters a sweep may vary (the scene registry's ``sweepable``);
    #: a scene's parameters besides these fields, as a drive's frequency, may be named
    sweepable = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        fields = _fields_in_order(cls)
        doc = cls.__dict__.get("__doc__")
        if not doc or not fields:
            return
        if "{attributes}" in doc:
            head, _, tail = doc.partition("{attributes}")
            cls.__doc__ = head + _attributes(cls, head[head.rfind("\n") + 1:]) + tail
        else:
            cls.__doc__ = doc.rstrip() + "\n\n    " + _attributes(cls, "    ") + "\n    "

    def __post_init__(self):
        for f in dataclasses.fields(self):
            decl = declaration(f)
            if decl is not None and decl.rule is not None:
                object.__setattr__(self, f.name, decl.rule(f.name, getattr(self, f.name)))
