"""The result object shared by every integration scheme.

Event-driven and time-stepping runs return the same :class:`SimulationResult`
so that their time histories plot and compare the same way.
"""

from dataclasses import dataclass, field

import numpy as np

from ..regimes import REGIME_LETTERS, Regime

__all__ = ["SimulationResult", "Event", "STATUS_MESSAGES", "SteadyState"]

#: status codes and their meaning (scipy.integrate style: 0 finished,
#: 1 a terminal event stopped the run, < 0 failure)
STATUS_MESSAGES = {
    0: "The run reached the end of the time interval.",
    1: "A terminal event occurred.",
    -1: "The contact problem became ill-posed (Painlevé condition violated).",
    -2: "Contact was lost where the method assumes permanent contact.",
    -3: "A contact problem (LCP) could not be solved.",
    -4: "The run was interrupted; the result holds what was finished.",
    -5: "A numerical failure occurred.",
    -6: "The state left the scene's valid region; the model does not apply beyond it.",
}


@dataclass
class Event:
    """One located regime change or impact.

    Attributes
    ----------
    t : float
        Dimensionless time of the event.
    kind : str
        ``"transition"``, ``"impact"``, ``"liftoff"`` or ``"painleve"``.
    before, after : Regime
        Regimes before and after the event.
    contact : int
        Index of the contact concerned.
    """

    t: float
    kind: str
    before: Regime
    after: Regime
    contact: int = 0

    def __repr__(self):
        return (f"Event(t={self.t:.12g}, {self.kind}, "
                f"{REGIME_LETTERS[self.before]}->{REGIME_LETTERS[self.after]})")


@dataclass
class SimulationResult:
    """Time history of a run, in the scene's dimensionless units.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Sample times.
    q, v : ndarray, shape (n, ndof)
        Generalized coordinates and velocities at the samples.
    regime : ndarray of int, shape (n, ncontacts)
        :class:`~moreau.regimes.Regime` code of each contact at each sample.
    force_N, force_T : ndarray, shape (n, ncontacts)
        Contact forces (time-stepping schemes report impulse / step).
    slip_velocity : ndarray, shape (n, ncontacts)
        Tangential relative velocity of each contact.
    gap : ndarray, shape (n, ncontacts)
        Normal gap of each contact.
    events : list of Event
        Located events (empty for schemes that do not locate events).
    status : int
        See :data:`STATUS_MESSAGES`.
    message : str
        Human-readable reason for termination.
    scheme : str
        Name of the integration scheme.
    stats : dict
        Counters: steps, LCP solves, pivots, fallbacks, residuals, penetration.
    t_events : list of ndarray
        For each user event function of :func:`~moreau.integrators.simulate`
        (``events=``), the times it occurred (empty without events).
    y_events : list of ndarray
        For each, the states ``(q, v)`` at those times, one row each.
    constraint_drift : float or None
        For a scene with joints, the largest ``|gE(q, t)|`` over the run's
        step ends (the joints' position-level drift, in the scene's units);
        None for a scene without joints.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    regime: np.ndarray
    force_N: np.ndarray
    force_T: np.ndarray
    slip_velocity: np.ndarray
    gap: np.ndarray
    events: list = field(default_factory=list)
    status: int = 0
    message: str = STATUS_MESSAGES[0]
    scheme: str = ""
    stats: dict = field(default_factory=dict)
    t_events: list = field(default_factory=list)
    y_events: list = field(default_factory=list)
    constraint_drift: float | None = None

    @property
    def success(self):
        """True when the run ended normally (status 0 or a terminal event)."""
        return self.status >= 0

    def regime_letters(self, contact=0):
        """Regime of one contact at each sample as a string of letters."""
        return "".join(REGIME_LETTERS[Regime(int(r))] for r in self.regime[:, contact])

    def to_dataframe(self, scene=None):
        """The time history as a :class:`pandas.DataFrame` (pandas is an optional extra).

        Parameters
        ----------
        scene : Scene, optional
            The scene that was run. A scene with SI units gives its SI columns
            (``Scene.si_columns``: ``t [s]``, ``q_1 [m]``, ``force_N_0 [N]``,
            ...); without it the columns are the scene's dimensionless ones,
            named without units. Regimes are given by name (``stick``,
            ``positive``, ``negative``, ``flight``).

        Returns
        -------
        pandas.DataFrame
            ``attrs`` holds ``scheme``, ``status``, ``message`` and ``units``
            (column -> unit).

        Examples
        --------
        >>> import numpy as np
        >>> from moreau.scenes import BouncingBall
        >>> from moreau.integrators import simulate
        >>> ball = BouncingBall()
        >>> res = simulate(ball, (0.0, 1.0), *ball.initial_state(), "moreau-jean", h=0.25)
        >>> df = res.to_dataframe(ball)
        >>> list(df.columns)[:3], df.attrs["units"]["t"]
        (['t', 'q_0', 'v_0'], 's')
        """
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - the message is the point
            raise ImportError("`to_dataframe` needs pandas: pip install -e \".[data]\"") from None
        if scene is not None and hasattr(scene, "si_columns"):
            cols = scene.si_columns(self)
        else:
            cols = [("t", "", self.t)]
            for name in ("q", "v"):
                arr = getattr(self, name)
                cols += [(f"{name}_{i}", "", arr[:, i]) for i in range(arr.shape[1])]
            for name in ("force_N", "force_T", "slip_velocity", "gap", "regime"):
                arr = getattr(self, name)
                cols += [(f"{name}_{i}", "", arr[:, i]) for i in range(arr.shape[1])]
        data, units = {}, {}
        for name, unit, col in cols:
            col = np.asarray(col)
            if name.startswith("regime"):
                col = np.array([Regime(int(r)).name.lower() for r in col], dtype=object)
            data[name] = col
            units[name] = unit
        df = pd.DataFrame(data)
        df.attrs.update(scheme=self.scheme, status=int(self.status), message=self.message,
                        units=units)
        return df


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
        The fixed point of the period map: ``(phi, phi', u2')`` at the
        Poincaré section ``tau = section_tau``.
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
    section_tau : float
        Phase of the Poincaré section at which ``state0`` is given.
    floquet_multipliers : ndarray of complex or None
        Eigenvalues of the period map's Jacobian at the fixed point,
        restricted to the free directions (cyclic coordinate and pinned
        contact directions removed), largest modulus first; None where
        they were not computed (no periodic orbit).
    floquet_method : str
        How they were computed: ``"saltation"`` (variational equations and
        saltation matrices of an event-driven walk) or
        ``"finite-differences"`` (of the period map).
    period : int
        Drive periods after which the orbit repeats (1 for a period-1 orbit;
        ``k`` for one found on the ``k``-th iterate of the period map).
        ``displacement_per_period`` is per drive period in either case.
    statistical : bool
        True for a statistical steady state (no periodic orbit:
        :mod:`moreau.analysis.statistical`): ``displacement_per_period`` is
        then the long-run mean after the transient, ``state0`` the state at
        the section after the last period simulated, and ``period`` 0.
    confidence_interval : tuple of float or None
        ``(low, high)`` of the long-run mean displacement per period at
        the level ``confidence`` (statistical steady states only).
    confidence : float or None
        The level of ``confidence_interval`` (0.95 by default).
    periods_used : int
        Drive periods whose displacements make the mean (after the
        transient, statistical steady states only).
    start : dict or None
        Where a statistical steady state's averaging run started: ``how``
        (``"rest"``, ``"given"``, ``"period-1-search"``, ...),
        ``description``, the state ``q``, ``v`` (the scene's units) and, where
        the scene converts to SI, ``q_si``, ``v_si`` with their units
        (:func:`moreau.analysis.statistical.statistical_steady_state`).
    attractors : list of dict or None
        A statistical steady state's starts grouped by overlapping
        intervals: each ``mean``, ``confidence_interval``, ``half_width``,
        ``starts`` (how many) and ``members`` (their indices).
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
    section_tau: float = 0.0
    floquet_multipliers: np.ndarray = None
    floquet_method: str = ""
    period: int = 1
    statistical: bool = False
    confidence_interval: tuple = None
    confidence: float = None
    periods_used: int = 0
    start: dict = None
    attractors: list = None

    @property
    def max_multiplier(self):
        """Largest modulus of the Floquet multipliers (None if they were not computed)."""
        m = self.floquet_multipliers
        if m is None:
            return None
        return float(np.max(np.abs(m))) if len(m) else 0.0

    @property
    def stable(self):
        """Whether every Floquet multiplier lies inside the unit circle (None if unknown)."""
        top = self.max_multiplier
        return None if top is None else bool(top < 1.0)

    @property
    def stability_margin(self):
        """``1 - max |lambda|``: distance of the largest multiplier from the unit circle."""
        top = self.max_multiplier
        return None if top is None else 1.0 - top
