"""Small scenes with exact solutions, shared by the scheme tests."""

import numpy as np

from moreau.scenes.base import Scene


class Oscillator(Scene):
    """Unit mass on a unit spring, its one contact far away (never active)."""
    ndof, mu, restitution = 1, np.array([0.0]), np.array([0.0])

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return -np.asarray(q, float)

    def gaps(self, q, t):
        return np.array([q[0] + 10.0])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)


class Block(Scene):
    """Unit point mass on the ground under gravity 1, Coulomb friction mu = 0.5."""
    ndof, mu, restitution = 2, np.array([0.5]), np.array([0.0])

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([0.0, -1.0])

    def gaps(self, q, t):
        return np.array([q[1]])

    def contact_jacobians(self, q, t):
        return np.array([[0.0, 1.0]]), np.zeros(1), np.array([[1.0, 0.0]]), np.zeros(1)
