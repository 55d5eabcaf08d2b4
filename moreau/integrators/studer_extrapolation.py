r"""Time stepping with step-size adjustment and extrapolation (Studer, Leine & Glocker, IJNME 2008).

The user gives a tolerance, not a step. The base is Moreau's midpoint
time-stepping scheme; the step size follows a local error estimate; smooth
phases are extrapolated to higher order, switching points are located by
shrinking the step.

The base step (Moreau's midpoint rule)
--------------------------------------
From ``(t, q, v)`` over ``h``: the midpoint ``t_M = t + h/2``,
``q_M = q + (h/2) v``, and::

    M(q_M) (v+ - v) = h h(q_M, v, t_M) + H_M^T P
    q+ = q_M + (h/2) v+

with Newton's impact law and 2D Coulomb friction (the problem of
:func:`~moreau.integrators.contact_problem.solve_contact_problem`) on the
local velocities at the step's end, ``U = H_E v+ + w_E``, where ``H_M`` are
the contact rows at ``(q_M, t_M)`` and ``H_E, w_E`` those at the predicted
end ``(q + h v, t + h)``. Three choices make the base step a smooth
one-step map inside a contact configuration, which extrapolation needs:

* *Index set.* A contact that carried a force in the last base step stays
  in the index set while its force is positive; another one enters when its
  midpoint gap is ``<= 0``. (With the gap test alone a persistent contact
  under a curved constraint, the friction drive's stator near its top, has a
  midpoint gap of ``O(h^2)`` and either sign, and the index set flickered:
  the run from the steady state's section at ``tau = pi`` stalled at tol
  1e-4.) Newton's law acts on a closing contact only (``e = 0`` on one that
  stays closed).
* *Rows at the end.* With ``U`` measured by the midpoint rows, a velocity
  that satisfies the constraint at ``t`` gives the first base step a force
  wrong by ``O(1)`` (half the constraint's curvature); the friction drive's
  normal force falls to 3.7e-4 of its peak, where that error lifted the rod
  off and the run crawled through thousands of steps. Measured at the end,
  the force of every base step is ``O(h)`` right.
* *Projection.* An accepted state has the contacts that carry a force put
  back on ``g = 0`` and ``WN v + wN = 0`` (Newton steps in the metric of
  ``M``): the extrapolated state satisfies them only to the tolerance.

The base step is second order in a smooth phase of the friction drive
(its forces do not depend on the velocity), first order in general.

Step-size adjustment and extrapolation
--------------------------------------
A macro step of size ``H`` is taken with ``n_j = 1, 2, ..., K`` base steps
(``K = columns``), giving ``T_{j,1}``. When every base step of every
sequence keeps the regimes (flight, slip direction, stick) the last
accepted step ended in and none closes a contact, the step lies in a smooth
phase and the Aitken–Neville table ::

    T_{j,k} = T_{j,k-1} + (T_{j,k-1} - T_{j-1,k-1}) / (n_j / n_{j-k+1} - 1)

extrapolates to order ``K`` (for an error expansion in every power of
``h``); the local error is estimated by ``|T_{K,K} - T_{K,K-1}|``.
Otherwise the step is non-smooth: the error of the two-step result
``T_{2,1}`` is estimated by ``|T_{2,1} - T_{1,1}|`` (step halving) and
``T_{2,1}`` is kept. The error is measured as
``max |dy| / (tol (1 + |y|))`` over positions and velocities. A step is
accepted when that is ``<= 1`` (or when ``H`` has reached ``h_min``,
counted in ``stats["forced_steps"]``), and the next step is
``H * min(4, max(0.1, 0.9 err^(-1/(p+1))))`` with ``p = K`` in smooth phases
and ``p = 1`` otherwise.

Switching points
----------------
An impact inside a step makes the halving error ``O(H)``, so the step
shrinks around it until the error allows; a contact that the midpoint step
crosses unseen (open at the midpoint, closed at the end) has the step
refused and quartered. A switch of the regimes without an impulse (a slip
reversal, a stick, a lift-off) that falls in the first base step of every
sequence is invisible to the halving: every sequence takes the new regime
from its first step on. Such a step is located by the jump of the
acceleration: with ``a_old`` the last accepted step's mean acceleration and
``a_new`` that of ``T_{1,1}``, the velocities carry an error
``|a_new - a_old| H``, which enters the error estimate (with ``p = 0``).
Without that the friction drive's error stalled at 1e-3 for any tolerance.

Dense output
------------
Between the ends of its macro steps the scheme's motion is the dense output
of :func:`dense_state`: in a smooth step the quintic Hermite interpolant of
the end positions, velocities and accelerations, the accelerations being the
mean accelerations of the first and the last base step of each sequence,
extrapolated with the state (as accurate as the step ends for ``K <= 4``:
the oscillator at tol 1e-10 is off by 1.8e-9 between its steps and at
them); in a step with a switch the cubic Hermite interpolant; a step with an
impact is not interpolated across it, but split where the motions before and
after the impulse meet. ``t_eval`` samples, events and ``sample_dt`` take it
(the bouncing ball sampled inside its steps: 2.1e-2 off at any tol as chords,
2.4e-11 at tol 1e-10 now).

On a scene with a compiled model the macro steps run in
:mod:`moreau.integrators._studer_kernels` (the same step, equal to the
Python one to 1e-12 from the same state and step size).

Measured (one period of the friction drive at 185 Hz from the walker's
orbit, relative error of the displacement): 6.0e-3, 9.7e-6, 5.0e-7, 6.7e-8 at
tol 1e-4, 1e-6, 1e-8, 1e-10 (767 base steps at 1e-8); the compiled loop
takes about 1.4 ms for that period at tol 1e-9 (937 base steps).
"""

import dataclasses
import math
from typing import ClassVar

import numpy as np

from .._validate import positive, relative_tolerance, whole_number
from ..regimes import Regime
from .result import SimulationResult  # noqa: F401  (named in result's docstring)
from ._blocks import FAST_BLOCK, keep_rows, result_of_rows, states_since
from ._loops import runner_for
from ._mj_kernels import LCP_HANDBACK, PAINLEVE, SINGULAR, STAT_NAMES
from ._dense import Piece
from ._studer_kernels import (DENSE_IMPACT, DENSE_SMOOTH, DENSE_SWITCH, NOT_FINITE,
                              STUDER_COUNTERS, TOO_MANY, studer_loop)
from .base import register_integrator
from .contact_problem import new_contact_counters, slip_signs, solve_contact_problem
from .event_driven_generic import project_positions
from .moreau_jean import classify_impulse
from .time_stepping import StepOptions, TimeStepping, check_step_fits, optional

__all__ = ["StuderExtrapolation", "dense_state", "dense_piece"]

#: bound on the accepted and rejected macro steps of one run
MAX_MACRO_STEPS = 10**7
#: a contact whose gap is below this (relative to ``1 + |q|``) at the start, and whose
#: normal velocity is above ``-CLOSED_SPEED (1 + |v|)``, starts closed
CLOSED_GAP = 1e-12
CLOSED_SPEED = 1e-9


@register_integrator("studer-extrapolation")
class StuderExtrapolation(TimeStepping):
    """Moreau midpoint time stepping with step-size control and extrapolation.

    Parameters
    ----------
    {start}
    tol : float
        Local error tolerance, in ``[100 eps, 1e-2]`` (what float64 can
        certify); positions and velocities are measured relative to ``1 + |y|``.
    columns : int
        Extrapolation columns ``K`` in ``[2, 8]``: the order in smooth phases.
    h0 : float, optional
        First macro step (default: ``(t_bound - t0) / 100``).
    h_min : float, optional
        Smallest macro step (default: ``1e-12 (t_bound - t0)``); a step that
        meets no tolerance at ``h_min`` is accepted and counted.
    lcp_method : {"auto", "lemke", "qp"}
    fast : {"auto", True, False}
        Run the compiled loop (:mod:`moreau.integrators._studer_kernels`, the
        same macro step) on a scene with a ``compiled_model()``; ``"auto"``
        does so unless ``lcp_method="qp"``. A macro step whose contact problem
        Lemke cannot solve is taken by the Python step (QP fallback).
    max_steps : int
        Bound on the macro steps (accepted and rejected) of the run.
    sample_dt : float, optional
        Record the state every ``sample_dt`` from ``t0`` (and at the run's
        end), taken from the dense output, instead of at every macro step's
        end. The steps do not depend on it.
    painleve : {"impulse", "stop"}
        At a one-contact step whose sliding piece has no solution (the discrete Painlevé
        condition fails the way the contact slides): take the step's unique answer, the
        impulsive stick (default; the tangential impact), or stop with status ``-1``
        wherever the pressed contact's free slip, of any size, runs that way
        (:func:`~moreau.integrators.contact_problem.solve_contact_problem`).

    Examples
    --------
    A unit mass dropped from height 1 onto the ground with ``e = 1`` is back at
    height 1 at ``t = 2 sqrt(2)``:

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.model.examples import Drop
    >>> res = simulate(Drop(), (0.0, 2 * np.sqrt(2)), [1.0], [0.0], "studer-extrapolation",
    ...                tol=1e-8)
    >>> bool(abs(res.q[-1, 0] - 1.0) < 1e-6)
    True
    """

    # the quick run keeps a row below 1e-6 (185 Hz: 8.5e-8 at tol 1e-10)
    compare_settings = ("tol", (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11),
                        (1e-4, 1e-10), {})
    #: the option that sets the local error tolerance (the shooting's finite differences
    #: step above it: :mod:`moreau.analysis.periodic_shooting`)
    error_tolerance_option = "tol"
    #: accepted macro steps per call of the compiled loop
    _block_steps = FAST_BLOCK
    #: ``t_eval`` samples and events are taken on the dense output (see :func:`dense_piece`)
    exact_motion = True

    #: the macro steps are the scheme's own (from ``h0``), not a fixed grid
    fixed_step = False

    @dataclasses.dataclass(frozen=True)
    class Options(StepOptions):
        """Options of :class:`StuderExtrapolation` (its parameters after ``t_bound``)."""
        tol: float = 1e-6
        columns: int = 4
        h0: float | None = None
        h_min: float | None = None
        lcp_method: str = "auto"
        fast: str | bool = "auto"
        max_steps: int = MAX_MACRO_STEPS
        sample_dt: float | None = None
        painleve: str = "impulse"

        _rules: ClassVar[dict] = {"tol": lambda v: relative_tolerance("tol", v),
                                  "columns": lambda v: whole_number("columns", v, 2, 8),
                                  "h0": optional(lambda v: positive("h0", v)),
                                  "h_min": optional(lambda v: positive("h_min", v))}

    def _new_counters(self):
        return {"steps": 0, **new_contact_counters(), "base_steps": 0, "rejected_steps": 0,
                "smooth_steps": 0, "forced_steps": 0, "max_penetration": 0.0}

    def _setup_scheme(self):
        # the accepted steps' rows (with their dense output) not yet handed to simulate
        self._new_rows = []
        # the rows of the result: every step's end, or the sample_dt grid
        self._out = []
        self._last_row = None
        self._handed_row = None
        self._next_sample = 1
        span = self.t_bound - self.t0
        self.h = span / 100.0 if self.h0 is None else check_step_fits(
            "h0", self.h0, self.t0, self.t_bound)
        if self.h_min is not None:
            check_step_fits("h_min", self.h_min, self.t0, self.t_bound)
        else:
            self.h_min = 1e-12 * span
        scene, nc = self.scene, self.scene.ncontacts
        self._macro = 0
        self._acc = None
        # regimes of the last base step of the last accepted step (-1: none yet)
        self._last_reg = np.full(nc, -1, dtype=int)
        if nc:
            # a contact touching at the start without approaching carries a force already
            # (a start on a persistent contact: a steady state's section)
            g = np.asarray(scene.gaps(self.q, self.t0), float)
            WN, wN, _, _ = scene.contact_jacobians(self.q, self.t0)
            vN = np.asarray(WN, float) @ self.v + np.asarray(wN, float)
            self._closed = ((g <= CLOSED_GAP * (1.0 + float(np.max(np.abs(self.q)))))
                            & (vN >= -CLOSED_SPEED * (1.0 + float(np.max(np.abs(self.v))))))

    # -- the base step ---------------------------------------------------------------------
    def _midpoint(self, t, q, v, h, closed):
        """One Moreau midpoint step from ``(t, q, v)`` with the contacts ``closed`` carrying force.

        Returns ``(q+, v+, closed+, pN, pT, slip, regime, switch, missed)``: ``switch``
        when a contact closed in the step, ``missed`` when a contact open at the
        midpoint is closed at the end (the step crossed an impact it did not see).
        """
        sc = self.scene
        tm = t + 0.5 * h
        qm = q + 0.5 * h * v
        M = np.asarray(sc.mass(qm), float)
        v_free = v + h * np.linalg.solve(M, np.asarray(sc.forces(qm, v, tm), float))
        nc = sc.ncontacts
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        slip = np.zeros(nc)
        v1 = v_free
        switch = False
        active = np.zeros(nc, dtype=bool)
        self.counters["base_steps"] += 1
        if nc:
            g = np.asarray(sc.gaps(qm, tm), float)
            # a contact that carried a force stays in the index set while its force is
            # positive, whatever the sign of its midpoint gap: a persistent contact under
            # a curved constraint (the stator's acceleration) has a midpoint gap of
            # O(h^2) of either sign, and the index set must not flicker with it
            active = closed | (g <= 0.0)
            if active.any():
                ia = np.flatnonzero(active)
                fa = ia[self._trow[ia] >= 0]
                tr = self._trow[fa]
                WN, wN, WT, wT = (np.asarray(x, float) for x in sc.contact_jacobians(qm, tm))
                vN_pre = (WN @ v + wN)[ia]
                # Newton's law acts on a contact that closes; one that carried a force
                # stays closed without a rebound (its approach speed is O(h))
                e = np.where(closed[ia], 0.0, self.e_c[ia])
                H = np.vstack([WN[ia], WT[tr]])
                MinvHT = np.linalg.solve(M, H.T)
                # the impulse acts along the midpoint's normals; the contact law holds for
                # the local velocities at the step's end (rows at the predicted end
                # position q + h v): a velocity that meets the constraint at t meets it
                # in the first base step too, and the force of that step is O(h) right
                # (rows at the midpoint make it O(1) wrong by half the constraint's
                # curvature, which flips the sign of a small force)
                WNe, wNe, WTe, wTe = (np.asarray(x, float)
                                      for x in sc.contact_jacobians(q + h * v, t + h))
                He = np.vstack([WNe[ia], WTe[tr]])
                W = He @ MinvHT
                U_free = He @ v_free + np.concatenate([wNe[ia], wTe[tr]])
                if np.all(U_free[:ia.size] + e * np.minimum(vN_pre, 0.0) >= 0.0):
                    # no contact needs to push: zero normal impulse bounds the friction
                    U = U_free
                else:
                    # the base steps of a macro step start from its regimes; the check
                    # only stops (painleve="stop"): the sequences repeat the base steps
                    stop = self.painleve == "stop"
                    p, pn, pt = solve_contact_problem(
                        W, U_free, self.mu_c[ia], e, vN_pre, lcp_method=self.lcp_method,
                        counters=self.counters, t=t, painleve=self.painleve,
                        slip_before=slip_signs(self._prev_reg[ia]) if stop else None,
                        warm=self._lcp_warm("base step"), warm_key=tuple(ia.tolist()))
                    pN[ia], pT[ia] = pn, pt
                    v1 = v_free + MinvHT @ p
                    U = U_free + W @ p
                slip[fa] = U[ia.size:]
        q1 = qm + 0.5 * h * v1
        closed1 = pN > 0.0
        switch = bool(np.any(closed1 & ~closed))
        missed = False
        if nc:
            g1 = np.asarray(sc.gaps(q1, t + h), float)
            missed = bool(np.any((g1 < 0.0) & ~active))
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)],
                          dtype=int)
        return q1, v1, closed1, pN, pT, slip, regime, switch, missed

    def _sequence(self, t, q, v, H, n):
        """``n`` base steps over ``H`` from the accepted state.

        Returns ``(y, smooth, missed, closed, pN, pT, slip, regime, closing)``: the
        end state and the mean accelerations of the first and the last base
        step, ``y = (q, v, a0, a1)``; ``smooth`` when every base step kept the regimes
        of the first and none closed a contact; the impulses summed over the steps;
        the slip velocities, regimes and closed contacts of the last base step;
        ``closing`` when some base step closed a contact.
        """
        h = H / n
        closed = self._closed
        smooth = True
        missed = False
        pN_sum = np.zeros(self.scene.ncontacts)
        pT_sum = np.zeros(self.scene.ncontacts)
        reg0 = None
        closing = False
        for i in range(n):
            v_before = v
            q, v, closed, pN, pT, slip, reg, switch, miss = self._midpoint(t + i * h, q, v, h,
                                                                           closed)
            # at the macro step's ends to O(h), and extrapolated with the state
            if i == 0:
                a0 = (v - v_before) / h
            a1 = (v - v_before) / h
            if reg0 is None:
                reg0 = reg
            missed = missed or miss
            closing = closing or switch
            smooth = smooth and not switch and not miss and np.array_equal(reg, reg0)
            pN_sum += pN
            pT_sum += pT
        return (np.concatenate([q, v, a0, a1]), smooth, missed, closed, pN_sum, pT_sum, slip,
                reg, closing)

    def _error(self, a, b, y):
        m = 2 * self.scene.ndof
        return float(np.max(np.abs(a[:m] - b[:m]) / (self.tol * (1.0 + np.abs(y[:m])))))

    def _step_impl(self):
        # macro steps end on the forcing's breakpoints: extrapolation makes a stick phase
        # under a piecewise-quadratic drive exact, its steps grow fourfold each time, and
        # one step spanned the stick-slip motor's whole slip phase (from tau = 2.27 to
        # 2 pi, error 12 % at tol 1e-10) with no sample inside it
        breaks = getattr(self.scene, "forcing_breakpoints", None)
        bp = () if breaks is None else breaks(self.t + 1e-12 * max(1.0, abs(self.t)),
                                              self.t_bound - 1e-12 * max(1.0, abs(self.t_bound)))
        bound = float(bp[0]) if len(bp) else self.t_bound
        if self._fast:
            self._fast_block(bound)
        else:
            self._generic_step(bound)
        if self.t == bound and bound < self.t_bound:
            # the forcing jumps here: the next step's acceleration is not comparable with
            # this one's, and the switch it may bring is located already
            self._acc = None

    def _loop_steps_to(self, start, t, rows):
        # one recorded sample per accepted macro step, after the run's first one
        return int(np.count_nonzero(np.asarray(rows) > start["t"]))

    def _fast_block(self, bound):
        n, nc = self.scene.ndof, self.scene.ncontacts
        q, v, closed, reg = self.q.copy(), self.v.copy(), self._closed.copy(), self._last_reg.copy()
        acc = np.zeros(n) if self._acc is None else self._acc.copy()
        th = np.array([self.t, self.h, 0.0 if self._acc is None else 1.0])
        nmax = getattr(self, "_block_limit", self._block_steps)
        ns = nmax + 2
        buf = (np.empty(ns), np.empty((ns, n)), np.empty((ns, n)),
               np.empty((ns, nc), dtype=np.int64), np.empty((ns, nc)), np.empty((ns, nc)),
               np.empty((ns, nc)), np.empty((ns, nc)), np.empty(ns, dtype=np.int64),
               np.empty((ns, n)), np.empty((ns, n)))
        st = self._stats
        st[:] = 0.0
        cnt = np.zeros(len(STUDER_COUNTERS), dtype=np.int64)
        m = self._model
        opts = (float(self.tol), int(self.columns), float(self.h_min),
                int(self.max_steps - self._macro))
        memo = (th, closed, reg, acc, cnt) + buf[8:]
        status, nacc, nrec = runner_for(m, studer_loop, self.scene)(
            m.par, self.mu_c, self.e_c, float(th[0]), float(th[1]), bound, 0, nmax, q, v, opts,
            memo, 1, self._pending_initial, self._lcp_ctl, *buf[:8], st)
        if nrec:
            self._add_rows(tuple(b[:nrec].copy() for b in buf))
            self._pending_initial = False
        self.t, self.h = float(th[0]), float(th[1])
        self.q, self.v, self._closed, self._last_reg = q, v, closed, reg
        self._acc = acc if th[2] else None
        c = self.counters
        for name, x in zip(STAT_NAMES, st):
            c[name] = max(c[name], float(x)) if name.startswith("max_") else c[name] + int(x)
        for name, x in zip(STUDER_COUNTERS, cnt):
            if name == "macro_steps":
                self._macro += int(x)
            else:
                c[name] += int(x)
        # the base class counts one step per call of _step_impl
        c["steps"] += nacc - 1
        if status == TOO_MANY:
            self._fail(-5, self._too_many())
        elif status == NOT_FINITE:
            self._fail(-5, f"non-finite state after the step at t = {self.t!r}")
        elif status == SINGULAR:
            self._fail(-5, f"the mass matrix is singular near t = {self.t!r}")
        elif status in (LCP_HANDBACK, PAINLEVE):
            # the generic step takes the macro step the loop stopped at (QP fallback, or
            # the full diagnosis of a Painleve case)
            c["steps"] += 1
            self._generic_step(bound)

    def _project(self, t, q, v, held):
        """The accepted state on the constraints of the contacts ``held`` (carrying a force).

        The extrapolated state satisfies ``g = 0`` and ``g' = 0`` only to the
        tolerance; a closed contact whose gap drifts open would be taken for a
        lift-off, and its re-closing for an impact. Positions go onto ``g = 0``
        (Newton steps), velocities onto ``WN v + wN = 0``, both in the metric of ``M``.
        """
        sc = self.scene
        q = project_positions(sc, t, q, held)
        WN, wN, _, _ = sc.contact_jacobians(q, t)
        W = np.asarray(WN, float)[held]
        MiW = np.linalg.solve(np.asarray(sc.mass(q), float), W.T)
        v = v - MiW @ np.linalg.solve(W @ MiW, W @ v + np.asarray(wN, float)[held])
        return q, v

    # -- the record: step ends, their dense output, the samples --------------------------
    def _snapshot(self):
        # no replay of a compiled block: the rows past the first one outside the valid
        # region are dropped (its step counters may count the rest of that block)
        return None

    def _unchecked_states(self):
        return states_since(self._out, self._region_seen)

    def _keep_checked(self, count):
        self._out = keep_rows(self._out, self._region_seen, count)
        self._region_seen = len(self._out)

    def _add_rows(self, rows):
        """Take accepted steps' rows ``(t, q, v, regime, force_N, force_T, slip, gap, kind,
        a0, a1)`` (the start's row first, kind -1): into the result and the dense output."""
        if self._want_pieces:
            self._new_rows.append(rows)
        if self.sample_dt is None:
            self._out.append(rows[:8])
        else:
            self._sample_grid(rows)
        self._last_row = tuple(a[-1:] for a in rows)

    def _sample_grid(self, rows):
        if self._last_row is None:
            self._out.append(tuple(a[:1] for a in rows[:8]))
            joined = rows
        else:
            joined = tuple(np.concatenate([a, b]) for a, b in zip(self._last_row, rows))
        t_end = float(joined[0][-1])
        # the window's end is the run's last row (result()), not a grid sample
        short = self.t_bound - 1e-12 * max(1.0, abs(self.t_bound))
        times = []
        while True:
            s = self.t0 + self._next_sample * self.sample_dt
            if s > t_end or s >= short:
                break
            times.append(s)
            self._next_sample += 1
        if times and len(joined[0]) > 1:
            piece = dense_piece(self.scene, joined)
            self._out.append(_stack([piece.sample(s) for s in times]))

    def _take_pieces(self):
        if not self._new_rows:
            return []
        rows = tuple(np.concatenate(c) for c in zip(*self._new_rows))
        self._new_rows = []
        if self._handed_row is not None:
            rows = tuple(np.concatenate([a, b]) for a, b in zip(self._handed_row, rows))
        self._handed_row = tuple(a[-1:] for a in rows)
        return [dense_piece(self.scene, rows)] if len(rows[0]) > 1 else []

    def result(self):
        """Assemble the recorded rows into a :class:`SimulationResult`."""
        chunks = list(self._out)
        if self.sample_dt is not None and self._last_row is not None and (
                not chunks or self._last_row[0][0] > chunks[-1][0][-1]):
            # the state the run ended in (the window's end, or where it stopped)
            chunks.append(self._last_row[:8])
        return result_of_rows(self, chunks)

    def _too_many(self):
        return f"more than `max_steps` = {self.max_steps} macro steps; raise it or loosen `tol`"

    def _generic_step(self, bound):
        sc = self.scene
        n = sc.ndof
        t, q, v = self.t, self.q, self.v
        c = self.counters
        K = self.columns
        while True:
            self._macro += 1
            if self._macro > self.max_steps:
                c["steps"] -= 1
                self._fail(-5, self._too_many())
                return
            H = min(self.h, bound - t)
            last = t + H >= bound - 1e-12 * max(1.0, abs(bound))
            T = [self._sequence(t, q, v, H, j) for j in (1, 2)]
            if (T[0][2] or T[1][2]) and H > self.h_min:
                # an impact crossed unseen: shrink until a midpoint lands in the contact
                c["rejected_steps"] += 1
                self.h = max(self.h_min, 0.25 * H)
                continue
            # smooth: every base step keeps the regimes the last accepted step ended in
            smooth = (T[0][1] and T[1][1] and np.array_equal(T[0][7], self._last_reg)
                      and np.array_equal(T[1][7], self._last_reg))
            j = 3
            while smooth and j <= K:
                T.append(self._sequence(t, q, v, H, j))
                smooth = T[-1][1] and np.array_equal(T[-1][7], self._last_reg)
                j += 1
            if smooth:
                # Aitken-Neville on n_j = j, for an error expansion in every power of h
                row = [T[0][0]]
                for j in range(2, K + 1):
                    new = [T[j - 1][0]]
                    for k in range(2, j + 1):
                        new.append(new[k - 2] + (new[k - 2] - row[k - 2]) / (j / (j - k + 1) - 1.0))
                    row = new
                y = row[K - 1]
                err = self._error(y, row[K - 2], y)
                order = K
                rec = T[K - 1]
                kind = DENSE_SMOOTH
            else:
                y = T[1][0]
                err = self._error(y, T[0][0], y)
                order = 1
                rec = T[1]
                kind = DENSE_IMPACT if T[1][8] else DENSE_SWITCH
                if kind == DENSE_IMPACT:
                    # an impulse in the step: the dense output joins the smooth motions
                    # before and after it, with the last step's acceleration in both
                    a = np.zeros(n) if self._acc is None else self._acc
                    y = np.concatenate([y[:2 * n], a, a])
                if (self._acc is not None and not (T[0][8] or T[1][8])
                        and not np.array_equal(T[0][7], self._last_reg)):
                    # the regimes changed in the first base step of every sequence (a
                    # slip reversal, a stick or a lift-off): the halving cannot see where,
                    # so the switch is located by the jump of the acceleration, which
                    # puts an error of |da| H on the velocities
                    da = np.abs((T[0][0][n:2 * n] - v) / H - self._acc)
                    e_sw = float(np.max(da * H / (self.tol * (1.0 + np.abs(y[n:2 * n])))))
                    if e_sw > err:
                        err, order = e_sw, 0
            if err <= 1.0 or H <= self.h_min:
                if err > 1.0:
                    c["forced_steps"] += 1
                break
            c["rejected_steps"] += 1
            self.h = max(self.h_min, H * max(0.1, 0.9 * err ** (-1.0 / (order + 1))))
        if smooth:
            c["smooth_steps"] += 1
        fac = 4.0 if err == 0.0 else min(4.0, max(0.1, 0.9 * err ** (-1.0 / (order + 1))))
        if not last:
            self.h = max(self.h_min, H * fac)
        t1 = bound if last else t + H
        q1, v1 = y[:n].copy(), y[n:2 * n].copy()
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1)) and math.isfinite(err)):
            c["steps"] -= 1
            self._fail(-5, f"non-finite state after the step at t = {t!r}")
            return
        nc = sc.ncontacts
        _, _, _, closed, pN, pT, slip, regime, _ = rec
        if closed.any():
            q1, v1 = self._project(t1, q1, v1, np.flatnonzero(closed))
        gap = np.asarray(sc.gaps(q1, t1), float) if nc else np.zeros(0)
        if nc:
            c["max_penetration"] = max(c["max_penetration"], float(np.max(-gap, initial=0.0)))
        if self._pending_initial:
            g0 = np.asarray(sc.gaps(q, t), float) if nc else gap
            # the first step's regime and forces, as every time-stepping scheme records its
            # start (no step has ended there)
            self._add_rows(_rows(t, q, v, regime, pN / H, pT / H, slip, g0, -1, np.zeros(n),
                                 np.zeros(n)))
            self._pending_initial = False
        self.t, self.q, self.v = t1, q1, v1
        self._closed = closed.copy()
        self._last_reg = regime.copy()
        # the acceleration of the step, unless a contact closed in it (an impulse)
        self._acc = None if rec[8] else (v1 - v) / H
        self._prev_reg = np.asarray(regime, dtype=int)
        self._add_rows(_rows(t1, q1, v1, regime, pN / H, pT / H, slip, gap, kind,
                             y[2 * n:3 * n], y[3 * n:]))


def _rows(t, q, v, regime, force_N, force_T, slip, gap, kind, a0, a1):
    """One row of :meth:`StuderExtrapolation._add_rows` from a step taken in Python."""
    return (np.array([t], float), np.array(q, float).reshape(1, -1),
            np.array(v, float).reshape(1, -1), np.asarray(regime, np.int64).reshape(1, -1),
            *(np.asarray(x, float).reshape(1, -1) for x in (force_N, force_T, slip, gap)),
            np.array([kind], np.int64), np.array(a0, float).reshape(1, -1),
            np.array(a1, float).reshape(1, -1))


def _stack(samples):
    cols = list(zip(*samples))
    return (np.array(cols[0], float), *(np.array(c, float) for c in cols[1:3]),
            np.array(cols[3], np.int64), *(np.array(c, float) for c in cols[4:]))


def dense_state(ta, tb, qa, va, qb, vb, kind, a0, a1, s):
    r"""The dense output of one macro step ``[ta, tb]`` at time ``s``: ``(q, v)``.

    * A smooth step (``kind`` :data:`~moreau.integrators._studer_kernels.DENSE_SMOOTH`)
      is the quintic Hermite interpolant of the positions, velocities and
      accelerations at its ends, ``v`` its derivative. The end states carry
      the step's error; ``a0, a1`` are the mean accelerations of the first
      and the last base step of each sequence, ``a + c_1 h + c_2 h^2 + ...``
      in the base step ``h = H / j``, extrapolated with the state, so they
      are ``O(H^K)`` right. The interpolation adds ``O(H^6)`` to ``q`` and
      ``O(H^5)`` to ``v`` (``H^6 s^3 (1 - s)^3 q^{(6)} / 720``), the
      accelerations ``O(H^{K+2})`` and ``O(H^{K+1})``: the dense output's
      local error in ``v`` is ``O(H^{min(K, 4) + 1})``, that of the step for
      ``K <= 4``.
    * A step in which the regimes change without an impulse (``DENSE_SWITCH``,
      first order) is the cubic Hermite interpolant of the end positions and
      velocities.
    * A step in which a contact closed (``DENSE_IMPACT``) is not interpolated
      across the impulse: the motion from the start, ``qa + va d + a d^2 / 2``,
      and the one into the end, ``qb + vb (s - tb) + a (s - tb)^2 / 2``
      (``a = a0``, the last smooth step's acceleration), differ by
      ``c - w d`` (``d = s - ta``, ``w = vb - va - a H`` the impulse's jump,
      ``c = qa - qb + vb H - a H^2 / 2``); they meet at
      ``d* = w.c / w.w`` (least squares), where the dense output passes from
      the first to the second.

    Examples
    --------
    A quintic is reproduced by the smooth step's interpolant:

    >>> import numpy as np
    >>> p = np.polynomial.Polynomial([1.0, -2.0, 0.5, 3.0, -1.0, 0.25])
    >>> d1, d2 = p.deriv(), p.deriv(2)
    >>> q, v = dense_state(0.0, 2.0, p(0.0), d1(0.0), p(2.0), d1(2.0), 2, d2(0.0), d2(2.0), 0.7)
    >>> bool(abs(q - p(0.7)) < 1e-12 and abs(v - d1(0.7)) < 1e-12)
    True
    """
    H = tb - ta
    if not H > 0.0:
        return np.array(qb, float), np.array(vb, float)
    if kind == DENSE_IMPACT:
        w = vb - va - a0 * H
        ww = float(np.dot(w, w))
        if ww > 0.0:
            c = qa - qb + vb * H - 0.5 * a0 * H * H
            split = min(max(float(np.dot(w, c)) / ww, 0.0), H)
            d = s - ta
            if d < split:
                return qa + va * d + 0.5 * a0 * d * d, va + a0 * d
            d = s - tb
            return qb + vb * d + 0.5 * a0 * d * d, vb + a0 * d
    x = (s - ta) / H
    m0, m1 = H * va, H * vb
    if kind == DENSE_SMOOTH:
        c0, c1 = H * H * a0, H * H * a1
        r0 = qb - qa - m0 - 0.5 * c0
        r1 = m1 - m0 - c0
        r2 = c1 - c0
        k3 = 10.0 * r0 - 4.0 * r1 + 0.5 * r2
        k4 = -15.0 * r0 + 7.0 * r1 - r2
        k5 = 6.0 * r0 - 3.0 * r1 + 0.5 * r2
        q = qa + x * (m0 + x * (0.5 * c0 + x * (k3 + x * (k4 + x * k5))))
        v = (m0 + x * (c0 + x * (3.0 * k3 + x * (4.0 * k4 + x * 5.0 * k5)))) / H
        return q, v
    r0 = qb - qa - m0
    r1 = m1 - m0
    k2 = 3.0 * r0 - r1
    k3 = r1 - 2.0 * r0
    return qa + x * (m0 + x * (k2 + x * k3)), (m0 + x * (2.0 * k2 + 3.0 * x * k3)) / H


def dense_piece(scene, rows):
    """The motion of consecutive macro steps as a :class:`~moreau.integrators._dense.Piece`.

    ``rows`` are the steps' rows (``t, q, v, regime, force_N, force_T, slip,
    gap, kind, a0, a1``), the first one the end of the step before them. A
    time between two rows gets :func:`dense_state` of the step that ends at
    the later one; its gaps from the scene at that state, the slip velocity
    of a contact that slips from the scene's rows, the regime and the forces
    of the step.
    """
    t, q, v, reg, fN, fT, slip, gap, kind, a0, a1 = rows
    fi = np.asarray(scene.frictional_index, dtype=int)
    nc = gap.shape[1]
    slipping = (int(Regime.POSITIVE), int(Regime.NEGATIVE))

    def where(s):
        return min(max(int(np.searchsorted(t, s, side="left")), 1), len(t) - 1)

    def at(s, j):
        return dense_state(t[j - 1], t[j], q[j - 1], v[j - 1], q[j], v[j], int(kind[j]), a0[j],
                           a1[j], s)

    def state(s):
        return np.concatenate(at(s, where(s)))

    def sample(s):
        j = where(s)
        qs, vs = at(s, j)
        H = t[j] - t[j - 1]
        w = (s - t[j - 1]) / H if H > 0.0 else 1.0
        sl = (1.0 - w) * slip[j - 1] + w * slip[j]
        g = np.asarray(scene.gaps(qs, s), float).reshape(nc) if nc else np.zeros(0)
        moving = [m for m, c in enumerate(fi) if reg[j, c] in slipping]
        if moving:
            _, _, WT, wT = scene.contact_jacobians(qs, s)
            u = np.asarray(WT, float) @ vs + np.asarray(wT, float)
            for m in moving:
                sl[fi[m]] = u[m]
        return (s, qs, vs, reg[j].copy(), fN[j].copy(), fT[j].copy(), sl, g)

    return Piece(t, state, sample, np.hstack([q, v]))
