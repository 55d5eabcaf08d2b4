"""Operation modes: the cyclic sequence of contact regimes over one period.

The paper names the steady states of the friction drive by their regime
sequence over a period: NS, NSPS, NPS, NP, NSP, SP. A cyclic sequence has no
first element, so this module fixes one canonical rotation: consecutive
repeats are merged (also across the period boundary) and the rotation whose
*letters* are smallest under the order ``N < S < P < F`` is chosen; only when
two rotations have the same letters do the impact marks decide. This
reproduces all six names of the paper. A regime entered through an impact
carries a ``!`` prefix (``"NF!S"``: negative slip, lift-off, flight, impact
into stick).

The rotation depends on the letters alone so that two schemes that see the
same regime cycle give the same rotation, whether or not both resolve every
impact (``"!NSNF"`` from the event-driven reference and ``"NSNF"`` from a
scheme that missed the impact still line up letter by letter).

Time-stepping schemes see regimes step by step; :func:`step_letters` turns
their per-step regime codes into letters the continuous system would use (a
closed *frictionless* contact slips, it cannot stick) and
:func:`impacts_after_flight` marks the regimes entered from flight, which is
how the event-driven reference marks its impacts.
"""

import numpy as np

from .regimes import REGIME_LETTERS, Regime

__all__ = ["mode_name", "split_tokens", "step_letters", "impacts_after_flight"]

_ORDER = {"N": 0, "S": 1, "P": 2, "F": 3}


def split_tokens(mode):
    """Split a mode string into tokens (``"NF!S"`` -> ``["N", "F", "!S"]``)."""
    tokens, pending = [], ""
    for ch in mode:
        if ch == "!":
            pending = "!"
            continue
        if ch not in _ORDER:
            raise ValueError(f"`mode` may contain only N, S, P, F and '!', got {ch!r}")
        tokens.append(pending + ch)
        pending = ""
    return tokens


def mode_name(sequence, impacts=None):
    """Canonical name of a cyclic regime sequence.

    Parameters
    ----------
    sequence : iterable of str
        Regime letters in time order over one period (``"N"``, ``"S"``, ``"P"``,
        ``"F"``); repeats are allowed and merged.
    impacts : iterable of bool, optional
        Same length as ``sequence``: True where the regime was entered by an
        impact.

    Returns
    -------
    str
        The canonical rotation, e.g. ``"NPS"``.

    Examples
    --------
    >>> mode_name("SPSN")
    'NSPS'
    >>> mode_name(["P", "P", "N", "N"])
    'NP'
    >>> mode_name("FSNF", impacts=[False, True, False, False])
    'NF!S'
    >>> mode_name("FNSN", impacts=[False, True, False, False])   # letters decide the rotation
    '!NSNF'
    """
    letters = list(sequence)
    flags = list(impacts) if impacts is not None else [False] * len(letters)
    if len(flags) != len(letters):
        raise ValueError("`impacts` must have the same length as `sequence`")
    for s in letters:
        if s not in _ORDER:
            raise ValueError(f"`sequence` may contain only N, S, P, F, got {s!r}")
    tokens = []
    for s, imp in zip(letters, flags):
        if tokens and tokens[-1][1] == s and not imp:
            continue
        tokens.append([imp, s])
    # merge across the period boundary: the run that ends the period continues the first one
    while len(tokens) > 1 and tokens[-1][1] == tokens[0][1] and not tokens[0][0]:
        tokens[0][0] = tokens[-1][0]
        tokens.pop()
    if not tokens:
        return ""
    letters_key = [_ORDER[s] for _, s in tokens]
    marks_key = [1 if imp else 0 for imp, _ in tokens]
    n = len(tokens)
    best = min(range(n), key=lambda i: (letters_key[i:] + letters_key[:i],
                                        marks_key[i:] + marks_key[:i]))
    rot = tokens[best:] + tokens[:best]
    return "".join(("!" if imp else "") + s for imp, s in rot)


def step_letters(regime, slip=None, mu=None):
    """Regime letters of the steps of a time-stepping run, as the continuous system names them.

    A step's regime comes from its impulses; a closed contact whose tangential
    impulse is strictly inside the cone is called stick. Without friction
    (``mu == 0``) there is no cone and no stick: the contact slips, in the
    direction of its slip velocity at the end of the step (``P`` for
    ``slip >= 0``, ``N`` otherwise), which is what the event-driven reference
    reports.

    Parameters
    ----------
    regime : array_like of int
        Per-step :class:`moreau.regimes.Regime` codes of one contact.
    slip : array_like of float, optional
        Per-step slip velocity of that contact; needed when ``mu == 0``.
    mu : float, optional
        Friction coefficient of the contact.

    Returns
    -------
    list of str

    Examples
    --------
    >>> step_letters([1, 3, 2, 0])
    ['P', 'S', 'N', 'F']
    >>> step_letters([3, 3, 3], slip=[0.2, -0.1, 0.0], mu=0.0)
    ['P', 'N', 'P']
    """
    codes = np.asarray(regime, dtype=int).ravel()
    letters = [REGIME_LETTERS[Regime(int(c))] for c in codes]
    if mu is not None and not float(mu) > 0.0:
        if slip is None:
            raise ValueError("`slip` is needed to name the regimes of a frictionless contact")
        sl = np.asarray(slip, dtype=float).ravel()
        if sl.shape != codes.shape:
            raise ValueError("`slip` must have one entry per step in `regime`")
        letters = [("P" if v >= 0.0 else "N") if s == "S" else s for s, v in zip(letters, sl)]
    return letters


def impacts_after_flight(letters):
    """Impact marks of a cyclic regime sequence: a contact regime that follows flight.

    A contact is closed again at the end of a flight at a non-zero approach
    velocity (a tangential touchdown is not generic), so the event-driven
    reference enters every regime after a flight through an impact; a
    time-stepping scheme's regime sequence is marked the same way.

    Examples
    --------
    >>> impacts_after_flight("NFNS")
    [False, False, True, False]
    >>> impacts_after_flight("SNF")   # cyclic: the S follows the final F
    [True, False, False]
    """
    letters = list(letters)
    n = len(letters)
    return [n > 1 and s != "F" and letters[i - 1] == "F" for i, s in enumerate(letters)]
