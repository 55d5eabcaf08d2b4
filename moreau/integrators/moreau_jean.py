r"""Moreau–Jean time stepping: the theta-scheme with velocity-level contact.

The scheme
----------
One step goes from ``(q_k, v_k)`` at ``t_k`` to ``t_{k+1} = t_k + h``::

    M (v_{k+1} - v_k) = h [theta h_{k+1} + (1 - theta) h_k] + H^T p
    q_{k+1}           = q_k + h [theta v_{k+1} + (1 - theta) v_k]

with ``theta`` in ``[1/2, 1]``, ``M = M(q_k)``, ``h_k = h(q_k, v_k, t_k)`` and
``p`` the contact impulses over the step (``H`` stacks the normal rows ``WN``
of the active contacts and the tangential rows ``WT`` of the active
frictional ones). Stiff forces are made implicit by linearising ``h_{k+1}``
about ``(q_k, v_k)`` at ``t_{k+1}``::

    h_{k+1} ~ h(q_k, v_k, t_{k+1}) + K (q_{k+1} - q_k) + C (v_{k+1} - v_k),
    K = dh/dq,  C = dh/dv   (both at (q_k, v_k, t_{k+1})).

With ``q_{k+1} - q_k = h v_k + h theta (v_{k+1} - v_k)`` this gives the
linear "iteration matrix" and the free velocity (the velocity without
contact impulses)::

    W_hat  = M - h theta C - h^2 theta^2 K
    v_free = v_k + W_hat^-1 ( h [theta h(q_k, v_k, t_{k+1}) + (1 - theta) h_k]
                              + h^2 theta K v_k )
    v_{k+1} = v_free + W_hat^-1 H^T p

so a stiff spring only stiffens ``W_hat`` and never forces a small step
(``theta = 1`` damps its oscillation, ``theta = 1/2`` keeps it undamped; for a
linear force law ``theta = 1/2`` is the trapezoidal rule and conserves the
energy exactly).

Contacts
--------
*Index set.* Contact ``i`` enters the step's contact problem when its
predicted gap is closed, ``g_i(q_k, t_k) + (h/2) gdot_i(t_k) <= 0``, or when
it carried a normal impulse in the previous step. The second clause is a
deliberate addition: in a closed *curved or moving* contact (the friction
drive's rod on its rotor) a velocity-level scheme lets the gap wander by
``O(h)`` while the contact keeps pressing, and the predicted-gap test alone
would then open it for one step, every few steps (measured on the friction
drive at 185 Hz, 2000 steps per period, in the steady state: 54 spurious
flight steps per period, and 1002 with projection, which leaves the gap at
rounding level with either sign). A closed contact leaves the index set
only through its own contact problem: ``p_N = 0`` with ``v_N >= 0``.

*Contact problem.* With the contact Jacobians evaluated at ``q_k`` and the
rheonomic terms ``wN, wT`` at ``t_{k+1}``, the local velocities after the
step are ``U = U_free + W p`` with ``U_free = H v_free + w(t_{k+1})`` and the
Delassus matrix ``W = H W_hat^-1 H^T``. Newton's impact law and 2D Coulomb
friction hold at velocity level::

    0 <= v_N,k+1 + e min(v_N,k, 0)  _|_  p_N >= 0
    stick |p_T| <= mu p_N with v_T,k+1 = 0, or slip p_T = -mu p_N sign(v_T,k+1)

where ``v_N,k = WN(q_k, t_k) v_k + wN(q_k, t_k)`` is the approach velocity
at the start of the step. This is the LCP of
:func:`moreau.lcp.friction.build_friction_lcp`, solved with
:func:`moreau.lcp.solve_lcp` (Lemke, falling back to QP with
``lcp_method="auto"``). A frictionless contact adds no tangential rows, a
step with no active contact solves nothing, a step with a single active
contact is solved by exact enumeration (:func:`one_contact_impulse`), and
no restitution term enters where ``e = 0``.

*Joints.* A scene with joint rows (:class:`~moreau.model.scene.Scene`'s
``joint_jacobians``, ``G = WE`` with the rheonomic term ``w = wE``, so that
``d phi/dt = G(q) v + w(t)`` for the joints' residuals ``phi = gE``) adds
them to the step's problem as equality rows with free reactions ``P``: rows
``[E; N; T]`` of :class:`moreau.contact.ContactProblem`, a mixed LCP solved
by :func:`moreau.contact.solve` (the equality rows eliminated by their Schur
complement; dependent rows raise :class:`~moreau.lcp.mlcp.RankDeficientError`,
and are refused before the first step where they are dependent at the
start). By default (``joint_rows="end"``) the rows hold the end velocity,
``G(q_k + h v_k) v_{k+1} + w(t_{k+1}) = 0``, at the predicted end point. With
``joint_rows="theta"`` they hold the joints on the velocity that moves the
positions, ``v_theta = theta v_{k+1} + (1 - theta) v_k``::

    G(q_th) v_theta + w(t_th) = 0,   q_th = q_k + theta h v_k,  t_th = t_k + theta h

(a target ``-(1 - theta)/theta (G v_k + w)`` on ``G v_{k+1} + w``). At
``theta = 1`` both are the same row. At ``theta = 1/2`` the ``"theta"`` rows
keep a conservative mechanism's energy (below) but do not hold the end
velocity on the joints: ``G v_{k+1} + w = -(G v_k + w)`` lets a velocity
across a joint, once a contact impulse has put one there, alternate in sign
from step to step instead of vanishing (a pinned rod resting on a stop keeps
velocities of 6e-3 at ``h = 0.01``, where the ``"end"`` rows bring it to rest
to 1e-17). So ``"end"`` is the default, at the price of a first-order energy
error at ``theta = 1/2`` (the next paragraph). ``joint_rows="theta-projected"``
takes the ``"theta"`` rows and then moves the end velocity to the
mass-weighted nearest one on the joints at the end point, ``v_{k+1} -=
M^-1 G^T (G M^-1 G^T)^-1 (G v_{k+1} + w)`` with ``G, w`` at ``(q_{k+1},
t_{k+1})`` (the generic step). The step itself keeps the energy as the
``"theta"`` rows do; the projection removes the kinetic energy of the
velocity across the joints, ``c^T (G M^-1 G^T)^-1 c / 2`` with ``c = G v +
w``. After a projection ``c`` is zero at ``q_k``; the next rows, at the
predicted midpoint ``q_th``, leave at ``q_{k+1}`` only the difference of the Jacobian's
variation over the two half steps, so the energy error stays second order
while no velocity is left across the joints (the double pendulum against
its wall, ``theta = 1/2``: energy error 1.46e-2, 2.72e-3, 5.66e-4 at ``h =
0.04, 0.02, 0.01``, ``|G v + w|`` below 1e-15; the ``"end"`` rows 0.71, 0.39,
0.21; a pinned rod on a stop comes to rest to 1.5e-18).

*Energy.* With a constant mass matrix (maximal coordinates) and a constant
force ``f`` (gravity; ``K = C = 0``) the step is ``M (v_{k+1} - v_k) = h f +
G^T P + H^T p`` and ``q_{k+1} - q_k = h v_theta``, so with ``E = v^T M v / 2
- f^T q``::

    E_{k+1} - E_k = (v_{k+1} - v_k)^T M (v_{k+1} + v_k) / 2 - h f^T v_theta
                  = (h f + G^T P + H^T p)^T (v_{k+1} + v_k) / 2 - h f^T v_theta

At ``theta = 1/2``, ``v_theta = (v_{k+1} + v_k) / 2`` and the ``f`` terms
cancel: ``E_{k+1} - E_k = P^T G v_theta + p^T H v_theta``. A scleronomic
joint row (``w = 0``) makes the first term vanish whatever point ``G`` is
evaluated at, and a frictionless contact with ``e = 1`` the second (its
``p_N > 0`` only with ``H v_{k+1} = -H v_k``, both at ``q_k``). The double
pendulum against its wall keeps its energy to rounding (1.4e-14 over a
strike at ``h = 0.005``); with ``M(q)`` or a nonlinear force the
trapezoidal rule's ``O(h^2)`` error remains. Rows on ``v_{k+1}`` alone
(``G v_{k+1} + w = 0``) would leave ``P^T G v_theta = P^T G v_k / 2``
with ``G v_k = O(h)`` and ``P = O(h)``: ``O(h^2)`` a step, a first-order
energy error (measured with such rows on the pendulum: 0.706, 0.390,
0.205 at ``h = 0.04, 0.02, 0.01``, the Jacobian at the half or the end
point alike).

*Drift.* Along the segment from ``q_k`` to ``q_{k+1}``::

    phi(q_{k+1}, t_{k+1}) - phi(q_k, t_k) = h [G(xi) v_theta + w(tau)]

with ``G(xi), w(tau)`` the averages over the step, which differ from
``G(q_th), w(t_th)`` by ``O(h^2)`` at ``theta = 1/2`` (the midpoint rule,
and ``q_th`` is the midpoint to ``O(h^2)``), by ``O(h)`` otherwise. The
rows make the bracket ``O(h^2)`` or ``O(h)``: the drift grows by ``O(h^3)``
or ``O(h^2)`` a step, second or first order over a fixed time (measured on
the pendulum at ``theta = 1/2``: 2.17e-3, 5.19e-4, 1.32e-4, 3.32e-5 at ``h =
0.04 .. 0.005``; on the slider-crank 4.6e-5 .. 7.2e-7 over ``n = 100 ..
800`` steps, and its slider's position and velocity at order 2; at ``theta
= 1`` order 1 on both). The position-level drift ``|gE|`` is reported as
the result's ``constraint_drift``. With ``joint_projection=True`` it is
held at rounding: after every step the positions are projected onto the
joints, ``q_{k+1}`` moved to the mass-weighted nearest point with ``gE = 0``
by Gauss–Newton iterations ``q += M^-1 G^T d`` with ``(G M^-1 G^T) d = -gE``
(velocities left alone, the iterations counted in
``projection_iterations``). The correction is the drift's growth over the
step, ``O(h^3)`` or ``O(h^2)``, so the scheme keeps its order (measured on
the pendulum at ``theta = 1/2``: drift below 1e-14, energy error 2.4e-3,
5.5e-4, 1.35e-4, 3.3e-5 at ``h = 0.04 .. 0.005``, order 2). It does not
keep the contacts: a correction may move a contact into its obstacle
(the pendulum with ``e = 0.5``, ``mu = 0.3``, ``theta = 1``, ``h = 0.005``
over ``[0, 10]``: largest penetration 2.3e-3 with it, 0 without; the
velocity-level contact rows take over at the next step). ``projection=True``
(onto the contacts, which would not keep the joints) is refused with joints.
On the compiled path (a scene that gives its joint rows compiled,
``compiled_joints()``: the planar builder's) the joints run in their own
loop, :mod:`moreau.integrators._mj_joint_kernels`: the same mixed LCP with
the equality rows eliminated and the contact in closed form; a step with
several active contacts (Lemke) is handed to the generic step. With
``joint_projection`` or a forced ``lcp_method`` a scene with joints takes
the generic step (``fast=True`` is then refused). ``painleve="stop"`` acts
on steps without joints only.

*Baumgarte.* ``joint_baumgarte=alpha`` in ``[0, 1]`` keeps the drift bounded
without a projection. Baumgarte's stabilisation replaces ``phi'' = 0`` by
``phi'' + 2 a phi' + b^2 phi = 0``; the velocity-level rows hold ``phi' =
0`` itself, so its analogue there is ``phi' + gamma phi = 0``, the drift
decaying at the rate ``gamma``. With ``gamma = alpha / h`` (a fraction of
the drift removed a step, whatever ``h``) the rows become::

    "end":    G v_{k+1} + w = -(alpha / h) phi_k
    "theta":  G v_theta + w = -(alpha / h) phi_k,    phi_k = gE(q_k, t_k)

(a target ``-(alpha / h) phi_k``, over ``theta`` for the ``"theta"`` rows).
With the drift's step of *Drift*, ``phi_{k+1} = phi_k + h [G v_theta + w] +
r_k``, where ``r_k`` is ``O(h^3)`` at ``theta = 1/2`` and ``O(h^2)``
otherwise, the ``"theta"`` rows (and both rows at ``theta = 1``) give::

    phi_{k+1} = (1 - alpha) phi_k + r_k,    |phi_k| <= (1 - alpha)^k |phi_0| + max |r| / alpha

a drift that no longer accumulates: an initial one decays by ``1 - alpha`` a
step, and the rest is bounded by the local error over ``alpha`` (``alpha =
1``: one step's, ``O(h^2)`` or ``O(h^3)``, against ``O(h)`` or ``O(h^2)``
accumulated over a fixed time without it). The ``"end"`` rows at ``theta <
1`` hold ``G v_k + w = -(alpha / h) phi_{k-1}`` from the step before, so
``phi_{k+1} = phi_k - alpha (theta phi_k + (1 - theta) phi_{k-1}) + r_k``:
roots of ``z^2 - (1 - alpha theta) z + alpha (1 - theta)``, inside the unit
circle for ``0 < alpha <= 1`` and ``1/2 <= theta <= 1`` (``P(1) = alpha >
0``, ``P(-1) = 2 + alpha (1 - 2 theta) > 0``, ``|alpha (1 - theta)| < 1``),
the same bound with ``P(1) = alpha``. The correction is a velocity ``(alpha /
h) phi``, ``O(h)`` or ``O(h^2)`` where the drift is the local error, so the
scheme keeps its order; it is not energy-neutral (it does work through the
joint impulses). Measured on the slider-crank over ten crank turns (the
crank's period at 100 and 200 steps, drift ``max |gE|``): ``theta = 1``
without it 1.56e-2 in the first turn and 3.64e-2 in the tenth at ``n = 100``
(7.8e-3, 1.8e-2 at 200), with ``alpha = 1`` 5.55e-4 in both (1.39e-4 at 200:
order 2), ``alpha = 0.5`` 1.10e-3, ``alpha = 0.1`` 4.7e-3; ``theta = 1/2``
with ``"theta"`` rows 8.2e-5 without, 3.1e-6 with ``alpha = 1`` (3.9e-7 at
200: order 3); the slider's position error falls with the drift (6.3e-2 to
6.2e-4 at ``theta = 1``, ``n = 100``). ``alpha = 0`` is the scheme without it,
bit for bit. Both the generic step and the compiled loop of joints take it.

*Spatial scenes* (:mod:`moreau.model.space`: ``q`` holds each body's centre
and unit quaternion, ``v`` its centre velocity and body-frame angular
velocity) take their own generic step. Each active contact has three rows
``[n, t1, t2]``; the step's problem ``U = U_free + W p`` with ``W = H M^-1
H^T`` is the spatial Coulomb problem of :mod:`moreau.contact.cone3d` (Newton's
impact law on the normal row), solved on the cone the option ``cone`` names:
``"exact"`` (Gauss–Seidel with the exact local solve and an Alart–Curnier
Newton polish, certified by the De Saxcé natural-map residual) or an integer
``d`` (the ``d``-direction polyhedral LCP by Lemke); the default ``"auto"``
is ``d = 8`` on a scene of point contacts and the exact cone on a scene with
a contact patch (below) or with box contacts between bodies (sphere–box,
box–box, :meth:`moreau.model.space.SpaceModel.add_box_contact`: the Python
step finds their points at every step; the compiled loop refuses them). An
unsolved problem raises :class:`~moreau.errors.LCPError` with the residual.
The centres move by ``h (theta v_{k+1} + (1 - theta) v_k)`` and each
quaternion by the exponential map of the same weighted body rate
(``p ⊗ exp(h omega / 2)``, unit to rounding). The forces other than the
gyroscopic one enter as in the planar step (with the state of ``t_k``); a
body with an anisotropic inertia turns by its own implicit step, ``J
(omega_free - omega_k) + h omega_t x J omega_t = h tau`` with ``omega_t =
theta omega_free + (1 - theta) omega_k`` (Newton on the 3x3 system; at
``theta = 1/2`` the implicit midpoint rule, which keeps a free body's energy
and ``|J omega|`` to rounding), and the contact impulses are added to that
free velocity through ``M^-1`` (a splitting: the cone solvers need the
symmetric ``W = H M^-1 H^T``, which the gyroscopic Jacobian would break; its
error is ``O(h)`` only where contacts act on a body spinning about a
non-principal axis). A contact's recorded tangential force and slip
are magnitudes, its regime ``P`` for slip in any direction. ``projection``
is refused. A contact with a patch (``contact_radius > 0``: Coulomb–Contensou
friction, :mod:`moreau.model.space`) adds its drilling row to the three,
and the step solves the round cone with three tangential rows
(:func:`moreau.contact.cone3d.solve_exact_contensou`); it takes
``cone="exact"`` (the default ``"auto"`` picks it) and refuses an integer
``cone`` by name. The step
runs in the compiled loop of :mod:`moreau.integrators._space_kernels` for
scenes whose contacts are spheres and material points (pucks) against
half-spaces, with or without a patch, and spheres of two bodies against each
other, the same step to rounding, the exact
cone's Newton polish included
(several contacts on one body: a puck's rim points, a box's corners); a
contact problem the loop does not finish (the exact cone where that Newton
misses the tolerance and the exact solver restarts from the polyhedral
solution; a Lemke failure) is handed to the Python step, which stays the
reference (``fast=False``).

*Compiled path.* Scenes with a ``compiled_model()`` (all shipped ones) run
the same step in the compiled loop of :mod:`moreau.integrators._mj_kernels`,
Lemke included (:func:`moreau.lcp.lemke.lemke_core`); a step on which Lemke
fails is handed back to this module's generic step (QP fallback) and the
loop resumes. The generic step stays as the reference (``fast=False``).

*Regimes.* Each step's regime is read from its impulses
(:func:`classify_impulse`): flight when ``p_N = 0`` (or the contact is not
active), positive slip when ``p_T = -mu p_N``, negative slip when
``p_T = +mu p_N``, stick when ``|p_T| < mu p_N``. A closed frictionless
contact has no tangential information and is reported as ``STICK``.

*Drift and projection.* The gap is only controlled through velocities, so
it drifts. On the friction drive (1000 steps per period, ``theta = 1``) the
closed contact's gap creeps open by 5.5e-8 per period (1.1e-7 with
``theta = 1/2``): 5.5e-5 after 1000 periods, 3 % of the stator amplitude,
enough to change the displacement per period at 20 Hz from -2.45e-4 to
about 0. With projection the gap stays below 1.3e-15 and the displacement
per period does not change over 1000 periods. With ``projection=True`` the
positions are corrected after every
step by a mass-weighted projection: every contact that carried a normal
impulse is put back on ``g = 0`` and every penetrating contact on ``g >= 0``
(Gauss–Newton iterations ``q += M^-1 WN^T d`` with
``(WN M^-1 WN^T) d = -g``; velocities are left alone). It assumes ``v = dq/dt``,
i.e. ``WN`` is the gradient of the gap, which holds for all scenes of this
package.

*Warm start.* On the compiled path with ``lcp_method="auto"``, a
multi-contact step is first solved without pivoting. From the second step
of a run on, the contacts keep the regimes of the step before (open,
slipping either way, sticking): the normal impulses of the loaded contacts
and the tangential ones of the sticking contacts solve their zero-velocity
equations on the Delassus matrix (2 x 2 for two sliding contacts; where
sticking contacts are statically indeterminate, one impulse of the
dependent set is set to zero, a vertex of the solution set). On the first
step, the support of the last LCP with the same active contacts is tried
(the principal subsystem ``M_BB z_B = -q_B``, ``z = 0`` off ``B``). Either
answer is kept only when it passes the check a Lemke solution must pass
(:func:`moreau.lcp.lcp_violation` to Lemke's tolerance) with every
inequality clear of its bound; otherwise Lemke runs, from scratch. While
the contacts keep their regimes no pivot is needed
(``lcp_warm_start=False`` turns it off). The generic step solves with
Lemke first and keeps the support of its last LCP on the same active
contacts: where Lemke's path meets a tie it would finish in exact
arithmetic, that support's point is tried before the QP, checked the same
way (:func:`~moreau.integrators.contact_problem.solve_contact_problem`'s
``warm``; the bidirectional drive's rods sticking at the cone's edge). A
solution near a change of regime (a slip ending within the step, a contact
about to lift off) is refused, so that the choice between two solutions
within rounding of each other is Lemke's, as on the generic path. Where the
contact problem has a unique solution the answer is Lemke's to Lemke's
accuracy, and on nearly dependent contact rows more accurate: on a box
tumbling onto both corners Lemke's sliding friction is off the cone by up
to 1.3e-7 of ``mu f_N`` (inside its certification), the warm answer by
3e-12. Where the problem has several solutions (statically indeterminate
sticking, e.g. both rods of :class:`~moreau.scenes.BidirectionalDrive`
sticking on the rotor at once, or the box resting on both corners) the
motion is the same to rounding but the split of the impulses is not
determined by the model, and the warm start may keep another vertex than
Lemke picks; the normal forces and the total friction agree.

Statistics (``SimulationResult.stats``)
---------------------------------------
``steps``; ``lcp_solves`` (contact problems solved, by Lemke/QP, the
one-contact enumeration or a warm start); ``direct_solves`` (the
enumeration's share); ``warm_starts`` (the share solved without pivoting,
in the regimes of the step before or on the previous support, compiled
path; on a spatial scene's Python step, a polyhedral LCP solved on the last
one's support where Lemke would have finished its path in exact arithmetic,
see :func:`moreau.lcp.solve_lcp`'s ``"auto"``); ``pivots`` (Lemke pivots);
``fallbacks`` (solves where ``"auto"`` fell back to QP); ``max_residual``
(largest scaled complementarity residual, :func:`moreau.lcp.lcp_residual`
of the friction LCP; on the compiled path Lemke's measure,
:func:`moreau.lcp.lcp_violation`; with ``lcp_method`` ``"nsgs"`` or
``"apgd"`` the certified natural-map residual, and ``iterations`` their
sweeps or gradient steps); ``max_penetration`` (largest ``-g``
after a step, 0 if none); ``projection_iterations``.
"""

import dataclasses
from typing import ClassVar

import numpy as np

from ..contact import ContactProblem, solve as solve_problem
from .._validate import in_closed_interval, positive_int
from ..errors import InputError, LCPError
from ..lcp.mlcp import RankDeficientError, equality_block
from ..model.scene import is_spatial, joint_row_count
from ..regimes import Regime
from .base import register_integrator
from .contact_problem import one_contact_impulse, one_contact_residual, solve_contact_problem
from ._blocks import FAST_BLOCK
from ._mj_joint_kernels import J_STAT_NAMES, run_joint_block
from ._mj_kernels import LCP_HANDBACK, mj_loop, prev_regimes
from ._space_kernels import run_space_loop, space_solver, space_tables
from ._space_step import check_cone, space_step
from ._sparse_mj import (ITERATIVE_METHODS, SPARSE_TOL, iterative_contact_step,  # noqa: F401
                         sparse_contacts_of, sparse_step)
# the time-stepping checks lived here; their names stay importable from this module
from .time_stepping import (LCP_METHODS, MAX_RECORD_BYTES, MAX_STEPS,  # noqa: F401
                            FixedStepOptions, TimeStepping, bool_option, check_lcp_options,
                            check_scene_contacts, optional,
                            check_step, check_step_fits, check_work, compiled_model_of,
                            next_time)

__all__ = ["MoreauJean", "one_contact_impulse", "one_contact_residual", "classify_impulse",
           "LCP_METHODS"]

#: most Python steps taken in a row on a spatial scene after hand-backs of the compiled loop
_MAX_PYTHON_RUN = 64

#: the failure messages of Moreau–Jean's compiled blocks (:meth:`_after_block`'s)
_MJ_FAILURES = dict(
    singular=("the iteration matrix W_hat = M - h theta C - h^2 theta^2 K is singular at "
              "t = {t!r}; reduce `h` or use a smaller `theta`"),
    numerical=("non-finite state after the step at t = {t!r} (the step `h` is probably "
               "too large for an explicit part of the forces)"))

# |p_T| within this relative distance of mu p_N counts as slip: the LCP and
# the enumeration reach the friction-cone boundary only up to rounding
SLIP_RTOL = 1e-10

# a projection iteration stops when every corrected gap is below this (the
# gaps of the package's scenes are O(1e-3 .. 1) in their own units)
PROJECTION_TOL = 1e-14
PROJECTION_MAXITER = 8


def classify_impulse(pN, pT, mu):
    """Regime of one contact from its impulses over a step.

    Parameters
    ----------
    pN, pT : float
        Normal and tangential impulse (``pT = 0`` for a frictionless contact).
    mu : float
        Friction coefficient.

    Returns
    -------
    Regime
        ``FLIGHT`` if ``pN <= 0``; ``POSITIVE`` if ``pT = -mu pN`` and
        ``NEGATIVE`` if ``pT = +mu pN`` (within a relative ``1e-10``);
        ``STICK`` otherwise, including a closed frictionless contact.

    Examples
    --------
    >>> classify_impulse(2.0, -0.2, 0.1).name, classify_impulse(2.0, 0.05, 0.1).name
    ('POSITIVE', 'STICK')
    """
    if not pN > 0.0:
        return Regime.FLIGHT
    if mu > 0.0:
        bound = mu * pN * (1.0 - SLIP_RTOL)
        if pT <= -bound:
            return Regime.POSITIVE
        if pT >= bound:
            return Regime.NEGATIVE
    return Regime.STICK


def _new_counters():
    return {"steps": 0, "lcp_solves": 0, "direct_solves": 0, "pivots": 0, "fallbacks": 0,
            "max_residual": 0.0, "max_penetration": 0.0, "projection_iterations": 0,
            "warm_starts": 0, "tangential_impacts": 0, "tangential_impact_times": []}


@dataclasses.dataclass(frozen=True, kw_only=True)
class ThetaOptions(FixedStepOptions):
    """The options of the Moreau–Jean family's θ-method step, beyond a fixed-step scheme's.

    Examples
    --------
    >>> MoreauJean.Options(h=0.1, theta=0.5).smooth_order()
    2
    """
    theta: float = 1.0
    closed0: object = None
    lemke_max_iter: int | None = None
    lcp_warm_start: bool = True

    def smooth_order(self):
        # the trapezoidal rule at theta = 1/2, a first-order theta-method otherwise
        return 2 if self.theta == 0.5 else 1


def _baumgarte_option(value):
    return in_closed_interval("joint_baumgarte", value, 0.0, 1.0)


def _mj_lcp_method_option(value):
    # Moreau–Jean's steps also run the iterative contact solvers by their registered names
    if value not in LCP_METHODS + ITERATIVE_METHODS:
        raise InputError(f"`lcp_method` must be one of {list(LCP_METHODS + ITERATIVE_METHODS)}, "
                         f"got {value!r}")
    return value


def _lcp_omega_option(value):
    value = float(value)
    if not 0.0 < value < 2.0:
        raise InputError(f"`lcp_omega` must lie in (0, 2), got {value!r}")
    return value


def _lcp_tol_option(value):
    value = float(value)
    if not 1e-15 <= value < 1.0:
        raise InputError(f"`lcp_tol` must lie in [1e-15, 1), got {value!r}")
    return value


def _joint_rows_option(value):
    if value not in ("end", "theta", "theta-projected"):
        raise InputError(f"`joint_rows` must be 'end', 'theta' or 'theta-projected', "
                         f"got {value!r}")
    return value


@register_integrator("moreau-jean")
class MoreauJean(TimeStepping):
    """Moreau–Jean theta-scheme with velocity-level Newton impacts and exact 2D Coulomb friction.

    See the module docstring for the scheme, the index set, the regime
    classification and the statistics.

    Parameters
    ----------
    {start}
    h : float
        Time step (dimensionless), > 0. The grid is ``t0 + k h``; the last
        step is shortened to end on ``t_bound``.
    theta : float
        In ``[1/2, 1]``; 1 is the backward-Euler-like, dissipative choice.
    projection : bool
        Project positions back onto the contacts after every step (refused
        with joints).
    joint_projection : bool
        Project positions onto the joints after every step (a scene with
        joints only; see the module docstring's *Drift*).
    joint_rows : {"end", "theta", "theta-projected"}
        The joints held on the end velocity (default) or on the θ-weighted
        velocity, which keeps a conservative mechanism's energy at θ = ½ but
        lets velocities across the joints alternate, or on the θ-weighted
        velocity with the end velocity then projected onto the joints (energy
        at second order, nothing across the joints; the generic step); module
        docstring, *Joints*.
    joint_baumgarte : float
        ``alpha`` in ``[0, 1]``: the joint rows also remove the fraction
        ``alpha`` of the joints' position residual at the step's start, so
        that the drift stays bounded instead of growing (module docstring,
        *Baumgarte*). 0 (default) leaves the rows as they are.
    cone : "auto", "exact" or int
        On a spatial scene (:mod:`moreau.model.space`), the friction cone of
        each step's problem: ``"exact"`` or the number ``d >= 3`` of the
        polyhedral cone's directions; see "Spatial scenes" in the module
        docstring. ``"auto"`` (default) is ``d = 8`` on a scene of point
        contacts and ``"exact"`` on a scene with a contact patch
        (``contact_radius > 0``: Coulomb–Contensou friction, which the
        polyhedral cone does not model; an integer ``cone`` is refused there
        by name) or with box contacts between bodies (a stack's resting
        faces, four points each, make degenerate polyhedral LCPs on which
        Lemke's pivots cost seconds a step). Planar scenes ignore it.
    lcp_method : {"auto", "lemke", "qp", "nsgs", "apgd"}
        Method of :func:`moreau.lcp.solve_lcp`. With ``"auto"`` a step with
        one active contact is solved in closed form and several active
        contacts go to Lemke with the QP fallback;
        ``"lemke"`` or ``"qp"`` forces that solver on the assembled LCP of
        every contact step, one contact included, so that solvers can be
        compared (``moreau compare``). ``"nsgs"`` and ``"apgd"`` (the
        iterative contact solvers of :mod:`moreau.contact`, by their
        registered names; planar scenes without joints) solve every contact
        step to ``lcp_tol``, warm-started from the last step's impulses, on
        the generic step or a scene's sparse step
        (:mod:`moreau.integrators._sparse_mj`, "Iterative solvers"); a step
        whose solver stops above ``lcp_tol`` fails the run (status -3, the
        residual in the message and in ``stats["max_residual"]``).
    lcp_tol : float, optional
        With ``"nsgs"``/``"apgd"``: the tolerance on the certified natural-map
        residual ``||F(r)|| / (1 + ||q||)``, in ``[1e-15, 1)``; 1e-8 by default.
    lcp_max_iter : int, optional
        With ``"nsgs"``/``"apgd"``: the budget of sweeps or gradient steps of
        each step's solve; 10 000 (NSGS) or 100 000 (APGD) by default.
    lcp_omega : float, optional
        With ``"nsgs"``: the over-relaxation in ``(0, 2)``, 1 by default (on
        a struck chain, :func:`moreau.scenes.ball_chain.sor_omega`).
    lemke_max_iter : int, optional
        Pivot limit of Lemke's method on each step's contact problem (default:
        Lemke's own, at least 1000). A step on which Lemke stops at the limit
        is solved by the QP fallback with ``lcp_method="auto"`` (counted in
        ``stats["fallbacks"]``); with ``"lemke"`` it raises an
        :class:`~moreau.errors.LCPError`. Not with ``"qp"``.
    lcp_warm_start : bool
        On the compiled path with ``lcp_method="auto"``, try the previous
        multi-contact LCP's support before Lemke, and on the generic step
        where Lemke's path would be finished in exact arithmetic (see the
        module docstring; default True). False makes every such step pivot
        from scratch.
    save_every : int
        Record one sample every ``save_every`` steps (and the last one). The
        sample at ``t0`` is the initial state with the first step's regime and
        forces.
    fast : {"auto", True, False}
        Use the compiled loop of :mod:`moreau.integrators._mj_kernels` (the
        same scheme, equal to rounding). ``"auto"`` uses it for every scene
        whose ``compiled_model()`` returns a model (all shipped scenes) unless
        ``lcp_method="qp"``; ``True`` insists; ``False`` takes the generic
        Python step through the :class:`Scene` interface. In the compiled mode
        one call of :meth:`step` advances a block of up to 65536 time steps
        (``stats["steps"]`` still counts time steps).
        A frictionless scene that offers a sparse contact model
        (``sparse_contacts()``: the ball chain from 150 balls) takes its
        sparse step instead, with ``fast`` ``"auto"`` or True,
        ``lcp_method="auto"`` and no projection: the same scheme with ``W``
        in CSR and each step's LCP solved exactly by
        :func:`moreau.lcp.active_set.solve_active_set` (``stats["max_residual"]``
        its natural-map residual; above ``SPARSE_TOL`` = 1e-10 the run fails,
        status -3), or by ``lcp_method`` ``"nsgs"``/``"apgd"``. Elsewhere
        these two take the generic step (``fast=True`` is then refused).
    closed0 : bool or array_like of bool, optional
        Contacts to treat as closed in the step before ``t0`` (the index-set
        memory; see the module docstring). Default: none. Lets a run continue
        another one exactly (:class:`moreau.analysis.mj_steady_state.PeriodMap`);
        the final flags are :attr:`closed`.
    painleve : {"impulse", "stop"}
        What a step does at a tangential impact, a contact sliding into a
        configuration where the discrete Painlevé condition fails the way it
        slides (:func:`~moreau.integrators.contact_problem.tangential_impact`):
        ``"impulse"`` (default) takes the step's unique solution, the
        impulsive stick (dynamic jamming), and counts it in
        ``stats["tangential_impacts"]`` with the step's start time in
        ``stats["tangential_impact_times"]``; ``"stop"`` ends the run with
        status ``-1`` (:class:`~moreau.errors.PainleveError`) at every step
        whose pressed contact's free slip, of any size, runs into a sliding
        piece without solution (a tangential impact, or a stick with a slip of
        rounding size pointing that way: the behaviour before the tangential
        impact was taken), for a study of Painlevé configurations. Detected
        on steps with one active frictional contact.

    Notes
    -----
    Recorded forces are impulse / step; the slip velocity is the one the
    contact problem enforced (Jacobian at ``q_k``, rheonomic terms at
    ``t_{k+1}``), 0 for a frictionless contact; the gap is ``g(q_{k+1}, t_{k+1})``.

    Examples
    --------
    A unit point mass sliding on the ground (gravity 1, ``mu = 0.5``) from
    speed 1 stops at ``t = 2``; with ``h = 0.01`` the discrete velocity is exact:

    >>> import numpy as np
    >>> from moreau.integrators import simulate
    >>> from moreau.model.scene import Scene
    >>> class Block(Scene):
    ...     ndof, mu, restitution = 2, np.array([0.5]), np.array([0.0])
    ...     def mass(self, q): return np.eye(2)
    ...     def forces(self, q, v, t): return np.array([0.0, -1.0])
    ...     def gaps(self, q, t): return np.array([q[1]])
    ...     def contact_jacobians(self, q, t):
    ...         return np.array([[0.0, 1.0]]), np.zeros(1), np.array([[1.0, 0.0]]), np.zeros(1)
    >>> res = simulate(Block(), (0.0, 1.0), [0.0, 0.0], [1.0, 0.0], "moreau-jean", h=0.01)
    >>> round(float(res.v[-1, 0]), 12), res.regime_letters()[-1]
    (0.5, 'P')
    """

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class Options(ThetaOptions):
        """Options of :class:`MoreauJean` (those of every fixed-step scheme,
        :class:`~moreau.integrators.time_stepping.FixedStepOptions`, the
        θ-method's, :class:`ThetaOptions`, ``projection`` and ``joint_projection``)."""
        projection: bool = False
        joint_projection: bool = False
        joint_rows: str = "end"
        joint_baumgarte: float = 0.0
        cone: str | int = "auto"
        lcp_tol: float | None = None
        lcp_max_iter: int | None = None
        lcp_omega: float | None = None
        _rules: ClassVar[dict] = {"joint_projection": bool_option("joint_projection"),
                                  "joint_rows": _joint_rows_option,
                                  "joint_baumgarte": _baumgarte_option,
                                  "cone": check_cone,
                                  "lcp_method": _mj_lcp_method_option,
                                  "lcp_tol": optional(_lcp_tol_option),
                                  "lcp_max_iter": optional(lambda v: positive_int("lcp_max_iter",
                                                                                  v)),
                                  "lcp_omega": optional(_lcp_omega_option)}

        def _check(self):
            super()._check()
            iterative = self.lcp_method in ITERATIVE_METHODS
            for name in ("lcp_tol", "lcp_max_iter", "lcp_omega"):
                if getattr(self, name) is not None and not iterative:
                    raise InputError(f"`{name}` is an option of the iterative contact solvers "
                                     f"(`lcp_method` in {list(ITERATIVE_METHODS)}), got "
                                     f"`lcp_method={self.lcp_method!r}`")
            if self.lcp_omega is not None and self.lcp_method != "nsgs":
                raise InputError("`lcp_omega` over-relaxes NSGS; `lcp_method='apgd'` has none")
            if iterative and self.lemke_max_iter is not None:
                raise InputError(f"`lemke_max_iter` limits Lemke's pivots; "
                                 f"`lcp_method={self.lcp_method!r}` runs no Lemke (its budget "
                                 f"is `lcp_max_iter`)")

    def __init__(self, scene, t0, q0, v0, t_bound, options=None, **keywords):
        super().__init__(scene, t0, q0, v0, t_bound, options, **keywords)
        if self._fast:
            # the compiled path keeps each contact's regime in its control array
            prev_regimes(self._lcp_ctl, self.scene.ncontacts)[:] = self._prev_reg

    solves_joints = True
    solves_space = True

    def _new_counters(self):
        return _new_counters()

    def _warm_start(self):
        return self.lcp_warm_start and self.lcp_method == "auto"

    def _setup_scheme(self):
        nc = self.scene.ncontacts
        if self.closed0 is not None:
            c0 = np.asarray(self.closed0)
            if c0.dtype != bool or c0.size not in (1, nc):
                raise InputError(f"`closed0` must be a bool or {nc} bools (one per contact), "
                                 f"got {self.closed0!r}")
            self._closed[:] = c0.reshape(-1)
        self._n_eq = joint_row_count(self.scene)
        self._max_drift = 0.0
        self._space = is_spatial(self.scene)
        # the Python steps left after the compiled spatial loop handed back a first step,
        # and how many it takes the next time (see _space_block)
        self._python_steps_left, self._python_run = 0, 1
        # the last polyhedral LCP's support, for the next Python step (_space_step.space_step);
        # on box contacts the exact cone starts from the last step's impulses
        self._lcp_memo = {}
        self._warm_cone = (np.zeros((self.scene.ncontacts, 3))
                           if self._space and getattr(self.scene, "box_index", ()) else None)
        if self._space and self.projection:
            raise InputError("`projection` is not defined on a spatial scene (its coordinates "
                             "are not its velocities' integrals); use projection=False")
        drilling = self._space and getattr(self.scene, "drilling", False)
        if self._space and self.cone == "auto":
            # the polyhedral cone has no drilling row; point contacts keep the 8 facets but
            # between boxes, whose resting faces make degenerate LCPs (Lemke's exact
            # arithmetic, seconds a step)
            self.cone = "exact" if drilling or getattr(self.scene, "box_index", ()) else 8
        if drilling and self.cone != "exact":
            raise InputError(f"`cone` must be \"exact\" on scene {self.scene.name!r}: its "
                             f"Coulomb–Contensou friction (a contact with `contact_radius` > 0) "
                             f"has no polyhedral form here, got cone={self.cone!r}")
        self._end_gap = None
        if self.lcp_method in ITERATIVE_METHODS and (self._space or self._n_eq):
            raise InputError(f"`lcp_method={self.lcp_method!r}` solves the contacts of a planar "
                             f"scene without joints; scene {self.scene.name!r} is "
                             + ("spatial" if self._space else "jointed")
                             + ": use lcp_method='auto'")
        if getattr(self, "joint_projection", False) and not self._n_eq:
            raise InputError(f"`joint_projection` projects the positions onto the joints; scene "
                             f"{self.scene.name!r} has no joint rows: use joint_projection=False")
        if getattr(self, "joint_baumgarte", 0.0) and not self._n_eq:
            raise InputError(f"`joint_baumgarte` corrects the joints' drift; scene "
                             f"{self.scene.name!r} has no joint rows: use joint_baumgarte=0")
        if self._n_eq:
            self._check_joints()

    def _joint_model(self, model, options):
        # the compiled loop of joints: the scene's joint rows as a compiled function, the
        # contact problem by the closed form as "auto" solves it (a forced solver, and the
        # joints' projection, take the generic step)
        joints = getattr(self.scene, "compiled_joints", None)
        joints = joints() if joints is not None else None
        if model is None or joints is None or self.lcp_method != "auto" \
                or self.joint_projection or self.joint_rows == "theta-projected" or self._space:
            return None
        return model

    def _check_joints(self):
        # refused before any work: what the generic step does not do with joints, and
        # joint rows that are dependent at the start (redundant or inconsistent joints)
        sc = self.scene
        if self.projection:
            raise InputError("`projection` projects onto the contacts only; the scene has "
                             f"{self._n_eq} joint rows, which it would not keep: use "
                             "projection=False (and joint_projection=True to project onto "
                             "the joints)")
        WE, _ = sc.joint_jacobians(self.q, self.t0)
        WE = np.asarray(WE, dtype=float)
        A = WE @ np.linalg.solve(np.asarray(sc.mass(self.q), dtype=float), WE.T)
        try:
            equality_block(A, label="joint rows")
        except RankDeficientError as exc:
            raise InputError(f"`scene` {sc.name!r}: its joints are redundant or inconsistent "
                             f"at the initial state: {exc}") from None
        g0 = np.asarray(sc.joint_residuals(self.q, self.t0), dtype=float)
        self._max_drift = float(np.max(np.abs(g0), initial=0.0))

    def result(self):
        res = super().result()
        if self._n_eq:
            res.constraint_drift = self._max_drift
        return res

    @property
    def closed(self):
        """Contacts that carried a normal impulse in the last step (the index-set memory), a copy."""
        return self._closed.copy()

    # -- one step -------------------------------------------------------------
    def _choose_compiled(self, fast, model, lcp_method, lemke_max_iter=None, warm_start=False):
        # a long frictionless chain's own sparse step (moreau.integrators._sparse_mj)
        self._sparse = None
        iterative = lcp_method in ITERATIVE_METHODS
        if not self._space and fast is not False and (lcp_method == "auto" or iterative) \
                and not self.projection and not self._n_eq:
            self._sparse = sparse_contacts_of(self.scene)
        if self._sparse is not None:
            return super()._choose_compiled(False, None, lcp_method, lemke_max_iter, warm_start)
        if iterative:
            # the compiled loop solves by closed form and Lemke: these solvers take the
            # generic step
            if fast is True:
                raise InputError(f"`fast=True` solves contacts in closed form or by Lemke; "
                                 f"`lcp_method={lcp_method!r}` needs fast='auto' or False on "
                                 f"scene {self.scene.name!r}")
            return super()._choose_compiled(False, None, lcp_method, lemke_max_iter, warm_start)
        if not self._space:
            return super()._choose_compiled(fast, model, lcp_method, lemke_max_iter, warm_start)
        if getattr(self.scene, "box_index", ()):
            # box contacts between bodies change their points as the bodies move: the
            # Python step finds them at every step, the compiled loop cannot state them
            if fast is True:
                raise InputError(f"`fast=True`: the compiled spatial step cannot state box "
                                 f"contacts between bodies (sphere-box, box-box: their points "
                                 f"change as the bodies move); scene {self.scene.name!r} has "
                                 f"them: use fast='auto' or False (the generic step)")
            return super()._choose_compiled(False, None, lcp_method, lemke_max_iter, warm_start)
        # a spatial scene's compiled loop is this module's own (its scene has no compiled model)
        tables = None
        if fast is not False:
            tables = space_tables(self.scene, self.cone, self.mu_c, self.e_c)
        if fast is True and tables is None:
            raise InputError(f"`fast=True`: the compiled spatial step knows spheres and material "
                             f"points against half-spaces and spheres against spheres; scene "
                             f"{self.scene.name!r} has other contacts: use fast='auto' or False "
                             "(the generic step)")
        super()._choose_compiled(fast, tables, lcp_method, lemke_max_iter, warm_start)

    def _runner(self, template):
        if self._space:
            return run_space_loop
        return super()._runner(template)

    def _step_impl(self):
        if self._sparse is not None:
            return sparse_step(self, self._sparse)
        if self._fast:
            return self._space_block() if self._space else self._fast_block()
        return self._generic_step()

    def _generic_step(self):
        """One step through the :class:`Scene` interface (the reference of the compiled loop)."""
        if self._space:
            return self._space_step()
        sc, theta = self.scene, self.theta
        t0, q, v = self.t, self.q, self.v
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)

        M = np.asarray(sc.mass(q), dtype=float)
        f = np.asarray(sc.forces(q, v, t1), dtype=float)
        K, C = (np.asarray(a, dtype=float) for a in sc.force_jacobians(q, v, t1))
        if theta != 1.0:
            f = theta * f + (1.0 - theta) * np.asarray(sc.forces(q, v, t0), dtype=float)
        rhs = h * f + (h * h * theta) * (K @ v)
        W_hat = M - (h * theta) * C - (h * h * theta * theta) * K
        Winv = _inverse(W_hat)
        if Winv is None:
            self.counters["steps"] -= 1     # the base class counts this failed step
            self._fail(-5, f"the iteration matrix W_hat = M - h theta C - h^2 theta^2 K is "
                           f"singular at t = {t0!r}; reduce `h` or use a smaller `theta`")
            return
        v_free = v + Winv @ rhs

        nc = sc.ncontacts
        pN = np.zeros(nc)
        pT = np.zeros(nc)
        slip = np.zeros(nc)
        active = np.zeros(nc, dtype=bool)
        v1 = v_free
        vN0 = np.zeros(nc)
        if nc:
            # the gaps at the end of the step before, when this step starts from its state
            g0 = (self._end_gap[2] if self._end_gap is not None and self._end_gap[0] is q
                  and self._end_gap[1] == t0 else np.asarray(sc.gaps(q, t0), dtype=float))
            WN0, wN0, _, _ = sc.contact_jacobians(q, t0)
            vN0 = np.asarray(WN0, dtype=float) @ v + np.asarray(wN0, dtype=float)
            active = (g0 + 0.5 * h * vN0 <= 0.0) | self._closed
            if active.any() and not self._n_eq:
                v1, slip = self._contact_step(q, t1, v_free, Winv, active, vN0, pN, pT)
        if self._n_eq:
            # the joints' Jacobian at the predicted theta-point ("theta" rows) or end point
            th = theta if self.joint_rows != "end" else 1.0
            q_th = q + (th * h) * v
            t_th = t1 if th == 1.0 else t0 + th * h
            v1, slip = self._joint_step(q, v, q_th, t_th, t1, v_free, Winv, active, vN0, pN, pT)

        q1 = q + h * (theta * v1 + (1.0 - theta) * v)
        closed = pN > 0.0
        if self.projection and nc:
            q1 = self._project(q1, t1, closed)
        if self._n_eq and self.joint_projection:
            q1 = self._project_joints(q1, t1)
        if self._n_eq and self.joint_rows == "theta-projected":
            v1 = self._project_joint_velocity(q1, t1, v1)
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            # no NaN may leave the integrator: stop here, keep the last good state
            self.counters["steps"] -= 1
            self._fail(-5, f"non-finite state after the step at t = {t0!r} (the step `h` is "
                           f"probably too large for an explicit part of the forces)")
            return
        gap = np.asarray(sc.gaps(q1, t1), dtype=float) if nc else np.zeros(0)
        if self._n_eq:
            gE = np.asarray(sc.joint_residuals(q1, t1), dtype=float)
            self._max_drift = max(self._max_drift, float(np.max(np.abs(gE), initial=0.0)))
        if nc:
            self.counters["max_penetration"] = max(self.counters["max_penetration"],
                                                   float(np.max(-gap, initial=0.0)))
        regime = np.array([int(classify_impulse(pN[i], pT[i], self.mu_c[i])) for i in range(nc)])
        self._regimes_before()[:] = regime
        self._closed = closed
        self._k += 1
        self.t, self.q, self.v = t1, q1, v1
        self._end_gap = (q1, t1, gap)

        fN, fT = pN / h, pT / h
        if self._pending_initial:
            self._record(t0, q, v, regime, fN, fT, slip, g0 if nc else gap)
            self._pending_initial = False
        last = t1 >= self.t_bound
        if self._k % self.save_every == 0 or last:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)

    def _space_step(self):
        """One step on a spatial scene (the module docstring's "Spatial scenes")."""
        sc = self.scene
        t0, q, v = self.t, self.q, self.v
        t1, h = next_time(self.t0, self._k, self.h, self.t_bound)
        q1, v1, pN, pT, slip, regime = space_step(sc, q, v, t0, t1, h, self.theta, self._closed,
                                                  self.mu_c, self.e_c, self.cone, self.counters,
                                                  self._lcp_memo, self._warm_cone)
        if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(v1))):
            self.counters["steps"] -= 1
            self._fail(-5, f"non-finite state after the step at t = {t0!r}")
            return
        gap = np.asarray(sc.gaps(q1, t1), dtype=float)
        if gap.size:
            self.counters["max_penetration"] = max(self.counters["max_penetration"],
                                                   float(np.max(-gap, initial=0.0)))
        self._prev_reg[:] = regime
        self._closed = pN > 0.0
        self._k += 1
        self.t, self.q, self.v = t1, q1, v1
        fN, fT = pN / h, pT / h
        if self._pending_initial:
            self._record(t0, q, v, regime, fN, fT, slip, np.asarray(sc.gaps(q, t0), float))
            self._pending_initial = False
        if self._k % self.save_every == 0 or t1 >= self.t_bound:
            self._record(t1, q1, v1, regime, fN, fT, slip, gap)

    def _joint_block(self):
        """One block of the compiled loop of joints (:mod:`._mj_joint_kernels`)."""
        sc, m = self.scene, self._model
        n, nc = sc.ndof, sc.ncontacts
        q, v = self.q.copy(), self.v.copy()
        closed = np.ascontiguousarray(self._closed, dtype=bool).copy()
        reg = np.ascontiguousarray(self._regimes_before(), dtype=np.int64).copy()
        buf = self._block_buffers(n)
        st = np.zeros(len(J_STAT_NAMES))
        status, k, nrec = run_joint_block(
            m.mass, m.forces, m.contacts, sc.compiled_joints(), n, nc, self._n_eq,
            m.has_jacobians, m.par, np.ascontiguousarray(self.mu_c, dtype=float),
            np.ascontiguousarray(self.e_c, dtype=float), float(self.t0), float(self.h),
            float(self.t_bound), self._k, getattr(self, "_block_limit", FAST_BLOCK), q, v,
            float(self.theta), self.joint_rows != "end", float(self.joint_baumgarte), closed,
            reg, self.save_every,
            self._pending_initial, *buf, st)
        self._keep_block(k, nrec, buf)
        self.q, self.v, self._closed = q, v, closed
        self._regimes_before()[:] = reg
        c = self.counters
        c["lcp_solves"] += int(st[0])
        c["max_residual"] = max(c["max_residual"], float(st[1]))
        c["max_penetration"] = max(c["max_penetration"], float(st[2]))
        self._max_drift = max(self._max_drift, float(st[3]))
        # a step the loop leaves (several contacts, a rank-deficient joint block, a case the
        # closed form does not decide) is the generic step's, which solves it or says why not
        self._after_block(status, **_MJ_FAILURES)

    def _space_block(self):
        if self._python_steps_left and not hasattr(self, "_block_limit"):
            # the loop handed back its first step twice in a row: the next ones go to the
            # Python step directly (the same step), for twice as many each time up to
            # _MAX_PYTHON_RUN, rather than the loop's work done twice on each (a replay
            # to a sample, _block_limit, runs the block as the first run did)
            self._python_steps_left -= 1
            return self._generic_step()
        k0 = self._k
        q, v, closed = self.q.copy(), self.v.copy(), self._closed.copy()
        status = self._run_block(None, (q, v, self._model.tables, float(self.theta), closed,
                                         space_solver(self.cone, self._model.several,
                                                      self._model.drilling)),
                                 (self._model.pairs,))
        self.q, self.v, self._closed = q, v, closed
        if status == LCP_HANDBACK:
            if self._k == k0:
                self._python_run = min(2 * self._python_run, _MAX_PYTHON_RUN)
                self._python_steps_left = self._python_run
            else:
                self._python_run = 1
        # a contact problem the loop does not finish (the exact cone's restart, a Lemke
        # failure) is the generic step's, which solves it or raises with its diagnosis
        self._after_block(status)

    def _fast_block(self):
        if self._n_eq:
            return self._joint_block()
        q, v, closed = self.q.copy(), self.v.copy(), self._closed.copy()
        status = self._run_block(mj_loop, (q, v, (float(self.theta), bool(self.projection)),
                                           (closed,)), (self._lcp_ctl,))
        self.q, self.v, self._closed = q, v, closed
        # Lemke failed on this step: the generic step solves it (QP fallback with
        # lcp_method="auto", an LCPError with "lemke"), then the loop resumes.
        # A tangential impact (or a Painlevé case on a singular Delassus matrix): the
        # generic step takes it and records it, or raises with the full diagnosis (the
        # state is the start of that step).
        self._after_block(status, **_MJ_FAILURES)

    def _regimes_before(self):
        # the regimes of the last step taken, generic or compiled (a view, written in place)
        if self._fast:
            return prev_regimes(self._lcp_ctl, self.scene.ncontacts)
        return self._prev_reg

    def _slip_before(self, ia):
        reg = self._regimes_before()[ia]
        return np.where(reg == int(Regime.POSITIVE), 1.0,
                        np.where(reg == int(Regime.NEGATIVE), -1.0, 0.0))

    def _contact_step(self, q, t1, v_free, Winv, active, vN0, pN, pT):
        sc = self.scene
        WN1, wN1, WT1, wT1 = (np.asarray(a, dtype=float) for a in sc.contact_jacobians(q, t1))
        ia = np.flatnonzero(active)
        fa = ia[self._trow[ia] >= 0]            # active frictional contacts
        tr = self._trow[fa]
        H = np.vstack([WN1[ia], WT1[tr]])
        w = np.concatenate([wN1[ia], wT1[tr]])
        Winv_HT = Winv @ H.T
        W = H @ Winv_HT
        U_free = H @ v_free + w
        mu, e = self.mu_c[ia], self.e_c[ia]
        na = len(ia)
        if na == 1 and self.lcp_method == "auto":
            p, pN[ia], pT[ia] = solve_contact_problem(W, U_free, mu, e, vN0[ia],
                                                      counters=self.counters, t=self.t,
                                                      slip_before=self._slip_before(ia),
                                                      painleve=self.painleve)
        else:
            p = self._solve_lcp(W, U_free, mu, e, vN0[ia], ia, pN, pT)
        v1 = v_free + Winv_HT @ p
        U = U_free + W @ p
        slip = np.zeros(sc.ncontacts)
        slip[fa] = U[na:]
        return v1, slip

    def _joint_step(self, q, v, q_th, t_th, t1, v_free, Winv, active, vN0, pN, pT):
        """The step's mixed LCP: the joint rows ``WE v_theta + wE = 0`` with the active contacts.

        Rows ``[E; N; T]`` of :class:`moreau.contact.ContactProblem`: the joint
        rows with ``WE, wE`` at ``(q_th, t_th)`` (the predicted theta-point, see
        the module docstring) and their target on ``v_{k+1}``, the contacts'
        Jacobians at ``q_k`` and rheonomic terms at ``t_{k+1}``, solved by
        :func:`moreau.contact.solve` (``"auto"``: the equality rows eliminated,
        the contacts by closed form or Lemke then QP; a forced ``lcp_method``
        is the inner solver of ``"mlcp"``).
        """
        sc = self.scene
        theta = self.theta
        WE, wE = (np.asarray(a, dtype=float) for a in sc.joint_jacobians(q_th, t_th))
        # theta (WE v_{k+1} + wE) + (1 - theta) (WE v_k + wE) = 0, as a target on v_{k+1}
        target = (None if theta == 1.0 or self.joint_rows == "end"
                  else ((theta - 1.0) / theta) * (WE @ v + wE))
        if self.joint_baumgarte:
            # the rows' velocity less (alpha / h) gE(q_k, t_k), divided by theta on the
            # theta-weighted rows (module docstring, *Baumgarte*)
            t0 = self.t
            corr = (self.joint_baumgarte / (t1 - t0)) * np.asarray(sc.joint_residuals(q, t0),
                                                                   dtype=float)
            if target is None:
                target = -corr
            else:
                target = target - corr / theta
        ia = np.flatnonzero(active)
        rows, rhs = [WE], [wE]
        fa = ia[:0]
        if ia.size:
            WN1, wN1, WT1, wT1 = (np.asarray(a, dtype=float) for a in sc.contact_jacobians(q, t1))
            fa = ia[self._trow[ia] >= 0]
            tr = self._trow[fa]
            rows += [WN1[ia], WT1[tr]]
            rhs += [wN1[ia], wT1[tr]]
        H = np.vstack(rows)
        Winv_HT = Winv @ H.T
        W = H @ Winv_HT
        U_free = H @ v_free + np.concatenate(rhs)
        # (built in the layout from checked data: a state gone non-finite is the step's
        # failure, found after it, not an input error)
        problem = ContactProblem.trusted(W, U_free, self.mu_c[ia], self.e_c[ia], vN0[ia],
                                         n_eq=self._n_eq, eq_target=target)
        if self.lcp_method == "auto":
            sol = solve_problem(problem, "auto", max_iter=self.lemke_max_iter)
            if not sol.success and "closed-form" in sol.path:
                # the one-contact closed form is not exact on a singular reduced Delassus
                # matrix (a contact whose normal and tangential rates the joints tie: a pinned
                # rod's tip on a stop), which the check on the whole problem catches: Lemke,
                # then the QP, as for several contacts
                for inner in ("lemke", "qp"):
                    sol = solve_problem(problem, "mlcp", max_iter=self.lemke_max_iter,
                                        inner=inner)
                    self.counters["fallbacks"] += 1
                    if sol.success:
                        break
        else:
            sol = solve_problem(problem, "mlcp", max_iter=self.lemke_max_iter,
                                inner=self.lcp_method)
        if not sol.success:
            raise LCPError(f"the step's mixed LCP (joints and contacts) at t = {self.t!r} was "
                           f"not solved ({sol.method}): {sol.message}")
        if ia.size:
            self.counters["lcp_solves"] += 1
            self.counters["max_residual"] = max(self.counters["max_residual"], sol.residual)
        if "lemke" in sol.path:
            self.counters["pivots"] += int(sol.iterations)
        pN[ia], pT[ia] = sol.pN, sol.pT
        v1 = v_free + Winv_HT @ sol.p
        slip = np.zeros(sc.ncontacts)
        if fa.size:
            U = U_free + W @ sol.p
            slip[fa] = U[self._n_eq + ia.size:]
        return v1, slip

    def _solve_lcp(self, W, U_free, mu, e, vN_pre, ia, pN, pT):
        # the assembled LCP of several contacts (or of one, with a forced solver)
        if self.lcp_method in ITERATIVE_METHODS:
            return iterative_contact_step(self, W, U_free, mu, e, vN_pre, ia, pN, pT)
        p, pN[ia], pT[ia] = solve_contact_problem(
            W, U_free, mu, e, vN_pre, lcp_method=self.lcp_method, counters=self.counters,
            lemke_max_iter=self.lemke_max_iter, t=self.t, slip_before=self._slip_before(ia),
            painleve=self.painleve,
            warm=self._lcp_warm("impulse") if self._warm_start() else None,
            warm_key=tuple(ia.tolist()))
        return p

    def _project(self, q, t, closed):
        """Mass-weighted projection onto ``g = 0`` (closed contacts) and ``g >= 0`` (the rest)."""
        sc = self.scene
        M = np.asarray(sc.mass(q), dtype=float)
        sel = closed.copy()
        for _ in range(PROJECTION_MAXITER):
            g = np.asarray(sc.gaps(q, t), dtype=float)
            sel |= g < 0.0
            if not sel.any() or np.max(np.abs(g[sel])) <= PROJECTION_TOL:
                break
            WN = np.asarray(sc.contact_jacobians(q, t)[0], dtype=float)[sel]
            MinvWT = np.linalg.solve(M, WN.T)
            d = np.linalg.solve(WN @ MinvWT, -g[sel])
            q = q + MinvWT @ d
            self.counters["projection_iterations"] += 1
        return q

    def _project_joint_velocity(self, q, t, v):
        """``v`` moved to the mass-weighted nearest velocity with ``G(q) v + w(t) = 0``."""
        sc = self.scene
        G, w = (np.asarray(a, dtype=float) for a in sc.joint_jacobians(q, t))
        MinvGT = np.linalg.solve(np.asarray(sc.mass(q), dtype=float), G.T)
        return v - MinvGT @ np.linalg.solve(G @ MinvGT, G @ v + w)

    def _project_joints(self, q, t):
        """Mass-weighted Gauss–Newton projection of ``q`` onto the joints, ``gE(q, t) = 0``."""
        sc = self.scene
        M = np.asarray(sc.mass(q), dtype=float)
        for _ in range(PROJECTION_MAXITER):
            gE = np.asarray(sc.joint_residuals(q, t), dtype=float)
            if np.max(np.abs(gE), initial=0.0) <= PROJECTION_TOL:
                break
            G = np.asarray(sc.joint_jacobians(q, t)[0], dtype=float)
            MinvGT = np.linalg.solve(M, G.T)
            q = q + MinvGT @ np.linalg.solve(G @ MinvGT, -gE)
            self.counters["projection_iterations"] += 1
        return q


def _inverse(W_hat):
    """``W_hat^-1``, or None when ``W_hat`` is singular to working precision.

    The matrices are small (``ndof`` x ``ndof``, the inverse is reused for the
    free velocity and the Delassus matrix); the 1-norm condition number
    decides singularity.
    """
    if not np.all(np.isfinite(W_hat)):
        return None
    try:
        Winv = np.linalg.inv(W_hat)
    except np.linalg.LinAlgError:
        return None
    cond = np.linalg.norm(W_hat, 1) * np.linalg.norm(Winv, 1)
    if not (np.isfinite(cond) and cond < 1e14):
        return None
    return Winv
