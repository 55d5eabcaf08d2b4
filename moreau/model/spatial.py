r"""Spatial rigid-body kinematics: unit quaternions, the exponential map, the gyroscopic term.

Conventions. A quaternion is ``q = (w, x, y, z)``; a unit one maps body
to world by :func:`rotation_matrix`. The angular velocity ``omega`` is in
the body frame, so the orientation obeys ``q' = 1/2 q ⊗ (0, omega)``, and
the body-frame Euler equations with inertia tensor ``J`` (about the centre
of mass, body frame) read

.. math::

    J \dot\omega + \omega \times J\omega = \tau_{body}.

Rotation update. For a step ``h`` with a constant body rate ``omega`` the
exact solution of ``q' = 1/2 q ⊗ (0, omega)`` is

.. math::

    q_{k+1} = q_k \otimes \exp\bigl((0, h\omega/2)\bigr), \qquad
    \exp((0, v)) = (\cos|v|, \; \tfrac{\sin|v|}{|v|} v),

(the pure quaternion's powers alternate between ``-|v|^2`` and ``(0, v)
(-|v|^2)^k``, and the series sums to cosine and sine). Both factors are
unit quaternions, so the norm stays 1 in exact arithmetic; the one
rounding each product leaves is removed by dividing by the norm, which
keeps ``|q| - 1`` at the level of one rounding (not a random walk over the
steps).

The free body (:func:`free_rigid_body`) advances ``omega`` by the implicit
midpoint rule on Euler's equations, ``J (omega_{k+1} - omega_k) = -h
omega_m x J omega_m`` with ``omega_m = (omega_k + omega_{k+1}) / 2``
(Newton on the 3x3 system to rounding), and ``q`` by the exponential map
with ``omega_m``. The midpoint rule keeps every quadratic invariant of
the flow: the energy ``1/2 omega.J omega`` and the body-frame
``|J omega|^2``; the world angular momentum ``R J omega`` is kept to the
scheme's order two.

Examples
--------
A quarter turn about the body's z axis in 1000 steps:

>>> import numpy as np
>>> q = np.array([1.0, 0.0, 0.0, 0.0])
>>> for _ in range(1000):
...     q = rotate_body(q, [0.0, 0.0, np.pi / 2], 1e-3)
>>> np.round(rotation_matrix(q) @ [1.0, 0.0, 0.0], 12).tolist() == [0.0, 1.0, 0.0]
True
"""

import math

import numpy as np
from numba import njit

from .._validate import finite_array, positive, positive_int
from ..errors import InputError

__all__ = [
    "quat_multiply",
    "quat_exp",
    "rotation_matrix",
    "check_unit_quaternion",
    "check_inertia",
    "gyroscopic_torque",
    "rotate_body",
    "rotate_into",
    "free_rigid_body",
    "kinetic_energy",
    "world_angular_momentum",
]

#: how far from 1 the norm of a given orientation may be
UNIT_TOL = 1e-12


@njit(cache=True, inline="always")
def _qmul(p, q, out):
    pw, px, py, pz = p[0], p[1], p[2], p[3]
    qw, qx, qy, qz = q[0], q[1], q[2], q[3]
    out[0] = pw * qw - px * qx - py * qy - pz * qz
    out[1] = pw * qx + px * qw + py * qz - pz * qy
    out[2] = pw * qy - px * qz + py * qw + pz * qx
    out[3] = pw * qz + px * qy - py * qx + pz * qw


@njit(cache=True, inline="always")
def _qexp(v0, v1, v2, out):
    a = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    # sin(a)/a by its series below 1e-4, where the quotient loses digits
    s = math.sin(a) / a if a > 1e-4 else 1.0 - a * a / 6.0 + a ** 4 / 120.0
    out[0] = math.cos(a)
    out[1] = s * v0
    out[2] = s * v1
    out[3] = s * v2


@njit(cache=True)
def _rotate(q, w0, w1, w2, h, out):
    e = np.empty(4)
    _qexp(0.5 * h * w0, 0.5 * h * w1, 0.5 * h * w2, e)
    _qmul(q, e, out)
    n = math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2 + out[3] ** 2)
    for i in range(4):
        out[i] /= n


@njit(cache=True)
def rotate_into(q, w0, w1, w2, h, out):
    """:func:`rotate_body`'s step ``q ⊗ exp((0, h omega / 2))`` into ``out``, compiled, unchecked.

    For compiled loops, on their own unit quaternions and finite rates.

    Examples
    --------
    >>> out = np.empty(4)
    >>> rotate_into(np.array([1.0, 0.0, 0.0, 0.0]), np.pi, 0.0, 0.0, 1.0, out)
    >>> np.round(out, 12).tolist()
    [0.0, 1.0, 0.0, 0.0]
    """
    _rotate(q, w0, w1, w2, h, out)


def quat_multiply(p, q):
    """Hamilton product ``p ⊗ q`` of quaternions ``(w, x, y, z)``.

    Examples
    --------
    >>> quat_multiply([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]).tolist()   # i j = k
    [0.0, 0.0, 0.0, 1.0]
    """
    p = finite_array("p", p, shape=(4,))
    q = finite_array("q", q, shape=(4,))
    out = np.empty(4)
    _qmul(p, q, out)
    return out


def quat_exp(v):
    """``exp((0, v)) = (cos|v|, sin|v| v/|v|)``, a unit quaternion.

    Examples
    --------
    >>> np.round(quat_exp([0.0, 0.0, np.pi / 4]), 12).tolist()   # a quarter turn about z
    [0.707106781187, 0.0, 0.0, 0.707106781187]
    """
    v = finite_array("v", v, shape=(3,))
    out = np.empty(4)
    _qexp(v[0], v[1], v[2], out)
    return out


def rotation_matrix(q, check=True):
    """The body-to-world rotation matrix of a unit quaternion.

    ``check=False`` skips the argument check, for a scheme whose quaternions
    are unit by construction (its inner loop).

    Examples
    --------
    >>> np.round(rotation_matrix(quat_exp([0.0, 0.0, np.pi / 4])), 12).tolist()
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    w, x, y, z = check_unit_quaternion(q) if check else q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def check_unit_quaternion(q, name="q"):
    """Return ``q`` as a float array, or raise unless it is a unit quaternion (to 1e-12).

    Examples
    --------
    >>> check_unit_quaternion([1.0, 0.0, 0.0, 0.1])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `q` must be a unit quaternion (w, x, y, z): |q| = 1.004987562 differs from 1 by more than 1e-12
    """
    q = finite_array(name, q, shape=(4,))
    n = float(np.linalg.norm(q))
    if abs(n - 1.0) > UNIT_TOL:
        raise InputError(f"`{name}` must be a unit quaternion (w, x, y, z): |{name}| = {n:.10g} "
                         f"differs from 1 by more than {UNIT_TOL:g}")
    return q


def check_inertia(J, name="inertia"):
    """Return the body-frame inertia tensor ``J`` as a 3x3 array, or raise.

    ``J`` may be given as its three principal moments or as a symmetric
    3x3 matrix. A rigid body's principal moments are positive and obey the
    triangle inequality ``J_i <= J_j + J_k`` (each is an integral of
    ``rho (r^2 - x_i^2)``, and ``J_j + J_k - J_i = 2 int rho x_i^2 >= 0``).

    Examples
    --------
    >>> check_inertia([1.0, 2.0, 3.0]).diagonal().tolist()
    [1.0, 2.0, 3.0]
    >>> check_inertia([1.0, 1.0, 3.0])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `inertia` must satisfy the triangle inequality J_i <= J_j + J_k of a rigid body's principal moments, got moments [1.0, 1.0, 3.0]
    """
    a = finite_array(name, J)
    if a.shape == (3,):
        a = np.diag(a)
    if a.shape != (3, 3):
        raise InputError(f"`{name}` must be 3 principal moments or a 3x3 matrix, got shape {a.shape}")
    if float(np.max(np.abs(a - a.T))) > 1e-12 * float(np.max(np.abs(a))):
        raise InputError(f"`{name}` must be a symmetric matrix")
    m = np.linalg.eigvalsh(a)
    if m[0] <= 0.0:
        raise InputError(f"`{name}` must be positive definite, got principal moments "
                         f"{np.round(m, 12).tolist()}")
    if m[2] > (m[0] + m[1]) * (1 + 1e-12):
        raise InputError(f"`{name}` must satisfy the triangle inequality J_i <= J_j + J_k of a "
                         f"rigid body's principal moments, got moments {np.round(m, 12).tolist()}")
    return a


def gyroscopic_torque(J, omega):
    """The gyroscopic term ``omega x J omega`` (body frame) of Euler's equations.

    Examples
    --------
    >>> gyroscopic_torque([1.0, 2.0, 3.0], [1.0, 1.0, 0.0]).tolist()
    [0.0, 0.0, 1.0]
    """
    J = check_inertia(J)
    w = finite_array("omega", omega, shape=(3,))
    return np.cross(w, J @ w)


def rotate_body(q, omega, h, check=True):
    """One exponential-map step ``q ⊗ exp((0, h omega / 2))``, ``omega`` in the body frame.

    ``check=False`` skips the argument checks (a scheme's inner loop, on its own
    unit quaternions and finite rates).

    Examples
    --------
    >>> q = rotate_body([1.0, 0.0, 0.0, 0.0], [np.pi, 0.0, 0.0], 1.0)   # half a turn about x
    >>> np.round(q, 12).tolist()
    [0.0, 1.0, 0.0, 0.0]
    """
    if check:
        q = check_unit_quaternion(q)
        w = finite_array("omega", omega, shape=(3,))
        h = positive("h", h)
    else:
        q = np.asarray(q, dtype=float)
        w = omega
    out = np.empty(4)
    _rotate(q, float(w[0]), float(w[1]), float(w[2]), float(h), out)
    return out


@njit(cache=True, inline="always")
def _solve3(A, F, out):
    # A out = F by Cramer's rule: a 3x3 system needs no LAPACK call
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    out[0] = (F[0] * c00 + A[0, 1] * (F[2] * A[1, 2] - F[1] * A[2, 2])
              + A[0, 2] * (F[1] * A[2, 1] - F[2] * A[1, 1])) / det
    out[1] = (A[0, 0] * (F[1] * A[2, 2] - F[2] * A[1, 2]) + F[0] * c01
              + A[0, 2] * (F[2] * A[1, 0] - F[1] * A[2, 0])) / det
    out[2] = (A[0, 0] * (F[2] * A[1, 1] - F[1] * A[2, 1])
              + A[0, 1] * (F[1] * A[2, 0] - F[2] * A[1, 0]) + F[0] * c02) / det


@njit(cache=True)
def _free_steps(q0, w0, J, h, n, qs, ws):
    q = q0.copy()
    w = w0.copy()
    qs[0] = q
    ws[0] = w
    A = np.empty((3, 3))
    F = np.empty(3)
    m = np.empty(3)
    Jm = np.empty(3)
    dw = np.empty(3)
    wn = np.empty(3)
    qn = np.empty(4)
    for k in range(n):
        wn[:] = w
        # Newton converges quadratically; ten steps is far beyond what it needs
        for _ in range(10):
            for i in range(3):
                m[i] = 0.5 * (w[i] + wn[i])
            for i in range(3):
                Jm[i] = J[i, 0] * m[0] + J[i, 1] * m[1] + J[i, 2] * m[2]
            # F = J (wn - w) + h m x J m;  dF/dwn = J + h/2 ([m]x J - [J m]x)
            for i in range(3):
                i1 = (i + 1) % 3
                i2 = (i + 2) % 3
                F[i] = (J[i, 0] * (wn[0] - w[0]) + J[i, 1] * (wn[1] - w[1])
                        + J[i, 2] * (wn[2] - w[2]) + h * (m[i1] * Jm[i2] - m[i2] * Jm[i1]))
                for j in range(3):
                    A[i, j] = J[i, j] + 0.5 * h * (m[i1] * J[i2, j] - m[i2] * J[i1, j])
                # minus [J m]x: its (i, i2) entry is (J m)_i1, its (i, i1) entry -(J m)_i2
                A[i, i2] -= 0.5 * h * Jm[i1]
                A[i, i1] += 0.5 * h * Jm[i2]
            _solve3(A, F, dw)
            for i in range(3):
                wn[i] -= dw[i]
            if math.sqrt(dw[0] ** 2 + dw[1] ** 2 + dw[2] ** 2) <= 1e-15 * (
                    math.sqrt(wn[0] ** 2 + wn[1] ** 2 + wn[2] ** 2) + 1e-300):
                break
        _rotate(q, 0.5 * (w[0] + wn[0]), 0.5 * (w[1] + wn[1]), 0.5 * (w[2] + wn[2]), h, qn)
        q[:] = qn
        w[:] = wn
        qs[k + 1] = q
        ws[k + 1] = w


def free_rigid_body(q0, omega0, inertia, h, n_steps):
    """Advance a torque-free rigid body ``n_steps`` steps of size ``h``.

    The implicit midpoint rule on Euler's equations (body frame) and the
    exponential-map update of the orientation with the midpoint rate; see
    the module's docstring.

    Parameters
    ----------
    q0 : array_like, shape (4,)
        Unit quaternion, body to world.
    omega0 : array_like, shape (3,)
        Body-frame angular velocity [rad/s].
    inertia : array_like, shape (3,) or (3, 3)
        Body-frame inertia tensor (:func:`check_inertia`).
    h : float
        Step [s], > 0.
    n_steps : int
        ``>= 1``.

    Returns
    -------
    q, omega : ndarray, shapes (n_steps + 1, 4) and (n_steps + 1, 3)

    Examples
    --------
    >>> q, w = free_rigid_body([1.0, 0, 0, 0], [0.1, 2.0, 0.1], [1.0, 2.0, 2.5], 1e-2, 1000)
    >>> J = np.diag([1.0, 2.0, 2.5])
    >>> bool(abs(kinetic_energy(J, w[-1]) / kinetic_energy(J, w[0]) - 1) < 1e-13)
    True
    """
    q0 = check_unit_quaternion(q0, "q0")
    w0 = finite_array("omega0", omega0, shape=(3,))
    J = check_inertia(inertia)
    h = positive("h", h)
    n = positive_int("n_steps", n_steps)
    qs = np.empty((n + 1, 4))
    ws = np.empty((n + 1, 3))
    _free_steps(q0 / np.linalg.norm(q0), w0, J, h, n, qs, ws)
    return qs, ws


def kinetic_energy(J, omega):
    """Rotational kinetic energy ``1/2 omega . J omega``."""
    J = np.asarray(J, dtype=float)
    omega = np.asarray(omega, dtype=float)
    return 0.5 * float(omega @ J @ omega)


def world_angular_momentum(q, J, omega):
    """World-frame angular momentum ``R(q) J omega``, one row per state when given arrays."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    omega = np.atleast_2d(np.asarray(omega, dtype=float))
    J = np.asarray(J, dtype=float)
    out = np.array([rotation_matrix(qi) @ (J @ wi) for qi, wi in zip(q, omega)])
    return out[0] if out.shape[0] == 1 else out
