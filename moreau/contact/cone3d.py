r"""The spatial Coulomb friction problem, two ways: a polyhedral LCP and the exact cone.

The problem (FCLib's form; Acary, Brémond and Huber 2018, "On solving
contact problems with Coulomb friction: formulations and numerical
comparisons"; Acary, Brémond, Koziara and Pérignon 2014, FCLib, INRIA
RT-0444): given the Delassus matrix ``W`` (``3nc x 3nc``, symmetric
positive semidefinite), the free velocity ``q`` (``3nc``) and the friction
coefficients ``mu`` (``nc``), every contact ``i`` owning the rows
``3i, 3i+1, 3i+2`` in the order ``[N, T1, T2]``, find the impulse ``r`` and
the velocity ``u = W r + q`` with, per contact,

.. math::

    K_i = \{ r : |r_T| \le \mu_i r_N \} \ni r_i, \qquad
    \hat u_i = u_i + (\mu_i |u_{T,i}|, 0, 0) \in K_i^*, \qquad
    r_i \cdot \hat u_i = 0,

with the dual cone ``K* = {u : mu |u_T| <= u_N}`` (De Saxcé's modified
velocity ``û`` turns the Coulomb law into a cone complementarity problem).
Per contact this reads: take-off (``r = 0``, ``u_N >= 0``), stick
(``u = 0``, ``r`` in ``K``) or slip (``u_N = 0``, ``|r_T| = mu r_N`` and
``r_T = -mu r_N u_T / |u_T|``).

How close ``r`` is to a solution is measured by the natural map of that
formulation, on the caller's data,

.. math::

    F(r) = r - \mathrm{proj}_K\bigl(r - \hat u(r)\bigr), \qquad
    \texttt{residual} = \|F(r)\|_2,

which vanishes exactly at the solutions (:func:`cone_residual`). It adds an
impulse to a velocity, so ``W`` and ``q`` should be in well-scaled units
(``W`` of order one); a solver stops when ``residual <= tol * ||q||``.

Two solvers
-----------
:func:`solve_polyhedral`
    The cone ``K`` replaced by the pyramid spanned by ``d`` directions
    (Stewart and Trinkle 1996; Anitescu and Potra 1997), a linear
    complementarity problem solved by :func:`moreau.lcp.solve_lcp` (Lemke,
    then what ``method="auto"`` tries, certified on the LCP's data). The
    derivation is in :func:`build_polyhedral_lcp`.
:func:`solve_exact`
    The round cone: projected Gauss–Seidel over contacts, each contact's
    3x3 problem solved exactly (:func:`local_solve`: take-off, stick, or
    slip with the sliding angle found by bracketing and bisection), then a
    nonsmooth Newton polish on the Alart–Curnier function; certified by the
    natural map above, with status ``"not converged"`` and the true
    residual when the budget ran out.

Rolling friction is left out. Torsional (drilling) friction coupled with
sliding, Coulomb–Contensou's law, has its own solver for contacts of four
rows, :func:`solve_exact_contensou` (the ellipsoid of
:mod:`moreau.model.space` as a round cone with three tangential rows,
:func:`project_contensou` its projection); the other solvers take three
rows a contact.

Examples
--------
A sphere (mass 1, radius 1, ``I = 2/5``) pressed on a plane and sliding:
its Delassus matrix is ``diag(1, 7/2, 7/2)``.

>>> import numpy as np
>>> W = np.diag([1.0, 3.5, 3.5]); q = np.array([-1.0, 3.0, 4.0])
>>> sol = solve_exact(W, q, 0.5)
>>> sol.status, np.round(sol.r, 12).tolist()
('converged', [1.0, -0.3, -0.4])
>>> poly = solve_polyhedral(W, q, 0.5, d=8)
>>> poly.status, round(float(poly.r[0]), 12)
('converged', 1.0)
"""

import math

import numpy as np
from numba import njit

from .._validate import finite_array
from ..errors import InputError
from ..lcp import STATUS_MESSAGES, solve_lcp

__all__ = [
    "ConeSolution",
    "check_cone_problem",
    "project_cone",
    "cone_residual",
    "facet_directions",
    "PolyhedralLCP",
    "build_polyhedral_lcp",
    "solve_polyhedral",
    "polyhedral_one_contact",
    "ONE_CONTACT_TOL",
    "local_solve",
    "solve_exact",
    "solve_cone",
    "exact_gauss_seidel",
    "exact_gauss_seidel_into",
    "exact_newton_polish",
    "natural_map_sq",
    "project_contensou",
    "local_solve_contensou",
    "check_block_problem",
    "solve_exact_contensou",
    "contensou_gauss_seidel",
    "CONVERGED",
    "NOT_CONVERGED",
]

#: status of a solution whose residual passed the stop test on the caller's data
CONVERGED = "converged"
#: status when the budget ran out first (the result holds the true residual)
NOT_CONVERGED = "not converged"

#: relative tolerance on the symmetry of ``W``
_SYM_RTOL = 1e-10


class ConeSolution:
    """The answer of a spatial friction solver.

    Attributes
    ----------
    r, u : ndarray, shape (3 nc,)
        Impulse and velocity ``u = W r + q``, per contact ``[N, T1, T2]``.
    status : str
        :data:`CONVERGED`, :data:`NOT_CONVERGED`, or (polyhedral) the LCP's
        message when it was not solved.
    success : bool
        ``status == "converged"``.
    residual : float
        The exact cone's natural-map residual ``||F(r)||`` on the caller's
        data (:func:`cone_residual`); for the polyhedral solver it measures
        the faceting error too, and does not vanish.
    relative_residual : float
        ``residual / ||q||`` (``residual`` itself when ``q = 0``).
    iterations : dict
        Work done: ``{"sweeps": .., "newton": ..}`` or ``{"pivots": ..}``.
    method : str
        ``"exact"`` or ``"polyhedral-d"`` with the number of directions.
    detail : str
        How the answer was reached.
    lcp : LCPResult or None
        The polyhedral solver's LCP result (``z = [r_N, beta, lambda]`` per
        contact), with its own certified violation.
    """

    __slots__ = ("r", "u", "status", "residual", "relative_residual", "iterations", "method",
                 "detail", "lcp")

    def __init__(self, r, u, status, residual, relative_residual, iterations, method, detail,
                 lcp=None):
        self.r, self.u, self.status = r, u, status
        self.residual, self.relative_residual = residual, relative_residual
        self.iterations, self.method, self.detail, self.lcp = iterations, method, detail, lcp

    @property
    def success(self):
        return self.status == CONVERGED

    def __repr__(self):
        return (f"ConeSolution(method={self.method!r}, status={self.status!r}, "
                f"residual={self.residual:.3g}, iterations={self.iterations})")


def check_cone_problem(W, q, mu):
    """Validate ``(W, q, mu)`` and return them as float arrays.

    Parameters
    ----------
    W : array_like, shape (3 nc, 3 nc)
        Symmetric; each diagonal 3x3 block positive definite.
    q : array_like, shape (3 nc,)
    mu : float or array_like, shape (nc,)
        ``>= 0``; a scalar applies to every contact.

    Returns
    -------
    W, q, mu : ndarray

    Raises
    ------
    InputError
        Naming the argument and the rule broken.

    Examples
    --------
    >>> check_cone_problem(np.eye(3), np.zeros(3), -0.1)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `mu` must be >= 0 for every contact, got -0.1 at contact 0
    """
    W = finite_array("W", W, ndim=2)
    n = W.shape[0]
    if W.shape[1] != n or n == 0 or n % 3:
        raise InputError(f"`W` must be square of size 3 nc (three rows [N, T1, T2] a contact, "
                         f"nc >= 1), got shape {W.shape}")
    nc = n // 3
    q = finite_array("q", q, shape=(n,))
    mu_arr = np.asarray(mu, dtype=float) if not isinstance(mu, str) else None
    if mu_arr is None or mu_arr.ndim > 1:
        raise InputError(f"`mu` must be a number or an array of shape ({nc},), got {mu!r}")
    mu_arr = finite_array("mu", np.full(nc, mu_arr) if mu_arr.ndim == 0 else mu_arr,
                          shape=(nc,))
    bad = np.flatnonzero(mu_arr < 0.0)
    if bad.size:
        raise InputError(f"`mu` must be >= 0 for every contact, got {float(mu_arr[bad[0]])!r} at "
                         f"contact {int(bad[0])}")
    scale = float(np.max(np.abs(W))) if n else 0.0
    asym = float(np.max(np.abs(W - W.T)))
    if asym > _SYM_RTOL * scale:
        raise InputError(f"`W` must be symmetric (a Delassus matrix H M^-1 H^T): "
                         f"max|W - W^T| = {asym:.3g} > {_SYM_RTOL:g} max|W|")
    for i in range(nc):
        block = W[3 * i:3 * i + 3, 3 * i:3 * i + 3]
        try:
            np.linalg.cholesky(0.5 * (block + block.T))
        except np.linalg.LinAlgError:
            raise InputError(f"`W`'s diagonal block of contact {i} must be positive definite "
                             f"(the contact must move under its own impulse)") from None
    return np.ascontiguousarray(W), np.ascontiguousarray(q), np.ascontiguousarray(mu_arr)


def _trusted(W, q, mu):
    # a caller's problem in the layout, from checked data: contiguous float arrays only
    return (np.ascontiguousarray(W, dtype=float), np.ascontiguousarray(q, dtype=float),
            np.ascontiguousarray(mu, dtype=float))


# --------------------------------------------------------------------------- cone geometry

@njit(cache=True, inline="always")
def _proj(n, t1, t2, mu):
    # projection on K = {|t| <= mu n}; its polar cone is {mu |t| <= -n}
    # hypot, not sqrt(t1^2 + t2^2): the squares underflow for |t| below 1e-154
    nt = math.hypot(t1, t2)
    # (n >= 0: with mu = 0, nt = 0 <= mu n = -0.0 holds for n < 0 too, off the cone)
    if nt <= mu * n and n >= 0.0:
        return n, t1, t2
    if mu * nt <= -n:
        return 0.0, 0.0, 0.0
    nn = (n + mu * nt) / (1.0 + mu * mu)
    f = mu * nn / nt
    return nn, f * t1, f * t2


@njit(cache=True)
def _natural_sq(r, u, mu):
    # sum over contacts of |r - proj_K(r - û)|^2
    total = 0.0
    for i in range(mu.shape[0]):
        k = 3 * i
        m = mu[i]
        uhat = u[k] + m * math.hypot(u[k + 1], u[k + 2])
        pn, p1, p2 = _proj(r[k] - uhat, r[k + 1] - u[k + 1], r[k + 2] - u[k + 2], m)
        total += (r[k] - pn) ** 2 + (r[k + 1] - p1) ** 2 + (r[k + 2] - p2) ** 2
    return total


@njit(cache=True)
def _project_all(r, mu):
    out = np.empty_like(r)
    for i in range(mu.shape[0]):
        k = 3 * i
        out[k], out[k + 1], out[k + 2] = _proj(r[k], r[k + 1], r[k + 2], mu[i])
    return out


def project_cone(x, mu):
    """Project ``x = [N, T1, T2]`` (one contact) on the cone ``{|t| <= mu n}``.

    Examples
    --------
    >>> project_cone([1.0, 3.0, 4.0], 0.5)      # (1 + 0.5*5)/1.25 = 2.8, |t| = 1.4
    array([2.8 , 0.84, 1.12])
    >>> project_cone([-1.0, 0.0, 0.0], 0.5).tolist()
    [0.0, 0.0, 0.0]
    """
    x = np.asarray(x, dtype=float)
    return np.array(_proj(float(x[0]), float(x[1]), float(x[2]), float(mu)))


def cone_residual(W, q, mu, r):
    """The natural-map residual ``||r - proj_K(r - û)||_2`` of ``r`` on the data.

    ``û = u + mu |u_T| e_N`` with ``u = W r + q`` (De Saxcé); zero exactly
    at the solutions of the Coulomb problem.

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5]); q = np.array([-1.0, 3.0, 4.0])
    >>> cone_residual(W, q, 0.5, [1.0, -0.3, -0.4]) < 1e-15             # slip against (3, 4)
    True
    >>> round(cone_residual(W, q, 0.5, [0.0, 0.0, 0.0]) ** 2, 12)   # r = 0 is not a solution
    0.8
    """
    W, q, mu = check_cone_problem(W, q, mu)
    r = finite_array("r", r, shape=q.shape)
    return math.sqrt(_natural_sq(r, W @ r + q, mu))


# --------------------------------------------------------------------------- polyhedral LCP

def facet_directions(d):
    """The ``d`` unit directions of the polyhedral cone, columns of a ``(2, d)`` array.

    ``D[:, k] = (cos 2 pi k/d, sin 2 pi k/d)``: a regular polygon, so the
    pyramid ``{r_N e_N + D beta : beta >= 0, sum beta <= mu r_N}`` is
    inscribed in the round cone and touches it along the ``d`` edges.

    Examples
    --------
    >>> np.round(facet_directions(4), 12).tolist()
    [[1.0, 0.0, -1.0, -0.0], [0.0, 1.0, 0.0, -1.0]]
    """
    if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 3:
        raise InputError(f"`d` must be an integer >= 3 (fewer directions do not span the "
                         f"tangent plane positively), got {d!r}")
    a = 2.0 * np.pi * np.arange(int(d)) / int(d)
    return np.vstack([np.cos(a), np.sin(a)])


class PolyhedralLCP:
    """The LCP of the polyhedral cone and how to read it back.

    Attributes
    ----------
    M : ndarray, shape (nc (d + 2), nc (d + 2))
    q : ndarray, shape (nc (d + 2),)
    B : ndarray, shape (3 nc, nc (d + 2))
        ``r = B z``: impulses from the LCP variables.
    D : ndarray, shape (2, d)
    d, n_contacts : int
    """

    __slots__ = ("M", "q", "B", "D", "d", "n_contacts")

    def __init__(self, M, q, B, D):
        self.M, self.q, self.B, self.D = M, q, B, D
        self.d = D.shape[1]
        self.n_contacts = B.shape[0] // 3

    def impulses(self, z):
        """``r = B z`` in the ``[N, T1, T2]`` layout."""
        return self.B @ z


def build_polyhedral_lcp(W, q, mu, d=8, *, check=True):
    r"""Build the LCP ``(M, q_lcp)`` of the polyhedral friction cone.

    Derivation. Replace the disc ``|r_T| <= mu r_N`` by the polygon with
    vertices ``mu r_N D_k``, ``D_k = (cos 2 pi k/d, sin 2 pi k/d)``:
    ``r_T = D beta`` with ``beta >= 0`` and ``e^T beta <= mu r_N``. Coulomb's
    maximal dissipation, ``r_T`` minimising ``u_T . r_T`` over the polygon,
    is the LP ``min_beta (D^T u_T) . beta`` subject to ``beta >= 0`` and
    ``mu r_N - e^T beta >= 0``. Its KKT conditions, with ``lambda`` the
    multiplier of the second constraint, are

    .. math::

        0 \le \beta \perp \lambda e + D^T u_T \ge 0, \qquad
        0 \le \lambda \perp \mu r_N - e^T \beta \ge 0,

    and ``lambda`` is the sliding speed: in slip the minimum of ``D_k .
    u_T`` over the directions is ``-lambda``; in stick ``lambda = 0``
    and, as ``D`` spans the plane positively (``d >= 3``), ``D^T u_T >= 0``
    forces ``u_T = 0``. With Signorini's ``0 <= r_N ⟂ u_N >= 0`` and, per
    contact, ``z_i = (r_N, beta_1..beta_d, lambda)``, the impulse is ``r = B
    z`` with ``B_i = [[1, 0, 0], [0, D, 0]]`` (``3 x (d + 2)``), and
    ``[u_N, D^T u_T] = B_i^T u``. Hence, with ``u = W B z + q``,

    .. math::

        w = M z + q_{lcp}, \quad
        M = B^T W B + E, \quad q_{lcp} = B^T q, \quad
        E_i = \begin{pmatrix} 0 & 0 & 0 \\ 0 & 0 & e \\ \mu_i & -e^T & 0
              \end{pmatrix}

    (``B^T W B`` has zero rows and columns at the ``lambda`` entries).
    ``M`` is copositive on ``z >= 0`` (``z.Mz = |W^{1/2} B z|^2 + mu r_N
    lambda``) but not monotone; Lemke's method processes it for ``W``
    positive semidefinite (Anitescu and Potra 1997; Stewart and Trinkle
    1996).

    Parameters
    ----------
    W, q, mu :
        The problem (:func:`check_cone_problem`).
    d : int
        Number of directions, ``>= 3``.

    Returns
    -------
    PolyhedralLCP

    Examples
    --------
    >>> lcp = build_polyhedral_lcp(np.eye(3), np.array([-1.0, 0.0, 0.0]), 0.5, d=4)
    >>> lcp.M.shape, lcp.q.tolist()
    ((6, 6), [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    >>> lcp.M[5].tolist()                     # mu r_N - e^T beta
    [0.5, -1.0, -1.0, -1.0, -1.0, 0.0]
    """
    W, q, mu = check_cone_problem(W, q, mu) if check else _trusted(W, q, mu)
    D = facet_directions(d)
    d = D.shape[1]
    nc = mu.shape[0]
    m = d + 2
    B = np.zeros((3 * nc, m * nc))
    E = np.zeros((m * nc, m * nc))
    for i in range(nc):
        b = m * i
        B[3 * i, b] = 1.0
        B[3 * i + 1:3 * i + 3, b + 1:b + 1 + d] = D
        E[b + 1:b + 1 + d, b + d + 1] = 1.0
        E[b + d + 1, b] = mu[i]
        E[b + d + 1, b + 1:b + 1 + d] = -1.0
    M = B.T @ W @ B + E
    return PolyhedralLCP(M, B.T @ q, B, D)


def solve_polyhedral(W, q, mu, d=8, *, method="auto", tol=None, check=True, support=None):
    """Solve the spatial friction problem with the ``d``-direction polyhedral cone.

    Parameters
    ----------
    W, q, mu :
        The problem (:func:`check_cone_problem`).
    d : int
        Number of friction directions, ``>= 3`` (default 8).
    method : {"auto", "lemke", "qp"}
        Passed to :func:`moreau.lcp.solve_lcp`. The QP formulations need a
        monotone ``M``, which this LCP is not, so after a Lemke failure
        ``"auto"`` reports the QP as not applicable rather than guessing.
    tol : float, optional
        The LCP's violation bound (:func:`moreau.lcp.lcp_violation`).
    check : bool
        False skips :func:`check_cone_problem`, for a caller that built the
        problem in its layout from checked data (a scheme's step).
    support : array of int, optional
        A guessed support of the LCP's answer (the last step's), passed to
        ``"auto"`` (:func:`moreau.lcp.solve_lcp`), which tries it only where
        Lemke's path would be finished in exact arithmetic.

    Returns
    -------
    ConeSolution
        ``status`` is ``"converged"`` when the LCP was solved and certified
        on its data, else the LCP's message; ``residual`` is the *exact*
        cone's natural map at the polyhedral answer (the faceting error);
        ``lcp`` holds the LCP result.

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5])
    >>> sol = solve_polyhedral(W, np.array([-1.0, 0.5, 0.0]), 0.5, d=4)   # sticks
    >>> sol.status, np.round(sol.r, 12).tolist(), np.round(sol.u, 12).tolist()
    ('converged', [1.0, -0.142857142857, 0.0], [0.0, 0.0, 0.0])
    """
    W, q, mu = check_cone_problem(W, q, mu) if check else _trusted(W, q, mu)
    lcp = build_polyhedral_lcp(W, q, mu, d, check=False)
    if support is None:
        res = solve_lcp(lcp.M, lcp.q, method, tol=tol)
    else:
        res = solve_lcp(lcp.M, lcp.q, method, tol=tol, support=support)
    r = lcp.impulses(res.z)
    u = W @ r + q
    residual = math.sqrt(_natural_sq(r, u, mu))
    qn = float(np.linalg.norm(q))
    status = CONVERGED if res.success else STATUS_MESSAGES.get(res.status, str(res.status))
    detail = (f"LCP of size {lcp.M.shape[0]} ({lcp.d} directions), method {res.method!r}, path "
              f"{'/'.join(res.path) if res.path else res.method}, LCP violation "
              f"{res.residual:.3g}.")
    if getattr(res, "detail", None):
        detail += " " + res.detail
    return ConeSolution(r, u, status, residual, residual / qn if qn > 0 else residual,
                        {"pivots": int(res.pivots)}, f"polyhedral-{lcp.d}", detail, lcp=res)


#: the violation (in :func:`moreau.lcp.lcp_violation`'s units) below which
#: :func:`polyhedral_one_contact`'s answer is certified (Lemke's own bound is 1e-9)
ONE_CONTACT_TOL = 1e-12


@njit(inline="always")
def _stick(A, b0, b1, b2):
    # A r = -b by Cramer's rule on the 3x3 block: (True, r) where det A > 0, else False; the
    # adjugate's entries as scalars (no array allocated in this hot branch). Inlined by numba:
    # as a function of its own it cost its callers' first compile 0.2 CPU s more
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    if not det > 0.0:
        return False, 0.0, 0.0, 0.0
    i01 = A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]
    i11 = A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]
    i21 = A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]
    i02 = A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]
    i12 = A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]
    i22 = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    rn = -(c00 * b0 + i01 * b1 + i02 * b2) / det
    r1 = -(c01 * b0 + i11 * b1 + i12 * b2) / det
    r2 = -(c02 * b0 + i21 * b1 + i22 * b2) / det
    return True, rn, r1, r2


@njit(cache=True)
def polyhedral_one_contact(W, q, mu, D, r):
    """One contact's polyhedral problem (:func:`build_polyhedral_lcp`) in closed form, certified.

    The LCP of one contact, ``z = (r_N, beta, lambda)``, has three kinds of
    answer, tried in turn: take-off (``r = 0``, ``lambda = max_k -D_k.u_T``:
    an answer whenever ``q_N >= 0``), stick (``r = -W^-1 q`` inside the
    pyramid, ``lambda = 0``) and slip, ``r_T = mu r_N t`` with ``t`` on the
    polygon's boundary: at a vertex ``D_k`` (``beta_k = mu r_N``) or on the
    facet from ``D_k`` to ``D_k+1`` (two betas; a 2 x 2 system for ``r_N``
    and the split), with ``u_N = 0`` and ``-lambda = D_k.u_T`` the least of
    the ``D_j.u_T``. The facet the stick impulse points through is tried,
    then its vertices and the facets beside them. A candidate counts where it
    meets the LCP's conditions to :data:`ONE_CONTACT_TOL` in the units of
    :func:`moreau.lcp.lcp_violation` (with a bound on ``max|M|``: stricter than
    Lemke's 1e-9). It is tried only far from Painlevé's coupling, ``2 mu
    |W_NT| < W_NN``, where an impulse along any ``t`` pushes the normal
    velocity up; nearer, the LCP may have several answers (a jam beside a
    take-off) and the caller's Lemke picks one (the test suite holds this
    function to Lemke's answer on random problems).

    Parameters
    ----------
    W : ndarray, shape (3, 3)
        The contact's Delassus block, symmetric positive definite.
    q : ndarray, shape (3,)
        Its free velocity ``[N, T1, T2]``.
    mu : float
    D : ndarray, shape (2, d)
        The directions (:func:`facet_directions`).
    r : ndarray, shape (3,)
        Receives the impulse where the answer is certified.

    Returns
    -------
    bool
        False where no candidate passed (``r`` untouched): the caller solves
        the LCP (Lemke).

    Examples
    --------
    >>> r = np.zeros(3)
    >>> W = np.diag([1.0, 3.5, 3.5]); D = facet_directions(4)
    >>> bool(polyhedral_one_contact(W, np.array([-1.0, 0.5, 0.0]), 0.5, D, r))   # sticks
    True
    >>> (np.round(r, 12) + 0.0).tolist()
    [1.0, -0.142857142857, 0.0]
    >>> bool(polyhedral_one_contact(W, np.array([-1.0, 3.0, 0.0]), 0.5, D, r))   # slips
    True
    >>> (np.round(r, 12) + 0.0).tolist()
    [1.0, -0.5, 0.0]
    """
    # As j -> D_j.u_T samples |u_T| cos(angle), a least value against both neighbours is the
    # least of all: a slip candidate is checked against every direction all the same
    d = D.shape[1]
    n0, f1, f2 = q[0], q[1], q[2]
    if 2.0 * mu * math.hypot(W[0, 1], W[0, 2]) >= W[0, 0]:
        # far from Painlevé's coupling only (an impulse along any t of the polygon pushes
        # the normal velocity up: W_NN - mu |W_NT| > W_NN / 2), where the answer is unique;
        # nearer, the LCP may have several (a jam beside a take-off) and Lemke's path picks one
        return False
    if n0 >= 0.0:
        r[0] = 0.0
        r[1] = 0.0
        r[2] = 0.0
        return True
    if mu <= 0.0:
        return False
    # the LCP's scales: s = max|q| (q_lcp = (q_N, D^T q_T, 0)) and a bound on max|M| (its
    # entries are W_NN, W_N.D_k, D_j.W_TT D_k, 1 and mu), so the bounds are tighter than Lemke's
    sc = abs(n0)
    for k in range(d):
        sc = max(sc, abs(D[0, k] * f1 + D[1, k] * f2))
    mm = max(1.0, mu, abs(W[0, 0]), abs(W[0, 1]) + abs(W[0, 2]),
             abs(W[1, 1]) + abs(W[1, 2]) + abs(W[2, 1]) + abs(W[2, 2]))
    tol_w = ONE_CONTACT_TOL * sc
    tol_z = tol_w / mm
    # stick: W r = -q
    a1, a2 = -f1, -f2                      # the sliding impulse's direction, failing stick
    ok, rn, r1, r2 = _stick(W, n0, f1, f2)
    if ok:
        if rn >= 0.0:
            # inside the polygon of vertices mu r_N D_k: below every facet's line, whose
            # outward normal is D_k + D_k+1 and whose offset is mu r_N (1 + D_k.D_k+1)
            inside = True
            for k in range(d):
                k1 = (k + 1) % d
                e1 = D[0, k] + D[0, k1]
                e2 = D[1, k] + D[1, k1]
                if e1 * r1 + e2 * r2 > mu * rn * (1.0 + D[0, k] * D[0, k1] + D[1, k] * D[1, k1]):
                    inside = False
                    break
            if inside:
                r[0] = rn
                r[1] = r1
                r[2] = r2
                return True
            a1, a2 = r1, r2
    # slip: the facet that the stick impulse (or -q_T) points through, then its two
    # vertices, then the facets beside them
    step = 2.0 * math.pi / d
    k0 = int(math.floor(math.atan2(a2, a1) / step)) % d
    for trial in range(5):
        if trial == 0:
            k, facet = k0, True
        elif trial < 3:
            k, facet = (k0 + trial - 1) % d, False
        else:
            k, facet = (k0 - 1 if trial == 3 else k0 + 1) % d, True
        if _slip_candidate(W, n0, f1, f2, mu, D, d, k, facet, tol_w, tol_z, r):
            return True
    return False


@njit(cache=True)
def _slip_candidate(W, n0, f1, f2, mu, D, d, k, facet, tol_w, tol_z, r):
    # slip at vertex k (facet False) or on the facet k -> k+1; writes r where certified
    k1 = (k + 1) % d
    dk0, dk1 = D[0, k], D[1, k]
    wn_k = W[0, 1] * dk0 + W[0, 2] * dk1
    if facet:
        e0, e1 = D[0, k1] - dk0, D[1, k1] - dk1
        wn_e = W[0, 1] * e0 + W[0, 2] * e1
        # e.W_TT d_k, e.W_TT e and e.W_TN
        te0 = W[1, 1] * dk0 + W[1, 2] * dk1
        te1 = W[2, 1] * dk0 + W[2, 2] * dk1
        ee0 = W[1, 1] * e0 + W[1, 2] * e1
        ee1 = W[2, 1] * e0 + W[2, 2] * e1
        a11 = W[0, 0] + mu * wn_k
        a12 = mu * wn_e
        a21 = e0 * W[1, 0] + e1 * W[2, 0] + mu * (e0 * te0 + e1 * te1)
        a22 = mu * (e0 * ee0 + e1 * ee1)
        b2 = -(e0 * f1 + e1 * f2)
        det = a11 * a22 - a12 * a21
        if det == 0.0:
            return False
        x = (-n0 * a22 - a12 * b2) / det       # r_N
        y = (a11 * b2 + a21 * n0) / det        # r_N alpha
        if not (x > 0.0 and y >= 0.0 and y <= x):
            return False
        t1 = x * dk0 + y * e0
        t2 = x * dk1 + y * e1
        rn = x
        r1 = mu * t1
        r2 = mu * t2
        bk, bk1 = mu * (x - y), mu * y
    else:
        g = W[0, 0] + mu * wn_k
        if not g > 0.0:
            return False
        rn = -n0 / g
        r1 = mu * rn * dk0
        r2 = mu * rn * dk1
        bk, bk1 = mu * rn, 0.0
    # the LCP's w at this z: u_N, D_j.u_T + lambda, mu r_N - sum beta
    un = W[0, 0] * rn + W[0, 1] * r1 + W[0, 2] * r2 + n0
    u1 = W[1, 0] * rn + W[1, 1] * r1 + W[1, 2] * r2 + f1
    u2 = W[2, 0] * rn + W[2, 1] * r1 + W[2, 2] * r2 + f2
    lam = -(dk0 * u1 + dk1 * u2)
    if lam < -tol_z or abs(un) > tol_w or abs(mu * rn - bk - bk1) > tol_w:
        return False
    # every D_j.u_T + lambda >= 0, = 0 (to the bound) where beta_j > 0
    for j in range(d):
        wj = D[0, j] * u1 + D[1, j] * u2 + lam
        if wj < -tol_w:
            return False
        bj = bk if j == k else bk1 if j == k1 else 0.0
        if bj > tol_z and wj > tol_w:
            return False
    r[0] = rn
    r[1] = r1
    r[2] = r2
    return True


# --------------------------------------------------------------------------- exact cone

@njit(cache=True)
def _local_res_sq(A, b, mu, rn, r1, r2):
    u0 = A[0, 0] * rn + A[0, 1] * r1 + A[0, 2] * r2 + b[0]
    u1 = A[1, 0] * rn + A[1, 1] * r1 + A[1, 2] * r2 + b[1]
    u2 = A[2, 0] * rn + A[2, 1] * r1 + A[2, 2] * r2 + b[2]
    uhat = u0 + mu * math.hypot(u1, u2)
    pn, p1, p2 = _proj(rn - uhat, r1 - u1, r2 - u2, mu)
    return (rn - pn) ** 2 + (r1 - p1) ** 2 + (r2 - p2) ** 2


@njit(cache=True, inline="always")
def _slip_cs(A, b, mu, c, s):
    # with s = (c, s) = (cos phi, sin phi), r = rho (1, -mu s) and u_N = 0:
    # rho = -b_N / g, g u_T = h; returns (s_perp . h, s . h, g)
    g = A[0, 0] - mu * (A[0, 1] * c + A[0, 2] * s)
    h1 = -b[0] * (A[1, 0] - mu * (A[1, 1] * c + A[1, 2] * s)) + g * b[1]
    h2 = -b[0] * (A[2, 0] - mu * (A[2, 1] * c + A[2, 2] * s)) + g * b[2]
    return -s * h1 + c * h2, c * h1 + s * h2, g


_N_SAMPLES = 64
# the samples' upper ends (k step + step) and their cosines and sines, computed once: the
# slip's solve has no trigonometry (_refine_angle turns rationally from a sample's start)
_SAMPLE_STEP = 2.0 * math.pi / _N_SAMPLES
_SAMPLE_COS = np.array([math.cos(k * _SAMPLE_STEP + _SAMPLE_STEP) for k in range(_N_SAMPLES)])
_SAMPLE_SIN = np.array([math.sin(k * _SAMPLE_STEP + _SAMPLE_STEP) for k in range(_N_SAMPLES)])
#: Gauss–Seidel sweeps without a new least residual before Newton takes over
_STALL = 50
#: directions of the polyhedral cone whose solution restarts Newton
_RESTART_D = 16
#: finer polygons tried in turn when Newton from the 16-gon's solution fails
_FINER_D = (32, 64, 128)


#: the sliding angle's bracket is refined to this width [rad] (a few rounding units of 2 pi)
_ANGLE_TOL = 4e-15
#: the tangent of half a sample's width: a bracket's parameter t runs over [0, _SAMPLE_T]
_SAMPLE_T = math.tan(0.5 * _SAMPLE_STEP)


@njit(cache=True, inline="always")
def _turn(c0, s0, t):
    # (cos, sin) of the angle phi0 + 2 atan(t), rational in t: no trigonometry, and of unit
    # norm to rounding since (1 - t^2)^2 + (2 t)^2 = (1 + t^2)^2
    den = 1.0 + t * t
    a = (1.0 - t * t) / den
    bb = 2.0 * t / den
    return a * c0 - bb * s0, a * s0 + bb * c0


@njit(cache=True, inline="always")
def _illinois_narrow(x, fx, lo, flo, wlo, hi, fhi, whi, side):
    # the bracket after the point x of value fx: x replaces the end whose value has its sign;
    # Illinois halves the weight (wlo, whi) of the end that stays twice in a row, where plain
    # regula falsi would keep it and converge linearly
    if (fx < 0.0) == (flo < 0.0):
        lo, flo, wlo = x, fx, fx
        if side < 0:
            whi *= 0.5
        side = -1
    else:
        hi, fhi, whi = x, fx, fx
        if side > 0:
            wlo *= 0.5
        side = 1
    return lo, flo, wlo, hi, fhi, whi, side


@njit(cache=True, inline="always")
def _refine_angle(A, b, mu, c0, s0, flo, fhi):
    # a root of the slip function in the sample [phi0, phi0 + step] (cos phi0 = c0, sin phi0 =
    # s0; flo, fhi its ends' values, of opposite signs) as (cos, sin), by the Illinois variant
    # of regula falsi (superlinear, the bracket kept) on t = tan((phi - phi0) / 2) in [0,
    # _SAMPLE_T]: each evaluation rational, without the cosine and sine an angle would cost
    # (they were two thirds of a slip's solve); a step that rounding puts outside the bracket
    # bisects instead. Stops once the bracket is _ANGLE_TOL wide in the angle (dphi = 2 dt /
    # (1 + t^2) <= 2 dt) and returns the end of least |F|; t = _SAMPLE_T returns the sample's
    # end (hi) itself, as (nan, nan), for the caller's table
    lo, hi = 0.0, _SAMPLE_T
    wlo, whi = flo, fhi           # the weights Illinois halves; flo, fhi stay the values
    side = 0
    for _ in range(100):
        if hi - lo <= 0.5 * _ANGLE_TOL:
            break
        x = hi - whi * (hi - lo) / (whi - wlo)
        if not lo < x < hi:
            # the secant lands on an end: a root there to rounding (a launch along a
            # sample's direction) when that end's F is rounding beside the other's
            if x <= lo and abs(flo) <= 1e-14 * abs(fhi):
                return _end(c0, s0, lo)
            if x >= hi and abs(fhi) <= 1e-14 * abs(flo):
                return _end(c0, s0, hi)
            x = 0.5 * (lo + hi)
            if not lo < x < hi:
                break
        cx, sx = _turn(c0, s0, x)
        fx, _, _ = _slip_cs(A, b, mu, cx, sx)
        if fx == 0.0:
            return cx, sx
        lo, flo, wlo, hi, fhi, whi, side = _illinois_narrow(x, fx, lo, flo, wlo, hi, fhi, whi,
                                                            side)
    return _end(c0, s0, lo if abs(flo) <= abs(fhi) else hi)


@njit(cache=True, inline="always")
def _end(c0, s0, t):
    # the bracket's answer t; its upper end _SAMPLE_T as (nan, nan): the caller's table has it
    if t == _SAMPLE_T:
        return math.nan, math.nan
    return _turn(c0, s0, t)


@njit(cache=True)
def _local(A, b, mu):
    # The one-contact problem u = A r + b, exactly: the three cases of the
    # Coulomb law tried in turn; slip by bracketing the sliding angle
    if b[0] >= 0.0:
        return 0.0, 0.0, 0.0
    if mu == 0.0:
        return -b[0] / A[0, 0], 0.0, 0.0
    # stick: A r = -b
    ok, rn, r1, r2 = _stick(A, b[0], b[1], b[2])
    if ok:
        if rn >= 0.0 and math.hypot(r1, r2) <= mu * rn:
            return rn, r1, r2
    # slip: roots of F(phi) = s_perp . (g u_T) with g > 0 and s . u_T >= 0
    if (A[0, 1] == 0.0 and A[1, 0] == 0.0 and A[0, 2] == 0.0 and A[2, 0] == 0.0
            and A[1, 2] == 0.0 and A[2, 1] == 0.0 and A[1, 1] == A[2, 2]):
        # an isotropic block (a sphere or a point under its centre of mass): F = A_NN (c b_2
        # - s b_1), whose one admissible root slides against b_T (the other has s . u_T < 0
        # where stick failed): r = rho (1, -mu b_T / |b_T|), rho = -b_N / A_NN
        bt = math.hypot(b[1], b[2])
        if bt > 0.0:
            rho = -b[0] / A[0, 0]
            return rho, -mu * rho * (b[1] / bt), -mu * rho * (b[2] / bt)
    best_n, best_1, best_2 = -b[0] / A[0, 0], 0.0, 0.0
    best = _local_res_sq(A, b, mu, best_n, best_1, best_2)
    c0, s0 = 1.0, 0.0
    fa, _, _ = _slip_cs(A, b, mu, c0, s0)
    for k in range(_N_SAMPLES):
        c1, s1 = _SAMPLE_COS[k], _SAMPLE_SIN[k]
        fb, _, _ = _slip_cs(A, b, mu, c1, s1)
        if fa == 0.0 or fa * fb < 0.0:
            c, sn = c0, s0
            if fa != 0.0:
                c, sn = _refine_angle(A, b, mu, c0, s0, fa, fb)
                if math.isnan(c):
                    c, sn = c1, s1
            _, along, g = _slip_cs(A, b, mu, c, sn)
            if g > 0.0 and along >= 0.0:
                rho = -b[0] / g
                rn = rho
                r1 = -mu * rho * c
                r2 = -mu * rho * sn
                res = _local_res_sq(A, b, mu, rn, r1, r2)
                if res < best:
                    best, best_n, best_1, best_2 = res, rn, r1, r2
        fa = fb
        c0, s0 = c1, s1
    if best > (_LOCAL_RTOL * _norm3(b[0], b[1], b[2])) ** 2:
        # the samples missed the answer (two roots of F within one sample, near where g
        # changes sign under a strong coupling 2 mu |A_NT| > A_NN): every root, isolated
        rn, r1, r2, res = _slip_all_roots(A, b, mu)
        if res < best:
            best_n, best_1, best_2 = rn, r1, r2
    return best_n, best_1, best_2


#: a local answer whose natural-map residual exceeds this fraction of ``|b|`` is not taken from
#: the samples: the slip's roots are then isolated one by one (:func:`_slip_all_roots`)
_LOCAL_RTOL = 1e-12
#: the isolation's pieces of the circle at the start, its narrowest piece [rad] and its budget
_ISO_START = 16
_ISO_MIN = 1e-9
_ISO_BUDGET = 4000


@njit(cache=True, inline="always")
def _norm3(a, b, c):
    return math.hypot(math.hypot(a, b), c)


@njit(cache=True, inline="always")
def _trig2(k0, p1, p2, k1, k2, x):
    # F(x) = k0 + p2 cos x - p1 sin x + k1 cos 2x + k2 sin 2x and F'(x)
    c = math.cos(x)
    s = math.sin(x)
    c2 = c * c - s * s
    s2 = 2.0 * s * c
    return (k0 + p2 * c - p1 * s + k1 * c2 + k2 * s2,
            -p2 * s - p1 * c - 2.0 * k1 * s2 + 2.0 * k2 * c2)


@njit(cache=True)
def _trig2_root(k0, p1, p2, k1, k2, lo, hi, flo, fhi):
    # a root of F in [lo, hi] (flo, fhi of opposite signs or one zero) by the Illinois variant
    # of regula falsi, bisecting where rounding puts the secant outside, to a rounding-wide
    # bracket; returns the end of least |F|
    if flo == 0.0:
        return lo
    if fhi == 0.0:
        return hi
    wlo, whi = flo, fhi
    side = 0
    for _ in range(200):
        if hi - lo <= 4.5e-16 * max(abs(lo), abs(hi)) + 1e-300:
            break
        x = hi - whi * (hi - lo) / (whi - wlo)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
            if not lo < x < hi:
                break
        fx, _ = _trig2(k0, p1, p2, k1, k2, x)
        if fx == 0.0:
            return x
        lo, flo, wlo, hi, fhi, whi, side = _illinois_narrow(x, fx, lo, flo, wlo, hi, fhi, whi,
                                                            side)
    return lo if abs(flo) <= abs(fhi) else hi


@njit(cache=True)
def _slip_all_roots(A, b, mu):
    # Every slip of one contact, u = A r + b with b_N < 0, stick failed. With s = (cos x,
    # sin x), r = rho (1, -mu s) and u_N = 0: g = A_NN - mu a.s (a = A_TN), rho = -b_N / g,
    # and g u_T = p + P s with p = A_NN b_T - b_N a, P = mu (b_N A_TT - b_T a^T). The slip
    # needs g > 0 and u_T = alpha s with alpha >= 0, so x is a root of F = s_perp . (p + P s)
    # (s_perp = (-sin x, cos x)): with cos^2 = (1 + cos 2x)/2, sin^2 = (1 - cos 2x)/2 and
    # sin cos = sin 2x / 2,
    #     F = k0 + p2 cos x - p1 sin x + k1 cos 2x + k2 sin 2x,
    #     k0 = (P21 - P12)/2, k1 = (P21 + P12)/2, k2 = (P22 - P11)/2,
    # a trigonometric polynomial of degree 2: at most four roots, two of which can lie
    # arbitrarily close (they meet where the slip appears or vanishes with mu). The roots are
    # isolated by subdividing the circle: on a piece of half-width w about m,
    # |F(x)| >= |F(m)| - |F'(m)| w - L2 w^2 / 2 with L2 = |p| + 4 |k| >= |F''| (no root where
    # that is positive), and where |F'(m)| > L2 w, F is monotone there (a root exactly where
    # its ends' signs differ, refined by _trig2_root). Pieces neither excluded nor monotone
    # are halved down to _ISO_MIN, where F and F' both vanish to O(L2 _ISO_MIN): a double
    # root, whose point of least |F| is a root to rounding. Of the roots with g > 0 the slip
    # of least natural-map residual is returned, with that residual squared (inf for none).
    a1, a2 = A[1, 0], A[2, 0]
    p1 = A[0, 0] * b[1] - b[0] * a1
    p2 = A[0, 0] * b[2] - b[0] * a2
    P11 = mu * (b[0] * A[1, 1] - b[1] * a1)
    P12 = mu * (b[0] * A[1, 2] - b[1] * a2)
    P21 = mu * (b[0] * A[2, 1] - b[2] * a1)
    P22 = mu * (b[0] * A[2, 2] - b[2] * a2)
    k0 = 0.5 * (P21 - P12)
    k1 = 0.5 * (P21 + P12)
    k2 = 0.5 * (P22 - P11)
    amp1 = math.hypot(p1, p2)
    amp2 = math.hypot(k1, k2)
    L2 = amp1 + 4.0 * amp2
    err = 1e-15 * (abs(k0) + amp1 + amp2 + abs(P11) + abs(P12) + abs(P21) + abs(P22)) + 1e-300
    roots = np.empty(64)
    nroot = 0
    # a stack of pieces (lo, hi, F(lo), F(hi)), depth first
    stack = np.empty((4 * _ISO_START + 256, 4))
    top = 0
    step = 2.0 * math.pi / _ISO_START
    for j in range(_ISO_START - 1, -1, -1):
        lo = j * step
        hi = (j + 1) * step
        stack[top, 0] = lo
        stack[top, 1] = hi
        stack[top, 2], _ = _trig2(k0, p1, p2, k1, k2, lo)
        stack[top, 3], _ = _trig2(k0, p1, p2, k1, k2, hi)
        top += 1
    work = 0
    while top > 0 and work < _ISO_BUDGET and nroot < roots.shape[0] - 3:
        work += 1
        top -= 1
        lo, hi, flo, fhi = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        w = 0.5 * (hi - lo)
        m = lo + w
        fm, dm = _trig2(k0, p1, p2, k1, k2, m)
        if abs(fm) - abs(dm) * w - 0.5 * L2 * w * w > err:
            continue
        if abs(dm) - L2 * w > err:
            if flo == 0.0 or fhi == 0.0 or (flo < 0.0) != (fhi < 0.0):
                roots[nroot] = _trig2_root(k0, p1, p2, k1, k2, lo, hi, flo, fhi)
                nroot += 1
            continue
        if w <= _ISO_MIN or top + 2 > stack.shape[0]:
            if (flo < 0.0) != (fm < 0.0):
                roots[nroot] = _trig2_root(k0, p1, p2, k1, k2, lo, m, flo, fm)
                nroot += 1
            if (fm < 0.0) != (fhi < 0.0):
                roots[nroot] = _trig2_root(k0, p1, p2, k1, k2, m, hi, fm, fhi)
                nroot += 1
            roots[nroot] = m
            nroot += 1
            continue
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = m, hi, fm, fhi
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2], stack[top + 1, 3] = \
            lo, m, flo, fm
        top += 2
    best = math.inf
    best_n, best_1, best_2 = 0.0, 0.0, 0.0
    for j in range(nroot):
        c = math.cos(roots[j])
        s = math.sin(roots[j])
        g = A[0, 0] - mu * (A[0, 1] * c + A[0, 2] * s)
        if not g > 0.0:
            continue
        rho = -b[0] / g
        rn, r1, r2 = rho, -mu * rho * c, -mu * rho * s
        res = _local_res_sq(A, b, mu, rn, r1, r2)
        if res < best:
            best, best_n, best_1, best_2 = res, rn, r1, r2
    return best_n, best_1, best_2, best


def local_solve(A, b, mu):
    """Solve the one-contact problem ``u = A r + b`` with the exact Coulomb cone.

    Take-off when ``b_N >= 0`` (``r = 0``); stick when ``r = -A^-1 b`` lies
    in the cone; otherwise slip: ``r = rho (1, -mu cos phi, -mu sin phi)``
    with ``u_N = 0`` giving ``rho = -b_N / g(phi)``, ``g = A_NN - mu A_NT s``,
    and the sliding angle a root of ``s_perp . u_T(phi) = 0`` with ``s .
    u_T >= 0``, bracketed on 64 samples of ``[0, 2 pi)`` and refined by
    the Illinois variant of regula falsi on ``tan`` of the half angle from
    the sample's start (the cosine and sine rational in it: no
    trigonometry) to a bracket ``4e-15`` rad wide. Of
    several admissible roots the one with the least residual is kept.
    Two roots can share a sample (under a strong coupling ``2 mu |A_NT| >
    A_NN``, beside the angle where ``g`` changes sign); where the samples'
    answer is not a solution to ``1e-12 |b|``, the roots of that condition,
    a trigonometric polynomial of degree 2 (at most four), are isolated one
    by one by subdividing the circle with a bound on its second derivative.
    A symmetric positive definite ``A`` always has a solution: the problem
    is the variational inequality of ``û(r)`` on ``K``, coercive as ``û(r) .
    r >= r.A r + b.r`` on ``K`` (Hartman–Stampacchia), so one of the three
    cases holds.

    Examples
    --------
    >>> A = np.diag([1.0, 3.5, 3.5])
    >>> np.round(local_solve(A, [-1.0, 3.0, 4.0], 0.5), 14).tolist()   # slip, against (3, 4)
    [1.0, -0.3, -0.4]
    >>> local_solve(A, [0.5, 3.0, 4.0], 0.5).tolist()                    # take-off
    [0.0, 0.0, 0.0]
    """
    W, b, mu = check_cone_problem(A, b, mu)
    return np.array(_local(W, b, float(mu[0])))


@njit(cache=True)
def _affine_into(W, q, r, out):
    # out = q + W r, row by row in the order every caller used (the same bits)
    n = q.shape[0]
    for j in range(n):
        acc = q[j]
        for l in range(n):
            acc += W[j, l] * r[l]
        out[j] = acc


@njit(cache=True)
def _pgs(W, q, mu, r, u, max_sweeps, tol_sq, relax, stall):
    # projected Gauss–Seidel over contacts; u = W r + q kept in step and
    # recomputed each sweep so that the residual is the one of the data.
    # relax < 1 moves each contact part way to its local solution (a convex
    # combination, so r stays in K); the sweeps stop after `stall` of them
    # without a new least residual (Gauss–Seidel can cycle when mu is large)
    return _pgs_into(W, q, mu, r, u, max_sweeps, tol_sq, relax, stall, np.empty((3, 3)),
                     np.empty(3))


@njit(cache=True)
def _pgs_into(W, q, mu, r, u, max_sweeps, tol_sq, relax, stall, A, b):
    # _pgs with its local block A (at least 3 x 3) and right-hand side b given: a
    # time-stepping loop passes its own scratch (nothing allocated a step)
    nc = mu.shape[0]
    n = 3 * nc
    res = _natural_sq(r, u, mu)
    best = res
    since = 0
    sweeps = 0
    while sweeps < max_sweeps and res > tol_sq and since < stall:
        for i in range(nc):
            k = 3 * i
            for a in range(3):
                b[a] = u[k + a] - (W[k + a, k] * r[k] + W[k + a, k + 1] * r[k + 1]
                                   + W[k + a, k + 2] * r[k + 2])
                for c in range(3):
                    A[a, c] = W[k + a, k + c]
            rn, r1, r2 = _local(A, b, mu[i])
            d0 = relax * (rn - r[k])
            d1 = relax * (r1 - r[k + 1])
            d2 = relax * (r2 - r[k + 2])
            if d0 != 0.0 or d1 != 0.0 or d2 != 0.0:
                for j in range(n):
                    u[j] += W[j, k] * d0 + W[j, k + 1] * d1 + W[j, k + 2] * d2
                if relax == 1.0:
                    r[k] = rn
                    r[k + 1] = r1
                    r[k + 2] = r2
                else:
                    r[k] += d0
                    r[k + 1] += d1
                    r[k + 2] += d2
        _affine_into(W, q, r, u)
        sweeps += 1
        res = _natural_sq(r, u, mu)
        if res < 0.999 * best:
            best = res
            since = 0
        else:
            since += 1
    return sweeps, res


def _alart_curnier(W, q, mu, rho, r):
    """Alart–Curnier function and one element of its generalized Jacobian."""
    n = r.shape[0]
    u = W @ r + q
    phi = np.empty(n)
    J = np.zeros((n, n))
    for i in range(mu.shape[0]):
        k = 3 * i
        p = rho[i]
        tau = r[k] - p * u[k]
        dtau = -p * W[k]
        dtau[k] += 1.0
        active = tau > 0.0
        phi[k] = r[k] - max(tau, 0.0)
        J[k, k] = 1.0
        if active:
            J[k] -= dtau
        x = r[k + 1:k + 3] - p * u[k + 1:k + 3]
        dx = -p * W[k + 1:k + 3]
        dx[0, k + 1] += 1.0
        dx[1, k + 2] += 1.0
        radius = mu[i] * max(tau, 0.0)
        nx = math.hypot(x[0], x[1])
        if nx <= radius:
            # inside the disc: Phi_T = rho u_T
            phi[k + 1:k + 3] = p * u[k + 1:k + 3]
            J[k + 1:k + 3] = p * W[k + 1:k + 3]
        else:
            xh = x / nx
            phi[k + 1:k + 3] = r[k + 1:k + 3] - radius * xh
            dP = (radius / nx) * (np.eye(2) - np.outer(xh, xh)) @ dx
            if active:
                dP += mu[i] * np.outer(xh, dtau)
            J[k + 1, k + 1] += 1.0
            J[k + 2, k + 2] += 1.0
            J[k + 1:k + 3] -= dP
    return phi, J


def _restart(W, q, mu, start, max_newton, tol_sq, r, res):
    """Newton from ``start`` (its own budget): its answer where better than ``(r, res)``,
    and its steps."""
    r_n, res_n, more = _newton(W, q, mu, start.copy(), int(max_newton), tol_sq)
    if res_n < res:
        return r_n, res_n, more
    return r, res, more


def _newton(W, q, mu, r, max_iter, tol_sq):
    """Nonsmooth Newton on the Alart–Curnier function with an Armijo search.

    Returns the iterate with the least natural-map residual seen (never a
    worse one than ``r``), the residual squared and the iterations done.
    """
    rho = 1.0 / np.array([W[3 * i, 3 * i] for i in range(mu.shape[0])])
    best_r = r.copy()
    best = _natural_sq(r, W @ r + q, mu)
    it = 0
    while it < max_iter and best > tol_sq:
        phi, J = _alart_curnier(W, q, mu, rho, r)
        merit = float(phi @ phi)
        try:
            step = np.linalg.solve(J, -phi)
        except np.linalg.LinAlgError:
            step = np.linalg.lstsq(J, -phi, rcond=None)[0]
        if not np.all(np.isfinite(step)):
            break
        t = 1.0
        while True:
            trial = r + t * step
            phi_t, _ = _alart_curnier(W, q, mu, rho, trial)
            if float(phi_t @ phi_t) <= (1.0 - 1e-4 * t) * merit or t < 1e-10:
                break
            t *= 0.5
        it += 1
        if t < 1e-10:
            break
        r = trial
        res = _natural_sq(r, W @ r + q, mu)
        if res < best:
            best, best_r = res, r.copy()
    return best_r, best, it


#: :func:`solve_exact` tries every set of contacts sticking with the others open (all
#: but every contact touching) up to this many contacts (2^nc - 1 linear solves of at
#: most 3 nc unknowns)
STICK_OR_OPEN_MAX_CONTACTS = 8


def _stick_or_open(W, q, mu, tol_sq):
    # (r, residual^2, touching contacts) of the first set S (by bitmask) whose sticking
    # impulse r_S = -W_SS^-1 q_S (r = 0 off S), projected on the cones, meets tol_sq on
    # the data; None when none does or there are too many contacts to try. Every contact
    # touching is left out: that is the sticking impulse -W^-1 q, tried after the
    # polyhedral restarts (the answer they find first where it is one)
    nc = mu.shape[0]
    if nc > STICK_OR_OPEN_MAX_CONTACTS:
        return None
    for mask in range((1 << nc) - 1):
        S = [i for i in range(nc) if mask >> i & 1]
        rows = np.array([3 * i + j for i in S for j in range(3)], dtype=np.intp)
        r = np.zeros_like(q)
        if rows.size:
            try:
                r[rows] = np.linalg.solve(W[np.ix_(rows, rows)], -q[rows])
            except np.linalg.LinAlgError:
                continue
            if not np.all(np.isfinite(r)):
                continue
        r = _project_all(r, mu)
        res = _natural_sq(r, W @ r + q, mu)
        if res <= tol_sq:
            return r, res, S
    return None


def solve_exact(W, q, mu, *, tol=1e-10, max_sweeps=500, max_newton=30, polish_from=1e-6,
                r0=None, check=True):
    """Solve the spatial friction problem on the exact (round) Coulomb cone.

    Projected Gauss–Seidel over contacts with the exact local solve
    (:func:`local_solve`) until the relative residual is below
    ``max(tol, polish_from)`` or 50 sweeps bring no new least residual (it
    can cycle when ``mu`` is large), then Newton on the Alart–Curnier
    function (quadratic near a nondegenerate solution) to ``tol`` with half
    the Newton budget. If that fails, Newton restarts from the
    16-direction polyhedral solution (:func:`solve_polyhedral`), then from
    the 32-, 64- and 128-direction ones while it still fails (with a large
    ``mu`` Lemke's answer need not be the one near the round cone's), then
    from the sticking impulse ``-W^-1 q`` projected on the cones (the
    answer itself where every contact sticks, which Lemke's paths can
    miss); each restart has its own budget of ``max_newton`` steps, so
    Newton takes at most ``5.5 max_newton`` steps in all (and
    ``max_newton`` more at the end, below). Last, under-relaxed
    Gauss–Seidel (each contact moved half way to its local solution)
    spends the sweeps left. The point of least natural-map residual met is
    projected on the cones: that projection is the answer, and its
    residual on the data the one reported (where the projection misses the
    bound that Newton's iterate met, Newton goes on from it to a hundredth
    of the bound first). Two direct candidates come before the finer
    polygons, each taken only where it meets the bound on the data: where
    ``W`` is singular (a resting stack of boxes), the least-norm sticking
    impulse ``-W^+ q`` projected on the cones (before the 16-direction
    restart); and, up to :data:`STICK_OR_OPEN_MAX_CONTACTS` contacts, every
    set of contacts sticking with the others open but the set of all (after
    it). ``detail`` says which phases ran. Measured on
    100 000 random problems of the property test's kind (``mu`` from 0 to
    3, one to six contacts): all converged in the cones but one (five
    contacts, ``mu = 2.55``: Newton stalls near 1e-2 from every start, and
    Lemke's 128-direction LCP took its exact-arithmetic path for minutes),
    which the sticking and open sets solve (four stick, one is open).

    Parameters
    ----------
    W, q, mu :
        The problem (:func:`check_cone_problem`).
    tol : float
        Stop when ``cone_residual <= tol * ||q||`` (``q = 0``: ``r = 0``).
    max_sweeps, max_newton : int
        Budgets: Gauss–Seidel sweeps (``>= 1``) and Newton steps (``>= 0``)
        of each Newton run (half of it for the first, from Gauss–Seidel's
        point).
    polish_from : float
        Relative residual at which Newton takes over.
    r0 : array_like, optional
        Starting impulse (default zero).
    check : bool
        False skips :func:`check_cone_problem` (see :func:`solve_polyhedral`).

    Returns
    -------
    ConeSolution
        ``status`` ``"converged"`` or ``"not converged"``; ``residual`` the
        true natural-map residual on the given data, finite.

    Examples
    --------
    >>> W = np.array([[2.0, 0.5, 0.0, 1.0, 0.0, 0.0], [0.5, 3.0, 0.0, 0.0, 0.0, 0.0],
    ...               [0.0, 0.0, 3.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 2.0, 0.0, 0.5],
    ...               [0.0, 0.0, 0.0, 0.0, 3.0, 0.0], [0.0, 0.0, 0.0, 0.5, 0.0, 3.0]])
    >>> sol = solve_exact(W, np.array([-1.0, 2.0, 0.0, -1.0, 0.0, -2.0]), 0.3)
    >>> sol.status, sol.relative_residual < 1e-10
    ('converged', True)
    >>> solve_exact(W, np.array([-1.0, 2.0, 0.0, -1.0, 0.0, -2.0]), 0.3,
    ...             max_sweeps=1, max_newton=0).status
    'not converged'
    """
    W, q, mu = check_cone_problem(W, q, mu) if check else _trusted(W, q, mu)
    for name, value, low in (("max_sweeps", max_sweeps, 1), ("max_newton", max_newton, 0)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise InputError(f"`{name}` must be an integer >= {low}, got {value!r}")
    for name, value in (("tol", tol), ("polish_from", polish_from)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) \
                or not 0.0 < float(value) < 1.0:
            raise InputError(f"`{name}` must be a number in (0, 1), got {value!r}")
    r = np.zeros_like(q) if r0 is None else finite_array("r0", r0, shape=q.shape).copy()
    qn = float(np.linalg.norm(q))
    scale = qn if qn > 0.0 else 1.0
    u = W @ r + q
    tol_sq = (tol * scale) ** 2
    switch_sq = (max(tol, polish_from) * scale) ** 2
    sweeps, res = _pgs(W, q, mu, r, u, int(max_sweeps), switch_sq, 1.0, _STALL)
    newton = 0
    how = []
    if res > tol_sq and max_newton > 0:
        # half the budget: the rest is for a restart (Newton converges in a
        # few steps from a good point, or not at all)
        r_n, res_n, newton = _newton(W, q, mu, r, (int(max_newton) + 1) // 2, tol_sq)
        if res_n < res:
            r, res = r_n, res_n
    if res > tol_sq and max_newton > 0 and q.shape[0] > 3:
        # W singular (more contact rows than the bodies' freedoms: a resting stack of
        # boxes, four points a face): every contact sticking with the least-norm impulse
        # r = -W^+ q, where np.linalg.solve's is noise, is the answer of a stack at rest
        # (box-stack-3d, three cubes: 1.5e-14 |q|, where Newton stalled and the
        # 16-gon's Lemke path met exact arithmetic on W's rounding); taken only where
        # it meets the bound on the data
        r_ls, _, rank, _ = np.linalg.lstsq(W, -q, rcond=None)
        if rank < q.shape[0] and np.all(np.isfinite(r_ls)):
            r_ls = _project_all(r_ls, mu)
            res_ls = _natural_sq(r_ls, W @ r_ls + q, mu)
            if res_ls <= tol_sq:
                r, res = r_ls, res_ls
                how.append(f"the least-norm sticking impulse -W^+ q (W of rank {rank} < "
                           f"{q.shape[0]}) is the answer")
    if res > tol_sq and max_newton > 0:
        # Gauss–Seidel stalled and Newton did not converge from its point:
        # start Newton again from the polyhedral cone's solution (Lemke always
        # reaches one for W positive semidefinite), O(1/d) from an exact one;
        # each restart has its own budget of max_newton steps
        poly = solve_polyhedral(W, q, mu, _RESTART_D)
        if poly.success:
            r, res, more = _restart(W, q, mu, poly.r, max_newton, tol_sq, r, res)
            newton += more
            how.append(f"Newton restarted from the {_RESTART_D}-direction polyhedral solution "
                       f"({poly.iterations['pivots']} Lemke pivots)")
            if res > tol_sq:
                # each contact sticking or open, r_S = -W_SS^-1 q_S on the touching set S:
                # an answer Newton can stall beside (seed 2839128055, mu 2.55: four stick,
                # one lifts off; Newton stalls near 1e-2 from every start), and cheap
                # against the finer polygons' Lemke paths (n = 650 at d = 128)
                found = _stick_or_open(W, q, mu, tol_sq)
                if found is not None:
                    r, res = found[0], found[1]
                    how.append(f"the answer found among the {(1 << mu.shape[0]) - 1} sets of "
                               f"sticking and open contacts (touching: {found[2]})")
            # with a large mu the polyhedral LCP can have several solutions and
            # Lemke's may lie outside Newton's basin (a contact slipping where
            # the round cone's solution sticks); finer polygons start Lemke on
            # other paths and lie closer to the round cone (seed 7656, mu 2:
            # d = 64 gives the round cone's solution itself, all sticking)
            start = poly.r
            for d in _FINER_D:
                if res <= tol_sq:
                    break
                poly = solve_polyhedral(W, q, mu, d)
                if not poly.success:
                    continue
                if np.max(np.abs(poly.r - start)) <= 1e-9 * np.max(np.abs(start)):
                    # the coarser polygon's vertex again (up to rounding):
                    # Newton would repeat its steps
                    continue
                start = poly.r
                r, res, more = _restart(W, q, mu, poly.r, max_newton, tol_sq, r, res)
                newton += more
                how.append(f"Newton restarted from the {d}-direction polyhedral solution "
                           f"({poly.iterations['pivots']} Lemke pivots, {more} step(s))")
        if res > tol_sq:
            # every contact sticking, r = -W^-1 q, projected on the cones: the answer
            # itself where it lies in them (mu above every contact's |r_T| / r_N there),
            # which Lemke's paths and Newton's from them can miss (seed 7656, mu 1.965)
            try:
                stick = _project_all(np.linalg.solve(W, -q), mu)
            except np.linalg.LinAlgError:
                stick = None
            if stick is not None and np.all(np.isfinite(stick)):
                r, res, more = _restart(W, q, mu, stick, max_newton, tol_sq, r, res)
                newton += more
                how.append(f"Newton restarted from the sticking impulse -W^-1 q projected on "
                           f"the cones ({more} step(s))")
    if res > tol_sq and sweeps < max_sweeps:
        r = r.copy()
        u = W @ r + q
        more, res = _pgs(W, q, mu, r, u, int(max_sweeps) - sweeps, tol_sq, 0.5, max_sweeps)
        sweeps += more
        how.append(f"{more} under-relaxed (1/2) sweep(s) at the end")
    # the answer lies in the cones: Newton's iterate may stand a little outside them, and
    # its projection is the answer, its residual on the data the one reported; where the
    # projection costs more than the bound allows, Newton goes on from the iterate to a
    # hundredth of the bound (its own budget of max_newton steps) and is projected again
    r_in = _project_all(r, mu)
    res_in = _natural_sq(r_in, W @ r_in + q, mu)
    if res_in > tol_sq and res <= tol_sq and max_newton > 0:
        r_n, _, more = _newton(W, q, mu, r.copy(), int(max_newton), 1e-4 * tol_sq)
        newton += more
        r_p = _project_all(r_n, mu)
        res_p = _natural_sq(r_p, W @ r_p + q, mu)
        how.append(f"{more} Newton step(s) more, the answer's projection on the cones "
                   f"missing the bound")
        if res_p < res_in:
            r_in, res_in = r_p, res_p
    r = r_in
    u = W @ r + q
    res = math.sqrt(_natural_sq(r, u, mu))
    status = CONVERGED if res <= tol * scale else NOT_CONVERGED
    detail = (f"{sweeps} Gauss–Seidel sweep(s) with the exact local solve, {newton} Alart–Curnier "
              f"Newton step(s){''.join('; ' + h for h in how)}; residual {res:.3g} against the bound {tol * scale:.3g} "
              f"(tol {tol:g} x ||q||).")
    return ConeSolution(r, u, status, res, res / qn if qn > 0 else res,
                        {"sweeps": int(sweeps), "newton": int(newton)}, "exact", detail)


@njit(cache=True)
def natural_map_sq(r, u, mu):
    """The squared natural-map residual ``||r - proj_K(r - û)||^2`` with ``u`` given, compiled.

    :func:`cone_residual` without the checks and the product ``u = W r + q``,
    for compiled callers (a time-stepping loop).

    Examples
    --------
    >>> round(natural_map_sq(np.zeros(3), np.array([-1.0, 3.0, 4.0]), np.array([0.5])), 12)
    0.8
    """
    return _natural_sq(r, u, mu)


@njit(cache=True)
def exact_gauss_seidel(W, q, mu, r, u, tol, polish_from, max_sweeps):
    """:func:`solve_exact`'s path where Gauss–Seidel alone converges, compiled.

    From ``r`` with ``u = W r + q`` (both updated in place), the exact local
    Gauss–Seidel sweeps of :func:`solve_exact` up to its Newton switch; where
    they reach ``tol`` the answer ends as :func:`solve_exact`'s does (its
    projection on the cones, the residual that of the projection), on
    contiguous float arrays checked by the caller. Where they do not, or the
    projection misses the bound, :func:`solve_exact` would go on with Newton:
    the caller hands the problem to it.

    Returns
    -------
    converged : bool
        ``residual <= tol ||q||``; False where Newton's polish is needed.
    residual : float
        The natural-map residual of ``r`` on the data (after the sweeps).
    qnorm : float
        ``||q||``.

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5]); q = np.array([-1.0, 3.0, 4.0])
    >>> r = np.zeros(3); u = q.copy()
    >>> ok, res, qn = exact_gauss_seidel(W, q, np.array([0.5]), r, u, 1e-10, 1e-6, 500)
    >>> bool(ok), np.round(r, 12).tolist(), qn
    (True, [1.0, -0.3, -0.4], 5.0990195135927845)
    """
    n = q.shape[0]
    return exact_gauss_seidel_into(W, q, mu, r, u, tol, polish_from, max_sweeps,
                                   np.empty((3, 3)), np.empty(3), np.empty(n), np.empty(n))


# inlined by numba, like _stick
@njit(inline="always")
def _bound_sq(q, tol):
    # ||q||, the scale of the bound (1 where q = 0) and the bound squared, (tol scale)^2
    qn = 0.0
    for j in range(q.shape[0]):
        qn += q[j] * q[j]
    qn = math.sqrt(qn)
    scale = qn if qn > 0.0 else 1.0
    return qn, scale, (tol * scale) ** 2


@njit(cache=True)
def exact_gauss_seidel_into(W, q, mu, r, u, tol, polish_from, max_sweeps, A, b, r_in, u_in):
    """:func:`exact_gauss_seidel` on the caller's scratch: ``A`` (at least 3 x 3), ``b`` (at
    least 3), ``r_in`` and ``u_in`` (at least ``q``'s length); the same operations.

    For a time-stepping loop that allocates nothing a step.

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5]); q = np.array([-1.0, 3.0, 4.0])
    >>> r = np.zeros(3); u = q.copy()
    >>> ok, res, qn = exact_gauss_seidel_into(W, q, np.array([0.5]), r, u, 1e-10, 1e-6, 500,
    ...                                       np.empty((3, 3)), np.empty(3), np.empty(3),
    ...                                       np.empty(3))
    >>> bool(ok), np.round(r, 12).tolist()
    (True, [1.0, -0.3, -0.4])
    """
    n = q.shape[0]
    qn, scale, tol_sq = _bound_sq(q, tol)
    switch_sq = (max(tol, polish_from) * scale) ** 2
    # np.int64: a literal (the global) would compile _pgs_into again
    _, res = _pgs_into(W, q, mu, r, u, max_sweeps, switch_sq, 1.0, np.int64(_STALL), A, b)
    if res > tol_sq:
        return False, math.sqrt(res), qn
    for i in range(mu.shape[0]):
        k = 3 * i
        r_in[k], r_in[k + 1], r_in[k + 2] = _proj(r[k], r[k + 1], r[k + 2], mu[i])
    _affine_into(W, q, r_in, u_in)
    res_in = _natural_sq(r_in, u_in, mu)
    if res_in > tol_sq:
        # the answer must lie in the cones, and its projection misses the bound: not
        # converged here (Newton's polish goes on from r)
        return False, math.sqrt(res_in), qn
    for j in range(n):
        r[j] = r_in[j]
        u[j] = u_in[j]
    res = math.sqrt(_natural_sq(r, u, mu))
    return res <= tol * scale, res, qn


@njit(cache=True)
def _alart_curnier_into(W, q, mu, rho, r, u, phi, J):
    # _alart_curnier's function and Jacobian written into phi and J, in its order of operations
    n = r.shape[0]
    _affine_into(W, q, r, u)
    for i in range(mu.shape[0]):
        k = 3 * i
        p = rho[i]
        tau = r[k] - p * u[k]
        active = tau > 0.0
        phi[k] = r[k] - max(tau, 0.0)
        for j in range(n):
            # the row of dtau = e_k - p W[k]
            dt = -p * W[k, j]
            if j == k:
                dt += 1.0
            J[k, j] = ((1.0 if j == k else 0.0) - dt) if active else (1.0 if j == k else 0.0)
        x0 = r[k + 1] - p * u[k + 1]
        x1 = r[k + 2] - p * u[k + 2]
        radius = mu[i] * max(tau, 0.0)
        nx = math.hypot(x0, x1)
        if nx <= radius:
            phi[k + 1] = p * u[k + 1]
            phi[k + 2] = p * u[k + 2]
            for j in range(n):
                J[k + 1, j] = p * W[k + 1, j]
                J[k + 2, j] = p * W[k + 2, j]
        else:
            h0 = x0 / nx
            h1 = x1 / nx
            phi[k + 1] = r[k + 1] - radius * h0
            phi[k + 2] = r[k + 2] - radius * h1
            f = radius / nx
            p00 = f * (1.0 - h0 * h0)
            p01 = f * (0.0 - h0 * h1)
            p11 = f * (1.0 - h1 * h1)
            for j in range(n):
                d0 = -p * W[k + 1, j]
                d1 = -p * W[k + 2, j]
                if j == k + 1:
                    d0 += 1.0
                if j == k + 2:
                    d1 += 1.0
                dp0 = p00 * d0 + p01 * d1
                dp1 = p01 * d0 + p11 * d1
                if active:
                    dt = -p * W[k, j]
                    if j == k:
                        dt += 1.0
                    dp0 += mu[i] * h0 * dt
                    dp1 += mu[i] * h1 * dt
                J[k + 1, j] = (1.0 if j == k + 1 else 0.0) - dp0
                J[k + 2, j] = (1.0 if j == k + 2 else 0.0) - dp1


@njit(cache=True)
def _lu_solve(A, b, x, floor):
    # A x = b by Gaussian elimination with partial pivoting (A, b overwritten); False on a
    # pivot at or below `floor`: A singular to rounding (a box's corners at rest)
    n = b.shape[0]
    for c in range(n):
        p = c
        for i in range(c + 1, n):
            if abs(A[i, c]) > abs(A[p, c]):
                p = i
        if abs(A[p, c]) <= floor:
            return False
        if p != c:
            for j in range(n):
                A[c, j], A[p, j] = A[p, j], A[c, j]
            b[c], b[p] = b[p], b[c]
        for i in range(c + 1, n):
            f = A[i, c] / A[c, c]
            if f != 0.0:
                for j in range(c + 1, n):
                    A[i, j] -= f * A[c, j]
                b[i] -= f * b[c]
    for c in range(n - 1, -1, -1):
        acc = b[c]
        for j in range(c + 1, n):
            acc -= A[c, j] * x[j]
        x[c] = acc / A[c, c]
    return True


#: a Newton Jacobian whose pivot falls to this fraction of its largest entry is singular
_SINGULAR = 1e-13


@njit(cache=True)
def _least_norm_step(J, rhs, step, A, b):
    # the least-norm solution of J step = rhs where J is singular to rounding, by the normal
    # equations regularised at 1e-14 of their scale, (J^T J + eps I) step = J^T rhs (the
    # null-space part damped to zero, the rest exact to the conditioning of J on its range;
    # LAPACK's least squares would cost the compile of its bindings); A and b are scratch
    n = rhs.shape[0]
    scale = 0.0
    for a in range(n):
        for c in range(n):
            acc = 0.0
            for k in range(n):
                acc += J[k, a] * J[k, c]
            A[a, c] = acc
        scale = max(scale, A[a, a])
        acc = 0.0
        for k in range(n):
            acc += J[k, a] * rhs[k]
        b[a] = acc
    for a in range(n):
        A[a, a] += 1e-14 * scale
    if not _lu_solve(A, b, step, 0.0):
        for a in range(n):
            step[a] = 0.0


@njit(cache=True)
def _all_finite(x):
    for j in range(x.shape[0]):
        if not math.isfinite(x[j]):
            return False
    return True


@njit(cache=True)
def _armijo(W, q, mu, rho, r, step, merit, trial, ut, phi, J):
    # _newton's search: the step halved until the merit |phi|^2 falls by 1e-4 t, down to 1e-10;
    # trial holds the last point tried
    n = r.shape[0]
    t = 1.0
    while True:
        for j in range(n):
            trial[j] = r[j] + t * step[j]
        _alart_curnier_into(W, q, mu, rho, trial, ut, phi, J)
        mt = 0.0
        for j in range(n):
            mt += phi[j] * phi[j]
        if mt <= (1.0 - 1e-4 * t) * merit or t < 1e-10:
            return t
        t *= 0.5


@njit(cache=True)
def exact_newton_polish(W, q, mu, r, u, tol, max_newton):
    """:func:`solve_exact`'s Newton polish after its Gauss–Seidel phase, compiled.

    From ``r`` (Gauss–Seidel's last iterate, :func:`exact_gauss_seidel`) the
    nonsmooth Newton method of :func:`solve_exact` on the Alart–Curnier
    function (``rho_i = 1 / W_NN,i``, Armijo's search halving the step down
    to ``1e-10``), ``max_newton`` steps at most, keeping the iterate of
    least natural-map residual; then, as :func:`solve_exact` ends, the
    projection of ``r`` on the cones, not converged where that misses the
    bound. ``r`` and ``u = W r + q`` are updated in place, on contiguous
    float arrays checked by the caller. The linear solves are Gaussian
    elimination with partial pivoting (LAPACK's in :func:`solve_exact`: the
    two agree to rounding), the least-norm solution where a pivot shows the
    Jacobian singular to rounding. Where that Newton does not reach ``tol
    ||q||``, :func:`solve_exact` restarts from the polyhedral solution; here
    Newton runs again from the same start with least-norm steps throughout
    (a Jacobian with a null space: contacts whose forces are statically
    indeterminate, a box's corners, where elimination does not always see
    the singularity). Where that misses too the caller hands the problem
    to :func:`solve_exact`.

    Returns
    -------
    converged : bool
        ``residual <= tol ||q||``.
    residual : float
        The natural-map residual of ``r`` on the data (:func:`cone_residual`).
    qnorm : float
        ``||q||``.
    steps : int
        Newton steps taken (both runs).

    Examples
    --------
    Two contacts of one body, where Gauss–Seidel alone stops at ``1e-6``:

    >>> W = np.array([[2.0, 0.5, 0.0, 1.0, 0.0, 0.0], [0.5, 3.0, 0.0, 0.0, 0.0, 0.0],
    ...               [0.0, 0.0, 3.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 2.0, 0.0, 0.5],
    ...               [0.0, 0.0, 0.0, 0.0, 3.0, 0.0], [0.0, 0.0, 0.0, 0.5, 0.0, 3.0]])
    >>> q = np.array([-1.0, 2.0, 0.0, -1.0, 0.0, -2.0]); mu = np.array([0.3, 0.3])
    >>> r = np.zeros(6); u = q.copy()
    >>> ok, res, qn = exact_gauss_seidel(W, q, mu, r, u, 1e-10, 1e-6, 500)
    >>> bool(ok), res > 1e-10 * qn
    (False, True)
    >>> ok, res, qn, steps = exact_newton_polish(W, q, mu, r, u, 1e-10, 15)
    >>> bool(ok), res <= 1e-10 * qn, bool(np.abs(r - solve_exact(W, q, mu).r).max() < 1e-14)
    (True, True, True)
    """
    n = q.shape[0]
    nc = mu.shape[0]
    qn, scale, tol_sq = _bound_sq(q, tol)
    rho = np.empty(nc)
    for i in range(nc):
        rho[i] = 1.0 / W[3 * i, 3 * i]
    start = r.copy()
    best_r = r.copy()
    # np.bool_ flags, not literals, which would compile _newton_run once for each value
    best, it = _newton_run(W, q, mu, rho, r, best_r, tol_sq, max_newton, np.False_)
    if best > tol_sq:
        # solve_exact's Newton missed (it would restart from the polyhedral solution): the
        # Jacobian is singular to rounding where it has a null space (a box's corners, their
        # forces statically indeterminate), which Gaussian elimination does not always see;
        # Newton again from the same point with the least-norm steps
        best2_r = start.copy()
        best2, more = _newton_run(W, q, mu, rho, start, best2_r, tol_sq, max_newton,
                                  np.True_)
        it += more
        if best2 < best:
            best = best2
            best_r[:] = best2_r
    if best > tol_sq:
        return False, math.sqrt(best), qn, it
    r[:] = best_r
    r_in = _project_all(r, mu)
    ut = np.empty(n)
    _affine_into(W, q, r_in, ut)
    res_in = _natural_sq(r_in, ut, mu)
    if res_in > tol_sq:
        # the answer must lie in the cones, and the projection of Newton's iterate misses the
        # bound: solve_exact (the caller's) polishes further before projecting
        return False, math.sqrt(res_in), qn, it
    r[:] = r_in
    _affine_into(W, q, r, u)
    res = math.sqrt(_natural_sq(r, u, mu))
    return res <= tol * scale, res, qn, it


@njit(cache=True)
def _newton_run(W, q, mu, rho, r, best_r, tol_sq, max_newton, least_norm):
    # _newton from r (moved): at most max_newton steps, best_r the iterate of least natural
    # residual (r's own to begin with); returns that residual squared and the steps taken.
    # Steps by Gaussian elimination as LAPACK's solve in _newton, the least-norm solution
    # where a pivot shows J singular to rounding, or throughout with `least_norm`
    n = r.shape[0]
    phi = np.empty(n)
    J = np.empty((n, n))
    Jc = np.empty((n, n))
    rhs = np.empty(n)
    step = np.empty(n)
    trial = np.empty(n)
    ut = np.empty(n)
    _affine_into(W, q, r, ut)
    best = _natural_sq(r, ut, mu)
    it = 0
    while it < max_newton and best > tol_sq:
        _alart_curnier_into(W, q, mu, rho, r, ut, phi, J)
        merit = 0.0
        big = 0.0
        for j in range(n):
            merit += phi[j] * phi[j]
            phi[j] = -phi[j]
            for l in range(n):
                big = max(big, abs(J[j, l]))
        Jc[:, :] = J
        rhs[:] = phi
        if least_norm or not _lu_solve(J, phi, step, _SINGULAR * big):
            _least_norm_step(Jc, rhs, step, J, phi)
        if not _all_finite(step):
            break
        t = _armijo(W, q, mu, rho, r, step, merit, trial, ut, phi, J)
        it += 1
        if t < 1e-10:
            break
        r[:] = trial
        _affine_into(W, q, r, ut)
        res = _natural_sq(r, ut, mu)
        if res < best:
            best = res
            best_r[:] = r
    return best, it


def solve_cone(W, q, mu, cone="exact", **options):
    """Solve the spatial friction problem with the cone a scheme's ``cone`` option names.

    Parameters
    ----------
    W, q, mu :
        The problem (:func:`check_cone_problem`).
    cone : "exact" or int
        ``"exact"``: :func:`solve_exact`; an integer ``d >= 3``:
        :func:`solve_polyhedral` with ``d`` directions.
    **options
        Passed to the solver chosen.

    Returns
    -------
    ConeSolution

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5]); q = np.array([-1.0, 0.0, 4.0])
    >>> [(solve_cone(W, q, 0.5, cone=c).r.round(12) + 0.0).tolist() for c in ("exact", 4)]
    [[1.0, 0.0, -0.5], [1.0, 0.0, -0.5]]
    >>> solve_cone(W, q, 0.5, cone="round")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `cone` must be "exact" or an integer number of directions >= 3, got 'round'
    """
    if isinstance(cone, str) and cone == "exact":
        return solve_exact(W, q, mu, **options)
    if isinstance(cone, bool) or not isinstance(cone, (int, np.integer)) or cone < 3:
        raise InputError(f'`cone` must be "exact" or an integer number of directions >= 3, '
                         f'got {cone!r}')
    return solve_polyhedral(W, q, mu, int(cone), **options)


# --------------------------------------------------------------------------- Coulomb–Contensou

def _proj_nd(x, mu):
    # projection on K = {|t| <= mu n}, t of any dimension (a contact's rows after the normal)
    n = x[0]
    nt = float(np.linalg.norm(x[1:]))
    if nt <= mu * n:
        return x.copy()
    if mu * nt <= -n:
        return np.zeros_like(x)
    nn = (n + mu * nt) / (1.0 + mu * mu)
    out = np.empty_like(x)
    out[0] = nn
    out[1:] = (mu * nn / nt) * x[1:]
    return out


def project_contensou(x, mu, lever):
    r"""Project ``x = [N, F1, F2, M]`` on Coulomb–Contensou's ellipsoidal cone, in its metric.

    The cone is ``{(N, F, M) : |F|^2 + (M / r*)^2 <= (mu N)^2}``
    (:mod:`moreau.model.space`, "Coulomb–Contensou friction", ``r* =
    lever``), and the projection is the nearest point in the metric ``G =
    diag(1, 1, 1, 1 / r*^2)``: with ``S = G^(1/2)``, ``(x - z)^T G (x - z) =
    |S x - S z|^2`` and ``S z`` ranges over the round cone ``|t| <= mu n`` of
    three tangential rows, so the answer is ``S^-1 proj(S x)``.

    Examples
    --------
    >>> project_contensou([1.0, 3.0, 4.0, 0.0], 0.5, 0.1).round(12).tolist()   # the force alone
    [2.8, 0.84, 1.12, 0.0]
    >>> project_contensou([1.0, 0.0, 0.0, 0.2], 0.5, 0.1).round(12).tolist()   # the torque alone
    [1.6, 0.0, 0.0, 0.08]
    """
    x = finite_array("x", x, shape=(4,))
    mu = float(mu)
    if not math.isfinite(mu) or mu < 0.0:
        raise InputError(f"`mu` must be a finite number >= 0, got {mu!r}")
    lever = float(lever)
    if not math.isfinite(lever) or lever <= 0.0:
        raise InputError(f"`lever` must be a finite number > 0 (r* = 2 r / 3), got {lever!r}")
    y = x.copy()
    y[3] /= lever
    p = _proj_nd(y, mu)
    p[3] *= lever
    return p


@njit(cache=True)
def _natural_sq_blocks(r, u, mu, starts):
    # sum over contacts of |r - proj_K(r - û)|^2, a contact's rows starts[i]:starts[i+1]
    total = 0.0
    for i in range(mu.shape[0]):
        a, b = starts[i], starts[i + 1]
        m = mu[i]
        ut = 0.0
        for j in range(a + 1, b):
            ut += u[j] * u[j]
        xn = r[a] - (u[a] + m * math.sqrt(ut))
        xt = 0.0
        for j in range(a + 1, b):
            xt += (r[j] - u[j]) ** 2
        xt = math.sqrt(xt)
        # the projection of x = (xn, x_T) on {|t| <= m n}: x, the apex, or scaled onto the cone
        if xt <= m * xn:
            pn, f = xn, 1.0
        elif m * xt <= -xn:
            pn, f = 0.0, 0.0
        else:
            pn = (xn + m * xt) / (1.0 + m * m)
            f = m * pn / xt
        total += (r[a] - pn) ** 2
        for j in range(a + 1, b):
            total += (r[j] - f * (r[j] - u[j])) ** 2
    return total


@njit(cache=True)
def _secular(c, d, m):
    # alpha >= 0 with |(diag(d) + alpha)^-1 c| = 1 (d >= 0), or 0 where that norm is <= 1 at 0,
    # over the first m entries: 1/|s(alpha)| - 1 is concave and increasing, so Newton from
    # the left end of the bracket [|c| - max d, |c| - min d] climbs monotonically to the root
    # (bisection guards rounding)
    cn = 0.0
    for k in range(m):
        cn += c[k] * c[k]
    cn = math.sqrt(cn)
    if cn == 0.0:
        return 0.0
    at0 = 0.0
    for k in range(m):
        if c[k] != 0.0:
            at0 = math.inf if d[k] == 0.0 else at0 + (c[k] / d[k]) ** 2
    if at0 <= 1.0:
        return 0.0
    dmax, dmin = d[0], d[0]
    for k in range(1, m):
        dmax = max(dmax, d[k])
        dmin = min(dmin, d[k])
    lo, hi = max(cn - dmax, 0.0), max(cn - dmin, 0.0)
    a = lo if lo > 0.0 else min(hi, 1e-300 + 1e-16 * cn)
    for _ in range(100):
        s2 = 0.0
        s3 = 0.0
        for k in range(m):
            e = c[k] / (d[k] + a)
            s2 += e * e
            s3 += e * e / (d[k] + a)
        norm = math.sqrt(s2)
        phi = 1.0 / norm - 1.0
        if phi > 0.0:
            hi = min(hi, a)
        else:
            lo = max(lo, a)
        dphi = s3 / (s2 * norm)
        new = a - phi / dphi if dphi > 0.0 else 0.5 * (lo + hi)
        if not lo <= new <= hi:
            new = 0.5 * (lo + hi)
        if abs(new - a) <= 4e-16 * (a + cn):
            return new
        a = new
    return a


def local_solve_contensou(A, b, mu):
    """Solve one contact's problem ``u = A r + b`` on the round cone of any tangential dimension.

    ``A`` is ``m x m`` (``m = 3`` for a point contact, ``4`` with the
    drilling row of Coulomb–Contensou friction), symmetric positive definite.
    Take-off when ``b_N >= 0``; stick when ``r = -A^-1 b`` lies in the cone;
    otherwise slip, ``r = rho (1, -mu s)`` with ``|s| = 1``, ``u_N = 0`` and
    ``u_T = alpha s``, ``alpha >= 0``. For a given ``rho`` the tangential
    rows read ``(mu rho A_TT + alpha I) s = rho A_TN + b_T``: with ``A_TT =
    Q diag(l) Q^T`` the norm of ``s`` falls monotonically with ``alpha``, so
    ``s(rho)`` is unique (a secular equation, solved by safeguarded Newton to
    rounding). The normal row leaves the scalar equation ``g(rho) = A_NN rho
    - mu rho A_NT . s(rho) + b_N = 0``, with ``g(0) = b_N < 0``, bracketed
    by doubling and solved by Brent's method to rounding.

    Examples
    --------
    >>> A = np.diag([1.0, 3.5, 3.5, 3.5])
    >>> (np.round(local_solve_contensou(A, [-1.0, 3.0, 0.0, 4.0], 0.5), 14) + 0.0).tolist()
    [1.0, -0.3, 0.0, -0.4]
    """
    A = np.ascontiguousarray(finite_array("A", A, ndim=2))
    b = np.ascontiguousarray(finite_array("b", b, shape=(A.shape[0],)))
    r = np.empty(b.shape[0])
    _local_nd(A, b, float(mu), r)
    return r


@njit(cache=True)
def _solve_small(A, b, x, M):
    # A x = b for an m x m block (m <= 4) by Gaussian elimination with partial pivoting on
    # the scratch M (m x (m + 1)); False where a pivot vanishes
    m = b.shape[0]
    for i in range(m):
        for j in range(m):
            M[i, j] = A[i, j]
        M[i, m] = b[i]
    for c in range(m):
        p = c
        for i in range(c + 1, m):
            if abs(M[i, c]) > abs(M[p, c]):
                p = i
        if M[p, c] == 0.0:
            return False
        if p != c:
            for j in range(m + 1):
                M[c, j], M[p, j] = M[p, j], M[c, j]
        for i in range(c + 1, m):
            f = M[i, c] / M[c, c]
            for j in range(c, m + 1):
                M[i, j] -= f * M[c, j]
    for c in range(m - 1, -1, -1):
        acc = M[c, m]
        for j in range(c + 1, m):
            acc -= M[c, j] * x[j]
        x[c] = acc / M[c, c]
    return True


@njit(cache=True)
def _slip_direction(A, b, mu, rho, lam, Q, cc, dd, s):
    # s(rho): (mu rho A_TT + alpha I) s = rho A_TN + b_T with |s| = 1, in A_TT's eigenbasis
    m = b.shape[0] - 1
    for k in range(m):
        acc = 0.0
        for j in range(m):
            acc += Q[j, k] * (rho * A[j + 1, 0] + b[j + 1])
        cc[k] = acc
        dd[k] = (mu * rho) * lam[k]
    alpha = _secular(cc, dd, m)
    for j in range(m):
        acc = 0.0
        for k in range(m):
            if cc[k] != 0.0:
                acc += Q[j, k] * (cc[k] / (dd[k] + alpha))
        s[j] = acc


@njit(cache=True)
def _slip_g(A, b, mu, rho, lam, Q, cc, dd, s):
    # the normal row's g(rho) = A_NN rho - mu rho A_NT . s(rho) + b_N
    _slip_direction(A, b, mu, rho, lam, Q, cc, dd, s)
    acc = 0.0
    for j in range(b.shape[0] - 1):
        acc += A[0, j + 1] * s[j]
    return A[0, 0] * rho - mu * rho * acc + b[0]


@njit(cache=True)
def _local_nd(A, b, mu, r):
    # local_solve_contensou's solve into r (any m >= 2 rows): take-off, stick, or slip with
    # g(rho) = 0 found by Brent's method (bisection, secant and inverse quadratic
    # interpolation, the bracket kept; Brent 1973, "Algorithms for minimization without
    # derivatives", ch. 4) to rounding
    m = b.shape[0]
    for k in range(m):
        r[k] = 0.0
    if b[0] >= 0.0:
        return
    if mu == 0.0:
        r[0] = -b[0] / A[0, 0]
        return
    M = np.empty((m, m + 1))
    rs = np.empty(m)
    nb = np.empty(m)
    for k in range(m):
        nb[k] = -b[k]
    solved = _solve_small(A, nb, rs, M)
    if solved:
        nt = 0.0
        for k in range(1, m):
            nt += rs[k] * rs[k]
        if rs[0] >= 0.0 and math.sqrt(nt) <= mu * rs[0]:
            for k in range(m):
                r[k] = rs[k]
            return
    lam, Q = np.linalg.eigh(np.ascontiguousarray(A[1:, 1:]))
    for k in range(m - 1):
        lam[k] = max(lam[k], 0.0)
    cc = np.empty(m - 1)
    dd = np.empty(m - 1)
    s = np.empty(m - 1)
    hi = -b[0] / A[0, 0]
    ghi = 0.0
    found = False
    for _ in range(200):
        ghi = _slip_g(A, b, mu, hi, lam, Q, cc, dd, s)
        if ghi > 0.0:
            found = True
            break
        hi *= 2.0
    if not found:
        # no slip root (a Painlevé-like block)
        if solved and rs[0] >= 0.0:
            for k in range(m):
                r[k] = rs[k]
        return
    rho = _brent(A, b, mu, 0.0, hi, b[0], ghi, lam, Q, cc, dd, s)
    _slip_direction(A, b, mu, rho, lam, Q, cc, dd, s)
    r[0] = rho
    for k in range(m - 1):
        r[k + 1] = -mu * rho * s[k]


@njit(cache=True)
def _brent(A, b, mu, xa, xb, fa, fb, lam, Q, cc, dd, s):
    # a root of g in [xa, xb] (fa, fb of opposite signs) to |dx| <= 4e-16 |x| (8.9e-16 rtol
    # over two), keeping a bracket [b, c] with |g(b)| <= |g(c)| and the step before last
    if fa == 0.0:
        return xa
    if fb == 0.0:
        return xb
    xc, fc = xa, fa
    e = xb - xa
    dstep = e
    for _ in range(400):
        if (fb > 0.0) == (fc > 0.0):
            xc, fc = xa, fa
            e = xb - xa
            dstep = e
        if abs(fc) < abs(fb):
            xa, fa = xb, fb
            xb, fb = xc, fc
            xc, fc = xa, fa
        tol = 2.0 * 4.45e-16 * abs(xb) + 0.5e-300
        half = 0.5 * (xc - xb)
        if abs(half) <= tol or fb == 0.0:
            return xb
        if abs(e) >= tol and abs(fa) > abs(fb):
            # interpolation: secant when two points coincide, else inverse quadratic
            sb = fb / fa
            if xa == xc:
                pp = 2.0 * half * sb
                qq = 1.0 - sb
            else:
                qa = fa / fc
                rb = fb / fc
                pp = sb * (2.0 * half * qa * (qa - rb) - (xb - xa) * (rb - 1.0))
                qq = (qa - 1.0) * (rb - 1.0) * (sb - 1.0)
            if pp > 0.0:
                qq = -qq
            else:
                pp = -pp
            if 2.0 * pp < min(3.0 * half * qq - abs(tol * qq), abs(e * qq)):
                e = dstep
                dstep = pp / qq
            else:
                dstep = half
                e = dstep
        else:
            dstep = half
            e = dstep
        xa, fa = xb, fb
        if abs(dstep) > tol:
            xb += dstep
        else:
            xb += tol if half > 0.0 else -tol
        fb = _slip_g(A, b, mu, xb, lam, Q, cc, dd, s)
    return xb


@njit(cache=True)
def contensou_gauss_seidel(W, q, mu, starts, r, u, bound_sq, max_sweeps):
    """:func:`solve_exact_contensou`'s Gauss–Seidel sweeps, compiled and unchecked.

    From ``r`` with ``u = W r + q`` (both updated in place), contact ``i``
    owning the rows ``starts[i]:starts[i + 1]``, sweeps until the squared
    natural-map residual is ``<= bound_sq`` or ``max_sweeps`` ran (one sweep
    for one contact). For compiled callers (a time-stepping loop) on
    contiguous float arrays and an int64 ``starts``.

    Returns
    -------
    sweeps : int
    residual_sq : float
        The squared residual on the data after the sweeps.

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5, 3.5]); q = np.array([-1.0, 3.0, 0.0, 4.0])
    >>> r = np.zeros(4); u = q.copy()
    >>> sweeps, res = contensou_gauss_seidel(W, q, np.array([0.5]), np.array([0, 4]), r, u,
    ...                                      1e-20, 500)
    >>> sweeps, (np.round(r, 12) + 0.0).tolist()
    (1, [1.0, -0.3, 0.0, -0.4])
    """
    nc = mu.shape[0]
    n = q.shape[0]
    res = _natural_sq_blocks(r, u, mu, starts)
    sweeps = 0
    while res > bound_sq and sweeps < max_sweeps:
        for i in range(nc):
            a, b = starts[i], starts[i + 1]
            m = b - a
            A = np.ascontiguousarray(W[a:b, a:b])
            bl = np.empty(m)
            for j in range(m):
                acc = 0.0
                for k in range(m):
                    acc += A[j, k] * r[a + k]
                bl[j] = u[a + j] - acc
            ri = np.empty(m)
            _local_nd(A, bl, mu[i], ri)
            for j in range(n):
                acc = 0.0
                for k in range(m):
                    acc += W[j, a + k] * (ri[k] - r[a + k])
                u[j] += acc
            for k in range(m):
                r[a + k] = ri[k]
        _affine_into(W, q, r, u)
        sweeps += 1
        res = _natural_sq_blocks(r, u, mu, starts)
        if nc == 1:
            break
    return sweeps, res


def check_block_problem(W, q, mu, sizes):
    """Validate a problem whose contacts own ``sizes`` rows each (3, or 4 with drilling).

    As :func:`check_cone_problem`, the rows of contact ``i`` following those
    of the contacts before it: ``[N, T1, T2]`` or ``[N, T1, T2, D]`` with
    ``D`` the scaled drilling row (:func:`solve_exact_contensou`).

    Returns
    -------
    W, q, mu : ndarray
    starts : ndarray of int, shape (nc + 1,)
        Each contact's first row, and the total.

    Examples
    --------
    >>> check_block_problem(np.eye(7), np.zeros(7), 0.3, [3, 3])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `sizes` must add up to W's size 7, got 6
    """
    sizes = np.asarray(sizes)
    if sizes.ndim != 1 or sizes.size == 0 or not np.all(np.isin(sizes, (3, 4))):
        raise InputError(f"`sizes` must list 3 or 4 rows for each contact, got {sizes!r}")
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    W = finite_array("W", W, ndim=2)
    if W.shape[0] != W.shape[1]:
        raise InputError(f"`W` must be square, got shape {W.shape}")
    if starts[-1] != W.shape[0]:
        raise InputError(f"`sizes` must add up to W's size {W.shape[0]}, got {int(starts[-1])}")
    nc = sizes.size
    q = finite_array("q", q, shape=(W.shape[0],))
    mu_arr = np.asarray(mu, dtype=float) if not isinstance(mu, str) else None
    if mu_arr is None or mu_arr.ndim > 1:
        raise InputError(f"`mu` must be a number or an array of shape ({nc},), got {mu!r}")
    mu_arr = finite_array("mu", np.full(nc, mu_arr) if mu_arr.ndim == 0 else mu_arr,
                          shape=(nc,))
    if np.any(mu_arr < 0.0):
        raise InputError(f"`mu` must be >= 0 for every contact, got {mu_arr.tolist()!r}")
    if float(np.max(np.abs(W - W.T))) > _SYM_RTOL * float(np.max(np.abs(W))):
        raise InputError("`W` must be symmetric (a Delassus matrix H M^-1 H^T)")
    for i in range(nc):
        a, b = starts[i], starts[i + 1]
        try:
            np.linalg.cholesky(W[a:b, a:b])
        except np.linalg.LinAlgError:
            raise InputError(f"`W`'s diagonal block of contact {i} must be positive definite "
                             f"(the contact must move under its own impulse)") from None
    return (np.ascontiguousarray(W), np.ascontiguousarray(q), np.ascontiguousarray(mu_arr),
            starts)


def solve_exact_contensou(W, q, mu, sizes, *, tol=1e-10, max_sweeps=500, r0=None, check=True):
    r"""Solve a friction problem whose contacts may carry a drilling row (Coulomb–Contensou).

    Contact ``i`` owns ``sizes[i]`` rows: ``[N, T1, T2]`` (Coulomb's cone)
    or ``[N, T1, T2, D]`` with ``D`` the drilling row scaled by the contact's
    lever ``r*`` (its impulse is the drilling torque's over ``r*``, its
    velocity ``r*`` times the spin about the normal). In those variables Leine
    and Glocker's ellipsoid is the round cone ``|r_T| <= mu r_N`` with three
    tangential rows (:mod:`moreau.model.space`, "Coulomb–Contensou friction"),
    and the law is the one of the module docstring with ``u_T`` and ``r_T``
    of dimension 3: De Saxcé's ``û = u + mu |u_T| e_N`` and the natural map
    ``r - proj_K(r - û)``, whose norm on the caller's data is the residual.

    Projected Gauss–Seidel over contacts, each contact's problem solved
    exactly by :func:`local_solve_contensou`; one contact is solved in one
    sweep. There is no Newton polish here: with several coupled contacts
    the sweeps stop at ``tol`` or after ``max_sweeps`` (status ``"not
    converged"``, the true residual reported).

    Parameters
    ----------
    W, q, mu, sizes :
        The problem (:func:`check_block_problem`).
    tol : float
        Stop when the residual is ``<= tol ||q||``.
    max_sweeps : int
    r0 : array_like, optional
        Starting impulse.
    check : bool
        False skips the checks (a scheme's step, its data checked already).

    Returns
    -------
    ConeSolution

    Examples
    --------
    >>> W = np.diag([1.0, 3.5, 3.5, 3.5]); q = np.array([-1.0, 3.0, 0.0, 4.0])
    >>> sol = solve_exact_contensou(W, q, 0.5, [4])
    >>> sol.status, (np.round(sol.r, 12) + 0.0).tolist()
    ('converged', [1.0, -0.3, 0.0, -0.4])
    """
    if check:
        W, q, mu, starts = check_block_problem(W, q, mu, sizes)
    else:
        W, q, mu = _trusted(W, q, mu)
        starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    if isinstance(max_sweeps, bool) or not isinstance(max_sweeps, (int, np.integer)) \
            or max_sweeps < 1:
        raise InputError(f"`max_sweeps` must be an integer >= 1, got {max_sweeps!r}")
    nc = mu.shape[0]
    r = np.zeros_like(q) if r0 is None else finite_array("r0", r0, shape=q.shape).copy()
    u = np.empty_like(q)
    _affine_into(W, q, r, u)
    qn = float(np.linalg.norm(q))
    scale = qn if qn > 0.0 else 1.0
    sweeps, res = contensou_gauss_seidel(W, q, mu, starts, r, u, (tol * scale) ** 2,
                                         int(max_sweeps))
    res = math.sqrt(res)
    status = CONVERGED if res <= tol * scale else NOT_CONVERGED
    detail = (f"{sweeps} Gauss–Seidel sweep(s) with the exact local solve over "
              f"{int(np.sum(np.diff(starts) == 4))} contact(s) with a drilling row; residual "
              f"{res:.3g} against the bound {tol * scale:.3g} (tol {tol:g} x ||q||).")
    return ConeSolution(r, u, status, res, res / qn if qn > 0 else res, {"sweeps": int(sweeps)},
                        "exact", detail)
