"""Scheme comparison: error against run time for every shipped scene (``moreau compare``).

For one scene, :func:`compare` runs

- the scene's reference at several tolerances (the event-driven reference of
  the friction drive; the exact solutions of the other scenes, which have no
  tolerance and give one row);
- Moreau–Jean with ``theta = 1/2`` and ``theta = 1`` at step counts spanning
  two decades, with the scheme's own contact solve (closed form for one
  contact, the compiled Lemke for two; ``lcp = None`` in the table);
- Moreau–Jean (``theta = 1``) with the contact problem of every step forced
  through Lemke and through the QP path (``lcp = "lemke"``, ``"qp"``), so that
  the solvers are compared as well as the schemes.

Errors are measured against the reference at its tightest setting, three ways:

``error``
    the scene's headline quantity, relative (the friction drive and the
    stick–slip motor: the displacement per period; the bouncing ball: the
    height at the end of the window; the sliding block: the stopping
    distance; the Painlevé rod: the horizontal position of its centre at the
    end of the window; the sliding box (two contacts): its exact stopping
    distance; the bidirectional drive (two contacts): the displacement per
    period against the generic event-driven steady state);
``trajectory_error``
    the max over one period (the comparison window) of the main coordinate's
    distance from the reference, both started from the same state (for the
    periodic scenes the reference's periodic state), on a common grid;
``switching_error``
    the largest shift of a regime switching time (or an impact time), when
    the two regime sequences agree (``None`` where they do not, or where the
    motion has no switch); on the two-contact scenes each contact's switches
    are matched separately.

The fitted ``order`` of each Moreau–Jean series is the slope of
``log(trajectory_error)`` against ``log(steps_per_period)``; the headline
error converges at the same rate but erratically (each slip reversal's
``O(h)`` error depends on where it falls inside its step), so its slope is
given as well (``order_headline``) but not used as the order.

For the friction drive, the ``lcp = None`` rows time and measure the discrete
steady state (the fixed point of the Moreau–Jean period map); the Lemke and
QP rows run one period from the reference's periodic state, because the QP
path costs about 16 ms per step and a shooting would repeat that many times.

Plateaus of the Moreau–Jean steady state (the ``notes`` of the report)
----------------------------------------------------------------------
At 2000 Hz the friction drive's Moreau–Jean steady state gives the same
relative error, -1.34e-3, at 5000, 10000 and 20000 steps per period with
``theta = 1/2`` (and -1.31e-3, -1.32e-3 with ``theta = 1`` at 5000 and
10000), then -3.0e-4 at 40000 with both. Measured cause (neither the
treatment of the moving constraint inside the step nor the projection):

* In the steady motion (mode ``NP``, the rod pinned by the closed contact)
  the rotor velocity ``u2'`` at ``tau = 0`` is the only free state. Over a
  period of pure slip the friction impulses do not depend on ``u2'`` as long
  as every step keeps its slip sign, so the *discrete* period map has slope
  exactly 1 in ``u2'`` (neutral) with jumps where a slip reversal moves from
  one step to the next. Only inside a window of width ~1e-9 the reversal
  step sticks, which sets ``u2'`` to the tip velocity at the end of that
  step (slope 0). The fixed point therefore sits in such a window: the
  discrete steady state puts the N -> P slip reversal exactly on a grid time
  ``tau_j``, while the continuous one has it at ``tau* = 2.98557``.
* The rotor velocity, and the displacement per period with it, is then off
  by ``K (tau_j - tau*)`` with ``K = -6.7`` (relative error per unit of
  ``tau``; the continuous period map is barely contracting, slope 0.987,
  so the reversal time and the rotor velocity are tightly coupled). The
  grid point ``tau_j = 2 pi 2376/5000 = 2.98577`` lies 2.0e-4 after
  ``tau*`` and is a grid point of N = 5000, 10000 and 20000 alike, so all
  three give ``-6.7 x 2.0e-4 = -1.34e-3``; N = 40000 adds a grid point
  0.5e-4 after ``tau*`` (``-3.0e-4``). With N = 4999 and 5001 (no shared
  grid point) the same formula gives the measured -5.3e-3 and -5.7e-3;
  ``theta = 1`` often settles on the grid point *before* ``tau*`` (20000
  steps: ``+7.5e-4``), which is why it seemed to keep converging.

So the error is first order in the worst case (``|tau_j - tau*| <= h``) but
erratic: it depends on where the reversal falls on the grid, and doubling N
keeps the old grid point. A variant of the step that locates the reversal
inside the step (splits the step where the slip velocity changes sign) would
remove it; it belongs to the integrator and is not part of this module.
:func:`compare` flags such plateaus in the report's ``notes`` and gives the
signed relative error of every row (``signed_error``).

Examples
--------
>>> rep = compare("sliding-block", steps=[20, 40, 80], lcp_steps=[], thetas=[1.0],
...               repeat=1, progress=False)
>>> [r["scheme"] for r in rep["rows"]][:2], rep["orders"][0]["theta"]
(['exact', 'moreau-jean'], 1.0)
>>> round(rep["orders"][0]["order"], 1)
1.0
"""

import csv
import json
import math
import os
import statistics
import time

import numpy as np

from .._validate import positive_int
from ..errors import InputError, MoreauError

__all__ = ["compare", "SCENES", "DEFAULT_STEPS", "write_outputs", "plot_work_precision",
           "check_out_dir", "make_case", "fit_order", "plateaus"]

TWO_PI = 2.0 * math.pi
#: Moreau–Jean steps per period of the full comparison (two decades)
DEFAULT_STEPS = (50, 100, 200, 500, 1000, 2000, 5000)
#: the same span with fewer points, for quick runs
QUICK_STEPS = (50, 150, 500, 1500, 5000)
#: steps per period of the forced-Lemke / forced-QP rows (QP costs ~16 ms a step)
DEFAULT_LCP_STEPS = (50, 100, 200)
QUICK_LCP_STEPS = (50, 100)
#: samples per period of the common grid of the trajectory error
GRID = 50


def fit_order(steps, errors):
    """Convergence order: minus the slope of ``log(error)`` against ``log(steps)``.

    Points with zero or missing error are left out; fewer than three points
    give None.

    Examples
    --------
    >>> round(fit_order([10, 20, 40], [1e-2, 5e-3, 2.5e-3]), 12)
    1.0
    """
    pts = [(n, e) for n, e in zip(steps, errors) if e is not None and e > 0 and math.isfinite(e)]
    if len(pts) < 3:
        return None
    n, e = np.array(pts, dtype=float).T
    return float(-np.polyfit(np.log(n), np.log(e), 1)[0])


def _median_time(fn, repeat, cheap=1.0):
    """Median run time of ``fn()`` and its output; runs slower than ``cheap`` seconds run once."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if times[0] > cheap:
            break
    return statistics.median(times), out


def _switches(letters, times):
    """``[(t, letter)]`` at every change of the per-sample letter (first entry excluded)."""
    out = []
    for i in range(1, len(letters)):
        if letters[i] != letters[i - 1]:
            out.append((float(times[i]), letters[i]))
    return out


def _drop_reversal_sticks(sw, h):
    # a one-step stick between slips of opposite sign is a reversal inside
    # the step (see moreau.analysis.mj_steady_state): the continuous system
    # has no stick there
    out = []
    i = 0
    while i < len(sw):
        if (i + 1 < len(sw) and sw[i][1] == "S" and sw[i + 1][0] - sw[i][0] <= 1.5 * h
                and out and {out[-1][1], sw[i + 1][1]} == {"N", "P"}):
            out.append((0.5 * (sw[i][0] + sw[i + 1][0]), sw[i + 1][1]))
            i += 2
            continue
        out.append(sw[i])
        i += 1
    merged = []
    for t, s in out:
        if not merged or merged[-1][1] != s:
            merged.append((t, s))
    return merged


def switching_error(ref, got):
    """Largest shift between matched switching times, None if the sequences differ or are empty.

    Examples
    --------
    >>> switching_error([(1.0, "P"), (2.0, "S")], [(1.1, "P"), (1.95, "S")])
    0.1
    >>> switching_error([(1.0, "P")], [(1.0, "S")]) is None
    True
    """
    if not ref or len(ref) != len(got) or any(a[1] != b[1] for a, b in zip(ref, got)):
        return None
    return float(round(max(abs(a[0] - b[0]) for a, b in zip(ref, got)), 15))


def _regime_switches(regimes):
    """Switches of a steady state's ``[[tau, letter], ...]`` (the entry at tau = 0 dropped)."""
    return [(float(t), s) for t, s in regimes[1:]]


# -- the scenes -----------------------------------------------------------------------------
class _Case:
    """One scene set up for comparison (a subclass per scene)."""

    ref_scheme = "exact"
    ref_rtols = (None,)
    tight_rtol = None
    window = TWO_PI            # the "period" the steps are counted over
    headline_name = ""
    projection = False

    def parameters(self):
        return {}

    # reference ---------------------------------------------------------------
    def reference(self, rtol):
        """``(headline, switches)`` of the reference at ``rtol``."""
        raise NotImplementedError

    def reference_grid(self):
        """The main coordinate of the tight reference on the common grid."""
        raise NotImplementedError

    # Moreau–Jean ---------------------------------------------------------------
    def start(self):
        """``(q0, v0)`` at ``t = 0`` for the runs."""
        raise NotImplementedError

    def coordinate(self, q):
        return q[:, 0]

    def headline_of_run(self, res):
        raise NotImplementedError

    def run_mj(self, n, theta, lcp):
        from ..integrators import simulate
        q0, v0 = self.start()
        # every step is kept: the switching times need each step's regime
        opts = dict(h=self.window / n, theta=theta, projection=self.projection)
        if lcp is not None:
            opts["lcp_method"] = lcp
        return simulate(self.scene, (0.0, self.window), q0, v0, "moreau-jean", **opts)

    def mj(self, n, theta, lcp):
        """``(headline, run)``: the timed work of one Moreau–Jean row."""
        res = self.run_mj(n, theta, lcp)
        if not res.success:
            raise MoreauError(f"Moreau–Jean run failed: {res.message}")
        return self.headline_of_run(res), res

    def measure(self, n, theta, lcp, out):
        """``(trajectory_error, switches, mode)`` of a Moreau–Jean row from its timed output."""
        _, res = out
        return self._trajectory_error(res), self._run_switches(res, self.window / n), None

    def _trajectory_error(self, res):
        grid = np.linspace(0.0, self.window, GRID + 1)
        idx = np.searchsorted(res.t, grid - 1e-9 * self.window)
        idx = np.minimum(idx, len(res.t) - 1)
        if np.max(np.abs(res.t[idx] - grid)) > 1e-9 * self.window:
            # the samples are not on the grid (steps not a multiple of GRID): interpolate
            y = np.interp(grid, res.t, self.coordinate(res.q))
        else:
            y = self.coordinate(res.q)[idx]
        return float(np.max(np.abs(y - self.reference_grid())) / self.trajectory_scale)

    trajectory_scale = 1.0

    def _run_switches(self, res, h):
        return self._run_switches_of(res, h, 0)

    def _run_switches_of(self, res, h, contact):
        letters = res.regime_letters(contact)
        t = res.t - h
        # a step's regime is recorded at its end: the switch happened in that step.
        # The regime in force at the start goes in front, so that a one-step
        # stick at the first switch is recognised as a reversal too
        sw = [(float(t[0]), letters[0])] + _switches(letters, t)
        return _drop_reversal_sticks(sw, h)[1:]


class _DriveCase(_Case):
    """A periodically driven scene whose headline is the displacement of its
    cyclic coordinate ``cyclic`` over one steady period; ``_tight()`` gives the
    reference's periodic state and its trajectory on the comparison grid."""

    cyclic = 1
    projection = True

    def reference_grid(self):
        return self._tight()["grid"]

    def start(self):
        r = self._tight()
        return r["q0"].copy(), r["v0"].copy()

    def coordinate(self, q):
        return q[:, self.cyclic]

    def headline_of_run(self, res):
        return float(res.q[-1, self.cyclic] - res.q[0, self.cyclic])

    def mj(self, n, theta, lcp):
        if lcp is not None:
            return super().mj(n, theta, lcp)
        from ..analysis.mj_steady_state import moreau_jean_steady_state
        ss = moreau_jean_steady_state(self.scene, n, theta=theta, projection=self.projection)
        return ss.displacement_per_period, ss


class _FrictionDriveCase(_DriveCase):
    ref_scheme = "event-driven"
    # the compiled steady state is cheap: go far enough to show the plateaus
    default_steps = DEFAULT_STEPS + (10000, 20000)
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
    tight_rtol = 1e-13
    headline_name = "displacement per period"
    projection = True

    def __init__(self, frequency=185.0, **params):
        from ..scenes.friction_drive import FrictionDrive, params_from_kwargs
        self.scene = FrictionDrive(params_from_kwargs(**params), frequency)
        self.frequency = self.scene.frequency
        self._params = dict(params)
        self.trajectory_scale = self.scene.u10
        self._ref = None

    def parameters(self):
        return dict(frequency=self.frequency, **self._params)

    def reference(self, rtol):
        from ..analysis.steady_state import find_steady_state
        ss = find_steady_state(self.scene, rtol=rtol)
        return ss.displacement_per_period, _regime_switches(ss.regimes)

    def _tight(self):
        if self._ref is None:
            from ..analysis.steady_state import find_steady_state
            from ..integrators import simulate
            ss = find_steady_state(self.scene, rtol=self.tight_rtol)
            q = np.array([ss.state0[0], 0.0])
            v = np.array(ss.state0[1:])
            tau_s = float(getattr(ss, "section_tau", 0.0) or 0.0)
            if tau_s > 0.0:
                # carry the periodic state from the section to tau = 2 pi = 0
                r = simulate(self.scene, (tau_s, TWO_PI), q, v, "event-driven", rtol=1e-12)
                q, v = np.array([r.q[-1, 0], 0.0]), r.v[-1].copy()
            grid_run = simulate(self.scene, (0.0, TWO_PI), q, v, "event-driven", rtol=1e-12,
                                samples_per_period=GRID)
            grid = np.linspace(0.0, TWO_PI, GRID + 1)
            idx = np.searchsorted(grid_run.t, grid - 1e-12)
            if np.max(np.abs(grid_run.t[idx] - grid)) > 1e-9:
                raise MoreauError("event-driven samples are not on the comparison grid")
            self._ref = dict(q0=q, v0=v, grid=grid_run.q[idx, 1])
        return self._ref


    def measure(self, n, theta, lcp, out):
        if lcp is not None:
            return super().measure(n, theta, lcp, out)
        _, ss = out
        # the trajectory: one period of the same scheme from the reference's periodic state
        res = self.run_mj(n, theta, None)
        return self._trajectory_error(res), _regime_switches(ss.regimes), ss.mode


class _StickSlipCase(_Case):
    ref_scheme = "stick-slip-exact"
    headline_name = "displacement per period"

    def __init__(self, frequency=1000.0, drive="sawtooth", **params):
        from ..scenes.stick_slip_motor import StickSlipMotor
        self.scene = StickSlipMotor(frequency=frequency, drive=drive, **params)
        self._params = dict(frequency=frequency, drive=drive, **params)
        self._ss = None
        self._grid = None

    def parameters(self):
        return dict(self._params)

    def _steady(self):
        if self._ss is None:
            from ..scenes.stick_slip_exact import stick_slip_steady_state
            self._ss = stick_slip_steady_state(self.scene)
        return self._ss

    def reference(self, rtol):
        from ..scenes.stick_slip_exact import stick_slip_steady_state
        ss = stick_slip_steady_state(self.scene)
        return ss.displacement_per_period, _regime_switches(ss.regimes)

    def start(self):
        return np.array([0.0, 0.0]), np.array([self._steady().state0[0], 0.0])

    def reference_grid(self):
        if self._grid is None:
            from ..integrators import simulate
            grid = np.linspace(0.0, TWO_PI, GRID + 1)
            q, v = self.start()
            xs = [q[0]]
            for a, b in zip(grid[:-1], grid[1:]):
                r = simulate(self.scene, (a, b), q, v, "stick-slip-exact")
                q, v = r.q[-1].copy(), r.v[-1].copy()
                xs.append(q[0])
            self._grid = np.array(xs)
        return self._grid

    def headline_of_run(self, res):
        return float(res.q[-1, 0] - res.q[0, 0])


class _BouncingBallCase(_Case):
    window = 2.6
    headline_name = "height at the end of the window"

    def __init__(self, restitution=0.5, radius=0.1, height=0.6):
        from ..scenes.bouncing_ball import BouncingBall
        self.scene = BouncingBall(restitution=restitution, radius=radius)
        self._params = dict(restitution=restitution, radius=radius, height=height)
        self.q0 = np.array([height])

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.q0.copy(), np.zeros(1)

    def reference(self, rtol):
        q0, v0 = self.start()
        q, _ = self.scene.exact_solution(np.array([self.window]), q0, v0)
        imp = self.scene.impacts(q0, v0, 64).t
        imp = [float(t) for t in imp if t < self.window]
        return float(q[-1, 0]), [(t, "!") for t in imp]

    def reference_grid(self):
        q0, v0 = self.start()
        q, _ = self.scene.exact_solution(np.linspace(0.0, self.window, GRID + 1), q0, v0)
        return q[:, 0]

    def headline_of_run(self, res):
        return float(res.q[-1, 0])

    def _run_switches(self, res, h):
        # impacts: a contact step that follows a flight step
        letters = res.regime_letters()
        t = res.t - h
        return [(float(t[i]), "!") for i in range(1, len(letters))
                if letters[i] != "F" and letters[i - 1] == "F"]


class _SlidingBlockCase(_Case):
    headline_name = "stopping distance"

    def __init__(self, mu=0.5, speed=2.0):
        from ..scenes.sliding_block import SlidingBlock
        self.scene = SlidingBlock(mu=mu)
        self.v0 = np.array([speed, 0.0])
        self._params = dict(mu=mu, speed=speed)
        self.window = 1.5 * self.scene.stopping_time(self.v0)

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return np.zeros(2), self.v0.copy()

    def reference(self, rtol):
        return (float(self.scene.stopping_distance(self.v0)),
                [(float(self.scene.stopping_time(self.v0)), "S")])

    def reference_grid(self):
        q, _ = self.scene.exact_solution(np.linspace(0.0, self.window, GRID + 1), *self.start())
        return q[:, 0]

    def headline_of_run(self, res):
        return float(res.q[-1, 0])


class _PainleveRodCase(_Case):
    ref_scheme = "sliding-ode"
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10)
    tight_rtol = 1e-13
    window = 0.5
    headline_name = "centre position at the end of the window"

    def __init__(self, mu=0.5, phi=0.9, tip_speed=-1.0, dphi=0.4):
        from ..scenes.painleve_rod import PainleveRod
        self.scene = PainleveRod(mu=mu)
        self._params = dict(mu=mu, phi=phi, tip_speed=tip_speed, dphi=dphi)
        self.q0, self.v0 = (np.asarray(a, dtype=float)
                            for a in self.scene.sliding_state(phi, tip_speed, dphi=dphi))
        self._sol = None

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.q0.copy(), self.v0.copy()

    def _ode(self, rtol):
        from scipy.integrate import solve_ivp
        rod = self.scene

        def rhs(t, y):
            a, lam_n, _ = rod.sliding_accelerations(y[:3], y[3:])
            if not lam_n > 0.0:
                raise MoreauError("the rod leaves the ground: the sliding reference does not apply")
            return np.concatenate([y[3:], a])

        return solve_ivp(rhs, (0.0, self.window), np.concatenate([self.q0, self.v0]),
                         method="DOP853", rtol=rtol, atol=rtol, dense_output=True)

    def reference(self, rtol):
        sol = self._ode(rtol)
        return float(sol.y[0, -1]), []

    def reference_grid(self):
        if self._sol is None:
            self._sol = self._ode(self.tight_rtol)
        return self._sol.sol(np.linspace(0.0, self.window, GRID + 1))[0]

    def headline_of_run(self, res):
        return float(res.q[-1, 0])


class _SlidingBoxCase(_Case):
    headline_name = "stopping distance"

    def __init__(self, mu=0.4, speed=1.0, half_width=0.5, half_height=0.25):
        from ..scenes.sliding_box import SlidingBox
        self.scene = SlidingBox(mu=mu, half_width=half_width, half_height=half_height)
        self.q0, _ = self.scene.initial_state()
        self.v0 = np.array([speed, 0.0, 0.0])
        self._params = dict(mu=mu, speed=speed, half_width=half_width, half_height=half_height)
        # checks mu b < a (both corners stay down) and mu > 0, before any work
        self.window = 1.5 * self.scene.stopping_time(self.v0)

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.q0.copy(), self.v0.copy()

    def reference(self, rtol):
        # both corners stop sliding together, at t* = v0 / mu
        t_stop = float(self.scene.stopping_time(self.v0))
        return (float(self.scene.stopping_distance(self.v0)),
                _flatten([[(t_stop, "S")], [(t_stop, "S")]]))

    def reference_grid(self):
        q, _ = self.scene.exact_solution(np.linspace(0.0, self.window, GRID + 1), *self.start())
        return q[:, 0]

    def headline_of_run(self, res):
        return float(res.q[-1, 0])

    def _run_switches(self, res, h):
        # each corner's stop is measured: Moreau–Jean may stop them a step apart
        return _flatten([self._run_switches_of(res, h, c) for c in (0, 1)])


def _contact_switches(regimes, tau_s, contact, h=0.0):
    """Switches ``[(tau, letter)]`` of one contact over ``[0, 2 pi)`` from a steady state's regimes.

    ``regimes`` holds ``[tau - tau_s, key]`` with one letter per contact in
    ``key``; one-step sticks at a slip reversal (``h`` > 0) are dropped as in
    the single-contact case.
    """
    pts = sorted(((float(t) + tau_s) % TWO_PI, k[contact]) for t, k in regimes)
    sw = [(0.0, pts[-1][1] if pts[0][0] > 1e-12 else pts[0][1])]
    for t, letter in pts:
        if letter != sw[-1][1]:
            sw.append((t, letter))
    return _drop_reversal_sticks(sw, h)[1:]


class _BidirectionalDriveCase(_DriveCase):
    """The two-rod drive's steady state; Moreau–Jean against the generic event-driven reference."""

    ref_scheme = "event-driven"
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10)
    tight_rtol = 1e-12
    headline_name = "displacement per period"
    cyclic = 2

    def __init__(self, frequency=185.0, **params):
        from ..scenes.bidirectional_drive import BidirectionalDrive, params_from_kwargs
        # default: rod a at full and rod b at half amplitude, so that both
        # contacts carry load and slip both ways (mode NSP|NP at 185 Hz)
        params.setdefault("x10_b", 1.0e-6)
        self.scene = BidirectionalDrive(params_from_kwargs(**params), frequency)
        self.frequency = self.scene.frequency
        self._params = dict(params)
        self.trajectory_scale = float(np.max(self.scene.u10))
        self._ref = None

    def parameters(self):
        return dict(frequency=self.frequency, **self._params)

    def _switches_of_steady(self, ss, h=0.0):
        tau_s = float(getattr(ss, "section_tau", 0.0) or 0.0)
        return [_contact_switches(ss.regimes, tau_s, c, h) for c in range(self.scene.ncontacts)]

    def reference(self, rtol):
        from ..analysis.steady_state import find_steady_state
        ss = find_steady_state(self.scene, "event-driven", rtol=rtol)
        return ss.displacement_per_period, _flatten(self._switches_of_steady(ss))

    def _tight(self):
        if self._ref is None:
            from ..analysis.steady_state import find_steady_state
            from ..integrators import simulate
            ss = find_steady_state(self.scene, "event-driven", rtol=self.tight_rtol)
            n = self.scene.ndof
            q, v = ss.state0[:n].copy(), ss.state0[n:].copy()
            tau_s = float(getattr(ss, "section_tau", 0.0) or 0.0)
            if tau_s > 0.0:
                # carry the periodic state from the section to tau = 2 pi = 0
                r = simulate(self.scene, (tau_s, TWO_PI), q, v, "event-driven", rtol=1e-12)
                q, v = r.q[-1].copy(), r.v[-1].copy()
            q[2] = 0.0
            run = simulate(self.scene, (0.0, TWO_PI), q, v, "event-driven", rtol=1e-12,
                           sample_dt=TWO_PI / (8 * GRID))
            grid = np.linspace(0.0, TWO_PI, GRID + 1)
            self._ref = dict(q0=q, v0=v, grid=np.interp(grid, run.t, run.q[:, 2]))
        return self._ref


    def measure(self, n, theta, lcp, out):
        # the trajectory and the switching times: one period of the same scheme
        # from the reference's periodic state (the Moreau–Jean steady state names
        # the regimes of the first contact only)
        res = out[1] if lcp is not None else self.run_mj(n, theta, None)
        h = self.window / n
        sw = [self._run_switches_of(res, h, c) for c in range(self.scene.ncontacts)]
        mode = out[1].mode if lcp is None else None
        return self._trajectory_error(res), _flatten(sw), mode


def _flatten(per_contact):
    """One switch list from per-contact lists: ``(tau, "c:letter")``, contact by contact.

    Examples
    --------
    >>> _flatten([[(2.0, "S")], [(1.0, "P"), (3.0, "N")]])
    [(2.0, '0:S'), (1.0, '1:P'), (3.0, '1:N')]
    """
    return [(t, f"{c}:{s}") for c, sw in enumerate(per_contact) for t, s in sw]


#: scene name -> (case class, accepted parameters, one-line description)
SCENES = {
    "friction-drive": (_FrictionDriveCase, ("frequency", "mu", "phi0", "restitution", "load",
                                            "x10", "k", "m", "m2", "length"),
                       "the paper's friction drive (steady state; SI parameters)"),
    "stick-slip-motor": (_StickSlipCase, ("frequency", "drive", "mu", "normal_force", "load"),
                         "stick-slip motor, one period from its periodic state"),
    "bouncing-ball": (_BouncingBallCase, ("restitution", "radius", "height"),
                      "ball dropped from rest, window 2.6 (three impacts)"),
    "sliding-block": (_SlidingBlockCase, ("mu", "speed"), "block sliding to rest on a level plane"),
    "painleve-rod": (_PainleveRodCase, ("mu", "phi", "tip_speed", "dphi"),
                     "Painlevé rod sliding on its tip, well-posed side"),
    "sliding-box": (_SlidingBoxCase, ("mu", "speed", "half_width", "half_height"),
                    "box sliding to rest on its two corners (two frictional contacts)"),
    "bidirectional-drive": (_BidirectionalDriveCase,
                            ("frequency", "mu", "phi0", "restitution", "load", "x10_a",
                             "x10_b", "phase", "k", "m", "m2", "length"),
                            "two-rod bidirectional drive (steady state; SI parameters; "
                            "default x10_b = 1e-6)"),
}


def make_case(scene, **params):
    """Set up scene ``scene`` (a key of :data:`SCENES`) for comparison; None values are dropped."""
    if scene not in SCENES:
        raise InputError(f"`scene` must be one of {sorted(SCENES)}, got {scene!r}")
    cls, allowed, _ = SCENES[scene]
    params = {k: v for k, v in params.items() if v is not None}
    bad = sorted(set(params) - set(allowed))
    if bad:
        raise InputError(f"scene {scene!r} takes the parameters {list(allowed)}; "
                         f"`{bad[0]}` does not apply to it")
    case = cls(**params)
    case.name = scene
    return case


def _relative(value, ref):
    return abs(value - ref) / abs(ref) if ref != 0.0 else abs(value)


def _signed(value, ref):
    return (value - ref) / abs(ref) if ref != 0.0 else value


def plateaus(rows, rel=0.02, min_error=1e-6):
    """Runs of Moreau–Jean rows whose headline error stays put while the step count doubles.

    Returns one note per run of at least two rows of one series
    (``theta``, ``lcp``) with ``steps_per_period`` growing by 2x or more at
    each step and signed errors within ``rel`` of each other (errors below
    ``min_error`` are left out). See the module docstring for what causes them
    on the friction drive.

    Examples
    --------
    >>> rows = [dict(scheme="moreau-jean", theta=0.5, lcp=None, status=0, steps_per_period=n,
    ...              signed_error=e) for n, e in [(1000, -3e-2), (5000, -1.34e-3),
    ...                                           (10000, -1.338e-3), (20000, -1.339e-3)]]
    >>> plateaus(rows)[0]["steps_per_period"]
    [5000, 10000, 20000]
    """
    series = {}
    for r in rows:
        if (r["scheme"] == "moreau-jean" and r["status"] == 0
                and r.get("signed_error") is not None):
            series.setdefault((r["theta"], r["lcp"]), []).append(r)
    notes = []
    for (theta, lcp), rs in series.items():
        rs = sorted(rs, key=lambda r: r["steps_per_period"])
        run = [rs[0]] if rs else []
        for r in rs[1:] + [None]:
            prev = run[-1] if run else None
            if (r is not None and prev is not None
                    and r["steps_per_period"] >= 2 * prev["steps_per_period"]
                    and abs(prev["signed_error"]) >= min_error
                    and abs(r["signed_error"] - prev["signed_error"])
                    <= rel * abs(prev["signed_error"])):
                run.append(r)
                continue
            if len(run) >= 2:
                e = run[0]["signed_error"]
                n = [x["steps_per_period"] for x in run]
                notes.append({
                    "theta": theta, "lcp": lcp, "steps_per_period": n, "signed_error": e,
                    "text": (f"theta={theta:g}: the headline error stays at {e:+.3g} for N = "
                             + ", ".join(map(str, n)) + ": the discrete steady state puts a "
                             "slip reversal on a grid time that these N share (see "
                             "moreau.analysis.compare, 'Plateaus')")})
            run = [r] if r is not None else []
    return notes


def compare(scene, steps=None, lcp_steps=None, thetas=(0.5, 1.0), repeat=3, quick=False,
            progress=True, on_row=None, **params):
    """Error against run time of every scheme on one scene.

    Parameters
    ----------
    scene : str
        A key of :data:`SCENES`.
    steps : sequence of int, optional
        Moreau–Jean steps per period (per comparison window for the
        non-periodic scenes); :data:`DEFAULT_STEPS` (two decades; the
        friction drive adds 10000 and 20000), or
        :data:`QUICK_STEPS` with ``quick=True``.
    lcp_steps : sequence of int, optional
        Steps per period of the forced-Lemke and forced-QP rows.
    thetas : sequence of float
        Values of theta for the default Moreau–Jean rows.
    repeat : int
        Run-time samples per row (the median is reported); rows slower than
        one second are timed once.
    quick : bool
        Fewer points, one timing per row.
    progress : bool
        Show a progress bar (tqdm, on stderr).
    on_row : callable, optional
        Called with each finished row (the caller can save as it goes).
    **params
        Scene parameters (see :data:`SCENES`).

    Returns
    -------
    dict
        ``scene``, ``parameters``, ``headline``, ``reference`` (scheme and
        tightest setting), ``rows`` (one per run: ``scheme``, ``theta``,
        ``lcp``, ``steps_per_period``, ``rtol``, ``time_s``, ``error``,
        ``trajectory_error``, ``switching_error``, ``mode``, ``status``,
        ``message``, ``signed_error``), ``orders`` (``scheme``, ``theta``,
        ``lcp``, ``order``, ``order_headline``), ``notes`` (plateaus of the
        headline error, :func:`plateaus`) and ``interrupted``.
    """
    case = make_case(scene, **params)
    if quick:
        steps = QUICK_STEPS if steps is None else steps
        lcp_steps = QUICK_LCP_STEPS if lcp_steps is None else lcp_steps
        repeat = 1
    if steps is None:
        steps = getattr(case, "default_steps", DEFAULT_STEPS)
    steps = [positive_int("steps", n) for n in steps]
    lcp_steps = [positive_int("lcp_steps", n)
                 for n in (DEFAULT_LCP_STEPS if lcp_steps is None else lcp_steps)]
    repeat = positive_int("repeat", repeat)
    from .._validate import in_closed_interval
    thetas = [in_closed_interval("theta", th, 0.5, 1.0) for th in thetas]

    tight = case.tight_rtol if case.tight_rtol is not None else None
    ref_value, ref_switches = case.reference(tight)
    # compile (numba) and load everything once, outside the timings
    case.mj(min(steps + lcp_steps, default=GRID), 1.0, None)
    if lcp_steps:
        case.mj(min(lcp_steps), 1.0, "lemke")
    report = {
        "scene": scene,
        "parameters": case.parameters(),
        "headline": case.headline_name,
        "reference": {"scheme": case.ref_scheme, "rtol": tight, "headline_value": ref_value},
        "rows": [],
        "orders": [],
        "notes": [],
        "interrupted": False,
    }
    jobs = [("ref", None, None, rtol) for rtol in case.ref_rtols]
    jobs += [("mj", th, None, n) for th in thetas for n in steps]
    jobs += [("mj", 1.0, lcp, n) for lcp in ("lemke", "qp") for n in lcp_steps]
    report["interrupted"] = collect_rows(
        jobs, lambda job: [_run_row(case, *job, repeat, ref_value, ref_switches)],
        report["rows"], on_row, progress, desc=f"compare {scene}", unit="run")
    report["orders"] = _orders(report["rows"])
    report["notes"] = plateaus(report["rows"])
    return report


def collect_rows(items, run, rows, on_row=None, progress=False, desc="", unit="item"):
    """Append ``run(item)``'s rows for each item, with a progress bar; keep them on Ctrl-C.

    Returns True when interrupted: the rows finished so far stay in ``rows``.
    """
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(items), desc=desc, unit=unit)
    try:
        for item in items:
            for row in run(item):
                rows.append(row)
                if on_row is not None:
                    on_row(row)
            if bar is not None:
                bar.update(1)
    except KeyboardInterrupt:
        return True
    finally:
        if bar is not None:
            bar.close()
    return False


def _run_row(case, kind, theta, lcp, setting, repeat, ref_value, ref_switches):
    row = {"scheme": case.ref_scheme if kind == "ref" else "moreau-jean", "theta": theta,
           "lcp": lcp, "steps_per_period": None if kind == "ref" else int(setting),
           "rtol": setting if kind == "ref" else None, "time_s": None, "error": None,
           "signed_error": None,
           "trajectory_error": None, "switching_error": None, "mode": None, "status": 0,
           "message": ""}
    try:
        if kind == "ref":
            t, (value, sw) = _median_time(lambda: case.reference(setting), repeat)
            row.update(time_s=t, error=_relative(value, ref_value),
                       signed_error=_signed(value, ref_value),
                       switching_error=switching_error(ref_switches, sw))
        else:
            t, out = _median_time(lambda: case.mj(setting, theta, lcp), repeat)
            value = out[0]
            traj, sw, mode = case.measure(setting, theta, lcp, out)
            row.update(time_s=t, error=_relative(value, ref_value), trajectory_error=traj,
                       signed_error=_signed(value, ref_value),
                       switching_error=switching_error(ref_switches, sw), mode=mode)
    except MoreauError as exc:
        row.update(status=-1, message=f"{type(exc).__name__}: {exc}")
    return row


def _orders(rows):
    series = {}
    for r in rows:
        if r["scheme"] == "moreau-jean" and r["status"] == 0:
            series.setdefault((r["theta"], r["lcp"]), []).append(r)
    out = []
    for (theta, lcp), rs in series.items():
        n = [r["steps_per_period"] for r in rs]
        out.append({"scheme": "moreau-jean", "theta": theta, "lcp": lcp,
                    "order": fit_order(n, [r["trajectory_error"] for r in rs]),
                    "order_headline": fit_order(n, [r["error"] for r in rs])})
    return out


# -- output ---------------------------------------------------------------------------------
CSV_FIELDS = ("scheme", "theta", "lcp", "steps_per_period", "rtol", "time_s", "error",
              "signed_error", "trajectory_error", "switching_error", "mode", "status", "message")


def check_out_dir(out):
    """Create ``out`` if needed and check that files can be written there (before any work)."""
    if os.path.exists(out) and not os.path.isdir(out):
        raise InputError(f"`--out` must be a folder, but {out!r} is a file")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise InputError(f"`--out` folder {out!r} cannot be created: {exc.strerror}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise InputError(f"`--out` folder {out!r} is not writable")
    return out


def write_outputs(report, out, tag=None, plot=True):
    """Write ``<tag>.csv``, ``<tag>.json`` and (with matplotlib) ``<tag>.png``; return the paths."""
    tag = tag or f"compare_{report['scene']}"
    paths = {}
    csv_path = os.path.join(out, tag + ".csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in report["rows"]:
            w.writerow(r)
    paths["csv"] = csv_path
    json_path = os.path.join(out, tag + ".json")
    with open(json_path, "w") as fh:
        json.dump(report, fh, indent=1)
    paths["json"] = json_path
    if plot:
        try:
            png = os.path.join(out, tag + ".png")
            plot_work_precision(report, png)
            paths["png"] = png
        except ImportError:
            paths["png"] = None
    return paths


def _label(r):
    if r["scheme"] != "moreau-jean":
        return r["scheme"]
    th = "1/2" if r["theta"] == 0.5 else f"{r['theta']:g}"
    return f"Moreau–Jean θ={th}" + (f", {r['lcp']}" if r["lcp"] else "")


def plot_work_precision(report, path, ax=None):
    """Log–log figure: headline error (filled) and trajectory error (open) against run time."""
    import matplotlib
    if ax is None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(7, 5))
    groups = {}
    for r in report["rows"]:
        if r["status"] == 0 and r["time_s"]:
            groups.setdefault(_label(r), []).append(r)
    floor = 1e-16
    for i, (label, rs) in enumerate(groups.items()):
        color = f"C{i}"
        t = [r["time_s"] for r in rs]
        ax.loglog(t, [max(r["error"], floor) for r in rs], "o-", color=color, label=label)
        tr = [(r["time_s"], r["trajectory_error"]) for r in rs if r["trajectory_error"]]
        if tr:
            ax.loglog(*zip(*tr), "o:", color=color, mfc="none")
    ax.set_xlabel("run time [s] (median)")
    ax.set_ylabel(f"relative error: {report['headline']} (filled), trajectory (open)")
    params = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                       for k, v in report["parameters"].items())
    ax.set_title(f"{report['scene']} ({params})", fontsize=9)
    ax.legend(fontsize=7)
    if own:
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)


def format_table(report):
    """The rows as a fixed-width text table."""
    lines = [f"{report['scene']}: {report['headline']} "
             f"(reference {report['reference']['scheme']}"
             + (f", rtol {report['reference']['rtol']:g}" if report['reference']['rtol'] else "")
             + ")",
             f"{'scheme':>17} {'theta':>5} {'lcp':>5} {'steps':>6} {'rtol':>7} {'time [ms]':>10} "
             f"{'error':>9} {'traj.':>9} {'switch':>9} mode"]

    def g(x, fmt):
        return format(x, fmt) if x is not None else "-"

    for r in report["rows"]:
        if r["status"] != 0:
            lines.append(f"{r['scheme']:>17} {g(r['theta'], '5g')} {r['lcp'] or '-':>5} "
                         f"{g(r['steps_per_period'], '6d')} {g(r['rtol'], '7.0e')} failed: "
                         f"{r['message']}")
            continue
        lines.append(f"{r['scheme']:>17} {g(r['theta'], '5g'):>5} {r['lcp'] or '-':>5} "
                     f"{g(r['steps_per_period'], '6d'):>6} {g(r['rtol'], '7.0e'):>7} "
                     f"{r['time_s'] * 1e3:10.2f} {g(r['error'], '9.2e'):>9} "
                     f"{g(r['trajectory_error'], '9.2e'):>9} {g(r['switching_error'], '9.2e'):>9} "
                     f"{r['mode'] or ''}")
    for o in report["orders"]:
        th = o["theta"]
        lines.append(f"order  theta={th:g} lcp={o['lcp'] or '-'}: "
                     f"{g(o['order'], '.2f')} (trajectory), {g(o['order_headline'], '.2f')} "
                     f"(headline)")
    for note in report.get("notes", []):
        lines.append("note: " + note["text"])
    return "\n".join(lines)
