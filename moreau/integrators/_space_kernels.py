"""Moreau–Jean's step on a spatial scene in one compiled loop, the twin of :mod:`._space_step`.

The loop :func:`space_loop` takes the arguments of every compiled block
(:meth:`moreau.integrators._blocks.CompiledRecording._run_block`): the
scene's bodies and contacts come as one tuple (:func:`space_tables`) in
place of a compiled model. A step is the Python step's
(:func:`moreau.integrators._space_step.space_step`), in the same order of
operations, written over each body's six columns: the free velocity (the
gyroscopic part by the body's own implicit 3x3 Newton), the contact rows of
the scene's shapes against its half-spaces
(:meth:`moreau.model.space.SpaceScene.contact_table`), the Delassus matrix
``W = H M^-1 H^T`` of the active contacts, then the cone:

(the cone's solver is an argument called through a pointer,
:func:`space_solver`, so that a run compiles and links only its own):

* ``"exact"``: :func:`moreau.contact.cone3d.exact_gauss_seidel`, the exact
  solver's Gauss–Seidel phase with its exact local solve, then where it
  stops short its Newton polish (:func:`moreau.contact.cone3d.exact_newton_polish`:
  several contacts on one body, a box's corners; compiled and linked only for
  scenes with such a body); where that misses too the step is handed back
  (:data:`LCP_HANDBACK`) to the Python step, which runs the whole solver;
* ``d`` directions: the polyhedral LCP of
  :func:`moreau.contact.cone3d.build_polyhedral_lcp`, assembled here and
  solved by :func:`moreau.lcp.lemke.lemke_core`; where Lemke fails the
  step is handed back (the Python step's solver has the exact tie decisions
  and the QP fallback).

Then the new velocity, the magnitudes of the tangential impulse and the
slip, the regimes and the exponential-map update of the orientations
(:func:`moreau.model.spatial.rotate_into`). The numbers are the Python
step's to rounding (sums in another order): tested to 1e-12 on every
spatial scene in ``tests/integrators/test_space_compiled.py``.
"""

import math

import numba
import numpy as np
from numba import njit
from numba.core import types as nbtypes

from .. import _jit_cache
from ..contact import cone3d as _cone3d
from ..contact.cone3d import (exact_gauss_seidel, exact_newton_polish, facet_directions,
                              natural_map_sq)
from ..lcp.lemke import DEFAULT_TOL, default_max_iter, lemke_core, lemke_workspace
from ..model import spatial as _spatial
from ..model.spatial import rotate_into
from . import _contact_step, _driver
from ._contact_step import LCP_HANDBACK, NUMERICAL, OK, S_LCP, S_PEN, S_PIVOTS, S_RES
from ._driver import grid_step

__all__ = ["SpaceTables", "space_tables", "space_loop", "space_solver", "run_space_loop",
           "SOLVE_SIGNATURE", "EXACT_TOL", "EXACT_POLISH_FROM", "EXACT_SWEEPS", "EXACT_NEWTON"]

#: :func:`moreau.contact.cone3d.solve_exact`'s defaults, which the Python step uses
EXACT_TOL, EXACT_POLISH_FROM, EXACT_SWEEPS = 1e-10, 1e-6, 500
#: its first Newton run's budget, half of its 30 steps (the rest is for its restart)
EXACT_NEWTON = 15

# the regimes (moreau.regimes.Regime) and the Python step's stick threshold
_POSITIVE, _STICK = 1, 3
_SLIP_RTOL = 1e-9


class SpaceTables:
    """A spatial scene as the compiled loop takes it: ``tables`` (:func:`space_tables`) and an
    unused ``par`` (the block runner passes a compiled model's parameters first)."""

    __slots__ = ("tables", "par", "several")

    def __init__(self, tables):
        self.tables = tables
        self.par = np.zeros(1)
        #: some body has several contacts: the exact cone may need Newton's polish
        bodies = tables[5][:, 0]
        self.several = bool(bodies.size > np.unique(bodies).size)


def space_tables(scene, cone, mu, e):
    """The compiled loop's description of a spatial scene, or None where it has none.

    A :class:`SpaceTables` of the tuple ``(masses, inertias, Minv blocks (nb, 6, 6), gyroscopic flags,
    gravity, contact table, mu, e, facet directions (2, d), Lemke's pivot
    limit per number of active contacts, d)`` (``d = 0``: the exact cone).
    None where a contact is of a kind the loop does not know
    (:meth:`~moreau.model.space.SpaceScene.contact_table`).
    """
    table = scene.contact_table()
    if table is None:
        return None
    nb = scene.nbodies
    Minv = np.asarray(scene.mass_inverse(scene.initial_state()[0]), dtype=float)
    blocks = np.array([Minv[6 * b:6 * b + 6, 6 * b:6 * b + 6] for b in range(nb)]).reshape(nb, 6, 6)
    gyro = np.zeros(nb, dtype=np.bool_)
    gyro[list(scene.gyroscopic_bodies)] = True
    d = 0 if cone == "exact" else int(cone)
    D = facet_directions(d) if d else np.zeros((2, 1))
    nc = scene.ncontacts
    maxit = np.array([default_max_iter(max(a * (d + 2), 1)) for a in range(nc + 1)],
                     dtype=np.int64)
    return SpaceTables((np.ascontiguousarray(scene.masses, dtype=float),
            np.ascontiguousarray(scene.inertias, dtype=float).reshape(nb, 3, 3), blocks, gyro,
            np.ascontiguousarray(scene.gravity, dtype=float), np.ascontiguousarray(table),
            np.ascontiguousarray(mu, dtype=float), np.ascontiguousarray(e, dtype=float),
            np.ascontiguousarray(D), maxit, np.int64(d)))


@njit(cache=True)
def _rotation(q, b, R):
    # the body-to-world rotation of body b's quaternion, normalised as the Python step does
    o = 7 * b + 3
    nrm = math.sqrt(q[o] * q[o] + q[o + 1] * q[o + 1] + q[o + 2] * q[o + 2] + q[o + 3] * q[o + 3])
    w, x, y, z = q[o] / nrm, q[o + 1] / nrm, q[o + 2] / nrm, q[o + 3] / nrm
    R[b, 0, 0] = 1 - 2 * (y * y + z * z)
    R[b, 0, 1] = 2 * (x * y - w * z)
    R[b, 0, 2] = 2 * (x * z + w * y)
    R[b, 1, 0] = 2 * (x * y + w * z)
    R[b, 1, 1] = 1 - 2 * (x * x + z * z)
    R[b, 1, 2] = 2 * (y * z - w * x)
    R[b, 2, 0] = 2 * (x * z - w * y)
    R[b, 2, 1] = 2 * (y * z + w * x)
    R[b, 2, 2] = 1 - 2 * (x * x + y * y)


@njit(cache=True)
def _offset(ct, i, R, s):
    # the contact point's offset s from its body's centre (world), by the contact's kind
    b = int(ct[i, 0])
    kind = ct[i, 1]
    for a in range(3):
        if kind == 2.0:
            s[a] = R[b, a, 0] * ct[i, 3] + R[b, a, 1] * ct[i, 4] + R[b, a, 2] * ct[i, 5]
        else:
            s[a] = -ct[i, 2] * ct[i, 9 + a]
            if kind == 1.0:
                s[a] += R[b, a, 0] * ct[i, 3] + R[b, a, 1] * ct[i, 4] + R[b, a, 2] * ct[i, 5]
    return b


@njit(cache=True)
def _gap(ct, i, q, R, s):
    b = _offset(ct, i, R, s)
    g = 0.0
    for a in range(3):
        g += ct[i, 9 + a] * ((q[7 * b + a] + s[a]) - ct[i, 6 + a])
    return g


@njit(cache=True)
def _rows(ct, i, R, s, rows):
    # rows[i, k] = (e, R^T (s x e)) for e = n, t1, t2 (moreau.model.space.point_rows)
    b = int(ct[i, 0])
    for k in range(3):
        e0, e1, e2 = ct[i, 9 + 3 * k], ct[i, 10 + 3 * k], ct[i, 11 + 3 * k]
        c0 = s[1] * e2 - s[2] * e1
        c1 = s[2] * e0 - s[0] * e2
        c2 = s[0] * e1 - s[1] * e0
        rows[i, k, 0] = e0
        rows[i, k, 1] = e1
        rows[i, k, 2] = e2
        for j in range(3):
            rows[i, k, 3 + j] = c0 * R[b, 0, j] + c1 * R[b, 1, j] + c2 * R[b, 2, j]


@njit(cache=True)
def _solve3(A, F, out):
    # A out = F by Gaussian elimination with partial pivoting (a 3x3 system)
    M = A.copy()
    x = F.copy()
    for c in range(3):
        p = c
        for r in range(c + 1, 3):
            if abs(M[r, c]) > abs(M[p, c]):
                p = r
        if p != c:
            for j in range(3):
                M[c, j], M[p, j] = M[p, j], M[c, j]
            x[c], x[p] = x[p], x[c]
        for r in range(c + 1, 3):
            f = M[r, c] / M[c, c]
            for j in range(c, 3):
                M[r, j] -= f * M[c, j]
            x[r] -= f * x[c]
    for c in range(2, -1, -1):
        acc = x[c]
        for j in range(c + 1, 3):
            acc -= M[c, j] * out[j]
        out[c] = acc / M[c, c]


@njit(cache=True)
def _free_rotation(J, w0, impulse, h, theta, w):
    # the Python step's _free_rotation: J (w - w0) + h wt x J wt = impulse, Newton on 3x3
    dw = np.empty(3)
    wt = np.empty(3)
    Jw = np.empty(3)
    F = np.empty(3)
    A = np.empty((3, 3))
    _solve3(J, impulse, dw)
    for a in range(3):
        w[a] = w0[a] + dw[a]
    for _ in range(20):
        for a in range(3):
            wt[a] = theta * w[a] + (1.0 - theta) * w0[a]
        for a in range(3):
            Jw[a] = J[a, 0] * wt[0] + J[a, 1] * wt[1] + J[a, 2] * wt[2]
        for a in range(3):
            a1 = (a + 1) % 3
            a2 = (a + 2) % 3
            F[a] = (J[a, 0] * (w[0] - w0[0]) + J[a, 1] * (w[1] - w0[1]) + J[a, 2] * (w[2] - w0[2])
                    + h * (wt[a1] * Jw[a2] - wt[a2] * Jw[a1]) - impulse[a])
            # h theta ([wt]x J - [J wt]x), row a
            for j in range(3):
                A[a, j] = J[a, j] + h * theta * (wt[a1] * J[a2, j] - wt[a2] * J[a1, j])
            A[a, a2] -= h * theta * Jw[a1]
            A[a, a1] += h * theta * Jw[a2]
        _solve3(A, F, dw)
        big = 0.0
        wmax = 0.0
        for a in range(3):
            w[a] -= dw[a]
            big = max(big, abs(dw[a]))
            wmax = max(wmax, abs(w[a]))
        if big <= 1e-15 * max(1.0, wmax):
            break


@njit(cache=True)
def _polyhedral(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter, r):
    # build_polyhedral_lcp's M = B^T W B + E, q = B^T Uf on the active contacts, Lemke, r = B z
    m = d + 2
    L = na * m
    for a in range(L):
        for c in range(L):
            Ml[a, c] = 0.0
    for a in range(na):
        ba = m * a
        for c in range(na):
            bc = m * c
            Ml[ba, bc] = W[3 * a, 3 * c]
            for k in range(d):
                Ml[ba, bc + 1 + k] = W[3 * a, 3 * c + 1] * D[0, k] + W[3 * a, 3 * c + 2] * D[1, k]
                Ml[ba + 1 + k, bc] = D[0, k] * W[3 * a + 1, 3 * c] + D[1, k] * W[3 * a + 2, 3 * c]
            for j in range(d):
                # (D^T W_TT)_j, then times D
                x1 = D[0, j] * W[3 * a + 1, 3 * c + 1] + D[1, j] * W[3 * a + 2, 3 * c + 1]
                x2 = D[0, j] * W[3 * a + 1, 3 * c + 2] + D[1, j] * W[3 * a + 2, 3 * c + 2]
                for k in range(d):
                    Ml[ba + 1 + j, bc + 1 + k] = x1 * D[0, k] + x2 * D[1, k]
        for k in range(d):
            Ml[ba + 1 + k, ba + d + 1] = 1.0
            Ml[ba + d + 1, ba + 1 + k] = -1.0
        Ml[ba + d + 1, ba] = mu_a[a]
        ql[ba] = Uf[3 * a]
        for k in range(d):
            ql[ba + 1 + k] = D[0, k] * Uf[3 * a + 1] + D[1, k] * Uf[3 * a + 2]
        ql[ba + d + 1] = 0.0
    status, pivots, _ = lemke_core(Ml, ql[:L], dl, zl, wl, rayl, work, iwork, max_iter,
                                   DEFAULT_TOL)
    if status == 0:
        for a in range(na):
            ba = m * a
            r[3 * a] = zl[ba]
            r1 = 0.0
            r2 = 0.0
            for k in range(d):
                r1 += D[0, k] * zl[ba + 1 + k]
                r2 += D[1, k] * zl[ba + 1 + k]
            r[3 * a + 1] = r1
            r[3 * a + 2] = r2
    return status, pivots


@njit(cache=True)
def _exact_solve(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter, r, u):
    # the exact cone by Gauss–Seidel; status 1 where Newton's polish is needed (never with
    # one contact a body, whose local solve is exact: the solver of such scenes)
    u[:] = Uf
    ok, res, qn = exact_gauss_seidel(W, Uf, mu_a, r, u, EXACT_TOL, EXACT_POLISH_FROM,
                                     np.int64(EXACT_SWEEPS))
    return np.int64(0 if ok else 1), np.int64(0), res, qn


@njit(cache=True)
def _exact_polish_solve(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter,
                        r, u):
    # the exact cone by Gauss–Seidel, then Newton's polish where it stops short (several
    # contacts on one body); status 1 where solve_exact would go on (its restart)
    u[:] = Uf
    ok, res, qn = exact_gauss_seidel(W, Uf, mu_a, r, u, EXACT_TOL, EXACT_POLISH_FROM,
                                     np.int64(EXACT_SWEEPS))
    if not ok:
        ok, res, qn, _ = exact_newton_polish(W, Uf, mu_a, r, u, EXACT_TOL,
                                             np.int64(EXACT_NEWTON))
    return np.int64(0 if ok else 1), np.int64(0), res, qn


@njit(cache=True)
def _polyhedral_solve(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter, r,
                      u):
    # the d-direction LCP by Lemke; its status (0: solved), pivots, the exact cone's
    # natural-map residual at the answer and ||Uf||
    status, pivots = _polyhedral(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork,
                                 max_iter, r)
    n3 = Uf.shape[0]
    qn = 0.0
    for a in range(n3):
        acc = Uf[a]
        for c in range(n3):
            acc += W[a, c] * r[c]
        u[a] = acc
        qn += Uf[a] * Uf[a]
    return status, pivots, math.sqrt(natural_map_sq(r, u, mu_a)), math.sqrt(qn)


_A1 = nbtypes.float64[::1]
_A2 = nbtypes.float64[:, ::1]
_INT = nbtypes.int64
#: the signature of the cone solvers, which the loop calls through a pointer: a run with
#: one cone neither compiles nor links the other (Lemke is a third of the loop's compile)
SOLVE_SIGNATURE = nbtypes.Tuple((_INT, _INT, nbtypes.float64, nbtypes.float64))(
    _A2, _A1, _A1, _A2, _INT, _INT, _A2, _A1, _A1, _A1, _A1, _A1, _A2, nbtypes.int64[::1], _INT,
    _A1, _A1)


def space_solver(cone, several=False):
    """The loop's solver of the cone ``cone`` (``"exact"`` or ``d``), compiled for :data:`SOLVE_SIGNATURE`.

    With ``several`` (some body has several contacts,
    :attr:`SpaceTables.several`) the exact cone's solver ends with Newton's
    polish; without, it is compiled without it (a third of the exact path's
    compile: with one contact a body Gauss–Seidel's exact local solve converges
    in a sweep).
    """
    fn = (_polyhedral_solve if cone != "exact" else
          _exact_polish_solve if several else _exact_solve)
    if not fn.signatures:
        fn.compile(SOLVE_SIGNATURE)
    return fn


def run_space_loop(*args):
    """:func:`space_loop` with the solver (argument 13) passed as a pointer, not linked in.

    The loop is compiled once for the argument types with the solver typed
    by :data:`SOLVE_SIGNATURE` (from numba's disk cache where it is there).
    """
    # one signature whatever the caller's scalars (an integer t0, a numpy bool)
    args = list(args)
    for i in (3, 4, 5, 11):
        args[i] = float(args[i])
    for i in (6, 7, 14):
        args[i] = int(args[i])
    args[15] = bool(args[15])
    if not _LOOP:
        types = [numba.typeof(a) for a in args]
        types[13] = nbtypes.FunctionType(SOLVE_SIGNATURE)
        space_loop.compile(tuple(types))
        space_loop.disable_compile()
        _LOOP.append(True)
    return space_loop(*args)


_LOOP = []


@njit(cache=True)
def space_loop(par, mu, e, t0, h, t_bound, k0, nmax, q, v, tables, theta, closed, solve,
               save_every, record_initial, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
               stats):
    """Up to ``nmax`` Moreau–Jean steps of a spatial scene from ``(q, v)`` at ``t0 + k0 h``.

    ``tables`` is :func:`space_tables`'s tuple, ``closed`` the contacts
    closed in the step before (updated), ``solve`` the cone's solver
    (:func:`space_solver`, called through a pointer), ``par`` unused (the block runner's
    slot of a compiled model's parameters). The recording buffers and
    ``stats`` are those of every compiled block. Returns ``(status, k,
    nrec)``: ``OK``, :data:`LCP_HANDBACK` (the contact problem of step ``k``
    is left to the Python step, the state is that step's start) or
    :data:`NUMERICAL` (a non-finite state; the last good one is kept).
    """
    bm, bJ, bMinv, bgyro, grav, ct, _, _, D, maxit, d = tables
    nb = bm.shape[0]
    nc = ct.shape[0]
    nv = 6 * nb
    nq = 7 * nb
    ncm = max(nc, 1)
    R = np.empty((nb, 3, 3))
    R1 = np.empty((nb, 3, 3))
    s = np.empty(3)
    rows = np.zeros((ncm, 3, 6))
    g0 = np.empty(ncm)
    g1 = np.empty(ncm)
    vN0 = np.empty(ncm)
    f = np.empty(nv)
    vfree = np.empty(nv)
    v1 = np.empty(nv)
    q1 = np.empty(nq)
    wb = np.empty(3)
    imp = np.empty(3)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    reg = np.zeros(ncm, dtype=np.int64)
    ia = np.empty(ncm, dtype=np.int64)
    MHT = np.empty((3 * ncm, 6))
    Wf = np.empty((3 * ncm, 3 * ncm))
    Uf_all = np.empty(3 * ncm)
    r_all = np.empty(3 * ncm)
    u_all = np.empty(3 * ncm)
    U = np.empty(3)
    mu_all = np.empty(ncm)
    Lmax = ncm * (d + 2)
    Ml = np.zeros((Lmax, Lmax))
    ql = np.zeros(Lmax)
    dl = np.ones(Lmax)
    zl = np.zeros(Lmax)
    wl = np.zeros(Lmax)
    rayl = np.zeros(Lmax + 1)
    work, iwork = lemke_workspace(Lmax)
    qt = np.empty(4)
    W = np.empty((0, 0))
    Uf = np.empty(0)
    mu_a = np.empty(0)
    r = np.empty(0)
    u = np.empty(0)
    for b in range(nb):
        _rotation(q, b, R)
    nrec = np.int64(0)  # not a literal: see _driver.drive
    k = k0
    status = OK
    while k - k0 < nmax:
        tk, t1, hk, last = grid_step(t0, k, h, t_bound)
        if tk >= t_bound:
            break
        # the forces but the gyroscopic ones, which each anisotropic body's rotation takes
        for b in range(nb):
            o = 6 * b
            for a in range(3):
                f[o + a] = bm[b] * grav[a]
            if bgyro[b]:
                for a in range(3):
                    f[o + 3 + a] = 0.0
            else:
                J = bJ[b]
                w0, w1, w2 = v[o + 3], v[o + 4], v[o + 5]
                j0 = J[0, 0] * w0 + J[0, 1] * w1 + J[0, 2] * w2
                j1 = J[1, 0] * w0 + J[1, 1] * w1 + J[1, 2] * w2
                j2 = J[2, 0] * w0 + J[2, 1] * w1 + J[2, 2] * w2
                f[o + 3] = -(w1 * j2 - w2 * j1)
                f[o + 4] = -(w2 * j0 - w0 * j2)
                f[o + 5] = -(w0 * j1 - w1 * j0)
            if theta != 1.0:
                for a in range(6):
                    f[o + a] = theta * f[o + a] + (1.0 - theta) * f[o + a]
            for a in range(6):
                acc = 0.0
                for j in range(6):
                    acc += bMinv[b, a, j] * f[o + j]
                vfree[o + a] = v[o + a] + hk * acc
            if bgyro[b]:
                for a in range(3):
                    imp[a] = hk * f[o + 3 + a]
                _free_rotation(bJ[b], v[o + 3:o + 6], imp, hk, theta, wb)
                for a in range(3):
                    vfree[o + 3 + a] = wb[a]
        for j in range(nv):
            v1[j] = vfree[j]
        na = 0
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
            reg[i] = 0
            g0[i] = _gap(ct, i, q, R, s)
            _rows(ct, i, R, s, rows)
            b = int(ct[i, 0])
            acc = 0.0
            for j in range(6):
                acc += rows[i, 0, j] * v[6 * b + j]
            vN0[i] = acc
            if g0[i] + 0.5 * hk * vN0[i] <= 0.0 or closed[i]:
                ia[na] = i
                na += 1
        if na:
            n3 = 3 * na
            for a in range(na):
                i = ia[a]
                b = int(ct[i, 0])
                mu_all[a] = mu[i]
                for kk in range(3):
                    row = 3 * a + kk
                    for j in range(6):
                        acc = 0.0
                        for l in range(6):
                            acc += bMinv[b, j, l] * rows[i, kk, l]
                        MHT[row, j] = acc
                    acc = 0.0
                    for j in range(6):
                        acc += rows[i, kk, j] * vfree[6 * b + j]
                    Uf_all[row] = acc
                Uf_all[3 * a] += e[i] * min(vN0[i], 0.0)
            # W = H M^-1 H^T by contact pairs: zero between two bodies' contacts
            for a in range(na):
                i = ia[a]
                ba = int(ct[i, 0])
                for c in range(na):
                    same = ba == int(ct[ia[c], 0])
                    for kk in range(3):
                        for ll in range(3):
                            acc = 0.0
                            if same:
                                for j in range(6):
                                    acc += rows[i, kk, j] * MHT[3 * c + ll, j]
                            Wf[3 * a + kk, 3 * c + ll] = acc
            if n3 != W.shape[0]:
                # the solvers take contiguous arrays of the problem's size: new ones only
                # when the number of active contacts changes
                W = np.empty((n3, n3))
                Uf = np.empty(n3)
                mu_a = np.empty(na)
                r = np.empty(n3)
                u = np.empty(n3)
            for a in range(n3):
                for c in range(n3):
                    W[a, c] = 0.5 * (Wf[a, c] + Wf[c, a])
                Uf[a] = Uf_all[a]
                r[a] = 0.0
            for a in range(na):
                mu_a[a] = mu_all[a]
            lst, piv, res, qn = solve(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work,
                                      iwork, maxit[na], r, u)
            if lst != 0:
                status = LCP_HANDBACK
                break
            stats[S_PIVOTS] += piv
            stats[S_LCP] += 1
            stats[S_RES] = max(stats[S_RES], res / qn if qn > 0.0 else res)
            for a in range(na):
                b = int(ct[ia[a], 0])
                for j in range(6):
                    v1[6 * b + j] += (MHT[3 * a, j] * r[3 * a] + MHT[3 * a + 1, j] * r[3 * a + 1]
                                      + MHT[3 * a + 2, j] * r[3 * a + 2])
            scale = 1e-300
            for a in range(n3):
                scale = max(scale, abs(Uf[a]))
            for a in range(na):
                i = ia[a]
                b = int(ct[i, 0])
                for kk in range(3):
                    acc = 0.0
                    for j in range(6):
                        acc += rows[i, kk, j] * v1[6 * b + j]
                    U[kk] = acc
                pN[i] = r[3 * a]
                pT[i] = math.hypot(r[3 * a + 1], r[3 * a + 2])
                slip[i] = math.hypot(U[1], U[2])
                if pN[i] > 0.0:
                    reg[i] = (_POSITIVE if mu[i] > 0.0 and slip[i] > _SLIP_RTOL * scale
                              else _STICK)
        # q moved at the theta-weighted velocity: centres, then orientations on SO(3)
        for b in range(nb):
            for a in range(3):
                q1[7 * b + a] = q[7 * b + a] + hk * (theta * v1[6 * b + a]
                                                     + (1.0 - theta) * v[6 * b + a])
            wm0 = theta * v1[6 * b + 3] + (1.0 - theta) * v[6 * b + 3]
            wm1 = theta * v1[6 * b + 4] + (1.0 - theta) * v[6 * b + 4]
            wm2 = theta * v1[6 * b + 5] + (1.0 - theta) * v[6 * b + 5]
            rotate_into(q[7 * b + 3:7 * b + 7], wm0, wm1, wm2, hk, qt)
            for a in range(4):
                q1[7 * b + 3 + a] = qt[a]
        finite = True
        for j in range(nq):
            finite = finite and math.isfinite(q1[j])
        for j in range(nv):
            finite = finite and math.isfinite(v1[j])
        if not finite:
            status = NUMERICAL
            break
        for b in range(nb):
            _rotation(q1, b, R1)
        for i in range(nc):
            g1[i] = _gap(ct, i, q1, R1, s)
            stats[S_PEN] = max(stats[S_PEN], -g1[i])
        if record_initial:
            _record(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec, tk,
                    q, v, reg, pN, pT, hk, slip, g0, nc)
            nrec += 1
            record_initial = False
        for j in range(nq):
            q[j] = q1[j]
        for j in range(nv):
            v[j] = v1[j]
        for b in range(nb):
            for a in range(3):
                for c in range(3):
                    R[b, a, c] = R1[b, a, c]
        for i in range(nc):
            closed[i] = pN[i] > 0.0
        k += 1
        if k % save_every == 0 or last:
            _record(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec, t1,
                    q, v, reg, pN, pT, hk, slip, g1, nc)
            nrec += 1
        if last:
            break
    return status, k, nrec


@njit(cache=True)
def _record(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec, t, q, v, reg,
            pN, pT, h, slip, gap, nc):
    rec_t[nrec] = t
    for j in range(q.shape[0]):
        rec_q[nrec, j] = q[j]
    for j in range(v.shape[0]):
        rec_v[nrec, j] = v[j]
    for i in range(nc):
        rec_reg[nrec, i] = reg[i]
        rec_fN[nrec, i] = pN[i] / h
        rec_fT[nrec, i] = pT[i] / h
        rec_slip[nrec, i] = slip[i]
        rec_gap[nrec, i] = gap[i]


#: every source whose compiled code ends up in this module's functions
KERNEL_SOURCES = ((__file__, _cone3d.__file__, _spatial.__file__, _driver.__file__)
                  + _contact_step.KERNEL_SOURCES)

# numba checks a cached kernel against its own file only: tie it to those it links in
CACHE_MODE = _jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    KERNEL_SOURCES)
