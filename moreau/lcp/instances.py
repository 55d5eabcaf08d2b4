"""Named LCP instances with known answers, shared by the tests and the benchmark.

Every instance states what a correct solver must do with it (``expect``):
``"solved"`` (a solution exists; any solver that reports success must meet
the residual check, and some answers are known exactly), ``"ray"`` (no
solution exists; Lemke ends on a secondary ray) or ``"lemke-ray"`` (a
solution exists but Lemke with covering vector ones provably ends on a ray).

Sources of the classic instances
--------------------------------
* Murty's exponential example: K. G. Murty, *Linear Complementarity, Linear
  and Nonlinear Programming*, Heldermann 1988, Chapter 6 (after Murty,
  "Computational complexity of complementary pivot methods", Math.
  Programming Study 7, 1978): ``M`` lower triangular with ones on the
  diagonal and twos below, ``q = -(2^n, 2^n + 2^(n-1), ..., 2^n + ... + 2)``.
  Lemke with covering vector ones visits all ``2^n`` complementary cones:
  ``2^n`` pivots counting the first (``z0`` enters) and the last (``z0``
  leaves). The unique solution is ``z = (2^n, 0, ..., 0)``.
* Cycling example (Kostreva; also Cottle-Pang-Stone): ``M = [[1,2,0],[0,1,2],
  [2,0,1]]``, ``q = -1``; Lemke without careful tie-breaking cycles. The
  solution is ``(1/3, 1/3, 1/3)``.
* R. W. Cottle, J.-S. Pang, R. E. Stone, *The Linear Complementarity
  Problem*, Academic Press 1992, example 4.4.16: ``M = [[1,-1],[-1,1]]``,
  ``q = (1,-1)``; the second pivot meets a tie between ``z0`` and ``w1``,
  and leaving with ``z0`` gives ``(0, 1)`` (every ``(t, 1 + t)`` solves).
* C. A. Floudas et al., *Handbook of Test Problems in Local and Global
  Optimization*, Kluwer 1999, section 10.2: ex. 10.2.1 (16 x 16 upper
  triangular ``M = I + 2 * strict upper``, ``q = -1``, unique solution
  ``e_16``), ex. 10.2.2 (``M = ones(2, 2)``, ``q = -1``: every ``z >= 0``
  with ``z1 + z2 = 1`` solves) and ex. 10.2.9 (a parametric instance: ``M =
  [[11,0,10,-1],[0,11,10,-1],[10,10,21,-1],[1,1,1,0]]``, ``q = (50, 50, l,
  -6)``; for ``0 <= l <= 23`` the solution is ``((l+16)/13, (l+16)/13,
  2(23-l)/13, (1286-9l)/13)``, and ``(3, 3, 0, 83)`` for ``l >= 23``).
* Murty (1988), example 2.9: ``M = [[-1,0,-3],[1,-2,-5],[-2,-1,-2]]``,
  ``q = (-3,-2,-1)``, ends on a secondary ray.
* The smallest infeasible LCP: ``M = [-1]``, ``q = [-1]`` (``w = -z - 1 < 0``).

All data here were re-derived or checked by direct substitution (see
``tests/lcp/test_instances.py``); nothing is taken on trust.
"""

from dataclasses import dataclass, field

import numpy as np

from .friction import FrictionLayout, build_friction_lcp

__all__ = [
    "Instance",
    "classic_instances",
    "random_instances",
    "all_instances",
    "murty",
    "random_p_matrix",
    "random_psd",
    "random_lp",
    "random_copositive",
    "random_friction_data",
    "random_friction",
]


@dataclass
class Instance:
    """One LCP with what is known about it.

    Attributes
    ----------
    name : str
        Unique, e.g. ``"murty-8"`` or ``"pmatrix-100"``.
    M, q : ndarray
    kind : str
        Family: ``"classic"``, ``"pmatrix"``, ``"psd"``, ``"copositive"``,
        ``"friction"``.
    expect : str
        ``"solved"``, ``"ray"`` or ``"lemke-ray"`` (see the module text).
    z : ndarray or None
        The solution when it is unique or the one Lemke must find.
    w : ndarray or None
        The ``w`` of every solution, when it is unique while ``z`` is not
        (symmetric positive semidefinite ``M``).
    unique : bool
        Whether the solution is unique (P-matrix).
    pivots : int or None
        Exact pivot count of Lemke with covering vector ones, where it is
        part of the instance's point.
    max_iter : int or None
        Pivot limit the instance needs beyond the default.
    layout : FrictionLayout or None
        For friction LCPs.
    extra : dict
        Anything else (e.g. the Delassus data of a friction instance).
    """

    name: str
    M: np.ndarray
    q: np.ndarray
    kind: str = "classic"
    expect: str = "solved"
    z: np.ndarray = None
    w: np.ndarray = None
    unique: bool = False
    pivots: int = None
    max_iter: int = None
    layout: FrictionLayout = None
    extra: dict = field(default_factory=dict)

    @property
    def n(self):
        return len(self.q)


def murty(n):
    """Murty's example of order ``n``: Lemke needs ``2^n`` pivots.

    Returns
    -------
    Instance

    Examples
    --------
    >>> inst = murty(3)
    >>> inst.M.tolist(), inst.q.tolist()
    ([[1.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 2.0, 1.0]], [-8.0, -12.0, -14.0])
    """
    M = np.eye(n) + 2.0 * np.tril(np.ones((n, n)), -1)
    q = -np.cumsum([2.0 ** (n - k) for k in range(n)])
    z = np.zeros(n)
    z[0] = 2.0**n
    return Instance(
        f"murty-{n}", M, q, z=z, unique=True, pivots=2**n, max_iter=2**n + 10,
        extra={"source": "Murty 1988, ch. 6"},
    )


def _parametric(lam):
    M = np.array([[11.0, 0, 10, -1], [0, 11, 10, -1], [10, 10, 21, -1], [1, 1, 1, 0]])
    q = np.array([50.0, 50.0, lam, -6.0])
    if lam <= 23.0:
        z = np.array([(lam + 16) / 13, (lam + 16) / 13, 2 * (23 - lam) / 13, (1286 - 9 * lam) / 13])
    else:
        z = np.array([3.0, 3.0, 0.0, 83.0])
    return Instance(f"handbook-10.2.9-l{lam:g}", M, q, z=z, unique=True, extra={"source": "Floudas et al. 1999, ex. 10.2.9"})


def classic_instances(murty_orders=(4, 8, 12)):
    """The classic hard cases, each with its known answer.

    Parameters
    ----------
    murty_orders : sequence of int
        Orders of Murty's example to include.

    Returns
    -------
    list of Instance

    Examples
    --------
    >>> [i.name for i in classic_instances(murty_orders=())][:3]
    ['cycling', 'cps-4.4.16', 'handbook-10.2.1']
    """
    out = []
    M = np.array([[1.0, 2, 0], [0, 1, 2], [2, 0, 1]])
    out.append(Instance("cycling", M, -np.ones(3), z=np.full(3, 1 / 3), unique=True,
                        extra={"source": "Kostreva; CPS 1992"}))
    out.append(Instance("cps-4.4.16", np.array([[1.0, -1], [-1, 1]]), np.array([1.0, -1]),
                        z=np.array([0.0, 1.0]), w=np.zeros(2), extra={"source": "CPS 1992, ex. 4.4.16"}))
    n = 16
    M = np.eye(n) + 2.0 * np.triu(np.ones((n, n)), 1)
    z = np.zeros(n)
    z[-1] = 1.0
    out.append(Instance("handbook-10.2.1", M, -np.ones(n), z=z, unique=True,
                        extra={"source": "Floudas et al. 1999, ex. 10.2.1"}))
    out.append(Instance("handbook-10.2.2-many", np.ones((2, 2)), -np.ones(2), w=None,
                        extra={"source": "Floudas et al. 1999, ex. 10.2.2",
                               "check": "z1 + z2 = 1: infinitely many solutions"}))
    for lam in (0.0, 1.0, 16.0, 23.0, 100.0):
        out.append(_parametric(lam))
    out.append(Instance("no-solution", np.array([[-1.0]]), np.array([-1.0]), expect="ray"))
    out.append(Instance("murty-ex-2.9", np.array([[-1.0, 0, -3], [1, -2, -5], [-2, -1, -2]]),
                        np.array([-3.0, -2, -1]), expect="ray", extra={"source": "Murty 1988, ex. 2.9"}))
    for k in murty_orders:
        out.append(murty(k))
    return out


def random_p_matrix(n, rng):
    """A random P-matrix that is neither symmetric nor positive definite in general.

    ``D (B B^T / n + I/2 + S - S^T)`` with ``D`` positive diagonal: the bracket
    has a positive definite symmetric part, hence positive principal minors,
    and a positive diagonal scaling keeps their sign.

    Examples
    --------
    >>> import numpy as np
    >>> M = random_p_matrix(3, np.random.default_rng(0))
    >>> bool(np.linalg.det(M) > 0 and np.all(np.diag(M) > 0))
    True
    """
    B = rng.standard_normal((n, n))
    S = rng.standard_normal((n, n))
    D = np.exp(rng.uniform(-1.0, 1.0, n))
    return D[:, None] * (B @ B.T / n + 0.5 * np.eye(n) + S - S.T)


def _planted(M, rng, density=0.5):
    # q so that a chosen complementary pair (z*, w*) solves LCP(M, q)
    n = M.shape[0]
    active = rng.random(n) < density
    z = np.where(active, rng.uniform(0.1, 2.0, n), 0.0)
    w = np.where(active, 0.0, rng.uniform(0.1, 2.0, n))
    return w - M @ z, z, w


def random_psd(n, rank, rng):
    """Symmetric PSD ``M`` of the given rank with a planted solution; ``w`` is unique."""
    B = rng.standard_normal((n, rank))
    M = B @ B.T / max(rank, 1)
    q, z, w = _planted(M, rng)
    return M, q, z, w


def random_lp(m, k, rng):
    """LCP of a random LP ``min c.x, A x >= b, x >= 0``: skew-symmetric (copositive-plus) ``M``."""
    A = rng.standard_normal((k, m))
    x = np.where(rng.random(m) < 0.5, rng.uniform(0.1, 1.0, m), 0.0)
    y = np.where(rng.random(k) < 0.5, rng.uniform(0.1, 1.0, k), 0.0)
    s1 = np.where(x > 0, 0.0, rng.uniform(0.1, 1.0, m))
    s2 = np.where(y > 0, 0.0, rng.uniform(0.1, 1.0, k))
    c = A.T @ y + s1
    b = A @ x - s2
    M = np.zeros((m + k, m + k))
    M[:m, m:] = -A.T
    M[m:, :m] = A
    q = np.concatenate([c, -b])
    return M, q


def random_copositive(n, rng):
    """Non-negative ``M`` with a positive diagonal: strictly copositive, so every ``q`` is solvable."""
    M = rng.uniform(0.0, 1.0, (n, n)) * (rng.random((n, n)) < 0.5)
    M[np.diag_indices(n)] = rng.uniform(0.5, 2.0, n)
    q = rng.standard_normal(n)
    return M, q


def random_friction_data(n_contacts, rng, frictionless=0.2, ndof=None):
    """Random, physically consistent 2D contact data.

    ``W = J Mass^-1 J^T`` from a random Jacobian ``J`` and a random SPD mass
    matrix; the velocities are those of a random motion, ``v_free = J u``
    and ``vN_pre = J_N u_pre``, as in a time step.

    Parameters
    ----------
    n_contacts : int
    rng : numpy.random.Generator
    frictionless : float
        Probability that a contact has ``mu = 0``.
    ndof : int, optional
        Degrees of freedom; by default drawn so that about half the instances
        have more contact rows than degrees of freedom (a rank-deficient
        ``W``, the case where pivoting meets degeneracy).

    Returns
    -------
    W, v_free, mu, e, vN_pre

    Notes
    -----
    With a rank-deficient ``W`` the restitution targets ``-e vN_pre^-`` of
    dependent contacts can contradict each other (a body squeezed between
    two walls cannot bounce off both), which makes the LCP infeasible for
    real, not numerically. Those instances therefore get ``e = 0``: with
    ``q`` in the range of ``J`` the friction LCP always has a solution
    (Stewart and Trinkle 1996; Anitescu and Potra 1997). A random ``v_free``
    outside that range would make rank-deficient instances infeasible, or
    solvable only through impulses of size ``1/eps``.
    """
    nc = n_contacts
    mu = rng.uniform(0.05, 1.0, nc)
    mu[rng.random(nc) < frictionless] = 0.0
    nf = int(np.count_nonzero(mu))
    m = nc + nf
    if ndof is None:
        ndof = int(rng.integers(max(1, m // 2), 2 * m + 2))
    A = rng.standard_normal((ndof, ndof))
    Mass = A @ A.T / ndof + 0.1 * np.eye(ndof)
    J = rng.standard_normal((m, ndof))
    W = J @ np.linalg.solve(Mass, J.T)
    W = 0.5 * (W + W.T)
    u_pre = rng.standard_normal(ndof)
    if J[0] @ u_pre > 0.0:
        # contact 0 approaches, so even a one-contact instance has work to do
        u_pre = -u_pre
    u_free = u_pre + 0.3 * rng.standard_normal(ndof)
    v_free = J @ u_free
    vN_pre = J[:nc] @ u_pre
    e = rng.uniform(0.0, 1.0, nc) if m <= ndof else np.zeros(nc)
    return W, v_free, mu, e, vN_pre


def random_friction(n_contacts, rng, **kwargs):
    """A random friction LCP as an :class:`Instance` (Delassus data in ``extra``)."""
    W, v_free, mu, e, vN_pre = random_friction_data(n_contacts, rng, **kwargs)
    M, q, layout = build_friction_lcp(W, v_free, mu, e, vN_pre)
    return Instance(
        f"friction-{n_contacts}", M, q, kind="friction", layout=layout,
        extra={"W": W, "v_free": v_free, "mu": mu, "e": e, "vN_pre": vN_pre},
    )


def random_instances(seed=0, p_sizes=(2, 5, 10, 30, 100, 300), contacts=(1, 5, 50)):
    """Random families: P-matrices, PSD (full and deficient rank), copositive-plus, friction.

    Returns
    -------
    list of Instance

    Examples
    --------
    >>> insts = random_instances(p_sizes=(3,), contacts=(1,))
    >>> sorted({i.kind for i in insts})
    ['copositive', 'friction', 'pmatrix', 'psd']
    """
    rng = np.random.default_rng(seed)
    out = []
    for n in p_sizes:
        M = random_p_matrix(n, rng)
        q = rng.standard_normal(n)
        out.append(Instance(f"pmatrix-{n}", M, q, kind="pmatrix", unique=True))
    for n, rank in ((10, 10), (10, 4), (40, 15)):
        M, q, z, w = random_psd(n, rank, rng)
        out.append(Instance(f"psd-{n}-rank{rank}", M, q, kind="psd", w=w, z=z if rank == n else None,
                            unique=rank == n, extra={"planted_z": z}))
    for m, k in ((3, 2), (12, 8)):
        M, q = random_lp(m, k, rng)
        out.append(Instance(f"lp-{m}x{k}", M, q, kind="copositive"))
    for n in (5, 20):
        M, q = random_copositive(n, rng)
        out.append(Instance(f"copositive-{n}", M, q, kind="copositive"))
    for nc in contacts:
        inst = random_friction(nc, rng)
        out.append(inst)
    return out


def all_instances(seed=0, murty_orders=(4, 8, 12), p_sizes=(2, 5, 10, 30, 100, 300), contacts=(1, 5, 50)):
    """:func:`classic_instances` followed by :func:`random_instances`."""
    return classic_instances(murty_orders) + random_instances(seed, p_sizes, contacts)
