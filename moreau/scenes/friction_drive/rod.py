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

A model evaluates the same sines and cosines in several of its functions,
and the Moreau–Jean step calls them at the same angle and phase several
times (:func:`moreau.compiled.memo_sincos`).
"""

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from numba import njit

from ...compiled import memo_sincos
from ..._validate import positive
from ...errors import InputError
from ...model.params import (FINITE, MASS, MU, NONNEGATIVE, POSITIVE, UNIT_INTERVAL, Declaration,
                             Declared, open_interval, param)

__all__ = ["rod_gap", "rod_forces", "rod_rows", "one_rod_mass", "memo_sincos", "MEMO_SLOTS",
           "RodParams", "OneRod"]

#: entries of ``par`` that :func:`memo_sincos` keeps for one argument, and what they
#: start at: an argument with its sine and cosine, exact ones, so that ``par`` is
#: consistent from the start
MEMO_SLOTS = (0.0, 0.0, 1.0)


@njit(cache=True)
def one_rod_mass(par, q, M):
    # one rod on the rotor, q = (phi, rotor): diag(1/3, J), J = par[0] in every one-rod model
    M[0, 0] = 1.0 / 3.0
    M[1, 1] = par[0]


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


#: a stator's displacement amplitude (the rod drives' x10), also below ``length sin(phi0) / 2``
AMPLITUDE = Declaration("m", POSITIVE, "Stator displacement amplitude",
                        "It must be below ``length sin(phi0) / 2``: the rod must not pass the "
                        "horizontal while in contact.")
#: the load on the rotor
ROTOR_LOAD = Declaration("N", FINITE, "Load ``F_L`` on the rotor")
#: the restitution of the rod-rotor impacts
ROD_RESTITUTION = Declaration("", UNIT_INTERVAL, "Newton restitution coefficient ``e`` of the "
                                                 "rod-rotor impacts")
#: the preload pressing the rod tip on the rotor
PRELOAD = Declaration("N", NONNEGATIVE, "Preload ``F_p``",
                      "The normal force pressing the rod tip on the rotor at rest, from a soft "
                      "pre-compressed preload spring (:mod:`moreau.scenes.friction_drive`, "
                      "\"Preload\").")


@dataclass(frozen=True)
class RodParams(Declared):
    """The parameters every rod drive shares, in SI units (the paper's values by default).

    The rod drives' parameter classes extend it, so that these fields come
    first, in this order, with these defaults and rules, in each of them.

    {attributes}

    Examples
    --------
    >>> RodParams(mu=0.2).with_(m=1e-5)
    RodParams(m=1e-05, m2=0.002, k=10000.0, length=0.001, phi0=0.7853981633974483, mu=0.2)
    """

    m: float = MASS(2.0e-5, "Rod mass")
    m2: float = MASS(2.0e-3, "Rotor mass")
    k: float = param(1.0e4, "N/m", POSITIVE, "Supporting spring stiffness")
    length: float = param(1.0e-3, "m", POSITIVE, "Rod length")
    phi0: float = param(math.pi / 4, "rad", open_interval(0.0, math.pi / 2, "0, pi/2",
                                                          "in the open interval (0, pi/2)"),
                        "Initial tilt of the rod")
    mu: float = MU(0.1)

    def _check_amplitude(self, name, x):
        # the rod must stay above the horizontal while in contact
        if not 2.0 * x < self.length * math.sin(self.phi0):
            raise InputError(
                f"`{name}` must be < length*sin(phi0)/2 = {self.length * math.sin(self.phi0) / 2!r} m "
                f"so that the rod stays above the horizontal in contact, got {x!r}")

    def with_(self, **changes):
        """Copy with some parameters changed (validated again)."""
        return replace(self, **changes)

    @classmethod
    def from_kwargs(cls, **kwargs):
        """The parameters from keyword arguments, ``None`` values left at their defaults.

        Examples
        --------
        >>> RodParams.from_kwargs(mu=0.2, m=None).mu
        0.2
        >>> RodParams.from_kwargs(x10=1e-6)
        Traceback (most recent call last):
        ...
        moreau.errors.InputError: unknown parameter(s) ['x10']; known: ['k', 'length', 'm', 'm2', 'mu', 'phi0']
        """
        names = {f.name for f in fields(cls)}
        unknown = set(kwargs) - names
        if unknown:
            raise InputError(f"unknown parameter(s) {sorted(unknown)}; known: {sorted(names)}")
        return cls(**{k: v for k, v in kwargs.items() if v is not None})


class OneRod:
    """What the drives of one rod at angle ``q[0]`` share: its valid region and first state.

    A mixin; the scene defines ``rest_state()``.
    """

    #: the rod's geometry (tip towards the rotor, contact above the hinge) holds only there
    valid_region = "0 < phi < pi/2 (the rod leans towards the rotor from below its upright position)"

    def inside_valid_region(self, t, q, v):
        phi = np.asarray(q)[:, 0]
        return (phi > 0.0) & (phi < 0.5 * math.pi)

    def initial_state(self):
        """The rest state :meth:`rest_state` at ``tau = 0``."""
        return self.rest_state()


class StatorMotion:
    """The prescribed base motion of a rod drive's rods, ``u1 = u10 (1 - cos(tau - delta))``.

    A mixin of the rod drives: each sets ``u10`` (the amplitude over the rod
    length, one per rod) and, with rods out of phase, ``delta`` (their phase
    lags); ``tau - 0.0`` is ``tau`` exactly, so a drive in phase loses nothing.
    """

    delta = 0.0

    def _scale_one_rod(self, p, frequency):
        """The dimensionless numbers of one rod of SI parameters ``p`` driven at ``frequency``.

        Time is ``tau = w t`` and forces are over ``m l w^2`` (see
        :mod:`moreau.scenes.friction_drive`).
        """
        self.frequency = positive("frequency", frequency)
        self.omega = 2.0 * math.pi * self.frequency
        self.J = p.m2 / p.m
        self.P = p.k / (p.m * self.omega ** 2)
        self.u10 = p.x10 / p.length
        self.force_scale = p.m * p.length * self.omega ** 2
        self.fL = p.load / self.force_scale
        #: dimensionless preload ``f_p = F_p / (m l w^2)`` (module docstring, "Preload")
        self.fp = p.preload / self.force_scale
        self.phi0 = p.phi0
        self.sin_phi0 = math.sin(p.phi0)
        self.mu = np.array([p.mu])
        self.restitution = np.array([p.restitution])
        #: velocity scale of the motion (the stator velocity amplitude), for tolerances
        self.velocity_scale = self.u10

    def u1(self, tau):
        return self.u10 * (1.0 - np.cos(tau - self.delta))

    def du1(self, tau):
        return self.u10 * np.sin(tau - self.delta)

    def ddu1(self, tau):
        return self.u10 * np.cos(tau - self.delta)

    def __repr__(self):
        return f"{type(self).__name__}(frequency={self.frequency!r}, params={self.params!r})"
