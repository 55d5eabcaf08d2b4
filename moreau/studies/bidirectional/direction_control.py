"""Direction control of the bidirectional drive: steady states over a balance or phase sweep.

Two knobs steer the two-rod drive (:class:`~moreau.scenes.BidirectionalDrive`):

``balance``  beta in [-1, 1]
    Stator amplitudes ``x10_a = x10 min(1, 1 - beta)`` and
    ``x10_b = x10 min(1, 1 + beta)``: ``beta = -1`` excites rod ``a`` alone,
    ``0`` both equally, ``+1`` rod ``b`` alone. By mirror symmetry the net
    velocity is an odd function of ``beta``.
``phase``  delta [rad]
    Both rods at the full amplitude ``x10``, stator ``b`` lagging by ``delta``.

Each point is the periodic steady state found by
:func:`moreau.analysis.periodic_shooting.shoot_periodic` with the chosen
scheme (the generic event-driven reference by default).
"""

import argparse
import csv
import math
import pathlib

import numpy as np

from ..._validate import positive
from ...analysis.periodic_shooting import shoot_periodic
from ...errors import InputError, MoreauError
from ...scenes.bidirectional_drive import BidirectionalDrive, BidirectionalDriveParams

__all__ = ["direction_sweep", "direction_figure", "bidirectional_params"]


def bidirectional_params(knob, value, base=None):
    """:class:`BidirectionalDriveParams` for one sweep point (see the module docstring)."""
    base = base or BidirectionalDriveParams()
    x10 = max(base.x10_a, base.x10_b)
    if knob == "balance":
        if not -1.0 <= value <= 1.0:
            raise InputError(f"`balance` values must be in [-1, 1], got {value!r}")
        return base.with_(x10_a=x10 * min(1.0, 1.0 - value), x10_b=x10 * min(1.0, 1.0 + value))
    if knob == "phase":
        return base.with_(x10_a=x10, x10_b=x10, phase=float(value))
    raise InputError(f"`knob` must be 'balance' or 'phase', got {knob!r}")


def direction_sweep(knob, values, frequency=185.0, base=None, scheme="event-driven",
                    progress=False):
    """Steady states of the bidirectional drive along one control knob.

    Parameters
    ----------
    knob : {"balance", "phase"}
    values : sequence of float
    frequency : float
        Drive frequency [Hz].
    base : BidirectionalDriveParams, optional
        The other parameters (paper's values by default); ``x10`` is the
        larger of its two amplitudes.
    scheme : str
        Scheme of the period map.
    progress : bool
        tqdm progress bar.

    Returns
    -------
    list of dict
        One row per value: ``value``, ``x10_a``, ``x10_b``, ``phase``,
        ``displacement_per_period_m``, ``velocity_m_per_s``, ``mode``,
        ``status`` (``"ok"`` or the error message; the numbers are then None).

    Examples
    --------
    >>> p = bidirectional_params("balance", 0.5)      # rod b at full, rod a at half amplitude
    >>> p.x10_a, p.x10_b
    (1e-06, 2e-06)
    >>> rows = direction_sweep("balance", [-1.0], frequency=2000.0)   # doctest: +SKIP
    >>> rows[0]["mode"]                                                # doctest: +SKIP
    'NP|F'
    """
    frequency = positive("frequency", frequency)
    vals = [float(v) for v in values]
    pts = [bidirectional_params(knob, v, base) for v in vals]   # validate before any work
    it = zip(vals, pts)
    if progress:
        from tqdm.auto import tqdm
        it = tqdm(list(it), desc=f"{knob} sweep", leave=False, disable=None)  # terminals only
    rows = []
    for v, p in it:
        sc = BidirectionalDrive(p, frequency=frequency)
        row = {"value": v, "x10_a": p.x10_a, "x10_b": p.x10_b, "phase": p.phase}
        try:
            ss = shoot_periodic(sc, scheme)
        except MoreauError as exc:
            row.update(displacement_per_period_m=None, velocity_m_per_s=None, mode="",
                       status=f"{type(exc).__name__}: {exc}")
        else:
            d = sc.displacement_to_si(ss.displacement_per_period)
            row.update(displacement_per_period_m=d, velocity_m_per_s=d * frequency,
                       mode=ss.mode, status="ok")
        rows.append(row)
    return rows


def direction_figure(balance_rows, phase_rows, path, frequency):
    """Two panels: mean rotor velocity against the balance and against the phase."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(8.0, 3.2), dpi=90)
    for ax, rows, label, scale in ((axes[0], balance_rows, r"balance $\beta$", 1.0),
                                   (axes[1], phase_rows, r"phase lag $\delta$ [deg]",
                                    180.0 / math.pi)):
        ok = [r for r in rows if r["status"] == "ok"]
        x = np.array([r["value"] * scale for r in ok])
        y = np.array([r["velocity_m_per_s"] * 1e3 for r in ok])
        ax.plot(x, y, "k.-", lw=1.0)
        modes = sorted({r["mode"] for r in ok})
        cmap = plt.get_cmap("tab10")
        for k, m in enumerate(modes):
            sel = [i for i, r in enumerate(ok) if r["mode"] == m]
            ax.plot(x[sel], y[sel], "o", ms=5, color=cmap(k % 10), label=m.replace("|", " / "))
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_xlabel(label)
        ax.legend(fontsize=6, title="mode rod a / rod b", title_fontsize=6, loc="best")
    axes[0].set_ylabel("mean rotor velocity [mm/s]")
    fig.suptitle(f"Bidirectional drive at {frequency:g} Hz: direction control "
                 "(event-driven steady states)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def main(argv=None):
    """``python -m moreau.studies.bidirectional.direction_control OUT_DIR [--frequency F]``: CSV and figure."""
    ap = argparse.ArgumentParser(description="direction-control sweeps of the bidirectional drive")
    ap.add_argument("out", help="output folder (created; must not hold earlier results)")
    ap.add_argument("--frequency", type=float, default=185.0)
    ap.add_argument("--points", type=int, default=13)
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    target = out / "direction_control.csv"
    if target.exists():
        raise InputError(f"`out` already holds {target}; choose an empty folder")
    out.mkdir(parents=True, exist_ok=True)
    n = args.points
    bal = direction_sweep("balance", np.linspace(-1.0, 1.0, n), args.frequency, progress=True)
    pha = direction_sweep("phase", np.linspace(0.0, 2 * math.pi, n), args.frequency,
                          progress=True)
    with open(target, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["knob"] + list(bal[0]))
        w.writeheader()
        for knob, rows in (("balance", bal), ("phase", pha)):
            for r in rows:
                w.writerow({"knob": knob, **r})
    direction_figure(bal, pha, out / "bidirectional_direction_control.png", args.frequency)
    for knob, rows in (("balance", bal), ("phase", pha)):
        for r in rows:
            v = r["velocity_m_per_s"]
            print(f"{knob:8s} {r['value']:8.4f} {'' if v is None else f'{v * 1e3:+.6f} mm/s'} "
                  f"{r['mode']} {r['status'][:60]}")


if __name__ == "__main__":
    main()
