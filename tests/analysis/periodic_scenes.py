"""Test-only periodic scenes with known Floquet multipliers and a known period doubling.

Both carry a spectator rotor ``r`` (``r'' = -c r'``), a coordinate that does
not enter the rest of the dynamics, so the shooting has its cyclic
coordinate; its own multiplier is ``exp(-2 pi c)``.
"""

import math

import numpy as np

from moreau.model.scene import Scene


class DampedOscillator(Scene):
    """``x'' + 2 zeta w0 x' + w0^2 x = cos t`` with one contact, ``x + 10 >= 0``, that never closes."""

    ndof = 2
    name = "damped-oscillator"
    period = 2.0 * math.pi
    cyclic_coordinates = (1,)

    def __init__(self, w0=1.3, zeta=0.1, c=0.2):
        self.w0, self.zeta, self.c = w0, zeta, c
        self.mu = np.array([0.0])
        self.restitution = np.array([0.0])

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([-self.w0 ** 2 * q[0] - 2 * self.zeta * self.w0 * v[0] + math.cos(t),
                         -self.c * v[1]])

    def gaps(self, q, t):
        return np.array([q[0] + 10.0])

    def contact_jacobians(self, q, t):
        return np.array([[1.0, 0.0]]), np.zeros(1), np.zeros((0, 2)), np.zeros(0)

    def contact_drift(self, q, v, t):
        return np.zeros(1), np.zeros(0)

    def initial_state(self):
        return np.zeros(2), np.zeros(2)

    def multipliers(self):
        """The exact multipliers: the oscillator's pair and the rotor's."""
        lam = self.w0 * complex(-self.zeta, math.sqrt(1.0 - self.zeta ** 2))
        T = self.period
        return [np.exp(lam * T), np.exp(lam.conjugate() * T), math.exp(-self.c * T)]


class TableBall(Scene):
    """A ball bouncing on a table that moves as ``A sin t``, gravity ``g``, restitution ``e``.

    The impact oscillator of period doubling: with ``Gamma = A / g`` (unit
    drive frequency) the period-1 orbit, one impact a period, loses
    stability at ``Gamma^2 = (pi (1 - e) / (1 + e))^2 + (2 (1 + e^2) / (1 + e)^2)^2``
    (1.527 for ``e = 1/2``) to a period-2 orbit.
    """

    ndof = 2
    name = "table-ball"
    period = 2.0 * math.pi
    cyclic_coordinates = (1,)

    def __init__(self, gamma=1.6, e=0.5, c=0.2):
        self.A, self.g, self.c = 1.0, 1.0 / gamma, c
        self.mu = np.array([0.0])
        self.restitution = np.array([e])

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([-self.g, -self.c * v[1]])

    def gaps(self, q, t):
        return np.array([q[0] - self.A * math.sin(t)])

    def contact_jacobians(self, q, t):
        return np.array([[1.0, 0.0]]), np.array([-self.A * math.cos(t)]), np.zeros((0, 2)), np.zeros(0)

    def contact_drift(self, q, v, t):
        return np.array([self.A * math.sin(t)]), np.zeros(0)

    def initial_state(self):
        return np.array([2.0, 0.0]), np.array([0.0, 0.0])


class RotorTableBall(TableBall):
    """The table ball with its rotor driven by the ball's height: ``r'' = -c (r' - x)``.

    The rotor's mean speed is the ball's mean height, so the displacement per
    period is ``2 pi <x>``: a long-run mean that exists for the chaotic
    bouncing of a large ``Gamma`` as well, where no periodic orbit is stable.
    """

    name = "rotor-table-ball"

    def forces(self, q, v, t):
        return np.array([-self.g, -self.c * (v[1] - q[0])])
