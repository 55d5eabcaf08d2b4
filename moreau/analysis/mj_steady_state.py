"""Periodic steady state of the *discrete* Moreau–Jean map of a periodic scene.

The rotor position ``u2`` does not enter the dynamics, so one drive period of
``N`` Moreau–Jean steps maps the state ``x = (phi, phi', u2')`` at
``tau = 0`` to the state at ``tau = 2 pi``: ``x -> Phi(x)``, plus the
displacement ``u2(2 pi) - u2(0)``. The steady state is the fixed point
``Phi(x*) = x*``, found by Newton's method on ``Phi(x) - x`` with a
forward-difference Jacobian (three extra period maps per iteration) and a
backtracking line search; no transient is simulated, so a barely
contracting map (the drive at 2000 Hz) costs no more than a strongly
contracting one. The eigenvalues of the period-map Jacobian at the fixed
point are reported (``stats["period_map_slope"]`` is the largest modulus).

The discrete map carries one discrete state besides ``x``: whether the
contact was closed in the last step (the index-set memory of
:mod:`moreau.integrators.moreau_jean`). It is held fixed during a Newton
solve and the solve is repeated if it does not come back unchanged after a
period.

Projection
----------
The default ``projection=True`` keeps a closed contact on ``g = 0``. Without
it the velocity-level scheme lets the gap of the closed contact creep by
``O(h)`` per period (always opening, from the curvature of
``sin phi``), so the map has no fixed point in ``phi``; with it ``phi`` at
``tau = 0`` is pinned by the contact and the map is effectively a map of
``u2'``.

Mode naming
-----------
Each step's regime comes from its impulses. A slip reversal inside one step
shows up as a one-step stick between slips of opposite sign; the continuous
system has no stick there, so :func:`merge_step_regimes` drops such a
one-step stick (the reversal time is put at the middle of that step). Any
other run, including a one-step stick between slips of the *same* sign or a
one-step slip, is kept. A closed frictionless contact is named by the sign of
its slip velocity, never stick (:func:`moreau.modes.step_letters`),
and a regime entered from flight is marked as entered through an impact, as
the event-driven reference marks it. The cyclic sequence is then named by
:func:`moreau.modes.mode_name`.
"""

import math
import time

import numpy as np

from .._validate import finite_array, in_closed_interval, positive, positive_int
from ..errors import ConvergenceError, InputError, MoreauError, PainleveError
from ..modes import impacts_after_flight, mode_name, step_letters
from ..integrators.contact_problem import check_painleve
from ..integrators.moreau_jean import LCP_METHODS, MoreauJean
from ..integrators.result import SteadyState
from ._illinois import false_position, illinois_update
from .floquet import period_map_jacobian, sorted_multipliers
from .periodic_shooting import free_bases
from .steady_solvers import register_steady_solver

__all__ = ["moreau_jean_steady_state", "merge_step_regimes", "PeriodMap"]

TWO_PI = 2.0 * math.pi


def merge_step_regimes(letters, taus, h, period=TWO_PI):
    """Regime runs of one period of time steps, as the continuous system would name them.

    Parameters
    ----------
    letters : sequence of str
        Regime letter of each step over one period (cyclic).
    taus : sequence of float
        Start time of each step, increasing, the first at ``tau = 0``.
    h : float
        Step length.
    period : float
        Length of the period (``2 pi`` in the drive's time ``tau``).

    Returns
    -------
    list of [float, str]
        ``[tau_start, letter]`` in time order, the first at ``tau = 0`` with
        the regime in force there; consecutive equal letters are merged (the
        last run may continue into the first across the period end).

    Examples
    --------
    >>> merge_step_regimes("NNNSPPPN", range(8), 1.0, period=8.0)
    [[0.0, 'N'], [3.5, 'P'], [7.0, 'N']]
    >>> merge_step_regimes("NNSSPP", range(6), 1.0, period=6.0)
    [[0.0, 'N'], [2.0, 'S'], [4.0, 'P']]
    >>> merge_step_regimes("NNSNN", range(5), 1.0, period=5.0)
    [[0.0, 'N'], [2.0, 'S'], [3.0, 'N']]
    """
    letters = list(letters)
    n = len(letters)
    if n == 0:
        return []
    if len(taus) != n:
        raise InputError("`taus` must have one entry per step in `letters`")
    # runs over the cycle: [start index, length, letter]
    runs = []
    for i, s in enumerate(letters):
        if runs and runs[-1][2] == s:
            runs[-1][1] += 1
        else:
            runs.append([i, 1, s])
    if len(runs) > 1 and runs[0][2] == runs[-1][2]:
        # the last run continues into the first one across the period boundary
        runs[0] = [runs[-1][0] - n, runs[-1][1] + runs[0][1], runs[0][2]]
        runs.pop()
    taus = list(taus)
    starts = [float(taus[r[0]]) if r[0] >= 0 else float(taus[r[0] + n]) - period for r in runs]
    m = len(runs)
    keep = []
    for j, (i0, length, s) in enumerate(runs):
        prev, nxt = runs[j - 1][2], runs[(j + 1) % m][2]
        if m >= 3 and s == "S" and length == 1 and {prev, nxt} == {"N", "P"}:
            keep.append(None)          # slip reversal inside one step
        else:
            keep.append(j)
    out = []
    pending_shift = None
    for j in range(m):
        if keep[j] is None:
            pending_shift = starts[j] + 0.5 * h
            continue
        t = starts[j] if pending_shift is None else pending_shift
        pending_shift = None
        out.append([t, runs[j][2]])
    if pending_shift is not None and out:
        out[0][0] = pending_shift
    # back to [0, 2 pi) in time order, the regime at tau = 0 first, repeats merged
    seq = sorted(([t % period if t < 0 or t >= period else t, s] for t, s in out),
                 key=lambda x: x[0])
    if seq and seq[0][0] > 0.0:
        seq.insert(0, [0.0, seq[-1][1]])
    merged = []
    for t, s in seq:
        if not merged or merged[-1][1] != s:
            merged.append([float(t), s])
    return merged


def _mode_of(merged):
    letters = [s for _, s in merged]
    return mode_name(letters, impacts_after_flight(letters))


class PeriodMap:
    """One drive period of Moreau–Jean steps of a periodic scene, as a map of its state.

    Works through the :class:`~moreau.model.scene.Scene` interface for any
    scene with a periodic drive (``scene.period``): the coordinates listed in
    ``scene.cyclic_coordinates`` (e.g. the rotor position) do not enter the
    dynamics, so the map acts on ``x = (q without them, v)`` and reports the
    advance of the first cyclic coordinate. For the friction drive
    ``x = (phi, phi', u2')``. The steps run in the integrator's compiled loop
    when the scene has a compiled model (``fast="auto"``).

    Parameters
    ----------
    scene : Scene
        With ``scene.period`` set and at least one cyclic coordinate.
    steps_per_period : int
    theta : float
    projection : bool
    fast : bool or "auto"
    lcp_method : {"auto", "lemke", "qp"}
        Passed to :class:`~moreau.integrators.moreau_jean.MoreauJean`.
    painleve : {"impulse", "stop"}
        Passed to :class:`~moreau.integrators.moreau_jean.MoreauJean`.

    Raises
    ------
    InputError
        A scene without a period or without a cyclic coordinate, bad options.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> pm = PeriodMap(FrictionDrive(frequency=185.0), 200)
    >>> x1, du2, closed = pm(np.array([np.pi / 4, 0.0, 0.0]), True)
    >>> x1.shape, closed.tolist()
    ((3,), [True])
    """

    def __init__(self, scene, steps_per_period, theta=1.0, projection=True, fast="auto",
                 lcp_method="auto", painleve="impulse"):
        self.painleve = check_painleve(painleve)
        period = getattr(scene, "period", None)
        if period is None:
            raise InputError(f"`scene` ({type(scene).__name__}) has no periodic drive "
                             f"(`scene.period` is None): a period map needs one")
        cyc = tuple(int(i) for i in getattr(scene, "cyclic_coordinates", ()))
        if not cyc:
            raise InputError(f"`scene` ({type(scene).__name__}) declares no cyclic coordinate "
                             f"(`scene.cyclic_coordinates`), so a periodic state cannot advance")
        self.scene = scene
        self.period = float(period)
        self.n = positive_int("steps_per_period", steps_per_period)
        if self.n > MAX_STEPS_PER_PERIOD:
            raise InputError(f"`steps_per_period` = {self.n:.3g} is more than the limit "
                             f"{MAX_STEPS_PER_PERIOD:.0e}: the shooting runs some 300 periods, "
                             f"{300 * self.n:.2g} steps, hours at 1e7 steps/s")
        self.theta = in_closed_interval("theta", theta, 0.5, 1.0)
        if not isinstance(projection, (bool, np.bool_)):
            raise InputError(f"`projection` must be True or False, got {projection!r}")
        self.projection = bool(projection)
        if fast not in ("auto", True, False):
            raise InputError(f"`fast` must be 'auto', True or False, got {fast!r}")
        self.fast = fast
        if lcp_method not in LCP_METHODS:
            raise InputError(f"`lcp_method` must be one of {list(LCP_METHODS)}, got {lcp_method!r}")
        self.lcp_method = lcp_method
        self.cyclic = cyc
        nq = scene.ndof
        self.kept = np.array([i for i in range(nq) if i not in cyc], dtype=int)
        self.dim = len(self.kept) + nq
        #: index in ``x`` of the velocity of the first cyclic coordinate
        self.cyclic_velocity = len(self.kept) + cyc[0]
        self.h = self.period / self.n
        self.evaluations = 0
        self.steps = 0
        self.lcp_solves = 0
        self.fallbacks = 0
        self.last = None
        #: the map whose finite differences stand for this one's derivative (itself; a
        #: forced-QP map's is its Lemke twin, see :func:`moreau_jean_steady_state`)
        self.derivative_map = self

    def state(self, q, v):
        """``x`` of a full state ``(q, v)``."""
        return np.concatenate([np.asarray(q, float)[self.kept], np.asarray(v, float)])

    def full_state(self, x):
        """``(q, v)`` of ``x``, the cyclic coordinates at 0."""
        q = np.zeros(self.scene.ndof)
        q[self.kept] = x[:len(self.kept)]
        return q, np.array(x[len(self.kept):], dtype=float)

    def _slip(self, q, v, slip):
        # a frictionless contact has no tangential row, so the scheme records
        # no slip velocity; the mode name still needs its sign
        sc = self.scene
        if float(sc.mu[0]) > 0.0 or not hasattr(sc, "slip_velocity"):
            return np.array(slip, dtype=float)
        return np.array([sc.slip_velocity(qi, vi) for qi, vi in zip(q, v)])

    def __call__(self, x, closed, record=False):
        """Map ``x`` at the section ``t = 0`` over one period.

        ``closed`` (a bool or one per contact) is the index-set memory at the
        section. Returns ``(x_end, displacement, closed_end)``; with
        ``record=True`` the per-step history of contact 0 is kept in
        :attr:`last` (a dict).
        """
        q, v = self.full_state(x)
        nc = self.scene.ncontacts
        c0 = np.broadcast_to(np.asarray(closed, dtype=bool), (nc,)).copy()
        integ = MoreauJean(self.scene, 0.0, q, v, self.period, h=self.h, theta=self.theta,
                           projection=self.projection, fast=self.fast, closed0=c0,
                           lcp_method=self.lcp_method, painleve=self.painleve,
                           save_every=1 if record else self.n)
        while integ.status == "running":
            integ.step()
        if integ.status != "finished":
            if integ.status_code == -1:
                raise PainleveError(f"period map: {integ.message}")
            raise MoreauError(f"period map failed: {integ.message}; increase `steps_per_period`")
        c = integ.counters
        self.steps += c["steps"]
        self.lcp_solves += c["lcp_solves"]
        self.fallbacks += c["fallbacks"]
        if record:
            res = integ.result()
            self.last = {"tau": res.t[1:] - self.h, "regime": res.regime[1:, 0].copy(),
                         "force_N": res.force_N[1:, 0].copy(),
                         "slip": self._slip(res.q[1:], res.v[1:], res.slip_velocity[1:, 0]),
                         "regime_all": res.regime[1:].copy(),
                         "slip_all": res.slip_velocity[1:].copy(),
                         "force_all": res.force_N[1:].copy(),
                         "max_penetration": c["max_penetration"],
                         "lcp_solves": c["lcp_solves"], "fallbacks": c["fallbacks"]}
        self.evaluations += 1
        k = self.cyclic[0]
        return self.state(integ.q, integ.v), float(integ.q[k] - q[k]), integ.closed


class _Stalled(ConvergenceError):
    """Shooting found no usable derivative: worth a transient run before giving up."""


#: bound on the steps per period of a discrete steady state (300 periods of shooting at
#: 1e6 steps each take about 30 s at 1e7 steps/s; 1e7 about five minutes)
MAX_STEPS_PER_PERIOD = 10**7


def moreau_jean_steady_state(scene, steps_per_period, theta=1.0, tol=1e-12, max_iter=50,
                             projection=True, x_guess=None, fast="auto", transient_periods=300,
                             lcp_method="auto", painleve="impulse"):
    """Periodic steady state of the Moreau–Jean map of a periodic scene, by shooting.

    Parameters
    ----------
    scene : Scene
        A scene with a periodic drive (``scene.period``) and a cyclic
        coordinate, e.g. :class:`~moreau.scenes.friction_drive.FrictionDrive`;
        see :class:`PeriodMap` for the state ``x``.
    steps_per_period : int
        Moreau–Jean steps per drive period, ``h = period / steps_per_period``.
    theta : float
        Scheme parameter in ``[1/2, 1]``.
    tol : float
        Bound on the periodic residual ``max_i |Phi(x)_i - x_i| / s_i`` with
        scale 1 for coordinates and ``scene.velocity_scale`` (default 1; the
        stator velocity amplitude ``u10`` for the drives) for velocities.
    max_iter : int
        Newton iterations.
    projection : bool
        Position projection after each step (see the module docstring for
        why the default is True).
    x_guess : array_like, optional
        Initial ``x`` at ``t = 0``; by default the scene's ``initial_state()``.
    fast : {"auto", True, False}
        Use the compiled loop (every scene with a compiled model).
    painleve : {"impulse", "stop"}
        Moreau–Jean's option: take a tangential impact, or stop there (a
        study of Painlevé configurations, the stress catalogue's).
    lcp_method : {"auto", "lemke", "qp"}
        The contact solver of every step (Moreau–Jean's option); ``"qp"``
        takes the generic Python step. The fixed point is that of this
        map, but with ``"qp"`` the finite differences (Newton's matrix, the
        reported slopes and multipliers) are those of the same map with
        Lemke's solve, compiled where the scene has a model: the two solve
        the same contact problems, Lemke exactly and in a fraction of the
        time, and a difference quotient of step 1e-7 would read the QP
        solver's tolerance as slope. Newton with that matrix still converges
        to the QP map's own fixed point, because its residual is the QP map's.
    transient_periods : int
        When shooting stalls (e.g. the rod in flight at the section, where the
        discrete map has no usable derivative), up to this many periods are
        simulated from the last iterate, and shooting is tried again from
        where they end. If the run settles on a period-1 orbit it is returned;
        if it does not, the result says so (``stats["periodic"] = False``,
        ``mode`` ``"no period-1 orbit"``) and reports the long-run average
        displacement per period instead (``min_normal_force`` is then that of
        the last period simulated).

    Returns
    -------
    SteadyState
        ``scheme="moreau-jean"``; ``stats`` holds ``periodic`` (True for a
        fixed point), ``steps`` and ``lcp_solves`` (over all ``period_maps``
        evaluated, including the recorded period and the Jacobians at the fixed
        point), ``fallbacks``, ``max_penetration`` (over the steady period),
        ``period_map_slope`` (largest ``|eigenvalue|`` of the period-map
        Jacobian at the fixed point, from central differences over 20 steps'
        worth of motion, i.e. the slope on the scale of the continuous
        system), ``period_map_eigenvalues``, ``period_map_local_slope`` (the
        same from a 1e-7 perturbation: the derivative of the piecewise-linear
        discrete map), ``transient_periods`` (periods simulated before the
        final shooting), ``steps_per_period``, ``theta``, ``projection`` and
        ``period_maps``. ``floquet_multipliers``: those of the discrete map
        in the free directions (:func:`_floquet`). Without a period-1 orbit: ``periodic = False``,
        ``message``, ``average_over_periods``, ``orbit_period`` (the smallest
        ``p <= 8`` with ``Phi^p(x) = x`` to ``sqrt(tol)``, or None).

    Raises
    ------
    InputError
        Bad arguments, a scene without a period.
    ConvergenceError
        No fixed point within ``max_iter`` Newton iterations, or (without
        projection) a map that has none.
    PainleveError
        The contact problem became ill-posed along the way.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> ss = moreau_jean_steady_state(FrictionDrive(frequency=20.0), 1000)
    >>> ss.mode, ss.periodic_residual < 1e-12
    ('NS', True)
    """
    t_start = time.perf_counter()
    tol = positive("tol", tol)
    max_iter = positive_int("max_iter", max_iter)
    transient_periods = positive_int("transient_periods", transient_periods)
    pm = PeriodMap(scene, steps_per_period, theta, projection, fast, lcp_method, painleve)
    if lcp_method == "qp":
        pm.derivative_map = PeriodMap(scene, steps_per_period, theta, projection, fast, "auto",
                                      painleve)
    vs = float(getattr(scene, "velocity_scale", 1.0))
    nk = len(pm.kept)
    scale = np.concatenate([np.ones(nk), np.full(scene.ndof, vs)])
    if x_guess is None:
        x = pm.state(*scene.initial_state())
    else:
        x = finite_array("x_guess", x_guess, shape=(pm.dim,)).copy()
    closed = np.asarray(scene.gaps(*pm.full_state(x)[:1], 0.0), dtype=float) <= 0.0

    it = 0
    transient = 0
    try:
        x, r, y1, closed, it = _settle(pm, x, closed, scale, tol, max_iter)
    except _Stalled:
        if not projection:
            raise
        # march the motion forward and shoot again from where it settles
        x, closed, transient, r = _march(pm, x, closed, scale, tol, transient_periods)
        if r > tol:
            try:
                x, r, y1, closed, it = _settle(pm, x, closed, scale, tol, max_iter)
            except _Stalled:
                return _no_orbit(pm, x, closed, scale, tol, transient, t_start)

    # the steady period, recorded, and the period-map Jacobian at the fixed point
    y1, disp, _ = pm(x, closed, record=True)
    r = float(np.max(np.abs(y1 - x) / scale))
    last = pm.last
    # perturbations on the scale of the motion (the velocity scale), not of a radian
    fd_scale = np.full(pm.dim, vs)
    dm = pm.derivative_map
    J_sec = _jacobian(dm, x, closed, fd_scale, 20.0 * pm.h, central=True)
    J_loc = _jacobian(dm, x, closed, fd_scale, 1e-7, y1=y1 if dm is pm else dm(x, closed)[0])
    eig = np.linalg.eigvals(J_sec)
    eig_loc = np.linalg.eigvals(J_loc)
    multipliers = _floquet(dm, x, closed, 2.0 * math.sqrt(pm.h) * vs)
    mode, merged, fmin = _modes_of_run(scene, pm, last)
    return SteadyState(
        scheme="moreau-jean",
        displacement_per_period=float(disp),
        state0=x.copy(),
        mode=mode,
        regimes=merged,
        min_normal_force=fmin,
        periodic_residual=r,
        iterations=it,
        wall_time=time.perf_counter() - t_start,
        stats={
            "periodic": True,
            "steps": int(pm.steps),
            "lcp_solves": int(pm.lcp_solves),
            "fallbacks": int(pm.fallbacks),
            "max_penetration": float(last["max_penetration"]),
            "period_map_slope": float(np.max(np.abs(eig))),
            "period_map_eigenvalues": _plain(eig),
            "period_map_local_slope": float(np.max(np.abs(eig_loc))),
            "transient_periods": transient,
            "steps_per_period": pm.n,
            "theta": pm.theta,
            "projection": pm.projection,
            "period_maps": pm.evaluations,
            # period maps run for finite differences by the forced-QP map's Lemke twin
            "derivative_period_maps": (pm.derivative_map.evaluations
                                       if pm.derivative_map is not pm else 0),
            # the index-set memory at the section: with state0 it reproduces the steady period
            "closed_at_section": [bool(c) for c in np.atleast_1d(closed)],
        },
        floquet_multipliers=multipliers,
        floquet_method="finite-differences",
    )


def _floquet(pm, x, closed, step):
    """Multipliers of the discrete period map in its free directions (central differences).

    The directions are those of the continuous system at the section
    (:func:`moreau.analysis.periodic_shooting.free_bases`, the closed
    contacts pinning their gaps and normal velocities): a perturbation that
    opens a closed contact is projected back by the scheme within a step and
    would only add spurious zero multipliers. The discrete map is piecewise
    smooth on the scale of one step (an event falls into one step or the
    next, :func:`_shoot`), so its local derivative is not the continuous
    system's; a perturbation ``2 sqrt(h)`` of the velocity scale spans
    ``~sqrt(N)`` steps' worth of event shift, whose quantisation then falls
    as the step shrinks while the curvature error stays ``O(h)``. Measured
    on the paper's drive (theta = 1) against the walker's saltation
    multiplier: at 2000 Hz errors 1.8e-4, 4.6e-5, 5.5e-6, 5.8e-6 at
    N = 1000, 4000, 16000, 64000; at 185 Hz 6.0e-4, 8.5e-5, 3.4e-4, 1.5e-4
    (not monotone: the quantisation).
    """
    q, _ = pm.full_state(x)
    touching = np.flatnonzero(np.atleast_1d(closed))
    Bq, Bv = free_bases(pm.scene, q, 0.0, pm.cyclic[0], touching)
    B = np.zeros((pm.dim, Bq.shape[1] + Bv.shape[1]))
    B[:len(pm.kept), :Bq.shape[1]] = Bq[pm.kept]
    B[len(pm.kept):, Bq.shape[1]:] = Bv
    if not B.shape[1]:
        return sorted_multipliers([])
    J = period_map_jacobian(lambda z: B.T @ pm(x + B @ z, closed)[0], np.zeros(B.shape[1]), step)
    return sorted_multipliers(np.linalg.eigvals(J))


def _settle(pm, x, closed, scale, tol, max_iter):
    """Shoot with the contact flags held, until they come back unchanged after a period."""
    it = 0
    for _ in range(4):
        x, r, y1, closed_end, n_it = _shoot(pm, x, closed, scale, tol, max_iter - it)
        it += n_it
        if np.array_equal(closed_end, closed):
            return x, r, y1, closed, it
        closed = closed_end
    raise _Stalled("the contact state at the section does not settle on a periodic value")


def _march(pm, x, closed, scale, tol, nmax):
    """Iterate the period map (simulate) up to ``nmax`` periods or until ``x`` repeats."""
    r = math.inf
    for k in range(1, nmax + 1):
        y, _, c = pm(x, closed)
        r = float(np.max(np.abs(y - x) / scale))
        same = np.array_equal(c, closed)
        x, closed = y, c
        if r <= tol and same:
            return x, closed, k, r
    return x, closed, nmax, r


def _no_orbit(pm, x, closed, scale, tol, transient, t_start):
    """No period-1 orbit: the long-run average displacement, and the orbit's period if short."""
    navg = max(50, min(500, transient))
    xs = [x]
    total = 0.0
    for i in range(navg):
        x, d, closed = pm(x, closed, record=i == navg - 1)
        xs.append(x)
        total += d
    avg = total / navg
    loose = math.sqrt(tol)
    orbit = None
    for p in range(2, 9):
        if float(np.max(np.abs(xs[-1] - xs[-1 - p]) / scale)) <= loose:
            orbit = p
            break
    what = (f"a period-{orbit} orbit" if orbit else "no periodic orbit of period <= 8 (the motion "
            "may be quasi-periodic or chaotic at this step size)")
    msg = (f"the Moreau–Jean map has no period-1 orbit here: after {transient + navg} periods "
           f"the motion settles on {what}; displacement_per_period is the long-run average "
           f"over the last {navg} periods")
    r = float(np.max(np.abs(xs[-1] - xs[-2]) / scale))
    return SteadyState(
        scheme="moreau-jean", displacement_per_period=float(avg), state0=xs[-1].copy(),
        mode="no period-1 orbit", regimes=[], min_normal_force=float(np.min(pm.last["force_N"])),
        periodic_residual=r, iterations=0, wall_time=time.perf_counter() - t_start,
        stats={"periodic": False, "message": msg, "average_over_periods": navg,
               "orbit_period": orbit, "transient_periods": transient,
               "steps": int(pm.steps), "lcp_solves": int(pm.lcp_solves),
               "fallbacks": int(pm.fallbacks), "steps_per_period": pm.n, "theta": pm.theta,
               "projection": pm.projection, "period_maps": pm.evaluations})


def _modes_of_run(scene, pm, last):
    """Mode name, regimes over the period and min normal force of a recorded period.

    One contact: the canonical mode (``"NP"``) and its merged regimes. Several:
    each contact's mode joined by ``"|"`` (``"NSP|NP"``, as the event-driven
    shooting names them), and regimes keyed by one letter per contact.
    """
    nc = last["regime_all"].shape[1]
    if nc == 1:
        letters = step_letters(last["regime"], last["slip"], float(scene.mu[0]))
        merged = merge_step_regimes(letters, last["tau"], pm.h, period=pm.period)
        return _mode_of(merged), merged, float(np.min(last["force_N"]))
    per = [step_letters(last["regime_all"][:, c], last["slip_all"][:, c], float(scene.mu[c]))
           for c in range(nc)]
    mode = "|".join(_mode_of(merge_step_regimes(p, last["tau"], pm.h, period=pm.period))
                    for p in per)
    merged = []
    for k, tau in enumerate(last["tau"]):
        key = "".join(p[k] for p in per)
        if not merged or merged[-1][1] != key:
            merged.append([float(tau % pm.period), key])
    return mode, merged, float(np.min(last["force_all"]))


def _plain(eig):
    # JSON-friendly: real numbers stay real
    return [float(z.real) if abs(z.imag) <= 1e-12 * max(1.0, abs(z)) else [float(z.real), float(z.imag)]
            for z in eig]


def _shoot(pm, x, closed, scale, tol, max_iter):
    """Fixed point of the period map with the contact flag ``closed`` held at ``tau = 0``.

    Newton on ``Phi(x) - x`` with a forward-difference Jacobian and a
    backtracking line search. The discrete map is piecewise linear on the
    scale of one step in ``u2'`` (a slip reversal falls into one step or the
    next): its local slope in ``u2'`` alternates between about 0 and exactly
    1, and where it is 1 the Newton matrix is singular. When a Newton step
    fails that way, and ``(phi, phi')`` are already periodic (the contact
    pins them, as with projection), the solve continues in ``u2'`` alone by
    bracketing and Illinois regula falsi, which needs only the monotonicity
    of ``Phi - x`` in ``u2'`` (friction makes ``u2' -> Phi`` non-expansive).

    Returns ``(x, residual, Phi(x), closed_end, iterations)``.
    """
    y1, _, c1 = pm(x, closed)
    F = y1 - x
    r = float(np.max(np.abs(F) / scale))
    j = pm.cyclic_velocity
    others = np.arange(len(x)) != j
    fd_scale = np.full(len(x), scale[j])
    it = 0
    while r > tol:
        it += 1
        if it > max_iter:
            raise ConvergenceError(
                f"Moreau–Jean shooting did not converge in `max_iter` Newton iterations "
                f"(periodic residual {r:.3g} > `tol`={tol:g})")
        dm = pm.derivative_map
        J = _jacobian(dm, x, closed, fd_scale, 1e-7, y1=y1 if dm is pm else dm(x, closed)[0])
        A = J - np.eye(len(x))
        pinned = float(np.max(np.abs(F[others]) / scale[others])) <= tol
        stalled = abs(A[j, j]) < 1e-6
        if not stalled:
            dx = np.linalg.lstsq(A, -F, rcond=None)[0]
            lam = 1.0
            for _ls in range(10):
                xn = x + lam * dx
                yn, _, cn = pm(xn, closed)
                Fn = yn - xn
                rn = float(np.max(np.abs(Fn) / scale))
                if rn < r:
                    break
                lam *= 0.5
            else:
                stalled = True
            if not stalled:
                x, y1, F, r, c1 = xn, yn, Fn, rn, cn
                continue
        if not pinned:
            raise _Stalled(
                f"Moreau–Jean shooting stalled at periodic residual {r:.3g}: the period map "
                f"has no usable derivative here and (phi, phi') are not periodic yet; "
                f"try projection=True or another `x_guess`")
        xb = y1.copy()
        xb[j] = x[j]
        x, r, y1, c1, n = _bracket_u(pm, xb, closed, scale, tol, max_iter - it)
        it += n
        break
    return x, r, y1, c1, it


def _bracket_u(pm, x, closed, scale, tol, max_iter):
    """Solve ``Phi_j(x) = x_j`` in the cyclic velocity ``x_j`` with the rest held (see :func:`_shoot`)."""
    j = pm.cyclic_velocity

    def ev(u):
        xx = x.copy()
        xx[j] = u
        y, _, c = pm(xx, closed)
        return y[j] - u, xx, y, c

    it = 0
    ua = x[j]
    Fa, xa, ya, ca = ev(ua)

    def done(F, xx, y):
        return float(np.max(np.abs(y - xx) / scale)) <= tol

    if done(Fa, xa, ya):
        return xa, float(np.max(np.abs(ya - xa) / scale)), ya, ca, it
    # expand in the direction of Phi - u until the sign changes: the root lies at
    # least |F| away since the slope of Phi in u is in [0, 1]
    step = Fa
    while True:
        it += 1
        if it > max_iter:
            raise ConvergenceError(
                "Moreau–Jean shooting did not converge in `max_iter` iterations: no sign "
                "change of Phi(u2') - u2' found yet")
        ub = ua + step
        Fb, xb, yb, cb = ev(ub)
        if done(Fb, xb, yb):
            return xb, float(np.max(np.abs(yb - xb) / scale)), yb, cb, it
        if np.sign(Fb) != np.sign(Fa):
            break
        ua, Fa, xa, ya, ca = ub, Fb, xb, yb, cb
        step *= 2.0
    # Illinois regula falsi on [ua, ub]
    side = 0
    while True:
        it += 1
        if it > max_iter:
            raise ConvergenceError(
                f"Moreau–Jean shooting did not converge in `max_iter` iterations "
                f"(bracket [{ua:.17g}, {ub:.17g}])")
        uc = false_position(ua, ub, Fa, Fb)
        Fc, xc, yc, cc = ev(uc)
        if done(Fc, xc, yc) or uc in (ua, ub):
            return xc, float(np.max(np.abs(yc - xc) / scale)), yc, cc, it
        ua, Fa, ub, Fb, side = illinois_update(ua, Fa, ub, Fb, uc, Fc, side,
                                               np.sign(Fc) == np.sign(Fb))


def _jacobian(pm, x, closed, scale, rel, y1=None, central=False):
    """Finite-difference Jacobian of the period map at ``x``, steps ``rel * scale_i``.

    Small ``rel`` gives the local derivative of the (piecewise linear)
    discrete map; ``rel`` of many steps ``h`` gives its slope on the scale of
    the continuous system, which is what governs the transient.
    """
    J = np.empty((len(x), len(x)))
    for i in range(len(x)):
        d = rel * max(abs(x[i]) if rel < 1e-3 else 0.0, scale[i])
        xp = x.copy()
        xp[i] += d
        yp, _, _ = pm(xp, closed)
        if central:
            xm = x.copy()
            xm[i] -= d
            ym, _, _ = pm(xm, closed)
            J[:, i] = (yp - ym) / (2.0 * d)
        else:
            J[:, i] = (yp - y1) / d
    return J


@register_steady_solver("moreau-jean")
def _steady_solver(scene, rtol=None, v_guess=None, max_iter=None, guess=None, **options):
    # find_steady_state's entry: the discrete map takes its own tolerance (`tol`),
    # iteration bound and guess (`x_guess`) in `options`; a neighbour's orbit
    # (continuation) is a guess close enough to skip the cold start's transient
    if guess is not None and options.get("x_guess") is None:
        options["x_guess"] = np.asarray(guess.state0, float)
        options.setdefault("transient_periods", CONTINUED_TRANSIENT)
    return moreau_jean_steady_state(scene, **options)


#: periods of the map run from a neighbour's orbit before Newton (a cold start runs 300)
CONTINUED_TRANSIENT = 5
