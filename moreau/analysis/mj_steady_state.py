"""Periodic steady state of the *discrete* Moreau–Jean map of the friction drive.

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
its slip velocity, never stick (:func:`moreau.analysis.modes.step_letters`),
and a regime entered from flight is marked as entered through an impact, as
the event-driven reference marks it. The cyclic sequence is then named by
:func:`moreau.analysis.modes.mode_name`.
"""

import math
import time

import numpy as np

from .._validate import in_closed_interval, positive, positive_int
from ..errors import ConvergenceError, InputError, MoreauError
from .modes import impacts_after_flight, mode_name, step_letters
from .steady_state import SteadyState

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
    """One drive period of Moreau–Jean steps of the friction drive, as a map of ``(phi, phi', u2')``.

    Uses the compiled loop for a :class:`~moreau.scenes.friction_drive.FrictionDrive`
    and the generic :class:`~moreau.integrators.moreau_jean.MoreauJean` otherwise
    (or with ``fast=False``).

    Parameters
    ----------
    scene : FrictionDrive
    steps_per_period : int
    theta : float
    projection : bool
    fast : bool or "auto"

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> pm = PeriodMap(FrictionDrive(frequency=185.0), 200)
    >>> x1, du2, closed = pm(np.array([np.pi / 4, 0.0, 0.0]), True)
    >>> x1.shape, closed
    ((3,), True)
    """

    def __init__(self, scene, steps_per_period, theta=1.0, projection=True, fast="auto"):
        from ..integrators.moreau_jean import is_friction_drive

        self.scene = scene
        self.n = positive_int("steps_per_period", steps_per_period)
        self.theta = in_closed_interval("theta", theta, 0.5, 1.0)
        if not isinstance(projection, (bool, np.bool_)):
            raise InputError(f"`projection` must be True or False, got {projection!r}")
        self.projection = bool(projection)
        if fast not in ("auto", True, False):
            raise InputError(f"`fast` must be 'auto', True or False, got {fast!r}")
        known = is_friction_drive(scene)
        if fast is True and not known:
            raise InputError("`fast=True` needs a FrictionDrive scene")
        self.fast = known and fast is not False
        self.h = TWO_PI / self.n
        self.evaluations = 0
        self.steps = 0
        self.lcp_solves = 0
        self.fallbacks = 0
        n = self.n
        if self.fast:
            from ..integrators._mj_kernels import new_stats
            from ..scenes._friction_drive_jit import pack_params
            self._par = pack_params(scene)
            self._buf = (np.empty(n + 1), np.empty((n + 1, 2)), np.empty((n + 1, 2)),
                         np.empty(n + 1, dtype=np.int64), np.empty(n + 1), np.empty(n + 1),
                         np.empty(n + 1), np.empty(n + 1))
            self._stats = new_stats()
        self.last = None

    def _slip(self, q, v, slip):
        # a frictionless contact has no tangential row, so the scheme records
        # no slip velocity; the mode name still needs its sign
        if float(self.scene.mu[0]) > 0.0:
            return np.array(slip, dtype=float)
        return np.array([self.scene.slip_velocity(qi, vi) for qi, vi in zip(q, v)])

    def __call__(self, x, closed, record=False):
        """Map ``x = (phi, phi', u2')`` at ``tau = 0`` over one period.

        Returns ``(x_end, displacement, closed_end)``; with ``record=True``
        the per-step history is kept in :attr:`last` (a dict).
        """
        q = np.array([x[0], 0.0])
        v = np.array([x[1], x[2]])
        if self.fast:
            from ..integrators._mj_kernels import OK, PAINLEVE, mj_run_fd
            st = self._stats
            st[:] = 0.0
            status, k, nrec, closed_end = mj_run_fd(
                self._par, 0.0, self.h, TWO_PI, 0, self.n, q, v, self.theta, self.projection,
                bool(closed), 1, False, *self._buf, st)
            self.steps += k
            self.lcp_solves += int(st[0])
            if status != OK:
                from ..errors import PainleveError
                if status == PAINLEVE:
                    raise PainleveError(
                        "discrete Painlevé condition W_NN - mu |W_NT| > 0 violated during the "
                        "period map: the contact problem has no unique solution")
                raise MoreauError("non-finite state in the period map; increase `steps_per_period`")
            if record:
                t, rq, rv, reg, fN, _, slip, _ = self._buf
                self.last = {"tau": t[:nrec] - self.h, "regime": reg[:nrec].copy(),
                             "force_N": fN[:nrec].copy(),
                             "slip": self._slip(rq[:nrec], rv[:nrec], slip[:nrec]), "max_penetration": float(st[5]),
                             "lcp_solves": int(st[0]), "fallbacks": 0}
        else:
            from ..integrators.moreau_jean import MoreauJean
            integ = MoreauJean(self.scene, 0.0, q, v, TWO_PI, h=self.h, theta=self.theta,
                               projection=self.projection, fast=False)
            integ._closed[:] = bool(closed)
            while integ.status == "running":
                integ.step()
            if integ.status != "finished":
                if integ.status_code == -1:
                    from ..errors import PainleveError
                    raise PainleveError(integ.message)
                raise MoreauError(f"period map failed: {integ.message}")
            q, v, closed_end = integ.q, integ.v, bool(integ._closed[0])
            c = integ.counters
            self.steps += c["steps"]
            self.lcp_solves += c["lcp_solves"]
            self.fallbacks += c["fallbacks"]
            if record:
                res = integ.result()
                self.last = {"tau": res.t[1:] - self.h, "regime": res.regime[1:, 0].copy(),
                             "force_N": res.force_N[1:, 0].copy(),
                             "slip": self._slip(res.q[1:], res.v[1:], res.slip_velocity[1:, 0]),
                             "max_penetration": c["max_penetration"],
                             "lcp_solves": c["lcp_solves"], "fallbacks": c["fallbacks"]}
        self.evaluations += 1
        return np.array([q[0], v[0], v[1]]), float(q[1]), bool(closed_end)


def moreau_jean_steady_state(scene, steps_per_period, theta=1.0, tol=1e-12, max_iter=50,
                             projection=True, x_guess=None, fast="auto"):
    """Periodic steady state of the Moreau–Jean map of the friction drive, by shooting.

    Parameters
    ----------
    scene : FrictionDrive
    steps_per_period : int
        Moreau–Jean steps per drive period, ``h = 2 pi / steps_per_period``.
    theta : float
        Scheme parameter in ``[1/2, 1]``.
    tol : float
        Bound on the periodic residual ``max_i |Phi(x)_i - x_i| / s_i`` with
        scales ``s = (1, u10, u10)`` (radian, and the stator velocity
        amplitude for the two rates).
    max_iter : int
        Newton iterations.
    projection : bool
        Position projection after each step (see the module docstring for
        why the default is True).
    x_guess : array_like, shape (3,), optional
        Initial ``(phi, phi', u2')`` at ``tau = 0``; the rod at rest on the
        rotor and the rotor at rest by default.
    fast : {"auto", True, False}
        Use the compiled loop (friction drive only).

    Returns
    -------
    SteadyState
        ``scheme="moreau-jean"``; ``stats`` holds ``steps`` and
        ``lcp_solves`` (over all ``period_maps`` evaluated, including the
        recorded period and the Jacobians at the fixed point), ``fallbacks``,
        ``max_penetration`` (over the steady period), ``period_map_slope``
        (largest ``|eigenvalue|`` of the period-map Jacobian at the fixed
        point, from central differences over 20 steps' worth of motion, i.e.
        the slope on the scale of the continuous system),
        ``period_map_eigenvalues``, ``period_map_local_slope`` (the same from
        a 1e-7 perturbation: the derivative of the piecewise-linear discrete
        map, 0 or 1 in ``u2'`` at most points), ``steps_per_period``,
        ``theta``, ``projection`` and ``period_maps``.

    Raises
    ------
    InputError
        Bad arguments.
    ConvergenceError
        No fixed point within ``max_iter`` Newton iterations.
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
    pm = PeriodMap(scene, steps_per_period, theta, projection, fast)
    scale = np.array([1.0, scene.u10, scene.u10])
    if x_guess is None:
        x = np.array([scene.phi0, 0.0, 0.0])
    else:
        from .._validate import finite_array
        x = finite_array("x_guess", x_guess, shape=(3,)).copy()
    closed = float(scene.gaps(np.array([x[0], 0.0]), 0.0)[0]) <= 0.0

    it = 0
    for _ in range(4):        # the contact flag must come back unchanged after one period
        x, r, y1, closed_end, n_it = _shoot(pm, x, closed, scale, tol, max_iter - it)
        it += n_it
        if closed_end == closed:
            break
        closed = closed_end
    else:
        raise ConvergenceError("the contact state at tau = 0 does not settle on a periodic value")

    # the steady period, recorded, and the period-map Jacobian at the fixed point
    _, disp, _ = pm(x, closed, record=True)
    last = pm.last
    # perturbations on the scale of the motion (the stator amplitude), not of a radian
    fd_scale = np.full(3, scene.u10)
    J_sec = _jacobian(pm, x, closed, fd_scale, 20.0 * pm.h, central=True)
    J_loc = _jacobian(pm, x, closed, fd_scale, 1e-7, y1=y1)
    eig = np.linalg.eigvals(J_sec)
    eig_loc = np.linalg.eigvals(J_loc)
    letters = step_letters(last["regime"], last["slip"], float(scene.mu[0]))
    merged = merge_step_regimes(letters, last["tau"], pm.h)
    return SteadyState(
        scheme="moreau-jean",
        displacement_per_period=float(disp),
        state0=x.copy(),
        mode=_mode_of(merged),
        regimes=merged,
        min_normal_force=float(np.min(last["force_N"])),
        periodic_residual=r,
        iterations=it,
        wall_time=time.perf_counter() - t_start,
        stats={
            "steps": int(pm.steps),
            "lcp_solves": int(pm.lcp_solves),
            "fallbacks": int(pm.fallbacks),
            "max_penetration": float(last["max_penetration"]),
            "period_map_slope": float(np.max(np.abs(eig))),
            "period_map_eigenvalues": _plain(eig),
            "period_map_local_slope": float(np.max(np.abs(eig_loc))),
            "steps_per_period": pm.n,
            "theta": pm.theta,
            "projection": pm.projection,
            "period_maps": pm.evaluations,
        },
    )


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
    fd_scale = np.full(3, scale[2])
    it = 0
    while r > tol:
        it += 1
        if it > max_iter:
            raise ConvergenceError(
                f"Moreau–Jean shooting did not converge in `max_iter` Newton iterations "
                f"(periodic residual {r:.3g} > `tol`={tol:g})")
        J = _jacobian(pm, x, closed, fd_scale, 1e-7, y1=y1)
        A = J - np.eye(3)
        pinned = float(np.max(np.abs(F[:2]) / scale[:2])) <= tol
        stalled = abs(A[2, 2]) < 1e-6
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
            raise ConvergenceError(
                f"Moreau–Jean shooting stalled at periodic residual {r:.3g}: the period map "
                f"has no usable derivative here and (phi, phi') are not periodic yet; "
                f"try projection=True or another `x_guess`")
        x, r, y1, c1, n = _bracket_u(pm, np.array([y1[0], y1[1], x[2]]), closed, scale, tol,
                                     max_iter - it)
        it += n
        break
    return x, r, y1, c1, it


def _bracket_u(pm, x, closed, scale, tol, max_iter):
    """Solve ``Phi_3(phi, phi', u) = u`` in ``u`` with ``(phi, phi')`` held (see :func:`_shoot`)."""
    def ev(u):
        xx = np.array([x[0], x[1], u])
        y, _, c = pm(xx, closed)
        return y[2] - u, xx, y, c

    it = 0
    ua = x[2]
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
        uc = (ua * Fb - ub * Fa) / (Fb - Fa)
        if not (min(ua, ub) < uc < max(ua, ub)):
            uc = 0.5 * (ua + ub)
        Fc, xc, yc, cc = ev(uc)
        if done(Fc, xc, yc) or uc in (ua, ub):
            return xc, float(np.max(np.abs(yc - xc) / scale)), yc, cc, it
        if np.sign(Fc) == np.sign(Fb):
            ub, Fb = uc, Fc
            if side == -1:
                Fa *= 0.5
            side = -1
        else:
            ua, Fa = uc, Fc
            if side == 1:
                Fb *= 0.5
            side = 1


def _jacobian(pm, x, closed, scale, rel, y1=None, central=False):
    """Finite-difference Jacobian of the period map at ``x``, steps ``rel * scale_i``.

    Small ``rel`` gives the local derivative of the (piecewise linear)
    discrete map; ``rel`` of many steps ``h`` gives its slope on the scale of
    the continuous system, which is what governs the transient.
    """
    J = np.empty((3, 3))
    for i in range(3):
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
