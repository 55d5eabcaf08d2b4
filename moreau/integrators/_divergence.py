"""A run whose state blew up is named as diverged, not by the symptom a step met on the way.

A step too large for a scheme's stability lets the state grow by a factor
every step; long before it overflows, the contact problem built from it is
nonsense (the flexible rod with Schatzman–Paoli at 100 steps a period:
``W_NN = 1.5e103`` after 43 steps, reported as a "discrete Painlevé
condition violated"). :func:`divergence` tells such a state apart and says
what the step did against the fastest smooth oscillation of the scene at
the start of the run.
"""

import math

import numpy as np

__all__ = ["divergence", "fastest_oscillation", "bounded_velocities", "GROWTH"]

#: a state this many times larger than the start (and than 1: the scenes are scaled) diverged
GROWTH = 1e8


def fastest_oscillation(scene, q, v, t):
    """``omega_max``: the largest ``sqrt`` of a positive eigenvalue of ``-M^-1 df/dq`` at a state.

    The stiffness is the central difference of the scene's forces in each
    coordinate (step ``1e-6 (1 + |q_i|)``). NaN where the forces cannot be
    evaluated, 0 without a positive eigenvalue (no oscillation).

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> sc = make_scene("flexible-rod-drive")
    >>> q, v = sc.rest_state()
    >>> fastest_oscillation(sc, q, v, 0.0) > 10.0
    True
    """
    try:
        q = np.asarray(q, float)
        v = np.asarray(v, float)
        n = q.size
        K = np.zeros((n, n))
        for i in range(n):
            d = 1e-6 * (1.0 + abs(q[i]))
            qp, qm = q.copy(), q.copy()
            qp[i] += d
            qm[i] -= d
            K[:, i] = -(np.asarray(scene.forces(qp, v, t), float)
                        - np.asarray(scene.forces(qm, v, t), float)) / (2.0 * d)
        lam = np.linalg.eigvals(np.linalg.solve(np.asarray(scene.mass(q), float), K))
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return math.nan
    lam = lam.real[(np.abs(lam.imag) <= 1e-9 * np.maximum(1.0, np.abs(lam))) & (lam.real > 0)]
    return float(math.sqrt(np.max(lam))) if lam.size else 0.0


def bounded_velocities(scene, n):
    """Index of the velocities a divergence is judged on: all but the cyclic coordinates'.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> bounded_velocities(FrictionDrive(), 2).tolist()
    [0]
    """
    cyc = set(int(i) for i in getattr(scene, "cyclic_coordinates", ()) or ())
    return np.array([i for i in range(n) if i not in cyc], dtype=int)


def divergence(scene, q_start, v_start, t_start, q, v, t, h=None):
    """Why the state ``(q, v)`` at ``t`` is a diverged run, or None.

    Diverged: not finite, or a velocity more than :data:`GROWTH` times the
    larger of 1 and the start's largest velocity (positions are left out: a
    free body's grows without bound over a long window; so are the velocities
    of cyclic coordinates: a rotor past stall runs away, which is physics,
    :mod:`moreau.analysis.runaway`). The reason gives the growth and,
    with a step ``h``, ``h omega_max`` at the start against the bound 2 of
    the explicit central-difference (Störmer–Verlet) step.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> sc = make_scene("flexible-rod-drive")
    >>> q, v = sc.rest_state()
    >>> divergence(sc, q, v, 0.0, q, v, 1.0) is None
    True
    >>> print(divergence(sc, q, v, 0.0, q, v + 1e12, 1.0, h=0.0628))  # doctest: +ELLIPSIS
    the state diverged: its largest velocity is 1e+12 at t = 1 against 1 at the start ...
    """
    keep = bounded_velocities(scene, np.size(v))
    x0 = np.ravel(np.asarray(v_start, float))[keep]
    x = np.ravel(np.asarray(v, float))[keep]
    start = max(1.0, float(np.max(np.abs(x0))) if x0.size else 1.0)
    finite = bool(np.all(np.isfinite(x)) and np.all(np.isfinite(np.asarray(q, float))))
    big = float(np.max(np.abs(x))) if finite and x.size else (0.0 if finite else math.inf)
    if not big > GROWTH * start:
        return None
    msg = (f"the state diverged: its largest velocity is {big:.3g} at t = {t:.6g} against "
           f"{start:.3g} at the start (scene units)")
    if h is None:
        return msg
    w = fastest_oscillation(scene, q_start, v_start, t_start)
    if not math.isfinite(w) or w == 0.0:
        return msg + f"; the step h = {h:.4g} (no smooth oscillation found at the start)"
    hw = h * w
    if hw >= 2.0:
        return (msg + f"; the step h = {h:.4g} exceeds the stability bound 2 / omega_max = "
                f"{2.0 / w:.4g} of an explicit step (omega_max = {w:.4g}, the fastest smooth "
                f"oscillation at the start: h omega_max = {hw:.3g} > 2)")
    return (msg + f"; the step h = {h:.4g} is within the linear stability bound 2 / omega_max "
            f"= {2.0 / w:.4g} at the start (omega_max = {w:.4g}): a nonlinear or contact-"
            f"driven instability")


def explicit_step_note(scene, q_start, v_start, t_start, h):
    """``"; the step h = ... exceeds the stability bound ..."`` where it does, else ``""``.

    For a run of an explicit scheme that stopped for another reason (it left
    the scene's valid region) on its way to diverging: the stop names the
    instability that drove it there.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> sc = make_scene("flexible-rod-drive")
    >>> q, v = sc.rest_state()
    >>> explicit_step_note(sc, q, v, 0.0, 1e-6)
    ''
    >>> explicit_step_note(sc, q, v, 0.0, 0.0628)[:40]
    '; the step h = 0.0628 exceeds the stabil'
    """
    w = fastest_oscillation(scene, q_start, v_start, t_start)
    if not math.isfinite(w) or w == 0.0 or h * w < 2.0:
        return ""
    return (f"; the step h = {h:.4g} exceeds the stability bound 2 / omega_max = {2.0 / w:.4g} "
            f"of an explicit step (omega_max = {w:.4g}, the fastest smooth oscillation at the "
            f"start: h omega_max = {h * w:.3g} > 2), which drove it there")
