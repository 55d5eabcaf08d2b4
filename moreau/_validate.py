"""Argument checks shared by the public entry points.

Each check raises :class:`moreau.errors.InputError` naming the argument in
backticks and stating the rule, before any numerical work is done.
"""

import math

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
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` must be a real number, got {value!r}") from None
    if not math.isfinite(x):
        raise InputError(f"`{name}` must be finite, got {x!r}")
    return x


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


def positive_int(name, value):
    """Return ``value`` as an int, or raise unless it is an integer >= 1."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"`{name}` must be an integer >= 1, got {value!r}")
    if value < 1:
        raise InputError(f"`{name}` must be an integer >= 1, got {value!r}")
    return int(value)


def finite_array(name, value, shape=None, ndim=None):
    """Return ``value`` as a float array after checking shape and finiteness.

    ``shape`` may contain ``None`` for a free dimension.
    """
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` must be an array of real numbers") from None
    if ndim is not None and a.ndim != ndim:
        raise InputError(f"`{name}` must have {ndim} dimension(s), got shape {a.shape}")
    if shape is not None:
        if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
            raise InputError(f"`{name}` must have shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"`{name}` must contain only finite values (no NaN or inf)")
    return a
