"""A user's own scene, written as a user would: a block on a moving belt, held by a spring.

Coordinates ``q = (x, y)``: the block's position along the belt (the spring
pulls it back to ``x = 0``) and its height above the belt. Unit mass,
gravity 1, spring stiffness ``k``, belt speed ``vb``, friction ``mu``. The
block sticks to the belt until the spring force ``k x`` reaches ``mu``, then
slips back: the classic stick-slip oscillator.
"""

import numpy as np
from numba import njit

from moreau.compiled import CompiledModel
from moreau.model.scene import Scene


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


# -- the same model through the compiled hook (moreau.compiled) ------------------------
# par = (k, vb). Kept in this importable module, so the engine caches its compiled loop on
# disk; the functions are the Python methods above, written for numba.

@njit
def belt_mass(par, q, M):
    M[0, 0] = 1.0
    M[1, 1] = 1.0


@njit
def belt_forces(par, q, v, t, D, need_jac):
    D[0, 0] = -par[0] * q[0]
    D[1, 0] = -1.0
    if need_jac:
        D[0, 1] = -par[0]


@njit
def belt_contacts(par, q, t, G, need_gap, need_T):
    if need_gap:
        G[0, 0] = q[1]
    G[0, 4] = 1.0           # WN = (0, 1)
    if need_T:
        G[0, 2] = -par[1]   # wT = -vb
        G[0, 5] = 1.0       # WT = (1, 0)


@njit
def belt_drift(par, q, v, t, Dr):
    Dr[0, 0] = 0.0
    Dr[0, 1] = 0.0


class CompiledBeltBlock(BeltBlock):
    """:class:`BeltBlock` with its compiled model, and the exact force Jacobians."""

    def force_jacobians(self, q, v, t):
        return np.array([[-self.k, 0.0], [0.0, 0.0]]), np.zeros((2, 2))

    def compiled_model(self):
        return CompiledModel(belt_mass, belt_forces, belt_contacts, belt_drift,
                             par=[self.k, self.vb], ndof=2, ncontacts=1, const_mass=True,
                             has_jacobians=True)


def local_belt_block():
    """``(scene class, its mass function)`` defined inside this call, as a notebook's would be.

    The mass function cannot be imported again by name (a new one each
    call), which is what the tests of notebook-defined models need.
    """
    @njit
    def mass(par, q, M):
        M[0, 0] = 1.0
        M[1, 1] = 1.0

    class Local(CompiledBeltBlock):
        def compiled_model(self):
            m = super().compiled_model()
            return CompiledModel(mass, m.forces, m.contacts, m.drift, m.par, 2, 1, True, True)

    return Local, mass
