"""Periodic steady states of periodically driven scenes.

A scene whose state is invariant under translation of one coordinate (the
rotor position of the friction drive) has a period map on the remaining
state; its fixed point is the periodic steady state, found by shooting.
"""

from dataclasses import dataclass, field

import numpy as np

__all__ = ["SteadyState"]


@dataclass
class SteadyState:
    """A periodic steady state, in the scene's dimensionless units.

    Attributes
    ----------
    scheme : str
        ``"event-driven"`` or ``"moreau-jean"``.
    displacement_per_period : float
        Net change of the translation-invariant coordinate over one period
        (dimensionless, ``u2 = x2 / l`` for the friction drive).
    state0 : ndarray
        The fixed point of the period map (state at ``tau = 0``).
    mode : str
        Canonical name of the cyclic regime sequence (e.g. ``"NP"``).
    regimes : list of (float, str)
        ``[tau_start, letter]`` of each regime over one period, tau in [0, 2 pi).
    min_normal_force : float
        Smallest dimensionless normal force over the period.
    periodic_residual : float
        ``|P(x*) - x*|`` of the period map at the returned fixed point.
    iterations : int
        Shooting iterations.
    wall_time : float
        Seconds spent.
    stats : dict
        Scheme-specific counters (steps, LCP solves, fallbacks, ...).
    """

    scheme: str
    displacement_per_period: float
    state0: np.ndarray
    mode: str
    regimes: list
    min_normal_force: float
    periodic_residual: float
    iterations: int = 0
    wall_time: float = 0.0
    stats: dict = field(default_factory=dict)
