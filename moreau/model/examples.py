"""Two small scenes for the reference's examples: a point dropped on the floor, and a spring.

Each is the smallest :class:`~moreau.model.scene.Scene` that shows a scheme's
behaviour in a line or two (:class:`Drop`: an impact; :class:`Spring`: the
order of a scheme where no contact acts). How such a scene is written is
shown by their source, and by :class:`moreau.integrators.moreau_jean.MoreauJean`'s example.
:func:`drop_model` is the drop's compiled model (:mod:`moreau.compiled`).
"""

import numpy as np
from numba import njit

from ..compiled import CompiledModel
from .scene import Scene

__all__ = ["Drop", "Spring", "drop_model"]


class Drop(Scene):
    """A unit point mass at height ``q`` under gravity 1, above the floor ``q = 0``.

    One frictionless contact. Dropped from rest at height 1 with ``e = 1``
    it meets the floor at ``t = sqrt(2)`` and is back at height 1 at
    ``t = 2 sqrt(2)``.

    Parameters
    ----------
    restitution : float
        Newton's coefficient of the contact (default 1: no loss).

    Examples
    --------
    >>> from moreau.integrators import simulate
    >>> res = simulate(Drop(restitution=0.0), (0.0, 2.0), [1.0], [0.0], "moreau-jean", h=1e-2)
    >>> float(res.v[-1, 0]), bool(abs(res.q[-1, 0]) < 1e-2)   # it lands and stays, to O(h)
    (0.0, True)
    """

    ndof = 1
    mu = np.array([0.0])

    def __init__(self, restitution=1.0):
        self.restitution = np.array([float(restitution)])

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return np.array([-1.0])

    def gaps(self, q, t):
        return np.array([q[0]])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)


class Spring(Scene):
    """A unit mass on a unit spring, ``q'' = -q``, far from its one contact (``g = q + 10``).

    From ``q = 1`` at rest the motion is ``q = cos t``; the contact never acts.

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> err = [abs(simulate(Spring(), (0.0, np.pi / 2), [1.0], [0.0], "moreau-jean", h=h,
    ...                     theta=0.5).q[-1, 0]) for h in (np.pi / 40, np.pi / 80)]
    >>> round(float(np.log2(err[0] / err[1])))        # theta = 1/2: second order
    2
    """

    ndof = 1
    mu = np.array([0.0])
    restitution = np.array([0.0])

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return -np.asarray(q, float)

    def force_jacobians(self, q, v, t):
        return -np.eye(1), np.zeros((1, 1))

    def gaps(self, q, t):
        return np.array([q[0] + 10.0])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)

    def contact_drift(self, q, v, t):
        return np.zeros(1), np.zeros(0)


# the functions of moreau.compiled's example, where they are explained
@njit
def _drop_mass(par, q, M):
    M[0, 0] = 1.0


@njit
def _drop_forces(par, q, v, t, D, need_jac):
    D[0, 0] = -1.0


@njit
def _drop_contacts(par, q, t, G, need_gap, need_T):
    if need_gap:
        G[0, 0] = q[0] - par[0]
    G[0, 3] = 1.0


@njit
def _drop_drift(par, q, v, t, Dr):
    Dr[0, 0] = 0.0


def drop_model(radius=0.0):
    """:class:`Drop`'s equations as a :class:`~moreau.compiled.CompiledModel`, for a ball of ``radius``.

    Unit mass under gravity 1, one frictionless contact of gap ``q - radius``
    (``radius = 0``: the point of :class:`Drop`).

    Examples
    --------
    >>> model = drop_model(0.1)
    >>> model.ndof, model.ncontacts, float(model.par[0])
    (1, 1, 0.1)
    """
    return CompiledModel(_drop_mass, _drop_forces, _drop_contacts, _drop_drift, par=[radius],
                         ndof=1, ncontacts=1, const_mass=True, has_jacobians=False)
