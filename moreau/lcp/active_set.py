"""The primal-dual active-set method for a sparse LCP whose matrix is an M-matrix.

Solves ``0 <= w = A z + q  _|_  z >= 0`` for a sparse ``A`` (scipy) by the
primal-dual active-set method, a semismooth Newton method on ``min(z, A z +
q) = 0`` (M. Hintermüller, K. Ito, K. Kunisch, *The primal-dual active set
strategy as a semismooth Newton method*, SIAM J. Optim. 13 (2003) 865-888):
guess the pressed set ``P`` (every row at first), solve ``A_PP z_P = -q_P`` by a sparse LU with
``z = 0`` off ``P``, take ``P = {z - (A z + q) > 0}``, repeat until ``P``
repeats. For a nonsingular M-matrix ``A`` (positive diagonal, off-diagonal
entries ``<= 0``, ``A^-1 >= 0``; a chain of bodies' Delassus matrix on a
line is one) the iterates are monotone from the second on, whatever the
first guess, and the method ends, with the exact solution to rounding,
within ``n + 2`` solves (Hintermüller, Ito and Kunisch's theorem 3.2); each
costs a sparse LU, for a banded ``A`` linear in ``n``. The first guess,
every row pressed, is the answer of a chain struck at once (every contact
presses), which then takes one solve; starting from the rows with
``q < 0`` instead, the pressed set grows by one contact a solve along the
chain. Any other matrix may cycle: a solve that has not ended within
``n + 2`` steps raises.

The residual returned is the natural map on the caller's data,
``||min(z, A z + q)||_2 / (1 + ||q||_2)``, recomputed on the ``z`` returned.
"""

import numpy as np
import scipy.sparse as sps
from scipy.sparse.linalg import splu

from .._validate import finite_array
from ..errors import InputError, LCPError

__all__ = ["solve_active_set"]


def solve_active_set(A, q):
    """``(z, residual, solves)`` of ``0 <= A z + q _|_ z >= 0``, ``A`` a sparse M-matrix.

    Parameters
    ----------
    A : sparse matrix or array_like, shape (n, n)
        A nonsingular M-matrix (module docstring).
    q : array_like, shape (n,)

    Returns
    -------
    z : ndarray, shape (n,)
    residual : float
        ``||min(z, A z + q)|| / (1 + ||q||)``, recomputed on ``z``.
    solves : int
        Sparse solves taken.

    Raises
    ------
    InputError
        Bad shapes or values.
    LCPError
        No end within ``n + 2`` steps, or a singular block (``A`` is not a
        nonsingular M-matrix).

    Examples
    --------
    >>> z, res, solves = solve_active_set([[2.0, -1.0], [-1.0, 2.0]], [-1.0, 1.0])
    >>> z.tolist(), res, solves
    ([0.5, 0.0], 0.0, 2)
    """
    q = finite_array("q", q, ndim=1)
    A = sps.csr_array(A, dtype=float)
    n = q.size
    if A.shape != (n, n):
        raise InputError(f"`A` must be square with the size of `q` ({n}), got {A.shape}")
    if not np.all(np.isfinite(A.data)):
        raise InputError("`A` must be finite")
    z = np.zeros(n)
    pressed = np.ones(n, dtype=bool)
    seen = None
    solves = 0
    while seen is None or not np.array_equal(pressed, seen):
        if solves > n + 2:
            raise LCPError(f"the active-set method did not end within {n + 2} steps (`A` is "
                           "not an M-matrix)")
        seen = pressed
        z = np.zeros(n)
        idx = np.flatnonzero(pressed)
        if idx.size:
            try:
                z[idx] = splu(sps.csc_array(A[idx][:, idx])).solve(-q[idx])
            except RuntimeError as exc:         # superlu: a singular principal block
                raise LCPError(f"the active-set method met a singular block of `A` ({exc}); "
                               "`A` is not a nonsingular M-matrix") from None
        pressed = z - (A @ z + q) > 0.0
        solves += 1
    z = np.maximum(z, 0.0)
    residual = float(np.linalg.norm(np.minimum(z, A @ z + q)) / (1.0 + np.linalg.norm(q)))
    return z, residual, solves
