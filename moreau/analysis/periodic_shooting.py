"""Periodic steady states of any periodically driven scene, by shooting on its period map.

The scene must be driven with period ``2 pi`` in its time (all drive scenes
of this package are) and have one *cyclic* coordinate that does not enter
the dynamics (a rotor position). The period map takes the state at the
Poincaré section ``tau_s`` to the state one period later, with the cyclic
coordinate reset; its fixed point is the periodic steady state and the
change of the cyclic coordinate is the net displacement per period.

Contacts touching at the section pin some of the state: a closed contact
fixes its gap and its normal velocity. Perturbing those would open the
contact (or push it in), so the unknowns are restricted to the directions
that keep the touching contacts' gaps and normal velocities at zero (the
null spaces of their normal rows ``WN``); after each update the state is
projected back onto the constraints. For the drive scenes with their rods
in contact at the section this leaves only the rotor velocity, and the
Newton iteration (forward-difference Jacobian, least-squares step) behaves
like a secant method on a scalar map. Any registered scheme can supply the
period map: the generic event-driven reference, or Moreau–Jean (where the
map is that of the discrete scheme).
"""

import math
import time

import numpy as np
from scipy.linalg import null_space

from .._validate import cyclic_coordinate, positive, positive_int
from ..errors import ConvergenceError, InputError, ResidualFloorError
from ..integrators import get_integrator, simulate
from ..integrators.base import check_options, scheme_options as options_of
from ..integrators.event_driven_generic import (ContactModeSolver, contact_law_regimes,
                                                contact_velocity_scale, project_positions)
from ..integrators.result import SteadyState
from ..modes import mode_name
from ..regimes import REGIME_LETTERS, Regime
from .floquet import period_map_jacobian, sorted_multipliers
from .steady_solvers import register_steady_solver

__all__ = ["shoot_periodic", "free_bases", "period_map_options", "bracket_scalar",
           "guess_options", "period_mode", "one_sample_per_period"]

TWO_PI = 2.0 * math.pi


#: periods of plain iteration (or period maps of the bracketing, one free direction) tried
#: after Newton stalls on a time-stepping scheme's period map
FIXED_POINT_PERIODS = 100

#: below this slope of ``P - I`` (its smallest singular value in several free directions) a
#: time-stepping map is on a flat step
FLAT_SLOPE = 1e-6


def _project(scene, t, q, v, touching):
    if not len(touching):
        return q, v
    q = project_positions(scene, t, q, touching, max_iter=5)
    WN, wN, _, _ = scene.contact_jacobians(q, t)
    WN, wN = WN[touching], wN[touching]
    MiW = np.linalg.solve(scene.mass(q), WN.T)
    v = v - MiW @ np.linalg.solve(WN @ MiW, WN @ v + wN)
    return q, v


def touching_contacts(scene, q, t):
    """Indices of the contacts whose gap at ``(q, t)`` is closed (to 1e-12 of the state's scale).

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=185.0)
    >>> touching_contacts(sc, sc.rest_state()[0], 0.0).tolist()
    [0]
    """
    gap_tol = 1e-12 * max(1.0, float(np.max(np.abs(q))))
    return np.flatnonzero(np.asarray(scene.gaps(q, t), dtype=float) <= gap_tol)


def free_bases(scene, q, t, cyclic, touching):
    """Orthonormal bases ``(Bq, Bv)`` of the free directions of a state at a section.

    ``Bq`` (``ndof`` rows, the cyclic coordinate's row zero) spans the
    position changes that keep the ``touching`` contacts' gaps closed to
    first order, ``Bv`` the velocity changes that keep their normal
    velocities; with no contact touching, every non-cyclic coordinate and
    every velocity is free. The period map and its Floquet multipliers act
    on ``z = (Bq^T dq, Bv^T dv)``.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=185.0)
    >>> q, v = sc.rest_state()
    >>> Bq, Bv = free_bases(sc, q, 0.0, 1, [0])
    >>> Bq.shape, Bv.shape
    ((2, 0), (2, 1))
    """
    touching = np.asarray(touching, dtype=int)
    keep = np.array([i for i in range(scene.ndof) if i != cyclic], dtype=int)
    if not len(touching):
        return np.eye(scene.ndof)[:, keep], np.eye(scene.ndof)
    WN = scene.contact_jacobians(q, t)[0][touching]
    Bq = np.zeros((scene.ndof, 0))
    nq = null_space(WN[:, keep])
    if nq.size:
        Bq = np.zeros((scene.ndof, nq.shape[1]))
        Bq[keep] = nq
    return Bq, null_space(WN)


def period_map_options(scheme, options):
    """The scheme's options for one period map: ``steps_per_period`` becomes the step ``h``.

    A time-stepping scheme (one that takes a step ``h``) is given its step as
    a number of steps per drive period (2000 by default); any other scheme
    refuses that setting.

    Examples
    --------
    >>> round(period_map_options("moreau-jean", {"steps_per_period": 100})["h"], 6)
    0.062832
    """
    opts = dict(options)
    accepted = options_of(get_integrator(scheme)) or ()
    if "h" in accepted:
        n = positive_int("steps_per_period", opts.pop("steps_per_period", 2000))
        if "h" in opts:
            raise InputError("give the step of the period map as `steps_per_period`, not `h`")
        opts["h"] = TWO_PI / n
    elif "steps_per_period" in opts:
        raise InputError(f"`steps_per_period` applies to time-stepping schemes; scheme "
                         f"{scheme!r} chooses its own steps")
    return opts


def one_sample_per_period(takes, options):
    """``options`` with the sampling setting that asks a scheme for one sample per drive period.

    ``takes`` are the options the scheme accepts; it also records whatever it
    records at events. A scheme without a sampling setting keeps ``options``.

    Examples
    --------
    >>> one_sample_per_period(("h", "save_every"), {"h": TWO_PI / 100})["save_every"]
    100
    >>> one_sample_per_period(("sample_dt",), {})
    {'sample_dt': 6.283185307179586}
    """
    out = dict(options)
    if "h" in takes and "save_every" in takes:
        out["save_every"] = int(round(TWO_PI / out["h"]))
    elif "sample_dt" in takes:
        out["sample_dt"] = TWO_PI
    elif "samples_per_period" in takes:
        out["samples_per_period"] = 1
    return out


def period_mode(scene, res, ts, span):
    """Mode name and regimes of a run recorded over one period, the same way for every scheme.

    Each sample but the last (the period's end, the start again) is named by
    the contact law at its state
    (:func:`~moreau.integrators.event_driven_generic.contact_law_regimes`):
    a run's first sample on a closed contact is not flight, and a
    time-stepping step whose impulse stayed in the cone across a slip
    reversal is not a stick.

    Returns
    -------
    mode : str
        Each contact's canonical mode, joined by ``"|"``.
    regimes : list of [float, str]
        Where the regimes (one letter per contact) change, as phases in ``[0, span)``
        from ``ts``.
    """
    nc = scene.ncontacts
    ms = ContactModeSolver(scene)
    # the run's velocity scale: a sample may fall where everything is at rest (the two-rod
    # drive's swap at tau = pi)
    vscale = contact_velocity_scale(scene, res.t, res.q, res.v, ms)
    law = np.array([contact_law_regimes(scene, tk, qk, vk, rk, ms, vscale=vscale)
                    for tk, qk, vk, rk in zip(res.t[:-1], res.q[:-1], res.v[:-1],
                                              res.regime[:-1])],
                   dtype=int).reshape(-1, nc)
    modes = []
    for c in range(nc):
        letters = [REGIME_LETTERS[Regime(int(x))] for x in law[:, c]]
        modes.append(mode_name(letters) if letters else "")
    regimes, prev = [], None
    for tk, row in zip(res.t[:-1], law):
        key = "".join(REGIME_LETTERS[Regime(int(x))] for x in row)
        if key != prev:
            regimes.append([float((tk - ts) % span), key])
            prev = key
    return "|".join(modes), regimes


def shoot_periodic(scene, scheme="event-driven", section_tau=0.0, q0=None, v0=None, cyclic=None,
                   rtol=1e-10, max_iter=30, transient_periods=0, scheme_options=None,
                   periods=1, floquet=True, **options):
    """Periodic steady state of a ``2 pi``-periodic scene, by Newton shooting.

    Parameters
    ----------
    scene : Scene
        Driven with period ``2 pi`` in its time, with a cyclic coordinate.
    scheme : str
        Registered scheme that computes the period map (``"event-driven"``,
        ``"event-driven-generic"``, ``"moreau-jean"``, ...).
    section_tau : float
        Phase of the Poincaré section.
    q0, v0 : array_like, optional
        Initial guess at the section; ``scene.rest_state(section_tau)`` by default.
    cyclic : int, optional
        Index of the cyclic coordinate; the one entry of
        ``scene.cyclic_coordinates`` by default.
    rtol : float
        Tolerance on the period-map residual in the free directions,
        relative to the velocity scale of the state.
    max_iter : int
        Newton iterations. Where they do not reach ``rtol`` with a
        time-stepping scheme (one with a step ``h``, whose period map is only
        piecewise smooth), the period map is iterated plainly from Newton's
        last state, up to :data:`FIXED_POINT_PERIODS` periods
        (``stats["fixed_point_periods"]``).
    transient_periods : int
        Periods simulated from the guess before shooting.
    scheme_options : dict, optional
        Options of the scheme whose names the shooting's own parameters take
        (a compliant scheme's ``rtol``); merged with ``options``.
    periods : int
        Shoot on this iterate of the period map (``k`` drive periods): a
        period-``k`` orbit. The displacement is reported per drive period.
    floquet : bool
        Compute the Floquet multipliers at the fixed point: central
        differences of the period map in the free directions (``2 n`` more
        period maps for ``n`` free directions), with steps of ``1e-6`` of
        the velocity scale, or for a time-stepping scheme ``2 sqrt(h)`` of
        it (its map is piecewise smooth on the scale of one step, as for
        :mod:`moreau.analysis.mj_steady_state`).
    **options
        Passed to the scheme (``steps_per_period`` is turned into ``h`` for
        Moreau–Jean, 2000 by default).

    Returns
    -------
    SteadyState
        ``state0`` is the full state ``(q, v)`` at the section (the cyclic
        coordinate at 0); ``mode`` names each contact's cyclic regime
        sequence, contacts separated by ``"|"``; ``regimes`` lists
        ``[tau, letters]`` with one letter per contact (``tau`` over the
        ``periods`` drive periods); ``floquet_multipliers`` are those of the
        (iterated) period map, ``period`` the number of drive periods.

    Raises
    ------
    InputError
        For a scene without a cyclic coordinate or a bad argument.
    ConvergenceError
        If Newton's method does not reach ``rtol``, or the scheme fails.

    Examples
    --------
    >>> from moreau.scenes import BidirectionalDrive, BidirectionalDriveParams
    >>> sc = BidirectionalDrive(BidirectionalDriveParams(x10_b=0.0), frequency=2000.0)
    >>> sc.cyclic_coordinates                    # the rotor position
    (2,)
    >>> ss = shoot_periodic(sc, "event-driven")  # doctest: +SKIP
    >>> ss.mode                                  # doctest: +SKIP
    'NP|F'
    """
    cyclic = cyclic_coordinate(scene, cyclic)
    rtol = positive("rtol", rtol)
    max_iter = positive_int("max_iter", max_iter)
    periods = positive_int("periods", periods)
    span = periods * TWO_PI

    get_integrator(scheme)  # an unknown name lists the known ones, before any work
    clash = set(scheme_options or {}) & set(options)
    if clash:
        raise InputError(f"`{sorted(clash)[0]}` is given twice (in `scheme_options` and as a keyword)")
    opts = period_map_options(scheme, {**options, **(scheme_options or {})})
    check_options(scheme, opts, scene)
    takes = options_of(get_integrator(scheme)) or ()
    fd_rel = _difference_step(get_integrator(scheme), opts)
    ts = float(section_tau)
    if q0 is None or v0 is None:
        if not hasattr(scene, "rest_state"):
            # any scene: its documented start (a user's scene need not define a rest state)
            q0, v0 = scene.initial_state()
        else:
            try:
                q0, v0 = scene.rest_state(ts)
            except TypeError:      # a scene whose rest state is given at tau = 0 only
                q0, v0 = scene.rest_state()
    q = np.array(q0, float)
    v = np.array(v0, float)
    q[cyclic] = 0.0
    start = time.perf_counter()
    calls = [0]

    def period(q, v, record=False):
        calls[0] += 1
        run_opts = dict(opts)
        if not record and "sample_dt" in takes:
            run_opts.setdefault("sample_dt", TWO_PI)
        res = simulate(scene, (ts, ts + span), q, v, scheme, **run_opts)
        if not res.success:
            raise ConvergenceError(f"the period map failed ({scheme}): {res.message}")
        return res

    for _ in range(-(-int(transient_periods) // periods)):
        res = period(q, v)
        q, v = res.q[-1].copy(), res.v[-1].copy()
        q[cyclic] = 0.0

    touching = touching_contacts(scene, q, ts)
    q, v = _project(scene, ts, q, v, touching)
    Bq, Bv = free_bases(scene, q, ts, cyclic, touching)
    nz_q = Bq.shape[1]

    def state(z, base):
        qb, vb = base
        qn = qb + Bq @ z[:nz_q]
        vn = vb + Bv @ z[nz_q:]
        return _project(scene, ts, qn, vn, touching)

    vmax = [0.0]

    def residual(qs, vs):
        res = period(qs, vs)
        vmax[0] = max(vmax[0], float(np.max(np.abs(res.v))))
        qe, ve = res.q[-1].copy(), res.v[-1].copy()
        disp = qe[cyclic] - qs[cyclic]
        qe[cyclic] = qs[cyclic]
        # only the free directions: a scheme that lets a closed gap wander
        # (Moreau-Jean) leaves a residual in the pinned ones that no
        # admissible start can remove
        return np.concatenate([Bq.T @ (qe - qs), Bv.T @ (ve - vs)]), disp

    base = (q, v)
    z = np.zeros(nz_q + Bv.shape[1])
    r, disp = residual(q, v)
    # the velocity scale of the motion over the period (the section may
    # catch the scene at rest)
    for tk in np.linspace(ts, ts + span, 33 * periods):
        _, wN, _, wT = scene.contact_jacobians(q, tk)
        vmax[0] = max(vmax[0], float(np.max(np.abs(wN), initial=0.0)),
                      float(np.max(np.abs(wT), initial=0.0)))
    vscale = max(vmax[0], float(np.max(np.abs(r))), 1e-300)
    it = 0
    fixed_point_periods = 0
    best = (float(np.max(np.abs(r))), z.copy())
    while np.max(np.abs(r)) > rtol * vscale:
        it += 1
        J = None
        if it <= max_iter:
            J = period_map_jacobian(lambda zz: residual(*state(zz, base))[0], z,
                                    fd_rel * np.maximum(vscale, np.abs(z)), f0=r, central=False)
        # a time-stepping scheme's period map is only piecewise smooth (its index set
        # changes on the grid): on a flat step of the map (slope of P - I about 0 in
        # a one-dimensional free space) Newton is blind, and it may stall anyway
        # in several free directions: P - I singular (a direction the grid-locked map
        # leaves unchanged; the piezo drive under Schatzman-Paoli, 60 blind Newton steps)
        slope = float(np.linalg.svd(J, compute_uv=False)[-1]) if J is not None else math.inf
        flat = slope < FLAT_SLOPE
        if it > max_iter or ("h" in takes and flat):
            newton = (f"shooting did not converge in `max_iter`={max_iter} Newton steps "
                      f"(residual {np.max(np.abs(r)) / vscale:.3g} relative)" if not flat else
                      f"Newton shooting met a flat step of the period map (slope of P - I "
                      f"{J[0, 0]:.2g}) after {it - 1} steps" if z.size == 1 else
                      f"Newton shooting met a flat step of the period map (P - I singular in "
                      f"a free direction: smallest singular value {slope:.2g}, the switches "
                      f"locked to the step grid) after {it - 1} steps, at a residual "
                      f"{np.max(np.abs(r)) / vscale:.3g} relative")
            if "h" not in takes:
                raise ConvergenceError(newton)
            if z.size == 1:
                # one free direction: P - I is non-increasing along it for a contracting
                # map (slope of P in [0, 1]), so a bracket of its sign change holds the
                # fixed point; start from Newton's best state
                z1, r, evals = bracket_scalar(lambda zz: residual(*state(zz, base))[0],
                                              best[1], rtol * vscale, FIXED_POINT_PERIODS)
                fixed_point_periods = evals
                qs, vs = state(z1, base)
                if np.max(np.abs(r)) > rtol * vscale:
                    raise ResidualFloorError(
                        f"{newton}; the period map's fixed point exists only to a residual "
                        f"{np.max(np.abs(r)) / vscale:.3g} relative (bracketed to rounding in "
                        f"{evals} period maps; the tolerance is {rtol:.3g}): its switches are "
                        f"locked to the step grid", state=(qs, vs),
                        residual=float(np.max(np.abs(r)) / vscale))
                break
            # plain iteration from Newton's best state (the last one can be far off
            # where a finite difference crossed a jump)
            qs, vs = state(best[1], base)
            qs, vs, r, fixed_point_periods = _iterate_period_map(
                period, qs, vs, cyclic, Bq, Bv, rtol * vscale, FIXED_POINT_PERIODS, newton,
                vscale)
            break
        step = np.linalg.lstsq(J, -r, rcond=None)[0]
        lam = 1.0
        for _ in range(6):
            qn, vn = state(z + lam * step, base)
            rn, dn = residual(qn, vn)
            if np.max(np.abs(rn)) < np.max(np.abs(r)) or lam < 0.05:
                break
            lam *= 0.5
        z = z + lam * step
        r, disp = rn, dn
        if np.max(np.abs(r)) < best[0]:
            best = (float(np.max(np.abs(r))), z.copy())
    if not fixed_point_periods:
        qs, vs = state(z, base)
    res = period(qs, vs, record=True)
    disp = float(res.q[-1, cyclic] - qs[cyclic]) / periods
    multipliers = None
    if floquet:
        # the residual's Jacobian in the free directions is B^T DP B - I (orthonormal bases)
        fd = 2.0 * math.sqrt(opts["h"]) if "h" in opts else max(1e-6, fd_rel)
        Jr = period_map_jacobian(lambda zz: residual(*state(zz, (qs, vs)))[0],
                                 np.zeros(z.size), fd * vscale)
        multipliers = sorted_multipliers(np.linalg.eigvals(Jr + np.eye(z.size)))
    mode, regimes = period_mode(scene, res, ts, span)
    closed = res.regime != int(Regime.FLIGHT)
    fmin = float(np.min(np.where(closed, res.force_N, np.inf))) if closed.any() else 0.0
    return SteadyState(
        scheme=scheme,
        displacement_per_period=disp,
        state0=np.concatenate([qs, vs]),
        mode=mode,
        regimes=regimes,
        min_normal_force=fmin,
        periodic_residual=float(np.max(np.abs(r)) / vscale),
        iterations=it,
        wall_time=time.perf_counter() - start,
        stats={"period_maps": calls[0], "unknowns": int(z.size),
               "fixed_point_periods": fixed_point_periods},
        section_tau=ts,
        floquet_multipliers=multipliers,
        floquet_method="finite-differences" if floquet else "",
        period=periods,
    )


def _difference_step(cls, opts):
    """Relative step of the period map's finite differences for scheme class ``cls``.

    ``1e-7``; for a scheme with an error tolerance (a class attribute
    ``error_tolerance_option`` names the option), ``sqrt(tol)`` where that is
    larger: its step sequence changes with the start, so its map is smooth
    only on scales above its tolerance, and a narrower difference reads the
    noise (Studer's scheme at 2000 Hz: a slope of P - I of 7e-3 under noise
    of 1e-10 at a difference of 1e-10).
    """
    name = getattr(cls, "error_tolerance_option", None)
    if not name:
        return 1e-7
    tol = opts.get(name, getattr(cls.Options(), name))
    return max(1e-7, math.sqrt(float(tol)))


def _iterate_period_map(period, q, v, cyclic, Bq, Bv, tol, max_periods, why, vscale):
    """Iterate the period map from ``(q, v)`` until it repeats within ``tol`` (free directions)."""
    for k in range(1, max_periods + 1):
        res = period(q, v)
        qe, ve = res.q[-1].copy(), res.v[-1].copy()
        qe[cyclic] = q[cyclic]
        r = np.concatenate([Bq.T @ (qe - q), Bv.T @ (ve - v)])
        q, v = qe, ve
        if np.max(np.abs(r)) <= tol:
            return q, v, r, k
    raise ResidualFloorError(f"{why}, and {max_periods} periods of plain iteration left a "
                             f"residual of {np.max(np.abs(r)):.3g} (the tolerance is {tol:.3g})",
                             state=(q, v), residual=float(np.max(np.abs(r)) / vscale))


def bracket_scalar(fun, z0, tol, max_evals):
    """Zero of a non-increasing scalar residual ``fun`` (one free direction) by bracketing.

    ``fun(z)`` returns ``P(z) - z`` as a one-element array. For a
    non-expansive map along the direction (slope of ``P`` in ``[0, 1]``,
    friction's rotor velocity) the zero lies at least ``|fun(z0)|`` away in
    the direction of ``fun(z0)``: the bracket is expanded from there by
    doubling, then closed by Illinois regula falsi. A map whose residual
    jumps over zero (switches locked to a step grid) ends with the bracket
    shrunk to adjacent floats; the end with the smaller residual is returned
    with it. A bracket still open after ``max_evals`` maps raises
    :class:`~moreau.errors.ConvergenceError`.

    Returns
    -------
    z : ndarray, shape (1,)
    r : ndarray, shape (1,)
        ``fun(z)``.
    evals : int
        Evaluations of ``fun`` (period maps).

    Examples
    --------
    >>> z, r, n = bracket_scalar(lambda z: np.array([0.5 * (1.0 - z[0])]), np.zeros(1), 1e-12, 60)
    >>> bool(abs(z[0] - 1.0) < 1e-11)
    True
    """
    evals = [0]

    def f(u):
        evals[0] += 1
        return float(np.asarray(fun(np.array([u])), float)[0])

    ua = float(np.asarray(z0, float)[0])
    fa = f(ua)
    if abs(fa) <= tol:
        return np.array([ua]), np.array([fa]), evals[0]
    step = fa
    while True:
        if evals[0] >= max_evals:
            raise ConvergenceError(f"no sign change of the period-map residual found in "
                                   f"{max_evals} period maps (last {fa:.3g})")
        ub = ua + step
        fb = f(ub)
        if abs(fb) <= tol:
            return np.array([ub]), np.array([fb]), evals[0]
        if np.sign(fb) != np.sign(fa):
            break
        ua, fa = ub, fb
        step *= 2.0
    side = 0
    ta, tb = fa, fb         # the true residuals at the ends (Illinois scales fa, fb)
    while True:
        uc = (ua * fb - ub * fa) / (fb - fa)
        if not min(ua, ub) < uc < max(ua, ub):
            uc = 0.5 * (ua + ub)
        if uc in (ua, ub):
            # the bracket is down to adjacent floats: the residual jumps over zero
            u, fu = (ua, ta) if abs(ta) <= abs(tb) else (ub, tb)
            return np.array([u]), np.array([fu]), evals[0]
        if evals[0] >= max_evals:
            raise ConvergenceError(f"the bracket [{ua:.17g}, {ub:.17g}] of the period map's "
                                   f"fixed point did not close in {max_evals} period maps")
        fc = f(uc)
        if abs(fc) <= tol:
            return np.array([uc]), np.array([fc]), evals[0]
        if np.sign(fc) == np.sign(fb):
            ub, fb, tb = uc, fc, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            ua, fa, ta = uc, fc, fc
            if side == 1:
                fb *= 0.5
            side = 1


def guess_options(scene, options):
    """``options`` with a neighbour's steady state ``guess`` turned into the shooting's start.

    The ``guess`` entry (a :class:`SteadyState`, continuation) becomes
    ``q0``, ``v0`` and ``section_tau``, unless those are given.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=185.0)
    >>> ss = SteadyState("event-driven", 0.1, np.array([0.7, 0.0, 0.0, -0.2]), "NP", [], 1.0,
    ...                  0.0, 1, 0.0, section_tau=0.5)
    >>> o = guess_options(sc, {"guess": ss})
    >>> o["q0"].tolist(), o["v0"].tolist(), o["section_tau"]
    ([0.7, 0.0], [0.0, -0.2], 0.5)
    """
    out = dict(options)
    guess = out.pop("guess", None)
    if guess is None or out.get("q0") is not None or out.get("v0") is not None:
        return out
    x = np.asarray(guess.state0, float)
    n = scene.ndof
    if x.size != 2 * n:
        raise InputError(f"`guess` has a state of {x.size} entries; the shooting of this scene "
                         f"needs the full state (q, v), {2 * n} entries")
    out["q0"], out["v0"] = x[:n].copy(), x[n:].copy()
    out.setdefault("section_tau", float(getattr(guess, "section_tau", 0.0) or 0.0))
    return out


@register_steady_solver("event-driven")
def _steady_solver(scene, rtol=1e-10, v_guess=None, max_iter=30, **options):
    # find_steady_state's entry for any periodic scene: Newton shooting on the period
    # map of the event-driven reference the scene resolves to
    return shoot_periodic(scene, "event-driven", rtol=rtol, max_iter=max_iter,
                          **guess_options(scene, options))
