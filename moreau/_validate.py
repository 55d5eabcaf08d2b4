"""Argument checks shared by the public entry points.

Each check raises :class:`moreau.errors.InputError` naming the argument in
backticks and stating the rule, before any numerical work is done.
"""

import math
import numbers

import numpy as np

from .errors import InputError


def finite_scalar(name, value):
    """Return ``value`` as a float, or raise if it is not a finite real number.

    Only numbers count: a string (``"0.1"``) or a bool (``True``) is refused
    rather than coerced, since either is a mistake at the call site.

    Examples
    --------
    >>> finite_scalar("mu", 0.1)
    0.1
    >>> finite_scalar("mu", "0.1")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `mu` must be a real number, got '0.1' (a str)
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)) \
            and not (isinstance(value, np.ndarray) and value.ndim == 0
                     and np.issubdtype(value.dtype, np.number)):
        raise InputError(f"`{name}` must be a real number, got {value!r} "
                         f"(a {type(value).__name__})")
    if isinstance(value, (complex, np.complexfloating)):
        raise InputError(f"`{name}` must be a real number, got {value!r}")
    x = as_float(name, value)
    if not math.isfinite(x):
        raise InputError(f"`{name}` must be finite, got {x!r}")
    return x


def as_float(name, value, what="be a real number"):
    """Return ``float(value)``, or raise where it has none: `name` must ``what``.

    Examples
    --------
    >>> as_float("events[0]", None, "return a real number")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `events[0]` must return a real number, got None
    """
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` must {what}, got {value!r}") from None


def positive(name, value):
    """Return ``value`` as a float, or raise unless it is finite and > 0."""
    x = finite_scalar(name, value)
    if x <= 0.0:
        raise InputError(f"`{name}` must be > 0, got {x!r}")
    return x


def nonnegative(name, value):
    """Return ``value`` as a float, or raise unless it is finite and >= 0."""
    x = finite_scalar(name, value)
    if x < 0.0:
        raise InputError(f"`{name}` must be >= 0, got {x!r}")
    return x


def in_open_interval(name, value, lo, hi, text=None):
    """Return ``value`` as a float, or raise unless ``lo < value < hi``."""
    x = finite_scalar(name, value)
    if not (lo < x < hi):
        rule = text or f"in the open interval ({lo}, {hi})"
        raise InputError(f"`{name}` must be {rule}, got {x!r}")
    return x


def in_closed_interval(name, value, lo, hi):
    """Return ``value`` as a float, or raise unless ``lo <= value <= hi``."""
    x = finite_scalar(name, value)
    if not (lo <= x <= hi):
        raise InputError(f"`{name}` must be in [{lo}, {hi}], got {x!r}")
    return x


def restitution(name, value):
    """Return ``value`` as a float, or raise unless it is a coefficient in [0, 1]."""
    return in_closed_interval(name, value, 0.0, 1.0)


def positive_int(name, value):
    """Return ``value`` as an int, or raise unless it is an integer >= 1."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"`{name}` must be an integer >= 1, got {value!r}")
    if value < 1:
        raise InputError(f"`{name}` must be an integer >= 1, got {value!r}")
    return int(value)


def whole_number(name, value, lo, hi):
    """Return ``value`` as an int, or raise unless it is a whole number in ``[lo, hi]``.

    An integer-valued float is taken (a count set from the command line or a
    sweep arrives as one); a bool is not.

    >>> whole_number("n", 3.0, 2, 5)
    3
    >>> whole_number("n", 2.5, 2, 5)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `n` must be a whole number in [2, 5], got 2.5
    """
    whole = isinstance(value, numbers.Integral) or (isinstance(value, float) and value.is_integer())
    if isinstance(value, bool) or not whole or not lo <= int(value) <= hi:
        raise InputError(f"`{name}` must be a whole number in [{lo}, {hi}], got {value!r}")
    return int(value)


def float_array(name, value, what="an array of real numbers"):
    """Return ``value`` as a float array (itself when it is one), or raise: `name` must be ``what``.

    Examples
    --------
    >>> float_array("t", [1, 2]).tolist()
    [1.0, 2.0]
    >>> float_array("t", "abc", "an array of times")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `t` must be an array of times
    """
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` must be {what}") from None


def finite_array(name, value, shape=None, ndim=None):
    """Return ``value`` as a float array after checking shape and finiteness.

    ``shape`` may contain ``None`` for a free dimension.
    """
    a = float_array(name, value)
    if ndim is not None and a.ndim != ndim:
        raise InputError(f"`{name}` must have {ndim} dimension(s), got shape {a.shape}")
    if shape is not None:
        if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
            raise InputError(f"`{name}` must have shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"`{name}` must contain only finite values (no NaN or inf)")
    return a


def times(name, value):
    """Return ``value`` as a 1-D float array of times, each finite and ``>= 0`` (a scalar: one).

    Examples
    --------
    >>> times("t", 2).tolist()
    [2.0]
    """
    t = np.atleast_1d(finite_array(name, value)).astype(float)
    if np.any(t < 0.0):
        raise InputError(f"`{name}` must be >= 0")
    return t


#: the tightest relative tolerance float64 arithmetic can certify: a hundred units of
#: rounding (eps = 2.2e-16), the floor scipy's solve_ivp sets for its own rtol
TOL_MIN = 100.0 * float(np.finfo(float).eps)
#: the loosest that still promises two correct digits
TOL_MAX = 1e-2


def relative_tolerance(name, value, floor=True):
    """Return ``value`` as a float, or raise unless ``100 eps <= value <= 1e-2``.

    A tighter tolerance cannot be met in float64: an error estimate made of
    roundings never falls below it, and an adaptive scheme halves its step
    until its step budget runs out. A looser one is no accuracy at all.
    ``floor=False`` accepts any positive tolerance up to ``1e-2``: for a
    solver that bounds its own (scipy's ``solve_ivp`` raises a smaller
    ``rtol`` to ``100 eps`` and says so) and which the package's analyses
    ask for a hundredth of their own tolerance.

    Examples
    --------
    >>> relative_tolerance("rtol", 1e-8)
    1e-08
    >>> relative_tolerance("tol", 1e-16)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `tol` must be in [100 eps, 1e-2] = [2.22e-14, 0.01]: float64 rounding (eps = 2.2e-16) bounds what an error estimate can certify, and a looser one keeps no two digits; got 1e-16
    """
    x = finite_scalar(name, value)
    if not floor:
        if not 0.0 < x <= TOL_MAX:
            raise InputError(f"`{name}` must be in (0, 1e-2]: a looser tolerance keeps no two "
                             f"digits; got {x!r}")
        return x
    if not TOL_MIN <= x <= TOL_MAX:
        raise InputError(f"`{name}` must be in [100 eps, 1e-2] = [{TOL_MIN:.3g}, {TOL_MAX:g}]: "
                         f"float64 rounding (eps = 2.2e-16) bounds what an error estimate can "
                         f"certify, and a looser one keeps no two digits; got {x!r}")
    return x


def cyclic_coordinate(scene, cyclic):
    """The index of the scene's coordinate ``cyclic`` that does not enter its dynamics.

    ``None`` takes the scene's one ``cyclic_coordinates`` entry (refused where
    it declares none, or several).

    Examples
    --------
    >>> class Rotor:                  # a scene's two attributes read here
    ...     ndof, cyclic_coordinates = 3, (2,)
    >>> cyclic_coordinate(Rotor(), None)
    2
    >>> cyclic_coordinate(Rotor(), 3)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `cyclic` must name a coordinate of the scene (0..2) that does not enter its dynamics, got 3
    """
    if cyclic is None:
        cyc = tuple(getattr(scene, "cyclic_coordinates", ()))
        cyclic = cyc[0] if len(cyc) == 1 else None
    if cyclic is None or not 0 <= int(cyclic) < scene.ndof:
        raise InputError(f"`cyclic` must name a coordinate of the scene (0..{scene.ndof - 1}) "
                         f"that does not enter its dynamics, got {cyclic!r}")
    return int(cyclic)
