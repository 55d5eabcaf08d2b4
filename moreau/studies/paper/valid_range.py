"""Where the paper's contact model holds: the lift-off and Painlevé limits.

The paper keeps the rod in permanent contact by choosing ``phi0`` and ``mu``
at each drive frequency so that the free normal acceleration ``D`` stays
negative and the Painlevé condition ``1 - mu tan(phi) > 0`` holds all the time
(its section 4.1). On the contact manifold ``sin phi = sin phi0 - u1(tau)`` the
rod's motion is an explicit function of ``tau``, so both limits are explicit:

* lift-off: ``max_tau D(tau) = 0``. With ``D >= 0`` somewhere the slipping
  rod's normal force ``-D / (A -+ mu B)`` would have to be negative there, so
  the rod lifts off. ``D`` does not depend on ``mu``.
* Painlevé: ``1 - mu tan(phi0) = 0``, since ``phi`` is largest at the stator's
  lowest point, where ``phi = phi0``.
"""

import math

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from ...scenes.friction_drive import FrictionDrive

__all__ = ["lift_off_margin", "painleve_edge", "lift_off_edges", "phi0_valid_range", "range_marks"]

_TAU = np.linspace(0.0, 2.0 * math.pi, 1025)


def lift_off_margin(params, frequency):
    """``max_tau D(tau) / u10`` on the contact manifold: negative where contact holds.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> lift_off_margin(PAPER_DEFAULTS, 185.0) < 0 < lift_off_margin(PAPER_DEFAULTS, 20000.0)
    True
    """
    sc = FrictionDrive(params, frequency)
    phi, dphi, _ = sc.contact_angle(_TAU)
    D = sc.coefficients(phi, dphi, _TAU)[3]
    i = int(np.argmax(D))
    best = float(D[i])
    if 0 < i < len(_TAU) - 1:
        def negD(t):
            p, dp, _ = sc.contact_angle(t)
            return -float(sc.coefficients(p, dp, t)[3])

        r = minimize_scalar(negD, bounds=(_TAU[i - 1], _TAU[i + 1]), method="bounded",
                            options={"xatol": 1e-12})
        best = max(best, -float(r.fun))
    return best / sc.u10


def painleve_edge(mu):
    """Largest admissible ``phi0``: ``atan(1/mu)`` (``pi/2`` without friction)."""
    return math.pi / 2 if mu == 0 else math.atan(1.0 / mu)


def lift_off_edges(params, frequency, lo=None, hi=None, n=241):
    """Values of ``phi0`` in ``(lo, hi)`` where the lift-off margin changes sign.

    Returns a sorted list of ``(phi0, side)`` with ``side`` ``"enters"`` when
    contact holds above the edge and ``"leaves"`` when it holds below.
    """
    lo = math.asin(2.0 * params.x10 / params.length) + 1e-6 if lo is None else lo
    hi = math.pi / 2 - 1e-6 if hi is None else hi

    def g(p):
        return lift_off_margin(params.with_(phi0=p), frequency)

    grid = np.linspace(lo, hi, n)
    vals = np.array([g(p) for p in grid])
    edges = []
    for a, b, ga, gb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if ga * gb < 0:
            r = brentq(g, a, b, xtol=1e-10)
            edges.append((r, "enters" if ga > 0 else "leaves"))
    return edges


def phi0_valid_range(params, frequency):
    """The ``phi0`` interval of the paper's study at one frequency.

    From the first lift-off edge where contact sets in (``D < 0`` above it)
    to the Painlevé edge ``atan(1/mu)``. Lift-off edges inside that interval
    (contact lost again) are returned as well.

    Returns
    -------
    dict
        ``lift_off_edge``, ``painleve_edge`` (radians) and ``inner_edges``
        (list of ``phi0`` where contact is lost or regained inside).

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> r = phi0_valid_range(PAPER_DEFAULTS, 20.0)
    >>> round(r["lift_off_edge"], 4), round(r["painleve_edge"], 4)
    (0.6155, 1.4711)
    """
    top = painleve_edge(params.mu)
    edges = lift_off_edges(params, frequency, hi=min(top, math.pi / 2 - 1e-6))
    enters = [p for p, s in edges if s == "enters"]
    low = enters[0] if enters else math.asin(2.0 * params.x10 / params.length)
    inner = [p for p, _ in edges if p > low + 1e-9]
    return {"lift_off_edge": low, "painleve_edge": top, "inner_edges": inner}


def range_marks(params, parameter, frequency=None):
    """Limits of the contact model along one swept parameter, to mark on its figure.

    ``{"contact_loss_Hz": f}`` for a frequency sweep (where ``max D = 0``),
    ``{"painleve_edge": 1/tan(phi0)}`` for ``mu``, the valid range of
    :func:`phi0_valid_range` for ``phi0``, and ``{}`` for the other parameters.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> round(range_marks(PAPER_DEFAULTS, "mu", 185.0)["painleve_edge"], 6)
    1.0
    """
    if parameter == "frequency":
        # the frequency where the rod would lift off (max D = 0), if there is one
        f_hi = 1e3
        while lift_off_margin(params, f_hi) < 0 and f_hi < 1e7:
            f_hi *= 2
        if f_hi >= 1e7:
            return {}
        return {"contact_loss_Hz": brentq(lambda f: lift_off_margin(params, f), f_hi / 2, f_hi)}
    if parameter == "mu":
        return {"painleve_edge": 1.0 / math.tan(params.phi0)}
    if parameter == "phi0":
        return phi0_valid_range(params, frequency)
    return {}
