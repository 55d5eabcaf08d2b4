"""A steady state as a JSON-ready dict in SI units, for any periodically driven scene.

``moreau steady --scene NAME`` prints this; it needs the scene's SI
conversions (``displacement_to_si``, ``force_to_si``), its drive
``frequency`` [Hz] and ``period``, which every shipped periodic scene has.

Examples
--------
>>> from moreau.model.registry import make_scene
>>> rep = steady_state_report(make_scene("friction-drive", frequency=20.0))
>>> rep["scene"], rep["mode"], rep["displacement_per_period_m"] < 0
('friction-drive', 'NS', True)
"""

import math
import time

from ..errors import InputError, MoreauError
from ..provenance import provenance
from .energy import energy_audit, energy_to_si, has_energy_audit
from .floquet import floquet_report
from .engine import audit_options
from .scheme_settings import make_scheme, steady_of

__all__ = ["steady_state_report", "check_periodic", "statistical_report"]

#: steady-state statistics copied into the report of a Moreau–Jean steady state
MJ_STATS = ("message", "steps", "lcp_solves", "fallbacks", "max_penetration", "period_map_slope",
            "period_map_eigenvalues")


def check_periodic(scene):
    """Refuse a scene without a periodic drive (no steady state to find)."""
    name = getattr(scene, "name", type(scene).__name__)
    if getattr(scene, "period", None) is None:
        raise InputError(f"scene {name!r} has no periodic drive (`period` is None): a periodic "
                         "steady state applies to periodically driven scenes only")
    for attr in ("frequency", "displacement_to_si", "force_to_si"):
        if not hasattr(scene, attr):
            raise InputError(f"scene {name!r} has no `{attr}`: the SI report needs it")
    return scene


def statistical_report(scene, ss):
    """The JSON fields that say whether a steady state is periodic or statistical.

    ``steady_state`` is ``"periodic"`` or ``"statistical"``; a statistical
    one (:mod:`moreau.analysis.statistical`) adds ``confidence_interval_m``
    (``[low, high]`` of the mean displacement per period, m),
    ``confidence_level``, ``periods_used`` (periods averaged),
    ``transient_periods`` (detected and dropped), ``periods_simulated``,
    ``statistical_status``, ``statistical_method``, ``statistical_precision``,
    ``statistical_options`` (the scheme's options of the run),
    ``why_not_periodic``, ``start`` (where the averaging started: ``how``,
    ``description``, the state ``q_si``, ``v_si`` with ``q_units``,
    ``v_units``, and ``q``, ``v`` in the scene's units, to start the API
    from), ``starts`` (each start's ``start``, ``status``, ``mean_m``,
    ``confidence_interval_m``, ``attractor``, ``cpu_time_s``) and
    ``attractors`` (the starts grouped by overlapping intervals:
    ``mean_m``, ``confidence_interval_m``, ``starts``, ``members``).
    """
    if not getattr(ss, "statistical", False):
        return {"steady_state": "periodic"}
    si = scene.displacement_to_si
    lo, hi = ss.confidence_interval
    st = ss.stats or {}
    starts = []
    for rec in st.get("starts", []):
        row = {k: v for k, v in rec.items()
               if k not in ("mean", "confidence_interval", "half_width")}
        if "mean" in rec:
            row["mean_m"] = float(si(rec["mean"]))
            row["confidence_interval_m"] = [float(si(x)) for x in rec["confidence_interval"]]
        starts.append(row)
    return {"steady_state": "statistical",
            "confidence_interval_m": [float(si(lo)), float(si(hi))],
            "confidence_level": ss.confidence, "periods_used": int(ss.periods_used),
            "transient_periods": st.get("transient_periods"),
            "periods_simulated": st.get("periods_simulated"),
            "statistical_status": st.get("status"), "statistical_method": st.get("method"),
            "statistical_precision": st.get("precision"),
            "statistical_options": st.get("options"),
            "why_not_periodic": st.get("why_not_periodic"),
            "start": ss.start, "starts": starts,
            "attractors": [{"mean_m": float(si(a["mean"])),
                            "confidence_interval_m": [float(si(x))
                                                      for x in a["confidence_interval"]],
                            "starts": a["starts"], "members": list(a["members"])}
                           for a in (ss.attractors or [])]}


def _energy_of(scene, ss, settings):
    """``(energy dict in J per period, None)``, or ``(None, why there is none)``."""
    if not has_energy_audit(scene, settings.name):
        return None, (f"no energy audit for scheme {settings.name!r} on scene "
                      f"{getattr(scene, 'name', type(scene).__name__)!r}")
    try:
        audit = energy_audit(scene, ss, settings.name, audit_options(settings))
    except MoreauError as exc:
        return None, f"no energy audit: {exc}"
    return energy_to_si(scene, audit), None


def steady_state_report(scene, scheme="event-driven", steps_per_period=None, theta=None,
                        rtol=None, parameters=None, options=None, max_period=1,
                        statistical_options=None):
    """Steady state of ``scene`` as a JSON-ready dict in SI units.

    Parameters
    ----------
    scene : Scene
        A periodically driven scene (:func:`check_periodic`).
    scheme : str
        Any registered scheme (:func:`moreau.analysis.scheme_settings.make_scheme`).
    steps_per_period, theta : optional
        Time-stepping schemes' steps per period (default 1000); ``theta`` for
        the schemes that take one (Moreau–Jean, default 1).
    rtol : float, optional
        The shooting tolerance (event-driven default 1e-10; Moreau–Jean its own).
    options : dict, optional
        The scheme's other options (a compliant contact's ``stiffness``).
    parameters : dict, optional
        The SI parameters to record (default: the scene's ``params`` fields).
    max_period : int
        Look for orbits of up to this many drive periods where period 1
        fails or is unstable (:func:`moreau.analysis.steady_state.find_steady_state`).
    statistical_options : dict, optional
        For the statistical steady state where no orbit is found:
        ``max_periods``, ``precision``, ``starts``, ``spread``, ``progress``
        (:func:`moreau.analysis.statistical.statistical_steady_state`).

    Returns
    -------
    dict
        ``scene``, ``frequency_Hz``, ``scheme``, ``mode``,
        ``displacement_per_period_m``, ``average_velocity_m_per_s``,
        ``regimes``, ``min_normal_force_N``, ``periodic``, ``periodic_residual``,
        ``shooting_iterations``, ``period`` (drive periods of the orbit),
        ``floquet_multipliers`` (``[re, im]`` pairs, largest modulus first),
        ``max_multiplier``, ``stable``, ``stability_margin`` (``1 - max
        |lambda|``) and ``floquet_method`` (:mod:`moreau.analysis.floquet`;
        None where there is no periodic orbit), ``steady_state``
        (``"periodic"`` or ``"statistical"``, :func:`statistical_report`:
        a statistical one's ``displacement_per_period_m`` is the long-run
        mean, with ``confidence_interval_m`` and ``periods_used``), ``wall_time_s``,
        ``parameters``, ``provenance``
        (:func:`moreau.provenance.provenance`), ``energy`` (the energy audit of
        the steady period, :mod:`moreau.analysis.energy`: joules per period
        and ``closing_error``; None with an ``energy_note`` where the scheme
        has no audit), ``derived`` where the scene gives ``derived_quantities()``
        (SI quantities it computes from its parameters); with
        Moreau–Jean also ``steps_per_period``, ``theta`` and the scheme's
        statistics.
    """
    check_periodic(scene)
    settings = make_scheme(scheme, theta, steps_per_period, rtol, options)
    t0 = time.perf_counter()
    ss = steady_of(scene, settings, max_period=max_period, statistical=True,
                   statistical_options=statistical_options)
    wall = time.perf_counter() - t0
    disp = float(scene.displacement_to_si(ss.displacement_per_period))
    if parameters is None:
        params = getattr(scene, "params", None)
        parameters = ({k: getattr(params, k) for k in params.__dataclass_fields__}
                      if params is not None and hasattr(params, "__dataclass_fields__") else {})
    out = {
        "scene": getattr(scene, "name", type(scene).__name__),
        "frequency_Hz": float(scene.frequency),
        "scheme": ss.scheme,
        "mode": ss.mode,
        "displacement_per_period_m": disp,
        "average_velocity_m_per_s": disp * float(scene.frequency),
        "regimes": [[float(t), r] for t, r in ss.regimes],
        # None, not NaN, where no period-1 orbit exists: JSON has no NaN
        "min_normal_force_N": (float(scene.force_to_si(ss.min_normal_force))
                               if math.isfinite(ss.min_normal_force) else None),
        "periodic": bool(ss.stats.get("periodic", True)) if ss.stats else True,
        # None where there is no orbit to close (a statistical steady state)
        "periodic_residual": (ss.periodic_residual if math.isfinite(ss.periodic_residual)
                              else None),
        "shooting_iterations": ss.iterations,
        "period": int(getattr(ss, "period", 1)),
        **floquet_report(ss),
        **statistical_report(scene, ss),
        "wall_time_s": wall,
        "parameters": dict(parameters),
        "provenance": provenance(),
    }
    derived = getattr(scene, "derived_quantities", None)
    if derived is not None:
        # what a scene computes from its parameters (a flexible rod's bending frequencies)
        out["derived"] = derived()
    if settings.steps_per_period is not None:
        out["steps_per_period"] = settings.steps_per_period
    if settings.theta is not None:
        out["theta"] = settings.theta
    if settings.options:
        out["options"] = settings.options
    if getattr(ss, "statistical", False):
        out["energy"], note = None, "no energy audit: a statistical steady state has no period"
    else:
        out["energy"], note = _energy_of(scene, ss, settings)
    if note:
        out["energy_note"] = note
    if scheme == "moreau-jean":
        for key in MJ_STATS:
            if ss.stats and key in ss.stats:
                val = ss.stats[key]
                out[key] = val if not hasattr(val, "tolist") else val.tolist()
    return out
