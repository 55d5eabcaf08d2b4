r"""Time stepping with step-size adjustment and extrapolation (Studer, Leine & Glocker, IJNME 2008).

The user gives a tolerance, not a step. The base is Moreau's midpoint
time-stepping scheme; the step size follows a local error estimate; smooth
phases are extrapolated to higher order, switching points are located by
shrinking the step.

The base step (Moreau's midpoint rule)
--------------------------------------
From ``(t, q, v)`` over ``h``: the midpoint ``t_M = t + h/2``,
``q_M = q + (h/2) v``, the contacts closed at the midpoint
(``g(q_M, t_M) <= 0``) form the index set, and::

    M(q_M) (v+ - v) = h h(q_M, v, t_M) + H^T P
    q+ = q_M + (h/2) v+

with Newton's impact law and 2D Coulomb friction on
``U = H(q_M, t_M) v+ + w(t_M)`` (the problem of
:func:`~moreau.integrators.contact_problem.solve_contact_problem`). It is
first order, and in a phase where the contact configuration (the closed
contacts and their stick/slip regimes) does not change, a smooth one-step
method whose global error has an expansion in powers of ``h``.

Step-size adjustment and extrapolation
--------------------------------------
A macro step of size ``H`` is taken with ``n_j = 1, 2, ..., K`` base steps
(``K = columns``), giving ``T_{j,1}``. When every base step of every
sequence sees the configuration of the first (no impact, no contact closing
or opening, no stick/slip change), the step lies in a smooth phase and the
Aitken–Neville table ::

    T_{j,k} = T_{j,k-1} + (T_{j,k-1} - T_{j-1,k-1}) / (n_j / n_{j-k+1} - 1)

extrapolates to order ``K``; the local error is estimated by
``|T_{K,K} - T_{K,K-1}|``. Otherwise the step is non-smooth: the error of
the two-step result ``T_{2,1}`` is estimated by ``|T_{2,1} - T_{1,1}|``
(step halving) and ``T_{2,1}`` is kept. The error is measured as
``max |dy| / (tol (1 + |y|))`` over positions and velocities. A step is
accepted when that is ``<= 1`` (or when ``H`` has reached ``h_min``,
counted in ``stats["forced_steps"]``), and the next step is
``H * min(4, max(0.1, 0.9 err^(-1/(p+1))))`` with ``p = K`` in smooth phases
and ``p = 1`` otherwise. A switching point (an impact or a change of
regime) inside a step makes the halving error ``O(H)``, so the step shrinks
around it until the error allows: that is how the switching points are
located, to a time accuracy that follows ``tol``.
"""

import math

import numpy as np

from .._validate import in_open_interval, positive, positive_int
from ..errors import InputError
from .base import Integrator, register_integrator
from .contact_problem import new_contact_counters, solve_contact_problem
from .moreau_jean import check_lcp_options, check_scene_contacts, classify_impulse

__all__ = ["StuderExtrapolation"]

#: bound on the accepted and rejected macro steps of one run
MAX_MACRO_STEPS = 10**7


@register_integrator("studer-extrapolation")
class StuderExtrapolation(Integrator):
    """Moreau midpoint time stepping with step-size control and extrapolation.

    Parameters
    ----------
    scene : Scene
    t0, q0, v0, t_bound
        See :class:`~moreau.integrators.base.Integrator`.
    tol : float
        Local error tolerance, in ``(0, 1)``; positions and velocities are
        measured relative to ``1 + |y|``.
    columns : int
        Extrapolation columns ``K`` in ``[2, 8]``: the order in smooth phases.
    h0 : float, optional
        First macro step (default: ``(t_bound - t0) / 100``).
    h_min : float, optional
        Smallest macro step (default: ``1e-12 (t_bound - t0)``); a step that
        meets no tolerance at ``h_min`` is accepted and counted.
    lcp_method : {"auto", "lemke", "qp"}
    max_steps : int
        Bound on the macro steps (accepted and rejected) of the run.

    Examples
    --------
    A unit mass dropped from height 1 onto the ground with ``e = 1`` is back at
    height 1 at ``t = 2 sqrt(2)``:

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.scenes.base import Scene
    >>> class Drop(Scene):
    ...     ndof, mu, restitution = 1, np.array([0.0]), np.array([1.0])
    ...     def mass(self, q): return np.eye(1)
    ...     def forces(self, q, v, t): return np.array([-1.0])
    ...     def gaps(self, q, t): return np.array([q[0]])
    ...     def contact_jacobians(self, q, t):
    ...         return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)
    >>> res = simulate(Drop(), (0.0, 2 * np.sqrt(2)), [1.0], [0.0], "studer-extrapolation",
    ...                tol=1e-8)
    >>> bool(abs(res.q[-1, 0] - 1.0) < 1e-6)
    True
    """

    compare_settings = ("tol", (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9), (1e-4, 1e-7), {})

    def __init__(self, scene, t0, q0, v0, t_bound, tol=1e-6, columns=4, h0=None, h_min=None,
                 lcp_method="auto", max_steps=MAX_MACRO_STEPS):
        super().__init__(scene, t0, q0, v0, t_bound)
        self.tol = in_open_interval("tol", tol, 0.0, 1.0)
        if isinstance(columns, bool) or not isinstance(columns, (int, np.integer)) \
                or not 2 <= columns <= 8:
            raise InputError(f"`columns` must be a whole number in [2, 8], got {columns!r}")
        self.columns = int(columns)
        span = self.t_bound - self.t0
        self.h = span / 100.0 if h0 is None else positive("h0", h0)
        self.h_min = 1e-12 * span if h_min is None else positive("h_min", h_min)
        self.lcp_method, _ = check_lcp_options(lcp_method)
        self.max_steps = positive_int("max_steps", max_steps)
        self.mu_c, self.e_c = check_scene_contacts(scene)
        nc = scene.ncontacts
        self._trow = np.full(nc, -1, dtype=int)
        self._trow[scene.frictional_index] = np.arange(len(scene.frictional_index))
        self.counters = {"steps": 0, **new_contact_counters(), "base_steps": 0,
                         "rejected_steps": 0, "smooth_steps": 0, "forced_steps": 0,
                         "max_penetration": 0.0}
        self._macro = 0
        self._pending_initial = True
        self._last_config = None

    # -- the base step ---------------------------------------------------------------------
    def _midpoint(self, t, q, v, h):
        """One Moreau midpoint step: ``(q+, v+, config, pN, pT, slip, impact)``."""
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
        impact = False
        self.counters["base_steps"] += 1
        if nc:
            g = np.asarray(sc.gaps(qm, tm), float)
            active = g <= 0.0
            if active.any():
                ia = np.flatnonzero(active)
                fa = ia[self._trow[ia] >= 0]
                tr = self._trow[fa]
                WN, wN, WT, wT = (np.asarray(x, float) for x in sc.contact_jacobians(qm, tm))
                vN_pre = (WN @ v + wN)[ia]
                H = np.vstack([WN[ia], WT[tr]])
                MinvHT = np.linalg.solve(M, H.T)
                W = H @ MinvHT
                U_free = H @ v_free + np.concatenate([wN[ia], wT[tr]])
                p, pn, pt = solve_contact_problem(W, U_free, self.mu_c[ia], self.e_c[ia], vN_pre,
                                                  lcp_method=self.lcp_method,
                                                  counters=self.counters, t=t)
                pN[ia], pT[ia] = pn, pt
                v1 = v_free + MinvHT @ p
                slip[fa] = (U_free + W @ p)[ia.size:]
                # an impact: a contact closing with a finite approach speed (not a
                # persistent contact, whose approach speed is O(h))
                vscale = 1.0 + float(np.max(np.abs(v)))
                impact = bool(np.any((pn > 0.0) & (vN_pre < -1e-6 * vscale)
                                     & (np.abs(vN_pre) > 10.0 * h * vscale)))
        q1 = qm + 0.5 * h * v1
        missed = False
        if nc:
            # a contact open at the midpoint but closed at the end: the step crossed an
            # impact it did not see (the step must be refused, whatever the estimate)
            g1 = np.asarray(sc.gaps(q1, t + h), float)
            missed = bool(np.any((g1 < 0.0) & ~active))
        config = tuple(int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc))
        if missed:
            config = None
        return q1, v1, config, pN, pT, slip, impact or missed

    def _sequence(self, t, q, v, H, n):
        """``n`` base steps over ``H``: the end state, whether the configuration held, impulses."""
        h = H / n
        config0 = None
        smooth = True
        missed = False
        pN_sum = pT_sum = 0.0
        slip = None
        for i in range(n):
            q, v, config, pN, pT, slip, impact = self._midpoint(t + i * h, q, v, h)
            missed = missed or config is None
            if i == 0:
                config0 = config
            smooth = smooth and not impact and config == config0
            pN_sum = pN_sum + pN
            pT_sum = pT_sum + pT
        # config0 None: some base step crossed an impact unseen
        return (np.concatenate([q, v]), smooth and not missed, None if missed else config0,
                pN_sum, pT_sum, slip, config)

    def _error(self, a, b, y):
        return float(np.max(np.abs(a - b) / (self.tol * (1.0 + np.abs(y)))))

    def _step_impl(self):
        sc = self.scene
        n = sc.ndof
        t, q, v = self.t, self.q, self.v
        c = self.counters
        while True:
            self._macro += 1
            if self._macro > self.max_steps:
                self.counters["steps"] -= 1
                self._fail(-5, f"more than `max_steps` = {self.max_steps} macro steps; "
                               f"raise it or loosen `tol`")
                return
            H = min(self.h, self.t_bound - t)
            last = t + H >= self.t_bound - 1e-12 * max(1.0, abs(self.t_bound))
            K = self.columns
            T = [self._sequence(t, q, v, H, j) for j in (1, 2)]
            if (T[0][2] is None or T[1][2] is None) and H > self.h_min:
                # an impact crossed unseen: shrink until a midpoint lands in the contact
                c["rejected_steps"] += 1
                self.h = max(self.h_min, 0.25 * H)
                continue
            # smooth: every base step keeps the configuration the last accepted step
            # ended in (a block that stops inside a step sticks in every base step of it,
            # but it slid before)
            smooth = (T[0][1] and T[1][1] and T[0][2] == T[1][2]
                      and T[0][2] == self._last_config)
            if smooth:
                for j in range(3, K + 1):
                    T.append(self._sequence(t, q, v, H, j))
                    if not (T[-1][1] and T[-1][2] == T[0][2]):
                        smooth = False
                        break
            if smooth:
                # Aitken-Neville on n_j = j: row j holds T_{j,1..j} (1-based)
                rows = {}
                for j in range(1, K + 1):
                    row = [T[j - 1][0]]
                    for k in range(2, j + 1):
                        prev_row = rows[j - 1]
                        ratio = j / (j - k + 1)
                        row.append(row[k - 2] + (row[k - 2] - prev_row[k - 2]) / (ratio - 1.0))
                    rows[j] = row
                y = rows[K][K - 1]
                err = self._error(y, rows[K][K - 2], y)
                order = K
                rec = T[-1]
            else:
                y = T[1][0]
                err = self._error(y, T[0][0], y)
                order = 1
                rec = T[1]
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
        t1 = self.t_bound if last else t + H
        q1, v1 = y[:n].copy(), y[n:].copy()
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            self.counters["steps"] -= 1
            self._fail(-5, f"non-finite state after the step at t = {t!r}")
            return
        nc = sc.ncontacts
        gap = np.asarray(sc.gaps(q1, t1), float) if nc else np.zeros(0)
        if nc:
            c["max_penetration"] = max(c["max_penetration"], float(np.max(-gap, initial=0.0)))
        _, _, _, pN, pT, slip, self._last_config = rec
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)])
        fN, fT = np.asarray(pN, float) / H * np.ones(nc), np.asarray(pT, float) / H * np.ones(nc)
        if self._pending_initial:
            g0 = np.asarray(sc.gaps(q, t), float) if nc else gap
            self._record(t, q, v, regime, fN, fT, slip, g0)
            self._pending_initial = False
        self.t, self.q, self.v = t1, q1, v1
        self._record(t1, q1, v1, regime, fN, fT, slip, gap)
        if math.isnan(err):
            self._fail(-5, f"the error estimate is NaN at t = {t!r}")
