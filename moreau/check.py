"""Checks of a scene's model: the first thing to run on a scene of one's own.

:func:`check_scene` evaluates the :class:`~moreau.scenes.base.Scene` methods
at a few states and compares them with independent computations:

* shapes and sizes: ``mass`` (n, n), ``forces`` (n,), ``gaps`` (nc,),
  ``contact_jacobians`` ((nc, n), (nc,), (nf, n), (nf,)) with ``nf`` the
  number of frictional contacts, ``contact_drift`` ((nc,), (nf,)), ``mu`` and
  ``restitution`` of length ``nc`` with ``mu >= 0`` and ``0 <= e <= 1``;
  every value finite;
* the mass matrix symmetric and positive definite (Cholesky);
* the normal rows against central differences of the gaps along the
  motion: ``d/dt g(q + t v, t) = WN v + wN``;
* the drift terms against differences of the contact velocities along the
  motion at constant ``v``: ``wNbar = d/dt (WN v + wN)`` and the same for the
  tangential rows;
* ``force_jacobians``, where the scene gives them, against central
  differences of ``forces``; a scene that leaves the default (central
  differences, :meth:`~moreau.scenes.base.Scene.force_jacobians`) while its
  forces depend on the state gets a note saying so;
* the compiled model, where the scene gives one, against the Python one.

Examples
--------
>>> from moreau.scenes.bouncing_ball import BouncingBall
>>> report = check_scene(BouncingBall())
>>> report.ok, report.problems
(True, [])
>>> print(report.summary().splitlines()[0])
bouncing-ball: every check passed (4 states)
"""


from __future__ import annotations

import dataclasses
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .errors import InputError
from .compiled import check_compiled_model
from .scenes.base import Scene

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
    """

    name: str
    ok: bool
    problems: list
    warnings: list
    errors: dict
    states: int

    def summary(self):
        head = (f"{self.name}: every check passed ({self.states} states)" if self.ok else
                f"{self.name}: {len(self.problems)} problem(s)")
        lines = [head] + [f"  problem: {p}" for p in self.problems]
        lines += [f"  warning: {w}" for w in self.warnings]
        lines += [f"  {k}: {v:.2e}" for k, v in self.errors.items()]
        return "\n".join(lines)


def _rel(a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.size == 0:
        return 0.0
    return float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b))))


def _shape(problems, what, value, shape):
    arr = np.asarray(value, dtype=float)
    if arr.shape != shape:
        problems.append(f"`{what}` has shape {arr.shape}, expected {shape}")
        return None
    if not np.all(np.isfinite(arr)):
        problems.append(f"`{what}` is not finite")
        return None
    return arr


def _overrides(scene, method):
    return getattr(type(scene), method) is not getattr(Scene, method)


def check_scene(scene: Scene, states: Sequence[tuple[ArrayLike, ArrayLike]] | None = None,
                t: float = 0.3, fd_tol: float = 1e-6, compiled_tol: float = 1e-12,
                seed: int = 0) -> SceneReport:
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

    Returns
    -------
    SceneReport
    """
    if not isinstance(scene, Scene):
        raise InputError(f"`scene` must be a Scene instance, got {type(scene).__name__}")
    problems, warnings, errors = [], [], {}
    n = int(scene.ndof)
    mu = np.asarray(scene.mu, dtype=float).reshape(-1)
    e = np.asarray(scene.restitution, dtype=float).reshape(-1)
    nc = mu.size
    name = getattr(scene, "name", type(scene).__name__)
    if n <= 0:
        problems.append(f"`ndof` must be a positive integer, got {scene.ndof!r}")
        return SceneReport(name, False, problems, warnings, errors, 0)
    if e.size != nc:
        problems.append(f"`restitution` has {e.size} entries but `mu` has {nc} (one per contact)")
    if np.any(~np.isfinite(mu)) or np.any(mu < 0):
        problems.append(f"`mu` must be finite and >= 0, got {mu.tolist()}")
    if np.any(~np.isfinite(e)) or np.any((e < 0) | (e > 1)):
        problems.append(f"`restitution` must be in [0, 1], got {e.tolist()}")
    nf = int(np.count_nonzero(mu > 0))
    if states is None:
        try:
            q0, v0 = scene.initial_state()
        except NotImplementedError:
            problems.append("`initial_state()` is not defined: give `states` to check")
            return SceneReport(name, False, problems, warnings, errors, 0)
        q0 = np.asarray(q0, dtype=float)
        v0 = np.asarray(v0, dtype=float)
        rng = np.random.default_rng(seed)
        states = [(q0, v0)] + [(q0 + 0.05 * rng.standard_normal(n),
                                v0 + 0.5 * rng.standard_normal(n)) for _ in range(3)]
    eps = 1e-6
    worst = {"gap rates (WN, wN)": 0.0, "normal drift (wNbar)": 0.0,
             "tangential drift (wTbar)": 0.0, "force Jacobians": 0.0}
    state_dependent_forces = False
    for q, v in states:
        q = _shape(problems, "q", q, (n,))
        v = _shape(problems, "v", v, (n,))
        if q is None or v is None:
            break
        M = _shape(problems, "mass(q)", scene.mass(q), (n, n))
        if M is not None:
            if _rel(M, M.T) > 1e-12:
                problems.append("`mass(q)` is not symmetric")
            else:
                try:
                    np.linalg.cholesky(M)
                except np.linalg.LinAlgError:
                    problems.append("`mass(q)` is not positive definite")
        h = _shape(problems, "forces(q, v, t)", scene.forces(q, v, t), (n,))
        if nc:
            g = _shape(problems, "gaps(q, t)", scene.gaps(q, t), (nc,))
            WN, wN, WT, wT = scene.contact_jacobians(q, t)
            WN = _shape(problems, "contact_jacobians: WN", WN, (nc, n))
            wN = _shape(problems, "contact_jacobians: wN", wN, (nc,))
            WT = _shape(problems, "contact_jacobians: WT", WT, (nf, n))
            wT = _shape(problems, "contact_jacobians: wT", wT, (nf,))
            wNb, wTb = scene.contact_drift(q, v, t)
            wNb = _shape(problems, "contact_drift: wNbar", wNb, (nc,))
            wTb = _shape(problems, "contact_drift: wTbar", wTb, (nf,))
            if g is not None and WN is not None and wN is not None:
                fd = (scene.gaps(q + eps * v, t + eps) - scene.gaps(q - eps * v, t - eps)) / (2 * eps)
                worst["gap rates (WN, wN)"] = max(worst["gap rates (WN, wN)"],
                                                  _rel(WN @ v + wN, fd))

            def rates(s):
                WN_, wN_, WT_, wT_ = scene.contact_jacobians(q + s * v, t + s)
                return WN_ @ v + wN_, WT_ @ v + wT_

            if wNb is not None and wTb is not None and WN is not None and WT is not None:
                (np_, tp), (nm, tm) = rates(eps), rates(-eps)
                worst["normal drift (wNbar)"] = max(worst["normal drift (wNbar)"],
                                                    _rel(wNb, (np_ - nm) / (2 * eps)))
                worst["tangential drift (wTbar)"] = max(worst["tangential drift (wTbar)"],
                                                        _rel(wTb, (tp - tm) / (2 * eps)))
        if h is not None:
            K = np.empty((n, n))
            C = np.empty((n, n))
            for j in range(n):
                d = np.zeros(n)
                d[j] = eps
                K[:, j] = (scene.forces(q + d, v, t) - scene.forces(q - d, v, t)) / (2 * eps)
                C[:, j] = (scene.forces(q, v + d, t) - scene.forces(q, v - d, t)) / (2 * eps)
            if np.max(np.abs(K)) + np.max(np.abs(C)) > fd_tol:
                state_dependent_forces = True
            if _overrides(scene, "force_jacobians"):
                Kp, Cp = scene.force_jacobians(q, v, t)
                Kp = _shape(problems, "force_jacobians: dh/dq", Kp, (n, n))
                Cp = _shape(problems, "force_jacobians: dh/dv", Cp, (n, n))
                if Kp is not None and Cp is not None:
                    worst["force Jacobians"] = max(worst["force Jacobians"],
                                                   _rel(Kp, K), _rel(Cp, C))
        if scene.compiled_model() is not None:
            diff = check_compiled_model(scene, q, v, t)
            errors["compiled model"] = max(errors.get("compiled model", 0.0), diff)
    for key, val in worst.items():
        errors[key] = val
        if val > fd_tol:
            problems.append(f"{key}: differs from central differences by {val:.2e} "
                            f"(> {fd_tol:g})")
    if errors.get("compiled model", 0.0) > compiled_tol:
        problems.append(f"the compiled model differs from the Python model by "
                        f"{errors['compiled model']:.2e} (> {compiled_tol:g})")
    if state_dependent_forces and not _overrides(scene, "force_jacobians"):
        warnings.append("`forces` depend on the state and `force_jacobians` is not defined: "
                        "implicit schemes take central differences of `forces` "
                        f"({4 * n} force evaluations a step)")
    return SceneReport(name, not problems, problems, warnings, errors, len(states))
