"""Time histories of the friction drive in SI units: CSV and figure output."""

import csv
import math
import os

import numpy as np

from ..._validate import positive, positive_int
from ...errors import InputError
from ...integrators import simulate
from ...regimes import REGIME_LETTERS, Regime
from ...scenes.friction_drive import FrictionDrive

__all__ = ["run_history", "write_history_csv", "plot_history"]

_COLUMNS = ["t", "x2", "v2", "phi", "normal_force", "tangential_force", "slip_velocity", "regime"]


#: bound on the samples of one time history (a CSV of about 2 GB)
MAX_SAMPLES = 10**7


def run_history(params, frequency, periods=10.0, scheme="event-driven", steps_per_period=2000,
                theta=1.0, samples_per_period=200, progress=False):
    """Simulate the friction drive from rest and return its SI time histories.

    Parameters
    ----------
    params : FrictionDriveParams
    frequency : float
        Drive frequency [Hz].
    periods : float
        Simulated drive periods, > 0.
    scheme : {"event-driven", "moreau-jean"}
    steps_per_period : int
        Moreau–Jean steps per period.
    samples_per_period : int
        Output samples per period (Moreau–Jean saves every
        ``steps_per_period // samples_per_period`` steps).

    Returns
    -------
    dict
        SI arrays (see :meth:`FrictionDrive.to_si`) plus ``status``,
        ``message``, ``events`` (event-driven) and ``stats``.

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> h = run_history(PAPER_DEFAULTS, 185.0, periods=1)
    >>> h["status"], round(float(h["t"][-1]) * 185.0, 12)
    (0, 1.0)
    """
    periods = positive("periods", periods)
    samples_per_period = positive_int("samples_per_period", samples_per_period)
    if periods * samples_per_period > MAX_SAMPLES:
        raise InputError(f"`periods` = {periods:g} at {samples_per_period} samples per period is "
                         f"{periods * samples_per_period:.2g} samples, more than the limit "
                         f"{MAX_SAMPLES:.0e} of one time history")
    scene = FrictionDrive(params, frequency)
    q0, v0 = scene.rest_state()
    span = (0.0, 2.0 * math.pi * periods)
    if scheme == "event-driven":
        res = simulate(scene, span, q0, v0, "event-driven", progress=progress,
                       samples_per_period=samples_per_period)
    elif scheme == "moreau-jean":
        steps_per_period = positive_int("steps_per_period", steps_per_period)
        res = simulate(scene, span, q0, v0, "moreau-jean", progress=progress,
                       h=2.0 * math.pi / steps_per_period, theta=theta,
                       save_every=max(1, steps_per_period // samples_per_period))
    else:
        raise InputError(f"`scheme` must be one of ['event-driven', 'moreau-jean'], got {scheme!r}")
    out = scene.to_si(res)
    out.update(status=res.status, message=res.message, events=res.events, stats=res.stats,
               scheme=res.scheme, frequency=scene.frequency)
    return out


def write_history_csv(hist, path):
    """Write the SI columns of a history to ``path``."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"{c}" for c in _COLUMNS])
        for row in zip(*(np.asarray(hist[c]) for c in _COLUMNS)):
            w.writerow([repr(float(x)) if i < len(_COLUMNS) - 1 else int(x) for i, x in enumerate(row)])


def plot_history(hist, path):
    """Rotor displacement, slip velocity and contact forces against time, coloured by regime."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.asarray(hist["t"]) * 1e3
    reg = np.asarray(hist["regime"])
    fig, ax = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    ax[0].plot(t, np.asarray(hist["x2"]) * 1e6, "k-", lw=1)
    ax[0].set_ylabel("rotor x2 [um]")
    ax[1].plot(t, np.asarray(hist["slip_velocity"]) * 1e3, "0.5", lw=0.8)
    for r in Regime:
        sel = reg == int(r)
        if sel.any():
            ax[1].plot(t[sel], np.asarray(hist["slip_velocity"])[sel] * 1e3, ".", ms=2,
                       label=REGIME_LETTERS[r])
    ax[1].axhline(0.0, color="0.7", lw=0.5)
    ax[1].set_ylabel("slip velocity [mm/s]")
    ax[1].legend(title="regime", fontsize=8, markerscale=4)
    ax[2].plot(t, hist["normal_force"], label="normal")
    ax[2].plot(t, hist["tangential_force"], label="tangential")
    ax[2].set_ylabel("contact force [N]")
    ax[2].set_xlabel("t [ms]")
    ax[2].legend(fontsize=8)
    ax[0].set_title(f"friction drive at {hist['frequency']:g} Hz ({hist['scheme']})")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def history_command(params, frequency, periods, scheme, steps_per_period, theta, out, plot,
                    progress):
    """The ``moreau run`` command: simulate from rest, write CSV (and figure)."""
    hist = run_history(params, frequency, periods, scheme, steps_per_period, theta,
                       progress=progress)
    os.makedirs(out, exist_ok=True)
    tag = f"history_{frequency:g}Hz_{scheme}"
    path = os.path.join(out, tag + ".csv")
    write_history_csv(hist, path)
    print(f"wrote {path} ({len(hist['t'])} samples); status {hist['status']}: {hist['message']}")
    if plot:
        try:
            fig = os.path.join(out, tag + ".png")
            plot_history(hist, fig)
            print(f"wrote {fig}")
        except ImportError:
            print("matplotlib is not installed: no figure (pip install 'moreau[plot]')")
    return hist
