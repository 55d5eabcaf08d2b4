"""Mixed linear complementarity problems: free variables with equations, and an LCP.

Find ``x = (u, z)``, ``u`` free (``k`` entries) and ``z >= 0``, with::

    A u + C z + a  = 0
    w = D u + B z + b >= 0,   z.w = 0

that is ``w_full = M x + q`` with ``M = [[A, C], [D, B]]``, ``q = (a, b)``,
its first ``k`` rows equations (Cottle, Pang and Stone 1992, Sec. 1.5; the
form of Siconos's ``MixedLinearComplementarityProblem``). The velocity-level
contact problem with bilateral joints is one (Anitescu and Potra 1997):
``u`` the joints' impulses, ``z`` the friction LCP's variables.

:func:`solve_mlcp` eliminates the equations: with ``A`` regular,
``u = -A^-1 (a + C z)`` and ``z`` solves ``LCP(B - D A^-1 C, b - D A^-1 a)``
(the Schur complement of ``A``), solved by :func:`moreau.lcp.solve_lcp`.
The answer is certified on the given ``(M, q)`` (:func:`mlcp_violation`).
A singular ``A`` is never divided by: :func:`equality_block` finds its rank
by an SVD and raises :class:`RankDeficientError` naming the dependent rows.
"""

import numpy as np

from ..errors import IllPosedError, InputError
from . import solve_lcp
from ._result import BREAKDOWN, SOLVED, STATUS_MESSAGES
from .lemke import DEFAULT_TOL

__all__ = ["RANK_RTOL", "RankDeficientError", "EqualityBlock", "equality_block", "MLCPResult",
           "solve_mlcp", "mlcp_violation", "mlcp_residual"]

#: a singular value of the equality block at most this times the largest counts as zero.
#: The SVD's singular values carry absolute errors of about n eps times the largest
#: (Golub and Van Loan 2013, Sec. 8.6), so this leaves three to four orders above
#: rounding; for a Delassus block G M^-1 G^T it refuses joint Jacobians G whose
#: condition number passes about 1e6.
RANK_RTOL = 1e-12

_EPS = float(np.finfo(float).eps)


class RankDeficientError(IllPosedError):
    """The equality rows of a mixed LCP are linearly dependent.

    Redundant constraints (their multipliers are not unique) or inconsistent
    ones (no solution); the message says which rows depend on each other and
    which case it is.

    Attributes
    ----------
    rank, n_eq : int
        Rank found and number of equality rows.
    dependent : list of list of int
        For each null direction, the rows with a significant coefficient in it.
    singular_values : ndarray
        Of the equality block, decreasing.
    consistent : bool or None
        True: the right-hand side satisfies the dependency (redundant rows);
        False: it does not (inconsistent rows); None: the dependency involves
        the complementarity variables, so it depends on them.
    """

    def __init__(self, message, rank, n_eq, dependent, singular_values, consistent):
        super().__init__(message)
        self.rank, self.n_eq, self.dependent = rank, n_eq, dependent
        self.singular_values, self.consistent = singular_values, consistent


class EqualityBlock:
    """A regular equality block ``A``, its rank checked (from :func:`equality_block`)."""

    __slots__ = ("A", "singular_values")

    def __init__(self, A, singular_values):
        self.A, self.singular_values = A, singular_values

    def solve(self, rhs):
        """``A^-1 rhs`` (``rhs`` a vector or the columns of a matrix), by LU with partial pivoting."""
        if self.A.shape[0] == 0:
            return np.zeros(np.shape(rhs))
        # (numpy's LAPACK gesv: scipy.linalg.lu_solve cost 10 ms a call here, against 5 us)
        return np.linalg.solve(self.A, rhs)

    @property
    def condition(self):
        """2-norm condition number of ``A``."""
        s = self.singular_values
        return float(s[0] / s[-1]) if s.size else 1.0


def equality_block(A, rhs=None, coupling=None, rtol=RANK_RTOL, label="equality rows"):
    """Factor the equality block ``A``, or name its dependent rows.

    Parameters
    ----------
    A : ndarray, shape (k, k)
    rhs : ndarray, shape (k,), optional
        ``a``, to tell redundant (consistent) from inconsistent rows.
    coupling : ndarray, shape (k, n), optional
        ``C``, the rows' coupling to the complementarity variables.
    rtol : float
        Singular values ``<= rtol`` times the largest count as zero
        (:data:`RANK_RTOL`).
    label : str
        What the rows are called in the message.

    Returns
    -------
    EqualityBlock

    Raises
    ------
    RankDeficientError
        ``A`` has rank below ``k``.

    Examples
    --------
    Two copies of one joint:

    >>> try:
    ...     equality_block(np.array([[2.0, 2.0], [2.0, 2.0]]), rhs=np.array([1.0, 1.0]))
    ... except RankDeficientError as err:
    ...     print(err.rank, err.dependent, err.consistent)
    ...     print(str(err).split("), ")[1])
    1 [[0, 1]] True
    null direction 0.707 r0 - 0.707 r1 = 0; the right-hand side satisfies it: redundant rows, whose multipliers are not unique
    """
    k = A.shape[0]
    if k == 0:
        return EqualityBlock(A, np.zeros(0))
    if not np.all(np.isfinite(A)):
        raise InputError(f"the {label}' block must be finite (no NaN or inf)")
    U, s, Vt = np.linalg.svd(A)
    smax = float(s[0])
    cut = rtol * smax
    rank = int(np.sum(s > cut)) if smax > 0.0 else 0
    if rank == k:
        return EqualityBlock(A, s)
    # left null vectors y (y^T A = 0): the dependencies among the rows
    Y = U[:, rank:]
    dependent, terms = [], []
    for j in range(Y.shape[1]):
        y = Y[:, j]
        rows = [int(i) for i in np.flatnonzero(np.abs(y) > 1e-3 * np.max(np.abs(y)))]
        y = y * np.sign(y[rows[0]])
        dependent.append(rows)
        terms.append(f"{y[rows[0]]:.3g} r{rows[0]}" + "".join(
            f" {'-' if y[i] < 0 else '+'} {abs(y[i]):.3g} r{i}" for i in rows[1:]))
    consistent = None
    scale = smax + (float(np.max(np.abs(rhs))) if rhs is not None and rhs.size else 0.0)
    if rhs is not None:
        tied = coupling is None or coupling.size == 0 or \
            float(np.max(np.abs(Y.T @ coupling))) <= 1e3 * _EPS * max(scale, 1.0) * k
        if tied:
            consistent = bool(float(np.max(np.abs(Y.T @ rhs))) <= 1e3 * _EPS * max(scale, 1.0) * k)
    rows = sorted({i for d in dependent for i in d})
    ratio = float(s[-1] / smax) if smax > 0.0 else 0.0
    verdict = {True: "; the right-hand side satisfies it: redundant rows, whose multipliers "
                     "are not unique",
               False: "; the right-hand side violates it: inconsistent rows, with no solution",
               None: "" if rhs is None else "; it involves the complementarity variables"}[consistent]
    raise RankDeficientError(
        f"{label} {rows} are linearly dependent: rank {rank} of {k} (SVD; singular values "
        f"<= {rtol:.3g} times the largest count as zero; the smallest is {ratio:.3g} times "
        f"the largest), null direction{'s' if len(terms) > 1 else ''} "
        + "; ".join(f"{t} = 0" for t in terms) + verdict,
        rank, k, dependent, s, consistent)


def _split(M, q, k):
    return M[:k, :k], M[:k, k:], M[k:, :k], M[k:, k:], q[:k], q[k:]


def mlcp_violation(M, q, n_eq, x):
    """How far ``x`` is from solving the MLCP, in units fixed by the data alone.

    The measure of :func:`moreau.lcp.lcp_violation` extended to the
    equations: ``max(max_i<k |w_i|, max_i>=k |min(m z_i, w_i)|) / s`` with
    ``s = max|q|`` and ``m = max|M|`` (each 1 when 0), at its worst over a
    bound ``(n + 2) eps (sum_j |M_ij x_j| + |q_i|)`` on the rounding of
    ``w = M x + q``. ``inf`` when anything is not finite.

    Examples
    --------
    >>> M = np.array([[2.0, 1.0], [1.0, 1.0]])
    >>> float(mlcp_violation(M, np.array([-2.0, 1.0]), 1, np.array([1.0, 0.0]))) < 1e-14
    True
    >>> round(float(mlcp_violation(M, np.array([-2.0, 1.0]), 1, np.array([0.5, 0.0]))), 12)
    0.5
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    x = np.asarray(x, dtype=float)
    n = q.size
    if n == 0:
        return 0.0
    if not (np.all(np.isfinite(M)) and np.all(np.isfinite(q)) and np.all(np.isfinite(x))):
        return np.inf
    w = M @ x + q
    r = (n + 2) * _EPS * (np.abs(M) @ np.abs(x) + np.abs(q))
    mmax = float(np.max(np.abs(M))) or 1.0
    qs = float(np.max(np.abs(q))) or 1.0
    eq = np.abs(w[:n_eq]) + r[:n_eq]
    a = mmax * x[n_eq:]
    wc, rc = w[n_eq:], r[n_eq:]
    comp = np.maximum(np.abs(np.minimum(a, wc - rc)), np.abs(np.minimum(a, wc + rc)))
    worst = max(float(np.max(eq, initial=0.0)), float(np.max(comp, initial=0.0)))
    return worst / qs if np.isfinite(worst) else np.inf


def mlcp_residual(M, q, n_eq, x):
    """Residual of ``x`` relative to the size of the answer (a diagnostic).

    ``max(max_i<k |w_i|, max_i>=k |min(z_i, w_i)|) / (1 + max|q| + max|M|
    max|x|)``: :func:`moreau.lcp.lcp_residual` with the equations' rows.
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return 0.0
    w = M @ x + q
    num = max(float(np.max(np.abs(w[:n_eq]), initial=0.0)),
              float(np.max(np.abs(np.minimum(x[n_eq:], w[n_eq:])), initial=0.0)))
    return num / (1.0 + float(np.max(np.abs(q))) + float(np.max(np.abs(M))) * float(np.max(np.abs(x))))


class MLCPResult:
    """Outcome of :func:`solve_mlcp`.

    Attributes
    ----------
    x : ndarray, shape (n,)
        ``(u, z)``: the free variables, then the complementarity ones.
    w : ndarray, shape (n,)
        ``M x + q``.
    n_eq : int
    status : int
        A code of :data:`moreau.lcp.STATUS_MESSAGES` (0: solved).
    pivots : int
        Of the LCP on the Schur complement.
    residual : float
        :func:`mlcp_violation` on the given data (the certified measure).
    method : str
        ``"schur+<LCP method>"``.
    lcp : LCPResult
        The Schur complement's LCP result.
    detail : str
    """

    __slots__ = ("x", "w", "n_eq", "status", "pivots", "residual", "method", "lcp", "detail")

    def __init__(self, x, w, n_eq, status, pivots, residual, method, lcp, detail=""):
        self.x, self.w, self.n_eq, self.status = x, w, n_eq, status
        self.pivots, self.residual, self.method, self.lcp, self.detail = pivots, residual, method, lcp, detail

    @property
    def u(self):
        return self.x[:self.n_eq]

    @property
    def z(self):
        return self.x[self.n_eq:]

    @property
    def success(self):
        return self.status == SOLVED

    @property
    def message(self):
        text = STATUS_MESSAGES.get(self.status, f"Unknown status {self.status}.")
        return f"{text} {self.detail}" if self.detail else text

    def __repr__(self):
        return (f"MLCPResult(status={self.status}, success={self.success}, method={self.method!r}, "
                f"pivots={self.pivots}, residual={self.residual:.3g}, n_eq={self.n_eq}, n={self.x.size})")


def schur_complement(block, C, D, B, a, b):
    """``(B - D A^-1 C, b - D A^-1 a)`` with ``A`` factored in ``block`` (:class:`EqualityBlock`)."""
    if C.shape[0] == 0:
        return B.copy(), b.copy()
    AiC = block.solve(C)
    Aia = block.solve(a)
    return B - D @ AiC, b - D @ Aia


def free_part(block, C, a, z, A=None):
    """``u = -A^-1 (a + C z)``, with one step of iterative refinement on ``A`` itself."""
    rhs = -(a + C @ z)
    u = block.solve(rhs)
    if u.size:
        u = u + block.solve(rhs - block.A @ u)
    return u


def solve_mlcp(M, q, n_eq, *, method="lemke", max_iter=None, tol=None, rank_rtol=RANK_RTOL,
               friction=None):
    """Solve the mixed LCP whose first ``n_eq`` variables are free and rows equations.

    Parameters
    ----------
    M : array_like, shape (n, n)
    q : array_like, shape (n,)
    n_eq : int
        Number of free variables (and equation rows), ``0 <= n_eq <= n``.
    method : {"lemke", "qp", "auto"}
        The LCP method on the Schur complement (:func:`moreau.lcp.solve_lcp`).
    max_iter : int, optional
    tol : float, optional
        Bound on :func:`mlcp_violation` for a solved status (default 1e-9,
        Lemke's).
    rank_rtol : float
        Rank tolerance of the equality block (:data:`RANK_RTOL`).
    friction : FrictionLayout, optional
        Layout of the complementarity part when it is a friction LCP (for
        the ``"qp"`` method).

    Returns
    -------
    MLCPResult

    Raises
    ------
    InputError
        Shapes, ``n_eq`` out of range, non-finite data.
    RankDeficientError
        The equality block ``A = M[:n_eq, :n_eq]`` is singular (rank by SVD).

    Examples
    --------
    ``u + z = 1``, ``w = u + 2 z - 0.5 >= 0``: ``z = 0`` gives ``u = 1``, ``w = 0.5``.

    >>> r = solve_mlcp(np.array([[1.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -0.5]), 1)
    >>> r.success, r.u.tolist(), r.z.tolist()
    (True, [1.0], [0.0])
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise InputError(f"`M` must be a square 2-D array, got shape {M.shape}")
    n = M.shape[0]
    if q.shape != (n,):
        raise InputError(f"`q` must have shape ({n},) like `M`, got {q.shape}")
    if isinstance(n_eq, (bool, np.bool_)) or not isinstance(n_eq, (int, np.integer)) or not 0 <= n_eq <= n:
        raise InputError(f"`n_eq` must be an integer in [0, {n}], got {n_eq!r}")
    if not (np.all(np.isfinite(M)) and np.all(np.isfinite(q))):
        raise InputError("`M` and `q` must be finite (no NaN or inf)")
    tol = DEFAULT_TOL if tol is None else float(tol)
    A, C, D, B, a, b = _split(M, q, n_eq)
    block = equality_block(A, rhs=a, coupling=C, rtol=rank_rtol)
    BS, bS = schur_complement(block, C, D, B, a, b)
    r = solve_lcp(BS, bS, method=method, max_iter=max_iter, friction=friction)
    z = np.asarray(r.z, dtype=float)
    u = free_part(block, C, a, z)
    x = np.concatenate([u, z])
    viol = mlcp_violation(M, q, n_eq, x)
    name = f"schur+{r.method}"
    if r.success and viol <= tol:
        return MLCPResult(x, M @ x + q, n_eq, SOLVED, r.pivots, viol, name, r)
    if r.success:
        return MLCPResult(x, M @ x + q, n_eq, BREAKDOWN, r.pivots, viol, name, r,
                          f"The Schur complement's LCP was solved, but the point fails the check "
                          f"on the given data: violation {viol:.3g} > tol {tol:.3g} (the equality "
                          f"block's condition number is {block.condition:.3g}).")
    return MLCPResult(x, M @ x + q, n_eq, r.status, r.pivots, viol, name, r,
                      f"On the Schur complement of the equality block: {r.message}")
