"""Moreau–Jean's step on a spatial scene in one compiled loop, the twin of :mod:`._space_step`.

The loop :func:`space_loop` takes the arguments of every compiled block
(:meth:`moreau.integrators._blocks.CompiledRecording._run_block`): the
scene's bodies and contacts come as one tuple (:func:`space_tables`) in
place of a compiled model. A step is the Python step's
(:func:`moreau.integrators._space_step.space_step`), in the same order of
operations, written over each body's six columns: the free velocity (the
gyroscopic part by the body's own implicit 3x3 Newton), the contact rows of
the scene's shapes against its half-spaces
(:meth:`moreau.model.space.SpaceScene.contact_table`) and of its sphere
pairs between two bodies (:meth:`~moreau.model.space.SpaceScene.pair_table`:
rows on both bodies' six velocities, the frame of the line of centres), the
Delassus matrix ``W = H M^-1 H^T`` of the active contacts (a block between
two contacts wherever they share a body), then the cone:

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
from numba.experimental.function_type import _get_wrapper_address as _wrapper_address

from .. import _jit_cache
from ..contact import cone3d as _cone3d
from ..contact.cone3d import (contensou_gauss_seidel, exact_gauss_seidel_into,
                              exact_newton_polish, facet_directions, natural_map_sq,
                              polyhedral_one_contact)
from ..lcp.lemke import DEFAULT_TOL, default_max_iter, lemke_core, lemke_workspace
from ..model import spatial as _spatial
from ..model.spatial import rotate_into
from . import _contact_step, _driver
from ._contact_step import LCP_HANDBACK, NUMERICAL, OK, S_LCP, S_PEN, S_PIVOTS, S_RES
from ._driver import grid_step, record_sample

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
    """A spatial scene as the compiled loop takes it: ``tables`` (:func:`space_tables`), the
    contacts' second bodies ``pairs`` (:meth:`~moreau.model.space.SpaceScene.pair_table`, None
    without contacts between two bodies) and an unused ``par`` (the block runner passes a
    compiled model's parameters first)."""

    __slots__ = ("tables", "pairs", "par", "several", "drilling")

    def __init__(self, tables, pairs=None):
        self.tables = tables
        self.pairs = pairs
        self.par = np.zeros(1)
        #: some body has several contacts: the exact cone may need Newton's polish
        bodies = tables[5][:, 0]
        if pairs is not None:
            bodies = np.concatenate([bodies, pairs[pairs[:, 0] >= 0.0, 0]])
        self.several = bool(bodies.size > np.unique(bodies).size)
        #: some frictional contact has a patch: Coulomb–Contensou's solver
        self.drilling = bool(np.any(tables[11] > 0.0))


def space_tables(scene, cone, mu, e):
    """The compiled loop's description of a spatial scene, or None where it has none.

    A :class:`SpaceTables` (with the scene's
    :meth:`~moreau.model.space.SpaceScene.pair_table`) of the tuple ``(masses, inertias,
    Minv blocks (nb, 6, 6), gyroscopic flags,
    gravity, contact table, mu, e, facet directions (2, d), Lemke's pivot
    limit per number of active contacts, d, drilling levers)`` (``d = 0``: the
    exact cone; a contact's lever ``r* > 0`` where it has a patch and
    friction: Coulomb–Contensou, its drilling row in the loop). None where a
    contact is of a kind the loop does not know
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
            np.ascontiguousarray(D), maxit, np.int64(d), _levers(scene, mu)),
        _pair_table(scene))


def _pair_table(scene):
    pairs = scene.pair_table() if hasattr(scene, "pair_table") else None
    return None if pairs is None else np.ascontiguousarray(pairs, dtype=float)


def _levers(scene, mu):
    # each contact's drilling lever r*, zero without a patch or without friction (the Python
    # step's Coulomb–Contensou rows: moreau.integrators._space_step._contensou_contacts)
    lever = np.asarray(getattr(scene, "drilling_levers", np.zeros(scene.ncontacts)), dtype=float)
    return np.ascontiguousarray(np.where(np.asarray(mu, dtype=float) > 0.0, lever, 0.0))


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
def _pair_gap(ct, pp, i, q, R, x):
    # (ok, gap) of a pair, its line left in x (_pair_line); not ok where the centres are
    # within the pair's bound (concentric spheres: no normal), which the Python step diagnoses
    L = _pair_line(ct, pp, i, q, R, x)
    if not L > pp[i, 5]:
        return False, 0.0
    return True, L - ct[i, 2] - pp[i, 1]


@njit(cache=True)
def _pair_line(ct, pp, i, q, R, x):
    # a contact between two bodies' spheres (moreau.model.space, "Contacts between two
    # spheres"), body a's sphere in the table ct, body b's in pp (SpaceScene.pair_table):
    # x[0:3] = R_a c_a, x[3:6] = R_b c_b, x[6:9] = n; returns the centres' distance L, n
    # left as it was where L <= pp[i, 5] (no normal: the caller hands the step back)
    a = int(ct[i, 0])
    b = int(pp[i, 0])
    for k in range(3):
        x[k] = R[a, k, 0] * ct[i, 3] + R[a, k, 1] * ct[i, 4] + R[a, k, 2] * ct[i, 5]
        x[3 + k] = R[b, k, 0] * pp[i, 2] + R[b, k, 1] * pp[i, 3] + R[b, k, 2] * pp[i, 4]
    d0 = (q[7 * b] + x[3]) - (q[7 * a] + x[0])
    d1 = (q[7 * b + 1] + x[4]) - (q[7 * a + 1] + x[1])
    d2 = (q[7 * b + 2] + x[5]) - (q[7 * a + 2] + x[2])
    L = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if L > pp[i, 5]:
        x[6] = d0 / L
        x[7] = d1 / L
        x[8] = d2 / L
    return L


@njit(cache=True)
def _pair_rows(ct, pp, i, R, x, rows, rowsb):
    # the pair's rows [n, t1, t2] on its two bodies from _pair_line's x: rowsb[i, k] = (e,
    # R_b^T (s_b x e)) on body b, rows[i, k] = -(e, R_a^T (s_a x e)) on body a, with s_a =
    # R_a c_a + r_a n, s_b = R_b c_b - r_b n and the frame of tangent_basis(n)
    # (moreau.model.space._frame, written out the same way); x[9:18] takes the frame
    a = int(ct[i, 0])
    b = int(pp[i, 0])
    n0, n1, n2 = x[6], x[7], x[8]
    a0, a1, a2 = abs(n0), abs(n1), abs(n2)
    k = (0 if a0 <= a2 else 2) if a0 <= a1 else (1 if a1 <= a2 else 2)
    nk = n0 if k == 0 else (n1 if k == 1 else n2)
    x[12] = -nk * n0
    x[13] = -nk * n1
    x[14] = -nk * n2
    x[12 + k] += 1.0
    f = 1.0 / math.sqrt(x[12] * x[12] + x[13] * x[13] + x[14] * x[14])
    u0, u1, u2 = x[12] * f, x[13] * f, x[14] * f
    x[9], x[10], x[11] = n0, n1, n2
    x[12], x[13], x[14] = u0, u1, u2
    x[15] = n1 * u2 - n2 * u1
    x[16] = n2 * u0 - n0 * u2
    x[17] = n0 * u1 - n1 * u0
    ra = ct[i, 2]
    rb = pp[i, 1]
    sa0, sa1, sa2 = x[0] + ra * n0, x[1] + ra * n1, x[2] + ra * n2
    sb0, sb1, sb2 = x[3] - rb * n0, x[4] - rb * n1, x[5] - rb * n2
    for kk in range(3):
        e0, e1, e2 = x[9 + 3 * kk], x[10 + 3 * kk], x[11 + 3 * kk]
        ca0 = sa1 * e2 - sa2 * e1
        ca1 = sa2 * e0 - sa0 * e2
        ca2 = sa0 * e1 - sa1 * e0
        cb0 = sb1 * e2 - sb2 * e1
        cb1 = sb2 * e0 - sb0 * e2
        cb2 = sb0 * e1 - sb1 * e0
        rows[i, kk, 0] = -e0
        rows[i, kk, 1] = -e1
        rows[i, kk, 2] = -e2
        rowsb[i, kk, 0] = e0
        rowsb[i, kk, 1] = e1
        rowsb[i, kk, 2] = e2
        for j in range(3):
            rows[i, kk, 3 + j] = -(ca0 * R[a, 0, j] + ca1 * R[a, 1, j] + ca2 * R[a, 2, j])
            rowsb[i, kk, 3 + j] = cb0 * R[b, 0, j] + cb1 * R[b, 1, j] + cb2 * R[b, 2, j]


@njit(cache=True)
def _drilling_row(ct, i, R, lever, rows):
    # rows[i, 3] = (0, r* R^T n): the patch's spin about the normal, r* n . (R omega)
    # (moreau.model.space.SpaceScene.drilling_rows)
    b = int(ct[i, 0])
    for j in range(3):
        rows[i, 3, j] = 0.0
        rows[i, 3, 3 + j] = lever * (ct[i, 9] * R[b, 0, j] + ct[i, 10] * R[b, 1, j]
                                     + ct[i, 11] * R[b, 2, j])


@njit(cache=True)
def _solve3(S, ia, jf, jo):
    # S[jo] = x with S[ia:ia+3] x = S[jf] by Gaussian elimination with partial pivoting (a 3x3
    # system), on the rows of the scratch S (rows 7-10 its working copy): no array allocated
    for i in range(3):
        for j in range(3):
            S[7 + i, j] = S[ia + i, j]
        S[10, i] = S[jf, i]
    for c in range(3):
        p = c
        for r in range(c + 1, 3):
            if abs(S[7 + r, c]) > abs(S[7 + p, c]):
                p = r
        if p != c:
            for j in range(3):
                S[7 + c, j], S[7 + p, j] = S[7 + p, j], S[7 + c, j]
            S[10, c], S[10, p] = S[10, p], S[10, c]
        for r in range(c + 1, 3):
            f = S[7 + r, c] / S[7 + c, c]
            for j in range(c, 3):
                S[7 + r, j] -= f * S[7 + c, j]
            S[10, r] -= f * S[10, c]
    for c in range(2, -1, -1):
        acc = S[10, c]
        for j in range(c + 1, 3):
            acc -= S[7 + c, j] * S[jo, j]
        S[jo, c] = acc / S[7 + c, c]


@njit(cache=True)
def _free_rotation(J, v, o, h, theta, S):
    # the Python step's _free_rotation: J (w - w0) + h wt x J wt = impulse, Newton on 3x3,
    # w0 = v[o:o+3], in the rows of the loop's scratch S (12 x 3; nothing allocated a step):
    # 0 w, 1 F then dw (the solve copies F first), 2 wt, 3 J wt, 4-6 J then the Jacobian,
    # 7-10 _solve3's working copy, 11 the impulse
    for a in range(3):
        for j in range(3):
            S[4 + a, j] = J[a, j]
    _solve3(S, 4, 11, 1)
    for a in range(3):
        S[0, a] = v[o + a] + S[1, a]
    for _ in range(20):
        for a in range(3):
            S[2, a] = theta * S[0, a] + (1.0 - theta) * v[o + a]
        for a in range(3):
            S[3, a] = J[a, 0] * S[2, 0] + J[a, 1] * S[2, 1] + J[a, 2] * S[2, 2]
        for a in range(3):
            a1 = (a + 1) % 3
            a2 = (a + 2) % 3
            S[1, a] = (J[a, 0] * (S[0, 0] - v[o]) + J[a, 1] * (S[0, 1] - v[o + 1])
                       + J[a, 2] * (S[0, 2] - v[o + 2])
                       + h * (S[2, a1] * S[3, a2] - S[2, a2] * S[3, a1]) - S[11, a])
            # h theta ([wt]x J - [J wt]x), row a
            for j in range(3):
                S[4 + a, j] = J[a, j] + h * theta * (S[2, a1] * J[a2, j] - S[2, a2] * J[a1, j])
            S[4 + a, a2] -= h * theta * S[3, a1]
            S[4 + a, a1] += h * theta * S[3, a2]
        _solve3(S, 4, 1, 1)
        big = 0.0
        wmax = 0.0
        for a in range(3):
            S[0, a] -= S[1, a]
            big = max(big, abs(S[1, a]))
            wmax = max(wmax, abs(S[0, a]))
        if big <= 1e-15 * max(1.0, wmax):
            break


@njit(cache=True)
def _polyhedral(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter, r):
    # build_polyhedral_lcp's M = B^T W B + E, q = B^T Uf on the active contacts, Lemke, r = B z
    if na == 1 and polyhedral_one_contact(W, Uf, mu_a[0], D, r):
        return np.int64(0), np.int64(0)
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
    # Lemke's scratch, unused by this cone, is Gauss–Seidel's (the loop sizes it >= 3 a contact)
    ok, res, qn = exact_gauss_seidel_into(W, Uf, mu_a, r, u, EXACT_TOL, EXACT_POLISH_FROM,
                                          np.int64(EXACT_SWEEPS), Ml, ql, zl, wl)
    return np.int64(0 if ok else 1), np.int64(0), res, qn


@njit(cache=True)
def _exact_polish_solve(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter,
                        r, u):
    # the exact cone by Gauss–Seidel, then Newton's polish where it stops short (several
    # contacts on one body); status 1 where solve_exact would go on (its restart)
    u[:] = Uf
    # Lemke's scratch, unused by this cone, is Gauss–Seidel's (the loop sizes it >= 3 a contact)
    ok, res, qn = exact_gauss_seidel_into(W, Uf, mu_a, r, u, EXACT_TOL, EXACT_POLISH_FROM,
                                          np.int64(EXACT_SWEEPS), Ml, ql, zl, wl)
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


@njit(cache=True)
def _contensou_solve(W, Uf, mu_a, D, na, d, Ml, ql, dl, zl, wl, rayl, work, iwork, max_iter, r,
                     u):
    # Coulomb–Contensou's exact cone (solve_exact_contensou's sweeps from r = 0), a contact's
    # rows from iwork[a] to iwork[a + 1] (3, or 4 with its drilling row); status 1 where the
    # sweeps stop short (the Python step then says so)
    n = Uf.shape[0]
    qn = 0.0
    for j in range(n):
        u[j] = Uf[j]
        qn += Uf[j] * Uf[j]
    qn = math.sqrt(qn)
    scale = qn if qn > 0.0 else 1.0
    _, res = contensou_gauss_seidel(W, Uf, mu_a, iwork[:na + 1], r, u,
                                    (EXACT_TOL * scale) ** 2, EXACT_SWEEPS)
    res = math.sqrt(res)
    return np.int64(0 if res <= EXACT_TOL * scale else 1), np.int64(0), res, qn


_A1 = nbtypes.float64[::1]
_A2 = nbtypes.float64[:, ::1]
_INT = nbtypes.int64
#: the signature of the cone solvers, which the loop calls through a pointer: a run with
#: one cone neither compiles nor links the other (Lemke is a third of the loop's compile)
SOLVE_SIGNATURE = nbtypes.Tuple((_INT, _INT, nbtypes.float64, nbtypes.float64))(
    _A2, _A1, _A1, _A2, _INT, _INT, _A2, _A1, _A1, _A1, _A1, _A1, _A2, nbtypes.int64[::1], _INT,
    _A1, _A1)


def space_solver(cone, several=False, drilling=False):
    """The loop's solver of the cone ``cone`` (``"exact"`` or ``d``), compiled for :data:`SOLVE_SIGNATURE`.

    With ``several`` (some body has several contacts,
    :attr:`SpaceTables.several`) the exact cone's solver ends with Newton's
    polish; without, it is compiled without it (a third of the exact path's
    compile: with one contact a body Gauss–Seidel's exact local solve converges
    in a sweep). With ``drilling`` (a contact with a patch,
    :attr:`SpaceTables.drilling`) it is Coulomb–Contensou's
    (:func:`moreau.contact.cone3d.contensou_gauss_seidel`).
    """
    key = (cone != "exact", bool(several), bool(drilling))
    got = _SOLVERS.get(key)
    if got is None:
        fn = (_polyhedral_solve if cone != "exact" else _contensou_solve if drilling else
              _exact_polish_solve if several else _exact_solve)
        if not fn.signatures:
            fn.compile(SOLVE_SIGNATURE)
        got = _SOLVERS[key] = _Solver(fn)
    return got


class _Solver:
    """A compiled solver as the loop's function-pointer argument, its address looked up once.

    numba unboxes a dispatcher passed for a first-class function by looking
    its compiled entry up on every call (60 us, a seventh of a short run's
    setup); an object with the ``__wrapper_address__`` protocol hands over the
    address it holds. The loop then calls the solver's C wrapper.
    """

    __slots__ = ("fn", "address")

    def __init__(self, fn):
        self.fn = fn
        self.address = _wrapper_address(fn, SOLVE_SIGNATURE)

    def __wrapper_address__(self):
        return self.address


_SOLVERS = {}


def run_space_loop(*args):
    """:func:`space_loop` with the solver (argument 13) passed as a pointer, not linked in.

    The loop is compiled once for the argument types with the solver typed
    by :data:`SOLVE_SIGNATURE` (from numba's disk cache where it is there):
    once for scenes without contacts between two bodies (``pairs``, argument
    16, None) and once, the bigger loop, for scenes with them.
    """
    # one signature whatever the caller's scalars (an integer t0, a numpy bool)
    args = list(args)
    for i in (3, 4, 5, 11):
        args[i] = float(args[i])
    for i in (6, 7, 14):
        args[i] = int(args[i])
    args[15] = bool(args[15])
    key = args[16] is None
    if key not in _LOOP:
        types = tuple(nbtypes.FunctionType(SOLVE_SIGNATURE) if i == 13 else numba.typeof(a)
                      for i, a in enumerate(args))
        space_loop.disable_compile(False)
        # processes that reach it together compile it once (_jit_cache.compile_lock)
        with _jit_cache.compile_lock(space_loop):
            space_loop.compile(types)
        space_loop.disable_compile()
        # its compiled entry, called directly: the dispatcher would type the solver
        # (a _Solver) as a Python object; the other arguments have the types compiled for
        # (the conversions above)
        _LOOP[key] = space_loop.overloads[types].entry_point
    return _LOOP[key](*args)


_LOOP = {}


@njit(cache=True)
def space_loop(par, mu, e, t0, h, t_bound, k0, nmax, q, v, tables, theta, closed, solve,
               save_every, record_initial, pairs, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
               stats):
    """Up to ``nmax`` Moreau–Jean steps of a spatial scene from ``(q, v)`` at ``t0 + k0 h``.

    ``tables`` is :func:`space_tables`'s tuple, ``closed`` the contacts
    closed in the step before (updated), ``solve`` the cone's solver
    (:func:`space_solver`, called through a pointer), ``pairs`` the scene's
    :meth:`~moreau.model.space.SpaceScene.pair_table` (None without contacts
    between two bodies: numba prunes their branches, and such a scene's loop
    is compiled without them), ``par`` unused (the block runner's
    slot of a compiled model's parameters). The recording buffers and
    ``stats`` are those of every compiled block. Returns ``(status, k,
    nrec)``: ``OK``, :data:`LCP_HANDBACK` (the contact problem of step ``k``
    is left to the Python step, the state is that step's start) or
    :data:`NUMERICAL` (a non-finite state; the last good one is kept).
    """
    bm, bJ, bMinv, bgyro, grav, ct, _, _, D, maxit, d, lever = tables
    nb = bm.shape[0]
    nc = ct.shape[0]
    nv = 6 * nb
    nq = 7 * nb
    ncm = max(nc, 1)
    drilling = False
    for i in range(nc):
        drilling = drilling or lever[i] > 0.0
    R = np.empty((nb, 3, 3))
    R1 = np.empty((nb, 3, 3))
    s = np.empty(3)
    # a contact's rows [n, t1, t2] and, with a patch (lever > 0), its drilling row
    rows = np.zeros((ncm, 4, 6))
    sz = np.empty(ncm, dtype=np.int64)
    st = np.zeros(ncm + 1, dtype=np.int64)
    g0 = np.empty(ncm)
    g1 = np.empty(ncm)
    vN0 = np.empty(ncm)
    f = np.empty(nv)
    vfree = np.empty(nv)
    v1 = np.empty(nv)
    q1 = np.empty(nq)
    fr = np.empty((12, 3))
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    reg = np.zeros(ncm, dtype=np.int64)
    ia = np.empty(ncm, dtype=np.int64)
    MHT = np.empty((4 * ncm, 6))
    Wf = np.empty((4 * ncm, 4 * ncm))
    Uf_all = np.empty(4 * ncm)
    U = np.empty(4)
    mu_all = np.empty(ncm)
    # (the exact cone's Gauss–Seidel takes its scratch from Lemke's: 3 rows a contact)
    Lmax = ncm * max(d + 2, 3)
    Ml = np.zeros((Lmax, Lmax))
    ql = np.zeros(Lmax)
    dl = np.ones(Lmax)
    zl = np.zeros(Lmax)
    wl = np.zeros(Lmax)
    rayl = np.zeros(Lmax + 1)
    work, iwork = lemke_workspace(Lmax)
    qt = np.empty(4)
    if pairs is not None:
        # a pair contact's rows on its body b, their M^-1 H^T columns there, its geometry
        rowsb = np.zeros((ncm, 3, 6))
        MHTb = np.empty((4 * ncm, 6))
        pg = np.empty(18)
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
                    fr[11, a] = hk * f[o + 3 + a]
                _free_rotation(bJ[b], v, o + 3, hk, theta, fr)
                for a in range(3):
                    vfree[o + 3 + a] = fr[0, a]
        for j in range(nv):
            v1[j] = vfree[j]
        na = 0
        for i in range(nc):
            pN[i] = 0.0
            pT[i] = 0.0
            slip[i] = 0.0
            reg[i] = 0
            if pairs is not None and pairs[i, 0] >= 0.0:
                ok, g = _pair_gap(ct, pairs, i, q, R, pg)
                if not ok:
                    # concentric spheres: the Python step raises with its diagnosis
                    status = LCP_HANDBACK
                    break
                g0[i] = g
                _pair_rows(ct, pairs, i, R, pg, rows, rowsb)
            else:
                g0[i] = _gap(ct, i, q, R, s)
                _rows(ct, i, R, s, rows)
            b = int(ct[i, 0])
            sz[i] = 3
            if lever[i] > 0.0:
                _drilling_row(ct, i, R, lever[i], rows)
                sz[i] = 4
            acc = 0.0
            for j in range(6):
                acc += rows[i, 0, j] * v[6 * b + j]
            if pairs is not None and pairs[i, 0] >= 0.0:
                bb = int(pairs[i, 0])
                for j in range(6):
                    acc += rowsb[i, 0, j] * v[6 * bb + j]
            vN0[i] = acc
            if g0[i] + 0.5 * hk * vN0[i] <= 0.0 or closed[i]:
                ia[na] = i
                na += 1
        if pairs is not None and status != OK:
            break
        if na:
            for a in range(na):
                st[a + 1] = st[a] + sz[ia[a]]
            n3 = st[na]
            for a in range(na):
                i = ia[a]
                b = int(ct[i, 0])
                mu_all[a] = mu[i]
                for kk in range(sz[i]):
                    row = st[a] + kk
                    for j in range(6):
                        acc = 0.0
                        for l in range(6):
                            acc += bMinv[b, j, l] * rows[i, kk, l]
                        MHT[row, j] = acc
                    acc = 0.0
                    for j in range(6):
                        acc += rows[i, kk, j] * vfree[6 * b + j]
                    if pairs is not None and pairs[i, 0] >= 0.0:
                        bb = int(pairs[i, 0])
                        for j in range(6):
                            acc2 = 0.0
                            for l in range(6):
                                acc2 += bMinv[bb, j, l] * rowsb[i, kk, l]
                            MHTb[row, j] = acc2
                        for j in range(6):
                            acc += rowsb[i, kk, j] * vfree[6 * bb + j]
                    Uf_all[row] = acc
                Uf_all[st[a]] += e[i] * min(vN0[i], 0.0)
            if pairs is not None:
                # W = H M^-1 H^T by contact pairs, each side on each side of the other where
                # their bodies are one (a half-space contact has one side: pairs[i, 0] < 0)
                for a in range(na):
                    i = ia[a]
                    ai = int(ct[i, 0])
                    bi = int(pairs[i, 0])
                    for c in range(na):
                        ac = int(ct[ia[c], 0])
                        bc = int(pairs[ia[c], 0])
                        for kk in range(sz[i]):
                            for ll in range(sz[ia[c]]):
                                acc = 0.0
                                oc = st[c] + ll
                                if ai == ac:
                                    for j in range(6):
                                        acc += rows[i, kk, j] * MHT[oc, j]
                                if ai == bc:
                                    for j in range(6):
                                        acc += rows[i, kk, j] * MHTb[oc, j]
                                if bi >= 0 and bi == ac:
                                    for j in range(6):
                                        acc += rowsb[i, kk, j] * MHT[oc, j]
                                if bi >= 0 and bi == bc:
                                    for j in range(6):
                                        acc += rowsb[i, kk, j] * MHTb[oc, j]
                                Wf[st[a] + kk, oc] = acc
            else:
                # W = H M^-1 H^T by contact pairs: zero between two bodies' contacts
                for a in range(na):
                    i = ia[a]
                    ba = int(ct[i, 0])
                    for c in range(na):
                        same = ba == int(ct[ia[c], 0])
                        for kk in range(sz[i]):
                            for ll in range(sz[ia[c]]):
                                acc = 0.0
                                if same:
                                    for j in range(6):
                                        acc += rows[i, kk, j] * MHT[st[c] + ll, j]
                                Wf[st[a] + kk, st[c] + ll] = acc
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
            if drilling:
                # the Coulomb–Contensou solver's blocks: its rows' starts, in Lemke's int
                # scratch (which that cone does not use)
                for a in range(na + 1):
                    iwork[a] = st[a]
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
                o = st[a]
                for j in range(6):
                    dv = MHT[o, j] * r[o] + MHT[o + 1, j] * r[o + 1] + MHT[o + 2, j] * r[o + 2]
                    if sz[ia[a]] == 4:
                        dv += MHT[o + 3, j] * r[o + 3]
                    v1[6 * b + j] += dv
                if pairs is not None and pairs[ia[a], 0] >= 0.0:
                    bb = int(pairs[ia[a], 0])
                    for j in range(6):
                        v1[6 * bb + j] += (MHTb[o, j] * r[o] + MHTb[o + 1, j] * r[o + 1]
                                           + MHTb[o + 2, j] * r[o + 2])
            scale = 1e-300
            for a in range(n3):
                scale = max(scale, abs(Uf[a]))
            for a in range(na):
                i = ia[a]
                b = int(ct[i, 0])
                for kk in range(sz[i]):
                    acc = 0.0
                    for j in range(6):
                        acc += rows[i, kk, j] * v1[6 * b + j]
                    if pairs is not None and pairs[i, 0] >= 0.0:
                        bb = int(pairs[i, 0])
                        for j in range(6):
                            acc += rowsb[i, kk, j] * v1[6 * bb + j]
                    U[kk] = acc
                o = st[a]
                pN[i] = r[o]
                pT[i] = math.hypot(r[o + 1], r[o + 2])
                slip[i] = math.hypot(U[1], U[2])
                # a contact slips where its generalized slip (u_T, r* omega_n) does
                moving = slip[i]
                if sz[i] == 4:
                    moving = math.sqrt(U[1] * U[1] + U[2] * U[2] + U[3] * U[3])
                if pN[i] > 0.0:
                    reg[i] = (_POSITIVE if mu[i] > 0.0 and moving > _SLIP_RTOL * scale
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
            if pairs is not None and pairs[i, 0] >= 0.0:
                ok, g = _pair_gap(ct, pairs, i, q1, R1, pg)
                if not ok:
                    status = LCP_HANDBACK
                    break
                g1[i] = g
            else:
                g1[i] = _gap(ct, i, q1, R1, s)
            stats[S_PEN] = max(stats[S_PEN], -g1[i])
        if pairs is not None and status != OK:
            break
        if record_initial:
            nrec = record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                                 nrec, tk, q, v, reg, pN, pT, hk, slip, g0, nc)
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
            nrec = record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                                 nrec, t1, q, v, reg, pN, pT, hk, slip, g1, nc)
        if last:
            break
    return status, k, nrec


#: every source whose compiled code ends up in this module's functions
KERNEL_SOURCES = ((__file__, _cone3d.__file__, _spatial.__file__, _driver.__file__)
                  + _contact_step.KERNEL_SOURCES)

# numba checks a cached kernel against its own file only: tie it to those it links in
CACHE_MODE = _jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    KERNEL_SOURCES)
