"""Compiled (numba) kernel of the friction-drive model, for the fast Moreau–Jean path.

The formulas are those of :class:`moreau.scenes.friction_drive.FrictionDrive`
(dimensionless, ``tau = w t``, ``q = (phi, u2)``, ``v = (phi', u2')``)::

    u1 = u10 (1 - cos tau),  u1' = u10 sin tau,  u1'' = u10 cos tau
    M  = diag(1/3, J)
    h  = (P cos phi (sin phi0 - sin phi) - u1''/2 cos phi,  -f_L)
    K  = dh/dq = [[P (-sin phi (sin phi0 - sin phi) - cos^2 phi) + u1''/2 sin phi, 0], [0, 0]]
    C  = dh/dv = 0
    g  = sin phi0 - sin phi - u1,   WN = (-cos phi, 0),  wN = -u1'
    WT = (sin phi, 1),              wT = 0

:func:`fd_eval` writes all of them for one ``(q, v, t)`` into a preallocated
buffer whose layout is given by the index constants below, so that the time
stepper (:mod:`moreau.integrators._mj_kernels`) allocates nothing per step.
The layout is that of any two-dof scene with one contact; the stepper reads
only the buffer.
"""

import math

import numpy as np
from numba import njit

__all__ = ["pack_params", "fd_eval", "fd_gap", "NOUT", "NPAR"]

# parameter vector
P_J, P_P, P_U10, P_FL, P_SPHI0, P_MU, P_E = range(7)
NPAR = 7

# model buffer: mass (row-major 2x2), forces, dh/dq, dh/dv, gap, WN, wN, WT, wT
M00, M01, M10, M11 = 0, 1, 2, 3
F0, F1 = 4, 5
K00, K01, K10, K11 = 6, 7, 8, 9
C00, C01, C10, C11 = 10, 11, 12, 13
GAP = 14
WN0, WN1, WNR = 15, 16, 17
WT0, WT1, WTR = 18, 19, 20
NOUT = 21


def pack_params(scene):
    """Parameter vector of a :class:`~moreau.scenes.friction_drive.FrictionDrive` for the kernels.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> par = pack_params(FrictionDrive(frequency=185.0))
    >>> par.shape, round(float(par[P_J]))
    ((7,), 100)
    """
    return np.array([scene.J, scene.P, scene.u10, scene.fL, scene.sin_phi0,
                     float(scene.mu[0]), float(scene.restitution[0])], dtype=np.float64)


@njit(cache=True)
def fd_eval(phi, dphi, t, par, out):
    """Write mass, forces, force Jacobians, gap and contact Jacobians at ``(q, v, t)`` into ``out``.

    ``phi`` and ``dphi`` are the rod angle and rate (the rotor coordinates do
    not enter the model); ``out`` has length :data:`NOUT`.
    """
    s = math.sin(phi)
    c = math.cos(phi)
    st = math.sin(t)
    ct = math.cos(t)
    u10 = par[P_U10]
    P = par[P_P]
    spring = par[P_SPHI0] - s
    ddu1 = u10 * ct
    out[M00] = 1.0 / 3.0
    out[M01] = 0.0
    out[M10] = 0.0
    out[M11] = par[P_J]
    out[F0] = P * c * spring - 0.5 * ddu1 * c
    out[F1] = -par[P_FL]
    out[K00] = P * (-s * spring - c * c) + 0.5 * ddu1 * s
    out[K01] = 0.0
    out[K10] = 0.0
    out[K11] = 0.0
    out[C00] = 0.0
    out[C01] = 0.0
    out[C10] = 0.0
    out[C11] = 0.0
    out[GAP] = spring - u10 * (1.0 - ct)
    out[WN0] = -c
    out[WN1] = 0.0
    out[WNR] = -u10 * st
    out[WT0] = s
    out[WT1] = 1.0
    out[WTR] = 0.0


@njit(cache=True)
def fd_gap(phi, t, par):
    """Gap ``sin phi0 - sin phi - u1(t)``."""
    return par[P_SPHI0] - math.sin(phi) - par[P_U10] * (1.0 - math.cos(t))
