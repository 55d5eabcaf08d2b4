"""Many disks among fixed walls, with a contact set found afresh at every state (issue 38).

A :class:`DiskSystem` holds ``N`` rigid disks (radius, mass, centroidal
inertia ``m r^2 / 2``; coordinates ``(x, y, phi)`` per disk, ``3 N`` in all)
and a few fixed walls (:class:`HalfPlane`, :class:`Segment`), each with its
own friction coefficient and restitution. Unlike a :class:`~moreau.model.scene.Scene`,
whose contact rows are fixed when it is built, the system finds its
contacts from the positions: a uniform-grid broad phase (:func:`grid_pairs`)
gives every pair of disks closer than a margin, and each disk is tested
against each wall; :meth:`DiskSystem.contacts` returns the gaps, normals and
Jacobian rows of those candidates.

The broad phase
---------------
Square cells of side ``2 r_max + margin`` (``r_max`` the largest radius):
two disks within ``margin`` of touching have centres closer than a cell
side, so they lie in the same or in neighbouring cells. The disks are
sorted by cell (one ``argsort`` of an integer key), and each disk is tested
against the disks of its own and its eight neighbouring cells, found by
binary search in the sorted keys. The cost is the sort plus nine searches a
disk plus the pairs tested (a bounded number a disk in a packing), about
linear in ``N``; :func:`brute_pairs` is the ``O(N^2)`` check.

Contact kinematics (derived here, checked by ``tests/model/test_granular.py``)
------------------------------------------------------------------------------
Disks ``a`` and ``b`` (centres ``c_a``, ``c_b``, radii ``r_a``, ``r_b``):
gap ``g = |c_b - c_a| - r_a - r_b``, normal ``n = (c_b - c_a) / |c_b - c_a|``
(from ``a`` to ``b``), tangent ``t = (-n_y, n_x)``. The material points in
contact are ``c_a + r_a n`` and ``c_b - r_b n``; a disk spinning at
``omega`` moves its point at lever ``d`` by ``omega e_z x d``, and
``e_z x n = t``, so the relative velocity of ``b``'s point against ``a``'s is::

    u_N = n . (v_b - v_a),    u_T = t . (v_b - v_a) - r_a omega_a - r_b omega_b.

``dg/dt = u_N`` exactly (the gap depends on the centres only). A wall is
body ``a`` at rest, with ``n`` the unit vector from its nearest point to the
centre of ``b`` (a half-plane: its outward normal), so ``g = dist - r_b``
and the same rows hold with ``v_a = 0``, ``omega_a = 0``.

Rolling resistance
------------------
With a rolling-resistance length ``mu_r > 0`` (:class:`DiskSystem`; per
wall), each contact also transmits a couple ``M``, ``+M`` on ``b`` and
``-M`` on ``a``, with ``|M| <= mu_r N`` (``N`` the normal force) and ``M``
opposing the relative rolling ``u_R = omega_b - omega_a`` where it is not
zero (:mod:`moreau.contact.rolling`). ``u_R`` is the rate of the relative
rotation ``phi_b - phi_a``: zero where the pair turns as one rigid body
(``omega_a = omega_b``), whatever it does; a couple does no work on a
translation, so the power of ``M`` is ``M u_R``. ``mu_r`` is a length (the
lever arm by which the normal force resists the roll, Coulomb's
coefficient of rolling friction), so the same ``mu_r`` is the same
resistance for a small and a large grain in contact; ``mu_r / r`` is the
slope a disk of radius ``r`` rests on (``tests/model/test_granular.py``).
The rows are then ``[N_i, T_i, R_i]`` per contact (``rolling=True`` of
:meth:`DiskSystem.jacobian`).

Examples
--------
Three disks on a floor, the third resting on the first two (five contacts):

>>> import numpy as np
>>> from moreau.model.granular import DiskSystem, HalfPlane
>>> s = 3 ** 0.5
>>> sys = DiskSystem([0.5, 0.5, 0.5], [1.0, 1.0, 1.0], walls=[HalfPlane((0, 0), (0, 1))], mu=0.5)
>>> x = np.array([[0.0, 0.5], [1.0, 0.5], [0.5, 0.5 + 0.5 * s]])
>>> c = sys.contacts(x, margin=1e-9)
>>> c.a.tolist(), c.b.tolist(), np.round(c.gap, 12).tolist()
([0, 0, 1, -1, -1], [1, 2, 2, 0, 1], [0.0, 0.0, 0.0, 0.0, 0.0])
"""

import math
from collections import namedtuple
from typing import NamedTuple

import numpy as np
import scipy.sparse as sps
from numba import njit

from .. import _jit_cache
from .._validate import finite_array, finite_scalar, nonnegative, positive
from ..errors import InputError
from .drawing import circle, contact, line
from .scene import Scene
from .units import SIUnits

__all__ = ["HalfPlane", "Segment", "DiskSystem", "DiskScene", "ContactSet", "grid_pairs",
           "brute_pairs", "random_fill", "EVERY_PAIR_MAX",
           "disk_wall_contacts"]

#: numba's cache pickles the module's name with the machine code; only the package's own
#: import caches (a copy imported under its bare file name by doctest collection must not)
_CACHE = __name__.startswith("moreau.")

_HALF_PLANE, _SEGMENT = 0, 1


#: a wall's material after its geometry, with the defaults (None: the disks' value)
_WALL_MATERIAL = (("mu", None), ("restitution", None), ("surface_speed", 0.0), ("mu_r", None))


def _wall(name, geometry, doc):
    """A wall's named tuple: the fields ``geometry``, then :data:`_WALL_MATERIAL`."""
    cls = namedtuple(name, geometry + tuple(f for f, _ in _WALL_MATERIAL),
                     defaults=tuple(d for _, d in _WALL_MATERIAL), module=__name__)
    cls.__doc__ = doc
    return cls


HalfPlane = _wall("HalfPlane", ("point", "normal"), """\
The fixed half-plane ``{p : n . (p - point) <= 0}``; disks stay on the side ``n`` points to.

    ``normal`` is normalised by :class:`DiskSystem`. ``surface_speed``: the
    wall's material slides along itself at this speed along ``t = (-n_y, n_x)``
    (a belt; the wall stays where it is, only the slip at its contacts
    changes). ``mu_r``: its rolling-resistance length (default: the disks').
    ``mu`` and ``restitution``: the wall's own (default: the disks').
    """)

Segment = _wall("Segment", ("start", "end"), """\
A fixed segment from ``start`` to ``end``, touched from either side and at its ends.

    ``surface_speed``: its material slides from ``start`` towards ``end`` at this speed.
    ``mu_r``: its rolling-resistance length (default: the disks'). ``mu`` and
    ``restitution``: the wall's own (default: the disks').
    """)


class ContactSet(NamedTuple):
    """The candidate contacts at one state (every array over the contacts, disk pairs first).

    Attributes
    ----------
    a : ndarray of int
        First body: a disk index, or ``-1 - w`` for wall ``w``.
    b : ndarray of int
        Second body (always a disk).
    gap : ndarray
    normal : ndarray, shape (nc, 2)
        From ``a`` to ``b``.
    mu, e : ndarray
        Friction coefficient and restitution of each contact.
    key : ndarray of int64
        A number per pair of bodies, the same at every state and in any system that
        numbers the bodies alike: ``a * 2**32 + b``.
    mu_r : ndarray
        Rolling-resistance length of each contact.
    """

    a: np.ndarray
    b: np.ndarray
    gap: np.ndarray
    normal: np.ndarray
    mu: np.ndarray
    e: np.ndarray
    key: np.ndarray
    mu_r: np.ndarray

    @property
    def size(self):
        return self.gap.size


# -- the broad phase ---------------------------------------------------------------------------

@njit(cache=_CACHE)
def _touch(x, radii, margin, k, j):
    # whether the gap between disks k and j is at most `margin`
    ddx = x[j, 0] - x[k, 0]
    ddy = x[j, 1] - x[k, 1]
    reach = radii[k] + radii[j] + margin
    return ddx * ddx + ddy * ddy <= reach * reach


@njit(cache=_CACHE)
def _grid_pairs(x, radii, margin, out_i, out_j, fill):
    n = x.shape[0]
    if n < 2:
        return 0
    rmax = 0.0
    for k in range(n):
        rmax = max(rmax, radii[k])
    cell = 2.0 * rmax + margin
    x0 = x[0, 0]
    y0 = x[0, 1]
    for k in range(n):
        x0 = min(x0, x[k, 0])
        y0 = min(y0, x[k, 1])
    ix = np.empty(n, dtype=np.int64)
    iy = np.empty(n, dtype=np.int64)
    ny = 1
    for k in range(n):
        ix[k] = int((x[k, 0] - x0) / cell)
        iy[k] = int((x[k, 1] - y0) / cell)
        ny = max(ny, iy[k] + 1)
    # rows of height ny + 2: a neighbour's key (ix +- 1, iy +- 1) never wraps into another column
    stride = ny + 2
    keys = np.empty(n, dtype=np.int64)
    for k in range(n):
        keys[k] = (ix[k] + 1) * stride + iy[k] + 1
    order = np.argsort(keys, kind="mergesort")
    sk = keys[order]
    count = 0
    for k in range(n):
        for dx in range(-1, 2):
            for dy in range(-1, 2):
                key = keys[k] + dx * stride + dy
                lo = np.searchsorted(sk, key, side="left")
                hi = np.searchsorted(sk, key, side="right")
                for m in range(lo, hi):
                    j = order[m]
                    if j > k and _touch(x, radii, margin, k, j):
                        if fill:
                            out_i[count] = k
                            out_j[count] = j
                        count += 1
    return count


@njit(cache=_CACHE)
def _brute_pairs(x, radii, margin, out_i, out_j, fill):
    n = x.shape[0]
    count = 0
    for k in range(n):
        for j in range(k + 1, n):
            if _touch(x, radii, margin, k, j):
                if fill:
                    out_i[count] = k
                    out_j[count] = j
                count += 1
    return count


_jit_cache.bind_cache_to_sources([_grid_pairs, _brute_pairs], [__file__])


def _pairs(kernel, x, radii, margin):
    x = np.ascontiguousarray(x, dtype=float)
    radii = np.ascontiguousarray(radii, dtype=float)
    none = np.zeros(0, dtype=np.int64)
    count = kernel(x, radii, float(margin), none, none, False)
    i = np.empty(count, dtype=np.int64)
    j = np.empty(count, dtype=np.int64)
    kernel(x, radii, float(margin), i, j, True)
    order = np.lexsort((j, i))
    return i[order], j[order]


def _check_cloud(x, radii, margin):
    x = finite_array("x", x, ndim=2)
    if x.shape[1] != 2:
        raise InputError(f"`x` must have shape (N, 2), got {x.shape}")
    radii = finite_array("radii", radii, shape=(x.shape[0],))
    if np.any(radii <= 0.0):
        raise InputError("`radii` must be > 0 for every disk")
    margin = nonnegative("margin", margin)
    return x, radii, margin


def grid_pairs(x, radii, margin=0.0):
    """Every pair of disks with ``|c_j - c_i| <= r_i + r_j + margin``, by a uniform grid.

    Parameters
    ----------
    x : array_like, shape (N, 2)
        Centres.
    radii : array_like, shape (N,)
    margin : float
        How far apart (gap) two disks may be and still be listed, ``>= 0``.

    Returns
    -------
    i, j : ndarray of int64
        The pairs, ``i < j``, sorted by ``(i, j)``.

    Examples
    --------
    >>> i, j = grid_pairs([[0.0, 0.0], [2.0, 0.0], [5.0, 0.0]], [1.0, 1.0, 1.0], margin=0.5)
    >>> i.tolist(), j.tolist()
    ([0], [1])
    >>> grid_pairs([[0.0, 0.0]], [-1.0])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `radii` must be > 0 for every disk
    """
    return _pairs(_grid_pairs, *_check_cloud(x, radii, margin))


def brute_pairs(x, radii, margin=0.0):
    """The same pairs as :func:`grid_pairs` by testing all ``N (N - 1) / 2`` of them (the check).

    Examples
    --------
    >>> i, j = brute_pairs([[0.0, 0.0], [2.0, 0.0], [5.0, 0.0]], [1.0, 1.0, 1.0], margin=0.5)
    >>> i.tolist(), j.tolist()
    ([0], [1])
    """
    return _pairs(_brute_pairs, *_check_cloud(x, radii, margin))


# -- walls -------------------------------------------------------------------------------------

@njit(cache=_CACHE)
def _wall_contacts(x, radii, kind, p0, p1, margin, out_w, out_b, out_g, out_n, fill):
    count = 0
    for w in range(kind.shape[0]):
        for b in range(x.shape[0]):
            if kind[w] == 0:
                nx = p1[w, 0]
                ny = p1[w, 1]
                d = nx * (x[b, 0] - p0[w, 0]) + ny * (x[b, 1] - p0[w, 1])
            else:
                ex = p1[w, 0] - p0[w, 0]
                ey = p1[w, 1] - p0[w, 1]
                s = ((x[b, 0] - p0[w, 0]) * ex + (x[b, 1] - p0[w, 1]) * ey) / (ex * ex + ey * ey)
                s = min(1.0, max(0.0, s))
                nx = x[b, 0] - (p0[w, 0] + s * ex)
                ny = x[b, 1] - (p0[w, 1] + s * ey)
                d = math.sqrt(nx * nx + ny * ny)
                if d > 0.0:
                    nx /= d
                    ny /= d
            g = d - radii[b]
            if g <= margin:
                if fill:
                    out_w[count] = w
                    out_b[count] = b
                    out_g[count] = g
                    out_n[count, 0] = nx
                    out_n[count, 1] = ny
                count += 1
    return count


_jit_cache.bind_cache_to_sources([_wall_contacts], [__file__])


def disk_wall_contacts(x, radii, kind, p0, p1, margin):
    """``(wall, disk, gap, normal)`` of every disk within ``margin`` of a wall.

    ``kind[w]`` is 0 for a half-plane (``p0`` a point, ``p1`` the unit
    normal) and 1 for a segment (``p0`` to ``p1``). A disk whose centre lies
    on a segment has no defined normal: it is reported with normal ``(0, 0)``
    (:meth:`DiskSystem.contacts` refuses it).
    """
    args = (np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(radii, dtype=float),
            np.ascontiguousarray(kind, dtype=np.int64), np.ascontiguousarray(p0, dtype=float),
            np.ascontiguousarray(p1, dtype=float), float(margin))
    z = np.zeros(0, dtype=np.int64)
    count = _wall_contacts(*args, z, z, np.zeros(0), np.zeros((0, 2)), False)
    w = np.empty(count, dtype=np.int64)
    b = np.empty(count, dtype=np.int64)
    g = np.empty(count)
    n = np.empty((count, 2))
    _wall_contacts(*args, w, b, g, n, True)
    return w, b, g, n


# -- the system --------------------------------------------------------------------------------

class DiskSystem:
    """Rigid disks and fixed walls; contacts from the positions (module docstring).

    Parameters
    ----------
    radii, masses : array_like, shape (N,)
        Positive.
    walls : sequence of HalfPlane or Segment
        Each may carry its own ``mu`` and ``restitution`` (default: those of
        the disk pairs).
    mu : float
        Friction coefficient between disks (and of walls that give none), ``>= 0``.
    restitution : float
        Newton restitution between disks (and of walls that give none), in ``[0, 1]``.
    gravity : (float, float)
        The acceleration of gravity, in the system's units.
    mu_r : float
        Rolling-resistance length between disks (and of walls that give none), ``>= 0``,
        in the system's units (module docstring); 0: disks roll freely, and
        :func:`~moreau.integrators.granular.simulate_disks` solves the problem without
        rolling rows.

    Attributes
    ----------
    n_disks : int
    inv_mass : ndarray, shape (3 N,)
        ``(1/m, 1/m, 1/I)`` per disk, ``I = m r^2 / 2``.
    rolling : bool
        Whether any contact (between disks or with a wall) has ``mu_r > 0``.

    Examples
    --------
    >>> sys = DiskSystem([1.0, 1.0], [2.0, 2.0], walls=[Segment((-5, 0), (5, 0), mu=0.9)])
    >>> sys.n_disks, sys.inv_mass.tolist()
    (2, [0.5, 0.5, 1.0, 0.5, 0.5, 1.0])
    >>> DiskSystem([1.0], [1.0], mu=-0.1)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `mu` must be >= 0, got -0.1
    """

    def __init__(self, radii, masses, *, walls=(), mu=0.5, restitution=0.0,
                 gravity=(0.0, -1.0), mu_r=0.0):
        radii = finite_array("radii", radii, ndim=1)
        n = radii.size
        if n == 0 or np.any(radii <= 0.0):
            raise InputError("`radii` must hold at least one disk, every radius > 0")
        masses = finite_array("masses", masses, shape=(n,))
        if np.any(masses <= 0.0):
            raise InputError("`masses` must be > 0 for every disk")
        mu = nonnegative("mu", mu)
        mu_r = nonnegative("mu_r", mu_r)
        restitution = finite_scalar("restitution", restitution)
        if not 0.0 <= restitution <= 1.0:
            raise InputError(f"`restitution` must lie in [0, 1], got {restitution!r}")
        self.gravity = finite_array("gravity", gravity, shape=(2,))
        self.radii, self.masses, self.mu, self.restitution = radii, masses, mu, restitution
        self.mu_r = mu_r
        self.n_disks = n
        self.inertias = 0.5 * masses * radii ** 2
        self.inv_mass = np.column_stack([1.0 / masses, 1.0 / masses, 1.0 / self.inertias]).ravel()
        kind, p0, p1, wmu, we, wvel, wmur = [], [], [], [], [], [], []
        for k, w in enumerate(walls):
            if isinstance(w, HalfPlane):
                nrm = finite_array(f"walls[{k}].normal", w.normal, shape=(2,))
                length = float(np.hypot(*nrm))
                if length == 0.0:
                    raise InputError(f"`walls[{k}].normal` must not be zero")
                kind.append(_HALF_PLANE)
                p0.append(finite_array(f"walls[{k}].point", w.point, shape=(2,)))
                p1.append(nrm / length)
                along = np.array([-nrm[1], nrm[0]]) / length
            elif isinstance(w, Segment):
                a = finite_array(f"walls[{k}].start", w.start, shape=(2,))
                b = finite_array(f"walls[{k}].end", w.end, shape=(2,))
                if np.array_equal(a, b):
                    raise InputError(f"`walls[{k}]` must have two distinct ends")
                kind.append(_SEGMENT)
                p0.append(a)
                p1.append(b)
                along = (b - a) / float(np.hypot(*(b - a)))
            else:
                raise InputError(f"`walls[{k}]` must be a HalfPlane or a Segment, got "
                                 f"{type(w).__name__}")
            m = mu if w.mu is None else nonnegative(f"walls[{k}].mu", w.mu)
            e = restitution if w.restitution is None else finite_scalar(
                f"walls[{k}].restitution", w.restitution)
            if not 0.0 <= e <= 1.0:
                raise InputError(f"`walls[{k}].restitution` must lie in [0, 1], got {e!r}")
            wmu.append(m)
            wmur.append(mu_r if w.mu_r is None else nonnegative(f"walls[{k}].mu_r", w.mu_r))
            we.append(e)
            wvel.append(finite_scalar(f"walls[{k}].surface_speed", w.surface_speed) * along)
        self.walls = tuple(walls)
        self.n_walls = len(kind)
        self._kind = np.array(kind, dtype=np.int64)
        self._p0 = np.array(p0, dtype=float).reshape(-1, 2)
        self._p1 = np.array(p1, dtype=float).reshape(-1, 2)
        self._wall_mu = np.array(wmu, dtype=float)
        self._wall_e = np.array(we, dtype=float)
        self._wall_mu_r = np.array(wmur, dtype=float)
        self.rolling = bool(mu_r > 0.0 or np.any(self._wall_mu_r > 0.0))
        #: the velocity of each wall's material, shape (n_walls, 2)
        self.wall_velocity = np.array(wvel, dtype=float).reshape(-1, 2)

    @property
    def ndof(self):
        return 3 * self.n_disks

    def contacts(self, x, margin=0.0):
        """The candidate contacts at centres ``x``: disk pairs and disk-wall pairs within ``margin``.

        Parameters
        ----------
        x : array_like, shape (N, 2)
        margin : float
            ``>= 0``; every contact with ``gap <= margin`` is listed.

        Returns
        -------
        ContactSet
            Disk pairs (sorted by ``(a, b)``), then wall contacts (by wall, then disk).

        Raises
        ------
        InputError
            Two coincident centres, or a centre on a segment (no normal).
        """
        x = np.ascontiguousarray(x, dtype=float)
        if x.shape != (self.n_disks, 2):
            raise InputError(f"`x` must have shape ({self.n_disks}, 2), got {x.shape}")
        margin = nonnegative("margin", margin)
        i, j = _pairs(_grid_pairs, x, self.radii, margin)
        d = x[j] - x[i]
        dist = np.hypot(d[:, 0], d[:, 1])
        if np.any(dist == 0.0):
            raise InputError("two disks have the same centre: their contact has no normal")
        n_pair = d / dist[:, None]
        g_pair = dist - self.radii[i] - self.radii[j]
        w, b, g_wall, n_wall = disk_wall_contacts(x, self.radii, self._kind, self._p0, self._p1,
                                                  margin)
        if np.any((n_wall[:, 0] == 0.0) & (n_wall[:, 1] == 0.0)):
            raise InputError("a disk's centre lies on a segment wall: its contact has no normal")
        a = np.concatenate([i, -1 - w])
        bb = np.concatenate([j, b])
        return ContactSet(
            a=a, b=bb, gap=np.concatenate([g_pair, g_wall]),
            normal=np.concatenate([n_pair, n_wall]),
            mu=np.concatenate([np.full(i.size, self.mu), self._wall_mu[w]]),
            e=np.concatenate([np.full(i.size, self.restitution), self._wall_e[w]]),
            key=a * (1 << 32) + bb,
            mu_r=np.concatenate([np.full(i.size, self.mu_r), self._wall_mu_r[w]]))

    def jacobian(self, contacts, rolling=False):
        """The contact Jacobian ``H`` (CSR, ``2 nc x 3 N``), rows ``[N_i, T_i]`` interleaved.

        Row ``2 i``: ``u_N = n . (v_b - v_a)``; row ``2 i + 1``:
        ``u_T = t . (v_b - v_a) - r_a omega_a - r_b omega_b`` (module
        docstring), a wall's terms left out. With ``rolling``, ``3 nc``
        rows ``[N_i, T_i, R_i]``, row ``3 i + 2`` the relative rolling
        ``u_R = omega_b - omega_a``.
        """
        c = contacts
        nc = c.size
        n = c.normal
        t = np.column_stack([-n[:, 1], n[:, 0]])
        stride = 3 if rolling else 2
        rows_n = stride * np.arange(nc)
        rows_t = rows_n + 1
        b, a = c.b, c.a
        disk_a = a >= 0
        ra = np.where(disk_a, self.radii[np.maximum(a, 0)], 0.0)
        rb = self.radii[b]
        rows = [rows_n, rows_n, rows_t, rows_t, rows_t]
        cols = [3 * b, 3 * b + 1, 3 * b, 3 * b + 1, 3 * b + 2]
        vals = [n[:, 0], n[:, 1], t[:, 0], t[:, 1], -rb]
        ia = np.flatnonzero(disk_a)
        aa = a[ia]
        rows += [rows_n[ia], rows_n[ia], rows_t[ia], rows_t[ia], rows_t[ia]]
        cols += [3 * aa, 3 * aa + 1, 3 * aa, 3 * aa + 1, 3 * aa + 2]
        vals += [-n[ia, 0], -n[ia, 1], -t[ia, 0], -t[ia, 1], -ra[ia]]
        if rolling:
            rows_r = rows_n + 2
            rows += [rows_r, rows_r[ia]]
            cols += [3 * b + 2, 3 * aa + 2]
            vals += [np.ones(nc), -np.ones(ia.size)]
        H = sps.csr_array((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(stride * nc, self.ndof))
        H.sum_duplicates()
        return H

    def contact_offsets(self, contacts, rolling=False):
        """``w`` with ``u = H v + w``: the walls' surface velocities, interleaved ``[N_i, T_i]``.

        A contact with a wall whose material moves at ``V`` has
        ``u_N -= n . V`` (zero: ``V`` is along the wall) and ``u_T -= t . V``.
        With ``rolling``, interleaved ``[N_i, T_i, R_i]``: a wall's material
        translates, ``u_R`` has no offset.
        """
        c = contacts
        s = 3 if rolling else 2
        w = np.zeros(s * c.size)
        on_wall = np.flatnonzero(c.a < 0)
        if on_wall.size and np.any(self.wall_velocity):
            V = self.wall_velocity[-1 - c.a[on_wall]]
            n = c.normal[on_wall]
            w[s * on_wall] = -np.einsum("ij,ij->i", n, V)
            w[s * on_wall + 1] = -(-n[:, 1] * V[:, 0] + n[:, 0] * V[:, 1])
        return w

    def delassus(self, H):
        """``W = H M^-1 H^T`` in CSR, ``M^-1`` diagonal (applied per body)."""
        W = sps.csr_array(H @ sps.diags_array(self.inv_mass) @ H.T)
        W.sum_duplicates()
        W.sort_indices()
        return W


def random_fill(n, width, r_min, r_max, *, x0=0.0, y0=0.0, seed=0):
    """``n`` disks of radii uniform in ``[r_min, r_max]`` on a loose square lattice, no overlap.

    Rows of ``floor(width / (2.04 r_max))`` disks from ``(x0, y0)`` upward,
    each centre moved by up to ``0.01 r_max`` at random (seeded): a start
    for a packing made by letting them fall (a disordered packing needs
    several radii).

    Returns
    -------
    radii : ndarray, shape (n,)
    x : ndarray, shape (n, 2)

    Examples
    --------
    >>> radii, x = random_fill(5, 4.2, 0.4, 0.5, seed=1)
    >>> x.shape, bool(np.all(radii >= 0.4)), sorted(set(np.round(x[:, 1]).tolist()))
    ((5, 2), True, [1.0, 2.0])
    """
    n = int(n)
    if n < 1:
        raise InputError(f"`n` must be >= 1, got {n!r}")
    if not 0.0 < r_min <= r_max:
        raise InputError(f"`r_min` and `r_max` must satisfy 0 < r_min <= r_max, got {r_min!r}, "
                         f"{r_max!r}")
    pitch = 2.04 * r_max
    cols = int(width // pitch)
    if cols < 1:
        raise InputError(f"`width` must hold one disk of radius `r_max` ({pitch:g}), got "
                         f"{width!r}")
    rng = np.random.default_rng(seed)
    radii = rng.uniform(r_min, r_max, n)
    k = np.arange(n)
    x = np.column_stack([x0 + 0.5 * pitch + (k % cols) * pitch,
                         y0 + 0.5 * pitch + (k // cols) * pitch])
    x += rng.uniform(-0.01 * r_max, 0.01 * r_max, (n, 2))
    return radii, x


#: the most disks a :class:`DiskScene` takes with every pair a candidate (``margin=None``):
#: its rows grow as the square of the disks
EVERY_PAIR_MAX = 64


class DiskScene(SIUnits, Scene):
    """The :class:`~moreau.model.scene.Scene` of a :class:`DiskSystem` with its contacts fixed at a start.

    The candidate contacts are those within ``margin`` at the start ``x0``
    (:meth:`DiskSystem.contacts`), fixed for good: every scheme runs this
    scene like any other. It holds while the disks touch only those
    candidates: its valid region is "every touching pair is a candidate of
    the start", checked on every recorded state (a scheme stops with status
    -6 where a pair outside them closes). A flow that changes its contacts
    runs with the broad phase every step instead
    (:func:`moreau.integrators.granular.simulate_disks`).

    Coordinates ``(x_i, y_i, phi_i)`` per disk; the drift terms of the rows
    (module docstring) with ``n' = (t . v_rel) t / |d|`` and
    ``t' = -(t . v_rel) n / |d|`` for two disks at distance ``|d|`` (and a
    disk at a segment's end): ``wNbar = (t . v_rel)^2 / |d|``,
    ``wTbar = -(t . v_rel)(n . v_rel) / |d|``; a half-plane or a segment's
    side has a constant normal, no drift.

    Parameters
    ----------
    system : DiskSystem
    x0 : array_like, shape (N, 2)
    v0 : array_like, shape (N, 3), optional
    margin : float or None
        Candidate gap at the start; None: every pair of disks and every disk
        and wall is a candidate (at most :data:`EVERY_PAIR_MAX` disks), so no
        contact can close outside them however far the disks move.
    name : str
    length, time, force : float
        SI size [m], [s], [N] of the system's units.
    default_window : float
        A run's length when none is named, in the system's time.

    Examples
    --------
    >>> sys = DiskSystem([0.5, 0.5], [1.0, 1.0], walls=[HalfPlane((0, 0), (0, 1))], mu=0.3)
    >>> sc = DiskScene(sys, [[0.0, 0.5], [1.0, 0.6]], margin=0.2)
    >>> sc.ncontacts, sc.ndof, np.round(sc.gaps(sc.initial_state()[0], 0.0), 12).tolist()
    (3, 6, [0.004987562112, 0.0, 0.1])
    """

    valid_region = "every touching pair of bodies is a candidate contact of the start"
    # the event-driven reference locates every impact of a settling pile one by one (minutes
    # for 18 disks over 0.2 s) and meets Lemke's ray in a collapse; NSGS steps it in seconds
    run_default = ("moreau-jean", {"lcp_method": "nsgs"})

    def __init__(self, system, x0, v0=None, *, margin=0.5, name="disks", length=1.0, time=1.0,
                 force=1.0, default_window=1.0):
        if not isinstance(system, DiskSystem):
            raise InputError(f"`system` must be a DiskSystem, got {type(system).__name__}")
        if system.rolling:
            # a Scene's rows are normal and tangential; a couple row has no place in them
            raise InputError("`system` must have no rolling resistance (`mu_r` = 0 for every "
                             "contact) in a DiskScene: run it with simulate_disks")
        N = system.n_disks
        self.system = system
        x0 = finite_array("x0", x0, shape=(N, 2))
        v0 = np.zeros((N, 3)) if v0 is None else finite_array("v0", v0, shape=(N, 3))
        self._q0 = np.column_stack([x0, np.zeros(N)]).ravel()
        self._v0 = v0.ravel().copy()
        if margin is None:
            if N > EVERY_PAIR_MAX:
                raise InputError(f"`margin=None` (every pair a candidate) takes at most "
                                 f"{EVERY_PAIR_MAX} disks, got {N}: give a margin, or run "
                                 f"simulate_disks (a broad phase every step)")
            # the order of DiskSystem.contacts: pairs by (a, b), then walls by wall and disk
            i, j = np.triu_indices(N, 1)
            w, b = np.divmod(np.arange(system.n_walls * N), N)
            a, b = np.concatenate([i, -1 - w]), np.concatenate([j, b])
            self._a, self._b = a, b
            self._keys = np.sort(a * (1 << 32) + b)
            self.mu = np.concatenate([np.full(i.size, system.mu), system._wall_mu[w]])
            self.restitution = np.concatenate([np.full(i.size, system.restitution),
                                               system._wall_e[w]])
        else:
            cs = system.contacts(x0, positive("margin", margin))
            self._a, self._b = cs.a, cs.b
            self._keys = np.sort(cs.key)
            self.mu, self.restitution = cs.mu.copy(), cs.e.copy()
        self.ndof = 3 * N
        self.name = name
        self.length, self.time, self.force = float(length), float(time), float(force)
        self.default_window = float(default_window)
        self.angle_coordinates = tuple(range(2, 3 * N, 3))
        self._M = np.diag(1.0 / system.inv_mass)
        self._h = np.tile(np.array([system.gravity[0], system.gravity[1], 0.0]), N) \
            * np.repeat(system.masses, 3)

    def _qscale(self):
        s = np.full(self.ndof, self.length)
        s[2::3] = 1.0
        return s

    def mass(self, q):
        return self._M.copy()

    def forces(self, q, v, t):
        return self._h.copy()

    def force_jacobians(self, q, v, t):
        return np.zeros((self.ndof, self.ndof)), np.zeros((self.ndof, self.ndof))

    def _geometry(self, q):
        """Gap, unit normal, and the distance the normal turns over (inf: it does not turn)."""
        sysm = self.system
        x = np.asarray(q, dtype=float).reshape(-1, 3)[:, :2]
        a, b = self._a, self._b
        nc = a.size
        gap = np.empty(nc)
        nrm = np.empty((nc, 2))
        turn = np.full(nc, np.inf)
        pair = a >= 0
        d = x[b[pair]] - x[a[pair]]
        dist = np.hypot(d[:, 0], d[:, 1])
        nrm[pair] = d / dist[:, None]
        gap[pair] = dist - sysm.radii[a[pair]] - sysm.radii[b[pair]]
        turn[pair] = dist
        for k in np.flatnonzero(~pair):
            w = -1 - a[k]
            c = x[b[k]]
            p0, p1 = sysm._p0[w], sysm._p1[w]
            if sysm._kind[w] == _HALF_PLANE:
                nrm[k] = p1
                gap[k] = p1 @ (c - p0) - sysm.radii[b[k]]
                continue
            e = p1 - p0
            s = (c - p0) @ e / (e @ e)
            foot = p0 + min(1.0, max(0.0, s)) * e
            dd = c - foot
            dist = float(np.hypot(*dd))
            nrm[k] = dd / dist
            gap[k] = dist - sysm.radii[b[k]]
            if not 0.0 < s < 1.0:
                turn[k] = dist
        return x, gap, nrm, turn

    def gaps(self, q, t):
        return self._geometry(q)[1]

    def _rows(self, q):
        x, gap, n, turn = self._geometry(q)
        cs = ContactSet(self._a, self._b, gap, n, self.mu, self.restitution,
                        self._a * (1 << 32) + self._b, np.zeros(self._a.size))
        H = self.system.jacobian(cs).toarray()
        return cs, H, self.system.contact_offsets(cs), turn

    def contact_jacobians(self, q, t):
        _, H, w, _ = self._rows(q)
        f = self.frictional_index
        return H[0::2], w[0::2], H[1::2][f], w[1::2][f]

    def contact_drift(self, q, v, t):
        cs, H, w, turn = self._rows(q)
        v = np.asarray(v, dtype=float).reshape(-1, 3)
        sysm = self.system
        vrel = v[cs.b, :2].copy()
        pair = cs.a >= 0
        vrel[pair] -= v[cs.a[pair], :2]
        wall = np.flatnonzero(~pair)
        vrel[wall] -= sysm.wall_velocity[-1 - cs.a[wall]]
        n = cs.normal
        t_ = np.column_stack([-n[:, 1], n[:, 0]])
        ut = np.einsum("ij,ij->i", t_, vrel)
        un = np.einsum("ij,ij->i", n, vrel)
        finite = np.isfinite(turn)
        wN = np.where(finite, ut * ut / np.where(finite, turn, 1.0), 0.0)
        wT = np.where(finite, -ut * un / np.where(finite, turn, 1.0), 0.0)
        return wN, wT[self.frictional_index]

    def inside_valid_region(self, t, q, v):
        q = np.asarray(q, dtype=float).reshape(np.shape(t) + (self.ndof,))
        out = np.ones(np.shape(t), dtype=bool)
        for k in range(out.size):
            x = q[k].reshape(-1, 3)[:, :2]
            try:
                keys = self.system.contacts(x, 0.0).key
            except InputError:
                out[k] = False
                continue
            out[k] = bool(np.all(np.isin(keys, self._keys)))
        return out

    def initial_state(self):
        return self._q0.copy(), self._v0.copy()

    def shapes(self, q, t=0.0):
        """Disks, walls and the candidate contacts at SI coordinates ``q`` (:mod:`moreau.model.drawing`).

        A candidate whose gap exceeds a hundredth of the system's length unit is
        marked ``"open"`` (an animation draws no point for it: with every pair a
        candidate, most are far apart).
        """
        qs = np.asarray(q, dtype=float) / self._qscale()
        x, gap, n, _ = self._geometry(qs)
        L = self.length
        out = []
        sysm = self.system
        span = float(np.ptp(x[:, 0]) + np.ptp(x[:, 1]) + 4.0 * np.max(sysm.radii))
        for w in range(sysm.n_walls):
            p0, p1 = sysm._p0[w], sysm._p1[w]
            if sysm._kind[w] == _HALF_PLANE:
                along = np.array([-p1[1], p1[0]])
                ends = [p0 - span * along, p0 + span * along]
            else:
                ends = [p0, p1]
            out.append(line([e * L for e in ends], role="ground"))
        for i in range(sysm.n_disks):
            out.append(circle(x[i] * L, sysm.radii[i] * L))
        for k in range(self._a.size):
            p = x[self._b[k]] - sysm.radii[self._b[k]] * n[k]
            c = contact(k, p * L, n[k], (-n[k, 1], n[k, 0]))
            c["open"] = bool(gap[k] > 0.01)
            out.append(c)
        return out
