"""Event-driven integration of any scene, through the :class:`~moreau.model.scene.Scene` interface.

The scheme follows the classical event-driven treatment of unilateral
contact with Coulomb friction (Pfeiffer and Glocker): the motion is cut into
smooth phases, each with a fixed *contact mode* (every contact open, sliding
one way, sliding the other way, or sticking), and the phases are joined at
events located to near machine precision.

Smooth phases
    With the mode fixed, the closed contacts' normal accelerations and the
    sticking contacts' slip accelerations are held at zero; sliding contacts
    carry the friction force ``lambdaT = -mu sign(gammaT) lambdaN``. That is
    one linear system per right-hand-side evaluation::

        M a = h + G^T lam,    H a + wbar = 0

    with ``H`` the rows ``[WN_closed; WT_stick]`` and ``G`` the same rows
    except that a sliding contact's normal row is ``WN_i - mu_i s_i WT_i``.
    The state is integrated by DOP853 (``ode_method="Radau"`` for stiff scenes)
    at a tight tolerance.

Events (terminal event functions of ``solve_ivp``, refined by its Brent root finder to a few ulps of time)
    * an open contact's gap closing;
    * a closed contact's normal force vanishing (lift-off);
    * a sliding contact's slip velocity vanishing;
    * a sticking contact's friction force reaching the cone ``|lambdaT| = mu lambdaN``;
    * a sliding contact's normal-force coefficient ``(H M^-1 G^T)_ii``
      vanishing, which is the Painlevé condition failing
      (:class:`~moreau.errors.PainleveError`).

Deciding the next mode
    At an event the state is projected back onto the closed contacts'
    constraints (gap and normal velocity zero, slip velocity zero for
    sticking contacts, in the metric of ``M``), then the frictional LCP at
    acceleration level is solved by Lemke's method over the closed
    contacts: contacts with zero slip get the full friction-cone variables
    (stick or slip in the direction the LCP picks), contacts with nonzero
    slip keep their sliding friction. The event itself settles the cases the
    LCP cannot decide at the event instant: a lift-off opens its contact, a
    saturated cone starts slip in the direction of the friction force's
    reaction. The new mode is then checked for well-posedness: the matrix
    of the normal forces (stick rows eliminated) must be a P-matrix, else
    :class:`~moreau.errors.PainleveError` is raised.

Impacts
    A gap closing with an approach velocity is an impact: Newton's
    restitution law with Coulomb friction, as the velocity-level LCP of
    :func:`moreau.lcp.build_friction_lcp` over every contact whose gap is
    closed, solved by Lemke's method.

Accumulation of impacts (Zeno) policy
    A contact whose rebound velocity after an impact is below
    ``zeno_rtol`` times the largest approach speed seen at that contact is
    treated as having reached the accumulation point: the impact is
    repeated as a plastic one (``e = 0``) for that contact and the contact
    closes. For a ball under gravity with restitution ``e`` and first impact
    speed ``V`` the remaining bounce time thus cut off is below
    ``2 zeno_rtol V / (1 - e)`` (``zeno_rtol = 1e-10`` by default). Independently,
    more than ``max_impacts`` impacts within one ``max_step`` of time stop the
    run with a :class:`~moreau.errors.MoreauError` (status ``-5``): an
    accumulation the policy did not end. A long run of well-separated
    impacts (an elastic ball bouncing for ever) is not one.

Rest
    A phase that starts at rest (velocities within ``vel_tol`` of zero, the
    mode's accelerations zero to rounding) under a forcing that does not
    change with time is an equilibrium: its state, forces and event
    functions are constant, no event can end it, and it is taken in one
    step to the window's end (or to the scene's next forcing breakpoint),
    the samples on the way being that state. The forcing counts as constant
    when ``forces``, ``gaps``, ``contact_jacobians`` and ``contact_drift`` at
    the state give the same numbers at 16 times spread evenly over the rest
    of the phase and at ``t + 10^k`` (``k >= -6``) as at its start; a forcing that changes
    and returns between them must declare its ``forcing_breakpoints``. After
    the Zeno closure of a bouncing ball the cost no longer grows with the window.

Joints
    A scene's joints (``n_joint_rows`` equality rows ``gE(q, t) = 0``) are
    reduced to their acceleration level, ``WE a + wEbar = 0``, and join
    every mode's equations beside the closed contacts' rows, their reactions
    free in sign. Where the contact problem is posed (the mode decision at an
    event, an impact) the joints' reactions are eliminated: the jointed
    system answers a force ``f`` with ``(I - Z WE) M^-1 f``, ``Z = M^-1 WE^T
    (WE M^-1 WE^T)^-1``, and an impact's velocity jump keeps ``WE v + wE =
    0``. The drift the smooth phase leaves on the position and velocity
    levels is removed by projecting the state onto the joints (with the
    closed contacts, in the metric of ``M``) after each smooth phase and each
    impact; ``constraint_drift`` of the result is the largest ``|gE|`` of its
    samples.

Known limits: a gap that dips below zero and comes back inside one
integrator step is not seen (``max_step`` bounds the step); scenes with
discontinuous forcing (a sawtooth drive) are integrated across the jumps by
step-size control, which costs steps and some accuracy.
"""

import math
from itertools import combinations, product

import dataclasses
from typing import ClassVar

import numpy as np
from scipy.integrate import solve_ivp

from .._validate import nonnegative, positive_int
from ..errors import InputError, LCPError, MoreauError, PainleveError
from ..lcp import METHODS as LCP_SOLVERS, build_friction_lcp, friction_impulses, solve_lcp
from ..model.scene import joint_row_count
from ..regimes import Regime
from .base import EventDrivenOptions, Integrator, get_integrator, register_integrator
from .contact_problem import MAX_PIECES_CONTACTS, friction_pieces
from .result import Event

__all__ = ["GenericEventDriven", "ContactModeSolver", "EventDrivenReference",
           "contact_law_regimes", "contact_velocity_scale", "project_onto_joints"]

_F, _P, _N, _S = int(Regime.FLIGHT), int(Regime.POSITIVE), int(Regime.NEGATIVE), int(Regime.STICK)
_SIGN = {_P: 1.0, _N: -1.0}


class ContactModeSolver:
    """Contact-mode dynamics of a scene: accelerations, forces, event functions.

    Parameters
    ----------
    scene : Scene

    Notes
    -----
    ``mode`` is an int array over contacts of :class:`~moreau.regimes.Regime`
    codes. A closed frictionless contact is coded ``POSITIVE`` (it has no
    tangential row, so the sign is immaterial).
    """

    def __init__(self, scene):
        self.scene = scene
        self.nc = scene.ncontacts
        self.ndof = scene.ndof
        self.mu = np.asarray(scene.mu, dtype=float).copy()
        self.e = np.asarray(scene.restitution, dtype=float).copy()
        # row of each frictional contact in WT (-1 for frictionless contacts)
        self.trow = np.full(self.nc, -1, dtype=int)
        self.trow[scene.frictional_index] = np.arange(len(scene.frictional_index))
        #: the scene's joint (equality) rows, always active
        self.nj = joint_row_count(scene)

    def joint_rows(self, t, q, v):
        """``(WE, wE, wEbar)`` of the scene's joints at ``(t, q, v)``."""
        sc = self.scene
        WE, wE = (np.asarray(x, dtype=float) for x in sc.joint_jacobians(q, t))
        return WE.reshape(self.nj, self.ndof), wE.reshape(self.nj), np.asarray(
            sc.joint_drift(q, v, t), dtype=float).reshape(self.nj)

    def joint_solve(self, M, WE, cols):
        """``M^-1 cols`` with the joints' reactions eliminated, and ``M^-1 WE^T S^-1`` (``S = WE M^-1 WE^T``).

        The joints hold ``WE a + wEbar = 0`` (or ``WE dv = 0`` at an impact): the
        response of the jointed system to the forces ``cols`` is ``(I - Z WE)
        M^-1 cols`` with ``Z = M^-1 WE^T S^-1``, and a residual ``r`` of the
        joint rows is removed by ``- Z r``.
        """
        X = np.linalg.solve(M, np.column_stack([WE.T, cols]))
        MiWE, Y = X[:, :self.nj], X[:, self.nj:]
        S = WE @ MiWE
        Z = np.linalg.solve(S, MiWE.T).T
        return Y - Z @ (WE @ Y), Z

    def kinematics(self, t, q, v):
        sc = self.scene
        M = sc.mass(q)
        h = sc.forces(q, v, t)
        WN, wN, WT, wT = sc.contact_jacobians(q, t)
        wNb, wTb = sc.contact_drift(q, v, t)
        return M, h, WN, wN, WT, wT, wNb, wTb

    def _rows(self, mode, WN, WT, wNb, wTb):
        """Rows ``H`` (measured accelerations), ``G`` (force directions) and drift."""
        closed = np.flatnonzero(mode != _F)
        stick = [i for i in closed if mode[i] == _S and self.trow[i] >= 0]
        nrow = len(closed) + len(stick)
        H = np.empty((nrow, self.ndof))
        G = np.empty((nrow, self.ndof))
        wbar = np.empty(nrow)
        for k, i in enumerate(closed):
            H[k] = WN[i]
            wbar[k] = wNb[i]
            j = self.trow[i]
            if j >= 0 and mode[i] in (_P, _N):
                G[k] = WN[i] - self.mu[i] * _SIGN[mode[i]] * WT[j]
            else:
                G[k] = WN[i]
        for k, i in enumerate(stick):
            j = self.trow[i]
            H[len(closed) + k] = WT[j]
            G[len(closed) + k] = WT[j]
            wbar[len(closed) + k] = wTb[j]
        return closed, stick, H, G, wbar

    def solve(self, t, q, v, mode):
        """Accelerations and contact forces of ``mode`` at ``(t, q, v)``.

        Returns
        -------
        a : ndarray (ndof,)
        lamN, lamT : ndarray (nc,)
            Normal and friction force of every contact (0 where open).
        A : ndarray
            The mode matrix ``H M^-1 G^T`` (closed normal rows, then stick rows).
        closed : ndarray of int
        kin : tuple
            The scene quantities at this state (see :meth:`kinematics`).
        """
        kin = self.kinematics(t, q, v)
        M, h, WN, wN, WT, wT, wNb, wTb = kin
        closed, stick, H, G, wbar = self._rows(mode, WN, WT, wNb, wTb)
        if self.nj:
            # the joints' rows after the contacts' (their reactions are free in sign)
            WE, _, wEb = self.joint_rows(t, q, v)
            H, G, wbar = np.vstack([H, WE]), np.vstack([G, WE]), np.concatenate([wbar, wEb])
        lamN = np.zeros(self.nc)
        lamT = np.zeros(self.nc)
        if H.shape[0] == 0:
            return np.linalg.solve(M, h), lamN, lamT, np.zeros((0, 0)), closed, kin
        X = np.linalg.solve(M, np.column_stack([h, G.T]))
        Mih, MiG = X[:, 0], X[:, 1:]
        A = H @ MiG
        rhs = -(H @ Mih + wbar)
        try:
            lam = np.linalg.solve(A, rhs)
            # redundant rows need three (two contacts, one sticking) or more than the
            # dof; the condition number (an SVD) is only paid there
            singular = not np.all(np.isfinite(lam)) or (
                A.shape[0] >= 3 and (A.shape[0] > self.ndof or np.linalg.cond(A) > 1e12))
        except np.linalg.LinAlgError:
            singular = True
        if singular:
            lam = self._redundant(mode, A, rhs, H, G, t)
        a = Mih + MiG @ lam
        nclosed = len(closed)
        lamN[closed] = lam[:nclosed]
        for k, i in enumerate(closed):
            if mode[i] in (_P, _N) and self.trow[i] >= 0:
                lamT[i] = -self.mu[i] * _SIGN[mode[i]] * lam[k]
        for k, i in enumerate(stick):
            lamT[i] = lam[nclosed + k]
        return a, lamN, lamT, A, closed, kin

    def _redundant(self, mode, A, rhs, H, G, t):
        # Redundant contacts without sliding (a block resting flat on two sticking
        # corners: 4 rows, 3 dof): H = G, A = H M^-1 H^T is positive semidefinite and
        # the accelerations are the unique projection, whatever split of the forces
        # solves A lam = rhs; the minimum-norm split is taken. With a sliding contact
        # (G != H) a singular A is a Painlevé configuration.
        sliding = np.any(np.isin(mode, (_P, _N)) & (self.mu > 0.0))
        if not sliding:
            lam = np.linalg.lstsq(A, rhs, rcond=1e-12)[0]
            if np.max(np.abs(A @ lam - rhs)) <= 1e-9 * max(float(np.max(np.abs(rhs))), 1e-300) + 1e-14:
                return lam
        raise PainleveError(
            f"the contact problem of mode {self.letters(mode)} is singular at t = {t:.12g}: "
            "the normal forces are not determined (Painlevé configuration or "
            "redundant contacts)")

    @staticmethod
    def letters(mode):
        return "".join(Regime(int(m)).letter for m in mode)

    def slip_velocities(self, q, v, t, kin=None):
        """Slip velocity of every contact (0 for frictionless ones)."""
        if kin is None:
            kin = self.kinematics(t, q, v)
        _, _, _, _, WT, wT, _, _ = kin
        out = np.zeros(self.nc)
        fr = self.trow >= 0
        out[fr] = WT[self.trow[fr]] @ v + wT[self.trow[fr]]
        return out

    def normal_velocities(self, q, v, t, kin=None):
        if kin is None:
            kin = self.kinematics(t, q, v)
        _, _, WN, wN, _, _, _, _ = kin
        return WN @ v + wN


def contact_law_regimes(scene, t, q, v, regime, solver=None, rtol=1e-9, vscale=None):
    """The regimes of a sample ``(t, q, v)`` by the contact law at that state.

    Every scheme records a regime code with each sample, each in its own way:
    a time-stepping scheme the impulse of the step that ends there, a
    compliant one the force of its spring at the state, a run's first sample
    none (flight, before any step). This names the sample as the continuous
    system would, the same way for every scheme:

    * a contact recorded open whose gap and normal velocity are zero (within
      ``rtol`` of the state's scales) is taken as closed, sticking where its
      slip velocity is zero and sliding its way otherwise; it stays closed if
      the contact problem of that mode gives it a positive normal force;
    * a closed frictional contact in stick sticks only if the stick holds:
      the tangential force that keeps its slip acceleration zero, with the
      closed contacts held, lies in the cone ``|lamT| <= mu lamN``; else it
      slips the way the force leaves the cone (``lamT > mu lamN``: negative
      slip). A step whose impulse stayed inside the cone across a slip
      reversal records a stick the continuous system does not have.

    Parameters
    ----------
    scene : Scene
    t, q, v : the sample's time and state
    regime : array_like of int
        The regime codes the scheme recorded (:class:`moreau.regimes.Regime`).
    solver : ContactModeSolver, optional
        Reused across the samples of a run.
    rtol : float
        Relative tolerance of a zero gap, normal and slip velocity.
    vscale : float, optional
        Scale of the contact velocities (:func:`contact_velocity_scale`): that of
        the run, where a sample may fall where everything is at rest. Default:
        that of the sample's own state.

    Returns
    -------
    ndarray of int

    Examples
    --------
    A ball resting on the floor, recorded in flight (a first sample), is closed:

    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> ball = BouncingBall(radius=0.1)
    >>> contact_law_regimes(ball, 0.0, np.array([0.1]), np.zeros(1), [0]).tolist()
    [1]
    """
    ms = solver if solver is not None else ContactModeSolver(scene)
    mode = np.array(regime, dtype=int).reshape(ms.nc)
    if ms.nc == 0 or not np.any((mode == _F) | (mode == _S)):
        return mode
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    kin = ms.kinematics(t, q, v)
    WN, wN, WT, wT = kin[2], kin[3], kin[4], kin[5]
    g = np.asarray(scene.gaps(q, t), dtype=float)
    vN = WN @ v + wN
    vT = ms.slip_velocities(q, v, t, kin)
    if vscale is None:
        vscale = _velocity_terms(kin, v)
    vscale = max(float(vscale), 1e-300)
    vtol = rtol * vscale
    gtol = rtol * (1.0 + float(np.max(np.abs(q))))
    touched = np.flatnonzero((mode == _F) & (np.abs(g) <= gtol) & (np.abs(vN) <= vtol))
    for i in touched:
        if ms.trow[i] < 0 or vT[i] > vtol:
            mode[i] = _P
        elif vT[i] < -vtol:
            mode[i] = _N
        else:
            mode[i] = _S
    if not np.any(mode == _S) and not touched.size:
        return mode
    try:
        _, lamN, lamT, _, _, _ = ms.solve(t, q, v, mode)
    except PainleveError:
        # redundant closed contacts (two rods sticking on one rotor): the forces of the
        # mode are not determined; the acceleration-level LCP decides, as at an event
        return _decided_regimes(scene, ms, t, q, v, regime, vscale, rtol)
    for i in touched:
        if not lamN[i] > 0.0:
            mode[i] = _F
    fscale = max(float(np.max(np.abs(lamN))), 1e-300)
    for i in np.flatnonzero(mode == _S):
        if ms.trow[i] < 0:
            mode[i] = _P
        elif lamT[i] > ms.mu[i] * lamN[i] + rtol * fscale:
            mode[i] = _N
        elif lamT[i] < -ms.mu[i] * lamN[i] - rtol * fscale:
            mode[i] = _P
    return mode


def _velocity_terms(kin, v):
    # the largest term of the contact velocities |W| |v| + |w| (not the velocities: zero
    # in stick), as the event-driven tolerances measure them
    WN, wN, WT, wT = kin[2], kin[3], kin[4], kin[5]
    av = np.abs(v)
    return max(float(np.max(np.abs(WN) @ av + np.abs(wN), initial=0.0)),
               float(np.max(np.abs(WT) @ av + np.abs(wT), initial=0.0)))


def contact_velocity_scale(scene, ts, qs, vs, solver=None, samples=64):
    """The scale of the contact velocities over a run's samples (at most ``samples`` of them).

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> contact_velocity_scale(BouncingBall(), [0.0, 1.0], [[1.0], [0.5]], [[0.0], [-1.0]])
    1.0
    """
    ms = solver if solver is not None else ContactModeSolver(scene)
    idx = np.unique(np.linspace(0, len(ts) - 1, min(samples, len(ts))).round().astype(int))
    out = 0.0
    for k in idx:
        q, v = np.asarray(qs[k], dtype=float), np.asarray(vs[k], dtype=float)
        out = max(out, _velocity_terms(ms.kinematics(float(ts[k]), q, v), v))
    return out


def _decided_regimes(scene, ms, t, q, v, regime, vscale, rtol):
    """The event-driven mode decision at a sample (:meth:`GenericEventDriven._decide`).

    A contact the scheme recorded closed counts as touching; a sample the
    decision cannot name (no solution, a Painlevé case) keeps its regimes.
    """
    integ = object.__new__(GenericEventDriven)
    integ.scene, integ.ms, integ.lcp_method = scene, ms, "lemke"
    integ.vel_tol, integ._vscale = rtol, vscale
    g = np.asarray(scene.gaps(q, t), dtype=float)
    closed = np.asarray(regime).reshape(ms.nc) != _F
    integ.gap_tol = max(float(np.max(np.abs(g[closed]), initial=0.0)),
                        rtol * (1.0 + float(np.max(np.abs(q)))))
    integ.counters = {"lcp_solves": 0}
    try:
        return integ._decide(t, q, v, {})
    except (PainleveError, LCPError):
        return np.array(regime, dtype=int).reshape(ms.nc)


def project_positions(scene, t, q, contacts, max_iter=4):
    """``q`` moved, in the metric of ``M``, onto ``g = 0`` for ``contacts`` (Newton steps).

    Stops when the gaps are exactly zero or the step is at round-off.
    """
    M = scene.mass(q)
    for _ in range(max_iter):
        g = scene.gaps(q, t)[contacts]
        if np.max(np.abs(g)) == 0.0:
            break
        WN = scene.contact_jacobians(q, t)[0][contacts]
        MiW = np.linalg.solve(M, WN.T)
        dq = MiW @ np.linalg.solve(WN @ MiW, g)
        q = q - dq
        if np.max(np.abs(dq)) <= 4e-16 * max(1.0, float(np.max(np.abs(q)))):
            break
    return q


def project_onto_joints(scene, t, q, contacts=(), max_iter=8):
    """``q`` moved, in the metric of ``M``, onto the joints ``gE = 0`` and ``g = 0`` for ``contacts``.

    Gauss-Newton steps ``dq = M^-1 W^T (W M^-1 W^T)^+ r`` on the stacked
    residuals ``r = (g[contacts], gE)`` with rows ``W = (WN[contacts]; WE)``
    (the pseudo-inverse takes redundant rows); stops when the residuals are
    zero or the step is at round-off.
    """
    contacts = np.asarray(contacts, dtype=int)
    M = scene.mass(q)
    for _ in range(max_iter):
        r = np.concatenate([np.asarray(scene.gaps(q, t), dtype=float)[contacts],
                            np.asarray(scene.joint_residuals(q, t), dtype=float)])
        if np.max(np.abs(r), initial=0.0) == 0.0:
            break
        W = np.vstack([np.asarray(scene.contact_jacobians(q, t)[0], dtype=float)[contacts],
                       np.asarray(scene.joint_jacobians(q, t)[0], dtype=float)])
        MiW = np.linalg.solve(M, W.T)
        dq = MiW @ np.linalg.lstsq(W @ MiW, r, rcond=1e-12)[0]
        q = q - dq
        if np.max(np.abs(dq)) <= 4e-16 * max(1.0, float(np.max(np.abs(q)))):
            break
    return q


def _one_of(name, value, allowed):
    if not isinstance(value, str) or value not in allowed:
        raise InputError(f"`{name}` must be one of {list(allowed)}, got {value!r}")
    return value


def _bool_option(value):
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"`record_pieces` must be True or False, got {value!r}")
    return bool(value)


@register_integrator("event-driven-generic")
class GenericEventDriven(Integrator):
    """Event-driven reference for any :class:`~moreau.model.scene.Scene`.

    Each :meth:`step` runs one smooth phase to its first event (or to
    ``t_bound``) and resolves the event. Samples are recorded at every event
    and every ``sample_dt`` of time. See the module docstring for the method
    and the impact-accumulation policy.

    Parameters
    ----------
    {start}
    rtol, atol : float
        Tolerances of the smooth-phase integrator (``atol`` absolute, per
        state component).
    ode_method : {"DOP853", "Radau"}
        Smooth-phase integrator; Radau for stiff scenes.
    max_step : float
        Largest integrator step; bounds the time in which a gap could dip
        below zero and come back unseen.
    sample_dt : float, optional
        Output interval; ``(t_bound - t0) / 256`` by default.
    gap_tol : float
        Gap at or below which a contact counts as touching.
    vel_tol : float
        Relative velocity below which a normal or slip velocity counts as
        zero at an event. The scale is the largest term of the contact
        velocities (``|W| |v| + |w|``) met so far, including the scene's
        rheonomic terms over the run, so a scene at rest still has one.
    zeno_rtol : float
        Rebound velocity, relative to the contact's largest approach speed,
        below which an impact sequence is taken as accumulated (contact closes).
    max_impacts : int
        Impacts allowed within one ``max_step`` of time (an accumulation).
    lcp_method : str
        LCP solver for the contact problems (see :func:`moreau.lcp.solve_lcp`).
    record_pieces : bool
        Keep the pieces of the run for analyses that integrate along it (the
        energy audit, :mod:`moreau.analysis.energy`): ``phases`` lists every
        smooth phase as ``(t0, t1, dense_output, mode)``, ``jumps`` every
        velocity jump at fixed positions as ``(t, q, v_pre, v_post, pN, pT,
        kind)``, with the impulses of each contact (``M (v_post - v_pre) =
        WN^T pN + WT^T pT``) and ``kind`` ``"impact"`` or ``"projection"``
        (the removal of a phase's drift from the closed contacts).

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> from moreau.integrators import simulate
    >>> ball = BouncingBall(restitution=0.5, radius=0.1)
    >>> res = simulate(ball, (0.0, 2.4), [0.6], [0.0], "event-driven-generic")
    >>> [round(ev.t, 12) for ev in res.events if ev.kind == "impact"]
    [1.0, 2.0]
    """

    exact_motion = True
    #: joints: their acceleration-level rows join every mode's equations (index
    #: reduction), their velocity rows every impact's, and the state is projected onto
    #: them after each smooth phase and each impact
    solves_joints = True

    @dataclasses.dataclass(frozen=True)
    class Options(EventDrivenOptions):
        """Options of :class:`GenericEventDriven` (its parameters after ``t_bound``)."""
        atol: float = 1e-15
        max_step: float = 0.1
        ode_method: str = "DOP853"
        gap_tol: float = 1e-13
        zeno_rtol: float = 1e-6
        max_impacts: int = 10000
        lcp_method: str = "lemke"
        record_pieces: bool = False

        _rules: ClassVar[dict] = {
            **EventDrivenOptions._rules,
            "ode_method": lambda v: _one_of("ode_method", v, ("DOP853", "Radau")),
            "gap_tol": lambda v: nonnegative("gap_tol", v),
            "vel_tol": lambda v: nonnegative("vel_tol", v),
            "zeno_rtol": lambda v: nonnegative("zeno_rtol", v),
            "max_impacts": lambda v: positive_int("max_impacts", v),
            "lcp_method": lambda v: _one_of("lcp_method", v, tuple(sorted(LCP_SOLVERS))),
            "record_pieces": _bool_option}

    takes_options_object = True

    def __init__(self, scene, t0, q0, v0, t_bound, options=None, **keywords):
        super().__init__(scene, t0, q0, v0, t_bound)
        self.options = o = self._take_options(options, keywords)
        self.phases = [] if o.record_pieces else None
        self.jumps = [] if o.record_pieces else None
        self.rtol, self.atol, self.ode_method = o.rtol, o.atol, o.ode_method
        self.max_step = o.max_step
        self.sample_dt = (o.sample_dt if o.sample_dt is not None
                          else (self.t_bound - self.t0) / 256.0)
        self.gap_tol, self.vel_tol, self.zeno_rtol = o.gap_tol, o.vel_tol, o.zeno_rtol
        self.max_impacts = o.max_impacts
        self.lcp_method = o.lcp_method
        self.ms = ContactModeSolver(scene)
        self._max_drift = 0.0
        nc = scene.ncontacts
        self.mode = np.zeros(nc, dtype=int)
        self._vscale = 0.0
        self._approach = np.zeros(nc)
        self._last_event_t, self._stalled = None, 0
        self._burst_t0, self._burst = -math.inf, 0
        self.counters.update({"events": 0, "impacts": 0, "lcp_solves": 0, "rhs": 0,
                              "segments": 0})
        self._next_sample = self.t0 + self.sample_dt
        if self._attempt(self._first_mode):
            self._record_state(self.t, self.q, self.v)

    def _first_mode(self):
        # the start's mode, from the velocity scale (a failure stops the run at once)
        scene = self.scene
        g = scene.gaps(self.q, self.t)
        if np.any(g < -self.gap_tol):
            i = int(np.argmin(g))
            raise InputError(f"`q0` penetrates contact {i}: gap = {g[i]:.3g} < 0")
        self._update_vscale(self.q, self.v, self.t)
        # a driven scene may start at rest: its rheonomic contact
        # velocities over the run set the scale then
        for tk in np.linspace(self.t0, self.t_bound, 17):
            _, wN, _, wT = scene.contact_jacobians(self.q, tk)
            self._vscale = max(self._vscale, float(np.max(np.abs(wN), initial=0.0)),
                               float(np.max(np.abs(wT), initial=0.0)))
        self._resolve(kind="start")

    # -- scales and tolerances ------------------------------------------------
    def _update_vscale(self, q, v, t):
        # the scale of the terms that make up the contact velocities, not of
        # the relative velocities themselves (zero in stick)
        kin = self.ms.kinematics(t, q, v)
        WN, wN, WT, wT = kin[2], kin[3], kin[4], kin[5]
        av = np.abs(v)
        terms = [np.abs(WN) @ av + np.abs(wN), np.abs(WT) @ av + np.abs(wT)]
        vel = np.concatenate(terms)
        if vel.size:
            self._vscale = max(self._vscale, float(vel.max()))

    def _vtol(self):
        return self.vel_tol * max(self._vscale, 1e-300)

    # -- recording ---------------------------------------------------------------
    def _sample_row(self, t, q, v, mode):
        ms = self.ms
        if ms.nj:
            self._max_drift = max(self._max_drift, float(np.max(np.abs(
                self.scene.joint_residuals(q, t)), initial=0.0)))
        a, lamN, lamT, _, _, kin = ms.solve(t, q, v, mode)
        slip = ms.slip_velocities(q, v, t, kin)
        gap = self.scene.gaps(q, t)
        return t, q, v, mode.copy(), lamN, lamT, slip, gap

    def _record_state(self, t, q, v):
        self._record(*self._sample_row(t, q, v, self.mode))
        # the velocity scale of the tolerances also learns from the samples:
        # events may all fall where the scene is momentarily at rest
        self._update_vscale(q, v, t)

    # -- projection onto the closed contacts' constraints ----------------------
    def _project_positions(self, t, q, contacts):
        if self.ms.nj:
            return project_onto_joints(self.scene, t, q, contacts)
        return project_positions(self.scene, t, q, contacts, max_iter=4)

    def _project(self, t, q, v, mode):
        closed = np.flatnonzero(mode != _F)
        nj = self.ms.nj
        if closed.size == 0 and not nj:
            return q, v
        sc = self.scene
        q = self._project_positions(t, q, closed)
        WN, wN, WT, wT = sc.contact_jacobians(q, t)
        stick = [i for i in closed if mode[i] == _S and self.ms.trow[i] >= 0]
        H = np.vstack([WN[closed]] + ([WT[self.ms.trow[stick]]] if stick else []))
        w = np.concatenate([wN[closed]] + ([wT[self.ms.trow[stick]]] if stick else []))
        if nj:
            WE, wE, _ = self.ms.joint_rows(t, q, v)
            H, w = np.vstack([H, WE]), np.concatenate([w, wE])
        MiH = np.linalg.solve(sc.mass(q), H.T)
        # lstsq: redundant closed contacts (a block flat on two corners) make H M^-1 H^T
        # singular; the projected velocity is unique all the same
        lam = -np.linalg.lstsq(H @ MiH, H @ v + w, rcond=1e-12)[0]
        v_post = v + MiH @ lam
        if self.jumps is not None:
            pN, pT = np.zeros(self.ms.nc), np.zeros(self.ms.nc)
            pN[closed] = lam[:closed.size]
            pT[stick] = lam[closed.size:closed.size + len(stick)]
            self.jumps.append((t, q.copy(), v.copy(), v_post.copy(), pN, pT, "projection"))
        return q, v_post

    # -- impacts ---------------------------------------------------------------------
    def _impact(self, t, q, v, touching):
        """Velocity jump of Newton's impact law with Coulomb friction over ``touching``."""
        ms, sc = self.ms, self.scene
        kin = ms.kinematics(t, q, v)
        M, _, WN, wN, WT, wT, _, _ = kin
        rows = [WN[touching]]
        fr = [i for i in touching if ms.trow[i] >= 0]
        if fr:
            rows.append(WT[ms.trow[fr]])
        J = np.vstack(rows)
        w = np.concatenate([wN[touching]] + ([wT[ms.trow[fr]]] if fr else []))
        if ms.nj:
            # the joints' impulses eliminated: the jointed system's response, from the
            # velocity on the joints (WE v + wE = 0 before and after)
            WE, wE, _ = ms.joint_rows(t, q, v)
            MiJ, Z = ms.joint_solve(M, WE, J.T)
            v = v - Z @ (WE @ v + wE)
        else:
            MiJ = np.linalg.solve(M, J.T)
        W = J @ MiJ
        vrel = J @ v + w
        mu = ms.mu[touching]
        e = ms.e[touching].copy()
        vN_pre = vrel[:len(touching)]
        self._approach[touching] = np.maximum(self._approach[touching], -vN_pre)
        for attempt in range(2):
            lcp = build_friction_lcp(W, vrel, mu, e, vN_pre)
            res = solve_lcp(lcp.M, lcp.q, self.lcp_method)
            self.counters["lcp_solves"] += 1
            z = res.z if res.success else None
            if z is None and len(touching) <= MAX_PIECES_CONTACTS:
                # the velocity-level problem has a solution (contact_problem.solve_contact_problem)
                z = friction_pieces(W, vrel, mu, e, vN_pre, *lcp)
                if z is not None:
                    self.counters["piece_enumerations"] = self.counters.get(
                        "piece_enumerations", 0) + 1
            if z is None:
                if np.any(mu > 0):
                    raise PainleveError(
                        f"the frictional impact problem at t = {t:.12g} has no solution "
                        f"(Lemke: {res.message}); a Painlevé-type impact configuration")
                raise LCPError(f"impact LCP at t = {t:.12g} not solved: {res.message}")
            p = friction_impulses(z, lcp.layout, stacked=True)
            vN_post = (vrel + W @ p)[:len(touching)]
            # Zeno policy: a rebound far below the contact's approach speeds is
            # the accumulation point of a bounce sequence; close the contact
            weak = (e > 0) & (vN_post > 0) & (vN_post <= self.zeno_rtol * self._approach[touching])
            if attempt == 0 and np.any(weak):
                e[weak] = 0.0
                self.counters["zeno_closures"] = self.counters.get("zeno_closures", 0) + int(weak.sum())
                continue
            break
        self.counters["impacts"] += 1
        if t - self._burst_t0 > self.max_step:
            self._burst_t0, self._burst = t, 0
        self._burst += 1
        if self._burst > self.max_impacts:
            raise MoreauError(f"more than `max_impacts`={self.max_impacts} impacts within "
                              f"`max_step`={self.max_step:g} of time before t = {t:.12g} (an "
                              "accumulation the Zeno policy did not end?)")
        v_post = v + MiJ @ p
        v_post, p = self._close_accumulation(t, touching, fr, J, w, MiJ, W, vrel, v, v_post, p)
        if self.jumps is not None:
            pN, pT = np.zeros(ms.nc), np.zeros(ms.nc)
            pN[touching] = p[:len(touching)]
            pT[fr] = p[len(touching):]
            self.jumps.append((t, q.copy(), v.copy(), v_post.copy(), pN, pT, "impact"))
        return v_post

    def _close_accumulation(self, t, touching, fr, J, w, MiJ, W, vrel, v, v_post, p):
        """The accumulation point of impacts on several contacts (a rocking block settling).

        After a plastic impact on one contact another touching one may leave
        at a speed far below the approach speeds seen there (the rocking
        block's pivot corner, lifted by the other corner's impact at ``2 a
        |w'|``): the next impact comes back within a time of the same order,
        and the series accumulates, as a bouncing ball's does. Where a
        touching contact leaves at or below ``zeno_rtol`` times its largest
        approach speed, the accumulation point is taken: the velocity is
        projected, in the metric of ``M``, onto every touching contact closed
        (normal velocity 0) and the frictional ones whose slip is as small
        sticking, and the contacts close. The projection removes velocities of
        the size of that weak lift-off; where it would change a contact
        velocity by more (the outcome depends on more than the accumulation),
        the run stops naming the contacts.
        """
        n_t = len(touching)
        U = vrel + W @ p
        vN = U[:n_t]
        appr = self._approach[touching]
        # a lift-off below the velocity tolerance is a closed contact already (_decide)
        weak = (vN > self._vtol()) & (vN <= self.zeno_rtol * appr)
        if not weak.any():
            return v_post, p
        small = float(np.max(vN[weak]))
        # contacts that leave at more than the Zeno bound are left free
        strong = (vN > self._vtol()) & ~weak
        rows = [k for k in range(n_t) if not strong[k]]
        rows += [n_t + k for k, i in enumerate(fr)
                 if not strong[list(touching).index(i)]
                 and abs(U[n_t + k]) <= max(self._vtol(), self.zeno_rtol * self._approach[i])]
        Jr = J[rows]
        lam = -np.linalg.lstsq(W[np.ix_(rows, rows)], U[rows], rcond=1e-12)[0]
        v_closed = v_post + MiJ[:, rows] @ lam
        change = np.abs(J @ (v_closed - v_post))
        if np.max(change) > 10.0 * small + self._vtol():
            names = [int(touching[k]) for k in np.flatnonzero(weak)]
            raise MoreauError(
                f"an accumulation of impacts at t = {t:.12g} whose outcome this scheme cannot "
                f"decide: contacts {names} leave at {small:.3g}, below `zeno_rtol` times their "
                f"approach speeds, but closing the touching contacts {list(map(int, touching))} "
                f"would change a contact velocity by {np.max(change):.3g}")
        p = p.copy()
        p[rows] += lam
        self.counters["zeno_closures"] = self.counters.get("zeno_closures", 0) + int(weak.sum())
        self.counters.setdefault("accumulation_times", []).append(float(t))
        return v_closed, p

    # -- mode decision ------------------------------------------------------------------
    def _decide(self, t, q, v, forced):
        """New contact mode from the acceleration-level frictional LCP.

        ``forced`` maps a contact to the regime its event imposes (lift-off ->
        FLIGHT, cone saturation -> slip direction).
        """
        ms, sc = self.ms, self.scene
        kin = ms.kinematics(t, q, v)
        M, h, WN, wN, WT, wT, wNb, wTb = kin
        g = sc.gaps(q, t)
        vN = WN @ v + wN
        vT = ms.slip_velocities(q, v, t, kin)
        vtol = self._vtol()
        mode = np.full(ms.nc, _F, dtype=int)
        cand = [i for i in range(ms.nc)
                if g[i] <= self.gap_tol and vN[i] <= vtol and forced.get(i) != _F]
        if not cand:
            return mode
        # friction model of each candidate in the LCP: full cone (zero slip) or
        # sliding with a fixed sign (nonzero slip, or a saturated cone)
        sign = {}
        cone = []
        for i in cand:
            if ms.trow[i] < 0:
                continue
            if i in forced:
                sign[i] = _SIGN[forced[i]]
            elif abs(vT[i]) > vtol:
                sign[i] = math.copysign(1.0, vT[i])
            else:
                cone.append(i)
        nC = len(cand)
        H = np.empty((nC + len(cone), ms.ndof))
        G = np.empty_like(H)
        wbar = np.empty(nC + len(cone))
        for k, i in enumerate(cand):
            H[k] = WN[i]
            G[k] = WN[i] - ms.mu[i] * sign[i] * WT[ms.trow[i]] if i in sign else WN[i]
            wbar[k] = wNb[i]
        for k, i in enumerate(cone):
            H[nC + k] = G[nC + k] = WT[ms.trow[i]]
            wbar[nC + k] = wTb[ms.trow[i]]
        if ms.nj:
            # the joints' reactions eliminated (their rows hold at acceleration level)
            WE, _, wEb = ms.joint_rows(t, q, v)
            X, Z = ms.joint_solve(M, WE, np.column_stack([h, G.T]))
            X[:, 0] -= Z @ wEb
        else:
            X = np.linalg.solve(M, np.column_stack([h, G.T]))
        A = H @ X[:, 1:]
        b = H @ X[:, 0] + wbar
        for k, i in enumerate(cand):
            if i in sign and i not in forced and A[k, k] <= 0.0 and b[k] < 0.0:
                raise PainleveError(
                    f"Painlevé configuration at t = {t:.12g}: contact {i} slides "
                    f"({'P' if sign[i] > 0 else 'N'}) with the normal-force coefficient "
                    f"WN M^-1 (WN - mu s WT)^T = {A[k, k]:.6g} <= 0 (mu = {ms.mu[i]:.6g}) while "
                    f"the free motion presses it (normal acceleration {b[k]:.6g} < 0): sliding "
                    "has no solution. The state needs an impulse, the tangential impact "
                    "(dynamic jamming), which this event-driven scheme does not take; the "
                    "time-stepping schemes take it")
        mu_eff = np.array([ms.mu[i] if i in cone else 0.0 for i in cand])
        lcp = build_friction_lcp(A, b, mu_eff, 0.0, np.zeros(nC))
        res = solve_lcp(lcp.M, lcp.q, self.lcp_method)
        self.counters["lcp_solves"] += 1
        if not res.success:
            if sign or cone:
                raise PainleveError(
                    f"the acceleration-level contact problem at t = {t:.12g} has no solution "
                    f"(Lemke: {res.message}); a Painlevé configuration (friction "
                    f"coefficients {ms.mu[cand].tolist()}, sliding contacts {sorted(sign)})")
            raise LCPError(f"acceleration-level contact LCP at t = {t:.12g} not solved: "
                           f"{res.message}")
        lam = friction_impulses(res.z, lcp.layout, stacked=True)
        acc = A @ lam + b
        lamN = lam[:nC]
        fscale = max(float(np.max(np.abs(lam))), float(np.max(np.abs(b))), 1e-300)
        ftol = 1e-12 * fscale
        for k, i in enumerate(cand):
            if lamN[k] <= ftol and acc[k] >= -ftol:
                continue     # leaves (or grazes): open
            if ms.trow[i] < 0:
                mode[i] = _P
            elif i in sign:
                mode[i] = _P if sign[i] > 0 else _N
            else:
                kk = nC + cone.index(i)
                if abs(acc[kk]) <= ftol:
                    mode[i] = _S
                else:
                    mode[i] = _P if acc[kk] > 0 else _N
        if not self._consistent(t, q, v, mode, cand, sign, cone):
            # a degenerate LCP (simultaneous events, redundant contacts) can
            # return a mode whose own dynamics leaves it at once; the case
            # analysis over the candidates' regimes finds the consistent one
            mode = self._enumerate(t, q, v, mode, cand, sign, cone)
        self._check_well_posed(t, q, v, mode)
        return mode

    def _consistent(self, t, q, v, mode, cand, sign, cone):
        """Whether ``mode`` satisfies its own sign conditions at ``(t, q, v)``."""
        ms = self.ms
        try:
            a, lamN, lamT, _, _, kin = ms.solve(t, q, v, mode)
        except PainleveError:
            return False
        WN, WT, wNb, wTb = kin[2], kin[4], kin[6], kin[7]
        scale = max(float(np.max(np.abs(lamN), initial=0.0)), float(np.max(np.abs(a))), 1e-300)
        tol = 1e-10 * scale
        for i in cand:
            j = ms.trow[i]
            if mode[i] == _F:
                if WN[i] @ a + wNb[i] < -tol:
                    return False
                continue
            if lamN[i] < -tol:
                return False
            if j < 0:
                continue
            if mode[i] == _S:
                if abs(lamT[i]) > ms.mu[i] * lamN[i] + tol:
                    return False
            elif i in cone and _SIGN[mode[i]] * (WT[j] @ a + wTb[j]) < -tol:
                return False
        return True

    def _enumerate(self, t, q, v, first, cand, sign, cone):
        ms = self.ms
        choices = []
        for i in cand:
            if ms.trow[i] < 0:
                choices.append((_P, _F))
            elif i in sign:
                choices.append((_P if sign[i] > 0 else _N, _F))
            else:
                choices.append((_S, _P, _N, _F))
        for combo in product(*choices):
            mode = first.copy()
            mode[list(cand)] = combo
            if self._consistent(t, q, v, mode, cand, sign, cone):
                return mode
        raise PainleveError(
            f"no contact mode is consistent at t = {t:.12g} (contacts {list(cand)}): the "
            "acceleration-level contact problem has no solution")

    def _check_well_posed(self, t, q, v, mode):
        """Raise PainleveError unless the mode's normal-force matrix is a P-matrix."""
        closed = np.flatnonzero(mode != _F)
        if closed.size == 0 or not np.any(np.isin(mode[closed], (_P, _N)) & (self.ms.mu[closed] > 0)):
            return
        _, _, _, A, closed, _ = self.ms.solve(t, q, v, mode)
        n = len(closed)
        K = A[:n, :n]
        if A.shape[0] > n:       # eliminate the stick rows (Schur complement)
            K = K - A[:n, n:] @ np.linalg.solve(A[n:, n:], A[n:, :n])
        scale = max(float(np.max(np.abs(K))), 1e-300)
        for r in range(1, min(n, 8) + 1):
            for idx in combinations(range(n), r):
                d = np.linalg.det(K[np.ix_(idx, idx)])
                if d <= 1e-13 * scale ** r:
                    names = ", ".join(f"{int(closed[i])} ({Regime(int(mode[closed[i]])).letter})"
                                      for i in idx)
                    raise PainleveError(
                        f"Painlevé configuration at t = {t:.12g}: the normal-force matrix of "
                        f"the sliding contacts [{names}] has a principal minor {d:.3g} <= 0 "
                        f"(friction coefficients {self.ms.mu[closed].tolist()}); the contact "
                        "problem has no solution or several")

    def _resolve(self, kind, forced=None, contact=None):
        """Impacts, projection and the new mode at the current state."""
        forced = forced or {}
        t, q, v = self.t, self.q, self.v
        sc, ms = self.scene, self.ms
        before = self.mode.copy()
        impacted = False
        if kind != "start":
            # remove the drift of the phase that just ended, so that a closed
            # contact's residual normal velocity is not taken for an impact
            q, v = self._project(t, q, v, before)
        for _ in range(ms.nc + 2):
            kin = ms.kinematics(t, q, v)
            g = sc.gaps(q, t)
            vN = ms.normal_velocities(q, v, t, kin)
            touching = np.flatnonzero(g <= self.gap_tol)
            if not np.any(vN[touching] < -self._vtol()):
                break
            q = self._project_positions(t, q, touching)
            self._update_vscale(q, v, t)
            v = self._impact(t, q, v, touching)
            impacted = True
        mode = self._decide(t, q, v, forced)
        q, v = self._project(t, q, v, mode)
        self.q, self.v, self.mode = q, v, mode
        self._update_vscale(q, v, t)
        if kind != "start":
            changed = np.flatnonzero(mode != before)
            evkind = "impact" if impacted else kind
            if contact is None and changed.size:
                contact = int(changed[0])
            c = 0 if contact is None else int(contact)
            self.events.append(Event(t=t, kind=evkind, before=Regime(int(before[c])),
                                     after=Regime(int(mode[c])), contact=c))
            self.counters["events"] += 1

    # -- smooth phase ---------------------------------------------------------------------
    def _phase_functions(self):
        """RHS and event functions of the current mode (with a one-entry cache)."""
        ms, sc, mode = self.ms, self.scene, self.mode.copy()
        n = sc.ndof
        cache = {}
        counters = self.counters

        def evaluate(t, y):
            key = (t, y.tobytes())
            hit = cache.get("key")
            if hit == key:
                return cache["val"]
            q, v = y[:n], y[n:]
            a, lamN, lamT, A, closed, kin = ms.solve(t, q, v, mode)
            counters["rhs"] += 1
            val = (a, lamN, lamT, A, closed, kin, q, v)
            cache["key"], cache["val"] = key, val
            return val

        def rhs(t, y):
            a = evaluate(t, y)[0]
            return np.concatenate([y[n:], a])

        y0 = np.concatenate([self.q, self.v])
        t0 = self.t
        a0, lamN0, lamT0, A0, closed0, kin0 = evaluate(t0, y0)[:6]
        fscale = max(float(np.max(np.abs(lamN0), initial=0.0)), 1e-300)
        g0 = sc.gaps(self.q, t0)
        vN0 = ms.normal_velocities(self.q, self.v, t0, kin0)
        vT0 = ms.slip_velocities(self.q, self.v, t0, kin0)
        vtol = self._vtol()
        # a function that starts on its zero (a phase begun by that very
        # event) is held positive for a short skip, so the start is not taken
        # for an event; later roots are found without bias
        skip = 1e-10 * max(1.0, abs(t0))
        events, meta = [], []

        def make(fun, start_zero=False, span=skip):
            if start_zero:
                t_on = t0 + span

                def ev(t, y, f=fun):
                    return 1.0 if t < t_on else f(t, y)
            else:
                ev = fun
            ev.terminal = True
            ev.direction = -1.0
            return ev

        for i in range(ms.nc):
            j = ms.trow[i]
            if mode[i] == _F:
                gap = (lambda t, y, i=i: sc.gaps(y[:n], t)[i])
                if g0[i] > self.gap_tol:
                    events.append(make(gap))
                elif vN0[i] > vtol:
                    # a rebound: skip a small part of its flight
                    gdd = float(kin0[2][i] @ a0 + kin0[6][i])
                    span = 1e-3 * 2.0 * vN0[i] / -gdd if gdd < 0 else skip
                    events.append(make(gap, True, max(span, skip)))
                else:
                    # lift-off with zero normal velocity: the gap grows like a
                    # power of the time and stays below round-off for a while,
                    # so re-contact is watched at -gap_tol
                    events.append(make(lambda t, y, i=i: sc.gaps(y[:n], t)[i] + self.gap_tol))
                meta.append(("gap", i))
                continue
            zf = lamN0[i] <= 1e-12 * fscale
            events.append(make(lambda t, y, i=i: evaluate(t, y)[1][i], zf))
            meta.append(("liftoff", i))
            if j < 0:
                continue
            if mode[i] == _S:
                mu = ms.mu[i]
                zc = mu * lamN0[i] - abs(lamT0[i]) <= 1e-12 * fscale
                events.append(make(lambda t, y, i=i, mu=mu:
                                   mu * evaluate(t, y)[1][i] - evaluate(t, y)[2][i], zc))
                meta.append(("cone", i, _N))     # friction at +mu lamN: slip turns negative
                events.append(make(lambda t, y, i=i, mu=mu:
                                   mu * evaluate(t, y)[1][i] + evaluate(t, y)[2][i], zc))
                meta.append(("cone", i, _P))
            else:
                s = _SIGN[mode[i]]

                def slip(t, y, j=j, s=s):
                    kin = evaluate(t, y)[5]
                    WT, wT = kin[4], kin[5]
                    return s * (WT[j] @ y[n:] + wT[j])

                events.append(make(slip, abs(vT0[i]) <= vtol))
                meta.append(("slip", i))
                k = int(np.flatnonzero(closed0 == i)[0])
                events.append(make(lambda t, y, k=k: evaluate(t, y)[3][k, k]))
                meta.append(("painleve", i))
        return rhs, events, meta, evaluate

    def _rest_phase(self):
        """Take a phase at rest under a constant forcing in one step; True if it was one."""
        t, q, v, mode = self.t, self.q, self.v, self.mode
        if np.max(np.abs(v), initial=0.0) > self._vtol():
            return False
        try:
            a, _, _, _, _, kin = self.ms.solve(t, q, v, mode)
        except PainleveError:
            return False
        self.counters["rhs"] += 1
        free = np.linalg.solve(kin[0], kin[1])
        scale = max(float(np.max(np.abs(free), initial=0.0)),
                    float(np.max(np.abs(a - free), initial=0.0)))
        if np.max(np.abs(a), initial=0.0) > 1e-12 * scale:
            return False
        breaks = self.scene.forcing_breakpoints(t, self.t_bound)
        t_end = float(breaks[0]) if len(breaks) else self.t_bound
        if not _constant_forcing(self.scene, q, v, t, t_end):
            return False
        n = self.scene.ndof
        y = np.concatenate([q, v])
        self.counters["segments"] += 1
        self.counters["rest_phases"] = self.counters.get("rest_phases", 0) + 1
        if self.phases is not None:
            self.phases.append((t, t_end, lambda s, y=y: y.copy(), mode.copy()))
        if self._want_pieces:
            self._add_piece(np.array([t, t_end]), lambda s, y=y: y.copy(),
                            lambda s, mode=mode.copy(): self._sample_row(s, q, v, mode))
        while self._next_sample < t_end:
            self._record_state(self._next_sample, y[:n].copy(), y[n:].copy())
            self._next_sample += self.sample_dt
        self.t = t_end
        self._record_state(self.t, self.q, self.v)
        return True

    def result(self):
        res = super().result()
        if self.ms.nj:
            res.constraint_drift = self._max_drift
        return res

    def _step_impl(self):
        if self.t == self._last_event_t:
            self._stalled += 1
            if self._stalled > 50:
                raise MoreauError(f"more than 50 events at t = {self.t:.15g} without progress "
                                  f"(contact modes {self.ms.letters(self.mode)})")
        else:
            self._last_event_t, self._stalled = self.t, 0
        if self._rest_phase():
            return
        rhs, events, meta, evaluate = self._phase_functions()
        y0 = np.concatenate([self.q, self.v])
        self.counters["segments"] += 1
        sol = solve_ivp(rhs, (self.t, self.t_bound), y0, method=self.ode_method, rtol=self.rtol,
                        atol=self.atol, events=events or None, dense_output=True,
                        max_step=self.max_step)
        t0, mode = self.t, self.mode.copy()
        y1 = self._follow_phase(sol, lambda t, q, v: self._sample_row(t, q, v, mode))
        if self.phases is not None:
            self.phases.append((t0, self.t, sol.sol, self.mode.copy()))
        n = self.scene.ndof
        self.q, self.v = y1[:n].copy(), y1[n:].copy()
        if sol.status != 1:
            self.q, self.v = self._project(self.t, self.q, self.v, self.mode)
            self._record_state(self.t, self.q, self.v)
            return
        fired = [k for k, te in enumerate(sol.t_events) if len(te)]
        kinds = [meta[k] for k in fired]
        forced = {}
        contact = kinds[0][1] if kinds else None
        label = "transition"
        for kd in kinds:
            if kd[0] == "painleve":
                raise PainleveError(
                    f"Painlevé condition fails at t = {self.t:.12g}: contact {kd[1]} slides "
                    f"({Regime(int(self.mode[kd[1]])).letter}) with a normal-force coefficient "
                    f"WN M^-1 (WN - mu s WT)^T that reaches 0 (mu = {self.ms.mu[kd[1]]:.6g}); "
                    "the contact problem loses existence or uniqueness")
            if kd[0] == "liftoff":
                forced[kd[1]] = _F
                label = "liftoff"
            elif kd[0] == "cone":
                forced[kd[1]] = kd[2]
        self._resolve(kind=label, forced=forced, contact=contact)
        self._record_state(self.t, self.q, self.v)


def _constant_forcing(scene, q, v, t0, t1):
    """Whether the scene's functions at ``(q, v)`` give the same numbers over ``[t0, t1]``.

    Probed at 16 evenly spread times and at ``t0 + 10^k`` (``k >= -6``) inside
    the interval, against ``t0``.

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> _constant_forcing(BouncingBall(), np.array([0.05]), np.zeros(1), 0.0, 1e9)
    True
    """
    def values(s):
        out = [scene.forces(q, v, s), scene.gaps(q, s), *scene.contact_jacobians(q, s),
               *scene.contact_drift(q, v, s)]
        if joint_row_count(scene):
            out += [scene.joint_residuals(q, s), *scene.joint_jacobians(q, s),
                    scene.joint_drift(q, v, s)]
        return [np.asarray(x, dtype=float) for x in out]

    ref = values(t0)
    span = t1 - t0
    probes = list(t0 + span * np.linspace(0.0, 1.0, 17)[1:])
    probes += [t0 + 10.0 ** k for k in range(-6, 20) if 10.0 ** k < span]
    for s in probes:
        if not all(np.array_equal(a, b) for a, b in zip(ref, values(s))):
            return False
    return True


@register_integrator("event-driven")
class EventDrivenReference(Integrator):
    """The event-driven reference of any scene (``"event-driven"``).

    A scene that has its own high-precision event-driven scheme names it in
    its ``reference_integrator`` attribute (the friction drive:
    ``"friction-drive-walker"``); every other scene gets
    :class:`GenericEventDriven`. Constructing this class returns an instance
    of the selected scheme, so ``result.scheme`` names the scheme that ran.
    To force one, use ``"event-driven-generic"`` or the scene's own name.

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> type(EventDrivenReference(BouncingBall(), 0.0, [1.0], [0.0], 1.0)).__name__
    'GenericEventDriven'
    >>> sc = FrictionDrive()
    >>> type(EventDrivenReference(sc, 0.0, *sc.rest_state(), 1.0)).__name__
    'EventDriven'
    """

    @staticmethod
    def resolve(scene):
        """The scheme that runs ``scene``: its own reference, or the generic one."""
        name = getattr(scene, "reference_integrator", None)
        return get_integrator(name) if name else GenericEventDriven

    def __new__(cls, scene, *args, **options):
        obj = cls.resolve(scene)(scene, *args, **options)
        obj.scheme = "event-driven"
        return obj
