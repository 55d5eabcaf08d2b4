r"""Energy audit of one steady period of a rod drive: where the stator's work goes.

The friction drive and the two-rod drive (:mod:`moreau.scenes.friction_drive`,
:mod:`moreau.scenes.bidirectional_drive`) are rods hinged on prescribed
stators and pressed on one rotor. Over a steady period the work the stators
do on the rods is spent against the load, in friction and in impacts; the
stored energy comes back to its value. The audit computes each term on its
own and reports how far they are from closing.

Derivation
----------
Take the full coordinates ``(x1_r, phi_r, x2)`` of the paper's Lagrangian
(rod ``r`` on stator ``r``, the rotor ``x2``), with the stator displacements
``x1_r`` treated as coordinates held on their prescribed motion by the
stator forces ``F_r``. In the scenes' dimensionless units (``tau = w t``,
``u = x / l``, forces over ``m l w^2``, energies over ``m l^2 w^2``) the energy
of the rods, the springs and the rotor (the stator's own mass left out) is::

    E = sum_r [1/2 u1r'^2 + 1/2 u1r' phi_r' cos phi_r + 1/6 phi_r'^2
               + 1/2 P (sin phi0 - sin phi_r)^2 + f_p (sin phi0 - sin phi_r)]
        + 1/2 J u2'^2

(``f_p`` the friction drive's preload, 0 for a scene without one; it
depends on ``phi_r`` only, so the stator forces below keep their form).

``T`` and ``V`` do not depend on time explicitly in these coordinates, so
``dE/dtau`` is the power of the generalised forces that are not in ``V``:
the stator forces ``f_r`` on ``u1r``, the load ``-f_L`` on ``u2`` and the
contact forces ``f_N, f_T`` along the gradients of the gaps ``g_N`` and the
tangential coordinates ``g_T``::

    dE/dtau = sum_r f_r u1r' - f_L u2' + sum_i (f_Ni g_Ni' + f_Ti g_Ti').

The ``u1r`` equation of Lagrange (``dg_Nr/du1r = -1``, ``dg_Tr/du1r = 0``)
gives the stator force: with the momentum ``pi_r = u1r' + 1/2 phi_r' cos
phi_r`` conjugate to ``u1r``, ``pi_r' = f_r - f_Nr``, so

    f_r = u1r'' + 1/2 (phi_r'' cos phi_r - phi_r'^2 sin phi_r) + f_Nr.

On a smooth piece of motion complementarity makes ``f_N g_N' = 0`` (in
contact ``g_N' = 0``, in flight ``f_N = 0``), stick makes ``f_T g_T' = 0``
and slip makes ``f_T g_T' = -mu f_N |g_T'| <= 0``. At an impact the
velocities jump with impulses ``p_N, p_T`` (and the stator's ``p_r``) while
the positions and the prescribed ``u1r'`` do not; ``T`` is quadratic with a
mass matrix fixed during the impact, so its jump is exactly the impulses
times the mean of the pre- and post-impact velocities::

    dE = sum_r p_r u1r' + sum_i (p_Ni <g_Ni'> + p_Ti <g_Ti'>),
    p_r = d(pi_r) + p_Nr,   <.> = (pre + post) / 2.

Integrating over one period from the Poincaré section gives the balance

    W_stator = W_load + D_positive + D_negative + D_impact + dE

with

* ``W_stator = sum_r [int f_r u1r' dtau + sum_impacts p_r u1r']``, the work
  the stators do on the rods;
* ``W_load = int f_L u2' dtau``, the work done against the load (``f_L``
  times the displacement per period: the scenes' load pushes towards
  ``-x``);
* ``D_positive``, ``D_negative = -int f_T g_T' dtau`` over the positive and
  negative slip of every contact (>= 0);
* ``D_impact = -sum_impacts (p_N <g_N'> + p_T <g_T'>)`` (>= 0 for a
  dissipative impact law);
* ``dE = E(end) - E(start)``, zero on a periodic orbit up to the shooting's
  residual.

Each term is computed by itself, so ``closing_error = (W_stator - W_load -
D_positive - D_negative - D_impact - dE) / max |term|`` measures how well the
computed motion satisfies its own equations. Where every term is below the
rounding bound (:data:`ROUNDING_RTOL` of the stored energy: no work is
exchanged, e.g. without friction) the closing error is None and a note says so.

Event-driven reference (the friction drive's walker)
  The period is re-walked from the steady state's section. On a contact
  piece the rod lies on the contact manifold, so ``phi, phi', phi''``,
  ``f_N, f_T`` and the rotor velocity (the walker's exact Fourier series of
  the slip regimes, or the tip velocity in stick) are closed-form functions
  of ``tau``; the power terms are integrated by composite Gauss–Legendre
  quadrature, the panels halved until two rules agree to 1e-13. A flight
  piece is integrated the same way on the DOP853 dense output, panel by
  solver step. Every jump of the state between two pieces (an impact, a
  touchdown put on the manifold, a slip ending at exactly the tip velocity)
  enters through its impulses, recovered from the velocity jump
  (``p_T = J d u2'``, ``p_N = (sin phi p_T - d phi' / 3) / cos phi``).
  Closes to about 1e-12 of the input work.

Event-driven reference (the generic scheme: the two-rod drive)
  :class:`~moreau.integrators.event_driven_generic.GenericEventDriven`
  redoes the period with its pieces kept: each smooth phase (one contact
  mode) is integrated by one 16-point Gauss–Legendre rule per solver step
  on its dense output, the forces of the mode solved at every node; each
  velocity jump (an impact, or the projection that removes a phase's drift
  from the closed contacts) enters through the impulses the scheme applied.
  Two-rod drive at 185 Hz (``x10_b = 1e-6`` m, mode ``NSP|NP``): 1.0e-12;
  on the friction drive it reproduces the walker's terms to 1e-12.

Moreau–Jean (the discrete scheme's own audit)
  One period of steps from the discrete steady state. Step ``k`` carries
  the impulses ``p_N, p_T`` of its contact problem, whose local velocities
  use the Jacobians at ``q_k`` and ``u1'(tau_{k+1})``. Its terms are the
  impulses times the mean of the step's pre- and post-step local velocities
  (the discrete counterpart of the impact formula above, so a step with a
  normal impulse is an impact of the scheme): ``D_impact`` from ``p_N``,
  friction from ``p_T``, put to the slip direction of the step's regime (a
  stick step to the direction of the slip it stops, the sign of its
  pre-step slip velocity); the stator impulse ``p_r = d(pi_r) + p_Nr`` works
  on the mean stator velocity of the step; the load works on the step's
  displacement. The smooth forces (spring, the rod's inertia on the moving
  hinge) are not in any term, so what the theta-scheme and the projection
  do to the energy shows as the closing error: first order in the step.
  Measured on the paper's drive (185 Hz and 2000 Hz): about 27/N with
  ``theta = 1`` (2.7e-2 and 2.8e-2 at N = 1000 steps a period, the
  scheme's numerical dissipation) and 0.16/N with ``theta = 1/2`` (1.6e-4
  and 1.4e-4); the terms converge to the reference's at first order too
  (2.9e-2 of the stator work at N = 1000, theta = 1). On the two-rod drive
  (``x10_b = 1e-6`` m, against the generic event-driven reference): 185 Hz,
  2.47e-2 and 1.25e-2 at N = 1000 and 2000 with ``theta = 1``, 1.27e-4 and
  6.3e-5 with ``theta = 1/2``; 2000 Hz, 2.79e-2 and 1.41e-2, 1.24e-4 and
  6.2e-5; the terms within 2.6e-2 (185 Hz, N = 1000, theta = 1) of the
  reference's.

Examples
--------
>>> from moreau.scenes.friction_drive import FrictionDrive
>>> from moreau.analysis.steady_state import find_steady_state
>>> sc = FrictionDrive(frequency=185.0)
>>> audit = energy_audit(sc, find_steady_state(sc), "event-driven")
>>> abs(audit["closing_error"]) < 1e-9
True
"""

import math

import numpy as np

from ..errors import ConvergenceError, InputError, MoreauError
from ..regimes import Regime
from ..model import registry
from .mj_steady_state import PeriodMap
from .period_k import full_state_of
from ..integrators.event_driven_generic import GenericEventDriven
from ..integrators.moreau_jean import MoreauJean

__all__ = ["ENERGY_TERMS", "ENERGY_COLUMNS", "ROUNDING_RTOL", "RodEnergy", "energy_audit",
           "energy_to_si", "register_energy_audit", "has_energy_audit", "gauss_legendre",
           "moreau_jean_energy_audit", "generic_event_driven_energy_audit", "balance"]

TWO_PI = 2.0 * math.pi

#: the audit's terms (dimensionless keys) and their SI names in JSON and CSV (J per period)
ENERGY_TERMS = (("stator_work", "stator_work_J"), ("load_work", "load_work_J"),
                ("friction_positive_slip", "friction_loss_positive_slip_J"),
                ("friction_negative_slip", "friction_loss_negative_slip_J"),
                ("impact_loss", "impact_loss_J"),
                ("stored_energy_change", "stored_energy_change_J"))

#: the sweep columns of the audit: joules per period, the relative closing error, and
#: ``energy_status`` ("ok", or why a point has no audit)
ENERGY_COLUMNS = tuple(si for _, si in ENERGY_TERMS) + ("energy_closing_error", "energy_status")

_AUDITS = {}


def register_energy_audit(scheme):
    """Decorator registering the energy audit of the steady states of scheme ``scheme``.

    An audit is called as ``audit(scene, steady_state, options)`` and returns
    the dimensionless terms (:data:`ENERGY_TERMS` keys) with ``closing_error``.
    """
    def deco(fn):
        _AUDITS[scheme] = fn
        return fn
    return deco


def _audit_name(scene, scheme):
    own = getattr(scene, "reference_integrator", None)
    if scheme == "event-driven" and own is not None and own in _AUDITS:
        return own
    return scheme


def has_energy_audit(scene, scheme):
    """Whether steady states of ``scene`` under ``scheme`` have an energy audit."""
    registry.discover()
    return hasattr(scene, "rod_layout") and _audit_name(scene, scheme) in _AUDITS


def energy_audit(scene, steady, scheme, options=None):
    """The energy audit of one steady period (dimensionless, see the module docstring).

    Parameters
    ----------
    scene : Scene
        A rod drive (it has ``rod_layout()``).
    steady : SteadyState
        Its steady state under ``scheme``.
    scheme : str
        The scheme that found it (``"event-driven"`` or ``"moreau-jean"``).
    options : dict, optional
        The scheme's settings (Moreau–Jean's ``steps_per_period``, ``theta``,
        ``lcp_method``), as the steady state was found with them.

    Returns
    -------
    dict
        ``stator_work``, ``load_work``, ``friction_positive_slip``,
        ``friction_negative_slip``, ``impact_loss``, ``stored_energy_change``
        (in units of ``m l^2 w^2`` per period), ``closing_error`` (relative
        to the largest term; None where no work is exchanged),
        ``rounding_bound`` and ``work_exchanged`` (:func:`balance`).
    """
    if not has_energy_audit(scene, scheme):
        raise InputError(f"`scheme` {scheme!r} has no energy audit for scene "
                         f"{getattr(scene, 'name', type(scene).__name__)!r}; audits exist for "
                         f"the rod drives under {sorted(_AUDITS)}")
    return _AUDITS[_audit_name(scene, scheme)](scene, steady, dict(options or {}))


def energy_to_si(scene, audit):
    """The audit in joules per period, keyed by the SI names of :data:`ENERGY_TERMS`.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=185.0)
    >>> a = dict.fromkeys([k for k, _ in ENERGY_TERMS], 1.0)
    >>> a["closing_error"] = 0.0
    >>> energy_to_si(sc, a)["stator_work_J"] == sc.force_scale * sc.params.length
    True
    """
    scale = float(scene.force_scale) * float(scene.params.length)
    out = {si: float(audit[k]) * scale for k, si in ENERGY_TERMS}
    err = audit["closing_error"]
    out["closing_error"] = None if err is None else float(err)
    if "rounding_bound" in audit:
        out["rounding_bound_J"] = float(audit["rounding_bound"]) * scale
    if err is None:
        out["note"] = (f"no work exchanged: every term is below the rounding bound "
                       f"{out['rounding_bound_J']:.1e} J ({ROUNDING_RTOL:g} of the stored "
                       "energy)")
    return out


#: the terms' rounding bound relative to the stored energy: the audits' accuracy (the
#: walker's tolerance 1e-12, the quadrature's 1e-13; measured closing errors 1e-15 .. 1e-12)
ROUNDING_RTOL = 1e-12


def balance(terms, energy_levels=()):
    """``terms`` with ``closing_error`` and ``rounding_bound`` added.

    ``closing_error = (W_stator - W_load - D - dE) / max |term|``: the
    unexplained share of the largest term (the stator's work, where the
    stators drive the motion). ``rounding_bound`` is :data:`ROUNDING_RTOL`
    times the largest of the terms and of the stored energies
    ``energy_levels`` (sampled over the period): where every term
    is below it, no work is exchanged over the period (a frictionless
    contact, a massless rotor) and the terms are rounding, so the closing
    error is None and ``work_exchanged`` False.

    Examples
    --------
    >>> t = dict(stator_work=1.0, load_work=0.25, friction_positive_slip=0.5,
    ...          friction_negative_slip=0.25, impact_loss=0.0, stored_energy_change=0.0)
    >>> balance(t, (3.0,))["closing_error"]
    0.0
    >>> b = balance(dict(t, stator_work=2.6e-18, load_work=0.0, friction_positive_slip=0.0,
    ...                  friction_negative_slip=0.0), (3e-3,))
    >>> b["closing_error"], b["work_exchanged"], b["rounding_bound"]
    (None, False, 3e-15)
    """
    w = terms["stator_work"]
    rest = (terms["load_work"] + terms["friction_positive_slip"] + terms["friction_negative_slip"]
            + terms["impact_loss"] + terms["stored_energy_change"])
    out = {k: float(v) for k, v in terms.items()}
    largest = max(abs(float(v)) for v in terms.values())
    bound = ROUNDING_RTOL * max(largest, float(np.max(np.abs(energy_levels), initial=0.0)))
    out["rounding_bound"] = bound
    out["work_exchanged"] = bool(largest > bound)
    out["closing_error"] = float((w - rest) / largest) if largest > bound else None
    return out


class RodEnergy:
    """Energy, stator momenta and contact velocities of a rod drive (module docstring).

    Parameters
    ----------
    scene : FrictionDrive or BidirectionalDrive
        Any scene with ``rod_layout()``: rods ``q[:n]``, the rotor ``q[n]``.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> re = RodEnergy(FrictionDrive(frequency=185.0))
    >>> float(re.energy(np.array([np.pi / 4, 0.0]), np.zeros(2), 0.0))
    0.0
    """

    def __init__(self, scene):
        if not hasattr(scene, "rod_layout"):
            raise InputError(f"`scene` ({type(scene).__name__}) is not a rod drive: it has no "
                             "`rod_layout()`")
        self.scene = scene
        self.u10, self.delta, self.side = (np.asarray(a, float) for a in scene.rod_layout())
        self.nr = self.u10.size
        self.J, self.P, self.s0, self.fL = scene.J, scene.P, scene.sin_phi0, scene.fL
        # the preload's potential f_p (sin phi0 - sin phi) (friction_drive, "Preload"); a
        # rod drive without a preload parameter has none
        self.fp = float(getattr(scene, "fp", 0.0))

    def stator(self, tau):
        """``(u1', u1'')`` of every rod, shape ``(..., n)``."""
        t = np.asarray(tau, float)[..., None] - self.delta
        return self.u10 * np.sin(t), self.u10 * np.cos(t)

    def energy(self, q, v, tau):
        """``E`` of states ``q, v`` (shape ``(ndof,)`` or ``(k, ndof)``) at ``tau``."""
        q, v = np.asarray(q, float), np.asarray(v, float)
        n = self.nr
        phi, dphi, du2 = q[..., :n], v[..., :n], v[..., n]
        d1, _ = self.stator(tau)
        rods = (0.5 * d1 * d1 + 0.5 * d1 * dphi * np.cos(phi) + dphi * dphi / 6.0
                + 0.5 * self.P * (self.s0 - np.sin(phi)) ** 2 + self.fp * (self.s0 - np.sin(phi)))
        return rods.sum(axis=-1) + 0.5 * self.J * du2 * du2

    def momenta(self, q, v, tau):
        """Stator momenta ``pi_r = u1r' + 1/2 phi_r' cos phi_r``, shape ``(..., n)``."""
        n = self.nr
        d1, _ = self.stator(tau)
        return d1 + 0.5 * np.asarray(v, float)[..., :n] * np.cos(np.asarray(q, float)[..., :n])

    def normal_velocity(self, q, v, tau):
        """``g_N' = -cos phi_r phi_r' - u1r'(tau)``, shape ``(..., n)``."""
        n = self.nr
        d1, _ = self.stator(tau)
        return -np.cos(np.asarray(q, float)[..., :n]) * np.asarray(v, float)[..., :n] - d1

    def slip_velocity(self, q, v):
        """``g_T' = u2' + side_r sin phi_r phi_r'``, shape ``(..., n)``."""
        n = self.nr
        q, v = np.asarray(q, float), np.asarray(v, float)
        return v[..., n, None] + self.side * np.sin(q[..., :n]) * v[..., :n]

    def jump(self, q, v_pre, v_post, tau):
        """Stator work and impact loss of a velocity jump at fixed ``q`` (one rod drive state).

        The impulses follow from ``M dv = WN^T p_N + WT^T p_T``; returns
        ``(stator_work, impact_loss)``, whose difference is the jump of ``E``.
        """
        n = self.nr
        dv = np.asarray(v_post, float) - np.asarray(v_pre, float)
        phi = np.asarray(q, float)[:n]
        s, c = np.sin(phi), np.cos(phi)
        # one rod carries the rotor's whole impulse; with two rods in contact at one instant
        # the split is not determined by the jump, but their sum is (the impact loss below
        # needs both): the reference that uses this is the single rod's
        if n != 1:
            raise InputError("`jump` recovers the impulses of a single rod drive only")
        pT = self.J * dv[n]
        pN = (self.side[0] * s[0] * pT - dv[0] / 3.0) / c[0]
        d1, _ = self.stator(tau)
        mean_vN = 0.5 * (self.normal_velocity(q, v_pre, tau) + self.normal_velocity(q, v_post, tau))
        mean_vT = 0.5 * (self.slip_velocity(q, v_pre) + self.slip_velocity(q, v_post))
        stator = float(d1[0] * (pN + 0.5 * c[0] * dv[0]))
        loss = -float(pN * mean_vN[0] + pT * mean_vT[0])
        return stator, loss


_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(16)


def _gl_panels(f, edges):
    mid = 0.5 * (edges[:-1] + edges[1:])
    half = 0.5 * np.diff(edges)
    tau = (mid[:, None] + half[:, None] * _GL_NODES).ravel()
    w = (half[:, None] * _GL_WEIGHTS).ravel()
    vals = np.atleast_2d(f(tau))
    return vals @ w, np.abs(vals) @ w


def gauss_legendre(f, a, b, rtol=1e-13, panel=TWO_PI / 16, max_halvings=14):
    """Integrals over ``[a, b]`` of the rows of ``f(tau)`` by composite 16-point Gauss–Legendre.

    The panels are halved until two successive rules agree to ``rtol`` of
    each row's absolute integral (and to 1e-15 of the largest). ``f`` takes
    an array of ``tau`` and returns an array of shape ``(k, len(tau))``.

    Examples
    --------
    >>> round(float(gauss_legendre(lambda t: np.cos(t)[None], 0.0, np.pi / 2)[0]), 13)
    1.0
    """
    if not b > a:
        return np.zeros(np.atleast_2d(f(np.array([a]))).shape[0])
    m = max(1, int(math.ceil((b - a) / panel)))
    I, _ = _gl_panels(f, np.linspace(a, b, m + 1))
    for _ in range(max_halvings):
        m *= 2
        I2, A2 = _gl_panels(f, np.linspace(a, b, m + 1))
        if np.all(np.abs(I2 - I) <= rtol * A2 + 1e-15 * np.max(A2) + 1e-300):
            return I2
        I = I2
    raise ConvergenceError(f"the energy quadrature over [{a:.6g}, {b:.6g}] did not converge "
                           f"in {max_halvings} halvings (difference {np.max(np.abs(I2 - I)):.3g})")


@register_energy_audit("moreau-jean")
def moreau_jean_energy_audit(scene, steady, options):
    """The Moreau–Jean scheme's own audit of its steady period (module docstring)."""
    stats = steady.stats or {}
    if not stats.get("periodic", True):
        raise MoreauError("the Moreau–Jean map has no period-1 orbit here: no steady period "
                          "to audit")
    closed = stats.get("closed_at_section")
    if closed is None:
        raise InputError("`steady` must come from moreau_jean_steady_state (its stats carry "
                         "the contact flags at the section)")
    n = int(options.get("steps_per_period", stats.get("steps_per_period")))
    theta = float(options.get("theta", stats.get("theta", 1.0)))
    pm = PeriodMap(scene, n, theta, bool(stats.get("projection", True)),
                   options.get("fast", "auto"), options.get("lcp_method", "auto"))
    q0, v0 = pm.full_state(np.asarray(steady.state0, float))
    integ = MoreauJean(scene, 0.0, q0, v0, pm.period, h=pm.h, theta=pm.theta,
                       projection=pm.projection, fast=pm.fast, lcp_method=pm.lcp_method,
                       closed0=np.asarray(closed, dtype=bool), save_every=1)
    while integ.status == "running":
        integ.step()
    if integ.status != "finished":
        raise MoreauError(f"the audited Moreau–Jean period failed: {integ.message}")
    res = integ.result()
    return _discrete_audit(RodEnergy(scene), res, pm.h)


def _discrete_audit(re, res, h):
    n = re.nr
    t, q, v = res.t, res.q, res.v
    if len(t) < 2:
        raise MoreauError("the audited period has no steps")
    # sample k >= 1 holds step k's state after the step and its impulses / step length
    dt = np.diff(t)
    pN = res.force_N[1:, :n] * dt[:, None]
    pT = res.force_T[1:, :n] * dt[:, None]
    q0, v0, v1 = q[:-1], v[:-1], v[1:]
    t1 = t[1:]
    # relative velocities before and after the step, each at its own time (Jacobians at
    # q_k, as the contact problem has them): the mean of the pre- and post-step values
    vN = 0.5 * (re.normal_velocity(q0, v0, t[:-1]) + re.normal_velocity(q0, v1, t1))
    vT0 = re.slip_velocity(q0, v0)
    vT = 0.5 * (vT0 + re.slip_velocity(q0, v1))
    fric = -pT * vT
    reg = res.regime[1:, :n]
    pos = (reg == int(Regime.POSITIVE)) | ((reg == int(Regime.STICK)) & (vT0 > 0.0))
    neg = (reg == int(Regime.NEGATIVE)) | ((reg == int(Regime.STICK)) & (vT0 < 0.0))
    d1a, _ = re.stator(t[:-1])
    d1b, _ = re.stator(t1)
    p_stator = re.momenta(q[1:], v1, t1) - re.momenta(q0, v0, t[:-1]) + pN
    terms = {
        "stator_work": float(np.sum(p_stator * 0.5 * (d1a + d1b))),
        "load_work": float(re.fL * (q[-1, n] - q[0, n])) + 0.0,   # no -0.0 without a load
        "friction_positive_slip": float(np.sum(fric[pos])),
        "friction_negative_slip": float(np.sum(fric[neg])),
        "impact_loss": float(-np.sum(pN * vN)),
        "stored_energy_change": float(re.energy(q[-1], v[-1], t[-1]) - re.energy(q[0], v[0], t[0])),
    }
    return balance(terms, re.energy(q, v, t))


#: the generic event-driven scheme's settings its audit passes on when it redoes the period
_GENERIC_OPTIONS = ("rtol", "atol", "ode_method", "max_step", "gap_tol", "vel_tol", "zeno_rtol",
                    "max_impacts", "lcp_method")


@register_energy_audit("event-driven-generic")
@register_energy_audit("event-driven")
def generic_event_driven_energy_audit(scene, steady, options):
    """The audit of a steady period of the generic event-driven scheme (any rod drive).

    The event-driven reference of a rod drive without a scheme of its own
    (the two-rod drive) is
    :class:`~moreau.integrators.event_driven_generic.GenericEventDriven`.
    The period is run again from the steady state's section with the run's
    pieces kept (``record_pieces``): on each smooth phase, whose contact mode
    is fixed, the power terms are integrated by a 16-point Gauss–Legendre
    rule per solver step on the dense output (one polynomial there), with
    the accelerations and contact forces of the phase's mode at each node;
    each velocity jump at an event enters through the impulses the scheme
    applied, an impact's into ``impact_loss`` and the stator's work, a
    projection's (the removal of a phase's drift from the closed contacts,
    about the integration tolerance) likewise. What the position projections
    and the integration error leave is the closing error.
    """
    q0, v0 = full_state_of(scene, steady.state0)
    tau_s = float(getattr(steady, "section_tau", 0.0) or 0.0)
    opts = {k: options[k] for k in _GENERIC_OPTIONS if k in options}
    integ = GenericEventDriven(scene, tau_s, q0, v0, tau_s + TWO_PI, record_pieces=True, **opts)
    while integ.status == "running":
        integ.step()
    if integ.status != "finished":
        raise MoreauError(f"the audited event-driven period failed: {integ.message}")
    re = RodEnergy(scene)
    terms = dict.fromkeys(("stator_work", "load_work", "friction_positive_slip",
                           "friction_negative_slip", "impact_loss"), 0.0)
    for t0, t1, sol, mode in integ.phases:
        I = _phase_integral(re, integ.ms, sol, t0, t1, mode)
        for k, x in zip(("stator_work", "load_work", "friction_positive_slip",
                         "friction_negative_slip"), I):
            terms[k] += float(x)
    for t, q, v_pre, v_post, pN, pT, _ in integ.jumps:
        w, loss = _jump_terms(re, t, q, v_pre, v_post, pN, pT)
        terms["stator_work"] += w
        terms["impact_loss"] += loss
    e0, e1 = re.energy(q0, v0, tau_s), re.energy(integ.q, integ.v, integ.t)
    terms["stored_energy_change"] = float(e1 - e0)
    # the energy's size over the period scales the rounding bound: 9 samples a phase (the
    # two-rod drive without friction is at rest at the phase ends, 6e-3 between)
    n = integ.ms.ndof
    levels = [e0, e1] + [re.energy(sol(t)[:n], sol(t)[n:], t) for t0, t1, sol, _ in
                         integ.phases for t in np.linspace(t0, t1, 9)]
    return balance(terms, levels)


def _jump_terms(re, t, q, v_pre, v_post, pN, pT):
    """``(stator_work, impact_loss)`` of a velocity jump with known contact impulses."""
    n = re.nr
    d1, _ = re.stator(t)
    p_stator = re.momenta(q, v_post, t) - re.momenta(q, v_pre, t) + pN[:n]
    mean_vN = 0.5 * (re.normal_velocity(q, v_pre, t) + re.normal_velocity(q, v_post, t))
    mean_vT = 0.5 * (re.slip_velocity(q, v_pre) + re.slip_velocity(q, v_post))
    return float(p_stator @ d1), -float(pN[:n] @ mean_vN + pT[:n] @ mean_vT)


def _phase_power(re, ms, sol, mode, tau):
    """Stator, load, positive- and negative-slip friction power at the nodes ``tau``."""
    n = re.nr
    out = np.zeros((4, tau.size))
    pos, neg = mode[:n] == int(Regime.POSITIVE), mode[:n] == int(Regime.NEGATIVE)
    for k, t in enumerate(tau):
        y = sol(t)
        q, v = y[:ms.ndof], y[ms.ndof:]
        a, lamN, lamT = ms.solve(t, q, v, mode)[:3]
        phi, dphi = q[:n], v[:n]
        d1, dd1 = re.stator(t)
        f_stator = dd1 + 0.5 * (a[:n] * np.cos(phi) - dphi * dphi * np.sin(phi)) + lamN[:n]
        fric = -lamT[:n] * re.slip_velocity(q, v)
        out[:, k] = (f_stator @ d1, re.fL * v[n], fric[pos].sum(), fric[neg].sum())
    return out


def _phase_integral(re, ms, sol, t0, t1, mode):
    if not t1 > t0:
        return np.zeros(4)
    ts = np.asarray(getattr(sol, "ts", [t0, t1]), float)
    edges = np.unique(np.concatenate([[t0, t1], ts[(ts > t0) & (ts < t1)]]))
    mid, half = 0.5 * (edges[:-1] + edges[1:]), 0.5 * np.diff(edges)
    tau = (mid[:, None] + half[:, None] * _GL_NODES).ravel()
    return _phase_power(re, ms, sol, mode, tau) @ (half[:, None] * _GL_WEIGHTS).ravel()
