"""The piezo drive's stack loop and its frequency sweep through the stator's resonance.

``python -m moreau.studies.piezo.loop_and_resonance OUT_DIR`` writes

* ``piezo_loop.csv`` and ``piezo_loop.png``: the displacement–voltage loops
  of the stack at several peak voltages (saturation flattens them);
* ``piezo_resonance.csv`` and ``piezo_resonance.png``: across the stator's
  resonance, the stator's stroke, the motor's mean velocity and the
  velocity of the prescribed-displacement drive (rigid stator) at the same
  stroke, from Moreau–Jean's periodic steady states.

Each row is one steady state of :func:`resonance_sweep`; the velocities are
in m/s, strokes in m (units in the CSV column names).
"""

import argparse
import csv
import math
import pathlib

import numpy as np

from ...outputs import write_csv
from ..._validate import positive_int
from ...analysis.mj_steady_state import moreau_jean_steady_state
from ...analysis.period_k import full_state_of
from ...errors import InputError, MoreauError
from ...integrators import simulate
from ...scenes.piezo_drive import PiezoDrive

__all__ = ["loop_curves", "resonance_sweep", "RESONANCE_STACK", "main"]

TWO_PI = 2.0 * math.pi

#: a linear stack on a heavy stator (resonance 2 kHz, damping ratio 0.3), preloaded rotor:
#: the setting of the resonance test
RESONANCE_STACK = dict(alpha=0.0, u_sat=math.inf, m1=0.02, k1=3.2e6, c1=150.0, preload=0.01)


def loop_curves(voltages, n=401, **params):
    """``[(U_pp, U [V], x [m])]``: the stack's periodic loop at each peak voltage."""
    return [(float(U),) + PiezoDrive(voltage=float(U), **params).hysteresis_loop(n)
            for U in voltages]


def resonance_sweep(frequencies, steps=500, **params):
    """Steady states of the dynamic-stator drive and its rigid equivalent across frequencies.

    Parameters
    ----------
    frequencies : sequence of float
        Drive frequencies [Hz].
    steps : int
        Moreau–Jean steps per period.
    **params
        Scene parameters (:data:`RESONANCE_STACK` by default).

    Returns
    -------
    list of dict
        ``frequency_Hz``, ``stroke_m`` (the stator's peak-to-peak motion),
        ``velocity_m_per_s``, ``rigid_velocity_m_per_s`` (rigid stator, a
        linear stack at the same stroke, same other parameters), ``mode``,
        ``status`` (``"ok"`` or the reason a point failed).

    Examples
    --------
    >>> rows = resonance_sweep([2800.0])
    >>> rows[0]["mode"], round(rows[0]["stroke_m"] * 1e6, 1)
    ('NP', 4.8)
    """
    steps = positive_int("steps", steps)
    params = dict(RESONANCE_STACK if not params else params)
    if params.get("stator", "dynamic") != "dynamic":
        raise InputError("`stator` must be 'dynamic' for a resonance sweep")
    rows = []
    for f in frequencies:
        row = dict(frequency_Hz=float(f), stroke_m=math.nan, velocity_m_per_s=math.nan,
                   rigid_velocity_m_per_s=math.nan, mode="", status="ok")
        try:
            s = PiezoDrive(frequency=float(f), **params)
            ss = moreau_jean_steady_state(s, steps)
            q, v = full_state_of(s, ss.state0)
            t0 = float(ss.section_tau or 0.0)
            r = simulate(s, (t0, t0 + TWO_PI), q, v, "moreau-jean", h=TWO_PI / steps)
            stroke = float(np.ptp(r.q[:, 2])) * s.params.length
            rig = PiezoDrive(frequency=float(f), **dict(
                params, stator="rigid", alpha=0.0, u_sat=math.inf,
                gain=stroke / s.params.voltage))
            sr = moreau_jean_steady_state(rig, steps)
            row.update(stroke_m=stroke, mode=ss.mode,
                       velocity_m_per_s=s.velocity_to_si(ss.displacement_per_period / TWO_PI),
                       rigid_velocity_m_per_s=rig.velocity_to_si(
                           sr.displacement_per_period / TWO_PI))
        except MoreauError as exc:
            row["status"] = f"failed: {exc}"
        rows.append(row)
    return rows


def _figures(loops, rows, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(4.6, 3.4), dpi=90)
    for U_pp, U, x in loops:
        ax.plot(U, x * 1e6, lw=1.0, label=f"{U_pp:g} V")
    ax.set_xlabel("voltage U [V]")
    ax.set_ylabel("free displacement [µm]")
    ax.set_title("Piezo stack: Bouc–Wen loops, saturation 150 V", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "piezo_loop.png")
    plt.close(fig)

    ok = [r for r in rows if r["status"] == "ok"]
    f = np.array([r["frequency_Hz"] for r in ok])
    fig, axes = plt.subplots(2, 1, figsize=(4.6, 5.0), dpi=90, sharex=True)
    axes[0].plot(f, [r["stroke_m"] * 1e6 for r in ok], "k.-")
    axes[0].set_ylabel("stator stroke [µm]")
    axes[1].plot(f, [r["velocity_m_per_s"] * 1e3 for r in ok], "k.-", label="dynamic stator")
    axes[1].plot(f, [r["rigid_velocity_m_per_s"] * 1e3 for r in ok], "r--",
                 label="prescribed stroke (rigid)")
    for r in ok:
        if "F" in r["mode"]:
            axes[1].plot(r["frequency_Hz"], r["velocity_m_per_s"] * 1e3, "o", mfc="none",
                         color="b")
    axes[1].set_ylabel("rotor velocity [mm/s]")
    axes[1].set_xlabel("drive frequency [Hz] (open circles: flight in the period)")
    axes[1].legend(fontsize=7)
    fig.suptitle("Piezo drive through the stator's resonance (2 kHz)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "piezo_resonance.png")
    plt.close(fig)


def main(argv=None):
    """``python -m moreau.studies.piezo.loop_and_resonance OUT_DIR [--points N]``: CSVs and figures."""
    ap = argparse.ArgumentParser(description="the piezo drive's stack loop and resonance sweep")
    ap.add_argument("out", help="output folder (created; must not hold earlier results)")
    ap.add_argument("--points", type=int, default=17, help="frequencies from 1 to 3 kHz")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    if (out / "piezo_resonance.csv").exists():
        raise InputError(f"`out` already holds {out / 'piezo_resonance.csv'}; choose an empty "
                         f"folder")
    out.mkdir(parents=True, exist_ok=True)
    loops = loop_curves((50.0, 100.0, 200.0, 400.0))
    with open(out / "piezo_loop.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["peak_voltage [V]", "U [V]", "x [m]"])
        for U_pp, U, x in loops:
            w.writerows((U_pp, a, b) for a, b in zip(U, x))
    rows = resonance_sweep(np.linspace(1000.0, 3000.0, positive_int("points", args.points)))
    write_csv(out / "piezo_resonance.csv", rows)
    if not args.no_plot:
        _figures(loops, rows, out)
    for r in rows:
        print(f"{r['frequency_Hz']:7.1f} Hz  stroke {r['stroke_m'] * 1e6:6.2f} um  "
              f"v {r['velocity_m_per_s'] * 1e3:8.3f} mm/s  rigid {r['rigid_velocity_m_per_s'] * 1e3:8.3f}"
              f" mm/s  {r['mode']} {r['status'] if r['status'] != 'ok' else ''}")
    return 0


if __name__ == "__main__":
    main()
