"""Compiled pieces of the rod of a friction drive, shared by the one- and two-rod drives.

Both drives are built from one rod pressed by its spring on the rotor (the
paper's model; the two-rod drive mirrors the second rod). These scalar
pieces take the sines and cosines already evaluated, so that a caller
evaluating several outputs at one state (a model's ``step``) computes each
transcendental once, and each formula is written once for both drives.

Rod ``j`` at angle ``phi`` (``s = sin phi``, ``c = cos phi``), base motion
``u1 = u10 (1 - cos tau')`` with ``tau' = tau - delta`` (``st = sin tau'``,
``ct = cos tau'``), rotor coordinate ``rotor``::

    h_j = P c (sin phi0 - s) - u1''/2 c,   dh_j/dphi = P (-s (sin phi0 - s) - c^2) + u1''/2 s
    g = sin phi0 - s - u1,   WN = -c e_j,   wN = -u1',   WT = sgn s e_j + e_rotor,   wT = 0

(derived in :mod:`moreau.scenes.friction_drive`).
"""

from numba import njit

__all__ = ["rod_gap", "rod_forces", "rod_rows"]


@njit(cache=True)
def rod_gap(sphi0, u10, s, ct):
    return sphi0 - s - u10 * (1.0 - ct)


@njit(cache=True)
def rod_forces(D, j, P, sphi0, u10, s, c, ct, need_jac):
    ddu1 = u10 * ct
    spring = sphi0 - s
    D[j, 0] = P * c * spring - 0.5 * ddu1 * c
    if need_jac:
        D[j, 1 + j] = P * (-s * spring - c * c) + 0.5 * ddu1 * s


@njit(cache=True)
def rod_rows(G, r, j, rotor, n, sgn, u10, s, c, st, need_T):
    # contact row r of the rod with angle q[j] (layout of moreau.compiled)
    G[r, 1] = -u10 * st
    G[r, 3 + j] = -c
    if need_T:
        G[r, 3 + n + j] = sgn * s
        G[r, 3 + n + rotor] = 1.0
