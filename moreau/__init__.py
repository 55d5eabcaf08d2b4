"""moreau: simulation of non-smooth mechanics (unilateral contact, Coulomb friction, impacts)."""

from .errors import (
    ContactLostError,
    ConvergenceError,
    IllPosedError,
    InputError,
    LCPError,
    MoreauError,
    PainleveError,
)

__version__ = "0.1.0"
