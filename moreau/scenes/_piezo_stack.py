"""The piezo stack of :mod:`moreau.scenes.piezo_drive`: voltage waveforms, saturation, Bouc–Wen loop.

Everything here is dimensionless and compiled, so that the scene's Python
methods and its compiled model evaluate the same closed forms.

Voltage
-------
``U(tau) = U_pp (1 - c(tau)) / 2`` with a unit waveform ``c`` (even, period
``2 pi``, ``c(0) = 1``, ``c(pi) = -1``, decreasing on ``[0, pi]``), so the
voltage rises from 0 to ``U_pp`` on ``[0, pi]`` and falls back on ``[pi, 2 pi]``:

=========  ==========================================  =====================
kind       ``c(tau)``                                   ``p`` (smoothing s)
=========  ==========================================  =====================
0 sine     ``cos tau``                                  unused
1 triangle ``asin(r cos tau) / asin(r)``, ``r = 1 - s`` the corners' rounding
2 square   ``tanh(k cos tau) / tanh(k)``, ``k = 1 / s`` the edges' duration
=========  ==========================================  =====================

Saturation
----------
The stack sees ``v = sigma tanh(y / sigma)`` with ``y = U / U_pp`` and
``sigma = U_sat / U_pp`` (``sigma = 0`` encodes no saturation, ``v = y``):
linear at low voltage, bounded by ``sigma`` at high voltage.

Bouc–Wen hysteresis (exponent 1)
--------------------------------
With ``eta = h / (d U_pp)`` and ``b = beta U_pp``, ``g = gamma U_pp``::

    deta = alpha dv - b |dv| eta - g dv |eta|

On a monotone piece of the input (``s = sgn dv``) with ``eta`` of one sign
(``sigma_h = sgn eta``) this is linear in ``eta``:
``deta/dv = alpha - a eta`` with ``a = s b + g sigma_h``, so

    eta(v0 + D) = eta0 exp(-a D) + alpha (1 - exp(-a D)) / a

and ``eta`` crosses zero (only towards the sign of ``s``) after
``D_z = log(1 - a eta0 / alpha) / a``; beyond it ``a = s (b + g)``.
The derivatives follow from the ODE: ``deta/dv = alpha - a eta``,
``d2eta/dv2 = -a deta/dv``.
"""

import math

from numba import njit

from ..errors import MoreauError

__all__ = ["waveform", "saturate", "bouc_wen_step", "bouc_wen_branch", "steady_loop_ends",
           "loop_pass", "periodic_pass",
           "loop_top", "WAVEFORMS"]

TWO_PI = 2.0 * math.pi

#: waveform names and their codes in the compiled parameter vector
WAVEFORMS = {"sine": 0, "triangle": 1, "square": 2}

# below this |a D| the exponential's series is used (its error a^2 D^2 / 6 relative)
_SERIES = 1e-8


@njit(cache=True)
def waveform(kind, s, tau):
    """``(c, c', c'')`` of the unit waveform ``kind`` (0 sine, 1 triangle, 2 square), smoothing ``s``."""
    ct = math.cos(tau)
    st = math.sin(tau)
    if kind == 0:
        return ct, -st, -ct
    if kind == 1:
        r = 1.0 - s
        A = math.asin(r)
        y, dy, ddy = r * ct, -r * st, -r * ct
        q = 1.0 - y * y
        sq = math.sqrt(q)
        return math.asin(y) / A, dy / (sq * A), (ddy / sq + dy * dy * y / (q * sq)) / A
    k = 1.0 / s
    T = math.tanh(k)
    y, dy, ddy = k * ct, -k * st, -k * ct
    th = math.tanh(y)
    se2 = 1.0 - th * th
    return th / T, se2 * dy / T, (se2 * ddy - 2.0 * th * se2 * dy * dy) / T


@njit(cache=True)
def saturate(sigma, y, dy, ddy):
    """``(v, v', v'')`` of ``v = sigma tanh(y / sigma)`` (``sigma = 0``: ``v = y``)."""
    if sigma == 0.0:
        return y, dy, ddy
    th = math.tanh(y / sigma)
    se2 = 1.0 - th * th
    return sigma * th, se2 * dy, se2 * ddy - 2.0 * th * se2 * dy * dy / sigma


@njit(cache=True)
def _expo(a, D):
    # (exp(-a D), (1 - exp(-a D)) / a), the second finite as a -> 0
    x = a * D
    if abs(x) < _SERIES:
        return 1.0 - x, D * (1.0 - 0.5 * x)
    e = math.exp(-x)
    return e, -math.expm1(-x) / a


@njit(cache=True)
def bouc_wen_step(eta0, D, alpha, b, g):
    """``(eta, a)``: Bouc–Wen state after a monotone input change ``D`` from ``eta0``.

    ``a`` is the coefficient of the piece the step ends on (``deta/dv =
    alpha - a eta`` there). A zero crossing inside the step is located in
    closed form and the step continued with the other sign's coefficient.
    """
    if D == 0.0:
        s = 1.0
    else:
        s = 1.0 if D > 0.0 else -1.0
    if eta0 > 0.0:
        sig = 1.0
    elif eta0 < 0.0:
        sig = -1.0
    else:
        sig = s
    a = s * b + g * sig
    if sig == -s and alpha > 0.0:
        x = a * eta0 / alpha
        if abs(a) * abs(eta0) < _SERIES * alpha:
            Dz = -eta0 / alpha
        else:
            Dz = math.log1p(-x) / a
        if abs(Dz) < abs(D):
            D -= Dz
            eta0 = 0.0
            a = s * (b + g)
    e, E = _expo(a, D)
    return eta0 * e + alpha * E, a


@njit(cache=True)
def bouc_wen_branch(eta0, D, alpha, b, g):
    """``(eta, deta/dv, d2eta/dv2)`` at the end of a monotone step (see :func:`bouc_wen_step`)."""
    eta, a = bouc_wen_step(eta0, D, alpha, b, g)
    d1 = alpha - a * eta
    return eta, d1, -a * d1


@njit(cache=True)
def _loop_map(eta_lo, vmax, alpha, b, g):
    eta_hi = bouc_wen_step(eta_lo, vmax, alpha, b, g)[0]
    return bouc_wen_step(eta_hi, -vmax, alpha, b, g)[0]


def steady_loop_ends(vmax, alpha, b, g):
    """``(eta_lo, eta_hi)``: the periodic Bouc–Wen loop between inputs ``0`` and ``vmax``.

    The fixed point of the loop map ``eta_lo -> fall(rise(eta_lo))``, which is
    increasing and piecewise affine; secant steps from plain iterates find it
    to rounding.

    Examples
    --------
    >>> lo, hi = steady_loop_ends(1.0, 0.3, 2.0, 0.5)
    >>> abs(_loop_map(lo, 1.0, 0.3, 2.0, 0.5) - lo) < 1e-15, lo < 0.0 < hi
    (True, True)
    """
    x0 = 0.0
    x1 = _loop_map(x0, vmax, alpha, b, g)
    for _ in range(200):
        f0 = _loop_map(x0, vmax, alpha, b, g) - x0
        f1 = _loop_map(x1, vmax, alpha, b, g) - x1
        if abs(f1) <= 1e-15 * max(1.0, abs(x1)):
            return x1, bouc_wen_step(x1, vmax, alpha, b, g)[0]
        if f1 == f0:
            x0, x1 = x1, _loop_map(x1, vmax, alpha, b, g)
        else:
            x0, x1 = x1, x1 - f1 * (x1 - x0) / (f1 - f0)
        if not math.isfinite(x1):
            break
    raise MoreauError(f"the Bouc-Wen loop (alpha={alpha!r}, beta U_pp={b!r}, gamma U_pp={g!r}) "
                      f"did not close: no periodic loop found")


@njit(cache=True)
def loop_top(sigma):
    """The largest stack input ``v`` over a period (at ``tau = pi``, where ``y = 1``)."""
    if sigma == 0.0:
        return 1.0
    return sigma * math.tanh(1.0 / sigma)


@njit(cache=True)
def loop_pass(v, eta0, alpha, b, g, out):
    """Bouc–Wen states along the input samples ``v`` from ``eta0`` at ``v[0]``, into ``out``.

    Exact for any input that is monotone between consecutive samples (the
    model is rate-independent); returns the state at the last sample.
    """
    eta = eta0
    out[0] = eta
    for k in range(1, v.shape[0]):
        eta = bouc_wen_step(eta, v[k] - v[k - 1], alpha, b, g)[0]
        out[k] = eta
    return eta


def periodic_pass(v, alpha, b, g, out):
    """:func:`loop_pass` from the state that one closed loop returns to.

    ``v`` holds one period's samples without repeating the first: the loop
    closes with the step from ``v[-1]`` back to ``v[0]``. The pass map is
    increasing and piecewise affine in its start, so secant steps find its
    fixed point to rounding.
    """
    def cycle(x):
        end = loop_pass(v, x, alpha, b, g, out)
        return bouc_wen_step(end, v[0] - v[-1], alpha, b, g)[0]

    x0 = 0.0
    x1 = cycle(x0)
    for _ in range(200):
        f0 = cycle(x0) - x0
        f1 = cycle(x1) - x1
        if abs(f1) <= 1e-15 * max(1.0, abs(x1)) or not math.isfinite(f1):
            break
        x0, x1 = (x1, x1 - f1 * (x1 - x0) / (f1 - f0)) if f1 != f0 else (x1, x1 + f1)
    loop_pass(v, x1, alpha, b, g, out)
    return out
