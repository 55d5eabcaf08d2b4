r"""Half-explicit time-discontinuous Galerkin time stepping on velocity level.

The scheme (Schindler & Acary, Math. Comput. Simul. 95, 2014; Schindler,
Rezaei, Kursawe & Acary, CMAME 290, 2015)
--------------------------------------------------------------------------
Moreau–Jean is the lowest member of a family: a Galerkin method in time on
velocity level whose trial velocities may jump at the left end of every step.
On a step ``I = (t_n, t_{n+1}]`` the measure differential inclusion
``M dv = f dt + H^T dP`` is tested with polynomials ``dv*`` of degree ``p``::

    int_I dv*^T (M v' - f - H^T lambda) dt  -  dv*(t_n+)^T (M (v_n+ - v_n-) - H^T P_n) = 0

where the contact measure ``dP = lambda dt + P_n delta(t_n)`` is split into
a force density inside the step and an impulse at its left end. The two parts
are propagated apart, which is the point of the family: a step with an impact
is first order whatever ``p``, and a smooth step is of the order of the
quadrature.

*Impulsive part.* The test function's value at ``t_n+`` gives
``M (v_n+ - v_n-) = H^T P_n`` with Newton's law
``0 <= U_N(v_n+) + e min(U_N(v_n-), 0) _|_ P_N >= 0`` and Coulomb's law on
the impulse: the contact problem of one Moreau–Jean step with zero step length
(:func:`moreau.integrators.contact_problem.solve_contact_problem`).

*Non-impulsive part.* With the velocity a polynomial of degree ``p``
interpolating at the ``p + 1`` Gauss–Lobatto nodes ``c_i`` of the step and
the integrals taken by the same Lobatto quadrature (weights ``b_i``), the
Galerkin equations become a collocation Runge–Kutta method with nodes ``c``
and weights ``b``. The *half-explicit* variant (2015) evaluates positions,
forces, the mass matrix and the contact directions at the stages already
computed, so that only the contact forces are implicit, one small contact
problem per stage::

    Q_i = q_n + h sum_{j<i} a_ij V_j
    V_i = v_n+ + h sum_{j<i} a_ij M_j^-1 (f_j + H_j^T lambda_j)
    0 <= U_N(Q_i, V_i) _|_ lambda_{N,i-1} >= 0,  lambda_{T,i-1} in -mu lambda_{N,i-1} Sign U_T(Q_i, V_i)

and the step ends with the quadrature, whose velocity fixes the last force::

    q_{n+1} = q_n + h sum_i b_i V_i,   v_{n+1} = v_n+ + h sum_i b_i M_i^-1 (f_i + H_i^T lambda_i)

with the same complementarity at ``(q_{n+1}, v_{n+1})`` for ``lambda_s``.
Each stage's problem is the contact problem of the module above with
``e = 0``: the impulse ``h a_{i,i-1} lambda_{i-1}`` acts along
``H_{i-1}^T`` (the stage where the force acts) and the velocity is measured
with ``H_i`` (the stage where the constraint holds), so the Delassus matrix
``H_i M_{i-1}^-1 H_{i-1}^T`` is not symmetric in general; Lemke's method
and the one-contact enumeration need no symmetry.

With ``p + 1`` Lobatto nodes and the explicit stage matrix ``a`` of the same
nodes, the non-impulsive part is an explicit Runge–Kutta method whose
weights are the Lobatto weights:

* ``degree=1`` (nodes 0, 1; trapezoidal weights): Heun's method, order 2;
* ``degree=2`` (nodes 0, 1/2, 1; Simpson weights): Kutta's method, order 3.

*Index set.* Contact ``i`` takes part in a step when it would close within
half a step at its present speed, ``g_i + (h/2) U_N,i <= 0`` (the rule of
Moreau–Jean), or when it carried a normal force in the step before. A
contact in the index set is held at velocity level: its gap does not drift
for a gap linear in ``q``, and drifts by the quadrature's error otherwise
(``O(h^{p+2})`` a step). That drift has no periodic orbit: on the friction
drive at 185 Hz and 400 steps a period the rod sank by 1.2e-11 a period and
shooting could not close. With ``projection=True`` (the default) a contact
that still carries a force at the end of a step has its gap put back to zero
by a Newton projection in the metric of ``M``, which moves the positions by
the drift only (the velocities already satisfy the constraint).

*What ``projection=False`` gives up.* Without the projection a contact is
held at velocity level only, where the index set caught it, and that need
not be on the surface. A contact enters the step's problem when
``g <= (h/2) |U_N|``; the step before, it was out, so ``g > (h/2) |U_N|``
there and one free step moved it by ``h |U_N| + O(h^2)``. A body arriving
at normal speed ``V`` is therefore stopped (``e = 0``), or starts to rest
after its bounces, at a gap ``|g| <= h V / 2 + O(h^2)``: hovering above the
surface or inside it, and it stays there, because a held contact keeps
``U_N = 0``. On the bouncing ball with ``e = 0`` (``V = sqrt 2``) the ball
rests at ``g = 5.95e-3 = 0.84 h V / 2`` with ``h = 1e-2``, at
``3.0e-4 = 0.43 h V / 2`` with ``h = 1e-3`` and at ``-1.1e-3`` (inside the
floor) with ``h = 5e-3``. The error is ``O(h)``, the scheme's order through
an impact, but it does not decay once the body rests: the rest position is
that of the step that caught the contact. With the projection the gap of a
contact that carries a force is put back to zero, so the contact closes.

Like every explicit scheme, the step must resolve the fastest smooth
oscillation; a run that blows up stops with a status.

On a scene with a compiled model the steps run in
:mod:`moreau.integrators._tdg_kernels` (equal to this module's step to
rounding): 1.2e6 steps/s at degree 1 and 9.1e5 at degree 2 on the bouncing
ball, 1.0e6 and 8.0e5 on the friction drive, two or three contact problems a
step in contact.
"""

import dataclasses
from typing import ClassVar

import numpy as np

from ..errors import InputError
from ._blocks import EXPLICIT_BLOWUP
from ._tdg_kernels import tdg_loop
from .base import register_integrator
from .contact_problem import new_contact_counters, slip_signs, solve_contact_problem
from .event_driven_generic import project_positions
from .moreau_jean import classify_impulse
from .time_stepping import FixedStepOptions, TimeStepping, next_time

__all__ = ["TimeDiscontinuousGalerkin", "LOBATTO_TABLEAUS"]

#: degree -> (nodes c, explicit stage matrix a, Lobatto weights b)
LOBATTO_TABLEAUS = {
    1: (np.array([0.0, 1.0]), np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([0.5, 0.5])),
    2: (np.array([0.0, 0.5, 1.0]), np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [-1.0, 2.0, 0.0]]),
        np.array([1.0, 4.0, 1.0]) / 6.0),
}


def _degree_option(degree):
    if isinstance(degree, bool) or degree not in LOBATTO_TABLEAUS:
        raise InputError(f"`degree` must be one of {sorted(LOBATTO_TABLEAUS)}, got {degree!r}")
    return int(degree)


@register_integrator("time-discontinuous-galerkin")
class TimeDiscontinuousGalerkin(TimeStepping):
    """Half-explicit time-discontinuous Galerkin stepping (see the module docstring).

    Parameters
    ----------
    degree : {1, 2}
        Polynomial degree of the velocity on a step: order ``degree + 1`` in
        smooth phases.
    lemke_max_iter : int, optional
        Pivot limit of Lemke's method.
    projection : bool
        Put the gaps of the contacts that carry a force at the end of a step
        back to zero (see the module docstring). With False a contact is
        held where the step caught it: a body at rest stays up to
        ``h V / 2`` above or inside the surface (``V`` its normal speed on
        arrival), an ``O(h)`` error that does not decay.
    scene, t0, q0, v0, t_bound, options, h, lcp_method, save_every, fast, max_steps, painleve
        As for every fixed-step scheme: :class:`~moreau.integrators.time_stepping.FixedStepOptions`.

    Notes
    -----
    Recorded forces are the step's whole contact impulse (the impact plus the
    quadrature of the stage forces) over the step; the slip velocity is the
    one enforced at the step's end; the gap is ``g(q_{n+1}, t_{n+1})``.

    Examples
    --------
    A unit mass on a unit spring, a quarter period, at degree 2 (third order):

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.model.examples import Spring
    >>> res = simulate(Spring(), (0.0, np.pi / 2), [1.0], [0.0], "time-discontinuous-galerkin",
    ...                h=np.pi / 200, degree=2)
    >>> bool(abs(res.q[-1, 0]) < 1e-6)
    True
    """

    compare_settings = ("steps_per_period", (50, 100, 200, 500, 1000, 2000, 5000, 10000),
                        (100, 300, 1000), {"degree": 2})

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class Options(FixedStepOptions):
        """Options of :class:`TimeDiscontinuousGalerkin` (those of every fixed-step scheme,
        :class:`~moreau.integrators.time_stepping.FixedStepOptions`, and its own)."""
        degree: int = 2
        lemke_max_iter: int | None = None
        projection: bool = True

        _rules: ClassVar[dict] = {"degree": _degree_option}

        def smooth_order(self):
            return self.degree + 1

    def _new_counters(self):
        return {"steps": 0, **new_contact_counters(), "max_penetration": 0.0,
                "projection_iterations": 0}

    # -- the pieces of one step ----------------------------------------------
    def _rows(self, ia, q, t, jac=None):
        """Stacked rows ``H`` (normal, then tangential of the frictional ones) and offsets ``w``.

        ``jac``: the scene's ``contact_jacobians(q, t)`` where the caller has them.
        """
        WN, wN, WT, wT = (np.asarray(x, dtype=float)
                          for x in (jac if jac is not None else self.scene.contact_jacobians(q, t)))
        fa = ia[self._trow[ia] >= 0]
        tr = self._trow[fa]
        return np.vstack([WN[ia], WT[tr]]), np.concatenate([wN[ia], wT[tr]]), fa

    def _solve(self, H_meas, w_meas, MinvHT, v_free, e, vN_pre, ia, t):
        """Impulse ``p`` (stacked rows) making ``H_meas v + w_meas`` obey the contact law."""
        W = H_meas @ MinvHT
        U_free = H_meas @ v_free + w_meas
        na = ia.size
        if np.all(U_free[:na] + e * np.minimum(vN_pre, 0.0) >= 0.0):
            # no contact needs to push: zero normal impulse bounds the friction to zero
            return np.zeros(U_free.size), U_free
        # a step solves several of these: the check only stops (painleve="stop")
        stop = self.painleve == "stop"
        p, _, _ = solve_contact_problem(W, U_free, self.mu_c[ia], e, vN_pre,
                                        lcp_method=self.lcp_method, counters=self.counters,
                                        lemke_max_iter=self.lemke_max_iter, t=t,
                                        slip_before=slip_signs(self._prev_reg[ia]) if stop else None,
                                        painleve=self.painleve, warm=self._lcp_warm("stage"),
                                        warm_key=tuple(ia.tolist()))
        return p, U_free + W @ p

    def _step_impl(self):
        if self._fast:
            return self._fast_block()
        return self._generic_step()

    def _fast_block(self):
        q, v, closed = self.q.copy(), self.v.copy(), self._closed.copy()
        c_st, a_st, b_st = LOBATTO_TABLEAUS[self.degree]
        status = self._run_block(tdg_loop, (q, v, (c_st, a_st, b_st, bool(self.projection)),
                                            (closed,)), (self._lcp_ctl,))
        self.q, self.v, self._closed = q, v, closed
        self._after_block(status, numerical=EXPLICIT_BLOWUP)

    def _generic_step(self):
        sc = self.scene
        t0, q, v = self.t, self.q, self.v
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)
        c, a, b = LOBATTO_TABLEAUS[self.degree]
        s = c.size
        nc = sc.ncontacts
        ia = np.zeros(0, dtype=int)
        if nc:
            g0 = np.asarray(sc.gaps(q, t0), dtype=float)
            jac0 = sc.contact_jacobians(q, t0)
            vN0 = np.asarray(jac0[0], dtype=float) @ v + np.asarray(jac0[1], dtype=float)
            ia = np.flatnonzero((g0 + 0.5 * h * vN0 <= 0.0) | self._closed)
        na = ia.size
        P_total = None
        U_end = None
        M = np.asarray(sc.mass(q), dtype=float)
        if na:
            # the impulsive part at t_n+: Newton's law on the pre-step velocities
            H, w, fa = self._rows(ia, q, t0, jac0)
            MinvHT = np.linalg.solve(M, H.T)
            P, _ = self._solve(H, w, MinvHT, v, self.e_c[ia], vN0[ia], ia, t0)
            v = v + MinvHT @ P
            P_total = P.copy()
        # the non-impulsive part: half-explicit Runge–Kutta on the Lobatto nodes
        Q = [q]
        V = [v]
        acc = [np.linalg.solve(M, np.asarray(sc.forces(q, v, t0), dtype=float))]
        dirs = [MinvHT] if na else []   # M_j^-1 H_j^T of each stage
        lam = []                        # contact force of each stage (stacked rows)
        for i in range(1, s + 1):
            last = i == s
            coef = b if last else a[i]
            ti = t1 if last else t0 + c[i] * h
            qi = q + h * sum(coef[j] * V[j] for j in range(i))
            vi = v + h * sum(coef[j] * acc[j] for j in range(i))
            if na:
                vi = vi + h * sum(coef[j] * (dirs[j] @ lam[j]) for j in range(i - 1))
                Hi, wi, _ = self._rows(ia, qi, ti)
                k = h * coef[i - 1]
                # the force of stage i-1 is fixed by the constraint at stage i
                P, U = self._solve(Hi, wi, dirs[i - 1], vi, np.zeros(na), np.zeros(na), ia, ti)
                vi = vi + dirs[i - 1] @ P
                lam.append(P / k)
                if last:
                    U_end = U
            if last:
                q1, v1 = qi, vi
                break
            Mi = np.asarray(sc.mass(qi), dtype=float)
            Q.append(qi)
            V.append(vi)
            acc.append(np.linalg.solve(Mi, np.asarray(sc.forces(qi, vi, ti), dtype=float)))
            if na:
                dirs.append(np.linalg.solve(Mi, Hi.T))
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            self._fail(-5, EXPLICIT_BLOWUP.format(t=t0, h=h))
            self.counters["steps"] -= 1     # the base class counts this failed step
            return
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        slip = np.zeros(nc)
        if na:
            P_total = P_total + h * sum(b[j] * lam[j] for j in range(s))
            pN[ia] = P_total[:na]
            pT[fa] = P_total[na:]
            slip[fa] = U_end[na:]
            held = ia[lam[-1][:na] > 0.0]
            if self.projection and held.size:
                q1 = project_positions(sc, t1, q1, held)
        gap = self._end_gaps(q1, t1, nc)
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)])
        self._prev_reg = regime
        self._closed = pN > 0.0
        self._k += 1
        fN, fT = pN / h, pT / h
        if self._pending_initial:
            g0r = np.asarray(sc.gaps(self.q, t0), dtype=float) if nc else gap
            # the first step's regime and forces, as every time-stepping scheme records its
            # start (no step has ended there)
            self._record(t0, self.q, self.v, regime, fN, fT, slip, g0r)
            self._pending_initial = False
        self.t, self.q, self.v = t1, q1, v1
        if self._k % self.save_every == 0 or t1 >= self.t_bound:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)
