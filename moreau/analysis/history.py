"""Time histories of any scene under any registered scheme: CSV, JSON sidecar and figure.

The engine of ``moreau run``. A scene with SI units gives its histories in SI
(``Scene.si_columns``), the same columns for every scene (the keys of
``to_si``, :data:`moreau.model.units.COMMON_KEYS`, one column per
coordinate and per contact), with the unit in each column name (``t [s]``,
``q_1 [m]``, ``force_N_0 [N]``); the regime of each contact is written by
name (``stick``, ``positive``, ``negative``, ``flight``). A JSON sidecar
records the scene, its parameters, what each coordinate is where the scene
names them (``coordinates``: the friction drive's ``q_0`` is ``phi`` and
``q_1`` is ``x2``), the scheme and its options, the run's status and the
provenance (:mod:`moreau.provenance`).

Examples
--------
>>> from moreau.scenes import make_scene
>>> res, cols = run_history(make_scene("bouncing-ball"), duration=0.5, scheme="moreau-jean",
...                         steps=500)
>>> res.success, [c[0] for c in cols][:3], cols[0][1]
(True, ['t', 'q_0', 'v_0'], 's')
"""

import csv
import json
import math
import os

import numpy as np

from .._validate import positive, positive_int
from ..errors import InputError
from ..integrators.base import get_integrator, scheme_options, simulate
from ..provenance import provenance
from ..regimes import Regime

__all__ = ["run_history", "history_tag", "write_history", "plot_history", "default_scheme",
           "default_run", "MAX_SAMPLES"]

#: bound on the samples of one time history (a CSV of about 2 GB)
MAX_SAMPLES = 10**7
#: bound on the steps of one time-stepping run (about 100 s of the compiled loop)
MAX_STEPS = 10**9


def _resolved(scheme, scene):
    cls = get_integrator(scheme)
    return cls.resolve(scene) if hasattr(cls, "resolve") else cls


def default_scheme(scene):
    """The scheme ``moreau run`` takes for ``scene`` when none is named.

    The scene's :attr:`~moreau.model.scene.Scene.run_default` where it names
    one (:func:`default_run`); else the event-driven reference (the scene's own
    where it has one) where it accepts the scene, else Moreau–Jean, which steps
    every scene: the generic event-driven scheme refuses spatial bodies
    (quaternions, the spatial friction cone) by name.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> default_scheme(make_scene("bouncing-ball")), default_scheme(make_scene("billiard-backspin"))
    ('event-driven', 'moreau-jean')
    """
    return default_run(scene)[0]


def default_run(scene):
    """The scheme and options ``moreau run`` takes for ``scene`` when no scheme is named.

    The scene's own :attr:`~moreau.model.scene.Scene.run_default` where it
    names one (a pile of disks: Moreau–Jean with NSGS), else
    :func:`default_scheme`'s rule with the scheme's default options.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> default_run(make_scene("bouncing-ball")), default_run(make_scene("silo"))
    (('event-driven', {}), ('moreau-jean', {'lcp_method': 'nsgs'}))
    """
    own = scene.run_default
    if own is not None:
        return own[0], dict(own[1])
    if _resolved("event-driven", scene).refusal(scene) is None:
        return "event-driven", {}
    return "moreau-jean", {}


def run_history(scene, *, periods=None, duration=None, scheme="event-driven", steps=None,
                samples=2000, progress=False, **options):
    """Simulate ``scene`` from its initial state; return the result and its columns.

    Parameters
    ----------
    scene : Scene
    periods : float, optional
        Drive periods to simulate (a scene with a periodic drive, ``scene.period``).
    duration : float, optional
        Time to simulate instead: seconds for a scene with SI units
        (``scene.time_unit_s``), else the scene's own time unit.
    scheme : str
        Any registered scheme (:data:`moreau.integrators.INTEGRATORS`).
    steps : int, optional
        Steps of a time-stepping scheme over the whole run (sets ``h``);
        alternatively give ``h`` in ``options``, in the scene's time unit.
    samples : int
        Samples kept: exactly this many, evenly spaced from the start to the
        end of the run (fewer where the run stops early), at least 2. An
        event-driven scheme samples its exact motion there, a time-stepping
        scheme interpolates between its step ends
        (:func:`~moreau.integrators.simulate`'s ``t_eval``).
    **options
        The scheme's own options; one it does not take is refused before any
        work, naming it and the scheme.

    Returns
    -------
    result : SimulationResult
    columns : list of (name, unit, array)
        From ``scene.si_columns(result)``.
    """
    if (periods is None) == (duration is None):
        raise InputError("give one of `periods` (drive periods) and `duration` (time)")
    if periods is not None:
        period = getattr(scene, "period", None)
        if period is None:
            raise InputError(f"`periods` needs a scene with a periodic drive; "
                             f"{type(scene).__name__} has none: give `duration`")
        periods = positive("periods", periods)
        if periods > MAX_SAMPLES:
            # every period keeps at least one sample
            raise InputError(f"`periods` = {periods:g} is more than the limit {MAX_SAMPLES:.0e} "
                             "of one time history")
        span = periods * period
    else:
        unit = scene.time_unit_s
        span = positive("duration", duration) / (unit if unit else 1.0)
    samples = positive_int("samples", samples)
    if samples < 2:
        raise InputError(f"`samples` must be >= 2 (the start and the end of the run), got "
                         f"{samples}")
    if samples > MAX_SAMPLES:
        raise InputError(f"`samples` = {samples:.3g} is more than the limit {MAX_SAMPLES:.0e} "
                         "of one time history")
    cls = _resolved(scheme, scene)
    accepted = scheme_options(cls) or ()
    stepping = "h" in accepted
    if stepping:
        if steps is not None and "h" in options:
            raise InputError("give one of `steps` and `h`")
        if steps is not None:
            steps = positive_int("steps", steps)
            options["h"] = span / steps
        elif "h" not in options:
            raise InputError(f"scheme {scheme!r} steps in time: give `steps` or `h`")
        nsteps = math.ceil(span / positive("h", options["h"]) - 1e-9)
        if nsteps > MAX_STEPS:
            raise InputError(f"{nsteps:.3g} steps is more than the limit {MAX_STEPS:.0e} of one "
                             "run; take fewer `steps` or a shorter run")
        options.setdefault("save_every", max(1, nsteps // samples))
    else:
        if steps is not None:
            raise InputError(f"`steps` applies to time-stepping schemes; {scheme!r} locates "
                             "its events (set its tolerance with `rtol`)")
        if "sample_dt" in accepted:
            options.setdefault("sample_dt", span / samples)
        elif "samples_per_period" in accepted and periods is not None:
            options.setdefault("samples_per_period", max(1, int(round(samples / periods))))
    q0, v0 = scene.initial_state()
    t_eval = np.linspace(0.0, span, samples)
    res = simulate(scene, (0.0, span), q0, v0, scheme, progress=progress, t_eval=t_eval,
                   **options)
    return res, scene.si_columns(res)


def history_tag(scene_name, params, scheme, options):
    """File name stem of a history: the scene, its non-default parameters, the scheme and its settings.

    Examples
    --------
    >>> history_tag("friction-drive", {"frequency": 185.0}, "moreau-jean", {"steps": 2000})
    'history_friction-drive_frequency185_moreau-jean_steps2000'
    """
    parts = [f"history_{scene_name}"]
    parts += [f"{k}{v:g}" if isinstance(v, float) else f"{k}{v}" for k, v in sorted(params.items())]
    parts.append(scheme)
    parts += [f"{k}{v:g}" if isinstance(v, float) else f"{k}{v}" for k, v in sorted(options.items())]
    return "_".join(parts).replace("/", "-")


def _header(name, unit):
    return f"{name} [{unit}]" if unit else name


def write_history(columns, path, meta):
    """Write ``columns`` to the CSV ``path`` and ``meta`` (plus the columns' units) beside it as JSON.

    Regime columns are written by name. Returns the sidecar's path.
    """
    names = [n for n, _, _ in columns]
    if len(names) != len(set(names)):
        raise InputError(f"the scene gives two columns of one name: {names}")
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([_header(n, u) for n, u, _ in columns])
        cols = []
        for name, _, arr in columns:
            if name.split("_")[0] == "regime":
                cols.append([Regime(int(c)).name.lower() for c in arr])
            else:
                cols.append([repr(float(x)) for x in arr])
        for row in zip(*cols):
            w.writerow(row)
    side = os.path.splitext(path)[0] + ".json"
    meta = dict(meta, columns=[{"name": n, "unit": u} for n, u, _ in columns],
                samples=int(len(columns[0][2])) if columns else 0, provenance=provenance())
    with open(side, "w") as fh:
        json.dump(meta, fh, indent=1, default=float)
    return side


def plot_history(columns, path, title=""):
    """Coordinates, normal forces and regimes against time, one panel each."""
    import matplotlib  # noqa: PLC0415  (optional at import: figures only)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    by = {n: (u, np.asarray(a)) for n, u, a in columns}
    tu, t = by["t"]
    coords = [n for n in by if n not in ("t",) and not n.startswith(
        ("v", "force", "slip", "gap", "regime"))]
    forces = [n for n in by if n.startswith("force_N")]
    regimes = [n for n in by if n.startswith("regime")]
    fig, ax = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for n in coords:
        ax[0].plot(t, by[n][1], lw=1, label=_header(n, by[n][0]))
    ax[0].legend(fontsize=8)
    ax[0].set_ylabel("coordinates")
    for n in forces:
        ax[1].plot(t, by[n][1], lw=1, label=_header(n, by[n][0]))
    if forces:
        ax[1].legend(fontsize=8)
    ax[1].set_ylabel("normal force")
    for k, n in enumerate(regimes):
        ax[2].step(t, by[n][1] + 0.08 * k, where="post", lw=1, label=n)
    ax[2].set_yticks([int(r) for r in Regime], [r.name.lower() for r in Regime])
    ax[2].set_xlabel(_header("t", tu))
    if regimes:
        ax[2].legend(fontsize=8)
    ax[0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
