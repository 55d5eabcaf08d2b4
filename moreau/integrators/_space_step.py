"""Moreau–Jean's step on a spatial scene: the friction cone per contact, orientations on SO(3).

See :mod:`moreau.integrators.moreau_jean` ("Spatial scenes") for the scheme.
"""

import numpy as np

from ..contact.cone3d import (CONVERGED, ConeSolution, facet_directions, natural_map_sq,
                              polyhedral_one_contact, solve_cone, solve_exact_contensou,
                              solve_polyhedral)
from ..errors import InputError, LCPError
from ..model.space import advance_coordinates
from ..regimes import Regime

#: a contact whose slip after the step is below this fraction of the step's velocity
#: scale counts as sticking
SLIP_RTOL = 1e-9


def check_cone(value):
    """The ``cone`` option: ``"auto"``, ``"exact"`` or an integer number of directions ``>= 3``."""
    if isinstance(value, str) and value in ("auto", "exact"):
        return value
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 3:
        raise InputError(f'`cone` must be "auto", "exact" or an integer number of directions '
                         f'>= 3, got {value!r}')
    return int(value)


def _free_rotation(J, w0, impulse, h, theta):
    """``w`` with ``J (w - w0) + h wt x J wt = impulse``, ``wt = theta w + (1 - theta) w0``.

    Newton on the 3x3 system (its Jacobian ``J + h theta ([wt]x J - [J wt]x)``)
    to rounding; at ``theta = 1/2`` the implicit midpoint rule, which keeps the
    free body's energy ``1/2 w.J w`` and ``|J w|`` (quadratic invariants).
    """
    if not (w0.any() or impulse.any()):
        # at rest and unloaded: Newton's answer is zero (+0.0) at its first step
        return np.zeros(3)
    w = w0 + np.linalg.solve(J, impulse)
    for _ in range(20):
        wt = theta * w + (1.0 - theta) * w0
        Jw = J @ wt
        F = J @ (w - w0) + h * np.cross(wt, Jw) - impulse
        A = J + h * theta * (_cross(wt) @ J - _cross(Jw))
        dw = np.linalg.solve(A, F)
        w = w - dw
        if np.max(np.abs(dw)) <= 1e-15 * max(1.0, float(np.max(np.abs(w)))):
            break
    return w


def _cross(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def space_step(scene, q, v, t0, t1, h, theta, closed, mu, e, cone, counters, memo=None,
               warm=None):
    """One step; returns ``(q1, v1, pN, pT, slip, regime)`` (``pT``, ``slip``: magnitudes).

    ``memo`` (a dict kept by the caller from step to step) remembers the
    support of the last polyhedral LCP of several contacts, by its active
    contacts, for :func:`_polyhedral`.

    ``warm``, an (nc, 3) array or None: the exact cone's solver starts from
    its rows (the last step's impulses of the contacts active again) and the
    step writes its own impulses there. A resting stack's faces make a
    degenerate problem (four points a face), where Gauss–Seidel from zero
    takes hundreds of sweeps to a solution that the last step's impulses
    already are.
    """
    # the forces without the gyroscopic term, which the rotation's own implicit step takes
    gyro = scene.gyroscopic(v)
    f = scene.forces(q, v, t1) - gyro
    if theta != 1.0:
        f = theta * f + (1.0 - theta) * (scene.forces(q, v, t0) - gyro)
    Minv = scene.mass_inverse(q)
    v_free = v + h * (Minv @ f)
    for b in scene.gyroscopic_bodies:
        k = 6 * b + 3
        v_free[k:k + 3] = _free_rotation(scene.inertias[b], v[k:k + 3], h * f[k:k + 3], h, theta)
    nc = scene.ncontacts
    pN, pT, slip = np.zeros(nc), np.zeros(nc), np.zeros(nc)
    regime = np.zeros(nc, dtype=int)
    v1 = v_free
    if nc:
        rows = scene.contact_rows(q)                    # (nc, 3, nvel): [n, t1, t2]
        vN0 = rows[:, 0, :] @ v
        g0 = scene.gaps(q, t0)
        if getattr(scene, "box_index", ()):
            # a box contact's slot may have no point at q (its rows zero): closed or not, it
            # is not in the problem
            closed = closed & scene.contacts_in_use(q)
        active = np.flatnonzero((g0 + 0.5 * h * vN0 <= 0.0) | closed)
        if active.size and getattr(scene, "drilling", False):
            v1 = _contensou_contacts(scene, q, v_free, Minv, rows, vN0, active, t0, mu, e,
                                     counters, pN, pT, slip, regime)
        elif active.size:
            H = rows[active].reshape(3 * active.size, -1)
            MinvHT = Minv @ H.T
            W = H @ MinvHT
            W = 0.5 * (W + W.T)
            U_free = H @ v_free
            U_free[0::3] += e[active] * np.minimum(vN0[active], 0.0)
            # (built in the layout from the scene's checked data); one contact's polyhedral
            # problem in closed form where certified, as the compiled loop solves it
            sol = _one_contact(W, U_free, mu[active], cone)
            if sol is None and cone != "exact" and memo is not None:
                sol = _polyhedral(W, U_free, mu[active], cone, active, memo, counters)
            elif sol is None and warm is not None and cone == "exact":
                sol = solve_cone(W, U_free, mu[active], cone, check=False,
                                 r0=warm[active].reshape(-1))
            if sol is None:
                sol = solve_cone(W, U_free, mu[active], cone, check=False)
            counters["lcp_solves"] += 1
            counters["max_residual"] = max(counters["max_residual"], sol.relative_residual)
            if "pivots" in sol.iterations:
                counters["pivots"] += int(sol.iterations["pivots"])
            if not sol.success:
                raise LCPError(f"the step's spatial friction problem at t = {t0!r} "
                               f"({sol.method} cone, {active.size} contacts) was not solved: "
                               f"{sol.status}, residual {sol.residual:.3g}; {sol.detail}")
            r = sol.r.reshape(-1, 3)
            if warm is not None:
                warm[:] = 0.0
                warm[active] = r
            v1 = v_free + MinvHT @ sol.r
            U = (H @ v1).reshape(-1, 3)
            scale = max(float(np.max(np.abs(U_free))), 1e-300)
            pN[active] = r[:, 0]
            pT[active] = np.hypot(r[:, 1], r[:, 2])
            slip[active] = np.hypot(U[:, 1], U[:, 2])
            for k, i in enumerate(active):
                if pN[i] > 0.0:
                    regime[i] = int(Regime.POSITIVE if mu[i] > 0.0 and slip[i] > SLIP_RTOL * scale
                                    else Regime.STICK)
    q1 = advance_coordinates(scene, q, theta * v1 + (1.0 - theta) * v, h)
    return q1, v1, pN, pT, slip, regime


def _one_contact(W, U_free, mu, cone):
    """One contact's polyhedral problem by :func:`moreau.contact.cone3d.polyhedral_one_contact`,
    as a :class:`~moreau.contact.cone3d.ConeSolution`; None where it is not certified."""
    if cone == "exact" or mu.size != 1:
        return None
    r = np.zeros(3)
    W = np.ascontiguousarray(W)
    U_free = np.ascontiguousarray(U_free)
    if not polyhedral_one_contact(W, U_free, float(mu[0]), facet_directions(cone), r):
        return None
    u = W @ r + U_free
    res = float(np.sqrt(natural_map_sq(r, u, mu)))
    qn = float(np.linalg.norm(U_free))
    return ConeSolution(r, u, CONVERGED, res, res / qn if qn > 0 else res, {"pivots": 0},
                        f"polyhedral-{cone}", "one contact in closed form")


def _polyhedral(W, U_free, mu, d, active, memo, counters):
    """The polyhedral problem as :func:`moreau.contact.cone3d.solve_polyhedral` solves it
    (``method="auto"``), with the support of the last one on the same active contacts given
    to ``"auto"`` (:func:`moreau.lcp.solve_lcp`): where Lemke's path would be finished in
    exact arithmetic, that support's point is tried first, checked on the data.

    Bodies at rest on several contacts (a pyramid of spheres) give after the first step data
    with rounding noise (tangential velocities of 1e-17, right-hand sides one ulp apart) on
    which the exact lexicographic path is long (75 pivots at d = 8, against 17 on the first
    step's clean data) on integers of thousands of bits: 35 s a step, where the support of
    the step before solves it with no pivot.
    """
    key = (tuple(active.tolist()), d)
    sol = solve_polyhedral(W, U_free, mu, d, check=False, support=memo.get(key))
    res = sol.lcp
    memo.clear()
    if res.success:
        memo[key] = np.flatnonzero(res.z > 0.0)
        if res.method == "support":
            counters["warm_starts"] = counters.get("warm_starts", 0) + 1
    return sol


def _contensou_contacts(scene, q, v_free, Minv, rows, vN0, active, t0, mu, e, counters,
                        pN, pT, slip, regime):
    """The active contacts' impulses with Coulomb–Contensou friction; returns ``v1``.

    A frictional contact with a patch (``scene.drilling_levers > 0``) adds
    its drilling row to ``[n, t1, t2]`` (:meth:`SpaceScene.drilling_rows`),
    and the problem is solved on the round cone with three tangential rows
    (:func:`moreau.contact.cone3d.solve_exact_contensou`). The recorded
    tangential force and slip are those of the two sliding rows; a contact
    slips (``P``) where its generalized slip ``(u_T, r* omega_n)`` does.
    """
    drill = scene.drilling_rows(q)
    lever = scene.drilling_levers
    blocks, sizes = [], []
    for i in active:
        if lever[i] > 0.0 and mu[i] > 0.0:
            blocks.append(np.vstack([rows[i], drill[i][None, :]]))
            sizes.append(4)
        else:
            blocks.append(rows[i])
            sizes.append(3)
    H = np.vstack(blocks)
    MinvHT = Minv @ H.T
    W = H @ MinvHT
    W = 0.5 * (W + W.T)
    U_free = H @ v_free
    starts = np.concatenate([[0], np.cumsum(sizes)])
    U_free[starts[:-1]] += e[active] * np.minimum(vN0[active], 0.0)
    sol = solve_exact_contensou(W, U_free, mu[active], sizes, check=False)
    counters["lcp_solves"] += 1
    counters["max_residual"] = max(counters["max_residual"], sol.relative_residual)
    if not sol.success:
        raise LCPError(f"the step's Coulomb–Contensou friction problem at t = {t0!r} "
                       f"({active.size} contacts) was not solved: {sol.status}, residual "
                       f"{sol.residual:.3g}; {sol.detail}")
    v1 = v_free + MinvHT @ sol.r
    U = H @ v1
    scale = max(float(np.max(np.abs(U_free))), 1e-300)
    for k, i in enumerate(active):
        a, b = starts[k], starts[k + 1]
        pN[i] = sol.r[a]
        pT[i] = np.hypot(sol.r[a + 1], sol.r[a + 2])
        slip[i] = np.hypot(U[a + 1], U[a + 2])
        if pN[i] > 0.0:
            moving = float(np.linalg.norm(U[a + 1:b])) > SLIP_RTOL * scale
            regime[i] = int(Regime.POSITIVE if mu[i] > 0.0 and moving else Regime.STICK)
    return v1
