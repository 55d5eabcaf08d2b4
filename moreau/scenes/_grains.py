"""The checks of the grain parameters shared by :mod:`moreau.scenes.granular_column` and
:mod:`moreau.scenes.silo` (one rule, one message, for both)."""

from .._validate import in_closed_interval, nonnegative, positive, positive_int
from ..errors import InputError

__all__ = ["check_grain_params"]


def check_grain_params(p, positive_names, nonnegative_names, counts=()):
    """Check and store, in place, the fields of the frozen dataclass ``p`` of a box of grains.

    In this order: ``positive_names`` > 0, ``counts`` whole numbers >= 1, ``spread`` in
    ``[1e-3, 1]``, ``nonnegative_names`` >= 0, ``restitution`` in ``[0, 1]``, ``seed`` a
    whole number >= 0, and ``width`` at least ``2.05 diameter`` (two grains side by side).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> p = SimpleNamespace(width=0.01, diameter=0.005, spread=0.8, restitution=0.0, seed=0)
    >>> check_grain_params(p, ("width", "diameter"), ())
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `width` must hold two grains (>= 2.05 `diameter`), got 0.01 m for 0.005 m grains
    """
    for name in positive_names:
        object.__setattr__(p, name, positive(name, getattr(p, name)))
    for name in counts:
        object.__setattr__(p, name, positive_int(name, getattr(p, name)))
    object.__setattr__(p, "spread", in_closed_interval("spread", p.spread, 1e-3, 1.0))
    for name in nonnegative_names:
        object.__setattr__(p, name, nonnegative(name, getattr(p, name)))
    object.__setattr__(p, "restitution",
                       in_closed_interval("restitution", p.restitution, 0.0, 1.0))
    object.__setattr__(p, "seed", positive_int("seed", int(p.seed) + 1) - 1)
    if p.width / p.diameter < 2.05:
        raise InputError(f"`width` must hold two grains (>= 2.05 `diameter`), got "
                         f"{p.width!r} m for {p.diameter!r} m grains")
