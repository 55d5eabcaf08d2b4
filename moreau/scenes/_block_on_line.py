"""The compiled model of a block on a straight track, shared by :mod:`moreau.scenes.sliding_block`
and :mod:`moreau.scenes.stick_slip_motor` (a block on a moving stator).

Scaled coordinates ``q = (x, y)``: along the track and off it, unit mass; one frictional
contact, gap ``y``, normal row ``dy``, tangential row ``dx`` (the layout of
:mod:`moreau.compiled`).
"""

from numba import njit

__all__ = ["block_mass", "block_contacts"]


@njit(cache=True)
def block_mass(par, q, M):
    """The unit mass matrix of ``(x, y)``."""
    M[0, 0] = 1.0
    M[1, 1] = 1.0


@njit(cache=True)
def block_contacts(par, q, t, G, need_gap, need_T):
    """The contact's gap ``y`` and its rows on a track at rest (a moving one adds its rate)."""
    if need_gap:
        G[0, 0] = q[1]
    G[0, 4] = 1.0
    if need_T:
        G[0, 5] = 1.0
