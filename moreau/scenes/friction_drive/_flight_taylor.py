"""Compiled Taylor-series integration of the friction drive's flight segments.

In flight the rod swings freely about its moving hinge; in the scene's
dimensionless variables (derived from the rod's Lagrangian with the contact
force removed, as in :meth:`FrictionDriveWalker._flight_rhs`)

    phi'' = 3 cos(phi) (P (sin phi0 - sin phi) - u10/2 cos(tau) + fp),

and the rotor decelerates uniformly, ``u2'' = -fL / J`` (exact quadratic).
The gap to the rotor is ``g = sin phi0 - sin phi - u10 (1 - cos tau)``.

The right-hand side is a composition of ``sin``, ``cos`` and products, so
the Taylor coefficients of ``phi`` about any time follow from the
recurrences of automatic differentiation: with ``S = sin phi``,
``C = cos phi`` (``S' = C phi'``, ``C' = -S phi'``)

    k S_k = sum_{j=1..k} j x_j C_{k-j},     k C_k = -sum_{j=1..k} j x_j S_{k-j},

``cos(tau0 + s)`` has the coefficients ``cos^(k)(tau0) / k!`` and
``(k + 2)(k + 1) x_{k+2} = 3 sum_j C_j H_{k-j}`` with
``H = P (sin phi0 - S) - u10/2 cos(tau) + fp``. The series of order
:data:`ORDER` is the step's dense output, and the gap is a polynomial in
the step whose first crossing is found by sampling and bisection: no
event a step-end sign test would miss, and no call back into Python.
The step is the largest one whose last two terms stay below the absolute
tolerance (the rule of Jorba and Zou, 2005), for the angle and the angular
velocity alike.

Against :func:`scipy.integrate.solve_ivp` (DOP853 at ``rtol`` 1e-12), which
the walker used before, a flight segment costs microseconds instead of
about a millisecond; the two agree to the latter's tolerance
(``tests/scenes/test_flight_taylor.py``).
"""

import math

import numpy as np
from numba import njit

__all__ = ["ORDER", "flight_steps", "DenseFlight"]

#: order of the Taylor polynomials
ORDER = 24
#: steps one compiled call stores before it hands back (the caller continues)
CAPACITY = 256
#: samples of the gap polynomial per step, to find a return that dips in and out
PER_STEP = 16

# codes of flight_steps
REACHED, RECONTACT, NEVER_CLEARED, FULL, FAILED = 0, 1, 2, 3, -1


@njit(cache=True)
def _series(x, S, C, cs, tau0, phi, dphi, a, P, b):
    """Taylor coefficients of phi (x), sin phi (S), cos phi (C), cos tau (cs) about tau0."""
    n = x.size - 1
    ct, st = math.cos(tau0), math.sin(tau0)
    f = 1.0
    for k in range(n + 1):
        if k > 0:
            f /= k
        r = k % 4
        d = ct if r == 0 else (-st if r == 1 else (-ct if r == 2 else st))
        cs[k] = d * f
    x[0] = phi
    x[1] = dphi
    S[0] = math.sin(phi)
    C[0] = math.cos(phi)
    for k in range(n + 1):
        if k >= 1:
            s_ = 0.0
            c_ = 0.0
            for j in range(1, k + 1):
                s_ += j * x[j] * C[k - j]
                c_ += j * x[j] * S[k - j]
            S[k] = s_ / k
            C[k] = -c_ / k
        if k + 2 <= n:
            F = 0.0
            for j in range(k + 1):
                h = -P * S[k - j] - b * cs[k - j]
                if k - j == 0:
                    h += a
                F += C[j] * h
            x[k + 2] = 3.0 * F / ((k + 2) * (k + 1))


@njit(cache=True)
def _gap_at(S, cs, s, g0, u10):
    # g(s) = sin phi0 - S(s) - u10 + u10 cos(tau0 + s), by Horner; g0 = sin phi0 - u10
    n = S.size - 1
    acc = u10 * cs[n] - S[n]
    for k in range(n - 1, -1, -1):
        acc = acc * s + (u10 * cs[k] - S[k])
    return g0 + acc


@njit(cache=True)
def _poly(x, s):
    n = x.size - 1
    p = x[n]
    dp = n * x[n]
    for k in range(n - 1, -1, -1):
        p = p * s + x[k]
        if k >= 1:
            dp = dp * s + k * x[k]
    return p, dp


@njit(cache=True)
def _root(S, cs, lo, hi, g0, u10):
    # bisection on the step's gap polynomial, g(lo) > 0 >= g(hi), to rounding
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _gap_at(S, cs, mid, g0, u10) > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def flight_steps(tau, phi, dphi, tau_end, skip, cleared, a, P, b, sin_phi0, u10, eps, hmax,
                 tol_gap, coef, starts, widths):
    """Integrate a flight from ``tau`` until the gap closes or ``tau_end``.

    Parameters
    ----------
    tau, phi, dphi : float
        Start (on the scene's dimensionless time and angle).
    tau_end : float
    skip : float
        Time after ``tau`` before a crossing of the gap counts as a return
        (a flight starts on a zero of the gap); before it only a gap below
        ``-tol_gap`` is a return.
    cleared : bool
        Whether the gap has already exceeded ``tol_gap`` in this flight.
    a, P, b : float
        ``P sin phi0 + fp``, ``P`` and ``u10 / 2`` of the equation of motion.
    eps, hmax : float
        Absolute tolerance of the last Taylor terms; longest step.
    coef, starts, widths : ndarray
        Storage of the steps' series ``(CAPACITY, ORDER + 1)``, start times
        and lengths (the dense output).

    Returns
    -------
    code, tau, phi, dphi, steps, cleared
        ``code``: :data:`REACHED` (``tau_end``), :data:`RECONTACT` (at the
        returned time), :data:`NEVER_CLEARED` (the gap went below
        ``-tol_gap`` without ever exceeding ``tol_gap``: the contact closes
        at the start), :data:`FULL` (storage full: call again from the
        returned state) or :data:`FAILED` (the step size collapsed).
    """
    n = coef.shape[1] - 1
    x = np.empty(n + 1)
    S = np.empty(n + 1)
    C = np.empty(n + 1)
    cs = np.empty(n + 1)
    g0 = sin_phi0 - u10
    tau_start = tau
    armed_at = tau + skip
    steps = 0
    while tau < tau_end:
        if steps == coef.shape[0]:
            return FULL, tau, phi, dphi, steps, cleared
        _series(x, S, C, cs, tau, phi, dphi, a, P, b)
        h = min(hmax, tau_end - tau)
        if steps == 0 and skip > 0.0:
            # the first step resolves the skip: a rebound's flight lasts about twice
            # its skip (the apex time), and the gap's samples must see its hump
            h = min(h, 4.0 * skip)
        for k in (n - 1, n):
            m = abs(x[k])
            if m > 0.0:
                h = min(h, (eps / m) ** (1.0 / k), (eps / (k * m)) ** (1.0 / (k - 1)))
        if not (h > 1e-13 * max(1.0, abs(tau))):
            return FAILED, tau, phi, dphi, steps, cleared
        if tau + h >= tau_end or tau_end - (tau + h) < 1e-14 * max(1.0, abs(tau_end)):
            h = tau_end - tau
        # element by element: a slice assignment compiles numba's shape-mismatch error
        # message (string formatting, about 2.5 CPU s on a cold cache)
        for j in range(n + 1):
            coef[steps, j] = x[j]
        starts[steps] = tau
        widths[steps] = h
        steps += 1
        # sample the gap polynomial across the step
        s_prev = 0.0
        g_prev = _gap_at(S, cs, 0.0, g0, u10)
        if g_prev > tol_gap:
            cleared = True
        for i in range(1, PER_STEP + 1):
            s = h * i / PER_STEP
            g = _gap_at(S, cs, s, g0, u10)
            armed = tau + s >= armed_at
            hit = (g <= 0.0 and g_prev > 0.0 and armed) or g < -tol_gap
            if hit:
                if g_prev > 0.0:
                    r = _root(S, cs, s_prev, s, g0, u10)
                    p, dp = _poly(x, r)
                    widths[steps - 1] = r
                    return RECONTACT, tau + r, p, dp, steps, cleared
                widths[steps - 1] = s_prev
                if not cleared:
                    return NEVER_CLEARED, tau_start, phi, dphi, steps, cleared
                # the gap crossed zero inside the skip, where only a dip below -tol_gap
                # counts, and the previous sample is on the surface to within tol_gap:
                # the return is there
                p, dp = _poly(x, s_prev)
                return RECONTACT, tau + s_prev, p, dp, steps, cleared
            if g > tol_gap:
                cleared = True
            s_prev, g_prev = s, g
        phi, dphi = _poly(x, h)
        tau = tau + h if h < tau_end - tau else tau_end
    return REACHED, tau, phi, dphi, steps, cleared


class DenseFlight:
    """Dense output of a Taylor flight: ``sol(tau)`` gives ``(phi, phi', u2, u2')``.

    ``tau`` may be a float (a vector of 4 is returned) or an array (shape
    ``(4, n)``), as with :func:`scipy.integrate.solve_ivp`'s dense output.
    """

    def __init__(self, coef, starts, widths, tau0, u2, du2, accel):
        self.coef, self.starts, self.widths = coef, starts, widths
        self.tau0, self.u2, self.du2, self.accel = tau0, u2, du2, accel

    def _one(self, t):
        i = int(np.searchsorted(self.starts, t, side="right")) - 1
        i = min(max(i, 0), len(self.starts) - 1)
        phi, dphi = _poly(self.coef[i], t - self.starts[i])
        s = t - self.tau0
        return np.array([phi, dphi, self.u2 + self.du2 * s + 0.5 * self.accel * s * s,
                         self.du2 + self.accel * s])

    def __call__(self, t):
        if np.ndim(t) == 0:
            return self._one(float(t))
        t = np.asarray(t, dtype=float)
        return np.stack([self._one(float(v)) for v in t], axis=1) if t.size else \
            np.zeros((4, 0))
