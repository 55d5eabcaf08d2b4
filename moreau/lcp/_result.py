"""The result object and status codes shared by every LCP method.

Every method in :mod:`moreau.lcp` returns an :class:`LCPResult`. Status codes
are small integers so that compiled code (the Lemke kernel, the time stepper)
can pass them around without Python objects; :data:`STATUS_MESSAGES` turns
them into text.
"""

import numpy as np

from ._certified import lcp_arrays, lcp_violation

__all__ = [
    "LCPResult",
    "STATUS_MESSAGES",
    "SOLVED",
    "SECONDARY_RAY",
    "MAX_ITER",
    "BREAKDOWN",
    "INVALID_INPUT",
    "SOLVER_FAILED",
    "NOT_APPLICABLE",
    "INFEASIBLE",
    "NO_SOLUTION",
    "lcp_residual",
    "lcp_violation",
]

#: a solution was found and passed the residual check
SOLVED = 0
#: Lemke's path ended on a secondary ray: no solution was found (``ray`` holds it)
SECONDARY_RAY = 1
#: the pivot or iteration limit was reached
MAX_ITER = 2
#: numerical breakdown: an unresolvable lexicographic tie, overflow, or a
#: terminal point that failed the residual check
BREAKDOWN = 3
#: the data were rejected (non-finite entries, non-positive covering vector);
#: only compiled callers see this, the Python entry points raise instead
INVALID_INPUT = 4
#: the QP backend returned no usable solution
SOLVER_FAILED = 5
#: the method has no formulation for this matrix (e.g. ``"qp"`` on a
#: non-monotone LCP without a friction layout)
NOT_APPLICABLE = 6
#: the LCP has no solution and the result carries the proof: a Farkas vector
#: ``y >= 0`` with ``M^T y <= 0`` and ``q.y < 0`` in ``certificate``
INFEASIBLE = 7
#: the LCP has no solution, shown by visiting every complementary piece in
#: exact arithmetic (``"auto"``'s enumeration); it may have feasible points,
#: so there is no Farkas vector (``certificate`` is None)
NO_SOLUTION = 8

STATUS_MESSAGES = {
    SOLVED: "Solution found.",
    SECONDARY_RAY: "Secondary ray: the complementary path left to infinity without reaching a solution.",
    MAX_ITER: "Iteration limit reached before a solution was found.",
    BREAKDOWN: "Numerical breakdown: the pivoting could not be carried on reliably.",
    INVALID_INPUT: "Invalid input: non-finite data or a non-positive covering vector.",
    SOLVER_FAILED: "The QP backend returned no usable solution.",
    NOT_APPLICABLE: "The method has no formulation for this problem.",
    INFEASIBLE: "Infeasible: no z >= 0 has M z + q >= 0, so the LCP has no solution.",
    NO_SOLUTION: "No solution: every complementary piece was shown empty in exact arithmetic.",
}


def lcp_residual(M, q, z, w=None):
    """Complementarity residual relative to the size of the answer (a diagnostic).

    Parameters
    ----------
    M, q, z
        As for :func:`lcp_violation`.
    w : ndarray, shape (n,), optional
        ``M @ z + q``; computed when not given.

    Returns
    -------
    float
        ``max_i |min(z_i, w_i)| / (1 + max|q| + max|M| * max|z|)``.

    Notes
    -----
    The denominator grows with ``z``, so this number is small for any point
    far enough out, solution or not (on ``M = [[1, -1], [-1, 1]]``, ``q =
    -1``, ``z = (2e9, 2e9)`` gives 2.3e-10 while ``w = -1``). It measures
    the rounding in ``M @ z + q`` and is kept as a diagnostic (the time
    stepper reports it); success is decided by :func:`lcp_violation`.

    Examples
    --------
    >>> import numpy as np
    >>> M = np.array([[2.0, 1.0], [1.0, 2.0]])
    >>> q = np.array([-1.0, -1.0])
    >>> float(lcp_residual(M, q, np.array([1/3, 1/3]))) < 1e-15
    True
    """
    M, q, z = lcp_arrays(M, q, z)
    if z.size == 0:
        return 0.0
    if w is None:
        w = M @ z + q
    num = float(np.max(np.abs(np.minimum(z, w))))
    scale = 1.0 + float(np.max(np.abs(q))) + float(np.max(np.abs(M))) * float(np.max(np.abs(z)))
    return num / scale


class LCPResult:
    """Outcome of one LCP solve: find ``z >= 0`` with ``w = M z + q >= 0``, ``z.w = 0``.

    Attributes
    ----------
    z, w : ndarray, shape (n,)
        The (candidate) solution and ``w = M @ z + q``. Always finite: on a
        failure they hold the last point the method reached.
    status : int
        One of the codes in :data:`STATUS_MESSAGES` (0 means solved).
    success : bool
        ``status == 0``.
    message : str
        What happened, in words.
    pivots : int
        Pivots (Lemke) or QP solves (QP methods) performed.
    residual : float
        The certified violation :func:`lcp_violation` of ``z``: a solved
        status means ``residual <= tol``.
    method : str
        The method that produced ``z`` (``"lemke"`` or ``"qp"``).
    path : tuple of str
        Every method that ran, in order; ``("lemke", "qp")`` when ``"auto"``
        fell back.
    ray : ndarray or None
        On a secondary ray, the direction ``(dz, dz0)`` of length ``n + 1``
        along which ``(z, z0)`` leaves: ``z + t dz`` with artificial level
        ``z0 + t dz0`` stays feasible and complementary for all ``t >= 0``
        in the augmented problem ``w = M z + q + d z0``.
    certificate : ndarray or None
        With status :data:`INFEASIBLE`, a Farkas vector ``y``: ``y >= 0``,
        ``M^T y <= 0``, ``q.y < 0``, ``max(y) = 1``. For any ``z >= 0``,
        ``y.(M z + q) = (M^T y).z + q.y < 0``, so some ``w_i`` is negative.

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.lcp import solve_lcp
    >>> res = solve_lcp(np.eye(2), np.array([-1.0, 2.0]))
    >>> res.success, res.z.tolist()
    (True, [1.0, 0.0])
    """

    # the hot fields are slots; the rarely set ones live in __dict__ only
    # when set and otherwise fall back to the class defaults below, which
    # keeps construction cheap on the per-time-step path
    __slots__ = ("z", "w", "status", "pivots", "residual", "method", "__dict__")

    ray = None
    certificate = None
    detail = ""
    _path = None

    def __init__(self, z, w, status, pivots, residual, method, path=None, ray=None, detail=""):
        self.z = z
        self.w = w
        self.status = status
        self.pivots = pivots
        self.residual = residual
        self.method = method
        if path is not None:
            self._path = tuple(path)
        if ray is not None:
            self.ray = ray
        if detail:
            self.detail = detail

    @property
    def path(self):
        return (self.method,) if self._path is None else self._path

    @path.setter
    def path(self, value):
        self._path = tuple(value)

    @property
    def success(self):
        return self.status == SOLVED

    @property
    def fallback_used(self):
        """True when ``"auto"`` had to fall back from Lemke to the QP method."""
        return len(self.path) > 1

    @property
    def message(self):
        text = STATUS_MESSAGES.get(self.status, f"Unknown status {self.status}.")
        if self.detail:
            text = f"{text} {self.detail}"
        return text

    def check(self, M, q, tol=1e-9):
        """Certify ``z`` against ``(M, q)`` afresh: :func:`lcp_violation` ``<= tol``.

        Parameters
        ----------
        M : array_like, shape (n, n)
        q : array_like, shape (n,)
        tol : float
            Bound on the violation.

        Returns
        -------
        bool
            True when ``z`` solves the LCP to within ``tol``.
        """
        return lcp_violation(M, q, self.z) <= tol

    def __repr__(self):
        return (
            f"LCPResult(status={self.status}, success={self.success}, method={self.method!r}, "
            f"pivots={self.pivots}, residual={self.residual:.3g}, n={len(self.z)})"
        )
