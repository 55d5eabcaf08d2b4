"""Event-driven reference integrator for the friction drive.

The run is split into smooth segments, one contact regime each (flight,
positive slip, negative slip, stick). Every regime change and impact is
located with a root finder (Brent's method) to near machine precision; the
regime after a slip velocity reaches zero comes from the exact
acceleration-level contact problem (Baraff's case analysis of
``g_N'' = A f_N - B f_T + D``, ``g_T'' = -B f_N + C f_T + E``).

While the tip touches the rotor the rod is fixed by the constraint
``sin phi = sin phi0 - u1(tau)``, so the contact forces of each regime are
explicit, ``2 pi``-periodic functions of ``tau``. The rotor acceleration of
each slip regime is expanded once in a Fourier series whose truncation error
is below round-off; its first and second antiderivatives are then exact, so
slip segments are integrated in closed form. Flight segments (the rod swings
freely) are integrated with compiled Taylor series at tight tolerance
(:mod:`moreau.scenes.friction_drive._flight_taylor`; SciPy's DOP853 on request); re-contact
is an impact with Newton's restitution coefficient and Coulomb friction.
"""

import dataclasses
import math
from typing import ClassVar

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from ..._validate import positive_int, relative_tolerance
from ...errors import InputError, MoreauError, PainleveError
from ...regimes import Regime
from ...integrators.base import Integrator, SchemeOptions, register_integrator
from ...integrators.result import Event
from ._flight_taylor import CAPACITY as FLIGHT_CAPACITY, ORDER as FLIGHT_ORDER
from ._flight_taylor import FAILED as _FT_FAILED, FULL as _FT_FULL
from ._flight_taylor import NEVER_CLEARED as _FT_NEVER_CLEARED, RECONTACT as _FT_RECONTACT
from ._flight_taylor import DenseFlight, flight_steps

__all__ = ["EventDriven", "ContactState", "FrictionDriveWalker", "impact_impulses"]

TWO_PI = 2.0 * math.pi
_F, _P, _N, _S = Regime.FLIGHT, Regime.POSITIVE, Regime.NEGATIVE, Regime.STICK
#: events in a row at one time after which a walk that makes no progress stops
MAX_EVENTS_AT_ONE_TIME = 1000
#: how flight segments are integrated: compiled Taylor series, or SciPy's DOP853
FLIGHT_METHODS = ("taylor", "dop853")
#: the longest Taylor step of a flight (its gap is sampled 16 times a step)
FLIGHT_HMAX = TWO_PI / 32
#: a recorded gap below -PENETRATION_TOL * u10 is a lost re-contact, an error (the
#: contact pieces are closed-form: their gaps are zero to rounding, about 1e-16)
PENETRATION_TOL = 1e-9


class ContactState:
    """Mutable state of the walk: time, regime and ``(phi, phi', u2, u2')``."""

    __slots__ = ("tau", "regime", "phi", "dphi", "u2", "du2")

    def __init__(self, tau, regime, phi, dphi, u2, du2):
        self.tau, self.regime = float(tau), Regime(regime)
        self.phi, self.dphi, self.u2, self.du2 = float(phi), float(dphi), float(u2), float(du2)

    def copy(self):
        return ContactState(self.tau, self.regime, self.phi, self.dphi, self.u2, self.du2)

    def __repr__(self):
        return (f"ContactState(tau={self.tau:.15g}, {self.regime.letter}, phi={self.phi:.15g}, "
                f"dphi={self.dphi:.6g}, u2={self.u2:.15g}, du2={self.du2:.15g})")


class _SlipSeries:
    """Fourier series of a 2 pi-periodic rotor acceleration and its antiderivatives."""

    def __init__(self, fun, tol=1e-13, n0=32, nmax=1 << 15):
        n = n0
        while True:
            tau = TWO_PI * np.arange(n) / n
            a = fun(tau)
            c = np.fft.rfft(a) / n
            scale = np.max(np.abs(a)) + 1e-300
            tail = np.max(np.abs(c[n // 4:]))
            if tail <= tol * scale or n >= nmax:
                break
            n *= 2
        self.truncation = float(tail / scale)
        # keep the modes that matter; the rest is below round-off
        keep = np.flatnonzero(np.abs(c) > 5e-15 * scale)
        K = int(keep.max()) if keep.size else 0
        K = max(K, 1)
        self.c0 = float(c[0].real)
        self.k = np.arange(1, K + 1, dtype=float)
        ck = 2.0 * c[1:K + 1]
        self.cA = ck / (1j * self.k)          # coefficients of the first antiderivative
        self.cAA = -ck / (self.k * self.k)    # and of the second
        self.ck = ck
        self._cA_list = [complex(c) for c in self.cA]

    def A_scalar(self, tau):
        """``A(tau)`` for one float, without numpy overhead (the event-location hot path)."""
        z = complex(math.cos(tau), math.sin(tau))
        zk = z
        acc = 0j
        for c in self._cA_list:
            acc += c * zk
            zk *= z
        return acc.real

    def A_uniform(self, n):
        """``A`` at ``tau = 2 pi j / n``, ``j = 0 .. n-1``, by one inverse FFT.

        On that grid ``exp(i k tau_j)`` depends on ``k mod n`` only: the
        coefficients are folded onto ``n`` bins (exact, aliasing included),
        instead of an ``n`` by ``K`` table of exponentials (``K`` is in the
        thousands at high frequency).
        """
        folded = np.zeros(n, dtype=complex)
        np.add.at(folded, self.k.astype(np.int64) % n, self.cA)
        return (n * np.fft.ifft(folded)).real

    def _basis(self, tau):
        return np.exp(1j * np.multiply.outer(np.asarray(tau, float), self.k))

    def A(self, tau):
        """Periodic part of the first antiderivative."""
        return (self._basis(tau) @ self.cA).real

    def AA(self, tau):
        """Periodic part of the second antiderivative."""
        return (self._basis(tau) @ self.cAA).real

    def both(self, tau):
        b = self._basis(tau)
        return (b @ self.cA).real, (b @ self.cAA).real


def impact_impulses(sc, mu, e, tau, phi, dphi, du2, sin=math.sin, cos=math.cos):
    """Impulses ``(p_N, p_T)`` of Newton's impact law with Coulomb friction (the walker's).

    ``sin`` and ``cos`` may be complex functions (``cmath``): the case
    analysis compares real parts only, so a complex-step derivative of the
    post-impact state follows the branch of the real impact
    (:mod:`moreau.scenes.friction_drive.floquet` takes its saltation
    matrices that way).

    Examples
    --------
    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=15000.0)
    >>> pN, pT = impact_impulses(sc, 0.0, 0.0, 0.0, 0.7, 1e-3, 0.0)   # approaching
    >>> bool(pN > 0.0), pT
    (True, 0.0)
    """
    s, c = sin(phi), cos(phi)
    vN = -c * dphi - sc.u10 * sin(tau)
    vT = du2 + s * dphi
    A, B, C = 3 * c * c, 3 * s * c, 1.0 / sc.J + 3 * s * s
    dvN = -(1.0 + e) * vN
    if mu > 0:
        det = A * C - B * B
        pN_s = (C * dvN - B * vT) / det
        pT_s = (B * dvN - A * vT) / det
        if pN_s.real >= 0 and abs(pT_s.real) <= mu * pN_s.real:
            return pN_s, pT_s
        p = dvN / (A + mu * B)
        if (vT - B * p - mu * C * p).real > 0:
            return p, -mu * p
        if (A - mu * B).real <= 0:
            raise PainleveError(
                f"impact at tau={float(tau.real):.12g} with 1 - mu*tan(phi) = "
                f"{1 - mu * math.tan(phi.real):.3g} <= 0 has no unique solution")
        p = dvN / (A - mu * B)
        return p, mu * p
    return dvN / A, 0.0


class _JoinedDense:
    """Dense output of two consecutive flight pieces."""

    def __init__(self, first, second, t_split):
        self.first, self.second, self.t_split = first, second, t_split

    def __call__(self, t):
        return self.first(t) if t < self.t_split else self.second(t)


class FrictionDriveWalker:
    """Segment-by-segment solver of the friction drive; the engine of the reference.

    Parameters
    ----------
    scene : FrictionDrive
    rtol : float
        Relative tolerance of the flight integration (contact segments are
        exact to round-off regardless).
    grid : int
        Samples per period used to bracket events before Brent's method.
    max_impacts : int
        Impacts allowed within one drive period (``2 pi`` in tau) before an
        accumulation (Zeno) is declared and the contact is closed; one more
        in that period is an error. The count is per period, not per run:
        an elastic rod that bounces once a period runs for as long as asked.
    flight_method : {"taylor", "dop853"}
        Flight segments by the compiled Taylor series (the default, see
        :mod:`moreau.scenes.friction_drive._flight_taylor`) or by SciPy's DOP853 at ``rtol``
        (slower by about two orders; kept as the cross-check).

    Notes
    -----
    With restitution ``e > 0`` the bounces of a re-contact accumulate (Zeno).
    After each impact the remaining time of the geometric bounce sequence is
    estimated as ``2 v_N / (|D| (1 - e))``; once it is below ``zeno_time``
    (``1e-6`` in tau) the accumulation point is taken as reached and the
    contact closes. The position error this makes is of order
    ``|D| zeno_time^2``.
    """

    def __init__(self, scene, rtol=1e-12, grid=512, max_impacts=10000, flight_method="taylor"):
        self.scene = scene
        self.rtol = relative_tolerance("rtol", rtol, floor=False)
        self.grid = positive_int("grid", grid)
        self.max_impacts = positive_int("max_impacts", max_impacts)
        self.mu = float(scene.mu[0])
        self.e = float(scene.restitution[0])
        self.n_impacts = 0
        self._burst_start = -math.inf
        self.zeno_time = 1e-6
        self._rebound_skip = None
        self.counters = {"events": 0, "impacts": 0, "flight_segments": 0, "root_solves": 0}
        if flight_method not in FLIGHT_METHODS:
            raise InputError(f"`flight_method` must be one of {list(FLIGHT_METHODS)}, "
                             f"got {flight_method!r}")
        self.flight_method = flight_method
        u10 = float(scene.u10)
        # the flight's constant arguments: a, P and b of the equation of motion, sin phi0,
        # u10, the Taylor terms' tolerance, the longest step and the gap's tolerance
        self._flight_args = (float(scene.P) * float(scene.sin_phi0) + float(scene.fp),
                             float(scene.P), 0.5 * u10, float(scene.sin_phi0), u10,
                             1e-3 * self.rtol * max(u10, 1e-12), FLIGHT_HMAX,
                             1e-13 * max(u10, 1e-300))
        self._flight_buffers = (np.empty((FLIGHT_CAPACITY, FLIGHT_ORDER + 1)),
                                np.empty(FLIGHT_CAPACITY), np.empty(FLIGHT_CAPACITY))
        self._build_tables()

    # -- tables over one period -----------------------------------------------
    def _build_tables(self):
        sc, mu, J, fL = self.scene, self.mu, self.scene.J, self.scene.fL
        self.series = {}
        for reg in (_P, _N):
            self.series[reg] = _SlipSeries(
                lambda t, reg=reg: (sc.contact_forces(t, reg)[1] - fL) / J)
        n = self.grid
        self.hg = TWO_PI / n
        tg = self.hg * np.arange(n)
        self.tg = tg
        phi, dphi, ddphi = sc.contact_angle(tg)
        self.g_phi, self.g_dphi = phi, dphi
        self.g_vtip = -np.sin(phi) * dphi
        self.g_A = {r: self.series[r].A_uniform(n) for r in (_P, _N)}
        self.g_fN = {r: sc.contact_forces(tg, r)[0] for r in (_P, _N, _S)}
        fNs, fTs = sc.contact_forces(tg, _S)
        self.g_stick_fT = fTs
        self.g_painleve = np.cos(phi) - mu * np.sin(phi)
        self.painleve_possible = bool(np.min(self.g_painleve) <= 0.0) or mu * math.tan(sc.phi0) >= 1.0
        # scale of the slip velocity, for tolerances
        self.vscale = float(np.max(np.abs(self.g_vtip))) + 1e-300
        self.fscale = float(np.max(np.abs(self.g_fN[_S]))) + 1e-300

    def checked_gap(self, st):
        """The gap of ``st``; raises where it is below ``-PENETRATION_TOL * u10``.

        Such a state is a re-contact the flight's event search did not see:
        it is never recorded or handed on as if it were a solution.
        """
        sc = self.scene
        gap = sc.sin_phi0 - math.sin(st.phi) - float(sc.u1(st.tau))
        if gap < -PENETRATION_TOL * max(sc.u10, 1e-300):
            raise MoreauError(
                f"the event-driven walker lost a re-contact: gap = {gap:.3g} < 0 at "
                f"tau = {st.tau!r} in regime {Regime(int(st.regime)).name}")
        return gap

    def reset(self):
        """Forget the impacts counted and a pending rebound skip: a new walk on the same tables."""
        self.n_impacts = 0
        self._burst_start = -math.inf
        self._rebound_skip = None

    # -- explicit contact quantities ------------------------------------------
    def vtip(self, tau):
        sc = self.scene
        s = sc.sin_phi0 - sc.u10 * (1.0 - math.cos(tau))
        return s * sc.u10 * math.sin(tau) / math.sqrt((1.0 - s) * (1.0 + s))

    def manifold(self, tau):
        sc = self.scene
        phi = math.asin(sc.sin_phi0 - sc.u10 * (1.0 - math.cos(tau)))
        return phi, -sc.u10 * math.sin(tau) / math.cos(phi)

    def _contact_scalars(self, tau):
        # the scene's contact_forces, written with math for single floats
        sc = self.scene
        cu, su = math.cos(tau), math.sin(tau)
        s = sc.sin_phi0 - sc.u10 * (1.0 - cu)
        c = math.sqrt((1.0 - s) * (1.0 + s))
        dd1 = sc.u10 * cu
        dphi = -sc.u10 * su / c
        ddphi = dphi * dphi * s / c - dd1 / c
        Fs = 0.5 * dd1 * c + ddphi / 3.0 - sc.P * c * (sc.sin_phi0 - s) - sc.fp * c
        return s, c, dphi, ddphi, Fs

    def fN(self, tau, regime):
        s, c, _, _, Fs = self._contact_scalars(tau)
        mu = self.mu
        if regime == _P:
            return -Fs / (c + mu * s)
        return -Fs / (c - mu * s)

    def stick_margins(self, tau):
        s, c, dphi, ddphi, Fs = self._contact_scalars(tau)
        sc = self.scene
        fT = sc.J * (-(dphi * dphi * c + ddphi * s)) + sc.fL
        fN = fT * s / c - Fs / c
        return fN, fT + self.mu * fN, self.mu * fN - fT

    def slip_state(self, st, tau):
        """``(u2, u2')`` at ``tau`` of the slip segment that starts at ``st``."""
        ser = self.series[st.regime]
        d = tau - st.tau
        A1, AA1 = ser.both(np.array([tau, st.tau]))
        du2 = st.du2 + ser.c0 * d + (A1[0] - A1[1])
        u2 = st.u2 + st.du2 * d + 0.5 * ser.c0 * d * d + (AA1[0] - AA1[1] - A1[1] * d)
        return u2, du2

    def stick_state(self, st, tau):
        phi, _ = self.manifold(tau)
        return st.u2 + math.cos(phi) - math.cos(st.phi), self.vtip(tau)

    # -- acceleration-level contact problem -------------------------------------
    def decide(self, tau, phi, dphi, slip, zero_slip):
        """Regime that follows a contact state with closed gap and zero normal velocity.

        Solves the 2D frictional contact problem at acceleration level by the
        exhaustive case analysis (flight, stick, positive slip, negative slip).
        Raises :class:`PainleveError` where negative slip is required but
        ``1 - mu tan(phi) <= 0``.
        """
        A, B, C, D, E = (float(x) for x in self.scene.coefficients(phi, dphi, tau))
        mu = self.mu
        AmB = A - mu * B
        if not zero_slip:
            if slip > 0:
                return _P if -D / (A + mu * B) > 0 else _F
            if AmB <= 0:
                raise PainleveError(
                    f"Painlevé condition violated in negative slip at tau={tau:.12g}: "
                    f"1 - mu*tan(phi) = {1 - mu * math.tan(phi):.3g} <= 0 (mu={mu}, phi={phi:.6g})")
            return _N if -D / AmB > 0 else _F
        if D >= 0.0:
            return _F
        det = A * C - B * B
        fN_s = -(C * D + B * E) / det
        fT_s = -(A * E + B * D) / det
        if fN_s >= 0 and abs(fT_s) <= mu * fN_s:
            return _S
        acc_p = (A * E + B * D + mu * (B * E + C * D)) / (A + mu * B)
        if acc_p > 0:
            return _P
        if AmB <= 0:
            raise PainleveError(
                f"Painlevé condition violated at tau={tau:.12g}: 1 - mu*tan(phi) = "
                f"{1 - mu * math.tan(phi):.3g} <= 0; the contact problem has no unique solution")
        acc_n = (A * E + B * D - mu * (B * E + C * D)) / AmB
        if acc_n < 0:
            return _N
        # exactly on a boundary of the case analysis: the stick solution is the limit of both
        return _S

    # -- event location --------------------------------------------------------
    def _window(self, ta, tb):
        k0 = math.floor(ta / self.hg) + 1
        k1 = math.floor(tb / self.hg)
        k = np.arange(k0, k1 + 1)
        return k * self.hg, k % self.grid

    def _first_root(self, f, tk, vals, ta, tb):
        """First tau in (ta, tb] where the continuous ``f`` (positive at ta+) reaches 0.

        ``vals`` are the samples of ``f`` at the grid points ``tk``. A sign
        change is refined by Brent's method; a grid cell whose samples stay
        positive but whose local minimum could dip below zero is checked
        with a bounded minimisation, so double crossings inside a cell are
        not missed. A segment that starts on a zero of ``f`` (slip starting
        from zero velocity) is searched from ``ta + skip`` on, ``skip`` being
        far below any physical time scale but above round-off.
        """
        skip = 1e-10 * max(1.0, abs(ta))
        keep = tk > ta + skip
        tk, vals = tk[keep], vals[keep]
        n = vals.size
        # the start: positive by assumption, unless the grid says otherwise
        t0 = ta
        if n == 0 or vals[0] <= 0.0:
            if f(ta) <= 0.0:
                t0 = ta + skip
            if t0 >= tb:
                return None
        # the end point is evaluated only where the last cell could reach zero
        need_end = n == 0 or tk[-1] < tb and (
            n < 2 or vals[-1] <= 2.0 * abs(vals[-1] - vals[-2]))
        if need_end:
            tt = np.empty(n + 2)
            fv = np.empty(n + 2)
            tt[1:n + 1], fv[1:n + 1] = tk, vals
            tt[-1], fv[-1] = tb, f(tb)
        else:
            tt = np.empty(n + 1)
            fv = np.empty(n + 1)
            tt[1:], fv[1:] = tk, vals
        tt[0] = t0
        fv[0] = vals[0] if n and vals[0] > 0.0 else 0.0
        neg = np.flatnonzero(fv[1:] <= 0.0)
        stop = neg[0] + 1 if neg.size else fv.size
        # interior local minima before the first sign change
        if stop > 2:
            seg = fv[:stop]
            d = np.diff(seg)
            mins = np.flatnonzero((d[:-1] < 0) & (d[1:] >= 0)) + 1
            for j in mins:
                var = abs(d[j - 1]) + abs(d[j])
                if seg[j] > var:
                    continue
                lo, hi = tt[j - 1], tt[min(j + 1, tt.size - 1)]
                r = minimize_scalar(f, bounds=(lo, hi), method="bounded",
                                    options={"xatol": 1e-14 * max(1.0, abs(hi))})
                if r.fun <= 0.0:
                    self.counters["root_solves"] += 1
                    if f(lo) <= 0.0:
                        return lo
                    return brentq(f, lo, r.x, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
        if not neg.size:
            return None
        i = neg[0] + 1
        lo, hi = tt[i - 1], tt[i]
        self.counters["root_solves"] += 1
        if f(lo) <= 0.0:
            return lo
        return brentq(f, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)

    def next_event(self, st, tau_end):
        """Locate the first event of the contact segment that starts at ``st``.

        Returns ``(tau_event, kind, new_regime)`` or ``(tau_end, None, regime)``.
        """
        ta = st.tau
        tb = min(tau_end, ta + TWO_PI)
        tk, jk = self._window(ta, tb)
        tk_ok = tk > ta
        tk, jk = tk[tk_ok], jk[tk_ok]
        cands = []
        reg = st.regime
        if reg in (_P, _N):
            sign = 1.0 if reg == _P else -1.0
            ser = self.series[reg]
            Aa = ser.A_scalar(ta)

            def slip(t):
                return sign * (st.du2 + ser.c0 * (t - ta) + ser.A_scalar(t) - Aa - self.vtip(t))

            vals = sign * (st.du2 + ser.c0 * (tk - ta) + self.g_A[reg][jk] - Aa - self.g_vtip[jk])
            r = self._first_root(slip, tk, vals, ta, tb)
            if r is not None:
                cands.append((r, "slip_end", None))
            r = self._first_root(lambda t: self.fN(t, reg), tk, self.g_fN[reg][jk], ta, tb)
            if r is not None:
                cands.append((r, "liftoff", _F))
        elif reg == _S:
            mu = self.mu
            fNg, fTg = self.g_fN[_S][jk], self.g_stick_fT[jk]
            r = self._first_root(lambda t: self.stick_margins(t)[1], tk, fTg + mu * fNg, ta, tb)
            if r is not None:
                cands.append((r, "stick_end", _P))
            r = self._first_root(lambda t: self.stick_margins(t)[2], tk, mu * fNg - fTg, ta, tb)
            if r is not None:
                cands.append((r, "stick_end", _N))
            r = self._first_root(lambda t: self.stick_margins(t)[0], tk, fNg, ta, tb)
            if r is not None:
                cands.append((r, "liftoff", _F))
        else:
            raise MoreauError("next_event is for contact regimes")
        if self.painleve_possible:
            mu = self.mu

            def pm(t):
                phi, _ = self.manifold(t)
                return math.cos(phi) - mu * math.sin(phi)

            r = self._first_root(pm, tk, self.g_painleve[jk], ta, tb)
            if r is not None:
                cands.append((r, "painleve", None))
        if not cands:
            return tb, None, reg
        return min(cands, key=lambda c: c[0])

    def move_contact(self, st, tau):
        """Return the state of the current contact segment at ``tau``."""
        out = st.copy()
        out.tau = tau
        out.phi, out.dphi = self.manifold(tau)
        if st.regime == _S:
            out.u2, out.du2 = self.stick_state(st, tau)
        else:
            out.u2, out.du2 = self.slip_state(st, tau)
        return out

    # -- flight -------------------------------------------------------------------
    def _flight_rhs(self, t, y):
        sc = self.scene
        phi = y[0]
        c = math.cos(phi)
        ddphi = 3.0 * (sc.P * c * (sc.sin_phi0 - math.sin(phi)) - 0.5 * sc.u10 * math.cos(t) * c
                       + sc.fp * c)
        return [y[1], ddphi, y[3], -sc.fL / sc.J]

    def _gap(self, t, y):
        sc = self.scene
        return sc.sin_phi0 - math.sin(y[0]) - sc.u10 * (1.0 - math.cos(t))

    def flight(self, st, tau_end, dense=False):
        """Integrate a flight segment up to re-contact or ``tau_end``.

        Returns ``(state_at_end, recontact, sol)``; ``sol`` is the dense output
        when requested. The compiled Taylor series of
        :mod:`moreau.scenes.friction_drive._flight_taylor` by default; with
        ``flight_method="dop853"`` SciPy's DOP853 (the cross-check).
        """
        self.counters["flight_segments"] += 1
        if self.flight_method == "dop853":
            return self._flight_dop853(st, tau_end, dense)
        sc = self.scene
        t0 = st.tau
        # a flight starts on a zero of the gap (lift-off or rebound): only a dip below
        # the gap's tolerance counts as a return before the skip
        skip = 1e-9 * max(1.0, abs(t0))
        if self._rebound_skip is not None:
            skip, self._rebound_skip = self._rebound_skip, None
        tau, phi, dphi, cleared = t0, st.phi, st.dphi, False
        coef, starts, widths = self._flight_buffers
        pieces = []
        while True:
            code, tau, phi, dphi, n, cleared = flight_steps(
                tau, phi, dphi, tau_end, t0 + skip - tau, cleared, *self._flight_args,
                coef, starts, widths)
            if dense:
                pieces.append((coef[:n].copy(), starts[:n].copy(), widths[:n].copy()))
            if code != _FT_FULL:
                break
        if code == _FT_FAILED:
            raise MoreauError(f"flight integration failed: the Taylor step collapsed at "
                              f"tau = {tau!r}")
        out = st.copy()
        if code == _FT_NEVER_CLEARED:
            # the rebound never cleared the gap's rounding: the contact closes where the
            # flight began (late in a Zeno sequence)
            tau, phi, dphi = t0, st.phi, st.dphi
        s = tau - t0
        accel = -float(sc.fL) / float(sc.J)
        out.tau, out.phi, out.dphi = float(tau), float(phi), float(dphi)
        out.u2 = st.u2 + st.du2 * s + 0.5 * accel * s * s
        out.du2 = st.du2 + accel * s
        sol = None
        if dense:
            sol = DenseFlight(np.concatenate([p[0] for p in pieces]),
                              np.concatenate([p[1] for p in pieces]),
                              np.concatenate([p[2] for p in pieces]), t0, st.u2, st.du2, accel)
        if code in (_FT_RECONTACT, _FT_NEVER_CLEARED):
            self.counters["root_solves"] += 1
            return out, True, sol
        return out, False, sol

    def _flight_dop853(self, st, tau_end, dense=False):
        # the former integration of a flight, kept as the independent cross-check
        def gap(t, y):
            return self._gap(t, y)

        gap.terminal = True
        gap.direction = -1
        y0 = [st.phi, st.dphi, st.u2, st.du2]
        scale = np.array([1.0, 1.0, 1.0, 1.0]) * max(self.scene.u10, 1e-12)
        opts = dict(method="DOP853", rtol=self.rtol, atol=1e-3 * self.rtol * scale)
        t0 = st.tau
        pre = None
        # a flight starts on a zero of the gap (lift-off or rebound): step off it
        # before watching for re-contact, so the start is not taken for an event
        skip = 1e-9 * max(1.0, abs(t0))
        if self._rebound_skip is not None:
            skip, self._rebound_skip = self._rebound_skip, None
        if t0 + skip < tau_end:
            pre = solve_ivp(self._flight_rhs, (t0, t0 + skip), y0, dense_output=True, **opts)
            # the skip is half the flight time at the rebound's normal acceleration; a
            # steeper pull (late in a Zeno sequence) can bring the rod back inside it
            early = self._missed_recontact(pre)
            if early is not None:
                te, ye = early
                out = st.copy()
                out.tau, out.phi, out.dphi, out.u2, out.du2 = te, *map(float, ye)
                return out, True, (pre.sol if dense else None)
            y0 = pre.y[:, -1]
            t0 = t0 + skip
        sol = solve_ivp(self._flight_rhs, (t0, tau_end), y0, events=gap, dense_output=True, **opts)
        if sol.status < 0:
            raise MoreauError(f"flight integration failed: {sol.message}")
        graze = self._missed_recontact(sol)
        if dense and pre is not None:
            sol.sol = _JoinedDense(pre.sol, sol.sol, t0)
        out = st.copy()
        if graze is not None:
            te, ye = graze
            out.tau, out.phi, out.dphi, out.u2, out.du2 = te, *map(float, ye)
            return out, True, (sol.sol if dense else None)
        if sol.status == 1:
            te = float(sol.t_events[0][0])
            ye = sol.y_events[0][0]
            out.tau, out.phi, out.dphi, out.u2, out.du2 = te, *map(float, ye)
            return out, True, (sol.sol if dense else None)
        out.tau = float(sol.t[-1])
        out.phi, out.dphi, out.u2, out.du2 = map(float, sol.y[:, -1])
        return out, False, (sol.sol if dense else None)

    def _missed_recontact(self, sol, per_step=16):
        """First re-contact inside a flight that the step-end sign test missed.

        ``solve_ivp`` compares the gap at the ends of its steps only, so a
        grazing return that dips below zero and comes back inside one step
        goes unseen. The dense output is sampled ``per_step`` times per step;
        a negative sample is bracketed and refined with Brent's method.
        Returns ``(tau, y)`` or ``None``.
        """
        t = sol.t
        if t.size < 2:
            return None
        frac = np.linspace(0.0, 1.0, per_step + 1)[1:-1]
        ts = np.sort(np.concatenate([t, (t[:-1, None] + np.diff(t)[:, None] * frac).ravel()]))
        if sol.status == 1:
            ts = ts[ts < sol.t_events[0][0]]
        if ts.size < 2:
            return None
        ys = sol.sol(ts)
        sc = self.scene
        g = sc.sin_phi0 - np.sin(ys[0]) - sc.u10 * (1.0 - np.cos(ts))
        tol = 1e-13 * max(sc.u10, 1e-300)
        bad = np.flatnonzero(g[1:] < -tol)
        if not bad.size:
            return None
        i = bad[0] + 1
        f = lambda tau: self._gap(tau, sol.sol(tau))  # noqa: E731
        if f(ts[i - 1]) <= 0.0:
            if np.all(g[:i] <= tol):
                # the rod never cleared the surface before sinking into it (a rebound
                # whose height is below the gap's rounding, late in a Zeno sequence):
                # the contact closes where the flight began
                return ts[0], sol.sol(ts[0])
            return None  # started on the surface: not a return
        te = brentq(f, ts[i - 1], ts[i], xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
        self.counters["root_solves"] += 1
        return te, sol.sol(te)

    def impact(self, st):
        """Apply Newton's impact law with Coulomb friction at a re-contact.

        Returns the post-impact state and the impulses ``(p_N, p_T)``.
        """
        sc = self.scene
        s, c = math.sin(st.phi), math.cos(st.phi)
        pN, pT = impact_impulses(sc, self.mu, self.e, st.tau, st.phi, st.dphi, st.du2)
        out = st.copy()
        out.dphi = st.dphi + 3.0 * (-c * pN + s * pT)
        out.du2 = st.du2 + pT / sc.J
        if st.tau - self._burst_start > TWO_PI:
            # a new drive period of impacts: an accumulation is counted within one
            self._burst_start = st.tau
            self.n_impacts = 0
        self.n_impacts += 1
        self.counters["impacts"] += 1
        if self.n_impacts > self.max_impacts:
            raise MoreauError(f"more than `max_impacts`={self.max_impacts} impacts within one "
                              f"drive period before tau = {st.tau:.12g}")
        return out, pN, pT

    # -- entering a regime ------------------------------------------------------------
    def classify(self, st, closing=False):
        """Set ``st.regime`` from a state (gap, normal and slip velocities, forces).

        With ``closing=True`` (right after a plastic impact) the gap and the
        normal velocity are taken as zero and the rod is put on the contact
        manifold.
        """
        sc = self.scene
        if not closing:
            gap = sc.sin_phi0 - math.sin(st.phi) - float(sc.u1(st.tau))
            vN = -math.cos(st.phi) * st.dphi - float(sc.du1(st.tau))
            tol_g = 1e-12 * max(sc.u10, 1e-300)
            tol_v = 1e-10 * self.vscale
            if gap < -tol_g:
                raise InputError(f"the initial state penetrates the rotor: gap = {gap:.3g} < 0")
            if gap > tol_g or vN > tol_v:
                st.regime = _F
                return st
            if vN < -tol_v:
                # closed gap and approaching: the state is an impact
                st, _, _ = self.impact(st)
        st.phi, st.dphi = self.manifold(st.tau)
        if self.mu * math.tan(st.phi) >= 1.0:
            raise PainleveError(
                f"Painlevé condition 1 - mu*tan(phi) > 0 fails at tau={st.tau:.12g} "
                f"(mu={self.mu}, phi={st.phi:.6g}, 1 - mu*tan(phi) = "
                f"{1 - self.mu * math.tan(st.phi):.3g})")
        slip = st.du2 + math.sin(st.phi) * st.dphi
        zero = abs(slip) <= 1e-13 * self.vscale
        st.regime = self.decide(st.tau, st.phi, st.dphi, slip, zero)
        if st.regime == _S:
            st.du2 = self.vtip(st.tau)
        return st

    # -- the walk ------------------------------------------------------------------------
    def segment(self, st, tau_end, on_segment=None):
        """Run one segment from ``st``: to its closing event or to ``tau_end``.

        Returns ``(state, event)``; ``event`` is ``None`` when ``tau_end`` was
        reached first. ``on_segment(start_state, end_state, flight_sol)``
        receives the finished segment (``flight_sol`` is the dense output of a
        flight segment, else ``None``).
        """
        if st.regime == _F:
            end, hit, sol = self.flight(st, tau_end, dense=on_segment is not None)
            if on_segment:
                on_segment(st, end, sol)
            if not hit:
                return end, None
            before = end.regime
            vN = -math.cos(end.phi) * end.dphi - float(self.scene.du1(end.tau))
            kind = "touchdown"
            if vN < -1e-10 * self.vscale:
                end, _, _ = self.impact(end)
                kind = "impact"
            vN_post = -math.cos(end.phi) * end.dphi - float(self.scene.du1(end.tau))
            D = float(self.scene.coefficients(end.phi, end.dphi, end.tau)[3])
            # remaining time of the geometric (Zeno) bounce sequence; below the
            # threshold the accumulation point is taken as reached
            zeno = (2.0 * vN_post / (-D * (1.0 - self.e))) if (D < 0 and self.e < 1) else math.inf
            # a flight that met the surface where it began (its rebound never cleared the
            # gap's rounding, see _missed_recontact) is at the accumulation point too: a
            # new rebound would start the same flight again, for ever (found at 15 kHz,
            # e = 0.5: vN_post = 4.7e-12 after a rebound of zero length, at every step)
            if (self.e > 0 and vN_post > 1e-12 * self.vscale and zeno > self.zeno_time
                    and self.n_impacts < self.max_impacts and end.tau > st.tau):
                end.regime = _F
                self._rebound_skip = 0.5 * vN_post / -D if D < 0 else None
            else:
                # plastic impact, or the accumulation point of a Zeno sequence: contact closes
                self.classify(end, closing=True)
            self.counters["events"] += 1
            return end, Event(end.tau, kind, before, end.regime)
        te, kind, new = self.next_event(st, tau_end)
        end = self.move_contact(st, te)
        if on_segment:
            on_segment(st, end, None)
        if kind is None:
            return end, None
        self.counters["events"] += 1
        if kind == "painleve":
            raise PainleveError(
                f"Painlevé condition 1 - mu*tan(phi) > 0 fails at tau={te:.12g} "
                f"(mu={self.mu}, phi={end.phi:.6g}): the contact problem loses existence "
                "or uniqueness")
        if kind == "slip_end":
            end.du2 = self.vtip(te)  # the slip velocity is exactly zero here
            end.regime = self.decide(te, end.phi, end.dphi, 0.0, True)
        elif kind == "liftoff":
            end.regime = _F
        else:
            if new == _N and self.mu * math.tan(end.phi) >= 1.0:
                raise PainleveError(
                    f"stick ends towards negative slip at tau={te:.12g} where "
                    f"1 - mu*tan(phi) = {1 - self.mu * math.tan(end.phi):.3g} <= 0")
            end.regime = new
        return end, Event(te, "liftoff" if kind == "liftoff" else "transition", st.regime, end.regime)

    def advance(self, st, tau_end, on_segment=None, on_event=None, max_events=100000):
        """Advance ``st`` to ``tau_end`` through all events; return the final state."""
        st = st.copy()
        n = stalled = 0
        while st.tau < tau_end:
            start = st.tau
            st, ev = self.segment(st, tau_end, on_segment)
            if ev is not None:
                n += 1
                if on_event:
                    on_event(ev)
                if n > max_events:
                    raise MoreauError(f"more than {max_events} events before tau={tau_end:.6g} "
                                      "(an accumulation of events?)")
                # a walk stuck at one time would otherwise run to max_events first
                stalled = 0 if st.tau > start else stalled + 1
                if stalled > MAX_EVENTS_AT_ONE_TIME:
                    raise MoreauError(
                        f"the event-driven walk makes no progress: {stalled} events in a row "
                        f"at tau = {st.tau!r} (last: {ev.kind}); "
                        f"{_stall_cause(ev, 'an accumulation of events')}")
        return st


def _stall_cause(ev, otherwise):
    # a touchdown that leaves the rod in flight, at one time: the flight re-contacts at once
    # and the closed contact, its normal force not positive, lifts off at once
    if ev is not None and ev.kind == "touchdown" and ev.before == ev.after == _F:
        return ("a grazing contact: the rod meets the rotor with no normal velocity and no "
                "normal force, so each flight re-contacts at once and each contact lifts off "
                "at once (a tangency the walk does not resolve: the motion is at a lift-off)")
    return otherwise


@register_integrator("friction-drive-walker")
class EventDriven(Integrator):
    """Event-driven reference integrator of the friction drive (``"friction-drive-walker"``).

    The high-precision path for :class:`~moreau.scenes.friction_drive.FrictionDrive`:
    contact segments are integrated in closed form, so they are exact to
    round-off. ``simulate(..., "event-driven")`` selects it for that scene
    (the scene names it in ``reference_integrator``); the scene-independent
    scheme, :class:`~moreau.integrators.event_driven_generic.GenericEventDriven`
    (``"event-driven-generic"``), cross-checks it.

    Each :meth:`step` advances to the next event (regime change or impact)
    or to ``t_bound``. Samples are recorded at every event and on a uniform
    grid of ``samples_per_period`` points per drive period.

    Parameters
    ----------
    scene : FrictionDrive
    t0, q0, v0, t_bound
        See :class:`~moreau.integrators.base.Integrator`; ``q0 = (phi, u2)``,
        ``v0 = (phi', u2')`` in the scene's dimensionless units.
    rtol : float
        Relative tolerance of flight segments.
    samples_per_period : int
        Output density.

    Examples
    --------
    Two drive periods from rest, one event a step (``simulate(..., "event-driven")`` runs
    these steps for this scene):

    >>> from moreau.scenes.friction_drive import FrictionDrive
    >>> sc = FrictionDrive(frequency=185.0)
    >>> walker = EventDriven(sc, 0.0, *sc.rest_state(), 4 * np.pi)
    >>> while walker.step() == "running":
    ...     pass
    >>> walker.status, walker.t == 4 * np.pi, walker.counters["events"]
    ('finished', True, 4)
    """

    exact_motion = True

    @dataclasses.dataclass(frozen=True)
    class Options(SchemeOptions):
        """Options of the friction drive's walker (its parameters after ``t_bound``)."""
        rtol: float = 1e-12
        samples_per_period: int = 128

        _rules: ClassVar[dict] = {
            "rtol": lambda v: relative_tolerance("rtol", v, floor=False),
            "samples_per_period": lambda v: positive_int("samples_per_period", v)}

    takes_options_object = True

    def __init__(self, scene, t0, q0, v0, t_bound, options=None, **keywords):
        super().__init__(scene, t0, q0, v0, t_bound)
        self.options = o = self._take_options(options, keywords)
        if scene.ncontacts != 1 or not hasattr(scene, "contact_angle"):
            raise InputError("`scene` must be a FrictionDrive for the event-driven reference")
        self.walker = FrictionDriveWalker(scene, rtol=o.rtol)
        self.samples_per_period = o.samples_per_period
        self._stalled = 0       # events in a row that did not advance time
        st = ContactState(self.t, _F, self.q[0], self.v[0], self.q[1], self.v[1])
        try:
            self.state = self.walker.classify(st)
        except PainleveError as exc:
            # the initial state is already ill-posed: a run that stops at once, with its cause
            self.state = st
            self._fail(-1, str(exc))
            return
        self._record_state(self.state)

    def _record_state(self, st):
        self._record(*self._sample_row(st))
        self.t, self.q, self.v = st.tau, np.array([st.phi, st.u2]), np.array([st.dphi, st.du2])

    def _sample_row(self, st):
        sc = self.scene
        if st.regime == _F:
            fN = fT = 0.0
        else:
            fN, fT = (float(x) for x in sc.contact_forces(st.tau, st.regime))
        slip = st.du2 + math.sin(st.phi) * st.dphi
        gap = self.walker.checked_gap(st)
        return (st.tau, np.array([st.phi, st.u2]), np.array([st.dphi, st.du2]), int(st.regime),
                fN, fT, slip, gap)

    def _on_segment(self, start, end, sol):
        if self._want_pieces and end.tau > start.tau:
            self._hand_segment(start, end, sol)
        dt = TWO_PI / self.samples_per_period
        k0 = math.floor(start.tau / dt) + 1
        k1 = math.ceil(end.tau / dt) - 1
        for k in range(k0, k1 + 1):
            tau = k * dt
            if start.regime == _F:
                y = sol(tau)
                s = ContactState(tau, _F, *y)
            else:
                s = self.walker.move_contact(start, tau)
            self._record_state(s)
        self._record_state(end)

    def _hand_segment(self, start, end, sol):
        # the segment's exact motion: the flight's dense output, or the closed form of a
        # contact segment; an event function is checked on a grid of 64 points per period.
        # The walk goes on changing its states after this call: keep copies
        start, end = start.copy(), end.copy()

        def at(tau):
            if tau >= end.tau:
                return end
            if start.regime == _F:
                return ContactState(tau, _F, *sol(tau))
            return self.walker.move_contact(start, tau)

        def state(tau):
            st = at(tau)
            return np.array([st.phi, st.u2, st.dphi, st.du2])

        k = max(2, math.ceil((end.tau - start.tau) / (TWO_PI / 64)) + 1)
        self._add_piece(np.linspace(start.tau, end.tau, k), state,
                        lambda tau: self._sample_row(at(tau)))

    #: events in a row at one time after which a walk that makes no progress stops
    MAX_EVENTS_AT_ONE_TIME = MAX_EVENTS_AT_ONE_TIME

    def _step_impl(self):
        w = self.walker
        start = self.state.tau
        end, ev = w.segment(self.state, self.t_bound, self._on_segment)
        if ev is not None:
            self.events.append(ev)
            self._record_state(end)
        self.state = end
        self.t = end.tau
        self.counters.update(w.counters)
        # a walk whose events stop advancing time would record a sample and an event each
        # step for ever (found: the stress catalogue's flight at e = 0.5 grew past 10 GB)
        self._stalled = 0 if end.tau > start else self._stalled + 1
        if self._stalled > self.MAX_EVENTS_AT_ONE_TIME:
            raise MoreauError(
                f"the event-driven walk makes no progress: {self._stalled} events in a row at "
                f"tau = {end.tau!r} (last: {ev.kind if ev is not None else 'none'}, regime "
                f"{Regime(int(end.regime)).name}); "
                f"{_stall_cause(ev, 'an accumulation of impacts it does not resolve')}")
