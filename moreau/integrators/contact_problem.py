"""The contact problem of one time step, as the time-stepping schemes call it.

Every velocity- or impulse-level scheme of this package ends a step with the
same problem on its active contacts: local velocities ``U = U_free + W p``
(``W`` the Delassus matrix over the stacked normal and tangential rows),
Newton's impact law ``0 <= U_N + e min(vN_pre, 0) _|_ p_N >= 0`` and 2D
Coulomb friction. The schemes differ only in what they put into ``W``,
``U_free``, ``e`` and ``vN_pre``. :func:`solve_contact_problem` hands it to
:func:`moreau.contact.solve` as a :class:`~moreau.contact.ContactProblem`:
one active contact in closed form, several by the friction LCP through
:func:`moreau.lcp.solve_lcp` (Lemke, then the QP fallback with
``lcp_method="auto"``), and keeps the schemes' statistics. A problem that is
not solved raises :class:`~moreau.errors.LCPError`; no false solution is
returned. The schemes' Painlevé policy (:data:`PAINLEVE_POLICIES`) and the
tangential-impact record live here too.
"""

import math

import numpy as np

from ..contact import ContactProblem, solve
from ..contact.solvers.closed_form import solve as closed_form_solve
from ..contact.closed_form import (MAX_PIECES_CONTACTS, friction_pieces,  # noqa: F401
                                   one_contact_impulse, one_contact_residual, tangential_impact)
from ..errors import InputError, LCPError, PainleveError

__all__ = ["solve_contact_problem", "new_contact_counters", "one_contact_impulse",
           "one_contact_residual", "PAINLEVE_POLICIES", "check_painleve", "tangential_impact",
           "sliding_regimes", "painleve_option", "slip_signs", "friction_pieces",
           "MAX_PIECES_CONTACTS"]


#: accepted values of the schemes' ``painleve`` option: take the tangential impact
#: (the impulsive stick the complete contact problem gives) or stop the run there
PAINLEVE_POLICIES = ("impulse", "stop")


def check_painleve(painleve):
    """Validate a scheme's ``painleve`` option (:data:`PAINLEVE_POLICIES`).

    Examples
    --------
    >>> check_painleve("stop")
    'stop'
    >>> check_painleve("jam")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `painleve` must be one of ['impulse', 'stop'], got 'jam'
    """
    if not isinstance(painleve, str) or painleve not in PAINLEVE_POLICIES:
        raise InputError(f"`painleve` must be one of {list(PAINLEVE_POLICIES)}, got {painleve!r}")
    return painleve


def painleve_option(painleve, fast):
    """``(painleve, fast)`` of a scheme, checked (the compiled loops hand a step where
    ``"stop"`` applies to the generic step, which stops there)."""
    return check_painleve(painleve), fast


def slip_signs(regimes):
    """``+1`` / ``-1`` / ``0`` of regime codes: positive slip, negative slip, neither."""
    reg = np.asarray(regimes)
    return np.where(reg == 1, 1.0, np.where(reg == 2, -1.0, 0.0))


def new_contact_counters():
    """The statistics :func:`solve_contact_problem` updates, all zero."""
    return {"lcp_solves": 0, "direct_solves": 0, "pivots": 0, "fallbacks": 0, "warm_starts": 0,
            "max_residual": 0.0, "tangential_impacts": 0, "tangential_impact_times": []}


def sliding_regimes(scene, q, v, t):
    """Regime codes of the contacts of ``scene`` that slide at ``(q, v, t)``, as the step before ``t`` would leave them.

    A frictional contact that is closed (gap <= 0) and not separating
    (normal velocity <= 0) with a nonzero slip velocity is coded
    ``POSITIVE`` or ``NEGATIVE`` by the slip's sign; every other contact
    ``FLIGHT``. A scheme starts its tangential-impact detection
    (:func:`tangential_impact`) from these, so that a run started sliding
    into a Painlevé configuration records its first step's jam.

    Examples
    --------
    >>> import math
    >>> from moreau.scenes.painleve_rod import PainleveRod
    >>> rod = PainleveRod()
    >>> q0, v0 = rod.sliding_state(phi=math.atan(2.0), tip_speed=-1.0)
    >>> sliding_regimes(rod, q0, v0, 0.0).tolist()
    [2]
    """
    nc = scene.ncontacts
    out = np.zeros(nc, dtype=np.int64)
    if nc == 0 or getattr(scene, "spatial", False):
        # a spatial contact slides in a plane: no sign, and no planar Painlevé detection
        return out
    fr = np.asarray(scene.frictional_index, dtype=int)
    if fr.size == 0:
        return out
    g = np.asarray(scene.gaps(q, t), dtype=float)
    vN, vT = (np.asarray(a, dtype=float) for a in scene.contact_velocities(q, v, t))
    for k, i in enumerate(fr):
        if g[i] <= 0.0 and vN[i] <= 0.0 and vT[k] != 0.0:
            out[i] = 1 if vT[k] > 0.0 else 2
    return out

def _jam_check(W, U_free, mu, e, vN_pre, slip_before, painleve, c, t):
    if mu.size != 1 or not mu[0] > 0.0:
        return
    if painleve == "stop":
        # the study of Painlevé configurations: stop wherever the free slip, whatever
        # its size, runs into a sliding piece without solution
        uT = float(U_free[1])
        if uT != 0.0 and tangential_impact(W[:2, :2], U_free[:2], mu[0], e[0], vN_pre[0],
                                           math.copysign(1.0, uT)):
            where = f" at t = {t!r}" if t is not None else ""
            raise PainleveError(
                f"tangential impact{where} (painleve='stop'): discrete Painlevé condition "
                f"W_NN - mu |W_NT| > 0 violated (W_NN = {W[0, 0]:.6g}, W_NT = {W[0, 1]:.6g}, "
                f"mu = {mu[0]:.6g}) with the contact sliding the paradoxical way: no sliding "
                f"solution exists, the step's solution is an impulsive stick")
        return
    if slip_before is None:
        return
    if not tangential_impact(W[:2, :2], U_free[:2], mu[0], e[0], vN_pre[0], slip_before[0]):
        return
    c["tangential_impacts"] = c.get("tangential_impacts", 0) + 1
    c.setdefault("tangential_impact_times", []).append(None if t is None else float(t))


def solve_contact_problem(W, U_free, mu, e, vN_pre, *, lcp_method="auto", counters=None,
                          lemke_max_iter=None, t=None, slip_before=None, painleve="impulse",
                          warm=None, warm_key=None):
    """Impulses of the active contacts of one step.

    Parameters
    ----------
    W : ndarray, shape (na + nf, na + nf)
        Delassus matrix over the rows ``[N of every active contact; T of the
        active frictional ones]``, the tangential rows in the order of the
        frictional contacts among the active ones.
    U_free : ndarray, shape (na + nf,)
        Local velocities without contact impulses.
    mu, e, vN_pre : ndarray, shape (na,)
        Friction and restitution coefficients and pre-step normal velocities
        of the active contacts.
    lcp_method : {"auto", "lemke", "qp"}
        ``"auto"`` solves one contact in closed form; ``"lemke"`` and
        ``"qp"`` force that solver on the assembled LCP.
    counters : dict, optional
        Updated in place (keys of :func:`new_contact_counters`).
    lemke_max_iter : int, optional
        Pivot limit of Lemke's method.
    t : float, optional
        Time of the step, for the error message and the record of a tangential impact.
    slip_before : array_like, shape (na,), optional
        Slip direction of each active contact at the end of the step before
        (``+1``, ``-1``, ``0``); with it a one-contact step is checked for a
        tangential impact (:func:`tangential_impact`), which is counted in
        ``counters["tangential_impacts"]`` with its time in
        ``counters["tangential_impact_times"]``.
    painleve : {"impulse", "stop"}
        ``"impulse"`` (default): take a tangential impact. ``"stop"``: raise
        :class:`~moreau.errors.PainleveError` on a one-contact step whose
        contact presses and whose free slip ``u_T``, of any size, runs along a
        sliding piece without solution (``W_NN - mu sign(u_T) W_NT <= 0``):
        every tangential impact, and also a stick whose slip of rounding size
        points the paradoxical way (the schemes' behaviour before the
        tangential impact was taken).
    warm : dict, optional
        The caller's memory from one step to the next, updated in place: it
        keeps the support of the last friction LCP solved, under
        ``warm_key`` (the active contacts, say). A problem of several
        contacts with the same key gets that support as its warm start
        (:class:`~moreau.contact.ContactProblem`'s ``warm``): where Lemke's
        path would be finished in exact arithmetic, ``"auto"`` tries that
        support's point first, checked on the data. A solve on it is counted
        in ``counters["warm_starts"]``, not as a fallback.
    warm_key : hashable, optional
        The key of this problem in ``warm``.

    Returns
    -------
    p : ndarray, shape (na + nf,)
        The impulses, stacked like the rows of ``W``.
    pN, pT : ndarray, shape (na,)
        Normal and tangential impulse of each active contact (``pT = 0`` on
        a frictionless one).

    Raises
    ------
    LCPError
        The contact problem has no certified solution.
    PainleveError
        A tangential impact with ``painleve="stop"``, or one contact whose
        Delassus matrix is singular violates the discrete Painlevé condition.

    Examples
    --------
    A unit mass sliding at speed 1 onto the ground at approach speed 1, ``mu = 0.5``:

    >>> p, pN, pT = solve_contact_problem(np.eye(2), np.array([-1.0, 1.0]), np.array([0.5]),
    ...                                   np.zeros(1), np.zeros(1))
    >>> pN, pT
    (array([1.]), array([-0.5]))
    """
    c = counters if counters is not None else new_contact_counters()
    mu = np.asarray(mu, dtype=float)
    e = np.asarray(e, dtype=float)
    vN_pre = np.asarray(vN_pre, dtype=float)
    _jam_check(W, U_free, mu, e, vN_pre, slip_before, painleve, c, t)
    c["lcp_solves"] += 1
    support = None
    if warm is not None:
        support = warm.get(warm_key)
        warm.clear()
    problem = ContactProblem.trusted(W, U_free, mu, e, vN_pre, warm=support)
    if mu.size == 1 and lcp_method == "auto":
        # what "auto" does with one contact, without the registry's dispatch (4 us of 15)
        try:
            sol = closed_form_solve(problem)
        except PainleveError:
            sol = None
        if sol is None or not sol.success:
            # singular W, or digits lost to it: "auto" hands it to Lemke (or raises the
            # Painlevé case where the problem has no solution)
            sol = solve(problem, "auto", max_iter=lemke_max_iter)
    else:
        sol = solve(problem, lcp_method, max_iter=lemke_max_iter)
    r = sol.lcp
    if r is None:
        c["direct_solves"] += 1
    else:
        if r.method == "lemke":
            c["pivots"] += int(r.pivots)
        if r.path[-1:] == ("support",):
            c["warm_starts"] += 1
        elif r.fallback_used:
            c["fallbacks"] += 1
        if warm is not None and r.success and r.z.size == mu.size + 3 * np.count_nonzero(mu > 0.0):
            warm[warm_key] = np.flatnonzero(r.z > 0.0)
        if sol.method == "pieces":
            c["piece_enumerations"] = c.get("piece_enumerations", 0) + 1
    if not sol.success:
        where = f" at t = {t!r}" if t is not None else ""
        raise LCPError(f"contact problem{where} not solved: {sol.message}")
    c["max_residual"] = max(c["max_residual"], sol.residual)
    return sol.p, sol.pN, sol.pT
