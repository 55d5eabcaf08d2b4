"""Linear complementarity problems: find ``z >= 0`` with ``w = M z + q >= 0`` and ``z.w = 0``.

One entry point, :func:`solve_lcp`, reaches every method by name. Each method
lives in its own module and exposes ``solve(M, q, *, max_iter, tol,
check_input, friction, ...)``; :data:`METHODS` maps names to them.

``"lemke"``
    Lemke's complementary pivoting with a lexicographic ratio test
    (:mod:`moreau.lcp.lemke`); compiled with numba, its kernel can also be
    called from compiled code (:func:`lemke_kernel`).
``"qp"``
    Convex QP formulations solved by OSQP through qpsolvers
    (:mod:`moreau.lcp.qp`); exact for symmetric PSD and monotone ``M``, a
    Tresca fixed point for the friction LCP.
``"auto"``
    Lemke first. When Lemke proves the LCP infeasible (a secondary ray with
    ``M`` copositive-plus, a ray that is itself a Farkas vector, or a unit
    vector that is one) that is the answer: status :data:`INFEASIBLE`, no
    QP. After a secondary ray that proves nothing, the dual of the LP
    ``{z >= 0, M z + q >= 0}`` (HiGHS) is tried for a Farkas vector, and for
    ``n <= enumerate_max_n`` (12) the ``2^n`` complementary pieces are
    visited (:mod:`moreau.lcp.decide`): a solution found is returned
    certified, every piece shown empty in exact arithmetic gives
    :data:`NO_SOLUTION`. On any other failure the QP method, with the path
    recorded in ``result.path``. Where Lemke's path would need more than
    ``lemke.DEFER_STEPS`` (4) steps decided in exact arithmetic (degenerate,
    over-constrained contact problems, where each exact step costs
    milliseconds to seconds), the QP at Lemke's tolerance comes first; its
    solution is taken when it passes the check on the data (path ``("lemke",
    "qp")``), else Lemke's path is finished exactly as above. With the
    option ``support`` (indices of a guessed support, e.g. the last time
    step's), the point of that support
    (:func:`moreau.lcp.lemke.solve_on_support`) comes before the QP there,
    taken when it passes the same check (path ``("lemke", "support")``, no
    pivot): the friction LCP of bodies at rest, whose data carry rounding
    noise, keeps its support from step to step, where the exact path costs
    seconds.

Success means the same for every method: ``z`` passed
:func:`lcp_violation` ``<= tol`` (``z >= -tol_z``, ``w = M z + q >=
-tol_w`` and ``|min(z_i / tol_z, w_i / tol_w)| <= 1`` with ``tol_w = tol
max|q|``, ``tol_z = tol_w / max|M|``), checked against the data after the
backend has finished, whatever the backend reported. Infeasibility is a
status too, :data:`INFEASIBLE`, and carries its proof, a Farkas vector, in
``result.certificate``.

The 2D Coulomb friction LCP is built by :func:`build_friction_lcp` and read
back by :func:`friction_impulses` (:mod:`moreau.lcp.friction`).

Examples
--------
>>> import numpy as np
>>> from moreau.lcp import solve_lcp
>>> M = np.array([[2.0, 1.0], [1.0, 2.0]])
>>> res = solve_lcp(M, np.array([-1.0, 1.0]))
>>> res.success, res.z.tolist(), res.w.tolist()
(True, [0.5, 0.0], [0.0, 1.5])
"""

import inspect

import numpy as np

from . import _result, decide, lemke, qp
from ._result import (
    BREAKDOWN,
    INFEASIBLE,
    INVALID_INPUT,
    MAX_ITER,
    NO_SOLUTION,
    NOT_APPLICABLE,
    SECONDARY_RAY,
    SOLVED,
    SOLVER_FAILED,
    STATUS_MESSAGES,
    LCPResult,
    lcp_residual,
    lcp_violation,
)
from ..errors import InputError
from .friction import (
    FrictionLayout,
    FrictionLCP,
    build_friction_lcp,
    contact_velocities,
    friction_impulses,
)
from .lemke import lemke_core, lemke_kernel, lemke_workspace

__all__ = [
    "solve_lcp",
    "METHODS",
    *_result.__all__,
    "lemke_kernel",
    "lemke_core",
    "lemke_workspace",
    "build_friction_lcp",
    "friction_impulses",
    "contact_velocities",
    "FrictionLayout",
    "FrictionLCP",
]


def _auto(M, q, *, max_iter=None, tol=None, check_input=True, friction=None,
          enumerate_max_n=decide.ENUMERATE_MAX_N, support=None):
    # Lemke's answer is exact when it exists; the QP path is slower and
    # less accurate, so it only runs when pivoting did not deliver. A proof
    # of infeasibility is an answer too: no QP can overturn it.
    if check_input:
        if (isinstance(enumerate_max_n, bool) or not isinstance(enumerate_max_n, (int, np.integer))
                or not 0 <= enumerate_max_n <= 20):
            raise InputError(f"`enumerate_max_n` must be an integer in [0, 20] (2^n pieces are "
                             f"visited), got {enumerate_max_n!r}")
        if support is not None:
            support = lemke._support_indices(support, len(q))
    first = lemke._solve(M, q, max_iter, tol, check_input, None, True)
    second = None
    if first is None and support is not None:
        # a guessed support (a time step's warm start) before the QP and the exact path,
        # checked on the data like them (see the module docstring)
        guess = lemke.solve_on_support(M, q, support, tol=tol)
        if guess is not None:
            guess.path = ("lemke", "support")
            guess.detail = (f"{guess.detail} Lemke first: its path needed more than "
                            f"{lemke.DEFER_STEPS} steps decided in exact arithmetic, so the "
                            f"support given was tried before finishing it exactly.")
            return guess
    if first is None:
        # Lemke's path needs more than a few steps in exact arithmetic (degenerate,
        # over-constrained problems: each step on Python integers of thousands of
        # bits, seconds in all). The QP, certified on the data to Lemke's tolerance,
        # comes first; the exact path only when it fails.
        second = qp.solve(M, q, tol=lemke.DEFAULT_TOL if tol is None else tol,
                          check_input=check_input, friction=friction)
        if second.status == SOLVED:
            # (a proof of infeasibility stays Lemke's, whose ray names its matrix class)
            second.path = ("lemke", "qp")
            second.detail = (f"{second.detail} Lemke first: its path needed more than "
                             f"{lemke.DEFER_STEPS} steps decided in exact arithmetic, so the QP "
                             f"was tried before finishing it exactly.")
            return second
        first = lemke.solve(M, q, max_iter=max_iter, tol=tol, check_input=check_input)
    if first.status == SOLVED or first.status == INFEASIBLE:
        return first
    if first.status == SECONDARY_RAY:
        decided = _decide_after_ray(first, np.asarray(M, dtype=float), np.asarray(q, dtype=float),
                                    tol, enumerate_max_n)
        if decided is not None:
            return decided
    if second is None or tol is None:
        # (a QP run above at Lemke's tolerance is reused where the tolerance is the same)
        second = qp.solve(M, q, tol=tol, check_input=check_input, friction=friction)
    second.path = first.path + ("qp",)
    second.detail = f"{second.detail} Lemke first: {first.message}"
    if second.status not in (SOLVED, INFEASIBLE) and first.residual < second.residual:
        # neither solved: keep the point closer to a solution, say so
        first.path = first.path + ("qp",)
        first.detail = f"{first.detail} The QP fallback failed too: {second.message}"
        return first
    return second


def _decide_after_ray(first, M, q, tol, max_n):
    # Lemke's secondary ray proved nothing: a Farkas vector from the LP dual,
    # then (small n) the complementary pieces. Returns a result, or None with
    # what was tried written into first.detail and first.path
    n = len(q)
    y = decide.lp_farkas(M, q)
    if y is not None:
        res = LCPResult(first.z, first.w, INFEASIBLE, first.pivots, first.residual, "lp",
                        path=("lemke", "lp"))
        res.certificate = y
        res.detail = (f"Lemke ended on a secondary ray that proves nothing; the dual of the LP "
                      f"{{z >= 0, M z + q >= 0}} (HiGHS) gave a Farkas vector y, with y >= 0, "
                      f"M^T y <= 0 and q.y = {float(q @ y):.3g} < 0 checked exactly on the given "
                      f"data, in `certificate`.")
        return res
    if n > max_n:
        first.path = ("lemke", "lp")
        return None
    out, z, counts = decide.enumerate_pieces(M, q, 1e-9 if tol is None else tol)
    how = (f"the 2^{n} = {counts['pieces']} complementary pieces were visited "
           f"(after Lemke ended on a secondary ray and the LP dual gave no Farkas vector)")
    if out == "solved":
        res = LCPResult(z, M @ z + q, SOLVED, first.pivots, lcp_violation(M, q, z), "enumerate",
                        path=("lemke", "lp", "enumerate"))
        res.detail = f"Solved by enumeration: {how}; z lies in the piece J = {counts['J']}."
        return res
    if out == "none":
        res = LCPResult(first.z, first.w, NO_SOLUTION, first.pivots, first.residual, "enumerate",
                        path=("lemke", "lp", "enumerate"))
        res.detail = (f"{how[0].upper()}{how[1:]}, and each was shown empty in exact rational arithmetic on the given "
                      f"data: {counts['regular']} by the unique solution of M_JJ z_J = -q_J "
                      f"violating a sign, {counts['singular']} (M_JJ singular) by a Farkas "
                      f"certificate checked exactly. So LCP(M, q) has no solution.")
        return res
    first.path = ("lemke", "lp", "enumerate")
    first.detail = (f"{first.detail} Then {how}: no solution found, but {counts['undecided']} "
                    f"of them could not be decided exactly, so nothing is proven.")
    return None


#: method name -> solve function, all with the signature of :func:`solve_lcp`
METHODS = {
    "lemke": lemke.solve,
    "qp": qp.solve,
    "auto": _auto,
}


def solve_lcp(M, q, method="lemke", *, max_iter=None, tol=None, check_input=True, friction=None, **options):
    """Solve the linear complementarity problem ``LCP(M, q)``.

    Find ``z >= 0`` with ``w = M z + q >= 0`` and ``z.w = 0``.

    Parameters
    ----------
    M : array_like, shape (n, n)
    q : array_like, shape (n,)
    method : {"lemke", "qp", "auto"}
        See :data:`METHODS`.
    max_iter : int, optional
        Pivot limit (Lemke) or fixed-point iteration limit (QP, friction).
    tol : float, optional
        Bound on the violation (:func:`lcp_violation`) for a solved status;
        each method has its own default (Lemke 1e-9, QP 1e-6).
    check_input : bool
        Validate the data in Python. With False, ``M`` and ``q`` must be
        float64 arrays of matching shapes; Lemke still rejects NaN and inf
        from its compiled code, so the lean path stays safe.
    friction : FrictionLayout, optional
        Layout from :func:`build_friction_lcp`; lets ``"qp"`` use the Tresca
        fixed point on the (non-monotone) friction LCP.
    **options
        Method-specific options, e.g. ``covering`` for ``"lemke"``.

    Returns
    -------
    LCPResult
        ``z``, ``w``, ``status``, ``success``, ``message``, ``pivots``,
        ``residual``, ``method``, ``path``, ``fallback_used``, ``ray`` and
        ``certificate``.

    Raises
    ------
    InputError
        An unknown ``method`` (the message lists the known ones), a
        non-square ``M``, a length mismatch, NaN or inf in the data.

    Examples
    --------
    >>> import numpy as np
    >>> res = solve_lcp(np.array([[-1.0]]), np.array([-1.0]))
    >>> res.status == INFEASIBLE, res.success, res.certificate.tolist()
    (True, False, [1.0])
    >>> solve_lcp(np.eye(1), np.ones(1), method="simplex")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `method` must be one of 'auto', 'lemke', 'qp'; got 'simplex'
    >>> solve_lcp(np.eye(1), np.ones(1), method="qp", covering=np.ones(1))
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `covering` is not an option of method 'qp'; its options: refine
    """
    if method == "lemke" and not options:
        # the per-time-step path: skip the keyword forwarding
        return lemke._solve(M, q, max_iter, tol, check_input, None)
    try:
        fn = METHODS[method]
    except (KeyError, TypeError):
        known = ", ".join(repr(k) for k in sorted(METHODS))
        raise InputError(f"`method` must be one of {known}; got {method!r}") from None
    if options:
        accepted = _method_options(method)
        for key in options:
            if key not in accepted:
                raise InputError(f"`{key}` is not an option of method {method!r}; its options: "
                                 + (", ".join(sorted(accepted)) or "none beyond max_iter, tol, "
                                    "check_input and friction"))
    return fn(M, q, max_iter=max_iter, tol=tol, check_input=check_input, friction=friction, **options)


_COMMON = ("max_iter", "tol", "check_input", "friction")


def _method_options(method):
    """The method-specific keyword options of ``method`` (beyond the common ones)."""
    params = inspect.signature(METHODS[method]).parameters
    return {k for k, p in params.items() if p.kind is inspect.Parameter.KEYWORD_ONLY
            and k not in _COMMON}
