"""Small scenes with exact solutions, shared by the scheme tests."""

import math

import numpy as np
from numba import njit
from scipy.optimize import brentq

from moreau.compiled import CompiledModel
from moreau.model.scene import Scene


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


@njit(cache=True)
def _damped_mass(par, q, M):
    M[0, 0] = 1.0


@njit(cache=True)
def _damped_forces(par, q, v, t, D, need_jac):
    D[0, 0] = -1.0 - par[1] * v[0]
    if need_jac:
        D[0, 1] = 0.0
        D[0, 2] = -par[1]


@njit(cache=True)
def _damped_contacts(par, q, t, G, need_gap, need_T):
    if need_gap:
        G[0, 0] = q[0] - par[0]
    G[0, 3] = 1.0


@njit(cache=True)
def _damped_drift(par, q, v, t, Dr):
    Dr[0, 0] = 0.0


class DampedBall(Scene):
    """A unit point mass under gravity 1 and a linear damper ``-c v``, bouncing on a floor.

    Height ``q = (y,)``, floor at ``y = r``, Newton's restitution ``e``. Between
    impacts ``u' = -1 - c u`` gives, from ``(y0, u0)`` after a time ``s``::

        u(s) = -1/c + (u0 + 1/c) exp(-c s)
        y(s) = y0 - s/c + (u0 + 1/c) (1 - exp(-c s)) / c

    (check: ``u = y'`` and ``u' = -c (u + 1/c)``). ``y`` is concave while
    ``u > -1/c``, which holds from any ``u0 > -1/c``: after the apex
    ``s_a = log(1 + c u0) / c`` (``u0 > 0``) the height decreases strictly, and
    the next impact is the one root of ``y(s) = r`` there, found by bisection
    to rounding. The impact maps ``u`` to ``-e u``.
    """
    ndof = 1
    mu = np.array([0.0])

    def __init__(self, c=0.5, restitution=0.5, r=0.1):
        self.c, self.r = float(c), float(r)
        self.restitution = np.array([float(restitution)])

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return np.array([-1.0 - self.c * v[0]])

    def gaps(self, q, t):
        return np.array([q[0] - self.r])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)

    def compiled_model(self):
        return CompiledModel(_damped_mass, _damped_forces, _damped_contacts, _damped_drift,
                             [self.r, self.c], 1, 1, True, True)

    def flight(self, s, y0, u0):
        """The state ``(y, u)`` a time ``s`` into a flight started at ``(y0, u0)``."""
        c = self.c
        decay = -math.expm1(-c * s)                 # 1 - exp(-c s), accurate for small c s
        return y0 - s / c + (u0 + 1.0 / c) * decay / c, u0 - (u0 + 1.0 / c) * decay

    def impacts(self, y0, u0, t_end):
        """Impact times and the velocities just before them, up to ``t_end``."""
        c, e = self.c, float(self.restitution[0])
        t, out = 0.0, []
        while True:
            s_lo = math.log1p(c * u0) / c if u0 > 0.0 else 0.0
            s_hi = s_lo + 1.0
            while self.flight(s_hi, y0, u0)[0] > self.r:
                s_hi *= 2.0
            s = brentq(lambda x: self.flight(x, y0, u0)[0] - self.r, s_lo, s_hi,
                       xtol=1e-15, rtol=4 * np.finfo(float).eps)
            if t + s > t_end:
                return out
            u_before = self.flight(s, y0, u0)[1]
            t += s
            out.append((t, u_before))
            y0, u0 = self.r, -e * u_before

    def exact(self, t, y0, u0):
        """The exact state at time ``t`` from ``(y0, u0)`` at 0 (not at an impact time)."""
        e = float(self.restitution[0])
        start = 0.0
        for ti, ub in self.impacts(y0, u0, t):
            start, y0, u0 = ti, self.r, -e * ub
        return self.flight(t - start, y0, u0)
