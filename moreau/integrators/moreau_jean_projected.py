"""Moreau–Jean with a direct projection of the positions onto ``g >= 0`` after each step.

The scheme of Siconos's ``MoreauJeanDirectProjectionOSI`` (V. Acary,
*Projected event-capturing time-stepping schemes for nonsmooth mechanical
systems with unilateral contact and Coulomb's friction*, CMAME 256 (2013)
224-250): a Moreau–Jean step (:mod:`moreau.integrators.moreau_jean`, the
same velocity update, index set, contact problem and regimes), then the
positions alone are moved back onto the admissible set.

*The projection.* With ``q~`` the step's position, ``M = M(q~)`` and the
gaps ``g`` of the contacts, the new position is the mass-weighted nearest
admissible point,

    min_q  1/2 (q - q~)^T M (q - q~)   subject to  g(q) >= 0,

solved by Gauss–Newton on the linearised constraints. At an iterate ``q_j``
with gaps ``g_j`` and normal rows ``WN_j = dg/dq(q_j)`` (restricted to the
set ``A`` of the contacts that penetrate, kept from one iterate to the
next), the subproblem ``min 1/2 dq^T M dq`` with ``g_j + WN_j dq >= 0`` has
the KKT conditions ``M dq = WN_j^T tau``, ``0 <= tau ⊥ g_j + S tau >= 0``
with ``S = WN_j M^-1 WN_j^T``: a frictionless LCP in ``tau``, solved in
closed form for one contact (``tau = max(0, -g / S)``) and by Lemke's method
for several. Then ``q_{j+1} = q_j + M^-1 WN_j^T tau``, until every gap is
above ``-PROJECTION_TOL`` or after ``PROJECTION_MAXITER`` iterations; the
velocities are left alone.

*How it differs from ``projection=True`` of Moreau–Jean.* That option puts
every contact that carried a normal impulse back on ``g = 0`` (an equality:
``S d = -g``, ``d`` of either sign) and every penetrating one on ``g >= 0``
as an equality too: it can pull a contact that carried an impulse but whose
gap opened within the step. Here every constraint is unilateral: ``tau >=
0`` only pushes, a positive gap is never closed, and a contact leaves the
set as soon as the LCP gives it no push. Both weigh by ``M``; both assume
``v = dq/dt`` (``WN`` is the gradient of the gap).

The compiled step rule (:func:`step_rule`) runs Moreau–Jean's step rule
(:func:`moreau.integrators._mj_kernels.step_rule`) and then the projection,
inside the compiled driver (:mod:`moreau.integrators._driver`); the Python
class reuses Moreau–Jean's and replaces its projection (:meth:`_project`).
"""

import dataclasses
import math

import numpy as np
from numba import njit

from ..errors import LCPError
from ..lcp import solve_lcp
from .base import register_integrator
from ._contact_step import (LCP_HANDBACK, NUMERICAL, OK, S_PEN, S_PROJ,  # noqa: F401
                            SHARED_INDIRECT, _lcp_size, _lcp_step, _lcp_step_unused,
                            lcp_buffers)
from ._driver import loop_template, spliced
from ._step_parts import gap_block, gaps_at, mass_inverse, move_by
from ._mj_kernels import step_rule as _mj_step
from ._mj_kernels import step_workspace as _mj_workspace
from .moreau_jean import MoreauJean, ThetaOptions

__all__ = ["MoreauJeanProjected", "mjp_loop"]

#: the projection stops when no gap is below minus this (scaled units), or after
#: PROJECTION_MAXITER Gauss–Newton iterations
PROJECTION_TOL = 1e-14
PROJECTION_MAXITER = 8
#: Moreau–Jean's switch of its own projection, set here for its step spliced into this loop
#: (moreau.integrators._driver.loop_template): that step runs with ``projection`` False, so
#: its projection is never taken and numba prunes it instead of compiling it
PROJECTION_REACHABLE = False
SPLICE_SWITCHES = ("PROJECTION_REACHABLE",)


# spliced, as Moreau–Jean's: allocated in the loop's own function
@spliced
def step_workspace(n, nc, opts, lcp_ctl):
    """Moreau–Jean's buffers and the projection's (one tuple)."""
    ncm = max(nc, 1)
    # the projection's LCP has its own matrix and layout memory (the step's LCP keeps its own)
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lcp_buffers(ncm)
    return (_mj_workspace(n, nc, opts, lcp_ctl),
            (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.zeros((n, ncm)),
             np.zeros((2 * ncm, 2 * ncm)), np.zeros(2 * ncm), np.zeros(2 * ncm), np.zeros(ncm),
             np.zeros(ncm), np.zeros(ncm), np.zeros(ncm, dtype=np.bool_),
             np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.int64),
             np.zeros(ncm, dtype=np.int64), np.zeros(ncm, dtype=np.bool_),
             np.zeros(ncm, dtype=np.int64)),
            (Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol))


@njit(inline="always", error_model="numpy")
def step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS, HAS_JAC,
              HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats, k, k0, tk, t1, hk,
              hn, record_initial, q, v, out):
    """A Moreau–Jean step, then the direct projection of ``q1`` (see the module docstring).

    ``opts`` is ``(theta,)``, ``memo`` ``(closed,)`` as Moreau–Jean's.
    Returns Moreau–Jean's statuses, :data:`LCP_HANDBACK` where Lemke fails on
    a projection's LCP and :data:`NUMERICAL` where ``M`` is singular.
    """
    n = NDOF
    nc = NCONTACTS
    mws, pws, lw = ws
    M, Mi, wk, X, S, gv, tau, nuN, nuT, mu0, sel, ia, base, trow, cl0, reg0 = pws
    Ml, ql, dl, zl, wl, rayl, work, iwork, lay, Ab, xb, idx, pcol = lw
    q1, v1, pN, pT, slip, reg, G0, Gq = out
    ...  # the steps (moreau.integrators._driver.loop_template)
    pen = stats[S_PEN]
    # what Moreau–Jean's step updates, kept for a projection handed back to Python
    closed = memo[0]
    for i in range(nc):
        cl0[i] = closed[i]
        reg0[i] = reg[i]
    st = _mj_step(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS, CONST_MASS,
                  HAS_JAC, HAS_GAPS, lcp_step, mws, par, mu, e, (opts[0], False), memo, lcp_ctl,
                  stats, k, k0, tk, t1, hk, hn, record_initial, q, v, out)
    if st != OK or nc == 0:
        return st
    # the penetration is that of the projected positions
    stats[S_PEN] = pen
    # Gq holds the gaps at (q1, t1): Moreau–Jean's step ends with them
    have_mi = False
    for i in range(nc):
        sel[i] = False
    for _ in range(PROJECTION_MAXITER):
        gmin = 0.0
        for i in range(nc):
            if Gq[i, 0] < 0.0:
                sel[i] = True
            gmin = min(gmin, Gq[i, 0])
        if gmin >= -PROJECTION_TOL:
            break
        if not have_mi:
            mass_inverse(mass_fn, par, q1, M, Mi, wk, n, NUMERICAL)
            have_mi = True
        contacts_fn(par, q1, t1, Gq, False, False)
        s = np.int64(0)  # not a literal: see _mj_kernels.step_rule
        for i in range(nc):
            if sel[i]:
                ia[s] = i
                s += 1
        # X = M^-1 WN_A^T, S = WN_A X, the LCP 0 <= tau ⊥ g_A + S tau >= 0
        gap_block(Gq, ia, s, Mi, X, S, n)
        for c in range(s):
            gv[c] = Gq[ia[c], 0]
        if s == 1:
            tau[0] = max(0.0, -gv[0] / S[0, 0])
        else:
            L = _lcp_size(s, ia, mu0, base, trow)
            # np.False_: a literal False would compile the LCP step a second time
            lst, piv, res, warm = lcp_step(S, gv, s, ia, mu0, tau, nuN, nuT, L, base, trow,
                                           Ml, ql, dl, zl, wl, rayl, work, iwork, lay, lcp_ctl,
                                           Ab, xb, idx, pcol, np.False_)
            if lst != 0:
                for i in range(nc):
                    closed[i] = cl0[i]
                    reg[i] = reg0[i]
                return LCP_HANDBACK
        move_by(X, tau, q1, s, n)
        stats[S_PROJ] += 1.0
        gaps_at(HAS_GAPS, gaps_fn, contacts_fn, par, q1, t1, Gq)
    for i in range(n):
        if not math.isfinite(q1[i]):
            return NUMERICAL
    for i in range(nc):
        if -Gq[i, 0] > stats[S_PEN]:
            stats[S_PEN] = -Gq[i, 0]
    return OK


mjp_loop = loop_template("mjp_loop", globals(), "Moreau–Jean projected")


@register_integrator("moreau-jean-projected")
class MoreauJeanProjected(MoreauJean):
    """Moreau–Jean with a direct projection onto ``g >= 0`` after each step (Acary 2013).

    The options of :class:`~moreau.integrators.moreau_jean.MoreauJean`,
    except ``projection``: this scheme always projects, unilaterally (see the
    module docstring for the projection and how it differs from Moreau–Jean's
    ``projection=True``). ``stats["projection_iterations"]`` counts the
    Gauss–Newton iterations.

    Examples
    --------
    >>> from moreau.scenes import BouncingBall
    >>> from moreau.integrators import simulate
    >>> sc = BouncingBall()
    >>> q0, v0 = sc.initial_state()
    >>> res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean-projected", h=1e-3)
    >>> res.scheme, bool(res.gap.min() >= -1e-14)
    ('moreau-jean-projected', True)
    """

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class Options(ThetaOptions):
        """Moreau–Jean's options but ``projection``: this scheme always projects."""

    #: read by Moreau–Jean's step: this scheme always projects (its own :meth:`_project`)
    projection = True
    #: its projection is onto the contacts only: a scene with joints is refused by name
    solves_joints = False
    solves_space = False
    compare_settings = ("steps_per_period", (50, 100, 200, 500, 1000, 2000, 5000, 10000),
                        (100, 300, 1000), {})

    def _fast_block(self):
        q, v, closed = self.q.copy(), self.v.copy(), self._closed.copy()
        status = self._run_block(mjp_loop, (q, v, (float(self.theta),), (closed,)),
                                 (self._lcp_ctl,))
        self.q, self.v, self._closed = q, v, closed
        self._after_block(
            status,
            singular=("the iteration matrix W_hat = M - h theta C - h^2 theta^2 K is singular at "
                      "t = {t!r}; reduce `h` or use a smaller `theta`"),
            numerical=("non-finite state or a singular mass matrix after the step at t = {t!r}"))

    def _project(self, q, t, closed):
        """The direct projection onto ``g >= 0`` (the module docstring's Gauss–Newton with an LCP)."""
        sc = self.scene
        M = np.asarray(sc.mass(q), dtype=float)
        sel = np.zeros(sc.ncontacts, dtype=bool)
        for _ in range(PROJECTION_MAXITER):
            g = np.asarray(sc.gaps(q, t), dtype=float)
            sel |= g < 0.0
            if g.min(initial=0.0) >= -PROJECTION_TOL:
                break
            WN = np.asarray(sc.contact_jacobians(q, t)[0], dtype=float)[sel]
            X = np.linalg.solve(M, WN.T)
            S = WN @ X
            if len(S) == 1:
                tau = np.array([max(0.0, -g[sel][0] / S[0, 0])])
            else:
                sol = solve_lcp(S, g[sel], method="lemke")
                if not sol.success:
                    raise LCPError(f"the projection's LCP at t = {t!r} has no solution "
                                     f"({sol.message})")
                tau = sol.z
            q = q + X @ tau
            self.counters["projection_iterations"] += 1
        return q
