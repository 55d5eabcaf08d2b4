"""Period-``k`` orbits: shooting on the ``k``-th iterate of the period map.

Where the period-1 shooting fails, or finds an orbit with a multiplier
outside the unit circle (past a period doubling, say), the long-run motion
may repeat only after ``k`` drive periods. :func:`find_period_k` shoots on
``P^k`` (:func:`moreau.analysis.periodic_shooting.shoot_periodic` with
``periods=k``) for ``k = 2, 3, ...`` from a few starting guesses: the
period-1 orbit's state pushed along each velocity coordinate (a flip
bifurcation's period-2 orbit lies next to it), and the states a transient
run from it passes at the section. It returns the first *stable* orbit
whose minimal period is ``k`` (a fixed point of ``P`` is one of ``P^k``
too, and Newton readily falls back onto it: those are refused).

Examples
--------
>>> from moreau.scenes.friction_drive import FrictionDrive
>>> from moreau.analysis.steady_state import find_steady_state
>>> find_steady_state(FrictionDrive(frequency=185.0), max_period=8).period   # stable: period 1
1
"""

import math

import numpy as np

from .._validate import positive_int
from ..errors import InputError, MoreauError
from ..integrators import simulate
from .periodic_shooting import shoot_periodic

__all__ = ["find_period_k", "minimal_period", "full_state_of"]

TWO_PI = 2.0 * math.pi

#: velocity pushes (shares of the orbit's largest speed) tried from the period-1 orbit
PUSHES = (0.15, -0.15, 0.05, -0.05, 0.3, -0.3)

#: periods of transient run whose section states are tried as guesses too
TRANSIENT_PERIODS = 40


def full_state_of(scene, state0):
    """``(q, v)`` of a steady state's ``state0`` (full, or without the cyclic coordinates)."""
    x = np.asarray(state0, float)
    n = scene.ndof
    if x.size == 2 * n:
        return x[:n].copy(), x[n:].copy()
    cyc = tuple(getattr(scene, "cyclic_coordinates", ()))
    if x.size == 2 * n - len(cyc):
        q = np.zeros(n)
        q[[i for i in range(n) if i not in cyc]] = x[:n - len(cyc)]
        return q, x[n - len(cyc):].copy()
    raise InputError(f"`state0` has {x.size} entries; scene {getattr(scene, 'name', '?')!r} "
                     f"needs {2 * n} (q, v) or {2 * n - len(cyc)} (without the cyclic coordinates)")


def _section_states(scene, scheme, q, v, ts, periods, options):
    res = simulate(scene, (ts, ts + periods * TWO_PI), q, v, scheme, **options)
    if not res.success:
        raise MoreauError(f"the run from the orbit failed: {res.message}")
    out = []
    for j in range(1, periods + 1):
        i = int(np.argmin(np.abs(res.t - (ts + j * TWO_PI))))
        out.append((res.q[i].copy(), res.v[i].copy(), res.t[i]))
    return out, float(np.max(np.abs(res.v))) if res.v.size else 1.0


def minimal_period(scene, scheme, ss, rtol=1e-6, options=None):
    """Smallest ``j`` dividing ``ss.period`` after which the orbit's state repeats.

    States are compared at the section, the cyclic coordinate aside,
    relative to the orbit's largest velocity.
    """
    k = int(ss.period)
    opts = dict(options or {})
    opts.setdefault("sample_dt", TWO_PI / 64)
    q, v = full_state_of(scene, ss.state0)
    cyc = set(getattr(scene, "cyclic_coordinates", ()))
    states, vmax = _section_states(scene, scheme, q, v, ss.section_tau, k, opts)
    keep = [i for i in range(scene.ndof) if i not in cyc]
    for j in range(1, k + 1):
        if k % j:
            continue
        qj, vj, tj = states[j - 1]
        if abs(tj - (ss.section_tau + j * TWO_PI)) > 1e-9 * (1.0 + abs(tj)):
            # the run did not sample the section exactly: the state there is unknown
            raise MoreauError("the orbit's run has no sample at the section")
        d = max(float(np.max(np.abs(qj[keep] - q[keep]))), float(np.max(np.abs(vj - v))))
        if d <= rtol * max(vmax, 1e-300):
            return j
    return k


def find_period_k(scene, scheme, max_period=8, start=None, section_tau=0.0, rtol=1e-10,
                  max_iter=30, options=None):
    """The first stable orbit of minimal period ``k`` in ``2..max_period``, or None.

    Parameters
    ----------
    scene : Scene
        A ``2 pi``-periodic scene with a cyclic coordinate.
    scheme : str
        The scheme whose period map is iterated (any registered scheme).
    max_period : int
        Largest ``k`` tried.
    start : SteadyState or tuple, optional
        The period-1 orbit (unstable) or a state ``(q, v)`` to start from;
        the scene's initial state by default.
    section_tau : float
        Phase of the section (the period-1 orbit's when ``start`` is one).
    rtol, max_iter
        Of each shooting (:func:`shoot_periodic`).
    options : dict, optional
        The scheme's options (``steps_per_period`` for a time-stepping one).

    Returns
    -------
    SteadyState or None
        With ``period = k``; its ``mode`` and ``regimes`` cover the ``k``
        periods, ``displacement_per_period`` is per drive period and the
        multipliers are those of ``P^k``.
    """
    max_period = positive_int("max_period", max_period)
    opts = dict(options or {})
    if start is None:
        q0, v0 = scene.initial_state()
    elif hasattr(start, "state0"):
        q0, v0 = full_state_of(scene, start.state0)
        section_tau = float(start.section_tau)
    else:
        q0, v0 = (np.asarray(a, float) for a in start)
    ts = float(section_tau)
    run_opts = {k: v for k, v in opts.items() if k != "steps_per_period"}
    if "steps_per_period" in opts:
        run_opts["h"] = TWO_PI / int(opts["steps_per_period"])
    try:
        passed, vmax = _section_states(scene, scheme, q0, v0, ts, TRANSIENT_PERIODS,
                                       {**run_opts, "sample_dt": TWO_PI / 64})
    except MoreauError:
        passed, vmax = [], max(float(np.max(np.abs(v0))), 1e-300)
    guesses = []
    cyc = set(getattr(scene, "cyclic_coordinates", ()))
    for a in PUSHES:
        for i in range(scene.ndof):
            if i in cyc:
                continue
            dv = np.zeros(scene.ndof)
            dv[i] = a * vmax
            guesses.append((q0, v0 + dv))
    guesses += [(q, v) for q, v, _ in passed[-max_period:]]
    for k in range(2, max_period + 1):
        for q, v in guesses:
            try:
                ss = shoot_periodic(scene, scheme, section_tau=ts, q0=q, v0=v, periods=k,
                                    rtol=rtol, max_iter=max_iter, **opts)
                if ss.stable and minimal_period(scene, scheme, ss, options=run_opts) == k:
                    return ss
            except MoreauError:
                continue
    return None
