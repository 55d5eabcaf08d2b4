"""``"mlcp"``: a contact problem with equality (bilateral) rows, the mixed LCP.

The equality rows are eliminated (:func:`eliminate_equalities`): with
``W = [[A, C], [D, B]]`` split at the ``n_eq`` equality rows and ``a =
u_E - eq_target``, the equality law ``A p_E + C p_C + a = 0`` gives ``p_E =
-A^-1 (a + C p_C)``, and the contact rows see the Schur complement
``W_S = B - D A^-1 C`` with free velocities ``u_S = u_C - D A^-1 a``: a
contact problem without equality rows, with the same ``mu``, ``e``,
``vN_pre``. An inner solver (``"auto"`` by default: closed form for one
contact, Lemke then QP) solves it; ``p_E`` follows, refined once on ``A``.
The whole answer is then certified on the caller's data: the friction MLCP
of :func:`build_friction_mlcp` (equality residuals, the impact law's
complementarity, the friction cone) by
:func:`moreau.lcp.mlcp.mlcp_violation` at Lemke's tolerance.

A singular ``A`` (redundant or inconsistent joints) is never divided by:
:func:`moreau.lcp.mlcp.equality_block` finds its rank by an SVD and raises
:class:`moreau.lcp.mlcp.RankDeficientError` naming the rows.
"""

import numpy as np

from ...lcp.friction import build_friction_lcp, friction_impulses
from ...lcp.lemke import DEFAULT_TOL
from ...lcp.mlcp import (RANK_RTOL, equality_block, free_part, mlcp_residual, mlcp_violation,
                         schur_complement)
from ..closed_form import friction_point
from ..problem import FAILED, SOLVED, ContactProblem, ContactSolution
from ..registry import register_solver, solve as solve_problem

__all__ = ["solve", "eliminate_equalities", "build_friction_mlcp"]


def eliminate_equalities(problem, rank_rtol=RANK_RTOL):
    """The contact problem left once the equality rows are eliminated, and how to get ``p_E`` back.

    Parameters
    ----------
    problem : ContactProblem
    rank_rtol : float
        Rank tolerance of the equality block (:data:`moreau.lcp.mlcp.RANK_RTOL`).

    Returns
    -------
    reduced : ContactProblem
        ``(W_S, u_S, mu, e, vN_pre)`` without equality rows.
    recover : callable
        ``recover(p_C) -> p_E``.

    Raises
    ------
    moreau.lcp.mlcp.RankDeficientError
        The equality block is singular.

    Examples
    --------
    The rod and floor of :mod:`moreau.contact` (rows ``E = x + y``, ``N = y``):

    >>> W = np.array([[2.0, 1.0], [1.0, 1.0]])
    >>> reduced, recover = eliminate_equalities(ContactProblem(W, [-1.0, -2.0], [0.0], n_eq=1))
    >>> reduced.W.tolist(), reduced.u_free.tolist(), recover(np.array([3.0])).tolist()
    ([[0.5]], [-1.5], [-1.0])
    """
    k = problem.n_eq
    W, u = problem.W, problem.u_free
    A, C, D, B = W[:k, :k], W[:k, k:], W[k:, :k], W[k:, k:]
    a = u[:k] - problem.eq_target
    block = equality_block(A, rhs=a, coupling=C, rtol=rank_rtol,
                           label="equality (bilateral) rows")
    WS, uS = schur_complement(block, C, D, B, a, u[k:])
    reduced = ContactProblem.trusted(WS, uS, problem.mu, problem.e, problem.vN_pre)
    return reduced, (lambda pC: free_part(block, C, a, np.asarray(pC, dtype=float)))


def _selection(problem, layout):
    # S with p_C = S z over the friction LCP's variables (build_friction_lcp's own)
    nc, nf = problem.n_contacts, problem.n_frictional
    S = np.zeros((nc + nf, layout.size))
    S[np.arange(nc), layout.normal] = 1.0
    fr = layout.frictional
    S[nc + np.arange(nf), layout.tplus[fr]] = 1.0
    S[nc + np.arange(nf), layout.tminus[fr]] = -1.0
    return S


def build_friction_mlcp(problem):
    """The friction MLCP of ``problem`` on its own data: ``(M, q, layout)``.

    Variables ``x = (p_E, z)``, ``z`` those of
    :func:`~moreau.lcp.friction.build_friction_lcp` on the contact rows
    (``layout``, its indices counted from ``n_eq``); rows: the equality
    rows ``u_E - eq_target + W_E p``, then the friction LCP's rows.

    Examples
    --------
    >>> W = np.array([[2.0, 1.0], [1.0, 1.0]])
    >>> M, q, layout = build_friction_mlcp(ContactProblem(W, [-1.0, -2.0], [0.0], n_eq=1))
    >>> M.tolist(), q.tolist()
    ([[2.0, 1.0], [1.0, 1.0]], [-1.0, -2.0])
    """
    k = problem.n_eq
    W, u = problem.W, problem.u_free
    Ml, ql, layout = build_friction_lcp(W[k:, k:], u[k:], problem.mu, problem.e, problem.vN_pre)
    S = _selection(problem, layout)
    n = k + layout.size
    M = np.zeros((n, n))
    M[:k, :k] = W[:k, :k]
    M[:k, k:] = W[:k, k:] @ S
    M[k:, :k] = S.T @ W[k:, :k]
    M[k:, k:] = Ml
    q = np.concatenate([u[:k] - problem.eq_target, ql])
    return M, q, layout


def _mlcp_point(problem, layout, p):
    # x = (p_E, z) of the stacked impulse p, beta = |U_T| from the caller's data
    k = problem.n_eq
    vT = (problem.u_free + problem.W @ p)[k + problem.n_contacts:]
    return np.concatenate([p[:k], friction_point(layout, p[k:], vT)])


def solve(problem, *, max_iter=None, tol=None, inner="auto", rank_rtol=RANK_RTOL):
    """Solve a contact problem with equality rows (the mixed LCP).

    Parameters
    ----------
    problem : ContactProblem
    max_iter, tol
        Passed to the inner solver; ``tol`` (default 1e-9, Lemke's) also
        bounds the certified violation on the caller's data.
    inner : str
        The registered solver of the reduced problem (no equality rows).
    rank_rtol : float
        Rank tolerance of the equality block (:data:`moreau.lcp.mlcp.RANK_RTOL`).

    Examples
    --------
    The rod and floor of :mod:`moreau.contact`, the mass now moving at ``(1, 2)``:
    the floor is left, the rod alone holds it.

    >>> W = np.array([[2.0, 1.0], [1.0, 1.0]])
    >>> sol = solve(ContactProblem(W, [3.0, 2.0], [0.0], n_eq=1))
    >>> sol.status, sol.p_eq.tolist(), sol.pN.tolist(), sol.residual < 1e-15
    ('solved', [-1.5], [0.0], True)
    """
    k = problem.n_eq
    if k == 0:
        return solve_problem(problem, inner, max_iter=max_iter, tol=tol)
    if problem.n_contacts == 0:
        return _equalities_only(problem, tol, rank_rtol)
    reduced, recover = eliminate_equalities(problem, rank_rtol)
    nc = problem.n_contacts
    if reduced.n_rows:
        inner_sol = solve_problem(reduced, inner, max_iter=max_iter, tol=tol)
        pC = np.asarray(inner_sol.p, dtype=float)
    else:
        inner_sol = None
        pC = np.zeros(0)
    p_eq = recover(pC)
    p = np.concatenate([p_eq, pC])
    M, q, layout = build_friction_mlcp(problem)
    x = _mlcp_point(problem, layout, p)
    viol = mlcp_violation(M, q, k, x)
    residual = mlcp_residual(M, q, k, x)
    bound = DEFAULT_TOL if tol is None else float(tol)
    method = "mlcp" if inner_sol is None else f"mlcp+{inner_sol.method}"
    path = ("mlcp",) + (() if inner_sol is None else inner_sol.path)
    iterations = 0 if inner_sol is None else inner_sol.iterations
    lcp = None if inner_sol is None else inner_sol.lcp
    pN, pT = friction_impulses(x[k:], layout)
    if inner_sol is not None and not inner_sol.success:
        return ContactSolution(p, p_eq, pN, pT, inner_sol.status, residual, method, iterations,
                               f"the contact rows, the equality rows eliminated: "
                               f"{inner_sol.message}", path, lcp)
    if not viol <= bound:
        return ContactSolution(p, p_eq, pN, pT, FAILED, residual, method, iterations,
                               f"the solution of the reduced problem fails the check on the "
                               f"caller's data: violation {viol:.3g} > tol {bound:.3g}", path, lcp)
    return ContactSolution(p, p_eq, pN, pT, SOLVED, residual, method, iterations,
                           f"Solved: equality rows eliminated, violation {viol:.3g} on the "
                           f"caller's data.", path, lcp)


def _equalities_only(problem, tol, rank_rtol):
    # no contact rows: p_E = -A^-1 a, certified like the general case (its friction MLCP is
    # (W, u_E - eq_target) itself), without building the empty contact part
    k = problem.n_eq
    W = problem.W
    a = problem.u_free[:k] - problem.eq_target
    C = W[:k, k:]
    block = equality_block(W[:k, :k], rhs=a, coupling=C, rtol=rank_rtol,
                           label="equality (bilateral) rows")
    p = free_part(block, C, a, np.zeros(0))
    viol = mlcp_violation(W, a, k, p)
    residual = mlcp_residual(W, a, k, p)
    bound = DEFAULT_TOL if tol is None else float(tol)
    none = np.zeros(0)
    if not viol <= bound:
        return ContactSolution(p, p, none, none, FAILED, residual, "mlcp", 0,
                               f"the solution of the reduced problem fails the check on the "
                               f"caller's data: violation {viol:.3g} > tol {bound:.3g}",
                               ("mlcp",), None)
    return ContactSolution(p, p, none, none, SOLVED, residual, "mlcp", 0,
                           f"Solved: equality rows eliminated, violation {viol:.3g} on the "
                           f"caller's data.", ("mlcp",), None)


register_solver("mlcp", solve, equality_rows=True,
                summary="equality rows eliminated (Schur complement), then an inner solver")
