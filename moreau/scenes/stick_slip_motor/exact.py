"""Exact event-driven reference for the stick–slip motor.

The motor's contact never opens (constant normal force), so only the slider
position ``x`` and velocity ``u = dx/dtau`` evolve, with the slip velocity
``w = u - s'(tau)`` and ``c(tau) = s''(tau) + fL``:

* positive slip (``w > 0``): ``u' = -mu n - fL``, so ``w' = -(c + mu n)``;
* negative slip (``w < 0``): ``u' = +mu n - fL``, so ``w' = mu n - c``;
* stick (``w = 0``): ``u' = s''``, admissible while ``|c| <= mu n``.

Slip motion is explicit (a parabola in ``x``), so the only work is finding
the events. The period is cut at every point where ``c`` crosses ``-mu n``
or ``+mu n`` (and at the drive's breakpoints); inside each piece the sign of
``w'`` in either slip regime and the admissibility of stick are fixed, so
``w`` is monotone there and has at most one zero, which a bracketing root
finder (Brent) locates to a few ulps. After a zero of ``w`` (or at the start
of a piece while sticking) the next regime is read off the sign of ``c``
inside the piece: stick if ``|c| <= mu n``, negative slip if ``c > mu n``,
positive slip if ``c < -mu n``. Tangencies need no special case.

The slider position does not enter the dynamics, so the period map acts on
``u(0)`` alone. It is non-expanding (slope in ``[0, 1)`` once the motion
reverses or sticks), so ``u -> P(u) - u`` is strictly decreasing and its
root, the periodic steady state, is bracketed and found by Brent's method.
"""

import dataclasses
import math
import time as _time

import numpy as np
from scipy.optimize import brentq

from ...errors import ConvergenceError, InputError
from ...modes import mode_name
from ...regimes import Regime
from ...integrators.base import Integrator, SchemeOptions, register_integrator
from ...integrators.result import Event, SteadyState
from .scene import TWO_PI, StickSlipMotor

__all__ = ["StickSlipReference", "stick_slip_steady_state", "stick_slip_period_map"]

_LETTER = {"P": Regime.POSITIVE, "N": Regime.NEGATIVE, "S": Regime.STICK}
_EPS = np.finfo(float).eps


def _check_scene(scene):
    if not isinstance(scene, StickSlipMotor):
        raise InputError(f"`scene` must be a StickSlipMotor, got {type(scene).__name__}")


class _Walker:
    """Piecewise-exact propagation of the slider over a time window."""

    def __init__(self, scene):
        _check_scene(scene)
        self.scene = scene
        self.drive = scene.drive
        self.mun = scene.friction_level
        self.fL = scene.fL
        base = [np.zeros(1)]
        for level in (-self.fL - self.mun, -self.fL + self.mun):
            base.append(self.drive.acceleration_crossings(level))
        base = np.unique(np.concatenate(base))
        self.base = base[(base >= 0.0) & (base < TWO_PI)]

    def _points(self, t0, t1):
        """``t0``, all cut points in ``(t0, t1)``, ``t1`` and the first cut point after ``t1``."""
        k0 = math.floor(t0 / TWO_PI)
        k1 = math.floor(t1 / TWO_PI) + 1
        pts = (self.base[None, :] + TWO_PI * np.arange(k0, k1 + 1)[:, None]).ravel()
        inner = pts[(pts > t0) & (pts < t1)]
        after = pts[pts > t1]
        nxt = after[0] if len(after) else t1 + TWO_PI
        return np.concatenate([[t0], inner, [t1, nxt]])

    def _decide(self, a, b):
        """Regime leaving ``w = 0`` into the open piece ``(a, b)``."""
        c = float(self.drive(0.5 * (a + b))[2]) + self.fL
        if abs(c) <= self.mun:
            return "S"
        return "N" if c > self.mun else "P"

    def friction_force(self, reg, tau):
        """Friction force on the slider (dimensionless) in regime ``reg`` at ``tau``."""
        if reg == "P":
            return -self.mun
        if reg == "N":
            return self.mun
        return float(self.drive(tau)[2]) + self.fL

    def walk(self, t0, x0, u0, t1):
        """Yield ``(tau, x, u, regime, events)`` at every event and cut point up to ``t1``.

        The first item is the initial state; ``events`` lists the
        ``(tau, before, after)`` transitions that happened at ``tau``.
        """
        pts = self._points(t0, t1)
        x, u, cur = float(x0), float(u0), float(t0)
        ds0 = float(self.drive(cur)[1])
        w0 = u - ds0
        # "fresh": the slip velocity left zero inside the current piece with
        # the sign of w' that the regime imposes there, so it cannot come back
        # to zero before the piece ends; no root search is needed.
        if abs(w0) <= 8.0 * _EPS * (1.0 + abs(u)):
            u, reg, fresh = ds0, self._decide(pts[0], pts[1]), True
        else:
            reg, fresh = ("P" if w0 > 0.0 else "N"), False
        yield cur, x, u, reg, []
        for i in range(len(pts) - 2):
            a, b = pts[i], pts[i + 1]
            end_events = []
            while True:
                if reg == "S":
                    c = float(self.drive(0.5 * (a + b))[2]) + self.fL
                    if abs(c) <= self.mun:
                        x += float(self.drive(b)[0]) - float(self.drive(cur)[0])
                        u, cur = float(self.drive(b)[1]), b
                        fresh = False
                        # stick that breaks right at b is reported at b, so
                        # that the node carries the regime that follows it
                        new = self._decide(b, pts[i + 2])
                        if new != "S":
                            end_events.append((b, "S", new))
                            reg, fresh = new, True
                        break
                    new = "N" if c > self.mun else "P"
                    yield cur, x, u, new, [(cur, reg, new)]
                    reg, fresh = new, True
                    continue
                sig = 1.0 if reg == "P" else -1.0
                acc = -sig * self.mun - self.fL
                dt = b - cur
                ub = u + acc * dt
                wb = ub - float(self.drive(b)[1])
                if fresh or sig * wb > 0.0:
                    x += u * dt + 0.5 * acc * dt * dt
                    u, cur, fresh = ub, b, False
                    if sig * wb <= 0.0:      # rounding put w at (or past) zero at b
                        tstar = b
                    else:
                        break
                else:
                    u_cur, t_cur = u, cur

                    def w(tau):
                        return u_cur + acc * (tau - t_cur) - float(self.drive(tau)[1])

                    if sig * w(cur) <= 0.0:
                        tstar = cur
                    elif wb == 0.0:
                        tstar = b
                    else:
                        tstar = brentq(w, cur, b, xtol=1e-300, rtol=4.0 * _EPS, maxiter=200)
                    dt = tstar - cur
                    x += u * dt + 0.5 * acc * dt * dt
                    cur = tstar
                # w = 0 at tstar: snap the slider onto the stator velocity
                u = float(self.drive(tstar)[1])
                if tstar >= b:
                    new = self._decide(b, pts[i + 2])
                    if new != reg:
                        end_events.append((b, reg, new))
                    reg, fresh = new, True
                    break
                new = self._decide(a, b)
                if new != reg:
                    yield tstar, x, u, new, [(tstar, reg, new)]
                reg, fresh = new, True
            yield b, x, u, reg, end_events


def stick_slip_period_map(scene, u0):
    """Slider velocity and displacement after one period from ``u(0) = u0``.

    Returns
    -------
    u1 : float
        ``dx/dtau`` at ``tau = 2 pi``.
    dx : float
        ``x(2 pi) - x(0)``.
    """
    walker = _Walker(scene)
    last = None
    for last in walker.walk(0.0, 0.0, u0, TWO_PI):
        pass
    return last[2], last[1]


def stick_slip_steady_state(scene):
    """Periodic steady state of the stick–slip motor, exact up to rounding.

    Parameters
    ----------
    scene : StickSlipMotor
        With ``|fL| < mu n`` (a load above the sliding friction drags the
        slider away and there is no periodic state).

    Returns
    -------
    SteadyState
        ``displacement_per_period`` in units of the drive amplitude,
        ``state0 = [dx/dtau]`` at ``tau = 0`` (the slider starts in contact,
        ``y = 0``), ``regimes`` as ``[tau, letter]`` over ``[0, 2 pi)``,
        ``mode`` the canonical name (e.g. ``"SP"``), ``min_normal_force = n``.

    Raises
    ------
    InputError
        If ``|load| >= mu * normal_force``.
    ConvergenceError
        If the root finder fails (it should not: the bracket is exact).

    Examples
    --------
    >>> from moreau.scenes.stick_slip_motor import StickSlipMotor
    >>> ss = stick_slip_steady_state(StickSlipMotor(frequency=1000.0, drive="sawtooth"))
    >>> ss.mode, round(ss.displacement_per_period, 6), bool(ss.periodic_residual < 1e-12)
    ('NSP', 1.925323, True)
    """
    _check_scene(scene)
    walker = _Walker(scene)
    mun, fL = walker.mun, walker.fL
    if not abs(fL) < mun:
        raise InputError(f"`load` must be smaller in size than the sliding friction "
                         f"`mu` * `normal_force` for a periodic steady state; got "
                         f"|fL| = {abs(fL):.6g} >= mu n = {mun:.6g} (dimensionless)")
    start = _time.perf_counter()
    tau = np.linspace(0.0, TWO_PI, 257)
    ds = walker.drive(tau)[1]
    # beyond these the slider slips one way for the whole period, so the
    # period map shifts u by -2 pi (mu n + fL) or +2 pi (mu n - fL)
    span = TWO_PI * (mun + abs(fL)) + 1.0
    u_hi = float(np.max(ds)) + span + 1.0
    u_lo = float(np.min(ds)) - span - 1.0
    calls = [0]

    def g(u):
        calls[0] += 1
        return stick_slip_period_map(scene, u)[0] - u

    g_hi, g_lo = g(u_hi), g(u_lo)
    if not (g_hi < 0.0 < g_lo):
        raise ConvergenceError(f"period map not bracketed: G({u_hi:.6g}) = {g_hi:.6g}, "
                               f"G({u_lo:.6g}) = {g_lo:.6g}")
    try:
        u_star, info = brentq(g, u_lo, u_hi, xtol=1e-300, rtol=4.0 * _EPS, maxiter=400,
                              full_output=True)
    except RuntimeError as exc:      # brentq signals non-convergence this way
        raise ConvergenceError(f"shooting on the slider velocity failed: {exc}") from None
    regimes = []
    nevents = 0
    last = None
    for node in walker.walk(0.0, 0.0, u_star, TWO_PI):
        tau_k, _, _, reg, events = node
        if not regimes:
            regimes.append([0.0, reg])
        for (te, _, after) in events:
            nevents += 1
            if te < TWO_PI:
                regimes.append([float(te), after])
        last = node
    u1, dx = last[2], last[1]
    letters = [r for _, r in regimes]
    return SteadyState(
        scheme="event-driven",
        displacement_per_period=float(dx),
        state0=np.array([u_star]),
        mode=mode_name(letters),
        regimes=regimes,
        min_normal_force=float(scene.n),
        periodic_residual=abs(u1 - u_star),
        iterations=int(info.iterations),
        wall_time=_time.perf_counter() - start,
        stats={"period_maps": calls[0] + 1, "events_per_period": nevents},
    )


@register_integrator("stick-slip-exact")
class StickSlipReference(Integrator):
    """Exact event-driven integration of a :class:`StickSlipMotor`.

    Each step advances to the next event (stick/slip transition) or cut
    point of the drive, where the state is recorded; the slider stays on the
    stator, so ``q0[1]`` and ``v0[1]`` must be 0.

    Parameters
    ----------
    scene : StickSlipMotor
    t0, q0, v0, t_bound
        As for :class:`~moreau.integrators.base.Integrator`.

    Examples
    --------
    >>> from moreau.integrators import simulate
    >>> from moreau.scenes.stick_slip_motor import StickSlipMotor
    >>> res = simulate(StickSlipMotor(drive="sine"), (0.0, 6.0), [0.0, 0.0], [1.0, 0.0],
    ...                "stick-slip-exact")
    >>> res.status, res.regime_letters()[:2]
    (0, 'SP')
    >>> res.events[0]       # stick breaks where sin(tau) = mu n
    Event(t=0.531243578339, transition, S->P)
    """

    exact_motion = True
    #: the scene's exact periodic steady state, for callers that know the scheme by name only
    steady_state = staticmethod(stick_slip_steady_state)

    @dataclasses.dataclass(frozen=True)
    class Options(SchemeOptions):
        """The exact scheme takes no options."""

    def __init__(self, scene, t0, q0, v0, t_bound):
        _check_scene(scene)
        super().__init__(scene, t0, q0, v0, t_bound)
        if self.q[1] != 0.0 or self.v[1] != 0.0:
            raise InputError(f"`q0` and `v0` must put the slider on the stator "
                             f"(q0[1] == 0 and v0[1] == 0), got {self.q[1]!r}, {self.v[1]!r}")
        self._walker = _Walker(scene)
        self._node = None
        self._gen = self._walker.walk(self.t, self.q[0], self.v[0], self.t_bound)
        self.counters.update({"events": 0})
        first = next(self._gen)
        self._take(first)

    def _take(self, node):
        tau, x, u, reg, events = node
        if self._want_pieces and self._node is not None and tau > self._node[0]:
            self._hand_piece(self._node, float(tau))
        self._node = (float(tau), float(x), float(u), reg)
        for (te, before, after) in events:
            self.events.append(Event(t=te, kind="transition", before=_LETTER[before],
                                     after=_LETTER[after]))
            self.counters["events"] += 1
        self.t = float(tau)
        self.q = np.array([x, 0.0])
        self.v = np.array([u, 0.0])
        fT = self._walker.friction_force(reg, tau)
        slip = u - float(self.scene.drive(tau)[1])
        self._record(self.t, self.q, self.v, int(_LETTER[reg]), self.scene.n, fT, slip, 0.0)

    def _hand_piece(self, node, tb):
        # the closed form between two nodes: the slider moves with the stator in stick,
        # at the constant acceleration of sliding friction and the load in slip
        ta, xa, ua, reg = node
        drive, w = self.scene.drive, self._walker
        acc = (-w.mun if reg == "P" else w.mun) - w.fL

        def xu(t):
            if reg == "S":
                s = drive(t)
                return xa + float(s[0]) - float(drive(ta)[0]), float(s[1])
            dt = t - ta
            return xa + ua * dt + 0.5 * acc * dt * dt, ua + acc * dt

        def state(t):
            x, u = xu(t)
            return np.array([x, 0.0, u, 0.0])

        def sample(t):
            x, u = xu(t)
            return (t, np.array([x, 0.0]), np.array([u, 0.0]), np.array([int(_LETTER[reg])]),
                    np.array([self.scene.n]), np.array([w.friction_force(reg, t)]),
                    np.array([u - float(drive(t)[1])]), np.zeros(1))

        k = max(2, math.ceil((tb - ta) / (TWO_PI / 64)) + 1)
        self._add_piece(np.linspace(ta, tb, k), state, sample)

    def _step_impl(self):
        node = next(self._gen, None)
        if node is None:     # the walk ended exactly at t_bound
            self.t = self.t_bound
            return
        self._take(node)
