"""The Illinois variant of regula falsi, one step at a time, for the analyses' root finders.

The caller keeps the bracket ``[a, b]`` with ``f(a)``, ``f(b)`` of opposite
signs, evaluates ``f`` at :func:`false_position` and narrows the bracket with
:func:`illinois_update`, which halves the value kept at the end that stays
twice in a row (Dowell and Jarratt 1971: superlinear where plain regula
falsi keeps one end and converges linearly).
"""

__all__ = ["false_position", "illinois_update"]


def false_position(a, b, fa, fb):
    """The secant's zero over ``[a, b]``, or the midpoint where rounding puts it outside.

    >>> false_position(0.0, 2.0, -1.0, 3.0)
    0.5
    """
    c = (a * fb - b * fa) / (fb - fa)
    if not min(a, b) < c < max(a, b):
        c = 0.5 * (a + b)
    return c


def illinois_update(a, fa, b, fb, c, fc, side, same_as_b):
    """``(a, fa, b, fb, side)`` after the point ``c``: it replaces ``b`` where ``same_as_b`` (its
    value has the sign of ``fb``), else ``a``; ``side`` (-1, 0 at the start, 1) says which end
    moved last, and the other end's value is halved when the same end moves twice.

    >>> illinois_update(0.0, -1.0, 2.0, 3.0, 0.5, 1.0, -1, True)
    (0.0, -0.5, 0.5, 1.0, -1)
    """
    if same_as_b:
        b, fb = c, fc
        if side == -1:
            fa *= 0.5
        side = -1
    else:
        a, fa = c, fc
        if side == 1:
            fb *= 0.5
        side = 1
    return a, fa, b, fb, side
