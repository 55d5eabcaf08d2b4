"""A user's own scene, written as a user would: a block on a moving belt, held by a spring.

Coordinates ``q = (x, y)``: the block's position along the belt (the spring
pulls it back to ``x = 0``) and its height above the belt. Unit mass,
gravity 1, spring stiffness ``k``, belt speed ``vb``, friction ``mu``. The
block sticks to the belt until the spring force ``k x`` reaches ``mu``, then
slips back: the classic stick-slip oscillator.
"""

import numpy as np

from moreau.scenes.base import Scene


class BeltBlock(Scene):
    ndof = 2
    name = "belt-block"

    def __init__(self, k=4.0, vb=0.5, mu=0.6):
        self.k, self.vb = k, vb
        self.mu = np.array([mu])
        self.restitution = np.array([0.0])

    def mass(self, q):
        return np.eye(2)

    def forces(self, q, v, t):
        return np.array([-self.k * q[0], -1.0])

    def gaps(self, q, t):
        return np.array([q[1]])

    def contact_jacobians(self, q, t):
        # slip velocity: the block's velocity relative to the belt
        return np.array([[0.0, 1.0]]), np.zeros(1), np.array([[1.0, 0.0]]), np.array([-self.vb])

    def contact_drift(self, q, v, t):
        return np.zeros(1), np.zeros(1)

    def initial_state(self):
        return np.zeros(2), np.array([self.vb, 0.0])
