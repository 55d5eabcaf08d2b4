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

__all__ = ["lift_off_margin", "painleve_edge", "lift_off_edges", "phi0_valid_range"]

_TAU = np.linspace(0.0, 2.0 * math.pi, 1025)


def lift_off_margin(params, frequency):
    """``max_tau D(tau) / u10`` on the contact manifold: negative where contact holds.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> lift_off_margin(PAPER_DEFAULTS, 185.0) < 0 < lift_off_margin(PAPER_DEFAULTS, 20000.0)
    True
    """
    from ...scenes.friction_drive import FrictionDrive

    sc = FrictionDrive(params, frequency)
    phi, dphi, _ = sc.contact_angle(_TAU)
    D = sc.coefficients(phi, dphi, _TAU)[3]
    i = int(np.argmax(D))
    best = float(D[i])
    if 0 < i < len(_TAU) - 1:
        from scipy.optimize import minimize_scalar

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
    from scipy.optimize import brentq

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
