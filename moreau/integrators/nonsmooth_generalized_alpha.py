r"""The nonsmooth generalized-α scheme: second order in free flight and in persistent contact.

After Chen, Acary, Virlez & Brüls (IJNME 2013), with the position-level
constraint of Brüls, Acary & Cardona (CMAME 2014) and the split of the
contact percussion into a smooth force and an impulse with Coulomb friction
as in Capobianco, Harsch, Eugster & Leine (IJNME 2021).

The split
---------
The equations of motion with contact are the measure equation
``M dv = h dt + H^T dP`` (``H`` the normal rows ``WN`` of the contacts and
the tangential rows ``WT`` of the frictional ones). The percussion measure
is split as ``dP = lambda dt + Lambda deta``: a smooth contact force
``lambda`` (a persistent contact pressing, sliding or sticking) and atoms
``Lambda`` (impacts). The velocity splits accordingly into a smooth part,
integrated by the Chung–Hulbert generalized-α method with ``lambda`` inside
its acceleration, and jumps caused by ``Lambda``; a position correction ``U``
keeps the gaps admissible.

One step from ``(q_n, v_n, a_n, acc_n)`` (``a`` the algorithmic
acceleration, ``acc`` the smooth one, contact forces included) has three
stages.

*1. Smooth stage* (unknowns ``acc_{n+1}`` and ``lambda_{n+1}``)::

    (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) acc_{n+1} + alpha_f acc_n
    q*  = q_n + h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
    v*  = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
    M(q*) acc_{n+1} = h(q*, v*, t_{n+1}) + H(q*)^T lambda_{n+1}

with, on the contacts ``B`` that were closed at the end of the previous
step (they carried a smooth force or an impulse), the contact law at
velocity level on the smooth velocity: ``0 <= U_N(q*, v*) _|_ lambda_N >= 0``
and Coulomb's law between ``lambda_T`` and ``U_T(q*, v*)`` (``U = H v + w``,
at ``t_{n+1}``). It is solved by Newton's method on ``acc_{n+1}`` with the
contact problem inside each iteration. Derivation: with ``c = (1 - alpha_f) /
(1 - alpha_m)`` a change ``dx`` of ``acc_{n+1}`` changes ``a_{n+1}`` by ``c dx``,
``q*`` by ``h^2 beta c dx`` and ``v*`` by ``k dx``, ``k = h gamma c``. The
linearised residual ``M x - h - H^T lambda`` has the Jacobian
``J = M - c (h^2 beta K + h gamma C)`` (``K, C`` the force Jacobians), so
``dx = J^-1 (h - M x + H^T lambda)`` and the contact velocities after the
iteration are affine in ``lambda``::

    U = U_free + W lambda,  W = k H J^-1 H^T,
    U_free = H (v* + k J^-1 (h - M x)) + w,

the contact problem of
:func:`~moreau.integrators.contact_problem.solve_contact_problem` with
``e = 0``: in ``lambda`` instead of an impulse. With linear forces and a
constant ``H`` one iteration is exact.

*2. Impulsive stage* (unknowns ``Lambda``). The contacts of ``B`` and those
whose predicted gap ``g(q*, t_{n+1})`` is ``<= 1e-12`` form a velocity-level
problem with Newton's law and Coulomb friction on ``U = H v_{n+1} + w``,
``v_{n+1} = v* + M^-1 H^T Lambda``, the pre-step normal velocity
``WN(q_n) v_n + wN(t_n)`` in the restitution term, Jacobians at
``(q*, t_{n+1})``. On a persistent contact ``v*`` already satisfies it, and
``Lambda = 0``: an impulse appears only at an impact (or at a closing
contact), which is therefore first order. The stage is skipped when every
active contact carries a smooth normal force.

*3. Position stage* (``position_level=True``, unknowns ``nu``):
``q_{n+1} = q* + M^-1 WN^T nu`` with ``g(q_{n+1}) = 0`` on the contacts that
carry a smooth normal force (``lambda_N > 0``: no drift either way) and
``0 <= g(q_{n+1}) _|_ nu >= 0`` on the other active ones, linearised at
``q*`` and iterated (Gauss–Newton, the equality rows eliminated by a Schur
complement and the rest a frictionless LCP, at most 8 times) until every gap
is within ``1e-14``. On a persistent contact ``nu`` is of the size of the
generalized-α method's local error in the gap, ``O(h^3)``, and does not
lower the order.

*Why second order.* In a phase where ``B`` and the friction regimes do not
change, stages 2 and 3 vanish (to ``O(h^3)``) and stage 1 is the
generalized-α method on the velocity-level (index-2) form of the
constrained equations with the friction law, second order in ``q`` and
``v`` (Arnold, Brüls & Cardona, Numer. Math. 2015) provided the start
acceleration is consistent. So the first ``acc_0 = a_0`` carries the contact
forces of the contacts closed at ``t_0``
(:func:`consistent_acceleration`: their problem at acceleration level with
the drift terms ``wbar``); an inconsistent ``a_0`` (the contact-free
acceleration) would put an ``O(1)`` transient into ``lambda`` and an ``O(h)``
error into the friction impulse. Without the smooth stage (the scheme
before, where a pressing contact's force entered through ``Lambda / h``)
a block sliding under smooth forcing converged at order 0.97; with it at
2.00 (``tests/integrators/test_nonsmooth_generalized_alpha.py``).

Impacts, contact closing and friction switches (slip reversal, stick–slip)
stay first order: the switch falls inside a step.

The coefficients come from the spectral radius at infinity ``rho_inf`` in
``[0, 1]``: ``alpha_m = (2 rho - 1) / (rho + 1)``, ``alpha_f = rho / (rho + 1)``,
``gamma = 1/2 + alpha_f - alpha_m``, ``beta = (gamma + 1/2)^2 / 4``
(second order, unconditionally stable for linear problems, ``rho_inf = 1``
is the undamped trapezoidal rule). Without the position stage
(``position_level=False``) the positions are the generalized-α ones, which
penetrate by ``O(h^2)`` at each impact.

The recorded contact force of a step is its whole percussion over the
step, ``lambda + Lambda / h``, and its regime is classified from it.
"""

import dataclasses
from typing import ClassVar

import numpy as np

from .._validate import in_closed_interval
from ..errors import ConvergenceError, LCPError
from ..lcp import solve_lcp
from ._mj_kernels import LCP_HANDBACK, PAINLEVE
from ._nsga_kernels import CONVERGENCE, nsga_loop
from .base import register_integrator
from .contact_problem import new_contact_counters, slip_signs, solve_contact_problem
from .moreau_jean import classify_impulse
from .time_stepping import FixedStepOptions, TimeStepping, next_time

__all__ = ["NonsmoothGeneralizedAlpha", "alpha_coefficients", "consistent_acceleration",
           "contact_drift_of", "mixed_projection"]

# the smooth Newton iteration stops at this relative change of the acceleration
NEWTON_RTOL = 1e-12
NEWTON_MAXITER = 25
# the position correction stops when every corrected gap is above -this
POSITION_TOL = 1e-14
# a predicted gap below this counts as closed: after a corrected impact the flight is
# symmetric and the next impact lands on the floor on a grid time, where rounding alone
# would otherwise decide between contact and flight (and change the energy lost)
CONTACT_TOL = 1e-12
POSITION_MAXITER = 8
# central-difference step of the drift terms of a scene without contact_drift
DRIFT_STEP = 1e-6


def alpha_coefficients(rho_inf):
    """``(alpha_m, alpha_f, gamma, beta)`` of the generalized-α method for ``rho_inf``.

    Examples
    --------
    >>> alpha_coefficients(1.0)
    (0.5, 0.5, 0.5, 0.25)
    """
    rho = float(rho_inf)
    am = (2.0 * rho - 1.0) / (rho + 1.0)
    af = rho / (rho + 1.0)
    gamma = 0.5 + af - am
    beta = 0.25 * (gamma + 0.5) ** 2
    return am, af, gamma, beta


@register_integrator("nonsmooth-generalized-alpha")
class NonsmoothGeneralizedAlpha(TimeStepping):
    """Nonsmooth generalized-α time stepping (see the module docstring).

    Parameters
    ----------
    rho_inf : float
        Spectral radius at infinity, in ``[0, 1]`` (default 0.9: mild damping
        of the highest modes).
    position_level : bool
        Correct positions onto the admissible set (no penetration, no drift).
    scene, t0, q0, v0, t_bound, options, h, lcp_method, save_every, fast, max_steps, painleve
        As for every fixed-step scheme: :class:`~moreau.integrators.time_stepping.FixedStepOptions`.

    Examples
    --------
    A unit mass on a unit spring, far from its one contact: second order.

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.model.examples import Spring
    >>> err = [abs(simulate(Spring(), (0.0, 2.0), [1.0], [0.0], "nonsmooth-generalized-alpha",
    ...                     h=h).q[-1, 0] - np.cos(2.0)) for h in (0.02, 0.01)]
    >>> round(float(np.log2(err[0] / err[1])))
    2
    """

    compare_settings = ("steps_per_period", (50, 100, 200, 500, 1000, 2000, 5000),
                        (100, 300, 1000), {})

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class Options(FixedStepOptions):
        """Options of :class:`NonsmoothGeneralizedAlpha` (those of every fixed-step scheme,
        :class:`~moreau.integrators.time_stepping.FixedStepOptions`, and its own)."""
        rho_inf: float = 0.9
        position_level: bool = True

        _rules: ClassVar[dict] = {"rho_inf": lambda v: in_closed_interval("rho_inf", v, 0.0, 1.0)}

        def smooth_order(self):
            return 2

    def _new_counters(self):
        return {"steps": 0, **new_contact_counters(), "max_penetration": 0.0,
                "newton_iterations": 0, "position_iterations": 0}

    def _setup_scheme(self):
        self.am, self.af, self.gamma, self.beta = alpha_coefficients(self.rho_inf)
        # a consistent start: the algorithmic acceleration carries the closed contacts'
        # forces, else its O(1) error feeds an O(h) error into the friction forces
        acc0, lam0 = consistent_acceleration(self.scene, self.q, self.v, self.t0,
                                             self.lcp_method, self.counters)
        self._closed = lam0 > 0.0
        self._acc = acc0
        self._a = acc0.copy()
        self._coef = np.array([self.am, self.af, self.gamma, self.beta])

    def _fast_block(self):
        q, v, a, acc = self.q.copy(), self.v.copy(), self._a.copy(), self._acc.copy()
        closed = self._closed.copy()
        status = self._run_block(nsga_loop, (q, v, (self._coef, bool(self.position_level)),
                                             (a, acc, closed)), (self._lcp_ctl,))
        self.q, self.v, self._a, self._acc, self._closed = q, v, a, acc, closed
        self._after_block(status, handback=(LCP_HANDBACK, PAINLEVE, CONVERGENCE),
                          singular="a singular mass or iteration matrix at t = {t!r}")

    def _smooth(self, q, v, a, acc, t1, h, closed):
        """The smooth stage: Newton on ``acc_{n+1}`` with the smooth contact forces of ``closed``.

        Returns ``(q*, v*, a_{n+1}, acc_{n+1}, lamN, lamT, slip)``: the smooth forces
        per contact (zero outside ``closed``) and the slip velocities at ``v*``.
        """
        sc = self.scene
        am, af, gamma, beta = self.am, self.af, self.gamma, self.beta
        c = (1.0 - af) / (1.0 - am)
        kv = h * gamma * c      # d v* / d acc_{n+1}
        nc = sc.ncontacts
        ib = np.flatnonzero(closed)
        fb = ib[self._trow[ib] >= 0] if ib.size else ib
        tr = self._trow[fb]
        lamN = np.zeros(nc)
        lamT = np.zeros(nc)
        slip = np.zeros(nc)
        x = acc.copy()
        for it in range(1, NEWTON_MAXITER + 1):
            a1 = c * x + (af * acc - am * a) / (1.0 - am)
            qs = q + h * v + h * h * (0.5 - beta) * a + h * h * beta * a1
            vs = v + h * (1.0 - gamma) * a + h * gamma * a1
            M = np.asarray(sc.mass(qs), float)
            f = np.asarray(sc.forces(qs, vs, t1), float)
            K, C = (np.asarray(m, float) for m in sc.force_jacobians(qs, vs, t1))
            J = M - c * (h * h * beta * K + h * gamma * C)
            dx = np.linalg.solve(J, f - M @ x)
            if ib.size:
                WN, wN, WT, wT = (np.asarray(y, float) for y in sc.contact_jacobians(qs, t1))
                H = np.vstack([WN[ib], WT[tr]])
                JiHT = np.linalg.solve(J, H.T)
                # the contact velocities at v*(x + dx) are affine in the smooth forces
                W = kv * (H @ JiHT)
                U_free = H @ (vs + kv * dx) + np.concatenate([wN[ib], wT[tr]])
                # Newton iterates: the check only stops (painleve="stop")
                stop = self.painleve == "stop"
                lam, ln, lt = solve_contact_problem(W, U_free, self.mu_c[ib], np.zeros(ib.size),
                                                    np.zeros(ib.size),
                                                    lcp_method=self.lcp_method,
                                                    counters=self.counters, t=self.t,
                                                    painleve=self.painleve,
                                                    slip_before=(slip_signs(self._prev_reg[ib])
                                                                 if stop else None),
                                                    warm=self._lcp_warm("newton"),
                                                    warm_key=tuple(ib.tolist()))
                dx = dx + JiHT @ lam
                lamN[ib], lamT[ib] = ln, lt
                slip[fb] = (U_free + W @ lam)[ib.size:]
            x = x + dx
            self.counters["newton_iterations"] += 1
            if np.max(np.abs(dx)) <= NEWTON_RTOL * max(1.0, np.max(np.abs(x))):
                a1 = c * x + (af * acc - am * a) / (1.0 - am)
                qs = q + h * v + h * h * (0.5 - beta) * a + h * h * beta * a1
                vs = v + h * (1.0 - gamma) * a + h * gamma * a1
                return qs, vs, a1, x, lamN, lamT, slip
        raise ConvergenceError(f"the smooth Newton iteration did not converge in "
                               f"{NEWTON_MAXITER} iterations at t = {self.t!r}")

    def _correct_positions(self, q, t, cand, held):
        """``q + M^-1 WN^T nu`` onto the candidate contacts' gaps.

        ``0 <= g _|_ nu >= 0`` on ``cand``, except ``g = 0`` (``nu`` of either
        sign) on ``held``, the contacts that carry a smooth normal force.
        """
        sc = self.scene
        M = np.asarray(sc.mass(q), float)
        ic = np.flatnonzero(cand)
        eq = held[ic]
        for _ in range(POSITION_MAXITER):
            g = np.asarray(sc.gaps(q, t), float)[ic]
            if np.min(g, initial=np.inf) >= -POSITION_TOL and \
                    np.max(np.abs(g[eq]), initial=0.0) <= POSITION_TOL:
                break
            WN = np.asarray(sc.contact_jacobians(q, t)[0], float)[ic]
            MinvWT = np.linalg.solve(M, WN.T)
            nu = mixed_projection(WN @ MinvWT, g, eq,
                                  method="lemke" if self.lcp_method != "qp" else "qp", t=t)
            q = q + MinvWT @ nu
            self.counters["position_iterations"] += 1
        return q

    def _step_impl(self):
        if self._fast:
            return self._fast_block()
        return self._generic_step()

    def _generic_step(self):
        sc = self.scene
        t0, q, v = self.t, self.q, self.v
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)
        qs, vs, a1, acc1, lamN, lamT, slip = self._smooth(q, v, self._a, self._acc, t1, h,
                                                          self._closed)
        nc = sc.ncontacts
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        v1, q1 = vs, qs
        if nc:
            gs = np.asarray(sc.gaps(qs, t1), float)
            active = (gs <= CONTACT_TOL) | self._closed
            held = lamN > 0.0
            # a contact carrying a smooth normal force meets its law at v* already: the
            # impulse problem is solved only when an active contact carries none
            if (active & ~held).any():
                ia = np.flatnonzero(active)
                fa = ia[self._trow[ia] >= 0]
                tr = self._trow[fa]
                WN0, wN0, _, _ = sc.contact_jacobians(q, t0)
                vN0 = (np.asarray(WN0, float) @ v + np.asarray(wN0, float))[ia]
                WN, wN, WT, wT = (np.asarray(x, float) for x in sc.contact_jacobians(qs, t1))
                H = np.vstack([WN[ia], WT[tr]])
                MinvHT = np.linalg.solve(np.asarray(sc.mass(qs), float), H.T)
                W = H @ MinvHT
                U_free = H @ vs + np.concatenate([wN[ia], wT[tr]])
                p, pn, pt = solve_contact_problem(W, U_free, self.mu_c[ia], self.e_c[ia], vN0,
                                                  lcp_method=self.lcp_method,
                                                  counters=self.counters, t=t0,
                                                  slip_before=slip_signs(self._prev_reg[ia]),
                                                  painleve=self.painleve,
                                                  warm=self._lcp_warm("impulse"),
                                                  warm_key=tuple(ia.tolist()))
                pN[ia], pT[ia] = pn, pt
                v1 = vs + MinvHT @ p
                slip[fa] = (U_free + W @ p)[ia.size:]
            if self.position_level and active.any():
                q1 = self._correct_positions(qs, t1, active, held)
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            self.counters["steps"] -= 1
            self._fail(-5, f"non-finite state after the step at t = {t0!r}")
            return
        gap = self._end_gaps(q1, t1, nc)
        # the step's whole percussion: smooth force over the step plus the impulse
        PN, PT = h * lamN + pN, h * lamT + pT
        regime = np.array([int(classify_impulse(PN[i], PT[i], self.mu_c[i]))
                           for i in range(nc)])
        self._prev_reg = regime
        self._closed = (pN > 0.0) | (lamN > 0.0)
        self._k += 1
        fN, fT = PN / h, PT / h
        if self._pending_initial:
            g0 = np.asarray(sc.gaps(q, t0), float) if nc else gap
            self._record(t0, q, v, regime, fN, fT, slip, g0)
            self._pending_initial = False
        self.t, self.q, self.v = t1, q1, v1
        self._a, self._acc = a1, acc1
        if self._k % self.save_every == 0 or t1 >= self.t_bound:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)


def contact_drift_of(scene, q, v, t):
    """``(wNbar, wTbar)`` of ``scene`` at ``(q, v, t)``: its own, or central differences.

    A scene without :meth:`~moreau.model.scene.Scene.contact_drift` gets the
    derivative of its contact velocities ``W(q + s v, t + s) v + w`` at
    ``s = 0`` by a central difference (``s = 1e-6``: an error of about
    ``1e-11``, far below what the consistent start acceleration needs, which
    is ``O(h)``).
    """
    try:
        wNb, wTb = scene.contact_drift(q, v, t)
        return np.asarray(wNb, float), np.asarray(wTb, float)
    except NotImplementedError:
        pass
    s = DRIFT_STEP * max(1.0, float(np.max(np.abs(q), initial=0.0)))

    def rates(ds):
        WN, wN, WT, wT = (np.asarray(x, float) for x in scene.contact_jacobians(q + ds * v, t + ds))
        return WN @ v + wN, WT @ v + wT

    (np_, tp), (nm, tm) = rates(s), rates(-s)
    return (np_ - nm) / (2.0 * s), (tp - tm) / (2.0 * s)


def consistent_acceleration(scene, q, v, t, lcp_method="auto", counters=None):
    """The start acceleration with the smooth contact forces of the closed contacts.

    The contacts that are closed (gap ``<= 1e-12``) and not separating or
    approaching (``|v_N| <= 1e-12``) carry a force ``lambda`` found at
    acceleration level: ``0 <= WN acc + wNbar _|_ lambda_N >= 0``; a sliding
    contact (``|v_T| > 1e-12``) has ``lambda_T = -mu lambda_N sign(v_T)``, a
    sticking one Coulomb's law on ``WT acc + wTbar``; ``M acc = h + H^T lambda``.

    Returns ``(acc, lamN)``, ``lamN`` the normal forces of every contact (zero
    on the others).

    A sliding contact in a Painlevé configuration with no consistent force
    (its normal-force coefficient ``WN M^-1 (WN - mu s WT)^T <= 0`` while the
    free motion presses it) has no smooth start: the state needs an impulse,
    the tangential impact. Such contacts get no smooth force here, and the
    first step's impulsive stage takes the jam (the velocity-level problem,
    which always has a solution).

    Examples
    --------
    A block sliding on level ground: the contact carries its weight and brakes it by mu = 0.3:

    >>> from moreau.model.registry import make_scene
    >>> acc, lamN = consistent_acceleration(make_scene("sliding-block"), np.zeros(2),
    ...                                     np.array([1.0, 0.0]), 0.0)
    >>> acc.round(12).tolist(), lamN.round(12).tolist()
    ([-0.3, 0.0], [1.0])
    """
    M = np.asarray(scene.mass(q), float)
    f = np.asarray(scene.forces(q, v, t), float)
    nc = scene.ncontacts
    lamN = np.zeros(nc)
    if nc == 0:
        return np.linalg.solve(M, f), lamN
    mu = np.asarray(scene.mu, float).reshape(-1)
    g = np.asarray(scene.gaps(q, t), float)
    WN, wN, WT, wT = (np.asarray(x, float) for x in scene.contact_jacobians(q, t))
    fi = np.asarray(scene.frictional_index, int)
    trow = np.full(nc, -1, dtype=int)
    trow[fi] = np.arange(fi.size)
    vN = WN @ v + wN
    ib = np.flatnonzero((g <= CONTACT_TOL) & (np.abs(vN) <= CONTACT_TOL))
    if ib.size == 0:
        return np.linalg.solve(M, f), lamN
    vT = np.zeros(nc)
    vT[fi] = WT @ v + wT
    wNb, wTb = contact_drift_of(scene, q, v, t)
    sliding = np.array([trow[i] >= 0 and abs(vT[i]) > CONTACT_TOL for i in ib], dtype=bool)
    stick = ib[(trow[ib] >= 0) & ~sliding]
    # columns: a sliding contact's force acts along WN - mu sign(vT) WT, with one unknown
    cols = [WN[i] - (mu[i] * np.sign(vT[i]) * WT[trow[i]] if s else 0.0)
            for i, s in zip(ib, sliding)]
    G = np.vstack(cols + [WT[trow[i]] for i in stick])
    H = np.vstack([WN[ib]] + [WT[trow[i]][None, :] for i in stick])
    MiGT = np.linalg.solve(M, G.T)
    U_free = H @ np.linalg.solve(M, f) + np.concatenate([wNb[ib],
                                                         [wTb[trow[i]] for i in stick]])
    mu_eff = np.where(sliding, 0.0, mu[ib])
    A = H @ MiGT
    paradox = np.array([s and A[k, k] <= 0.0 for k, s in enumerate(sliding)], dtype=bool)
    if paradox.any():
        # the acceleration-level problem of a sliding contact whose normal-force
        # coefficient is not positive has no solution or several: leave it to the
        # impulsive stage (see the docstring), and solve for the others
        keep = ~paradox
        rows = np.concatenate([keep, np.ones(stick.size, dtype=bool)])
        ib, A, U_free, G, mu_eff = ib[keep], A[np.ix_(rows, rows)], U_free[rows], G[rows], mu_eff[keep]
        if ib.size == 0:
            return np.linalg.solve(M, f), lamN
    lam, ln, _ = solve_contact_problem(A, U_free, mu_eff, np.zeros(ib.size),
                                       np.zeros(ib.size), lcp_method=lcp_method,
                                       counters=counters, t=t)
    lamN[ib] = ln
    return np.linalg.solve(M, f + G.T @ lam), lamN


def mixed_projection(W, g, eq, method="lemke", t=None):
    """``nu`` with ``W nu + g = 0`` on the rows ``eq`` and ``0 <= W nu + g _|_ nu >= 0`` elsewhere.

    The equality rows are eliminated (a Schur complement, positive
    semidefinite for a positive semidefinite ``W``) and the rest is an LCP
    solved by :func:`moreau.lcp.solve_lcp`.

    Examples
    --------
    >>> mixed_projection(np.eye(2), np.array([0.5, 0.5]), np.array([True, False])).tolist()
    [-0.5, 0.0]
    """
    nu = np.zeros(g.size)
    e = np.flatnonzero(eq)
    u = np.flatnonzero(~eq)
    if e.size:
        Wee_inv = np.linalg.inv(W[np.ix_(e, e)])
        S = W[np.ix_(u, u)] - W[np.ix_(u, e)] @ Wee_inv @ W[np.ix_(e, u)]
        qs = g[u] - W[np.ix_(u, e)] @ Wee_inv @ g[e]
    else:
        S, qs = W, g
    if u.size:
        r = solve_lcp(S, qs, method=method)
        if not r.success:
            raise LCPError(f"the position correction at t = {t!r} was not solved: {r.message}")
        nu[u] = r.z
    if e.size:
        nu[e] = -Wee_inv @ (g[e] + W[np.ix_(e, u)] @ nu[u])
    return nu
