"""Lemke's complementary pivoting method with a lexicographic ratio test.

The LCP is: find ``z >= 0`` with ``w = M z + q >= 0`` and ``z.w = 0``.
Lemke's method adds an artificial variable ``z0`` along a covering vector
``d > 0``::

    w - M z - d z0 = q,      w, z, z0 >= 0,      w_i z_i = 0,

starts from the almost-complementary basis where ``z0`` is just large enough
to make ``w >= 0``, and pivots in the complement of whichever variable left,
until ``z0`` leaves (a solution) or the entering column has no positive
entry (a secondary ray).

Implementation
--------------
The work is done by :func:`lemke_core`, compiled with ``numba.njit``, on a
condensed (Tucker) tableau: one row per basic variable, one column per
non-basic variable, ``n x (n + 1)``, with the right-hand side kept apart in
contiguous storage. That is half the columns of the textbook
``[I, -M, -d, q]`` tableau, so half the work per pivot. Rows whose entry in
the pivot column is exactly zero are skipped, which pays on the sparse
friction LCPs.

The ratio test is lexicographic: among rows tied at the minimum ratio it
picks the lexicographic minimum of ``(b_i, (B^-1)_i) / a_i``, reading the rows
of ``B^-1`` from the tableau columns of the original ``w`` variables. If
``z0`` is among the tied rows it leaves at once, which ends the path on a
solution. In exact arithmetic this rule keeps the basis lexicographically
positive and no basis can repeat (Cottle, Pang and Stone 1992, Sec. 4.9).

In floating point a tie can be decided by rounding noise (an exact zero
computed as -5e-15 against another as -1e-16), and a wrong decision can
cycle. So an order is taken from floating point only where it stands above a
rounding bound of the entries, ``ROUND`` (``2^16 eps``, a growth allowance
over many pivots) times the size of each row; an entering-column entry
within that bound of zero is no candidate, and if it could have changed the
step (no other candidate, or a ratio that could undercut the minimum) the
step is not taken in floating point either. Where floating point cannot
decide, and where a basis repeats (the visited bases are hashed past ``2 n +
16`` pivots), :func:`solve` decides that one step in exact arithmetic and goes
back to floating point from the basis reached, on a tableau made afresh from
the data with the right-hand side's exact zeros; a solution reached that way
is the exact point of its basis, correctly rounded. Both are compiled
(:mod:`moreau.lcp._modular`: ``B^-1`` from the ``k x k`` block of the basic
non-``w`` variables, its entries as residues modulo primes below ``2^50``
whose product exceeds Hadamard's bound, signs read after a float filter with a
rigorous error bound); where the moduli cannot hold the numbers, Python's
integers take the step (:func:`moreau.lcp._exact.exact_step`). The whole
path is finished in exact arithmetic only where a hand-over state repeats,
where the basis is not
lexicographically positive for the caller's data (the path then starts
afresh) or too close to singular for floating point to follow; from
``n = 33`` that path is walked one compiled exact step at a time, and the
exact part of a call stops at :data:`EXACT_TIME_BUDGET` CPU seconds with
:data:`MAX_ITER` and a detail naming the budget. The path is
the exact lexicographic one and cannot cycle. One exception, for cost: where
``z0``'s ratio ties another row's within rounding, ``z0`` leaves (the point
is a solution up to rounding, certified on the data as always), where the
exact path might pivot on. The compiled entries
(:func:`lemke_kernel`, :func:`lemke_core`), which have no exact path, count
an undecidable entry as a tie and stop on a repeated basis with
:data:`BREAKDOWN`, never running on to the pivot limit.

Tolerances are relative, so they follow the scale of the data. A pivot
entry counts as positive when it exceeds ``PIVOT_TOL`` times the largest
magnitude in its column; a smaller positive entry is not thrown away (on
badly scaled problems, e.g. a triangular P-matrix whose solution spans
eleven orders of magnitude, it is genuine) but compared with the rounding
level of that entry, ``NOISE_TOL * sum_j |B^-1_ij| |A_ej|`` with ``A_e`` the
entering column of ``[I, -M, -d]``, and kept when it stands above it.
Ratios tie within ``TIE_TOL`` relative difference (the tied rows are then
ordered by the lexicographic test, right-hand sides first), and a
right-hand side that cancels to rounding level is set to exactly zero so
that degenerate rows are recognised as such.

:func:`solve` (and :func:`lemke_kernel`) pivot on balanced data: ``D M D``
and ``D q`` with ``D`` a diagonal of powers of two that brings the rows of
``M`` towards unit size together with their columns (a symmetric scaling
keeps the matrix classes Lemke's theorems need), then both to unit scale.
Powers of two make the maps exact, and ``D`` depends only on the differences
of the rows' exponents, so a problem scaled uniformly by a power of two
pivots bit for bit as the unscaled one; data such as ``diag(1e300, 1e-300)``
come to unit size.

A terminal point is never trusted blindly: ``w = M z + q`` is recomputed from
the *caller's* data (one matrix-vector product) and the violation of
:func:`moreau.lcp.lcp_violation`, whose tolerances are fixed by ``max|q|``
and ``max|M|`` and not by the size of ``z``, must be ``<= tol`` at its worst
over the rounding of that product (a bound ``(n + 2) eps (|M| |z| + |q|)``):
a point whose complementarity rests on cancellation below rounding is not a
solution anyone can check. If the pivoting's own check fails, the basis
found is re-solved directly (``M_JJ z_J = -q_J`` by Gaussian elimination with
partial pivoting) and checked again; if that fails too the status is
:data:`BREAKDOWN`.

A secondary ray is turned into a proof of infeasibility only when a Farkas
vector built from it checks out in exact rational arithmetic on the caller's
data (:func:`moreau.lcp.certify.infeasibility_from_ray`), or a unit vector
``e_i`` is one (``q_i < 0`` and row ``i`` of ``M`` non-positive,
:func:`unit_farkas`): the status is then :data:`INFEASIBLE`, with the Farkas
vector in ``certificate``. Otherwise it stays :data:`SECONDARY_RAY`, which
proves nothing (``"auto"`` goes further: :mod:`moreau.lcp.decide`).

Calling from compiled code
--------------------------
``lemke_kernel`` and ``lemke_core`` are plain ``numba`` functions and can be
called from other ``@njit`` code, e.g. a time-stepping loop::

    status, pivots, residual = lemke_kernel(M, q, z_out, w_out, max_iter, tol)

See their docstrings for the exact argument types.
"""

import math
import time
from fractions import Fraction

import numpy as np
from numba import njit
from scipy.linalg.lapack import dgetrf as _getrf, dgetrs as _getrs

from .. import _jit_cache
from .._validate import finite_array, float_array, positive, positive_int
from ..errors import InputError
from . import _certified, _exact, _modular, certify
from ._certified import farkas_float
from ._certified import residual as _residual
from ._result import lcp_violation
from .certify import FARKAS_TOL, infeasibility_from_ray
from ._result import (
    BREAKDOWN,
    INFEASIBLE,
    INVALID_INPUT,
    MAX_ITER,
    SECONDARY_RAY,
    SOLVED,
    LCPResult,
)

__all__ = [
    "solve",
    "balance",
    "lemke_kernel",
    "lemke_core",
    "lemke_workspace",
    "default_max_iter",
    "SOLVED",
    "SECONDARY_RAY",
    "MAX_ITER",
    "BREAKDOWN",
    "INVALID_INPUT",
    "unit_farkas",
    "PIVOT_TOL",
    "NOISE_TOL",
    "TIE_TOL",
    "DEFAULT_TOL",
    "solve_on_support",
    "SUPPORT_PIVOT_RTOL",
]

#: a pivot-column entry above this times the column's largest magnitude is a
#: candidate without further checks
PIVOT_TOL = 1e-9
#: a smaller positive entry is a candidate when it exceeds this times its
#: rounding scale ``sum_j |B^-1_ij| |A_ej|``
NOISE_TOL = 1e3 * np.finfo(float).eps
#: two ratios tie within this relative difference
TIE_TOL = 1e-9
#: the rounding allowance of a tableau entry, relative to the size of its row
#: (2^16 eps: a growth allowance over many pivots). Two lexicographic entries
#: closer than that are not separated in floating point
ROUND = 2.0**16 * np.finfo(float).eps
# internal statuses: the compiled pivoting hands over to the exact path
_HANDOFF_TIE = 100
_HANDOFF_CYCLE = 101
# internal statuses of the compiled path that allocates nothing (_core): a
# path that needs the hash set of visited bases, or a solution whose residual
# check failed and whose basis must be re-solved, goes on in _continue
_NEED_SEEN = 102
_NEED_REPAIR = 103
# _plain_stage: the data need scaling, nothing was pivoted
_NOT_PLAIN = 104
# _core: start the path from the data (_first_pivot)
_FRESH = 105
# the output buffer of _solve_packed: z, w, the ray (n + 1) and the scaling of a
# hand-over (2 n + 3), _OUT n + 4 floats
_OUT = 5
# slots of the hash set of visited bases (a power of two)
_SEEN_SIZE = 1 << 14
#: default bound on the violation (:func:`moreau.lcp.lcp_violation`) for a
#: result to count as solved
DEFAULT_TOL = 1e-9
#: work budget of the default pivot limit: pivots times n (n + 1) tableau
#: updates, about a second of pivoting
WORK_BUDGET = 2**30

# cancellation below this many ulps of the operands is rounding, not data
_SNAP = 16.0 * np.finfo(float).eps



def default_max_iter(n):
    """Default pivot limit for an LCP of size ``n``.

    ``max(1000, 50 n, min(2^(n+1), 2^30 // (n (n + 1))))``.

    Lemke's method needs ``O(n)`` pivots on practical problems, but
    ``2^n`` on Murty's exponential examples; ``2^(n+1)`` lets those finish
    (n = 12: 8192, n = 16: 131072, n = 20: 2097152). The second term caps
    the work, pivots times the ``n (n + 1)`` tableau entries each one
    updates, at :data:`WORK_BUDGET` = 2^30 (about a second), so that a
    pathological problem cannot hang a time-stepping loop: the bound is
    ``2^(n+1)`` up to n = 20, then falls to ``50 n`` (from n = 278 on).

    Parameters
    ----------
    n : int

    Returns
    -------
    int

    Examples
    --------
    >>> default_max_iter(4), default_max_iter(12), default_max_iter(16), default_max_iter(100)
    (1000, 8192, 131072, 106311)
    """
    n = int(n)
    exp = 2 ** (n + 1) if n < 62 else 2**62
    return max(1000, 50 * n, min(exp, WORK_BUDGET // max(n * (n + 1), 1)))


# the default limits of small sizes, looked up on the per-time-step path
_MAX_ITER_TABLE = tuple(default_max_iter(n) for n in range(512))


@njit(cache=True)
def lemke_workspace(n):
    """Allocate the work arrays of :func:`lemke_core` for size ``n``.

    Returns
    -------
    work : ndarray of float64, shape (n + 3, m)
        ``m`` is ``n + 1`` rounded up to a multiple of 8, so that the row
        updates run in whole SIMD blocks.
    iwork : ndarray of int64, shape (3 n + 1,)
    """
    return np.empty((n + 3, _padded(n))), np.empty(3 * n + 1, dtype=np.int64)


@njit(cache=True)
def _padded(n):
    return ((n + 1 + 7) // 8) * 8


@njit(cache=True, _nrt=False)
def _row_scales(T, b, pos, n, i, qsum):
    # (S, Sb): the size of the entries that make up row i of the tableau (its
    # own entries and its row of B^-1), and that of its right-hand side
    # b_i = (B^-1 q)_i, a sum of terms up to max|B^-1_i| sum|q|
    s = 0.0
    for k in range(n + 1):
        s = max(s, abs(T[i, k]))
    binv = 0.0
    for j in range(n):
        p = pos[j]
        if p >= 0:
            if p == i:
                binv = max(binv, 1.0)
        else:
            binv = max(binv, abs(T[i, -p - 1]))
    return max(s, binv), max(abs(b[i]), binv * qsum)


@njit(cache=True, _nrt=False)
def _lex_compare(T, b, pos, n, i, k, ai, ak, qsum, exact_ok, rhs_only):
    # Compare rows i and k of [b | B^-1] / a lexicographically (with rhs_only,
    # their ratios b / a alone): -1 or 1 when
    # the order stands above the rounding of the entries, 0 when every entry
    # ties, 2 when floating point cannot tell (only with exact_ok; else an
    # undecidable entry counts as a tie, the rounding noise of an exact zero
    # being the usual case). Column j of B^-1 is the current tableau column
    # of the original basic variable w_j: a unit vector if w_j is basic, else
    # its non-basic slot. Cross products (ai, ak > 0) avoid a division per entry.
    si, sbi = _row_scales(T, b, pos, n, i, qsum)
    sk, sbk = _row_scales(T, b, pos, n, k, qsum)
    for j in range(-1, n):
        if j < 0:
            # the right-hand sides: their ratios tie to TIE_TOL, not necessarily exactly
            vi = b[i]
            vk = b[k]
            ei = sbi
            ek = sbk
        else:
            p = pos[j]
            if p >= 0:
                vi = 1.0 if p == i else 0.0
                vk = 1.0 if p == k else 0.0
            else:
                s = -p - 1
                vi = T[i, s]
                vk = T[k, s]
            ei = si
            ek = sk
        xi = vi * ak
        xk = vk * ai
        diff = xi - xk
        # the error of vi ak - vk ai when every entry of a row is off by ROUND
        # times its row's scale
        bound = ROUND * (ei * ak + abs(vi) * sk + ek * ai + abs(vk) * si)
        if abs(diff) > bound:
            return -1 if diff < 0.0 else 1
        if diff != 0.0 and exact_ok:
            return 2
        if rhs_only:
            return 0
    return 0


@njit(cache=True, inline="always")
def _key(v):
    # a 64-bit mix of a variable's number (splitmix64's finaliser, wrapping
    # int64 arithmetic): XORed over the basis it identifies a basis
    x = (v + 1) * -7046029254386353131
    x ^= (x >> 30) & 0x3FFFFFFFF
    x *= -4658895280553007687
    x ^= (x >> 27) & 0x1FFFFFFFFF
    x *= -7723592293110705685
    return x ^ ((x >> 31) & 0x1FFFFFFFF)


@njit(cache=True, _nrt=False)
def _pivot(T, b, col, n, r, s):
    # Exchange the basic variable of row r with the non-basic one of slot s
    # in the condensed tableau x_B + T[:n, :n+1] x_N = b; col holds T[:n, s].
    # Columns past n are zero padding, updated along (0 - f*0) so that the
    # inner loop has no scalar remainder.
    ncol = T.shape[1]
    inv = 1.0 / col[r]
    prow = T[n]  # scratch row: keeps the pivot row apart from the rows it updates
    for k in range(ncol):
        prow[k] = T[r, k] * inv
    prow[s] = inv
    b_r = b[r] * inv
    for i in range(n):
        f = col[i]
        if f == 0.0 or i == r:
            continue
        row = T[i]
        for k in range(ncol):
            row[k] -= f * prow[k]
        row[s] = -f * inv
        b_old = b[i]
        fb = f * b_r
        b_new = b_old - fb
        # a RHS that cancels to rounding level is a degenerate zero: make it
        # exact so that ties are seen as ties. A negative value is rounding
        # or a tolerance-level tie resolved the other way: the ratio test
        # keeps b >= 0.
        if b_new < 0.0 or abs(b_new) <= _SNAP * (abs(b_old) + abs(fb)):
            b_new = 0.0
        b[i] = b_new
    for k in range(ncol):
        T[r, k] = prow[k]
    b[r] = b_r


@njit(cache=True, inline="always")
def _write_ray(col, pos, n, entering, ray_out):
    # the secondary ray along the entering column col: the entering variable +1,
    # each basic z_j and z0 (ray_out[n]) moving by minus its row's entry
    for j in range(n):
        p = pos[n + j]
        if p >= 0:
            ray_out[j] = -col[p]
        elif n + j == entering:
            ray_out[j] = 1.0
    ray_out[n] = -col[pos[2 * n]]


@njit(cache=True, inline="always")
def _views(work, iwork, n):
    # the path's arrays in the workspace: the tableau T, the right-hand side b,
    # the entering column col, the basis and pos (see _core)
    return work, work[n + 1], work[n + 2], iwork[:n], iwork[n:]


@njit(cache=True, inline="always")
def _scales(M, q, n):
    # max|M_ij|, max|q_i| and sum |q_i|
    mmax = 0.0
    qmax = 0.0
    qsum = 0.0
    for i in range(n):
        for j in range(n):
            mmax = max(mmax, abs(M[i, j]))
        qmax = max(qmax, abs(q[i]))
        qsum += abs(q[i])
    return mmax, qmax, qsum


@njit(cache=True, inline="always")
def _start_tableau(M, q, d, T, b, basis, pos, n, ncol):
    # the tableau [-M | -d | 0] with right-hand side q and every w basic: w_j in row j,
    # z_j and z0 in the slots 1 .. n + 1 of the nonbasic (see _core's `pos`)
    for i in range(n):
        for j in range(n):
            T[i, j] = -M[i, j]
        T[i, n] = -d[i]
        for j in range(n + 1, ncol):
            T[i, j] = 0.0
        b[i] = q[i]
        basis[i] = i
        pos[i] = i
        pos[n + i] = -(i + 1)
    pos[2 * n] = -(n + 1)


@njit(cache=True, _nrt=False)
def _copy_into(dst, src):
    # an explicit loop: a slice assignment (dst[:] = src) makes numba compile its
    # shape-mismatch error path, about 3 s of every cold start
    for k in range(dst.shape[0]):
        dst[k] = src[k]


@njit(cache=True, _nrt=False)
def _extract_z(b, pos, n, z_out):
    for j in range(n):
        p = pos[n + j]
        z_out[j] = b[p] if p >= 0 else 0.0


@njit(cache=True, inline="always")
def eliminate(A, x, s, rtol, atol, pcol, sol, cols):
    """Solve the ``s x s`` system ``A y = x`` by Gaussian elimination with partial pivoting.

    A column whose best pivot is not above ``rtol`` times the column's
    largest entry (before elimination, so that the test does not depend on
    the units of one unknown), nor above ``atol``, has no pivot: its unknown
    is set to zero, a vertex of the solution set where the system is
    singular but consistent.
    ``A`` and ``x`` are overwritten; ``pcol`` receives each pivot row's
    column. Writes ``sol[cols[c]] = y[c]`` and returns the number of pivots
    (``s`` when the system is regular).
    """
    prow = 0
    for c in range(s):
        cmax = 0.0
        for a in range(s):
            cmax = max(cmax, abs(A[a, c]))
        piv = prow
        best = 0.0
        for r in range(prow, s):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                piv = r
        thr = rtol * cmax
        if atol > thr:
            thr = atol
        # `not >` takes NaN as no pivot too
        if not best > thr:
            continue
        if piv != prow:
            for j in range(s):
                tmp = A[prow, j]
                A[prow, j] = A[piv, j]
                A[piv, j] = tmp
            tmp = x[prow]
            x[prow] = x[piv]
            x[piv] = tmp
        for r in range(prow + 1, s):
            fct = A[r, c] / A[prow, c]
            if fct != 0.0:
                for j in range(c + 1, s):
                    A[r, j] -= fct * A[prow, j]
                x[r] -= fct * x[prow]
        pcol[prow] = c
        prow += 1
    for c in range(s):
        sol[cols[c]] = 0.0
    for r in range(prow - 1, -1, -1):
        c = pcol[r]
        acc = x[r]
        for j in range(c + 1, s):
            acc -= A[r, j] * sol[cols[j]]
        sol[cols[c]] = acc / A[r, c]
    return prow


@njit(cache=True)
def _resolve_basis(M, q, pos, n, z_out):
    # Re-solve the terminal complementary basis directly: with J the basic
    # z variables, M_JJ z_J = -q_J. Rounding accumulated over many pivots is
    # gone after this; returns False when M_JJ is numerically singular (z_out
    # is then partly written: the caller keeps its own copy).
    J = np.empty(n, dtype=np.int64)
    m = 0
    for j in range(n):
        if pos[n + j] >= 0:
            J[m] = j
            m += 1
    A = np.empty((m, m))
    x = np.empty(m)
    for a in range(m):
        x[a] = -q[J[a]]
        for c in range(m):
            A[a, c] = M[J[a], J[c]]
    amax = 0.0
    for a in range(m):
        for c in range(m):
            amax = max(amax, abs(A[a, c]))
    for j in range(n):
        z_out[j] = 0.0
    pcol = np.empty(m, dtype=np.int64)
    return eliminate(A, x, m, 0.0, 1e3 * np.finfo(np.float64).eps * amax, pcol, z_out, J) == m


@njit(cache=True, _nrt=False)
def _noise_scale(T, pos, M, d, n, i, entering):
    # sum_j |B^-1_ij| |A_ej|: the size of the terms that make up entry i of
    # the entering column B^-1 A_e, hence the scale of its rounding error.
    # When a slack w_k enters, A_e = e_k and that sum is the entry itself,
    # B^-1_ik, which measures nothing: an exact zero that pivoting left at
    # 1e-17 would pass as genuine. The entry was then formed by eliminations
    # on row i of B^-1, so its rounding is relative to that row's size.
    acc = 0.0
    rowmax = 0.0
    for j in range(n):
        p = pos[j]
        if p >= 0:
            if p != i:
                continue
            bij = 1.0
        else:
            bij = abs(T[i, -p - 1])
        if bij > rowmax:
            rowmax = bij
        if entering < n:
            aej = 1.0 if j == entering else 0.0
        elif entering < 2 * n:
            aej = abs(M[j, entering - n])
        else:
            aej = d[j]
        acc += bij * aej
    if entering < n:
        acc = rowmax
    # the entry itself was made by eliminations on the whole tableau row:
    # its rounding is relative to the largest entry of that row too
    for k in range(n + 1):
        t = abs(T[i, k])
        if t > acc:
            acc = t
    return acc


@njit(cache=True, inline="always")
def lemke_core(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter, tol):
    """Lemke's method on preallocated arrays (compiled; callable from ``@njit`` code).

    Parameters
    ----------
    M : float64[:, :], shape (n, n)
    q : float64[:], shape (n,)
    d : float64[:], shape (n,)
        Covering vector, all entries finite and > 0 (``np.ones(n)`` is usual).
    z_out, w_out : float64[:], shape (n,)
        Receive ``z`` and ``w = M z + q``; finite on every status.
    ray_out : float64[:], shape (n + 1,)
        On :data:`SECONDARY_RAY`, the ray direction ``(dz, dz0)``; zero otherwise.
    work : float64[:, :], shape (n + 3, m) with ``m >= n + 1``
        Tableau, right-hand side and scratch storage, overwritten;
        :func:`lemke_workspace` allocates it with ``m`` padded for SIMD.
    iwork : int64[:], shape (3 n + 1,)
        Basis bookkeeping, overwritten.
    max_iter : int
        Pivot limit, counting the first pivot on ``z0``.
    tol : float
        Bound on the violation (:func:`moreau.lcp.lcp_violation`) for the
        result to count as solved.

    Returns
    -------
    status : int
        :data:`SOLVED` (0), :data:`SECONDARY_RAY` (1; the kernel does not
        tell a proof of infeasibility from a failure, see
        :func:`moreau.lcp.certify.infeasibility_from_ray`), :data:`MAX_ITER` (2),
        :data:`BREAKDOWN` (3) or :data:`INVALID_INPUT` (4: NaN or inf in
        ``M`` or ``q``, a covering entry that is not finite and > 0, or a
        workspace that is too small; ``z_out`` and ``w_out`` are then zero).
    pivots : int
        Pivots performed (0 when ``q >= 0``).
    residual : float
        Violation of ``z_out``; ``inf`` on :data:`INVALID_INPUT`.

    Notes
    -----
    The arrays are not checked for shape beyond the workspace: ``M`` must
    be ``n x n`` and the output vectors at least ``n`` (``n + 1``) long.
    """
    status, pivots, residual = _start(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter, tol,
                                      np.bool_(False))
    if status == _NEED_SEEN or status == _NEED_REPAIR:
        status, pivots, residual = _continue(M, q, d, z_out, w_out, ray_out, work, iwork,
                                             max_iter, tol, np.bool_(False), status, pivots,
                                             residual)
    return status, pivots, residual


@njit(cache=True, inline="always")
def _start(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter, tol, exact_ok):
    # _core from the data. np.int64, not the constants: literal arguments
    # would type (and compile) a second _core
    return _core(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter, tol, exact_ok, iwork[:1],
                 np.int64(0), np.int64(0), np.int64(_FRESH))


# _core, _first_pivot and _core_resume allocate nothing and are compiled without numba's
# reference counting (_nrt=False): on a small LCP the atomic increments and
# decrements of the arrays passed and viewed cost more than the pivoting. A
# function compiled so may only call functions that allocate nothing either;
# what needs memory (the hash set of a long path, the re-solve of a basis)
# returns _NEED_SEEN or _NEED_REPAIR to _continue, which its callers run
@njit(cache=True, _nrt=False)
def _core(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter, tol, exact_ok, seen, pivots,
          entering, status):
    # lemke_core (the public entry documents it), as Lemke's path to its end.
    # With status _FRESH, from the data (_start, _first_pivot); else from the
    # tableau and basis in work and iwork (_views), `pivots` made, with
    # `entering` to enter next, status MAX_ITER (another status: the path has
    # ended already, only the terminal point is made; _core_resume's modes).
    # One function for every start: numba optimises and compiles the code of a
    # callee again in each caller up the chain, so the path is in one library.
    # With exact_ok, a tie that floating point cannot decide, or a repeated
    # basis, returns _HANDOFF_TIE or _HANDOFF_CYCLE with the basis in
    # ray_out[:n] and the entering variable in ray_out[n], for the exact path
    # (_exact.exact_lemke) to go on from; without it (compiled callers) an
    # undecidable entry counts as a tie and a repeated basis is BREAKDOWN,
    # never a run to max_iter. `seen` is the hash set of visited states
    # (_SEEN_SIZE zeros), or of length 1 when none is allocated yet: the path
    # then returns _NEED_SEEN, with `entering` in ray_out[n], when its watch begins
    n = q.shape[0]
    if status == _FRESH:
        status, entering, mmax, qmax, qsum = _first_pivot(M, q, d, z_out, w_out, ray_out, work,
                                                          iwork)
        if status != MAX_ITER:
            return status, np.int64(0), np.inf if status == INVALID_INPUT else 0.0
        pivots = np.int64(1)
    else:
        mmax, qmax, qsum = _scales(M, q, n)
    T, b, col, basis, pos = _views(work, iwork, n)
    z0 = 2 * n
    # (basis, entering) identified by the XOR of its variables' keys: an exact
    # lexicographic path never repeats one, so a repeat is rounding having
    # decided a tie wrongly. Past 2 n + 16 pivots of a run (a path that long
    # is rare outside exponential examples) the states go into a hash set; when
    # it is three-quarters full it is cleared, and a loop is caught on its next round
    hb = 0
    for i in range(n):
        hb ^= _key(basis[i])
    nseen = 0
    # a set handed in (by _continue) is fresh: the watch goes on at once
    watch = 2 * n + 15 + pivots if seen.shape[0] == 1 else pivots

    while status == MAX_ITER and pivots < max_iter:
        if pivots >= watch:
            if seen.shape[0] == 1:
                ray_out[n] = entering
                return _NEED_SEEN, pivots, np.inf
            if 4 * nseen >= 3 * seen.shape[0]:
                for k in range(seen.shape[0]):
                    seen[k] = 0
                nseen = 0
            state = hb ^ _key(entering + 3 * n)
            if state == 0:
                state = 1
            h = state & (_SEEN_SIZE - 1)
            while seen[h] != 0 and seen[h] != state:
                h = (h + 1) & (_SEEN_SIZE - 1)
            if seen[h] == state:
                status = _HANDOFF_CYCLE if exact_ok else BREAKDOWN
                break
            seen[h] = state
            nseen += 1
        s = -pos[entering] - 1
        # -- ratio test over rows with a clearly positive pivot-column entry;
        # the column is gathered once into contiguous storage
        cmax = 0.0
        for i in range(n):
            a = T[i, s]
            col[i] = a
            if abs(a) > cmax:
                cmax = abs(a)
        if not cmax < np.inf:
            status = BREAKDOWN
            break
        thr = PIVOT_TOL * cmax
        theta = np.inf
        nunc = 0
        unc = T[n]  # scratch row until the pivot: the rounding bound of each uncertain entry
        for i in range(n):
            a = col[i]
            unc[i] = 0.0
            if exact_ok and a != 0.0 and abs(a) <= thr:
                # an entry within the rounding bound of its row may be an exact
                # zero or of either sign: no candidate here; whether it could
                # change the outcome is judged once theta is known
                si, _ = _row_scales(T, b, pos, n, i, qsum)
                if abs(a) <= ROUND * si:
                    unc[i] = ROUND * si
                    nunc += 1
                    continue
            if a > 0.0 and a <= thr:
                # small: keep it only if it stands above its rounding level;
                # otherwise it is rounding of a zero, and becomes one (in the
                # tableau too, so that the elimination agrees)
                if not a > NOISE_TOL * _noise_scale(T, pos, M, d, n, i, entering):
                    col[i] = 0.0
                    T[i, s] = 0.0
                    a = 0.0
            if a > 0.0:
                t = b[i] / a
                if t < theta:
                    theta = t
        if nunc > 0:
            # an uncertain entry a_i in (0, u_i] would have the ratio b_i / a_i >=
            # b_i / u_i: it can change the step only where that is not above theta
            # (or where there is no other candidate: the ray would rest on it)
            for i in range(n):
                u = unc[i]
                if u > 0.0:
                    _, sbi = _row_scales(T, b, pos, n, i, qsum)
                    if theta == np.inf or b[i] <= theta * u + ROUND * sbi:
                        status = _HANDOFF_TIE
                        break
            if status == _HANDOFF_TIE:
                break
        if theta == np.inf:
            # secondary ray: entering variable +1, basic ones move by -a_i
            _write_ray(col, pos, n, entering, ray_out)
            status = SECONDARY_RAY
            break
        lim = theta + TIE_TOL * abs(theta)
        r = np.int64(-1)  # not a literal (see the first pivot)
        nties = 0
        for i in range(n):
            a = col[i]
            if a > 0.0 and unc[i] == 0.0 and b[i] / a <= lim:
                nties += 1
                if r < 0:
                    r = i
        if nties > 1:
            zrow = pos[z0]
            a_z = col[zrow]
            z0_tied = a_z > 0.0 and unc[zrow] == 0.0 and b[zrow] / a_z <= lim
            if z0_tied and exact_ok:
                # z0 does not leave where its ratio stands above another tied
                # row's beyond rounding (a tie of TIE_TOL only). Within rounding
                # it leaves: the point then solves the LCP up to rounding and is
                # certified on the data like any other (an exact path would cost
                # a friction LCP of n = 100 seconds, for a rounding-level step)
                for i in range(n):
                    a = col[i]
                    if i != zrow and a > 0.0 and unc[i] == 0.0 and b[i] / a <= lim:
                        c = _lex_compare(T, b, pos, n, zrow, i, a_z, a, qsum, exact_ok, np.True_)
                        if c == 1:
                            z0_tied = False
                            break
            if z0_tied:
                # z0 can leave now: take the solution
                r = zrow
            else:
                best = r
                unresolved = False
                undecided = False
                for i in range(r + 1, n):
                    a = col[i]
                    if a > 0.0 and unc[i] == 0.0 and b[i] / a <= lim:
                        c = _lex_compare(T, b, pos, n, i, best, a, col[best], qsum, exact_ok,
                                         np.False_)
                        if c == 2:
                            undecided = True
                            break
                        if c < 0:
                            best = i
                            unresolved = False
                        elif c == 0:
                            unresolved = True
                if undecided:
                    status = _HANDOFF_TIE
                    break
                if unresolved:
                    status = BREAKDOWN
                    break
                r = best
        _pivot(T, b, col, n, r, s)
        pivots += 1
        leaving = basis[r]
        basis[r] = entering
        pos[entering] = r
        pos[leaving] = -(s + 1)
        hb ^= _key(leaving) ^ _key(entering)
        if leaving == z0:
            status = SOLVED
            break
        entering = leaving + n if leaving < n else leaving - n

    if status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
        for i in range(n):
            ray_out[i] = basis[i]
            z_out[i] = 0.0
            w_out[i] = q[i]
        ray_out[n] = entering
        return status, pivots, np.inf
    _extract_z(b, pos, n, z_out)
    for j in range(n):
        if not abs(z_out[j]) < np.inf:
            # overflow somewhere in the tableau: report a finite point
            for k in range(n):
                z_out[k] = 0.0
            status = BREAKDOWN
            break
    residual = _residual(M, q, z_out, w_out, mmax, qmax)
    if status == SOLVED and not residual <= tol:
        # accumulated rounding: _continue re-solves the terminal basis from the data
        return _NEED_REPAIR, pivots, residual
    if not residual < np.inf:
        for k in range(n):
            z_out[k] = 0.0
        residual = _residual(M, q, z_out, w_out, mmax, qmax)
    return status, pivots, residual


@njit(cache=True, _nrt=False)
def _first_pivot(M, q, d, z_out, w_out, ray_out, work, iwork):
    # _core's start from the data: checks them (INVALID_INPUT, z = w = 0),
    # answers q >= 0 (SOLVED, z = 0, w = q), else makes the tableau and its
    # first pivot, on z0 (MAX_ITER: the path goes on with `entering`); returns
    # (status, entering, max|M|, max|q|, sum|q|)
    n = q.shape[0]
    for k in range(n + 1):
        ray_out[k] = 0.0
    # -- data scale and validity (NaN fails every comparison, so test with `not`)
    mmax = 0.0
    for i in range(n):
        for j in range(n):
            a = abs(M[i, j])
            if not a < np.inf:
                for k in range(n):
                    z_out[k] = 0.0
                    w_out[k] = 0.0
                return INVALID_INPUT, 0, 0.0, 0.0, 0.0
            if a > mmax:
                mmax = a
    qmax = 0.0
    qsum = 0.0
    qmin = np.inf
    for i in range(n):
        if not abs(q[i]) < np.inf or not (d[i] > 0.0 and d[i] < np.inf):
            for k in range(n):
                z_out[k] = 0.0
                w_out[k] = 0.0
            return INVALID_INPUT, 0, 0.0, 0.0, 0.0
        qmax = max(qmax, abs(q[i]))
        qsum += abs(q[i])
        qmin = min(qmin, q[i])
    if n == 0 or qmin >= 0.0:
        for k in range(n):
            z_out[k] = 0.0
            w_out[k] = q[k]
        return SOLVED, 0, 0.0, 0.0, 0.0

    # pos[var] = row if basic, else -(slot + 1); variables: w_j -> j,
    # z_j -> n + j, z0 -> 2n
    T, b, col, basis, pos = _views(work, iwork, n)
    ncol = T.shape[1]
    if ncol < n + 1 or T.shape[0] < n + 3 or iwork.shape[0] < 3 * n + 1:
        for k in range(n):
            z_out[k] = 0.0
            w_out[k] = 0.0
        return INVALID_INPUT, 0, 0.0, 0.0, 0.0
    _start_tableau(M, q, d, T, b, basis, pos, n, ncol)
    for i in range(n):
        col[i] = -d[i]
    z0 = 2 * n

    # -- first pivot: z0 enters at the lexicographic minimum of (q_i, e_i)/d_i.
    # With B^-1 = I, of two rows tied in q_i/d_i the one with the larger
    # index is lexicographically smaller (its unit entry comes later), so a
    # forward scan keeps the last of the tied rows.
    r = np.int64(0)  # not a literal: it would type (and compile) _pivot a second time
    rr = q[0] / d[0]
    for i in range(1, n):
        ri = q[i] / d[i]
        if ri <= rr + TIE_TOL * max(abs(ri), abs(rr)):
            r = i
            rr = min(ri, rr)
    _pivot(T, b, col, n, r, n)
    leaving = basis[r]
    basis[r] = z0
    pos[z0] = r
    pos[leaving] = -(n + 1)
    entering = leaving + n  # complement of w_r is z_r
    return MAX_ITER, entering, mmax, qmax, qsum


@njit(cache=True, inline="always")
def _continue(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter, tol, exact_ok, status,
              pivots, residual):
    # the rest of a path _core or _core_resume handed back (_NEED_SEEN: the
    # path goes on with a hash set of visited states; _NEED_REPAIR: the
    # solution's basis is re-solved from the data), with the tableau, basis
    # and outputs where they left them
    n = q.shape[0]
    if status == _NEED_SEEN:
        seen = np.zeros(_SEEN_SIZE, dtype=np.int64)
        entering = np.int64(ray_out[n])
        # the ray stays zero unless the path ends on one
        ray_out[n] = 0.0
        status, pivots, residual = _core(M, q, d, z_out, w_out, ray_out, work, iwork, max_iter,
                                         tol, exact_ok, seen, np.int64(pivots), entering,
                                         np.int64(MAX_ITER))
    if status == _NEED_REPAIR:
        mmax, qmax, _ = _scales(M, q, n)
        pos = iwork[n:]
        status = SOLVED
        zsave = z_out.copy()
        wsave = w_out.copy()
        ok = _resolve_basis(M, q, pos, n, z_out)
        res2 = _residual(M, q, z_out, w_out, mmax, qmax) if ok else np.inf
        if ok and res2 <= tol:
            residual = res2
        else:
            _copy_into(z_out, zsave)
            _copy_into(w_out, wsave)
            status = BREAKDOWN
        if not residual < np.inf:
            for k in range(n):
                z_out[k] = 0.0
            residual = _residual(M, q, z_out, w_out, mmax, qmax)
    return status, pivots, residual


# modes of _core_resume: go on along the path, the basis is the solution's
# (z0 has left), or the entering variable has no positive entry (a ray)
_RESUME_PATH = 0
_RESUME_SOLVED = 1
_RESUME_RAY = 2
# a basis whose float tableau takes a pivot below this times its column is too
# close to singular for floating point to follow: the exact path takes the next step
_REBUILD_TOL = 1e-8


@njit(cache=True, _nrt=False)
def _core_resume(M, q, d, z_out, w_out, ray_out, work, iwork, start):
    # The start of Lemke's path on (M, q, d) from a basis the exact path
    # (moreau.lcp._exact.exact_step) has decided: start = (basis of each row
    # (n), entering variable, mode, pivots made, the basis's right-hand side
    # row by row (n), exactly rounded), all floats. The tableau of that basis
    # is made afresh from the data, by
    # pivoting its non-w variables in from the all-w basis (partial pivoting
    # among the rows whose w must leave), so that the rounding of the path
    # before the hand-over is gone, and takes the exact right-hand side (its
    # zeros are the degenerate rows, its order that of the exact path).
    # Returns (status, pivots, residual, entering) for _core to go on from, by
    # mode: along the path (_RESUME_PATH: MAX_ITER), to the basis's point as the
    # answer (_RESUME_SOLVED: SOLVED), or to the secondary ray of the entering
    # column (_RESUME_RAY: SECONDARY_RAY, the ray written). A basis too close
    # to singular for floating point (a pivot below _REBUILD_TOL times its
    # column) is handed back at once (_HANDOFF_TIE, or BREAKDOWN outside
    # _RESUME_PATH; final): the exact path decides its step too. The data are
    # finite (the hand-over came from _core).
    n = q.shape[0]
    for k in range(n + 1):
        ray_out[k] = 0.0
    T, b, col, basis, pos = _views(work, iwork, n)
    ncol = T.shape[1]
    _start_tableau(M, q, d, T, b, basis, pos, n, ncol)
    # the w of row i leaves (its row takes a non-w variable) when w_i is not in the target
    # basis; ray_out[:n] marks those rows while the tableau is built
    for i in range(n):
        ray_out[i] = 1.0
    for i in range(n):
        v = int(start[i])
        if v < n:
            ray_out[v] = 0.0
    for t in range(n):
        v = int(start[t])
        if v < n:
            continue
        s = -pos[v] - 1
        cmax = 0.0
        r = np.int64(-1)  # not a literal (see _first_pivot)
        best = 0.0
        for i in range(n):
            a = T[i, s]
            col[i] = a
            cmax = max(cmax, abs(a))
            if ray_out[i] != 0.0 and basis[i] < n and abs(a) > best:
                best = abs(a)
                r = i
        if r < 0 or not best > _REBUILD_TOL * cmax:
            status = _HANDOFF_TIE
            if start[n + 1] != _RESUME_PATH:
                status = BREAKDOWN
            for i in range(n):
                ray_out[i] = start[i]
                z_out[i] = 0.0
                w_out[i] = q[i]
            ray_out[n] = start[n]
            return status, np.int64(start[n + 2]), np.inf, np.int64(0)
        _pivot(T, b, col, n, r, s)
        leaving = basis[r]
        basis[r] = v
        pos[v] = r
        pos[leaving] = -(s + 1)
        ray_out[r] = 0.0
    for i in range(n + 1):
        ray_out[i] = 0.0
    # the rows were filled in another order than start's: match them by variable.
    # A NaN (the compiled exact step, _modular.modular_step) marks a right-hand
    # side known to be positive but not given: it is (B^-1 q)_i from the
    # tableau's columns of B^-1 (those of the w's), since the b pivoted along
    # above was cut to zero wherever an intermediate basis made it negative
    for t in range(n):
        i = pos[int(start[t])]
        if not np.isnan(start[n + 3 + t]):
            b[i] = start[n + 3 + t]
            continue
        acc = 0.0
        for j in range(n):
            p = pos[j]
            if p < 0:
                acc += T[i, -p - 1] * q[j]
            elif p == i:
                acc += q[j]
        b[i] = max(acc, 0.0)
    entering = int(start[n])
    mode = int(start[n + 1])
    status = MAX_ITER
    if mode == _RESUME_SOLVED:
        status = SOLVED
    elif mode == _RESUME_RAY:
        s = -pos[entering] - 1
        for i in range(n):
            col[i] = T[i, s]
        _write_ray(col, pos, n, entering, ray_out)
        status = SECONDARY_RAY
    return np.int64(status), np.int64(start[n + 2]), np.inf, np.int64(entering)


@njit(cache=True)
def lemke_kernel(M, q, z_out, w_out, max_iter, tol):
    """Lemke's method with covering vector ``d = 1`` (compiled; callable from ``@njit`` code).

    Allocates its own workspace, and brings data whose largest entry lies
    outside ``[2^-64, 2^64]`` (e.g. subnormal numbers, on which the
    tableau's arithmetic keeps only a few bits) to unit scale by exact
    powers of two first; use :func:`lemke_core`, which does neither, in
    tight loops that reuse one workspace on data of sane scale.

    Parameters
    ----------
    M : float64[:, :], shape (n, n)
    q : float64[:], shape (n,)
    z_out, w_out : float64[:], shape (n,)
        Receive ``z`` and ``w = M z + q``.
    max_iter : int
        Pivot limit.
    tol : float
        Bound on the violation for a solved status.

    Returns
    -------
    status : int
        As for :func:`lemke_core`, except that a secondary ray whose ``dz``
        is a Farkas vector (``dz >= 0``, ``M^T dz <= 0``, ``q.dz < 0``, to
        :data:`moreau.lcp.certify.FARKAS_TOL`) comes back as
        :data:`INFEASIBLE` (7): a proof that the LCP has no solution.
    pivots : int
    residual : float
        As for :func:`lemke_core`.
    """
    n = q.shape[0]
    out = np.empty(_OUT * n + 4)
    fbuf = np.empty(_fbuf_size(n))
    ibuf = np.empty(4 * n + 1, dtype=np.int64)
    d = fbuf[_fbuf_size(n) - n:]
    for i in range(n):
        d[i] = 1.0
    status, pivots, residual = _solve_buffers(M, q, d, out, fbuf, ibuf, max_iter, tol,
                                              np.bool_(False), np.bool_(False))
    for i in range(n):
        z_out[i] = out[i]
        w_out[i] = out[n + i]
    return status, pivots, residual




@njit(cache=True, _nrt=False)
def balance(M, q, sexp):
    """Power-of-two balancing of ``LCP(M, q)`` (compiled; callable from Python).

    Fills ``sexp`` with exponents ``s`` of ``D = diag(2^s)`` and returns
    ``(ok, ka, kb)``: the LCP ``(2^ka D M D, 2^kb D q)`` has its largest
    entries in ``[0.5, 1)`` and the solutions ``2^(kb-ka) D^-1 z``. Row and
    column ``i`` scale together, which keeps the matrix classes Lemke's
    theorems need (PSD, copositive-plus, P); ``D`` brings the diagonal of
    ``M`` towards one (a row with a zero diagonal entry: its largest entry),
    so ``diag(1e300, 1e-300)`` becomes the identity and a PSD matrix has
    entries of at most about one. ``s`` depends only on the differences of the exponents:
    a uniform power-of-two scaling of ``M`` leaves it unchanged and the
    balanced problem bit for bit the same. ``ok`` is False when the data
    hold NaN or inf.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.zeros(2, dtype=np.int64)
    >>> ok, ka, kb = balance(np.diag([1e300, 1e-300]), np.array([-1.0, -1.0]), s)
    >>> Mb = np.ldexp(np.diag([1e300, 1e-300]), s[:, None] + s[None, :] + ka)
    >>> ok, bool(0.25 <= Mb.diagonal().min() and Mb.max() < 1.0)
    (True, True)
    """
    n = q.shape[0]
    emin = 1 << 30
    for i in range(n):
        rmax = 0.0
        for j in range(n):
            a = abs(M[i, j])
            if not a < np.inf:
                return False, 0, 0
            if a > rmax:
                rmax = a
        if not abs(q[i]) < np.inf:
            return False, 0, 0
        # the diagonal sets the scale where it is there (D M D then has a unit
        # diagonal, and a PSD M entries of at most 1); a row without one, its
        # largest entry
        a = abs(M[i, i]) if M[i, i] != 0.0 else rmax
        e = math.frexp(a)[1] if a > 0.0 else (1 << 30)
        sexp[i] = e
        if e < emin:
            emin = e
    any_row = False
    for i in range(n):
        # a zero row keeps its scale; the others shrink by half their excess
        # (an excess below 2^_ROW_EXCESS is left alone: it costs nothing to pivot on)
        ex = 0 if sexp[i] == (1 << 30) else sexp[i] - emin
        sexp[i] = -(ex // 2) if ex >= _ROW_EXCESS else 0
        any_row = any_row or sexp[i] != 0
    mmax = 0.0
    qmax = 0.0
    for i in range(n):
        qmax = max(qmax, abs(_times_pow2(q[i], sexp[i])))
        for j in range(n):
            a = abs(M[i, j]) if not any_row else abs(_times_pow2(M[i, j], sexp[i] + sexp[j]))
            if a > mmax:
                mmax = a
    ka = -math.frexp(mmax)[1] if mmax > 0.0 else 0
    kb = -math.frexp(qmax)[1] if qmax > 0.0 else 0
    return True, ka, kb


# 2^k as floats for |k| <= 1000: a multiplication by an exact power of two is
# exact (barring underflow) and far cheaper than ldexp in the O(n^2) loops
_POW2 = np.ldexp(1.0, np.arange(-1000, 1001))
# data whose normalising exponents lie within this range are pivoted on as given
_PLAIN_RANGE = 20
# rows whose scale exceeds the smallest row's by less than 2^this are not rescaled
_ROW_EXCESS = 10


@njit(cache=True, inline="always")
def _times_pow2(x, k):
    if -1000 <= k <= 1000:
        y = x * _POW2[k + 1000]
        # a subnormal product has lost bits: ldexp rounds it once, as scaling should
        if y == 0.0 or abs(y) >= 2.2250738585072014e-308:
            return y
    return math.ldexp(x, k)


@njit(cache=True, _nrt=False)
def _balance_rows_to_q(M, q, rexp, cexp):
    # the second balancing, for when the symmetric one leaves a row's q far
    # below the others (diag(1e300, 1e-300), q = (-1, -1): D q = (-1e-300, -1),
    # and the tiny component is lost to the tolerance of the balanced data).
    # Rows are scaled by their q (by their largest entry where q_i = 0), then
    # columns by their largest entry: LCP(R M C, R q) has the solutions
    # C^-1 z. It keeps P-matrices but not PSD, so it comes second.
    n = q.shape[0]
    for i in range(n):
        a = abs(q[i])
        if a == 0.0:
            for j in range(n):
                a = max(a, abs(M[i, j]))
        rexp[i] = -math.frexp(a)[1] if a > 0.0 else 0
    for j in range(n):
        a = 0.0
        for i in range(n):
            a = max(a, abs(_times_pow2(M[i, j], rexp[i])))
        cexp[j] = -math.frexp(a)[1] if a > 0.0 else 0
    return _unit_exponents(M, q, rexp, cexp)


@njit(cache=True, _nrt=False)
def _balance_ruiz(M, q, rexp, cexp, sweeps):
    # the third balancing: rows and columns equilibrated apart (R M C), each
    # by the geometric mean of its largest and smallest nonzero entry, in
    # powers of two (a max-norm equilibration stops at once on a friction
    # LCP, whose unit coupling entries hide a tiny Delassus block). It finds
    # scalings a symmetric one cannot: there the impulse columns and the cone
    # rows must scale by the block's size while the rest stays put.
    # Computed on M / 2^e(max|M|), so a uniform power-of-two scaling of the
    # data leaves R and C unchanged.
    n = q.shape[0]
    mmax = 0.0
    for i in range(n):
        rexp[i] = 0
        cexp[i] = 0
        for j in range(n):
            mmax = max(mmax, abs(M[i, j]))
    e0 = -math.frexp(mmax)[1] if mmax > 0.0 else 0
    for _ in range(sweeps):
        for i in range(n):
            # np.bool_ flags: literals would compile _geo_exponent once for each value
            rexp[i] -= _geo_exponent(M, e0, rexp, cexp, i, np.True_)
        for j in range(n):
            cexp[j] -= _geo_exponent(M, e0, rexp, cexp, j, np.False_)
    return _unit_exponents(M, q, rexp, cexp)


@njit(cache=True, _nrt=False)
def _geo_exponent(M, e0, rexp, cexp, k, row):
    # half the summed exponents of the largest and smallest nonzero entry of
    # row (or column) k of 2^e0 R M C: the power of two to divide it by
    n = M.shape[0]
    hi = 0.0
    lo = np.inf
    for m in range(n):
        i, j = (k, m) if row else (m, k)
        a = abs(_times_pow2(M[i, j], e0 + rexp[i] + cexp[j]))
        if a > 0.0:
            hi = max(hi, a)
            lo = min(lo, a)
    if hi == 0.0:
        return 0
    return (math.frexp(hi)[1] + math.frexp(lo)[1]) // 2


@njit(cache=True, _nrt=False)
def _unit_exponents(M, q, rexp, cexp):
    # (ka, kb) bringing max|R M C| and max|R q| to [0.5, 1)
    n = q.shape[0]
    qmax = 0.0
    mmax = 0.0
    for i in range(n):
        qmax = max(qmax, abs(_times_pow2(q[i], rexp[i])))
        for j in range(n):
            mmax = max(mmax, abs(_times_pow2(M[i, j], rexp[i] + cexp[j])))
    ka = -math.frexp(mmax)[1] if mmax > 0.0 else 0
    kb = -math.frexp(qmax)[1] if qmax > 0.0 else 0
    return ka, kb


@njit(cache=True)
def _run_scaled(M, q, d, rexp, cexp, ka, kb, z_out, w_out, ray_out, work, iwork, max_iter, tol,
                scale_d, mmax, qmax, exact_ok, start):
    # lemke_core on (2^ka R M C, 2^kb R q), R = diag(2^rexp), C = diag(2^cexp),
    # mapped back (z = 2^(ka-kb) C z') and judged on the caller's data with
    # the rounding of M z + q counted (_residual): the scaled problem is the
    # means, the caller's is the one answered. Powers of two make every map exact.
    n = q.shape[0]
    unit = ka == 0 and kb == 0
    for i in range(n):
        unit = unit and rexp[i] == 0 and cexp[i] == 0
    if unit:
        # no scaling (a hand-over from the plain stage): the data as they are
        Ms, qs, ds = M, q, d
    else:
        Ms = np.empty((n, n))
        qs = np.empty(n)
        ds = np.empty(n)
        for i in range(n):
            qs[i] = _times_pow2(q[i], rexp[i] + kb)
            # the covering vector of the scaled problem: all ones by default
            # (the caller's d = 1 is a choice, not data), else the caller's mapped
            ds[i] = _times_pow2(d[i], rexp[i]) if scale_d else d[i]
            for j in range(n):
                Ms[i, j] = _times_pow2(M[i, j], rexp[i] + cexp[j] + ka)
    if start.shape[0] == 0:
        status, pivots, residual = _start(Ms, qs, ds, z_out, w_out, ray_out, work, iwork, max_iter,
                                          tol, exact_ok)
    else:
        # from a basis the exact path decided (start: see _core_resume)
        status, pivots, residual, entering = _core_resume(Ms, qs, ds, z_out, w_out, ray_out, work,
                                                          iwork, start)
        if status != _HANDOFF_TIE and status != BREAKDOWN:
            status, pivots, residual = _core(Ms, qs, ds, z_out, w_out, ray_out, work, iwork,
                                             max_iter, tol, np.bool_(True), iwork[:1], pivots,
                                             entering, status)
    if status == _NEED_SEEN or status == _NEED_REPAIR:
        status, pivots, residual = _continue(Ms, qs, ds, z_out, w_out, ray_out, work, iwork,
                                             max_iter, tol, np.bool_(exact_ok or start.shape[0] > 0),
                                             status, pivots, residual)
    if status == INVALID_INPUT or status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
        # a hand-over carries the basis in ray_out: nothing to map back
        return status, pivots, residual
    finite = True
    for j in range(n):
        z_out[j] = _times_pow2(z_out[j], ka - kb + cexp[j])
        if not abs(z_out[j]) < np.inf:
            finite = False
        # the ray is a direction: dz = C dz', and dz0 = 2^-ka dz0' makes
        # (dz, dz0) a ray of M dz + R^-1 d' dz0 (the covering R^-1 d'; d' = d
        # where R = C = I, as for data of one scale)
        ray_out[j] = math.ldexp(ray_out[j], cexp[j])
    ray_out[n] = math.ldexp(ray_out[n], -ka)
    if not finite:
        # the answer is outside the range of doubles at the data's scale
        for j in range(n):
            z_out[j] = 0.0
        return BREAKDOWN, pivots, _residual(M, q, z_out, w_out, mmax, qmax)
    residual = _residual(M, q, z_out, w_out, mmax, qmax)
    if status == SOLVED or status == BREAKDOWN:
        status = SOLVED if residual <= tol else BREAKDOWN
    if status == SECONDARY_RAY and _ray_proves(M, q, ray_out):
        status = INFEASIBLE
    return status, pivots, residual


@njit(cache=True, _nrt=False)
def unit_farkas(M, q):
    """The first ``i`` for which ``e_i`` is a Farkas vector of ``LCP(M, q)``, or -1 (compiled).

    ``e_i`` is one when ``q_i < 0`` and every ``M_ij <= 0``: then ``w_i = (M
    z)_i + q_i < 0`` for every ``z >= 0``. The test reads the data as they
    are, with no arithmetic, so it is exact.

    Examples
    --------
    >>> import numpy as np
    >>> int(unit_farkas(np.array([[1.0, 0.0], [-1.0, 0.0]]), np.array([-1.0, -1.0])))
    1
    """
    n = q.shape[0]
    for i in range(n):
        if q[i] < 0.0:
            ok = True
            for j in range(n):
                if not M[i, j] <= 0.0:
                    ok = False
                    break
            if ok:
                return i
    return -1


@njit(cache=True)
def _screen_ray(M, q, ray):
    # the candidates moreau.lcp.certify._candidates builds from a ray (the
    # clipped ray, with entries below 1e-12, 1e-9, 1e-6 of the largest removed,
    # and rounded to 40, 26, 20, 12 bits), each judged by farkas_float, and the
    # unit vectors (unit_farkas): 1 one is proven, 0 one needs the exact
    # check, -1 every one fails rigorously. Then whether M might be PSD (where
    # the exact null-space projection is tried): not when its symmetric part
    # has a negative diagonal entry, or a zero one with a nonzero row, nor when
    # M is nonnegative with a positive diagonal (certify.copositive_plus_class
    # names that class first, and projects only for the PSD one), nor when a
    # 2 x 2 principal block of S = (M + M^T) / 2 has an eigenvalue below twice
    # the tolerance of copositive_plus_class (-100 n^2 eps max|S|): then so
    # has S (interlacing), and that test, far above this one's rounding, says no
    n = q.shape[0]
    maybe_psd = True
    nonneg = True
    smax = 0.0
    for i in range(n):
        if M[i, i] < 0.0:
            maybe_psd = False
        elif M[i, i] == 0.0:
            nonneg = False
            for j in range(n):
                if M[i, j] + M[j, i] != 0.0:
                    maybe_psd = False
                    break
        for j in range(n):
            nonneg = nonneg and M[i, j] >= 0.0
            smax = max(smax, abs(0.5 * (M[i, j] + M[j, i])))
    if nonneg:
        maybe_psd = False
    if maybe_psd:
        tau = 2.0 * 100.0 * n * n * np.finfo(np.float64).eps * smax
        for i in range(n):
            for j in range(i + 1, n):
                a = M[i, i]
                bb = M[j, j]
                h = 0.5 * (M[i, j] + M[j, i])
                lam = 0.5 * (a + bb) - math.sqrt(0.25 * (a - bb) ** 2 + h * h)
                if lam < -tau:
                    maybe_psd = False
                    break
            if not maybe_psd:
                break
    if unit_farkas(M, q) >= 0:
        return 1, maybe_psd
    top = 0.0
    for i in range(n):
        if not abs(ray[i]) < np.inf:
            return 0, maybe_psd
        top = max(top, ray[i])
    if not top > 0.0:
        return -1, maybe_psd
    y = np.empty(n)
    c = np.empty(n)
    for i in range(n):
        y[i] = max(ray[i] / top, 0.0)
    best = -1
    for k in range(8):
        for i in range(n):
            if k == 0:
                c[i] = y[i]
            elif k < 4:
                cut = 1e-12 if k == 1 else (1e-9 if k == 2 else 1e-6)
                c[i] = 0.0 if y[i] < cut else y[i]
            else:
                bits = 40 if k == 4 else (26 if k == 5 else (20 if k == 6 else 12))
                c[i] = math.ldexp(np.round(math.ldexp(y[i], bits)), -bits)
        v = farkas_float(M, q, c)
        if v > best:
            best = v
            if best == 1:
                break
    return best, maybe_psd


@njit(cache=True)
def _ray_proves(M, q, ray):
    # the ray's dz (negative rounding noise clipped) is a Farkas vector, decided
    # rigorously in floating point (farkas_float); an undecided case stays a
    # ray here and goes to the exact rational check in Python
    if not _ray_is_farkas(M, q, ray, FARKAS_TOL):
        return False
    n = q.shape[0]
    y = np.empty(n)
    for i in range(n):
        y[i] = max(ray[i], 0.0)
    return farkas_float(M, q, y) == 1


@njit(cache=True, _nrt=False)
def _plain_stage(M, q, d, out, fbuf, ibuf, max_iter, tol, exact_ok):
    # The first stage of _lemke_rest, which allocates nothing: the balancing
    # exponents (balance, into ibuf[3 n + 1:]) and, on data of one moderate
    # scale, Lemke on them as given (_core, the tableau in fbuf). Returns
    # (status, pivots, residual, ka, kb), status _NOT_PLAIN when the data need
    # the scaled stages. Buffers: out as for _solve_packed, fbuf of
    # _fbuf_size(n) floats, ibuf of 4 n + 1 integers.
    n = q.shape[0]
    m = _padded(n)
    work = fbuf[:(n + 3) * m].reshape((n + 3, m))
    iwork = ibuf[:3 * n + 1]
    sexp = ibuf[3 * n + 1:]
    for i in range(n):
        sexp[i] = 0
    ok, ka, kb = balance(M, q, sexp)
    if not ok:
        # NaN or inf: _core refuses them
        status, pivots, residual = _start(M, q, d, out[:n], out[n:2 * n], out[2 * n:3 * n + 1],
                                          work, iwork, max_iter, tol, exact_ok)
        return status, pivots, residual, ka, kb
    plain = -_PLAIN_RANGE <= ka <= _PLAIN_RANGE and -_PLAIN_RANGE <= kb <= _PLAIN_RANGE
    for i in range(n):
        plain = plain and sexp[i] == 0
    if not plain:
        return _NOT_PLAIN, 0, np.inf, ka, kb
    # data of one moderate scale: the pivoting's tests are all relative, so
    # pivoting on them as given is what the normalised copy would do (the
    # property tests scale by 2^k and compare), minus the copy
    status, pivots, residual = _start(M, q, d, out[:n], out[n:2 * n], out[2 * n:3 * n + 1], work,
                                      iwork, max_iter, tol, exact_ok)
    return status, pivots, residual, ka, kb


@njit(cache=True, inline="always")
def _solve_buffers(M, q, d, out, fbuf, ibuf, max_iter, tol, scale_d, exact_ok):
    # Lemke on the symmetrically balanced data (balance): a uniformly scaled
    # problem pivots exactly as the unscaled one, and the matrix class is
    # kept. The common case (data of one scale, a solution or the pivot limit)
    # ends in _plain_stage; the rest in _lemke_rest.
    n = q.shape[0]
    status, pivots, residual, ka, kb = _plain_stage(M, q, d, out, fbuf, ibuf, max_iter, tol,
                                                    exact_ok)
    if status == SOLVED or status == MAX_ITER or status == INVALID_INPUT:
        return status, pivots, residual
    m = _padded(n)
    return _lemke_rest(M, q, d, out[:n], out[n:2 * n], out[2 * n:3 * n + 1],
                       fbuf[:(n + 3) * m].reshape((n + 3, m)), ibuf[:3 * n + 1], ibuf[3 * n + 1:],
                       ka, kb, max_iter, tol, scale_d, exact_ok, out[3 * n + 1:], status, pivots,
                       residual)


@njit(cache=True, inline="always")
def _lemke_rest(M, q, d, z_out, w_out, ray_out, work, iwork, sexp, ka, kb, max_iter, tol, scale_d,
                exact_ok, info, status, pivots, residual):
    # After _plain_stage (its outcome in status, pivots, residual; _NOT_PLAIN
    # when it did not pivot): where the answer fails on the caller's data,
    # Lemke again on the balanced data, then with rows scaled to their q
    # (_balance_rows_to_q), then with rows and columns equilibrated apart
    # (_balance_ruiz). On a hand-over to the exact path (exact_ok), info
    # (2 n + 3) receives the scaling of the data pivoted on (_handoff_info),
    # for the exact step and the resume to use the same. Inlined (numba IR)
    # into the entries (through _solve_buffers): as a library of its own it had
    # numba optimise and compile _run_scaled and _core once more for each.
    n = q.shape[0]
    plain = status != _NOT_PLAIN
    if plain:
        if status == _NEED_SEEN or status == _NEED_REPAIR:
            status, pivots, residual = _continue(M, q, d, z_out, w_out, ray_out, work, iwork,
                                                 max_iter, tol, exact_ok, status, pivots, residual)
        if status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
            _handoff_info(info, sexp, sexp, np.int64(0), np.int64(0), np.bool_(False),
                          np.bool_(True))
            return status, pivots, residual
        if status == SECONDARY_RAY and (_ray_proves(M, q, ray_out) or unit_farkas(M, q) >= 0):
            status = INFEASIBLE
        if status != BREAKDOWN:
            return status, pivots, residual
    mmax, qmax, _ = _scales(M, q, n)
    if plain:
        status, pivots, residual = BREAKDOWN, pivots, residual
    else:
        status, pivots, residual = _run_scaled(M, q, d, sexp, sexp, ka, kb, z_out, w_out,
                                               ray_out, work, iwork, max_iter, tol, scale_d,
                                               mmax, qmax, exact_ok, ray_out[:0])
        if status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
            _handoff_info(info, sexp, sexp, ka, kb, scale_d, np.bool_(False))
            return status, pivots, residual
        if status == SECONDARY_RAY and unit_farkas(M, q) >= 0:
            status = INFEASIBLE
        if status != BREAKDOWN:
            return status, pivots, residual
    rexp = np.zeros(n, dtype=np.int64)
    cexp = np.zeros(n, dtype=np.int64)
    for attempt in range(2):
        if attempt == 0:
            ka2, kb2 = _balance_rows_to_q(M, q, rexp, cexp)
        else:
            ka2, kb2 = _balance_ruiz(M, q, rexp, cexp, 12)
        same = ka2 == ka and kb2 == kb
        for i in range(n):
            same = same and rexp[i] == sexp[i] and cexp[i] == sexp[i]
        if same:
            continue
        z1 = z_out.copy()
        w1 = w_out.copy()
        r1 = ray_out.copy()
        status2, pivots2, residual2 = _run_scaled(M, q, d, rexp, cexp, ka2, kb2, z_out, w_out,
                                                  ray_out, work, iwork, max_iter, tol, scale_d,
                                                  mmax, qmax, exact_ok, ray_out[:0])
        if status2 == _HANDOFF_TIE or status2 == _HANDOFF_CYCLE:
            _handoff_info(info, rexp, cexp, ka2, kb2, scale_d, np.bool_(False))
        pivots += pivots2
        if status2 == SECONDARY_RAY and unit_farkas(M, q) >= 0:
            status2 = INFEASIBLE
        if status2 == SOLVED or status2 == _HANDOFF_TIE or status2 == _HANDOFF_CYCLE:
            return status2, pivots, residual2
        if residual2 < residual:
            status, residual = status2, residual2
        else:
            _copy_into(z_out, z1)
            _copy_into(w_out, w1)
            _copy_into(ray_out, r1)
    return status, pivots, residual


@njit(cache=True, _nrt=False)
def _ray_is_farkas(M, q, y, tol):
    # moreau.lcp.certify.farkas_vector(M, q, y, tol) is not None, compiled:
    # y >= 0 (to -tol after scaling to max 1), q.y < 0 and
    # max(M^T y) <= tol max|M| |q.y| / max|q|
    n = q.shape[0]
    top = 0.0
    for i in range(n):
        if not abs(y[i]) < np.inf:
            return False
        if y[i] > top:
            top = y[i]
    if not top > 0.0:
        return False
    qy = 0.0
    qmax = 0.0
    for i in range(n):
        yi = y[i] / top
        if yi < -tol:
            return False
        if yi > 0.0:
            qy += q[i] * yi
        qmax = max(qmax, abs(q[i]))
    if not qy < 0.0:
        return False
    mmax = 0.0
    g = -np.inf
    for j in range(n):
        acc = 0.0
        for i in range(n):
            a = M[i, j]
            mmax = max(mmax, abs(a))
            yi = y[i] / top
            if yi > 0.0:
                acc += a * yi
        g = max(g, acc)
    return g <= tol * mmax * (-qy) / qmax


@njit(cache=True)
def _solve_packed(M, q, out, max_iter, tol, covering):
    # one compiled call per Python solve. The outputs live in one buffer
    # (z | w | ray | hand-over) allocated by the caller: returning arrays from
    # compiled code costs more than the whole pivoting on a small LCP. With
    # `covering`, the covering vector follows them (out[_OUT n + 4:], n floats)
    # and is balanced with the data; without, it is ones, made here (one array
    # argument less to type on every call from Python). One entry for both: as
    # two, numba optimised and compiled Lemke's whole path into each (4 CPU s)
    n = q.shape[0]
    if M.shape[0] != n or M.shape[1] != n or (out.shape[0] != _OUT * n + 4 + n if covering
                                               else out.shape[0] < _OUT * n + 4):
        # the unchecked path must never read out of bounds
        return INVALID_INPUT, 0, np.inf
    # the tableau and the covering vector in one allocation, the integer work in another
    fbuf = np.empty(_fbuf_size(n))
    ibuf = np.empty(4 * n + 1, dtype=np.int64)
    d = fbuf[_fbuf_size(n) - n:]
    for i in range(n):
        d[i] = out[_OUT * n + 4 + i] if covering else 1.0
    return _solve_buffers(M, q, d, out, fbuf, ibuf, max_iter, tol, covering, np.bool_(True))


@njit(cache=True, _nrt=False)
def _fbuf_size(n):
    # floats of the buffer of _solve_buffers: the tableau (n + 3 rows of
    # _padded(n)) and the covering vector
    return (n + 3) * _padded(n) + n


# inlined (numba IR) into _exact_run: as a library of its own it had numba
# optimise and compile all of _run_scaled once more for _exact_run
@njit(cache=True, inline="always")
def _resume_packed(M, q, d, out, start, max_iter, tol):
    # _solve_packed from a basis the exact path decided (start: see
    # _core_resume), on the data scaled as the run that handed over
    # (out[3 n + 1:], written by _handoff_info); judged on the caller's data
    n = q.shape[0]
    info = out[3 * n + 1:]
    rexp = np.empty(n, dtype=np.int64)
    cexp = np.empty(n, dtype=np.int64)
    for i in range(n):
        rexp[i] = np.int64(info[i])
        cexp[i] = np.int64(info[n + i])
    ka = np.int64(info[2 * n])
    kb = np.int64(info[2 * n + 1])
    scale_d = info[2 * n + 2] != 0.0
    mmax, qmax, _ = _scales(M, q, n)
    work = np.empty((n + 3, _padded(n)))
    iwork = np.empty(3 * n + 1, dtype=np.int64)
    z_out = out[:n]
    w_out = out[n:2 * n]
    ray_out = out[2 * n:3 * n + 1]
    status, pivots, residual = _run_scaled(M, q, d, rexp, cexp, ka, kb, z_out, w_out, ray_out,
                                           work, iwork, max_iter, tol, scale_d, mmax, qmax,
                                           np.bool_(True), start)
    if status == SECONDARY_RAY and unit_farkas(M, q) >= 0:
        status = INFEASIBLE
    if status != _HANDOFF_TIE and status != _HANDOFF_CYCLE:
        # the terminal basis, for the exact point of a solution (info is spent)
        for i in range(n):
            info[i] = iwork[i]
    return status, pivots, residual


# outcomes of _exact_run: the path left the hand-over (its status is final for
# the exact steps), a hand-over state repeated, the step limit was reached, the
# step is left to the Python integers (_exact.exact_step), the pivot limit
_RUN_DONE = 0
_RUN_REPEAT = 1
_RUN_LIMIT = 2
_RUN_PYTHON = 3
_RUN_MAX_ITER = 4
# _RUN_DONE on a solution whose exact point is in z already
_RUN_EXACT_POINT = 5


@njit(cache=True)
def _exact_run(M, q, d, out, start, primes, status, pivots, max_iter, tol, max_steps):
    # The loop of _exact_steps in compiled code: each hand-over's step decided
    # exactly by _modular.modular_step on the data as scaled by the run that
    # handed over (out[3 n + 1:], _handoff_info), the path resumed in floating
    # point from the basis reached (_resume_packed), at most max_steps times.
    # Returns (outcome, status, pivots, residual, steps); start holds the last
    # resume's start, out the path's state as _resume_packed leaves it.
    n = q.shape[0]
    z0 = 2 * n
    steps = 0
    keys = np.empty(max_steps + 1, dtype=np.int64)
    basis = np.empty(n, dtype=np.int64)
    flags = np.empty(n)
    Ms = np.empty((n, n))
    qs = np.empty(n)
    ds = np.empty(n)
    residual = np.inf
    info = out[3 * n + 1:]
    unit = True
    for t in range(2 * n + 3):
        unit = unit and info[t] == 0.0
    while status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
        hb = 0
        for i in range(n):
            basis[i] = np.int64(out[2 * n + i])
            hb ^= _key(basis[i])
        entering = np.int64(out[3 * n])
        key = hb ^ _key(entering + 3 * n)
        for t in range(steps):
            if keys[t] == key:
                return _RUN_REPEAT, status, pivots, residual, steps
        if steps >= max_steps:
            return _RUN_LIMIT, status, pivots, residual, steps
        keys[steps] = key
        if unit:
            # the plain stage's hand-over: the data as given
            outcome, leaving = _modular.modular_step(M, q, d, basis, entering, primes, flags)
        else:
            ka = np.int64(info[2 * n])
            kb = np.int64(info[2 * n + 1])
            for i in range(n):
                ri = np.int64(info[i])
                qs[i] = _times_pow2(q[i], ri + kb)
                ds[i] = _times_pow2(d[i], ri) if info[2 * n + 2] != 0.0 else d[i]
                for j in range(n):
                    Ms[i, j] = _times_pow2(M[i, j], ri + np.int64(info[n + j]) + ka)
            outcome, leaving = _modular.modular_step(Ms, qs, ds, basis, entering, primes, flags)
        if outcome < 0:
            return _RUN_PYTHON, status, pivots, residual, steps
        steps += 1
        for i in range(n):
            start[i] = basis[i]
            start[n + 3 + i] = flags[i]
        start[n] = entering
        if outcome == _modular.STEP_RAY:
            start[n + 1] = _RESUME_RAY
        else:
            pivots += 1
            for i in range(n):
                if basis[i] == leaving:
                    start[i] = entering
            if leaving == z0:
                start[n + 1] = _RESUME_SOLVED
            else:
                start[n] = leaving + n if leaving < n else leaving - n
                start[n + 1] = _RESUME_PATH
        start[n + 2] = pivots
        if pivots >= max_iter and outcome != _modular.STEP_RAY and leaving != z0:
            return _RUN_MAX_ITER, status, pivots, residual, steps
        status, pivots, residual = _resume_packed(M, q, d, out, start, max_iter, tol)
    if status == SOLVED and steps > 0:
        # the exact point of the terminal basis (info: its variables), correctly
        # rounded, as _exact.basis_point gives it; w and the check follow in Python
        m = 0
        for i in range(n):
            v = np.int64(info[i])
            if n <= v < 2 * n:
                basis[m] = v - n
                m += 1
        # np.bool_: the type of a Python caller's bool, one compile for both
        if _modular.exact_point(M, q, basis[:m], primes, out[:n], np.bool_(True)):
            return _RUN_EXACT_POINT, status, pivots, residual, steps
    return _RUN_DONE, status, pivots, residual, steps


@njit(cache=True)
def _violation(M, q, z):
    # lcp_violation of a finite z on finite data, without the Python checks
    n = q.shape[0]
    mmax, qmax, _ = _scales(M, q, n)
    return _residual(M, q, z, np.empty(n), mmax, qmax)


@njit(cache=True, _nrt=False)
def _handoff_info(info, rexp, cexp, ka, kb, scale_d, plain):
    # the scaling of the data a hand-over happened on: (2^ka R M C, 2^kb R q)
    # with covering 2^rexp d (scale_d) or d, R = diag(2^rexp), C = diag(2^cexp);
    # the plain stage pivots on the data as given (all exponents 0)
    n = rexp.shape[0]
    for i in range(n):
        info[i] = 0.0 if plain else float(rexp[i])
        info[n + i] = 0.0 if plain else float(cexp[i])
    info[2 * n] = 0.0 if plain else float(ka)
    info[2 * n + 1] = 0.0 if plain else float(kb)
    info[2 * n + 2] = 1.0 if scale_d and not plain else 0.0


class _LemkeResult(LCPResult):
    # the explanation of a failure is composed only when someone reads it,
    # so that a failed solve costs no more than a successful one
    __slots__ = ()

    def __init__(self, z, w, status, pivots, residual):
        # the base's defaults (path, ray, detail) are the class's: only the
        # slots are set, a sixth of the cost of a small solve less
        self.z = z
        self.w = w
        self.status = status
        self.pivots = pivots
        self.residual = residual
        self.method = "lemke"

    @property
    def detail(self):
        d = self.__dict__.get("_detail")
        if d is not None:
            return d
        if self.status == SOLVED:
            return ""
        if self.status == INFEASIBLE:
            # proven in compiled code; the words (and the matrix class they
            # name, an eigenvalue computation) only when someone reads them
            _, M, q = self.__dict__["_ray"]
            why = _ray_or_unit_proof(M, q, self.ray)[1]
            d = f"{why} `ray` holds the direction (dz, dz0) (after {self.pivots} pivots)."
            self.__dict__["_detail"] = d
            return d
        if self.status == SECONDARY_RAY and "_ray" in self.__dict__:
            _, M, q = self.__dict__["_ray"]
            why = infeasibility_from_ray(M, q, self.ray)[1]
            d = f"{why} `ray` holds the direction (dz, dz0) (after {self.pivots} pivots)."
            self.__dict__["_detail"] = d
            return d
        return _DETAIL.get(self.status, "") + f" (after {self.pivots} pivots)"

    @detail.setter
    def detail(self, value):
        self.__dict__["_detail"] = value

    @property
    def ray(self):
        # _ray = (output buffer, M, q), set on the ray statuses in one go:
        # the first write to an instance's __dict__ is what costs
        packed = self.__dict__.get("_ray")
        if packed is None:
            return None
        n = len(self.z)
        return packed[0][2 * n:3 * n + 1]

    @property
    def certificate(self):
        if self.status != INFEASIBLE:
            return None
        y = self.__dict__.get("_cert")
        if y is None:
            _, M, q = self.__dict__["_ray"]
            if _ray_proves(M, q, self.ray):
                # scaled by a power of two (largest entry in [1, 2)): exact, so the
                # vector proven in compiled code is the one handed out
                y = np.maximum(self.ray[:len(self.z)], 0.0)
                y = np.ldexp(y, 1 - np.frexp(np.max(y))[1])
            elif unit_farkas(M, q) >= 0:
                # the compiled code proved it by a unit vector (unit_farkas)
                y = np.zeros(len(self.z))
                y[unit_farkas(M, q)] = 1.0
            else:
                # by a cleaned candidate of the ray (_screen_ray)
                y = _ray_or_unit_proof(M, q, self.ray)[0]
            self.__dict__["_cert"] = y
        return y

    @certificate.setter
    def certificate(self, value):
        self.__dict__["_cert"] = value


_DETAIL = {
    SECONDARY_RAY: "No solution was found; `ray` holds the direction of the ray.",
    MAX_ITER: "Raise `max_iter` or try method='qp'.",
    BREAKDOWN: "The lexicographic ratio test could not separate tied rows, or the terminal "
    "point failed the residual check.",
}

_F8 = np.dtype(np.float64)
_NDARRAY = np.ndarray


def coerce_lcp(M, q):
    """``(M, q)`` as float64 arrays of matching square shapes; refusals name the argument."""
    # cheap when the caller already passes float64 arrays, the common case
    if type(M) is not _NDARRAY or M.dtype is not _F8 or M.ndim != 2 or not M.flags.c_contiguous:
        M = _as_matrix(M)
    if type(q) is not _NDARRAY or q.dtype is not _F8 or q.ndim != 1:
        q = _as_vector(q)
    m0, m1 = M.shape
    if m0 != m1:
        raise InputError(f"`M` must be square, got shape {M.shape}")
    if m0 != q.shape[0]:
        raise InputError(f"`q` must have length {m0} to match `M`, got {q.shape[0]}")
    return M, q


def _real(name, a):
    # a complex array would lose its imaginary part in the float conversion
    if np.iscomplexobj(a):
        raise InputError(f"`{name}` must be real, got a complex array")


def _as_matrix(M):
    _real("M", M)
    a = float_array("M", M)
    if a.ndim != 2:
        raise InputError(f"`M` must be a square 2-D array, got shape {a.shape}")
    # C order: a Fortran-ordered or strided array would compile the whole solver
    # again for its layout (23 CPU s on a cold cache), for the same arithmetic
    return np.ascontiguousarray(a)


def _as_vector(q, name="q"):
    _real(name, q)
    a = float_array(name, q)
    if a.ndim != 1:
        raise InputError(f"`{name}` must be a 1-D array, got shape {a.shape}")
    return np.ascontiguousarray(a)


def _raise_nonfinite(M, q, d):
    # the compiled code refused the data: say why, shapes first (an unchecked
    # call with mismatched arrays is refused there before any read)
    M = np.asarray(M)
    q = np.asarray(q)
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise InputError(f"`M` must be square, got shape {M.shape}")
    if q.ndim != 1 or q.shape[0] != M.shape[0]:
        got = q.shape[0] if q.ndim == 1 else f"shape {q.shape}"
        raise InputError(f"`q` must have length {M.shape[0]} to match `M`, got {got}")
    if d is not None and np.shape(d) != q.shape:
        raise InputError(f"`covering` must have length {q.shape[0]}, got shape {np.shape(d)}")
    finite_array("M", M)
    finite_array("q", q)
    if d is not None:
        finite_array("covering", d)
        if not np.all(d > 0):
            raise InputError("`covering` must be strictly positive")
    raise InputError("invalid LCP data")  # pragma: no cover - the checks above fire first


def _support_indices(support, n):
    """``support`` as an int64 array of distinct indices in ``[0, n)``; InputError otherwise."""
    try:
        B = np.asarray(support, dtype=np.int64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError("`support` must be a sequence of integer indices") from None
    if B.size and (B.min() < 0 or B.max() >= n or np.unique(B).size != B.size):
        raise InputError(f"`support` must hold distinct indices in [0, {n}), got {B.tolist()}")
    return B


#: :func:`solve_on_support` refuses a support whose ``M_BB`` has a pivot (Gaussian
#: elimination with partial pivoting) below this times the largest entry of its column
SUPPORT_PIVOT_RTOL = 1e-8


def solve_on_support(M, q, support, *, tol=None):
    """The point of a guessed support, ``M_BB z_B = -q_B`` and ``z = 0`` off ``B``, if it solves.

    A warm start for a sequence of LCPs that keep their solution's support
    (the contact problems of a time-stepping scheme between contact
    events): no pivoting, one ``|B| x |B|`` elimination. The point is
    accepted only as any method's answer is, by the check on the caller's
    data (:func:`moreau.lcp.lcp_violation`, at its worst over the rounding
    of ``w = M z + q``, ``<= tol``), and only where ``M_BB`` is clearly
    regular: every pivot of the elimination above
    :data:`SUPPORT_PIVOT_RTOL` times the largest entry of its column.

    Parameters
    ----------
    M : ndarray, shape (n, n)
    q : ndarray, shape (n,)
    support : array_like of int
        The indices ``B`` of the guessed nonzero ``z``, each in ``[0, n)``,
        without repeats.
    tol : float, optional
        The violation bound (default :data:`DEFAULT_TOL`, Lemke's).

    Returns
    -------
    LCPResult or None
        Solved, with ``pivots = 0`` and ``method = "support"``; None where
        the support is refused (a singular ``M_BB``, or a point that fails
        the check).

    Raises
    ------
    InputError
        Bad shapes, non-finite data, an index out of range or repeated.

    Examples
    --------
    >>> M = np.array([[2.0, 1.0], [1.0, 2.0]])
    >>> res = solve_on_support(M, np.array([-1.0, 1.0]), [0])
    >>> res.method, res.pivots, res.z.tolist()
    ('support', 0, [0.5, 0.0])
    >>> solve_on_support(M, np.array([-1.0, 1.0]), [1]) is None    # z_1 = -0.5
    True
    """
    M, q = coerce_lcp(M, q)
    finite_array("M", M)
    finite_array("q", q)
    tol = DEFAULT_TOL if tol is None else positive("tol", tol)
    n = q.shape[0]
    B = _support_indices(support, n)
    z = np.zeros(n)
    if B.size:
        A = M[np.ix_(B, B)]
        # LAPACK's partial pivoting (getrf), with no compile on a cold start; a pivot at
        # rounding level of its column is a singular block
        lu, piv, _ = _getrf(A)
        if not np.all(np.abs(np.diag(lu)) > SUPPORT_PIVOT_RTOL * np.max(np.abs(A), axis=0)):
            return None
        z[B] = _getrs(lu, piv, -q[B])[0]
    residual = float(lcp_violation(M, q, z))
    if not residual <= tol:
        return None
    res = LCPResult(z, M @ z + q, SOLVED, 0, residual, "support")
    res.detail = (f"Solved on the support guessed ({B.size} of {n} variables), with no pivot, and "
                  f"checked on the data like any answer.")
    return res


def solve(M, q, *, max_iter=None, tol=None, check_input=True, friction=None, covering=None):
    """Solve ``LCP(M, q)`` by Lemke's method.

    Parameters
    ----------
    M : array_like, shape (n, n)
    q : array_like, shape (n,)
    max_iter : int, optional
        Pivot limit; :func:`default_max_iter` when not given (``max(1000,
        50 n, min(2^(n+1), 2^30 // (n (n + 1))))``: enough for Murty's
        exponential examples up to n = 20).
    tol : float, optional
        Bound on the violation (:func:`moreau.lcp.lcp_violation`) for a
        solved status (default :data:`DEFAULT_TOL`).
    covering : array_like, shape (n,), optional
        Covering vector ``d > 0``; all ones when not given.
    check_input : bool
        When False, the costlier checks of the options are skipped; the
        types and shapes of ``M`` and ``q`` are checked on every call, and
        non-finite data still come back as an error, detected in compiled
        code.
    friction : FrictionLayout, optional
        Accepted so that every method shares one signature; Lemke's method
        needs no structure and ignores it.

    Returns
    -------
    LCPResult
        On a secondary ray, status :data:`INFEASIBLE` with the Farkas vector
        in ``certificate`` when the ray proves infeasibility (``M``
        copositive-plus, or the ray itself a Farkas vector, see
        :func:`moreau.lcp.certify.infeasibility_from_ray`), else
        :data:`SECONDARY_RAY`; ``ray`` holds the ray in both cases.

    Raises
    ------
    InputError
        ``M`` not square, ``q`` of the wrong length, NaN or inf in the data,
        a non-positive covering vector.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]])
    >>> res = solve(M, -np.ones(3))
    >>> res.success, np.round(res.z, 12).tolist()
    (True, [0.333333333333, 0.333333333333, 0.333333333333])
    """
    return _solve(M, q, max_iter, tol, check_input, covering)


def _solve_packed_first(M, q, out, max_iter, tol, covering):
    # the first call compiles the solver (or loads it from the disk cache) under the
    # compile lock: processes that reach it together (pytest's or a sweep's workers)
    # compile it once, the others load the machine code (15 CPU s each otherwise)
    global _solve_entry
    with _jit_cache.compile_lock(_solve_packed):
        result = _solve_packed(M, q, out, max_iter, tol, covering)
    _solve_entry = _solve_packed
    return result


_solve_entry = _solve_packed_first


def _solve(M, q, max_iter, tol, check_input, covering, defer=False):
    # positional twin of solve(): the entry point calls it directly, since a
    # keyword call costs a noticeable part of a 4-variable solve
    # types and shapes are checked on every path (an unchecked call must not
    # reach compiled code with arrays it would read out of bounds); the
    # inline fast path of coerce_lcp costs a handful of attribute reads
    if type(M) is not _NDARRAY or M.dtype is not _F8 or M.ndim != 2 or not M.flags.c_contiguous:
        M = _as_matrix(M)
    if type(q) is not _NDARRAY or q.dtype is not _F8 or q.ndim != 1:
        q = _as_vector(q)
    # shapes are checked in compiled code before any read (_solve_packed:
    # INVALID_INPUT, then _raise_nonfinite names the argument)
    if check_input:
        if max_iter is not None:
            max_iter = positive_int("max_iter", max_iter)
        if tol is not None:
            tol = positive("tol", tol)
        if covering is not None:
            covering = _as_vector(covering, "covering")
            if covering.shape != q.shape:
                raise InputError(f"`covering` must have length {q.shape[0]}, got {covering.shape[0]}")
    n = q.shape[0]
    if max_iter is None:
        max_iter = _MAX_ITER_TABLE[n] if n < 512 else default_max_iter(n)
    # a covering vector rides behind the outputs (_solve_packed): one signature, one compile
    if covering is None:
        out = np.empty(_OUT * n + 4)
    else:
        out = np.empty(_OUT * n + 4 + covering.shape[0])
        out[_OUT * n + 4:] = covering
    status, pivots, residual = _solve_entry(
        M, q, out, max_iter, DEFAULT_TOL if tol is None else tol, covering is not None,
    )
    if status == SOLVED:
        return _LemkeResult(out[:n], out[n:2 * n], status, pivots, residual)
    if status == INVALID_INPUT:
        _raise_nonfinite(M, q, covering)
    if status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
        return _exact_steps(M, q, covering, out, status, pivots, max_iter,
                            DEFAULT_TOL if tol is None else tol, defer)
    return _packed_result(M, q, out, status, pivots, residual, "")


def _packed_result(M, q, out, status, pivots, residual, note):
    # the result of a compiled run whose outputs are in `out`; `note` (how
    # the exact path took part) goes before the detail
    n = q.shape[0]
    res = _LemkeResult(out[:n], out[n:2 * n], status, pivots, residual)
    if status == INFEASIBLE:
        # proven in compiled code: the ray's dz is a Farkas vector with every
        # sum's rounding bounded (farkas_float); the words, with the matrix
        # class they name, come only when someone reads them
        res.__dict__["_ray"] = (out, M, q)
    elif status == SECONDARY_RAY:
        # a ray proves infeasibility only through a Farkas vector that holds
        # exactly on the caller's data (the compiled pre-filter is not a proof)
        res.__dict__["_ray"] = (out, M, q)
        _prove_secondary_ray(res, M, q, out[2 * n:3 * n + 1], pivots)
    if note:
        res.detail = f"{note} {res.detail}".rstrip()
    return res


#: with ``defer`` (the ``auto`` method), the exact steps a path may take before
#: it is handed back undecided; the arch's friction LCPs measured 1 to 4 steps
#: where the path then ends in floating point, and 24 then a whole exact path
#: (0.6 s at n = 40, 19 s at n = 88: Python integers of thousands of bits)
DEFER_STEPS = 4


#: CPU seconds (``time.process_time``) that the exact-arithmetic part of one Lemke call may
#: take: past it the call ends with status ``MAX_ITER`` and a detail naming this budget, and
#: the caller's fallback (``"auto"``: the QP) runs. The compiled exact walk takes 10 to
#: 400 ms a step at n = 216 to 650 (12 s for the 883 steps of seed 2839128055's 128-gon,
#: where the whole tableau of Python integers took minutes); a path that needs more is
#: given up rather than left to run
EXACT_TIME_BUDGET = 10.0

# from this size on, a path finished in exact arithmetic is walked step by step with
# the compiled exact step (_exact_walk: the k x k block of the basis's non-w variables)
# rather than on the whole tableau of Python integers (_exact.exact_lemke: 2 n + 2
# columns of integers that grow with every pivot; 1.6 s a pivot at n = 650)
_WALK_MIN_N = 33


def _exact_steps(M, q, covering, out, handoff, pivots, max_iter, tol, defer=False):
    # The compiled pivoting met a tie rounding could not decide, or a repeated
    # basis. That step is decided in exact arithmetic (_exact.exact_step, on
    # the data as scaled by the run that handed over: powers of two, so the
    # caller's data exactly), and the path goes back to floating point from
    # the basis it reached (_resume_packed, on a tableau made afresh from the
    # data), as often as needed. The whole path is finished in exact arithmetic
    # (_exact_finish) only where a hand-over state repeats, where the basis is
    # not lexicographically positive for the data (an earlier decision of
    # rounding was wrong) or too close to singular to be followed in floating
    # point, and past 2 n + 16 exact steps. With defer, None instead of a
    # whole exact path or a path of more than DEFER_STEPS exact steps: the
    # caller (auto) tries a certified alternative first, then calls again
    # without defer.
    n = q.shape[0]
    d = np.ones(n) if covering is None else covering
    first = handoff
    seen = set()
    start = np.empty(2 * n + 3)
    deadline = time.process_time() + EXACT_TIME_BUDGET
    # the steps in compiled code first (_exact_run); what it leaves (a step too
    # large for its moduli, a refused basis, a repeat, the limit) goes on here
    # as before, with the Python integers
    run, status, pivots, residual, steps = _exact_run(
        M, q, d, out, start, _modular.primes(), handoff, pivots, max_iter, tol,
        DEFER_STEPS if defer else 2 * n + 17)
    # the compiled run put the exact point of the solution's basis in z already
    exact_point = run == _RUN_EXACT_POINT
    if run == _RUN_MAX_ITER:
        status, residual = MAX_ITER, float(lcp_violation(M, q, np.zeros(n)))
        out[:n] = 0.0
        out[n:2 * n] = q
    elif run == _RUN_REPEAT:
        if defer:
            return None
        return _exact_finish(M, q, covering, out, status, pivots, max_iter, tol,
                             out[2 * n:3 * n].astype(np.int64).tolist(), int(out[3 * n]),
                             deadline=deadline)
    while status == _HANDOFF_TIE or status == _HANDOFF_CYCLE:
        basis = out[2 * n:3 * n].astype(np.int64)
        entering = int(out[3 * n])
        key = (frozenset(basis.tolist()), entering)
        if defer and (key in seen or steps >= DEFER_STEPS):
            return None
        if key in seen or steps > 2 * n + 16:
            return _exact_finish(M, q, covering, out, status, pivots, max_iter, tol,
                                 basis.tolist(), entering, deadline=deadline)
        if time.process_time() > deadline:
            return _budget_result(M, q, first, pivots, steps)
        seen.add(key)
        info = out[3 * n + 1:_OUT * n + 4]
        if not info.any():
            # the plain stage: the data as given
            Ms, qs, ds = M, q, d
        else:
            ex = info[:n].astype(np.int64)
            ka, kb = int(info[2 * n]), int(info[2 * n + 1])
            Ms = np.ldexp(M, ex[:, None] + info[n:2 * n].astype(np.int64)[None, :] + ka)
            qs = np.ldexp(q, ex + kb)
            ds = np.ldexp(d, ex) if info[2 * n + 2] != 0.0 else d
        step = _exact.exact_step(Ms, qs, ds, basis, entering)
        if step is None and defer:
            return None
        if step is None:
            return _exact_finish(M, q, covering, out, status, pivots, max_iter, tol,
                                 basis.tolist(), entering, deadline=deadline)
        kind, leaving, b = step
        steps += 1
        start[:n] = basis
        start[n] = entering
        start[n + 3:] = b
        if kind == "ray":
            start[n + 1] = _RESUME_RAY
        else:
            pivots += 1
            start[:n][basis == leaving] = float(entering)
            if leaving == 2 * n:
                start[n + 1] = _RESUME_SOLVED
            else:
                start[n] = leaving + n if leaving < n else leaving - n
                start[n + 1] = _RESUME_PATH
        start[n + 2] = pivots
        if pivots >= max_iter and kind != "ray" and leaving != 2 * n:
            status, residual = MAX_ITER, float(lcp_violation(M, q, np.zeros(n)))
            out[:n] = 0.0
            out[n:2 * n] = q
            break
        status, pivots, residual = _resume_packed(M, q, d, out, start, max_iter, tol)
    if status == BREAKDOWN and defer:
        return None
    if status == BREAKDOWN:
        # the float path could not go on from a basis the exact path reached:
        # the exact path goes on from that basis (lexicographically positive,
        # as the exact step kept it; _exact.exact_lemke checks it again), not afresh
        if start[n + 1] == _RESUME_SOLVED:
            # z0 left in the exact step: the exact path ends there, at the point
            # of that complementary basis, computed exactly and checked on the data
            J = [int(v) - n for v in start[:n] if n <= v < 2 * n]
            z = _exact.basis_point(M, q, J)
            if z is not None:
                out[:n] = z
                # a point of huge entries may overflow here: its check then fails
                # (residual inf or NaN) and the exact path goes on, without a warning
                with np.errstate(over="ignore", invalid="ignore"):
                    out[n:2 * n] = M @ out[:n] + q
                residual = float(_violation(M, q, out[:n]))
                if residual <= tol:
                    note = (f"Pivoting met {_why(first)}; {steps} step{'s' if steps > 1 else ''} "
                            f"of the path {'were' if steps > 1 else 'was'} decided in exact "
                            f"arithmetic, the last one ending the path, the rest in floating point.")
                    return _packed_result(M, q, out, SOLVED, int(start[n + 2]), residual, note)
        if start[n + 1] == _RESUME_PATH:
            return _exact_finish(M, q, covering, out, first, int(start[n + 2]), max_iter, tol,
                                 start[:n].astype(np.int64).tolist(), int(start[n]),
                                 deadline=deadline)
        return _exact_finish(M, q, covering, out, first, pivots, max_iter, tol,
                             deadline=deadline)
    if status == SOLVED:
        # the point of the terminal basis in exact arithmetic, correctly rounded
        # (M_JJ z_J = -q_J, J its z variables): the answer the exact path gives
        if exact_point:
            z = out[:n]
        else:
            J = [int(v) - n for v in out[3 * n + 1:4 * n + 1] if n <= v < 2 * n]
            z = _exact.basis_point(M, q, J)
        if z is not None:
            out[:n] = z
            with np.errstate(over="ignore", invalid="ignore"):   # as above: the check decides
                out[n:2 * n] = M @ out[:n] + q
            residual = float(_violation(M, q, out[:n]))
            status = SOLVED if residual <= tol else BREAKDOWN
    note = (f"Pivoting met {_why(first)}; {steps} step{'s' if steps > 1 else ''} of the path "
            f"{'were' if steps > 1 else 'was'} decided in exact arithmetic, the rest in "
            f"floating point.")
    return _packed_result(M, q, out, status, pivots, residual, note)


def _why(handoff):
    return ("a lexicographic tie that floating point could not separate" if handoff == _HANDOFF_TIE
            else "a repeated basis (rounding had decided a tie wrongly)")


def _ray_or_unit_proof(M, q, ray):
    # (y, why): a Farkas vector from the ray (infeasibility_from_ray), else a
    # unit vector e_i (q_i < 0, row i of M <= 0: exact without arithmetic)
    y, why = infeasibility_from_ray(M, q, ray)
    if y is not None:
        return y, why
    i = int(unit_farkas(M, q))
    if i < 0:
        return None, why
    y = np.zeros(len(q))
    y[i] = 1.0
    cls = certify.copositive_plus_class(M)
    src = (f"M is copositive-plus ({cls}), so Lemke's theorem says the ray means infeasibility"
           if cls is not None else "M is of no certified class")
    return y, (f"Lemke ended on a secondary ray ({src}); `certificate` holds the unit vector e_{i}: "
               f"q_{i} = {q[i]:.3g} < 0 and row {i} of M is <= 0, so w_{i} = (M z)_{i} + q_{i} < 0 "
               f"for every z >= 0 (exact: no arithmetic involved).")


def _prove_secondary_ray(res, M, q, ray, pivots):
    verdict, maybe_psd = _screen_ray(M, q, ray)
    if verdict == 1:
        # a candidate (or a unit vector) is a Farkas vector, decided exactly in
        # compiled code (farkas_float); the vector and the words are made only
        # when someone reads them, by the same candidates in the same order
        res.status = INFEASIBLE
        return
    if verdict < 0 and not maybe_psd:
        # every candidate fails rigorously, and M is not PSD (where the exact
        # null-space projection could still find one): no proof, and the words
        # only when someone reads them
        res.status = SECONDARY_RAY
        return
    y, why = _ray_or_unit_proof(M, q, ray)
    res.status = INFEASIBLE if y is not None else SECONDARY_RAY
    if y is not None:
        res.certificate = y
    res.detail = f"{why} `ray` holds the direction (dz, dz0) (after {pivots} pivots)."


def _budget_result(M, q, handoff, pivots, steps):
    # the exact-arithmetic part spent EXACT_TIME_BUDGET: no answer, said so
    n = len(q)
    res = _LemkeResult(np.zeros(n), q.copy(), MAX_ITER, pivots,
                       float(lcp_violation(M, q, np.zeros(n))))
    res.detail = (f"Pivoting met {_why(handoff)}; the path's exact-arithmetic part stopped at "
                  f"its time budget ({EXACT_TIME_BUDGET:g} CPU s, "
                  f"moreau.lcp.lemke.EXACT_TIME_BUDGET) after {pivots} pivots"
                  f"{f' ({steps} decided exactly)' if steps else ''}, with no answer.")
    return res


def _exact_walk(M, q, covering, basis, entering, max_iter, pivots, deadline):
    # exact_lemke's path (the same pivots, the same end) one step at a time by
    # the compiled exact step (_modular.modular_step; the Python integers'
    # _exact.exact_step where its moduli do not reach), from the given basis
    # when the step accepts it (lexicographically positive for the data), else
    # afresh. Returns exact_lemke's tuple, z as floats correctly rounded, or
    # _exact.BUDGET (the budget) with the pivots made; on a secondary
    # ray, exact_lemke finishes from the ray's basis (it ends at once)
    n = len(q)
    d = np.ones(n) if covering is None else covering
    z0 = 2 * n
    P = _modular.primes()
    flags = np.empty(n)
    resumed = False
    b = None
    if basis is not None and entering is not None and z0 in basis:
        b = np.array(basis, dtype=np.int64)
        e = int(entering)
        first = _modular.modular_step(M, q, d, b, np.int64(e), P, flags)
        if first[0] == _modular.STEP_TOO_BIG:
            first = (_modular.STEP_REFUSED, -1) if _exact.exact_step(M, q, d, b, e) is None \
                else first
        resumed = first[0] != _modular.STEP_REFUSED
    if not resumed:
        if np.min(q) >= 0.0:
            return _exact.SOLVED, [0.0] * n, None, 0, False
        # z0 enters at the lexicographic minimum of (q_i, e_i) / d_i: the smallest
        # q_i / d_i (compared exactly), ties to the larger index, as exact_lemke
        ratios = [Fraction(float(q[i])) / Fraction(float(d[i])) for i in range(n)]
        r = 0
        for i in range(1, n):
            if ratios[i] <= ratios[r]:
                r = i
        b = np.arange(n, dtype=np.int64)
        b[r] = z0
        e = r + n
        pivots = 1
    while pivots < max_iter:
        if time.process_time() > deadline:
            return _exact.BUDGET, None, None, pivots, resumed
        outcome, leaving = _modular.modular_step(M, q, d, b, np.int64(e), P, flags)
        if outcome == _modular.STEP_TOO_BIG:
            step = _exact.exact_step(M, q, d, b, e)
            outcome = (_modular.STEP_REFUSED if step is None else
                       _modular.STEP_RAY if step[0] == "ray" else _modular.STEP_PIVOT)
            leaving = -1 if step is None or step[0] == "ray" else step[1]
        if outcome != _modular.STEP_PIVOT:
            # a ray (or, which the exact steps rule out, a refused basis): exact_lemke
            # from this basis ends the path and gives the ray
            st, zx, rayx, piv, again = _exact.exact_lemke(M, q, covering, basis=b.tolist(),
                                                          entering=e, max_iter=max_iter,
                                                          pivots=pivots, deadline=deadline)
            # (pivots counted as the walk counts them; afresh, which the exact steps
            # rule out, from exact_lemke's start)
            return st, zx, rayx, piv, resumed and again
        pivots += 1
        b[b == leaving] = e
        if leaving == z0:
            J = np.array([v - n for v in b if n <= v < z0], dtype=np.int64)
            z = np.zeros(n)
            if not _modular.exact_point(M, q, J, P, z, np.bool_(True)):
                z = _exact.basis_point(M, q, J.tolist())
                if z is None:
                    # singular, which a terminal basis is not, or outside the floats' range
                    return _exact.SOLVED, None, None, pivots, resumed
            return _exact.SOLVED, list(z), None, pivots, resumed
        e = leaving + n if leaving < n else leaving - n
    return _exact.MAX_ITER, None, None, pivots, resumed


def _exact_finish(M, q, covering, out, handoff, pivots, max_iter, tol, basis=None, entering=None,
                  deadline=None):
    # the path is finished in exact arithmetic (moreau.lcp._exact) from the
    # basis the floating-point path handed over (None: afresh), or afresh when
    # that basis is not lexicographically positive for the caller's data, and
    # its end is judged on the caller's data; past the deadline (process time)
    # the call ends without an answer (_budget_result)
    n = len(q)
    if deadline is None:
        deadline = time.process_time() + EXACT_TIME_BUDGET
    if n >= _WALK_MIN_N:
        st, zx, rayx, piv, resumed = _exact_walk(M, q, covering, basis, entering, max_iter,
                                                 pivots, deadline)
        if st == _exact.BUDGET or (st == _exact.MAX_ITER and zx is None):
            if st == _exact.BUDGET:
                return _budget_result(M, q, handoff, piv if resumed else pivots + piv, 0)
            res = _LemkeResult(np.zeros(n), q.copy(), MAX_ITER, piv,
                               float(lcp_violation(M, q, np.zeros(n))))
            res.detail = (f"Pivoting met {_why(handoff)} and was walked on in exact arithmetic "
                          f"to the pivot limit. {_DETAIL[MAX_ITER]} (after {piv} pivots)")
            return res
    else:
        st, zx, rayx, piv, resumed = _exact.exact_lemke(M, q, covering, basis=basis,
                                                         entering=entering, max_iter=max_iter,
                                                         pivots=pivots, deadline=deadline)
        if st == _exact.BUDGET:
            return _budget_result(M, q, handoff, piv if resumed else pivots + piv, 0)
    total = piv if resumed else pivots + piv
    try:
        if zx is None:
            raise OverflowError
        z = np.array([float(v) for v in zx]) if n else np.zeros(0)
    except OverflowError:
        # the exact point lies outside the range of doubles
        res = _LemkeResult(np.zeros(n), q.copy(), BREAKDOWN, total,
                           float(lcp_violation(M, q, np.zeros(n))))
        res.detail = ("Pivoting was finished in exact arithmetic, but its end point lies outside "
                      "the range of floating-point numbers.")
        return res
    w = M @ z + q
    residual = float(lcp_violation(M, q, z))
    why = ("a lexicographic tie that floating point could not separate" if handoff == _HANDOFF_TIE
           else "a repeated basis (rounding had decided a tie wrongly)")
    where = (f"from the basis reached after {pivots} floating-point pivots" if resumed
             else f"afresh (the basis after {pivots} floating-point pivots was not "
                  f"lexicographically positive)")
    note = f"Pivoting met {why} and was finished in exact arithmetic {where}."
    if st == _exact.SOLVED:
        status = SOLVED if residual <= tol else BREAKDOWN
        res = _LemkeResult(z, w, status, total, residual)
        res.detail = note if status == SOLVED else (
            f"{note} The exact solution, rounded to floats, fails the check on the data "
            f"(violation {residual:.3g} > tol = {tol:.3g}).")
        return res
    if st == _exact.MAX_ITER:
        res = _LemkeResult(z, w, MAX_ITER, total, residual)
        res.detail = f"{note} {_DETAIL[MAX_ITER]} (after {total} pivots)"
        return res
    res = _LemkeResult(z, w, SECONDARY_RAY, total, residual)
    top = max(abs(v) for v in rayx)
    # a direction: scaled to a largest entry of 1 before rounding, it stays finite
    ray = np.array([float(v / top) for v in rayx])
    out[2 * n:3 * n + 1] = ray
    res.__dict__["_ray"] = (out, M, q)
    _prove_secondary_ray(res, M, q, ray, total)
    res.detail = f"{note} {res.detail}"
    return res


# the compiled functions freeze FARKAS_TOL from certify.py and link _certified.py
# and _modular.py: their on-disk cache must follow those files too (numba only
# checks this one)
_jit_cache.bind_cache_to_sources(
    [f for f in list(globals().values()) if hasattr(f, "py_func") and hasattr(f, "_cache")
     and getattr(f.py_func, "__module__", None) == __name__],
    (__file__, certify.__file__, _certified.__file__, _modular.__file__))
