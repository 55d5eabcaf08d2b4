"""The grain parameters shared by :mod:`moreau.scenes.granular_column` and
:mod:`moreau.scenes.silo`, declared once (one rule, one message, for both)."""

from .._validate import in_closed_interval, positive_int
from ..errors import InputError
from ..model.params import NONNEGATIVE, POSITIVE, UNIT_INTERVAL, Declaration, Declared, Rule

__all__ = ["Grains", "WIDTH", "DIAMETER", "SPREAD", "DENSITY", "GRAIN_MU", "GRAIN_RESTITUTION",
           "SEED", "MU_R"]


def _seed(name, value):
    """``value`` as a whole number >= 0 (a float's fraction dropped)."""
    return positive_int(name, int(value) + 1) - 1


WIDTH = Declaration("m", POSITIVE)
DIAMETER = Declaration("m", POSITIVE, "The largest grain's diameter")
SPREAD = Declaration("", Rule(in_closed_interval, "in [1e-3, 1]", (1e-3, 1.0)),
                     "Smallest over largest radius")
DENSITY = Declaration("kg/m^2", POSITIVE, "Mass per unit area of the grains")
GRAIN_MU = Declaration("", NONNEGATIVE)
GRAIN_RESTITUTION = Declaration("", UNIT_INTERVAL, "Newton restitution of every contact")
SEED = Declaration("", Rule(_seed, "a whole number >= 0"), "The random radii and start jitter")
MU_R = Declaration("m", NONNEGATIVE, "Rolling-resistance length of every contact")


class Grains(Declared):
    """A box of grains' parameters: each field checked by its declaration, then ``width`` at
    least ``2.05 diameter`` (two grains side by side).

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Box(Grains):
    ...     width: float = WIDTH(0.01)
    ...     diameter: float = DIAMETER(0.005)
    >>> Box()
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `width` must hold two grains (>= 2.05 `diameter`), got 0.01 m for 0.005 m grains
    """

    def __post_init__(self):
        super().__post_init__()
        if self.width / self.diameter < 2.05:
            raise InputError(f"`width` must hold two grains (>= 2.05 `diameter`), got "
                             f"{self.width!r} m for {self.diameter!r} m grains")
