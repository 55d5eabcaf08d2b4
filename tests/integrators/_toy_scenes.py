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


class ForcedSlider(Scene):
    """Unit point mass pressed on the ground by a varying force and pushed along it.

    Forces ``(1 + cos(t)/2 - x/5, -1 + sin(3 t)/2)``, Coulomb ``mu = 0.3``:
    launched at ``v = 1`` it slides forward without stopping on ``[0, 3]``
    (``v >= 1``), the contact closed and pressing (normal force
    ``1 - sin(3 t)/2``), so ``x'' = 1 + cos(t)/2 - x/5 - 0.3 (1 - sin(3 t)/2)``.
    """
    ndof, mu, restitution = 2, np.array([0.3]), np.array([0.0])

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([1.0 + 0.5 * np.cos(t) - 0.2 * q[0], -1.0 + 0.5 * np.sin(3.0 * t)])

    def force_jacobians(self, q, v, t):
        return np.array([[-0.2, 0.0], [0.0, 0.0]]), np.zeros((2, 2))

    def gaps(self, q, t):
        return np.array([q[1]])

    def contact_jacobians(self, q, t):
        return np.array([[0.0, 1.0]]), np.zeros(1), np.array([[1.0, 0.0]]), np.zeros(1)

    @staticmethod
    def sliding_rhs(t, y):
        """The reduced equation of the slide, ``(x, x')``, for a reference solution."""
        normal = 1.0 - 0.5 * np.sin(3.0 * t)
        return [y[1], 1.0 + 0.5 * np.cos(t) - 0.2 * y[0] - 0.3 * normal]
