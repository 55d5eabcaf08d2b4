"""Checks of a scene's model: the first thing to run on a scene of one's own.

:func:`check_scene` evaluates the :class:`~moreau.model.scene.Scene` methods
at a few states and compares them with independent computations:

* shapes and sizes: ``mass`` (n, n), ``forces`` (n,), ``gaps`` (nc,),
  ``contact_jacobians`` ((nc, n), (nc,), (nf, n), (nf,)) with ``nf`` the
  number of frictional contacts, ``contact_drift`` ((nc,), (nf,)), ``mu`` and
  ``restitution`` of length ``nc`` with ``mu >= 0`` and ``0 <= e <= 1``;
  every value finite;
* the mass matrix symmetric and positive definite (Cholesky);
* the normal rows against central differences of the gaps along the
  motion: ``d/dt g(q + t v, t) = WN v + wN``, and the rheonomic terms alone
  against differences in time at fixed positions: ``wN = dg/dt``;
* the gaps' continuity, along a short simulated motion (Moreau–Jean,
  whose states are checked too) and along the straight paths between the
  checked states: a change of a gap over a short part of a path must match
  its rate there (a jump in a gap is invisible to differences at a state);
* the drift terms against differences of the contact velocities along the
  motion at constant ``v``: ``wNbar = d/dt (WN v + wN)`` and the same for the
  tangential rows;
* ``force_jacobians``, where the scene gives them, against central
  differences of ``forces``; a scene that leaves the default (central
  differences, :meth:`~moreau.model.scene.Scene.force_jacobians`) while its
  forces depend on the state gets a note saying so;
* the tangential rows, where the scene states the tangential positions
  whose rates they are (an optional method ``slip_positions(q, t)``, one
  entry per frictional contact: a belt's ``x - vb t``), against their
  differences: ``WT v + wT`` along the motion and ``wT`` in time at fixed
  positions;
* the joint rows, where the scene has joints: ``WE v + wE`` against central
  differences of ``joint_residuals`` along the motion, ``joint_drift``
  against differences of ``WE v + wE`` at constant ``v``;
* the compiled model, where the scene gives one, against the Python one,
  each output by name (a wrong sign of a rheonomic term ``wT`` in one of
  them is named; without ``slip_positions`` nothing else checks ``wT``).

A problem met at several states is listed once, with the states.

Examples
--------
>>> from moreau.scenes.bouncing_ball import BouncingBall
>>> report = check_scene(BouncingBall())
>>> report.ok, report.problems
(True, [])
>>> print(report.summary().splitlines()[0])
bouncing-ball: every check passed (12 states)
"""


from __future__ import annotations

import dataclasses
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .errors import InputError, MoreauError
from .compiled import evaluate_compiled
from .integrators import simulate
from .model.scene import Scene, is_spatial, joint_row_count
from .model.space import advance_coordinates
from .model.spatial import quat_exp, quat_multiply

__all__ = ["check_scene", "SceneReport"]


@dataclasses.dataclass
class SceneReport:
    """What :func:`check_scene` found.

    Attributes
    ----------
    ok : bool
        No problem found.
    problems : list of str
        Each names the method and what is wrong with it.
    warnings : list of str
        Not wrong, but worth knowing (e.g. missing force Jacobians).
    errors : dict
        The largest measured relative difference of each comparison.
    states : int
        How many states were checked.
    where : dict
        For a problem met at particular states or paths, their names.
    """

    name: str
    ok: bool
    problems: list
    warnings: list
    errors: dict
    states: int
    where: dict = dataclasses.field(default_factory=dict)

    def summary(self):
        head = (f"{self.name}: every check passed ({self.states} states)" if self.ok else
                f"{self.name}: {len(self.problems)} problem(s)")
        lines = [head]
        for p in self.problems:
            at = self.where.get(p)
            if at and len(at) == self.states and all("state" in a or "motion's" in a
                                                     for a in at):
                at = [f"at every one of the {self.states} states"]
            lines.append(f"  problem: {p}" + (f" (seen {'; '.join(at)})" if at else ""))
        lines += [f"  warning: {w}" for w in self.warnings]
        lines += [f"  {k}: {v:.2e}" for k, v in self.errors.items()]
        return "\n".join(lines)


def _check_spatial(scene, states, t, fd_tol, seed):
    """:func:`check_scene` on a spatial scene (:mod:`moreau.model.space`).

    Positions move along the exponential map (``advance_coordinates``):
    ``WN v`` against central differences of the gaps, ``WT v`` against those
    of the contact points taken as material points of their bodies, the
    drift against differences of the rows times a constant ``v``, and
    ``dh/dv`` against differences of the forces; the mass matrix symmetric
    positive definite. A spatial scene has no compiled model.
    """
    name = getattr(scene, "name", type(scene).__name__)
    n, nv, nc = int(scene.ndof), int(scene.nvel), scene.ncontacts
    nf = len(scene.frictional_index)
    problems, errors = [], {}
    if states is None:
        q0, v0 = (np.asarray(a, dtype=float) for a in scene.initial_state())
        rng = np.random.default_rng(seed)
        states = [(q0, v0)]
        for _ in range(3):
            q = q0.copy()
            for b in range(n // 7):
                q[7 * b:7 * b + 3] += 0.05 * rng.standard_normal(3)
                q[7 * b + 3:7 * b + 7] = quat_multiply(q[7 * b + 3:7 * b + 7],
                                                       quat_exp(0.05 * rng.standard_normal(3)))
            states.append((q, v0 + 0.5 * rng.standard_normal(nv)))
    eps = 1e-6
    worst = {"gap rates (WN, wN)": 0.0, "slip rates (WT, wT)": 0.0, "normal drift (wNbar)": 0.0,
             "tangential drift (wTbar)": 0.0, "force Jacobians": 0.0}

    def material(qq, q_at):
        # (a contact between two bodies: the difference of its two material points)
        return np.asarray(scene.material_points(qq, q_at), dtype=float).reshape(nc, 3)

    for q, v in states:
        M = np.asarray(scene.mass(q), dtype=float)
        if M.shape != (nv, nv) or _rel(M, M.T) > 1e-12 or np.any(np.linalg.eigvalsh(
                0.5 * (M + M.T)) <= 0.0):
            problems.append("`mass(q)` is not a symmetric positive definite (nvel, nvel) matrix")
        qp = advance_coordinates(scene, q, v, eps)
        qm = advance_coordinates(scene, q, -v, eps)
        _, C = scene.force_jacobians(q, v, t)
        fd = np.column_stack([(scene.forces(q, v + eps * e, t) - scene.forces(q, v - eps * e, t))
                              / (2 * eps) for e in np.eye(nv)])
        worst["force Jacobians"] = max(worst["force Jacobians"], _rel(C, fd))
        if not nc:
            continue
        WN, wN, WT, wT = scene.contact_jacobians(q, t)
        if WN.shape != (nc, nv) or WT.shape != (2 * nf, nv):
            problems.append(f"`contact_jacobians` gives WN {WN.shape} and WT {WT.shape}, "
                            f"expected ({nc}, {nv}) and ({2 * nf}, {nv})")
            break
        gdot = (scene.gaps(qp, t) - scene.gaps(qm, t)) / (2 * eps)
        worst["gap rates (WN, wN)"] = max(worst["gap rates (WN, wN)"], _rel(WN @ v + wN, gdot))
        pdot = (material(qp, q) - material(qm, q)) / (2 * eps)
        bases = scene.contact_bases(q)
        slip = np.array([[bases[i][1] @ pdot[i], bases[i][2] @ pdot[i]]
                         for i in scene.frictional_index]).reshape(-1)
        worst["slip rates (WT, wT)"] = max(worst["slip rates (WT, wT)"], _rel(WT @ v + wT, slip))
        Jp, Jm = scene.contact_jacobians(qp, t), scene.contact_jacobians(qm, t)
        wNb, wTb = scene.contact_drift(q, v, t)
        worst["normal drift (wNbar)"] = max(worst["normal drift (wNbar)"], _rel(
            wNb, (Jp[0] @ v - Jm[0] @ v) / (2 * eps)))
        worst["tangential drift (wTbar)"] = max(worst["tangential drift (wTbar)"], _rel(
            wTb, (Jp[2] @ v - Jm[2] @ v) / (2 * eps)))
    for key, value in worst.items():
        errors[key] = value
        if value > fd_tol:
            problems.append(f"{key}: differs from central differences along the "
                            f"exponential-map motion by {value:.2e} (> {fd_tol:g})")
    return SceneReport(name, not problems, problems, ["a spatial scene has no compiled model"],
                       errors, len(states))


def _rel(a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.size == 0:
        return 0.0
    return float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b))))


def _shape(add, what, value, shape):
    arr = np.asarray(value, dtype=float)
    if arr.shape != shape:
        add(f"`{what}` has shape {arr.shape}, expected {shape}")
        return None
    if not np.all(np.isfinite(arr)):
        add(f"`{what}` is not finite")
        return None
    return arr


def _overrides(scene, method):
    return getattr(type(scene), method) is not getattr(Scene, method)


#: what each output of a compiled model is, for a problem that names it
_COMPILED_NAMES = {"mass": "M", "forces": "h", "K": "dh/dq", "C": "dh/dv", "gaps": "the gaps",
                   "WN": "WN", "wN": "wN (the normal rows' rheonomic term)",
                   "WN_normal_only": "WN (normal rows alone)",
                   "wN_normal_only": "wN (normal rows alone)", "WT": "WT",
                   "wT": "wT (the tangential rows' rheonomic term)", "wNbar": "wNbar",
                   "wTbar": "wTbar", "gaps_alone": "the gaps (gaps function)"}


def _compiled_differences(scene, q, v, t):
    """``{name: scaled difference}`` of each output of the compiled model against Python's."""
    c = evaluate_compiled(scene.compiled_model(), q, v, t)
    fr = scene.frictional_index
    K, Cj = scene.force_jacobians(q, v, t)
    WN, wN, WT, wT = scene.contact_jacobians(q, t)
    wNb, wTb = scene.contact_drift(q, v, t)
    python = {"mass": scene.mass(q), "forces": scene.forces(q, v, t), "K": K, "C": Cj,
              "gaps": scene.gaps(q, t), "WN": WN, "wN": wN, "WN_normal_only": WN,
              "wN_normal_only": wN, "WT": WT, "wT": wT, "wNbar": wNb, "wTbar": wTb,
              "gaps_alone": scene.gaps(q, t)}
    out = {}
    for key, b in python.items():
        if key not in c:
            continue
        a = np.asarray(c[key], dtype=float)
        if key in ("WT", "wT", "wTbar"):
            a = a[fr]
        b = np.asarray(b, dtype=float)
        if b.size:
            out[key] = _rel(a.reshape(b.shape), b)
    return out


def _gap_jumps(scene, qa, ta, qb, tb, pieces):
    """The worst jump of the gaps along the straight path from ``(qa, ta)`` to ``(qb, tb)``.

    On each of ``pieces`` parts the change of the gaps is compared with their
    rate at the part's middle (``WN dq + wN dt``, second-order accurate for a
    smooth gap); a change that differs from it by more than a tenth of the
    rate's own size is a jump. Returns ``(excess, contact, change, rate, q, t)``
    of the worst part, or None when every part agrees.
    """
    dq = (qb - qa) / pieces
    dt = (tb - ta) / pieces
    g0 = np.asarray(scene.gaps(qa, ta), dtype=float)
    worst = None
    for k in range(pieces):
        q1, t1 = qa + (k + 1) * dq, ta + (k + 1) * dt
        g1 = np.asarray(scene.gaps(q1, t1), dtype=float)
        WN, wN, _, _ = scene.contact_jacobians(qa + (k + 0.5) * dq, ta + (k + 0.5) * dt)
        WN, wN = np.asarray(WN, dtype=float), np.asarray(wN, dtype=float)
        rate = WN @ dq + wN * dt
        size = np.abs(WN) @ np.abs(dq) + np.abs(wN) * abs(dt)
        excess = np.abs(g1 - g0 - rate) - (0.1 * size + 1e-9 * (1.0 + np.abs(g1)))
        i = int(np.argmax(excess))
        if excess[i] > 0.0 and (worst is None or excess[i] > worst[0]):
            worst = (float(excess[i]), i, float(g1[i] - g0[i]), float(rate[i]),
                     qa + (k + 0.5) * dq, ta + (k + 0.5) * dt)
        g0 = g1
    return worst


#: steps of the short simulated motion along which the gaps are followed
MOTION_STEPS = 128
#: parts of the straight path between consecutive checked states
PATH_PIECES = 64


def _short_motion(scene, q0, v0, t0):
    """A short Moreau-Jean motion from ``(q0, v0)`` at ``t0``: a result, or the reason it failed."""
    period = getattr(scene, "period", None)
    span = min(1.0, 0.25 * period) if period else 1.0
    try:
        res = simulate(scene, (t0, t0 + span), q0, v0, "moreau-jean", h=span / MOTION_STEPS,
                       fast=False)
    except MoreauError as exc:
        return f"{type(exc).__name__}: {exc}"
    if res.t.size < 2:
        return res.message
    return res


def check_scene(scene: Scene, states: Sequence[tuple[ArrayLike, ArrayLike]] | None = None,
                t: float = 0.3, fd_tol: float = 1e-6, compiled_tol: float = 1e-12,
                seed: int = 0, motion: bool = True) -> SceneReport:
    """Check ``scene``'s model methods against independent computations.

    Parameters
    ----------
    scene : Scene
    states : list of (q, v), optional
        Where to check. Default: the scene's ``initial_state()`` and three
        random perturbations of it (positions by 0.05, velocities by 0.5 in
        the scene's units).
    t : float
        Time of the checks (the drive phase of a rheonomic scene).
    fd_tol : float
        Largest accepted relative difference from the central differences.
    compiled_tol : float
        Largest accepted relative difference of the compiled model.
    seed : int
        Seed of the random perturbations.
    motion : bool
        Also follow a short Moreau–Jean motion from the first state (128
        steps over ``min(1, period / 4)``): the checks at 8 of its states,
        and the gaps' continuity along it and along the straight paths
        between the states.

    Returns
    -------
    SceneReport
        A problem met at several states is listed once; the summary names
        the states where it appears.
    """
    if not isinstance(scene, Scene):
        raise InputError(f"`scene` must be a Scene instance, got {type(scene).__name__}")
    if is_spatial(scene):
        return _check_spatial(scene, states, t, fd_tol, seed)
    found, warnings, errors = {}, [], {}

    def note(msg, where):
        places = found.setdefault(msg, [])
        if where is not None and where not in places:
            places.append(where)

    def report(nstates):
        problems = list(found)
        return SceneReport(name, not problems, problems, warnings, errors, nstates,
                           {p: w for p, w in found.items() if w})

    n = int(scene.ndof)
    mu = np.asarray(scene.mu, dtype=float).reshape(-1)
    e = np.asarray(scene.restitution, dtype=float).reshape(-1)
    nc = mu.size
    name = getattr(scene, "name", type(scene).__name__)
    if n <= 0:
        note(f"`ndof` must be a positive integer, got {scene.ndof!r}", None)
        return report(0)
    if e.size != nc:
        note(f"`restitution` has {e.size} entries but `mu` has {nc} (one per contact)", None)
    if np.any(~np.isfinite(mu)) or np.any(mu < 0):
        note(f"`mu` must be finite and >= 0, got {mu.tolist()}", None)
    if np.any(~np.isfinite(e)) or np.any((e < 0) | (e > 1)):
        note(f"`restitution` must be in [0, 1], got {e.tolist()}", None)
    nf = int(np.count_nonzero(mu > 0))
    nj = joint_row_count(scene)
    if states is None:
        try:
            q0, v0 = scene.initial_state()
        except NotImplementedError:
            note("`initial_state()` is not defined: give `states` to check", None)
            return report(0)
        q0 = np.asarray(q0, dtype=float)
        v0 = np.asarray(v0, dtype=float)
        rng = np.random.default_rng(seed)
        states = [(q0, v0)] + [(q0 + 0.05 * rng.standard_normal(n),
                                v0 + 0.5 * rng.standard_normal(n)) for _ in range(3)]
        labels = ["at the initial state"] + [f"at perturbed state {k}" for k in (1, 2, 3)]
    else:
        labels = [f"at state {k}" for k in range(len(states))]
    checks = [(lab, q, v, t) for lab, (q, v) in zip(labels, states)]
    path = None
    eps = 1e-6
    worst = {"gap rates (WN, wN)": 0.0, "rheonomic terms (wN against d/dt of the gaps)": 0.0,
             "normal drift (wNbar)": 0.0, "tangential drift (wTbar)": 0.0,
             "force Jacobians": 0.0}
    compiled = {}
    state_dependent_forces = False
    good = []
    given = len(checks)
    k = 0
    while k < len(checks):
        label, q, v, ts = checks[k]
        k += 1

        def add(msg, label=label):
            note(msg, label)
        q = _shape(add, "q", q, (n,))
        v = _shape(add, "v", v, (n,))
        if q is None or v is None:
            break
        good.append((label, q, ts))
        M = _shape(add, "mass(q)", scene.mass(q), (n, n))
        if M is not None:
            if _rel(M, M.T) > 1e-12:
                add("`mass(q)` is not symmetric")
            else:
                try:
                    np.linalg.cholesky(M)
                except np.linalg.LinAlgError:
                    add("`mass(q)` is not positive definite")
        h = _shape(add, "forces(q, v, t)", scene.forces(q, v, ts), (n,))
        if nc:
            g = _shape(add, "gaps(q, t)", scene.gaps(q, ts), (nc,))
            WN, wN, WT, wT = scene.contact_jacobians(q, ts)
            WN = _shape(add, "contact_jacobians: WN", WN, (nc, n))
            wN = _shape(add, "contact_jacobians: wN", wN, (nc,))
            WT = _shape(add, "contact_jacobians: WT", WT, (nf, n))
            wT = _shape(add, "contact_jacobians: wT", wT, (nf,))
            wNb, wTb = scene.contact_drift(q, v, ts)
            wNb = _shape(add, "contact_drift: wNbar", wNb, (nc,))
            wTb = _shape(add, "contact_drift: wTbar", wTb, (nf,))
            if g is not None and WN is not None and wN is not None:
                fd = (scene.gaps(q + eps * v, ts + eps)
                      - scene.gaps(q - eps * v, ts - eps)) / (2 * eps)
                worst["gap rates (WN, wN)"] = max(worst["gap rates (WN, wN)"],
                                                  _rel(WN @ v + wN, fd))
                # the rheonomic terms alone: the gaps' change in time at fixed positions
                fdt = (scene.gaps(q, ts + eps) - scene.gaps(q, ts - eps)) / (2 * eps)
                key = "rheonomic terms (wN against d/dt of the gaps)"
                worst[key] = max(worst[key], _rel(wN, fdt))
            slide = getattr(scene, "slip_positions", None)
            if slide is not None and WT is not None and wT is not None and nf:
                # the tangential rows against a tangential position the scene states
                sp = _shape(add, "slip_positions(q, t)", slide(q, ts), (nf,))
                if sp is not None:
                    fd = (np.asarray(slide(q + eps * v, ts + eps), dtype=float)
                          - np.asarray(slide(q - eps * v, ts - eps), dtype=float)) / (2 * eps)
                    key = "slip rates (WT, wT)"
                    worst[key] = max(worst.get(key, 0.0), _rel(WT @ v + wT, fd))
                    fdt = (np.asarray(slide(q, ts + eps), dtype=float)
                           - np.asarray(slide(q, ts - eps), dtype=float)) / (2 * eps)
                    key = "rheonomic terms (wT against d/dt of the slip positions)"
                    worst[key] = max(worst.get(key, 0.0), _rel(wT, fdt))

            def rates(s):
                WN_, wN_, WT_, wT_ = scene.contact_jacobians(q + s * v, ts + s)
                return WN_ @ v + wN_, WT_ @ v + wT_

            if wNb is not None and wTb is not None and WN is not None and WT is not None:
                (np_, tp), (nm, tm) = rates(eps), rates(-eps)
                worst["normal drift (wNbar)"] = max(worst["normal drift (wNbar)"],
                                                    _rel(wNb, (np_ - nm) / (2 * eps)))
                worst["tangential drift (wTbar)"] = max(worst["tangential drift (wTbar)"],
                                                        _rel(wTb, (tp - tm) / (2 * eps)))
        if nj:
            # the joint rows, like the contacts': rates along the motion, drift at constant v
            WE, wE = scene.joint_jacobians(q, ts)
            WE = _shape(add, "joint_jacobians: WE", WE, (nj, n))
            wE = _shape(add, "joint_jacobians: wE", wE, (nj,))
            wEb = _shape(add, "joint_drift(q, v, t)", scene.joint_drift(q, v, ts), (nj,))
            gE = _shape(add, "joint_residuals(q, t)", scene.joint_residuals(q, ts), (nj,))
            if WE is not None and wE is not None and gE is not None:
                fd = (np.asarray(scene.joint_residuals(q + eps * v, ts + eps), dtype=float)
                      - np.asarray(scene.joint_residuals(q - eps * v, ts - eps),
                                   dtype=float)) / (2 * eps)
                key = "joint rates (WE, wE)"
                worst[key] = max(worst.get(key, 0.0), _rel(WE @ v + wE, fd))
            if wEb is not None and WE is not None and wE is not None:
                rp = [np.asarray(a, dtype=float)
                      for a in scene.joint_jacobians(q + eps * v, ts + eps)]
                rm = [np.asarray(a, dtype=float)
                      for a in scene.joint_jacobians(q - eps * v, ts - eps)]
                fd = ((rp[0] @ v + rp[1]) - (rm[0] @ v + rm[1])) / (2 * eps)
                key = "joint drift (wEbar)"
                worst[key] = max(worst.get(key, 0.0), _rel(wEb, fd))
        if h is not None:
            K = np.empty((n, n))
            C = np.empty((n, n))
            for j in range(n):
                d = np.zeros(n)
                d[j] = eps
                K[:, j] = (scene.forces(q + d, v, ts) - scene.forces(q - d, v, ts)) / (2 * eps)
                C[:, j] = (scene.forces(q, v + d, ts) - scene.forces(q, v - d, ts)) / (2 * eps)
            if np.max(np.abs(K)) + np.max(np.abs(C)) > fd_tol:
                state_dependent_forces = True
            if _overrides(scene, "force_jacobians"):
                Kp, Cp = scene.force_jacobians(q, v, ts)
                Kp = _shape(add, "force_jacobians: dh/dq", Kp, (n, n))
                Cp = _shape(add, "force_jacobians: dh/dv", Cp, (n, n))
                if Kp is not None and Cp is not None:
                    worst["force Jacobians"] = max(worst["force Jacobians"],
                                                   _rel(Kp, K), _rel(Cp, C))
        if scene.compiled_model() is not None:
            for key, diff in _compiled_differences(scene, q, v, ts).items():
                compiled[key] = max(compiled.get(key, 0.0), diff)
                if diff > compiled_tol:
                    add(f"the compiled model's {_COMPILED_NAMES[key]} differs from the Python "
                        "model's")
        if k == given and motion and nc and not any("has shape" in m or "is not finite" in m
                                                    for m in found):
            # the given states have the right shapes: follow a short motion from the first
            path = _short_motion(scene, good[0][1], np.asarray(checks[0][2], dtype=float), t)
            if isinstance(path, str):
                warnings.append(f"the short motion from {labels[0][3:]} failed ({path}); only "
                                "the states were checked")
                path = None
            else:
                for j in np.linspace(1, path.t.size - 1, 8).round().astype(int):
                    checks.append((f"at the motion's t = {path.t[j]:.6g}", path.q[j],
                                   path.v[j], float(path.t[j])))
    if compiled:
        errors["compiled model"] = max(compiled.values())
    if nc:
        # the gaps are continuous: along the motion, and along the straight paths between
        # the checked states (a jump in a gap is invisible to differences at the states)
        jumps = []
        if path is not None:
            for k in range(path.t.size - 1):
                jumps.append(("along the motion",
                              _gap_jumps(scene, path.q[k], float(path.t[k]), path.q[k + 1],
                                         float(path.t[k + 1]), 1)))
        for (la, qa, ta), (lb, qb, tb) in zip(good, good[1:]):
            if ta == tb:
                jumps.append((f"between {la[3:]} and {lb[3:]}",
                              _gap_jumps(scene, qa, ta, qb, tb, PATH_PIECES)))
        # one problem per contact: its worst jump, and every path where one was seen
        per_contact = {}
        for where, jump in jumps:
            if jump is not None:
                best, places = per_contact.setdefault(jump[1], [jump, []])
                if jump[0] > best[0]:
                    per_contact[jump[1]][0] = jump
                if where not in places:
                    places.append(where)
        for i, (jump, places) in sorted(per_contact.items()):
            _, _, change, rate, qj, tj = jump
            msg = (f"`gaps(q, t)` of contact {i} is not continuous: it changes by {change:.3g} "
                   f"where its rate WN dq + wN dt gives {rate:.3g}, near q = "
                   f"{np.array2string(qj, precision=4)}, t = {tj:.6g}")
            for where in places:
                note(msg, where)
    for key, val in worst.items():
        errors[key] = val
        if val > fd_tol:
            note(f"{key}: differs from central differences by {val:.2e} (> {fd_tol:g})", None)
    if state_dependent_forces and not _overrides(scene, "force_jacobians"):
        warnings.append("`forces` depend on the state and `force_jacobians` is not defined: "
                        "implicit schemes take central differences of `forces` "
                        f"({4 * n} force evaluations a step)")
    return report(len(good))
