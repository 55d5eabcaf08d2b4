"""Contact regimes of a single 2D frictional contact and their one-letter names.

The letters follow the paper: ``N`` negative slip, ``P`` positive slip,
``S`` stick, plus ``F`` for flight (no contact). Slip is measured as the
tangential velocity of the second body relative to the first
(``dot(delta_T)``); in positive slip the friction force is ``-mu * f_N``.
"""

from enum import IntEnum

__all__ = ["Regime", "REGIME_LETTERS"]


class Regime(IntEnum):
    """Contact regime codes, stored as small integers in result arrays."""

    FLIGHT = 0
    POSITIVE = 1
    NEGATIVE = 2
    STICK = 3

    @property
    def letter(self):
        return REGIME_LETTERS[self]

    @classmethod
    def from_letter(cls, letter):
        for r, s in REGIME_LETTERS.items():
            if s == letter:
                return r
        raise ValueError(f"`letter` must be one of {sorted(REGIME_LETTERS.values())}, got {letter!r}")


REGIME_LETTERS = {
    Regime.FLIGHT: "F",
    Regime.POSITIVE: "P",
    Regime.NEGATIVE: "N",
    Regime.STICK: "S",
}
