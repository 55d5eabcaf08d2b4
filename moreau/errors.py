"""Exception hierarchy of :mod:`moreau`.

Every exception the package raises on purpose derives from :class:`MoreauError`,
so ``except MoreauError`` catches them all. Bad input additionally derives from
:class:`ValueError`, so code that already handles ``ValueError`` keeps working.
"""

__all__ = [
    "MoreauError",
    "InputError",
    "IllPosedError",
    "PainleveError",
    "ContactLostError",
    "LCPError",
    "ConvergenceError",
    "RunawayError",
]


class MoreauError(Exception):
    """Root of all errors raised by :mod:`moreau`."""


class InputError(MoreauError, ValueError):
    """An argument breaks a stated rule (shape, sign, range, finiteness).

    The message names the argument in backticks and states the rule.
    """


class IllPosedError(MoreauError):
    """The mechanical model has no (unique) solution at the current state."""


class PainleveError(IllPosedError):
    """The Painlevé condition ``1 - mu*tan(phi) > 0`` is violated."""


class ContactLostError(IllPosedError):
    """A method that assumes permanent contact met a state where contact is lost."""


class LCPError(MoreauError):
    """A linear complementarity problem could not be solved."""


class ConvergenceError(MoreauError):
    """An iterative procedure (shooting, root finding) did not converge."""


class RunawayError(ConvergenceError):
    """No steady state exists: the driven body runs away (e.g. past the motor's stall load)."""
