"""Operation modes: the cyclic sequence of contact regimes over one period.

The paper names the steady states of the friction drive by their regime
sequence over a period: NS, NSPS, NPS, NP, NSP, SP. A cyclic sequence has no
first element, so this module fixes one canonical rotation: consecutive
repeats are merged (also across the period boundary) and the rotation that is
smallest under the order ``N < S < P < F`` is chosen. This reproduces all six
names of the paper. A regime entered through an impact carries a ``!`` prefix
(``"NF!S"``: negative slip, lift-off, flight, impact into stick).
"""

__all__ = ["mode_name", "split_tokens"]

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
    keyed = [(_ORDER[s], 0 if not imp else 1) for imp, s in tokens]
    n = len(tokens)
    best = min(range(n), key=lambda i: keyed[i:] + keyed[:i])
    rot = tokens[best:] + tokens[:best]
    return "".join(("!" if imp else "") + s for imp, s in rot)
