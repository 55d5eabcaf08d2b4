"""LCP through convex quadratic programs (qpsolvers with the OSQP backend).

Which QP is solved depends on what ``M`` is; the result's ``detail`` names it.

``"bound"`` -- symmetric positive semidefinite ``M``
    ``min 1/2 z.M z + q.z`` subject to ``z >= 0``. Its KKT conditions are
    exactly the LCP (``w = M z + q`` is the multiplier of ``z >= 0``), so
    every minimiser is an LCP solution and vice versa.

``"gap"`` -- monotone ``M`` (``M + M^T`` positive semidefinite, not symmetric)
    ``min z.(M z + q) = 1/2 z.(M + M^T) z + q.z`` subject to ``z >= 0`` and
    ``M z + q >= 0``. The objective is the complementarity gap, convex here
    and ``>= 0`` on the feasible set, so its minimisers with value 0 are
    exactly the LCP solutions; a solvable monotone LCP reaches 0.

``"tresca"`` -- the 2D Coulomb friction LCP (pass ``friction=layout``)
    This LCP is not monotone (the row ``mu p_N - p_T+ - p_T-`` has no
    symmetric partner), so no single convex QP is equivalent to it. Instead
    the Coulomb law is reached as a fixed point of Tresca problems: with the
    friction bound ``s = mu p_N^k`` frozen, friction is a box constraint and
    the impulse ``p = (p_N, p_T)`` is the solution of the convex QP::

        min 1/2 p.W p + p.b   subject to  p_N >= 0,  -s <= p_T <= s

    with ``W`` the Delassus matrix and ``b`` the free velocity including the
    restitution term, both read back from ``M`` and ``q``. Its KKT
    conditions are Signorini's law for ``p_N`` and Tresca's law for ``p_T``
    (stick inside the box, slip against ``v_T`` on its faces). The next
    bound is ``s = mu p_N^(k+1)``, starting from the frictionless impulse.
    A fixed point (``p_N^(k+1) = p_N^k``) is a Coulomb solution: with
    ``p_T+ = max(p_T, 0)``, ``p_T- = max(-p_T, 0)`` and ``beta = |v_T|`` it
    solves the friction LCP. The iteration is a contraction only for small
    enough ``mu`` (in terms of ``W``); when it stops without converging the
    answer is a Tresca solution with a lagged bound and the status says
    so. ``tests/lcp/test_qp.py`` measures how far it lands from Lemke's
    solution on random friction instances.

Every answer is finished by an active-set refinement: with ``J`` the indices
where ``z_i > w_i``, ``M_JJ z_J = -q_J`` is solved (least squares) and kept
if it lowers the violation. OSQP, a first-order method, stops at ``eps``
accuracy; the refinement recovers the exact vertex once the active set is
right. Whatever OSQP reports, a result counts as solved only when the
violation of :func:`moreau.lcp.lcp_violation` (tolerances fixed by the
data, not by the size of ``z``) is ``<= tol`` (default :data:`DEFAULT_TOL`).

Infeasibility
-------------
OSQP detects infeasible and unbounded QPs and returns a certificate. On
``"bound"`` the QP is unbounded below ("dual infeasible") exactly when the
LCP is infeasible: the certificate is a direction ``d >= 0`` with ``M d =
0`` and ``q.d < 0``, a Farkas vector. On ``"gap"`` the constraints ``z >=
0``, ``M z + q >= 0`` have no solution ("primal infeasible"; the
multipliers of ``M z + q >= 0`` in the certificate are a Farkas vector),
and OSQP may see first that the objective falls without bound along a
direction ``d >= 0``, ``M d >= 0``, ``(M + M^T) d = 0``, ``q.d < 0`` ("dual
infeasible"; ``d`` is a Farkas vector). OSQP's infeasibility tolerances
are set to its ``eps`` so that these certificates come out accurate. In
either case the vector is checked (:func:`moreau.lcp.certify.farkas_vector`)
and the status is :data:`~moreau.lcp.INFEASIBLE`, the message naming which
of OSQP's certificates it came from. A certificate that does not check out
gives :data:`~moreau.lcp.SOLVER_FAILED`.
"""

import math
import warnings

import numpy as np
import scipy.sparse as sp
from qpsolvers import Problem, solve_problem

from .._validate import positive, positive_int
from ..errors import InputError
from ._result import (
    INFEASIBLE,
    MAX_ITER,
    NOT_APPLICABLE,
    SOLVED,
    SOLVER_FAILED,
    LCPResult,
    lcp_violation,
)
from .certify import farkas_vector
from .lemke import balance, coerce_lcp

__all__ = ["solve", "DEFAULT_TOL", "qp_formulation"]

#: default bound on the violation (:func:`moreau.lcp.lcp_violation`) for a
#: QP answer to count as solved
DEFAULT_TOL = 1e-6
#: relative accuracy asked of a Farkas vector read from OSQP's certificates
#: (no feasible point within ``||z||_1 < 1e6 max|q| / max|M|``)
OSQP_FARKAS_TOL = 1e-6
#: OSQP's absolute and relative tolerances
OSQP_EPS = 1e-9
#: OSQP's iteration limit (first-order: slow on rank-deficient P)
OSQP_MAX_ITER = 20000
# symmetry and semidefiniteness are judged relative to max|M|
_STRUCT_TOL = 1e-10


def _osqp(P, c, lb=None, ub=None, G=None, h=None, initvals=None, max_iter=None, eps=OSQP_EPS):
    # One QP through qpsolvers; returns x or None
    return _osqp_run(P, c, lb, ub, G, h, initvals, max_iter, eps)[0]


# OSQP's infeasibility verdicts (qpsolvers passes OSQP's status string
# through in `extras["info"]`)
_PRIMAL_INF = ("primal infeasible", "primal infeasible inaccurate")
_DUAL_INF = ("dual infeasible", "dual infeasible inaccurate")


def _osqp_run(P, c, lb=None, ub=None, G=None, h=None, initvals=None, max_iter=None, eps=OSQP_EPS):
    # One QP through qpsolvers; returns (x or None, OSQP status text, primal
    # infeasibility certificate, dual infeasibility certificate). OSQP's stopping rule mixes
    # absolute and relative tolerances, so the data are first brought to
    # unit scale (z = alpha * x_hat, alpha = max|c| / max|P|): a Delassus
    # matrix of 1e-5 would otherwise read as "dual infeasible".
    n = len(c)
    sP = float(np.max(np.abs(P))) if P.size else 0.0
    sc = max(float(np.max(np.abs(c))) if n else 0.0, float(np.max(np.abs(h))) if h is not None and len(h) else 0.0)
    sP = sP if sP > 0.0 else 1.0
    sc = sc if sc > 0.0 else 1.0
    alpha = sc / sP
    if not (np.isfinite(alpha) and alpha > 0.0):
        return None, "bad scale", None, None
    Psp = sp.csc_matrix(P / sP)
    Gsp = None if G is None else sp.csc_matrix(G / sP)
    prob = Problem(
        Psp, c / sc, G=Gsp, h=None if h is None else h / sc,
        lb=None if lb is None else lb / alpha, ub=None if ub is None else ub / alpha,
    )
    opts = dict(eps_abs=eps, eps_rel=eps, eps_prim_inf=eps, eps_dual_inf=eps, polish=False, verbose=False,
                max_iter=OSQP_MAX_ITER if max_iter is None else max_iter)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            sol = solve_problem(prob, solver="osqp", initvals=None if initvals is None else initvals / alpha, **opts)
        except Exception:  # the backend's own failures become a status, not a crash
            return None, "exception", None, None
    extras = getattr(sol, "extras", None) or {}
    info = extras.get("info")
    text = str(getattr(info, "status", "unknown"))
    pcert = extras.get("prim_inf_cert")
    dcert = extras.get("dual_inf_cert")
    # an iterate that stopped short of OSQP's tolerance is still returned:
    # the refinement and the certification decide whether it solves the LCP
    x = sol.x
    if x is None or x.shape != (n,):
        return None, text, pcert, dcert
    with np.errstate(over="ignore", invalid="ignore"):
        x = x * alpha
    if not np.all(np.isfinite(x)):
        return None, text, pcert, dcert
    return x, text, pcert, dcert


def _infeasibility(M, q, form, text, pcert, dcert):
    # OSQP's verdict turned into a checked Farkas vector, or None. The
    # certificates are those of the scaled QP; positive scalings of the
    # rows and columns do not change the signs a Farkas vector needs.
    n = len(q)
    if text in _DUAL_INF and dcert is not None and len(dcert) == n:
        # d >= 0 along which the objective falls without bound: on "bound"
        # M d = 0 and q.d < 0; on "gap" (M + M^T) d = 0, M d >= 0, hence
        # M^T d = -M d <= 0: a Farkas vector either way
        y = farkas_vector(M, q, np.asarray(dcert, dtype=float), OSQP_FARKAS_TOL)
        return y, "OSQP: dual infeasible (the QP is unbounded below along a Farkas direction)"
    if text in _PRIMAL_INF and pcert is not None and form == "gap" and len(pcert) == 2 * n:
        # rows: -M z <= q first (multipliers >= 0), then the bounds z >= 0
        y = farkas_vector(M, q, np.asarray(pcert, dtype=float)[:n], OSQP_FARKAS_TOL)
        return y, "OSQP: primal infeasible (no z >= 0 with M z + q >= 0)"
    return None, ""


def _refine(M, q, z, res):
    # re-solve on the active set guessed from (z, w); keep only if better
    w = M @ z + q
    m = float(np.max(np.abs(M))) if M.size else 1.0
    J = np.flatnonzero(m * z > w)
    if J.size == 0:
        cand = np.zeros_like(z)
    else:
        cand = np.zeros_like(z)
        sol, *_ = np.linalg.lstsq(M[np.ix_(J, J)], -q[J], rcond=None)
        cand[J] = sol
    r2 = lcp_violation(M, q, cand)
    if r2 < res:
        return cand, r2
    return z, res


def qp_formulation(M, friction=None):
    """Name the QP formulation :func:`solve` would use for ``M``.

    Returns
    -------
    str
        ``"bound"``, ``"tresca"``, ``"gap"`` or ``"none"``.

    Examples
    --------
    >>> import numpy as np
    >>> qp_formulation(np.eye(2)), qp_formulation(np.array([[1.0, 1.0], [-1.0, 1.0]]))
    ('bound', 'gap')
    """
    M = np.asarray(M, dtype=float)
    scale = max(float(np.max(np.abs(M))), 1e-300) if M.size else 1.0
    sym = M.size == 0 or float(np.max(np.abs(M - M.T))) <= _STRUCT_TOL * scale
    if sym and (M.size == 0 or np.linalg.eigvalsh(M)[0] >= -_STRUCT_TOL * scale * len(M)):
        return "bound"
    if friction is not None:
        return "tresca"
    S = 0.5 * (M + M.T)
    if np.linalg.eigvalsh(S)[0] >= -_STRUCT_TOL * scale * len(M):
        return "gap"
    return "none"


def _tresca(M, q, layout, max_iter, fp_tol):
    # fixed point over Tresca QPs; returns (z, qp_solves, converged, note)
    nc = layout.n_contacts
    fr = layout.frictional
    rows = np.concatenate([layout.normal, layout.tplus[fr]])
    # rows/columns p_N and p_T+ of M hold exactly the Delassus matrix W
    W = M[np.ix_(rows, rows)]
    b = q[rows]
    scale = max(float(np.max(np.abs(W))), 1e-300) if W.size else 1.0
    if W.size and float(np.max(np.abs(W - W.T))) > 1e-8 * scale:
        return None, 0, False, "the Delassus block read from `M` is not symmetric"
    mu = layout.mu[fr]
    nf = len(fr)
    lb = np.concatenate([np.zeros(nc), np.zeros(nf)])
    ub = np.concatenate([np.full(nc, np.inf), np.zeros(nf)])
    p = None
    solves = 0
    converged = False
    # the normal impulses that set the friction bounds (the fixed point's argument),
    # and the previous argument and residual for the secant update
    pN_in = np.zeros(nc)
    prev = None
    for _ in range(max_iter):
        s = mu * pN_in[fr]
        lb[nc:] = -s
        ub[nc:] = s
        x = _osqp(W, b, lb=lb, ub=ub, initvals=p)
        solves += 1
        if x is None:
            return None, solves, False, "OSQP failed on a Tresca subproblem"
        x[:nc] = np.maximum(x[:nc], 0.0)
        x[nc:] = np.clip(x[nc:], -s, s)
        p = x
        pN = p[:nc]
        if nf == 0:
            converged = True
            break
        r = pN - pN_in
        if np.max(np.abs(r)) <= fp_tol * (1.0 + np.max(np.abs(pN))):
            converged = True
            break
        # plain iteration pN_in <- pN converges only linearly (9.5 QPs a step on
        # the friction drive at 185 Hz); with one contact the fixed point is a scalar
        # equation, and a secant step on the residual pN(pN_in) - pN_in takes 3.0.
        # With several contacts a componentwise secant ignores their coupling and
        # converged less often on random instances than plain iteration, so it is
        # kept to one contact. The map is piecewise linear and a secant step can
        # overshoot a kink: it is kept only where it stays admissible (>= 0), and
        # the caller certifies the final answer anyway
        nxt = pN.copy()
        if prev is not None and nc == 1:
            d_in = pN_in - prev[0]
            d_r = r - prev[1]
            ok = np.abs(d_r) > 1e-14 * (1.0 + np.abs(pN))
            step = np.where(ok, pN_in - r * d_in / np.where(ok, d_r, 1.0), pN)
            nxt = np.where(step >= 0.0, step, pN)
        prev = (pN_in, r)
        pN_in = nxt
    v = b + W @ p
    z = np.zeros(layout.size)
    z[layout.normal] = p[:nc]
    pT = p[nc:]
    z[layout.tplus[fr]] = np.maximum(pT, 0.0)
    z[layout.tminus[fr]] = np.maximum(-pT, 0.0)
    z[layout.beta[fr]] = np.abs(v[nc:])
    return z, solves, converged, ""


def solve(M, q, *, max_iter=None, tol=None, check_input=True, friction=None, refine=True):
    """Solve ``LCP(M, q)`` through convex QPs (see the module text for the formulations).

    The QP is solved on balanced data, ``2^ka D M D`` and ``2^kb D q`` with
    ``D`` a diagonal of powers of two (:func:`moreau.lcp.lemke.balance`; only
    the uniform factors for a friction layout, whose structure a row scaling
    would break), so that the answer does not depend on the units of the
    data; the answer and any Farkas vector are checked on the caller's data.

    Parameters
    ----------
    M : array_like, shape (n, n)
    q : array_like, shape (n,)
    max_iter : int, optional
        Limit on Tresca fixed-point iterations (default 100); the other
        formulations solve one QP.
    tol : float, optional
        Bound on the violation (:func:`moreau.lcp.lcp_violation`) for a
        solved status (default :data:`DEFAULT_TOL`).
    check_input : bool
        Validate shapes and finiteness (always cheap next to a QP solve).
    friction : FrictionLayout, optional
        Layout of a friction LCP from :func:`moreau.lcp.build_friction_lcp`;
        selects the Tresca fixed point when ``M`` is not symmetric.
    refine : bool
        Finish with the active-set refinement (see the module text). Turn
        it off to see what OSQP alone delivers.

    Returns
    -------
    LCPResult
        ``pivots`` counts the QP solves. Status :data:`~moreau.lcp.SOLVED`
        only when the answer passes :func:`moreau.lcp.lcp_violation` on the
        caller's data; :data:`~moreau.lcp.INFEASIBLE` only with a Farkas
        vector in ``certificate`` that holds exactly on the caller's data
        (:func:`moreau.lcp.certify.farkas_holds`); an OSQP verdict that does
        not check out is :data:`~moreau.lcp.SOLVER_FAILED`, the message
        saying so.

    Examples
    --------
    >>> import numpy as np
    >>> res = solve(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, -1.0]))
    >>> res.success, np.round(res.z, 9).tolist()
    (True, [0.333333333, 0.333333333])
    >>> res = solve(np.diag([1e300, 1e-300]), np.array([-1.0, -1.0]))
    >>> res.success, np.allclose(res.z * [1e300, 1e-300], 1.0, rtol=1e-12)
    (True, True)
    """
    M, q = coerce_lcp(M, q)
    if check_input:
        if not (np.all(np.isfinite(M))):
            raise InputError("`M` must contain only finite values (no NaN or inf)")
        if not (np.all(np.isfinite(q))):
            raise InputError("`q` must contain only finite values (no NaN or inf)")
        if max_iter is not None:
            max_iter = positive_int("max_iter", max_iter)
        if tol is not None:
            tol = positive("tol", tol)
        if friction is not None and getattr(friction, "size", None) != len(q):
            raise InputError(f"`friction` must be the layout of this LCP (size {len(q)})")
    tol = DEFAULT_TOL if tol is None else tol
    n = len(q)
    sexp = np.zeros(n, dtype=np.int64)
    ok, ka, kb = balance(M, q, sexp)
    if not ok:
        raise InputError("`M` and `q` must contain only finite values (no NaN or inf)")
    if friction is not None:
        # the Tresca fixed point reads the layout's structure from M: no scaling
        sexp[:] = 0
        ka = kb = 0
    Ms = np.ldexp(M, sexp[:, None] + sexp[None, :] + ka)
    qs = np.ldexp(q, sexp + kb)
    res = _solve_scaled(Ms, qs, max_iter, tol, friction, refine)
    # back to the caller's units: z = 2^(ka-kb) D z', a Farkas vector y = D y'
    with np.errstate(over="ignore", invalid="ignore"):
        z = np.ldexp(res.z, sexp + ka - kb)
    if res.status == INFEASIBLE:
        y = farkas_vector(M, q, np.ldexp(res.certificate, sexp))
        z0 = np.zeros(n)
        if y is not None:
            out = LCPResult(z0, q.copy(), INFEASIBLE, res.pivots, lcp_violation(M, q, z0), "qp",
                            detail=res.detail)
            out.certificate = y
            return out
        return LCPResult(z0, q.copy(), SOLVER_FAILED, res.pivots, lcp_violation(M, q, z0), "qp",
                         detail=f"{res.detail} That Farkas vector of the balanced data does not "
                         "hold exactly on the given data: infeasibility is not proven.")
    if not np.all(np.isfinite(z)):
        z0 = np.zeros(n)
        return LCPResult(z0, q.copy(), SOLVER_FAILED, res.pivots, lcp_violation(M, q, z0), "qp",
                         detail="the answer lies outside the range of doubles in the given units.")
    with np.errstate(over="ignore", invalid="ignore"):
        w = M @ z + q
    viol = lcp_violation(M, q, z, w)
    status, detail = res.status, res.detail
    if status == SOLVED and not viol <= tol:
        status = SOLVER_FAILED
        detail = (f"{detail} The answer solves the balanced data but fails the check on the given "
                  f"data: violation {viol:.2e} > tol = {tol:.1e} (rounding of M z at that size).")
    return LCPResult(z, w, status, res.pivots, viol, "qp", detail=detail)


def _solve_scaled(M, q, max_iter, tol, friction, refine):
    # the QP solve proper, on balanced data (see solve)
    tol = DEFAULT_TOL if tol is None else tol
    n = len(q)
    if n == 0 or np.all(q >= 0.0):
        z = np.zeros(n)
        return LCPResult(z, q.copy(), SOLVED, 0, 0.0, "qp", detail="q >= 0: z = 0.")
    form = qp_formulation(M, friction)
    status = SOLVED
    note = ""
    solves = 1
    if form in ("bound", "gap"):
        # OSQP at a tight tolerance sometimes stalls on a rank-deficient P
        # ("dual infeasible inaccurate"); a looser solve, refined on its
        # active set, then usually lands on the exact vertex
        z = None
        res = np.inf
        unverified = ""
        for k, eps in enumerate((OSQP_EPS, 1e-6)):
            if form == "bound":
                x, text, pcert, dcert = _osqp_run(M, q, lb=np.zeros(n), eps=eps)
            else:
                x, text, pcert, dcert = _osqp_run(M + M.T, q, lb=np.zeros(n), G=-M, h=q, eps=eps)
            solves = k + 1
            if text in _PRIMAL_INF or text in _DUAL_INF:
                y, which = _infeasibility(M, q, form, text, pcert, dcert)
                if y is not None:
                    z0 = np.zeros(n)
                    out = LCPResult(z0, q.copy(), INFEASIBLE, solves, lcp_violation(M, q, z0), "qp",
                                    detail=f"{which}, formulation {form!r}; `certificate` holds the "
                                    f"Farkas vector y: y >= 0, M^T y <= 0, q.y = {float(q @ y):.3g} < 0.")
                    out.certificate = y
                    return out
                unverified = f"OSQP reported {text!r} but its certificate does not check out"
            if x is None:
                continue
            x = np.maximum(x, 0.0)
            rx = lcp_violation(M, q, x)
            if refine and np.isfinite(rx):
                x, rx = _refine(M, q, x, rx)
            if rx < res:
                z, res = x, rx
            if res <= tol:
                break
        if res > tol and unverified:
            note = unverified
    elif form == "tresca":
        z, solves, converged, note = _tresca(M, q, friction, 100 if max_iter is None else max_iter, 1e-10)
        if z is not None and not converged:
            status = MAX_ITER
            note = f"the Tresca fixed point did not converge in {solves} QP solves"
    else:
        z0 = np.zeros(n)
        return LCPResult(
            z0, q.copy(), NOT_APPLICABLE, 0, lcp_violation(M, q, z0), "qp",
            detail="QP formulations need a symmetric PSD `M`, a monotone `M` (M + M^T PSD), "
            "or a friction layout (`friction=`).",
        )
    if z is None:
        z0 = np.zeros(n)
        return LCPResult(z0, q.copy(), SOLVER_FAILED, solves, lcp_violation(M, q, z0), "qp",
                         detail=note or f"OSQP found no solution of the {form!r} QP.")
    z = np.maximum(z, 0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        w = M @ z + q
    res = lcp_violation(M, q, z, w)
    if not np.isfinite(res):
        z0 = np.zeros(n)
        return LCPResult(z0, q.copy(), SOLVER_FAILED, solves, lcp_violation(M, q, z0), "qp",
                         detail=f"the {form!r} QP answer overflowed.")
    if refine:
        z, res = _refine(M, q, z, res)
        w = M @ z + q
    if status == SOLVED and not res <= tol:
        # whatever OSQP said: a point that fails the certification is no solution
        status = SOLVER_FAILED
        note = note or f"the {form!r} QP answer fails the certification: violation {res:.2e} > tol = {tol:.1e}"
    detail = f"formulation {form!r}" + (f"; {note}" if note else "") + "."
    return LCPResult(z, w, status, solves, res, "qp", detail=detail)
