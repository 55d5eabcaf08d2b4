"""Moreau–Jean's step on a sparse, frictionless contact model (long chains: the ball chain).

A scene whose ``sparse_contacts()`` returns ``(inv_mass, forces, jacobian,
gaps)`` rather than None is stepped here by :class:`~moreau.integrators.moreau_jean.MoreauJean`
(``fast="auto"``, ``lcp_method="auto"``, no projection): a diagonal mass
matrix (``inv_mass``, shape ``(ndof,)``), constant forces (``forces``,
shape ``(ndof,)``), frictionless contacts, the normal rows ``WN(q)`` as a
scipy CSR matrix (``jacobian(q)``) and the gaps ``gaps(q)``. Nothing of size
``ndof x ndof`` or ``nc x ndof`` is dense. It is the step of
:mod:`moreau.integrators.moreau_jean` with ``M`` diagonal and ``K = C = 0``:
``v_free = v_k + h M^-1 f``, the same index set (``g + (h/2) gdot <= 0`` or
an impulse in the step before), and the contact problem on the active
contacts, ``W = WN M^-1 WN^T`` (CSR), ``0 <= W p + WN v_free + e min(vN_k, 0)
_|_ p >= 0``.

The LCP is solved by the primal-dual active-set method
(:func:`moreau.lcp.active_set.solve_active_set`), exact to rounding in at
most ``nc + 2`` sparse solves where ``W`` is an M-matrix. A chain's ``W`` is
one: tridiagonal, positive definite, with off-diagonal entries ``-1/m_i <=
0``. On other matrices it may cycle; a solve that has not ended in ``nc + 2``
steps (LCPError), or ends with a natural-map residual ``||min(p, W p + q)||
/ (1 + ||q||)`` above :data:`SPARSE_TOL`, fails the step (status -3), never
passed silently. The residual of the answer used is recorded in
``stats["max_residual"]``, the active-set solves in ``stats["pivots"]``. A
problem with ``q >= 0`` (a chain at rest or coming apart) has the answer
``p = 0``, taken without a solve.

Iterative solvers
-----------------
With ``lcp_method`` one of :data:`ITERATIVE_METHODS` (``"nsgs"``,
``"apgd"``: the contact-problem solvers of :mod:`moreau.contact` by their
registered names) the step's problem goes to that solver instead, on this
sparse path and on the generic (dense) step alike (:func:`iterative_contact_step`):
in FCLib's layout (:mod:`moreau.contact.fclib_layout`: a frictionless contact
gets a decoupled tangential row whose cone holds its impulse at 0), to the
natural-map tolerance ``lcp_tol`` (default :data:`ITERATIVE_TOL`) within
``lcp_max_iter`` sweeps or gradient steps (default :data:`ITERATIVE_BUDGET`),
NSGS over-relaxed by ``lcp_omega``. The solve starts from the impulses of the
step before on the contacts active in both (zero elsewhere), unless no
impulse at all has the smaller residual (after an impact the next step's
answer is about zero, and the impact's impulses would be a start far off);
where no impulse at all meets the tolerance (its residual is exact: ``u =
q``) it is the answer, without a solve.
The certified residual of the answer enters ``stats["max_residual"]`` and
the sweeps ``stats["iterations"]``; a solve that stops above its tolerance
fails the step with status -3 and the solver's message (the residual, the
tolerance, the iterations), as a failed Lemke or active-set solve does:
never taken silently.
"""

import math

import numpy as np
import scipy.sparse as sps

from ..contact import ContactProblem, from_fclib, to_fclib
from ..contact._sparse import problem_residual
from ..contact.solvers.apgd import solve_apgd
from ..contact.solvers.nsgs import solve_nsgs
from ..errors import LCPError
from ..lcp.active_set import solve_active_set
from ..regimes import Regime
from .time_stepping import next_time

#: the natural-map residual, relative to ``1 + ||q||``, a sparse step's LCP must meet (the
#: active-set answer is exact to rounding: the chains measured end near 1e-16)
SPARSE_TOL = 1e-10

#: the registered contact-problem solvers Moreau–Jean runs as iterative ones (``lcp_method``)
ITERATIVE_METHODS = ("nsgs", "apgd")
#: their natural-map tolerance without ``lcp_tol`` (the registered solvers' own)
ITERATIVE_TOL = 1e-8
#: their budget without ``lcp_max_iter``: NSGS sweeps, APGD gradient steps (the registered
#: solvers' own)
ITERATIVE_BUDGET = {"nsgs": 10_000, "apgd": 100_000}


def sparse_contacts_of(scene):
    """The scene's sparse frictionless contact model, or None (the dense paths)."""
    hook = getattr(scene, "sparse_contacts", None)
    if hook is None or np.any(np.asarray(scene.mu, dtype=float) != 0.0):
        return None
    return hook()


def sparse_step(integ, model):
    """One Moreau–Jean step of ``integ`` (a MoreauJean) on ``model`` (module docstring)."""
    inv_m, f, jacobian, gaps = model
    theta = integ.theta
    t0, q, v = integ.t, integ.q, integ.v
    t1, h = next_time(integ.t0, integ._k, integ.h, integ.t_bound)
    v_free = v + h * (inv_m * f)
    WN = jacobian(q)
    if not isinstance(WN, sps.csr_array):
        WN = sps.csr_array(WN)
    nc = WN.shape[0]
    g0 = integ._end_gap[2] if integ._end_gap is not None else np.asarray(gaps(q), dtype=float)
    vN0 = WN @ v
    active = (g0 + 0.5 * h * vN0 <= 0.0) | integ._closed
    pN = np.zeros(nc)
    v1 = v_free
    if active.any():
        every = bool(active.all())
        ia = np.flatnonzero(active)
        Ha = WN if every else WN[ia]
        U = Ha @ v_free
        qa = U + integ.e_c[ia] * np.minimum(vN0[ia], 0.0)
        # q >= 0: p = 0 solves it exactly (most steps of a chain: at rest, or moving apart)
        if np.any(qa < 0.0):
            W = sps.csr_array((Ha * inv_m) @ Ha.T)
            if integ.lcp_method in ITERATIVE_METHODS:
                q2 = np.zeros(2 * ia.size)
                q2[0::2] = qa
                r = _solve_iterative(integ, _interleaved(W), q2, np.zeros(ia.size), ia, nc)
                p = r[0::2]
            else:
                p, residual, solves = solve_active_set(W, qa)
                c = integ.counters
                c["lcp_solves"] += 1
                c["pivots"] += solves
                c["max_residual"] = max(c["max_residual"], residual)
                if not residual <= SPARSE_TOL:
                    raise LCPError(f"the sparse contact problem at t = {t0!r} ended with "
                                   f"residual {residual:.3g} > {SPARSE_TOL:g}")
            pN[ia] = p
            v1 = v_free + inv_m * (Ha.T @ p)
    q1 = q + h * (theta * v1 + (1.0 - theta) * v)
    if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
        integ.counters["steps"] -= 1
        integ._fail(-5, f"non-finite state after the step at t = {t0!r}")
        return
    gap = np.asarray(gaps(q1), dtype=float)
    integ.counters["max_penetration"] = max(integ.counters["max_penetration"],
                                            float(np.max(-gap, initial=0.0)))
    regime = np.where(pN > 0.0, int(Regime.STICK), int(Regime.FLIGHT))
    integ._closed = pN > 0.0
    integ._k += 1
    integ.t, integ.q, integ.v = t1, q1, v1
    integ._end_gap = (q1, t1, gap)
    fN, zero = pN / h, np.zeros(nc)
    if integ._pending_initial:
        integ._record(t0, q, v, regime, fN, zero, zero, g0)
        integ._pending_initial = False
    if integ._k % integ.save_every == 0 or t1 >= integ.t_bound:
        integ._record(t1, q1, v1, regime, fN, zero, zero, gap)


# -- the iterative solvers (module docstring, "Iterative solvers") ------------------------------

def _interleaved(W):
    """FCLib's ``W`` of frictionless contacts: ``W``'s entries on the normal rows and columns,
    a unit decoupled tangential row per contact (CSR, built without a dense matrix)."""
    n = W.shape[0]
    W = sps.csr_array(W)
    W.sum_duplicates()
    counts = np.diff(W.indptr)
    indptr = np.zeros(2 * n + 1, dtype=np.int64)
    indptr[1::2] = counts
    indptr[2::2] = 1
    np.cumsum(indptr, out=indptr)
    tangential = indptr[1:-1:2]
    normal = np.ones(indptr[-1], dtype=bool)
    normal[tangential] = False
    indices = np.empty(indptr[-1], dtype=np.int64)
    data = np.empty(indptr[-1])
    indices[normal] = 2 * W.indices
    data[normal] = W.data
    indices[tangential] = 2 * np.arange(n) + 1
    data[tangential] = 1.0
    return sps.csr_array((data, indices, indptr), shape=(2 * n, 2 * n))


def _start_residual(W, q, mu, r):
    """``||F(r)|| / (1 + ||q||)`` in plain float sums, to choose a start (the solver certifies
    what it returns); frictionless contacts in numpy: ``F_N = min(r_N, u_N)``, ``F_T = r_T``."""
    if np.any(mu):
        return problem_residual(W, q, mu, r)[0]
    u = W @ r + q
    fn = np.minimum(r[0::2], u[0::2])
    return math.sqrt(float(fn @ fn + r[1::2] @ r[1::2])) / (1.0 + float(np.linalg.norm(q)))


def _solve_iterative(integ, W, q, mu, ia, nc):
    """FCLib-layout impulses of the step's problem ``(W, q, mu)`` on the active contacts ``ia``
    (of ``nc``) by ``integ.lcp_method``, warm-started; the books kept, a miss raised."""
    method = integ.lcp_method
    tol = ITERATIVE_TOL if integ.lcp_tol is None else integ.lcp_tol
    c = integ.counters
    c["lcp_solves"] += 1
    c.setdefault("iterations", 0)
    zero = np.zeros_like(q)
    # F(0) is exact (u = q): where no impulse meets the tolerance, it is the answer (after
    # an inexact impact the next steps' problems are of the size of its residual)
    res_zero = _start_residual(W, q, mu, zero)
    if res_zero <= tol:
        c["max_residual"] = max(c["max_residual"], res_zero)
        return zero
    last = getattr(integ, "_iterative_last", None)
    r0 = None
    if last is not None and last[0] == integ._k - 1:
        r0 = last[1][ia].ravel()
        if not np.any(r0) or res_zero <= _start_residual(W, q, mu, r0):
            r0 = None
    budget = ITERATIVE_BUDGET[method] if integ.lcp_max_iter is None else integ.lcp_max_iter
    if method == "nsgs":
        omega = 1.0 if integ.lcp_omega is None else integ.lcp_omega
        res = solve_nsgs(W, q, mu, r0=r0, tol=tol, max_sweeps=budget, omega=omega)
    else:
        res = solve_apgd(W, q, mu, r0=r0, tol=tol, max_iter=budget)
    c["iterations"] += res.iterations
    c["max_residual"] = max(c["max_residual"], res.residual)
    if not res.converged:
        raise LCPError(f"the contact problem at t = {integ.t!r} was not solved: {res.message}")
    r = np.zeros((nc, 2))
    r[ia] = res.r.reshape(-1, 2)
    integ._iterative_last = (integ._k, r)
    return res.r


def iterative_contact_step(integ, W, U_free, mu, e, vN_pre, ia, pN, pT):
    """The generic step's contact problem by ``integ.lcp_method`` (:data:`ITERATIVE_METHODS`).

    ``W, U_free`` over the rows ``[N of the active contacts ia; T of the
    active frictional ones]`` (:class:`moreau.contact.ContactProblem`'s
    layout), ``mu, e, vN_pre`` of the active contacts. Writes ``pN[ia],
    pT[ia]`` and returns the stacked impulses; raises
    :class:`~moreau.errors.LCPError` where the solver stops above its tolerance.
    """
    problem = ContactProblem.trusted(W, U_free, mu, e, vN_pre)
    local = to_fclib(problem)
    r = _solve_iterative(integ, sps.csr_array(local.W), local.q, local.mu, ia,
                         integ.scene.ncontacts)
    pN[ia] = r[0::2]
    pT[ia] = np.where(mu > 0.0, r[1::2], 0.0)
    return from_fclib(problem, r)
