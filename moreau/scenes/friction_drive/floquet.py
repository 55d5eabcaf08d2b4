r"""Floquet multipliers of the friction drive's event-driven steady state, by saltation matrices.

The walker's period map starts at a Poincaré section where the rod touches
the rotor, so the rod is on the contact manifold ``sin phi = sin phi0 -
u1(tau)`` there and the only free direction of the state is the rotor
velocity ``u2'``: the map is scalar and has one multiplier. Its derivative
is the product, over the pieces of the steady period, of

* the variational flow of each smooth piece: ``1`` on a slip piece (the
  rotor acceleration of a slip regime depends on ``tau`` only), ``0`` on a
  stick piece (the rotor moves with the tip whatever it started with), and
  on a flight the 2×2 variational equations of the rod's swing
  (``phi'' = 3 (P cos phi (sin phi0 - sin phi) - u1''/2 cos phi)``) with
  ``u2'`` carried unchanged;
* the saltation matrix of every event: with the event surface ``h(x, tau) =
  0``, the reset ``x+ = g(x-, tau)`` and the vector fields ``f-`` before and
  ``f+`` after,

  .. math::

     S = D_x g - (D_x g\, f^- + \partial_\tau g - f^+)\,
         \frac{\nabla h}{\nabla h \cdot f^- + \partial_\tau h}.

  The state is ``u2'`` on a contact piece and ``(phi, phi', u2')`` in
  flight, so ``S`` is rectangular where the two meet. A slip ending
  (``h`` the slip velocity) gives ``S = (a^+ - v_tip') / (a^- - v_tip')``
  between slips, ``0`` into stick; a lift-off and the end of a stick happen
  at times fixed by the drive alone (``f_N`` and the stick margins depend on
  ``tau`` only), so ``S = D_x g``; a re-contact (``h`` the gap) goes through
  the impact law, whose derivative is taken by a complex step through
  :func:`~moreau.scenes.friction_drive.walker.impact_impulses`.

:func:`walker_period_map_slope` gives the same derivative by central
differences of the walker's period map, the check of the saltation product.

Examples
--------
>>> from moreau.scenes.friction_drive import FrictionDrive
>>> from moreau.analysis.steady_state import find_steady_state
>>> sc = FrictionDrive(frequency=185.0)
>>> ss = find_steady_state(sc)
>>> m = walker_monodromy(sc, ss)
>>> m.shape, bool(abs(m[0, 0] - walker_period_map_slope(sc, ss)) < 1e-6)
((1, 1), True)
"""

import cmath
import math

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import ConvergenceError, InputError, MoreauError
from ...regimes import Regime
from .walker import ContactState, FrictionDriveWalker, impact_impulses

__all__ = ["walker_monodromy", "walker_period_map_slope", "GrazingEvent"]

TWO_PI = 2.0 * math.pi
_F, _S = Regime.FLIGHT, Regime.STICK

#: a re-contact (or slip ending) whose event-surface speed is below this share of the
#: velocity scale is grazing: the period map has no derivative there
GRAZING = 1e-7


class GrazingEvent(ConvergenceError):
    """An event is (nearly) tangent to its surface: the saltation matrix does not exist."""


def _section_start(walker, steady):
    tau_s = float(getattr(steady, "section_tau", 0.0) or 0.0)
    phi, dphi, du2 = (float(x) for x in steady.state0)
    return walker.classify(ContactState(tau_s, Regime.FLIGHT, phi, dphi, 0.0, du2))


class _Fields:
    """Vector fields, resets and event surfaces of the walker's pieces."""

    def __init__(self, walker):
        self.w = walker
        self.sc = walker.scene

    def _angle(self, tau):
        return tuple(float(np.ravel(x)[0]) for x in self.sc.contact_angle(np.array([tau])))

    def vtip_rate(self, tau):
        phi, dphi, ddphi = self._angle(tau)
        return -(math.cos(phi) * dphi * dphi + math.sin(phi) * ddphi)

    def rotor_acceleration(self, tau, regime):
        if regime == _S:
            return self.vtip_rate(tau)
        fT = float(np.asarray(self.sc.contact_forces(np.array([tau]), regime)[1]).ravel()[0])
        return (fT - self.sc.fL) / self.sc.J

    def flight(self, st):
        sc = self.sc
        c = math.cos(st.phi)
        ddphi = 3.0 * (sc.P * c * (sc.sin_phi0 - math.sin(st.phi)) - 0.5 * sc.ddu1(st.tau) * c
                       + sc.fp * c)
        return np.array([st.dphi, float(ddphi), -sc.fL / sc.J])

    def field(self, st):
        if st.regime == _F:
            return self.flight(st)
        return np.array([self.rotor_acceleration(st.tau, st.regime)])

    def enter(self, post, tau):
        """``(D_x g, d g/d tau)`` of the reset that puts a contact state (``u2'``) into ``post``."""
        if post.regime == _S:
            return np.zeros((1, 1)), np.array([self.vtip_rate(tau)])
        if post.regime == _F:
            phi, dphi, ddphi = self._angle(tau)
            return np.array([[0.0], [0.0], [1.0]]), np.array([dphi, ddphi, 0.0])
        return np.ones((1, 1)), np.zeros(1)

    def impact(self, pre, post, impact):
        """``(D_x g, d g/d tau)`` of a re-contact from flight state ``pre`` into ``post``.

        Complex-step derivatives of the impact law (exact to round-off); a
        touchdown without impact leaves ``u2'`` unchanged.
        """
        sc, w = self.sc, self.w

        def g(phi, dphi, du2, tau):
            if impact:
                pN, pT = impact_impulses(sc, w.mu, w.e, tau, phi, dphi, du2, cmath.sin, cmath.cos)
            else:
                pN = pT = 0.0
            if post.regime == _F:
                s, c = cmath.sin(phi), cmath.cos(phi)
                return np.array([phi, dphi + 3.0 * (-c * pN + s * pT), du2 + pT / sc.J])
            if post.regime == _S:
                return np.array([complex(w.vtip(tau.real), 0.0)])  # replaced below
            return np.array([du2 + pT / sc.J])

        if post.regime == _S:
            return np.zeros((1, 3)), np.array([self.vtip_rate(pre.tau)])
        x = [complex(pre.phi), complex(pre.dphi), complex(pre.du2), complex(pre.tau)]
        hstep = 1e-30
        cols = []
        for k in range(4):
            xk = list(x)
            xk[k] += 1j * hstep
            cols.append(np.imag(g(*xk)) / hstep)
        D = np.column_stack(cols)
        return D[:, :3], D[:, 3]


def _saltation(Dg, g_tau, f_pre, f_post, grad_h, h_tau, scale):
    """The saltation matrix (module docstring); ``grad_h`` None for an event fixed in time."""
    if grad_h is None:
        return Dg
    rate = float(grad_h @ f_pre + h_tau)
    if not abs(rate) > GRAZING * scale:
        raise GrazingEvent(f"an event crosses its surface at speed {rate:.3g} (grazing): the "
                           "period map has no derivative there")
    return Dg - np.outer(Dg @ f_pre + g_tau - f_post, grad_h) / rate


def _flight_flow(walker, a, b):
    """Variational flow ``d(phi, phi', u2')(b) / d(phi, phi', u2')(a)`` of a flight piece."""
    sc = walker.scene

    def rhs(t, y):
        phi, dphi = y[0], y[1]
        s, c = math.sin(phi), math.cos(phi)
        dd1 = float(sc.ddu1(t))
        # the preload's torque f_p cos(phi) last (friction_drive's "Preload")
        ddphi = 3.0 * (sc.P * c * (sc.sin_phi0 - s) - 0.5 * dd1 * c + sc.fp * c)
        k = 3.0 * (-sc.P * s * (sc.sin_phi0 - s) - sc.P * c * c + 0.5 * dd1 * s - sc.fp * s)
        # the 2x2 variation [[p11, p12], [p21, p22]] of (phi, phi')
        return [dphi, ddphi, y[4], y[5], k * y[2], k * y[3]]

    if not b.tau > a.tau:
        return np.eye(3)
    scale = max(sc.u10, 1e-12)
    sol = solve_ivp(rhs, (a.tau, b.tau), [a.phi, a.dphi, 1.0, 0.0, 0.0, 1.0], method="DOP853",
                    rtol=walker.rtol, atol=1e-3 * walker.rtol * scale)
    if sol.status < 0:
        raise MoreauError(f"the flight's variational equations failed: {sol.message}")
    y = sol.y[:, -1]
    out = np.eye(3)
    out[:2, :2] = [[y[2], y[3]], [y[4], y[5]]]
    return out


def walker_monodromy(scene, steady, rtol=1e-12, walker=None, walk=None):
    """Monodromy matrix of the walker's steady period, from saltation matrices.

    Parameters
    ----------
    scene : FrictionDrive
    steady : SteadyState
        The walker's steady state (:func:`walker_steady_state`).
    rtol : float
        Tolerance of the flights and their variational equations.
    walker : FrictionDriveWalker, optional
        A walker of ``scene`` at ``rtol`` to walk the period with (its
        tables are reused: building them costs as much as the walk).
    walk : (list, list), optional
        The steady period already walked from its section state by
        ``walker``: its pieces ``(start, end)`` (copies) and its events. Not
        walked again then.

    Returns
    -------
    ndarray
        ``(1, 1)`` for a section in contact (the free direction ``u2'``);
        ``(3, 3)`` in ``(phi, phi', u2')`` for one in flight.

    Raises
    ------
    GrazingEvent
        An event of the period is tangent to its surface.
    """
    walker = _walker_of(scene, rtol, walker)
    fields = _Fields(walker)
    vs = walker.vscale
    st0 = _section_start(walker, steady)
    if walk is not None:
        pieces, events = walk
    else:
        pieces, events = [], []
        # the walker changes a finished piece's end state in place (impact, manifold): copy
        walker.advance(st0, st0.tau + TWO_PI, on_event=events.append,
                       on_segment=lambda a, b, sol: pieces.append((a.copy(), b.copy())))
    M = np.eye(3 if st0.regime == _F else 1)
    ev = iter(events)
    pending = next(ev, None)
    for i, (a, b) in enumerate(pieces):
        if a.regime == _F:
            M = _flight_flow(walker, a, b) @ M
        elif a.regime == _S:
            M = np.zeros_like(M)
        if i + 1 == len(pieces):
            break
        post = pieces[i + 1][0]
        if pending is None or pending.t != b.tau:
            # a contact piece split without an event (the walker's search window)
            continue
        kind, pending = pending.kind, next(ev, None)
        if a.regime == _F:
            c = math.cos(b.phi)
            Dg, g_tau = fields.impact(b, post, kind == "impact")
            grad_h = np.array([-c, 0.0, 0.0])
            h_tau = -float(scene.du1(b.tau))
            S = _saltation(Dg, g_tau, fields.flight(b), fields.field(post), grad_h, h_tau, vs)
        else:
            Dg, g_tau = fields.enter(post, b.tau)
            if kind == "transition" and a.regime != _S:
                # a slip ends: h = u2' - v_tip(tau)
                S = _saltation(Dg, g_tau, fields.field(b), fields.field(post), np.ones(1),
                               -fields.vtip_rate(b.tau), vs)
            else:
                # lift-off, end of stick: at times set by the drive alone
                S = Dg
        M = S @ M
    return M


def _walker_of(scene, rtol, walker):
    # a given walker must walk this scene at this tolerance; it starts a fresh walk
    if walker is None:
        return FrictionDriveWalker(scene, rtol=rtol)
    if walker.scene is not scene or walker.rtol != rtol:
        raise InputError("`walker` must be a walker of `scene` at tolerance `rtol`")
    walker.reset()
    return walker


def walker_period_map_slope(scene, steady, step=1e-5, rtol=1e-12, walker=None):
    """``dP/du2'`` of the walker's scalar period map by central differences (the check).

    ``step`` is relative to the walker's velocity scale (the largest tip
    speed); ``walker`` as in :func:`walker_monodromy`.
    """
    walker = _walker_of(scene, rtol, walker)
    st0 = _section_start(walker, steady)
    if st0.regime == _F:
        raise MoreauError("the section is in flight: the walker's period map is not scalar there")
    h = step * walker.vscale
    phi_s, dphi_s = walker.manifold(st0.tau)

    def P(v):
        st = walker.classify(ContactState(st0.tau, _F, phi_s, dphi_s, 0.0, v))
        return walker.advance(st, st.tau + TWO_PI).du2

    return (P(st0.du2 + h) - P(st0.du2 - h)) / (2.0 * h)
