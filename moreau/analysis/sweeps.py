"""Parameter sweeps of the friction drive's periodic steady state.

A sweep evaluates the steady state at each value, records the operation mode,
the displacement per period and the smallest normal force, and writes a CSV
file and (with matplotlib installed) a figure. A point where the model is
ill-posed is recorded with its reason instead of a number; an interrupted
sweep keeps the points it had finished.
"""

import csv
import math
import os

import numpy as np

from .._validate import positive, positive_int
from ..errors import InputError, MoreauError

__all__ = ["sweep", "run_sweep", "SWEEP_DEFAULTS"]

#: parameter -> (start, stop, num, log)
SWEEP_DEFAULTS = {
    "frequency": (10.0, 12500.0, 250, True),
    "mu": (0.01, 0.99, 99, False),
    "phi0": (0.62, 1.46, 85, False),
}


def sweep(parameter, values, params=None, frequency=None, progress=False, rtol=1e-10):
    """Steady states of the friction drive over ``values`` of one parameter.

    Parameters
    ----------
    parameter : {"frequency", "mu", "phi0"}
    values : array_like
    params : FrictionDriveParams, optional
        The other parameters (paper defaults).
    frequency : float
        Drive frequency [Hz] for ``mu`` and ``phi0`` sweeps.
    progress : bool
        Show a progress bar.

    Returns
    -------
    list of dict
        One row per value: ``value``, ``mode``, ``displacement_per_period_m``,
        ``average_velocity_m_per_s``, ``min_normal_force_N``,
        ``periodic_residual``, ``error`` (empty when the point succeeded).

    Examples
    --------
    >>> rows = sweep("frequency", [20.0, 2000.0])
    >>> [r["mode"] for r in rows]
    ['NS', 'NP']
    """
    from ..scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive
    from .steady_state import find_steady_state

    if parameter not in SWEEP_DEFAULTS:
        raise InputError(f"`parameter` must be one of {sorted(SWEEP_DEFAULTS)}, got {parameter!r}")
    params = PAPER_DEFAULTS if params is None else params
    if parameter != "frequency":
        frequency = positive("frequency", frequency if frequency is not None else float("nan"))
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise InputError("`values` must be a non-empty 1-D array of finite numbers")
    it = values
    if progress:
        from tqdm.auto import tqdm
        it = tqdm(values, desc=f"sweep {parameter}", unit="pt")
    rows = []
    try:
        for x in it:
            row = {"value": float(x), "mode": "", "displacement_per_period_m": math.nan,
                   "average_velocity_m_per_s": math.nan, "min_normal_force_N": math.nan,
                   "periodic_residual": math.nan, "error": ""}
            try:
                if parameter == "frequency":
                    scene = FrictionDrive(params, float(x))
                else:
                    scene = FrictionDrive(params.with_(**{parameter: float(x)}), frequency)
                ss = find_steady_state(scene, rtol=rtol)
                d = scene.displacement_to_si(ss.displacement_per_period)
                row.update(mode=ss.mode, displacement_per_period_m=d,
                           average_velocity_m_per_s=d * scene.frequency,
                           min_normal_force_N=scene.force_to_si(ss.min_normal_force),
                           periodic_residual=ss.periodic_residual)
            except MoreauError as exc:
                row["error"] = f"{type(exc).__name__}: {exc}"
            rows.append(row)
    except KeyboardInterrupt:
        pass  # keep the finished points
    return rows


def write_csv(rows, path):
    """Write sweep rows to ``path`` as CSV."""
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()) if rows else ["value"])
        w.writeheader()
        w.writerows(rows)


def plot_sweep(rows, parameter, path, title=""):
    """Figure of displacement per period against the parameter, coloured by mode."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.array([r["value"] for r in rows])
    d = np.array([r["displacement_per_period_m"] for r in rows]) * 1e6
    modes = [r["mode"] or "error" for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(x, d, "k-", lw=1)
    for m in dict.fromkeys(modes):
        sel = np.array([mm == m for mm in modes])
        ax.plot(x[sel], np.where(np.isfinite(d[sel]), d[sel], 0.0), ".", ms=5, label=m)
    if parameter == "frequency":
        ax.set_xscale("log")
        ax.set_xlabel("drive frequency f [Hz]")
    else:
        ax.set_xlabel({"mu": "friction coefficient mu", "phi0": "initial tilt phi0 [rad]"}[parameter])
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.set_ylabel("displacement per period [um]")
    ax.set_title(title)
    ax.legend(title="mode", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run_sweep(parameter, params, frequency=None, start=None, stop=None, num=None, log=None,
              out="out", progress=True, plot=True):
    """The ``moreau sweep`` command: compute, write CSV and figure, print a summary."""
    d0, d1, dn, dlog = SWEEP_DEFAULTS[parameter]
    start = d0 if start is None else start
    stop = d1 if stop is None else stop
    num = positive_int("num", dn if num is None else num)
    log = dlog if log is None else log
    if parameter != "frequency" and frequency is None:
        raise InputError("`--frequency` is required for mu and phi0 sweeps")
    values = np.geomspace(start, stop, num) if log else np.linspace(start, stop, num)
    rows = sweep(parameter, values, params, frequency, progress=progress)
    os.makedirs(out, exist_ok=True)
    tag = parameter if parameter == "frequency" else f"{parameter}_{frequency:g}Hz"
    csv_path = os.path.join(out, f"sweep_{tag}.csv")
    write_csv(rows, csv_path)
    print(f"wrote {csv_path} ({len(rows)} points)")
    if plot:
        try:
            fig_path = os.path.join(out, f"sweep_{tag}.png")
            plot_sweep(rows, parameter, fig_path, title=f"friction drive: {tag}")
            print(f"wrote {fig_path}")
        except ImportError:
            print("matplotlib is not installed: no figure (pip install 'moreau[plot]')")
    prev = None
    for r in rows:
        label = r["mode"] or ("error: " + r["error"].split(":")[0])
        if label != prev:
            print(f"  from {r['value']:.6g}: {label}")
            prev = label
    return rows
