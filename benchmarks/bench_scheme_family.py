"""The scheme family against Siconos's OSIs: accuracy, speed and energy on two impact scenes.

For every registered time-stepping scheme of moreau (Moreau–Jean at theta
1/2 and 1, and each scheme that ``moreau compare`` runs by its steps per
period), for moreau's
event-driven reference, and for Siconos's OSIs
(``benchmarks/siconos_osis.py``, run by the system interpreter when
``python3-siconos`` is installed), on

``ball``
    the bouncing ball (radius 0.05, from rest at 1.05, e = 0.5), error of the
    height and velocity at ``t = 2`` against the exact solution;
``oscillator``
    a unit mass on a unit spring with a wall at ``q = -0.5``, e = 1, from
    ``q = 1`` at rest (energy 1/2), error at ``t = 20`` against moreau's
    event-driven reference at rtol 1e-12;

and the friction drive (``friction-drive``, 185 Hz, the paper's parameters,
from rest, ``h = 2 pi / 1000``): the average displacement per period of the
rotor over periods 10..20 (5..10 with ``--quick``) against moreau's
event-driven reference (rtol 1e-12) over the same window, for moreau's
compiled Moreau–Jean (theta 1/2 and 1) and for Siconos's MoreauJeanOSI,
MoreauJeanCombinedProjectionOSI, MoreauJeanDirectProjectionOSI,
MoreauJeanGOSI, MoreauJeanBilbaoOSI and LsodarOSI (those that cannot run
the system say why), with each one's steps per second and moreau's
compiled Moreau–Jean theta = 1/2 rate over it (``moreau_mj_speedup``),
measured in the same run (Siconos: one run after the plugin build; moreau:
median of ``--repeat`` runs after a warm-up);

and the energy table: the largest and the final relative energy drift over
1e5 steps (``h = 1e-3``) on the elastic (e = 1) ball and on the oscillator,
for every time-stepping scheme, the tolerance-driven ones (Studer at tol
1e-6 and 1e-9) and the compliant ones (stiffness 1e4, sampled every 1e-3)
over the same time (``--energy-only``: that table alone).
(Schatzman–Paoli records the central difference ``(q_{k+1} - q_{k-1}) / 2h``:
on a node inside an impact, the mean of the velocities of the steps that
arrive and leave, whose kinetic energy is below both sides' and near 0 for
an elastic impact. Its largest drift is therefore that of one sample inside
an impact, below the initial energy (0.91 on the ball, 0.69 on the
oscillator, measured); its final drift is the one to read.) Speeds are steps per second (median of ``--repeat`` runs), with the ratio
to Siconos's MoreauJeanOSI measured in the same run.

Run: ``python benchmarks/bench_scheme_family.py [--quick] [--out DIR] [--friction-drive-only]
[--energy-only]``;
writes ``scheme_family.json`` and ``scheme_family.csv`` to ``--out``
(default ``./out``) and prints the tables.
"""

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys

import numpy as np
from numba import njit

from _timing import median_time
from moreau.compiled import CompiledModel
from moreau.integrators import INTEGRATORS, simulate
from moreau.integrators.base import get_integrator, scheme_options
from moreau.model.scene import Scene
from moreau.scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive
from moreau.model.registry import make_scene

HERE = os.path.dirname(os.path.abspath(__file__))
TWO_PI = 2.0 * np.pi
#: the OSIs tried on the friction drive (issue 18's list, and the direct projection)
FD_OSIS = ("MoreauJeanOSI", "MoreauJeanCombinedProjectionOSI", "MoreauJeanDirectProjectionOSI",
           "MoreauJeanBilbaoOSI", "MoreauJeanGOSI", "LsodarOSI")
#: why an OSI that fails on the friction drive cannot run it, where Siconos does not say
FD_WHY = {"LsodarOSI": "EventDriven's impact and acceleration problems are LCPs, which take no "
                       "Coulomb friction (NewtonImpactFrictionNSL): Siconos throws "
                       "std::exception at the first advanceToEvent"}
#: what a run that finishes does wrong, as observed (Siconos 4.4, Debian)
FD_NOTES = {"MoreauJeanGOSI": "the rod is not driven: over one period phi moves by 3e-6 and u2 by "
                              "1e-21; the stator's motion enters only through the relation's "
                              "h_dot, which MoreauJeanGOSI's global problem appears to ignore"}
SICONOS_OSIS = ("MoreauJeanOSI", "MoreauJeanGOSI", "MoreauJeanCombinedProjectionOSI",
                "MoreauJeanDirectProjectionOSI", "MoreauJeanBilbaoOSI", "LsodarOSI")


def time_stepping_schemes():
    """``(name, options, label)``: Moreau–Jean at theta 1/2 and 1, and every other
    registered scheme that compare runs by its steps per period."""
    out = [("moreau-jean", {"theta": 0.5}, "moreau-jean theta=1/2"),
           ("moreau-jean", {"theta": 1.0}, "moreau-jean theta=1")]
    for name in sorted(INTEGRATORS):
        settings = getattr(INTEGRATORS[name], "compare_settings", None)
        if settings and settings[0] == "steps_per_period":
            out.append((name, {}, name))
    return tuple(out)


def tolerance_schemes():
    """``(name, options, label)`` of the registered schemes driven by a tolerance ``tol``."""
    out = []
    for name in sorted(INTEGRATORS):
        settings = getattr(INTEGRATORS[name], "compare_settings", None)
        if settings and settings[0] == "tol":
            out += [(name, {"tol": tol}, f"{name} tol={tol:g}") for tol in (1e-6, 1e-9)]
    return tuple(out)


def stiffness_schemes():
    """``(name, options, label)`` of the registered compliant schemes, at one contact stiffness.

    Their model is regularised, so their energy drift mixes the model (the
    contact spring's energy is not in the rigid energy while it is compressed)
    and the integration; the final drift, in flight, is the one to read.
    """
    out = []
    for name in sorted(INTEGRATORS):
        settings = getattr(INTEGRATORS[name], "compare_settings", None)
        if settings and settings[0] == "stiffness":
            opts = dict(settings[3], stiffness=1e4)
            out.append((name, opts, f"{name} k=1e4"))
    return tuple(out)


# the wall oscillator's compiled model (moreau.compiled): the user-scene hook
@njit(cache=True)
def _osc_mass(par, q, M):
    M[0, 0] = 1.0


@njit(cache=True)
def _osc_forces(par, q, v, t, D, need_jac):
    D[0, 0] = -q[0]
    if need_jac:
        D[0, 1] = -1.0


@njit(cache=True)
def _osc_contacts(par, q, t, G, need_gap, need_T):
    if need_gap:
        G[0, 0] = q[0] + 0.5
    G[0, 3] = 1.0


@njit(cache=True)
def _osc_drift(par, q, v, t, Dr):
    Dr[0, 0] = 0.0


class WallOscillator(Scene):
    """Unit mass on a unit spring, a wall at ``q = -0.5`` (restitution 1)."""

    ndof, mu, restitution = 1, np.array([0.0]), np.array([1.0])
    name = "wall-oscillator"

    def mass(self, q):
        return np.eye(1)

    def forces(self, q, v, t):
        return -np.asarray(q, dtype=float)

    def force_jacobians(self, q, v, t):
        return -np.eye(1), np.zeros((1, 1))

    def gaps(self, q, t):
        return np.array([q[0] + 0.5])

    def contact_jacobians(self, q, t):
        return np.array([[1.0]]), np.zeros(1), np.zeros((0, 1)), np.zeros(0)

    def contact_drift(self, q, v, t):
        return np.zeros(1), np.zeros(0)

    def initial_state(self):
        return np.array([1.0]), np.array([0.0])

    def compiled_model(self):
        return CompiledModel(_osc_mass, _osc_forces, _osc_contacts, _osc_drift, [0.0], 1, 1,
                             True, True)


def cases(e_ball=0.5):
    ball = make_scene("bouncing-ball", restitution=e_ball)
    osc = WallOscillator()
    return {"ball": (ball, lambda q, v: 0.5 * v * v + q),
            "oscillator": (osc, lambda q, v: 0.5 * (v * v + q * q))}


def reference(name, scene, t_end):
    q0, v0 = scene.initial_state()
    if name == "ball":
        q, v = scene.exact_solution(np.array([t_end]), q0, v0)
        return float(q[0, 0]), float(v[0, 0])
    r = simulate(scene, (0.0, t_end), q0, v0, "event-driven", rtol=1e-12, atol=1e-14)
    return float(r.q[-1, 0]), float(r.v[-1, 0])


def siconos(case, osi, h, t_end, e):
    py = "/usr/bin/python3"
    if not os.path.exists(py):
        return {"osi": osi, "case": case, "error": "no system python3 with siconos"}
    cmd = [py, os.path.join(HERE, "siconos_osis.py"), case, osi, "--h", repr(h),
           "--t-end", repr(t_end), "--e", repr(e)]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    try:
        return json.loads(run.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        tail = (run.stderr.strip().splitlines() or ["no output"])[-1]
        return {"osi": osi, "case": case, "error": f"exit {run.returncode}: {tail}"}


def fd_params(scene, label):
    """The friction drive's dimensionless parameters as ``siconos_osis.py`` takes them."""
    q0, v0 = scene.rest_state()
    return {"label": label, "J": scene.J, "P": scene.P, "u10": scene.u10, "fL": scene.fL,
            "sin_phi0": scene.sin_phi0, "mu": float(scene.mu[0]),
            "e": float(scene.restitution[0]), "q0": [float(x) for x in q0],
            "v0": [float(x) for x in v0]}


def siconos_fd(osi, par, periods):
    cmd = ["/usr/bin/python3", os.path.join(HERE, "siconos_osis.py"), "friction-drive", osi,
           "--fd-params", json.dumps(par), "--periods", str(periods)]
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    except subprocess.TimeoutExpired:
        return {"osi": osi, "error": "no result in 900 s"}
    try:
        return json.loads(run.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        tail = (run.stderr.strip().splitlines() or ["no output"])[-1]
        return {"osi": osi, "error": f"exit {run.returncode}: {tail}"}


def friction_drive_rows(quick, repeat, use_siconos, frequency=185.0):
    """Rows of the friction-drive table (see the module docstring)."""
    scene = FrictionDrive(PAPER_DEFAULTS, frequency)
    label = f"{frequency:g} Hz"
    periods, skip = (10, 5) if quick else (20, 10)
    steps = 1000
    q0, v0 = scene.rest_state()
    # the reference over the window: to the window's start, then on to its end
    a = simulate(scene, (0.0, TWO_PI * skip), q0, v0, "event-driven", rtol=1e-12)
    b = simulate(scene, (TWO_PI * skip, TWO_PI * periods), a.q[-1], a.v[-1], "event-driven",
                 rtol=1e-12)
    if a.status != 0 or b.status != 0 or abs(b.t[-1] - TWO_PI * periods) > 1e-9:
        raise RuntimeError(f"event-driven reference failed: {a.message} {b.message}")
    d_ref = float((b.q[-1, 1] - a.q[-1, 1]) / (periods - skip))
    window = f"periods {skip}..{periods} from rest"
    rows = [{"table": "friction-drive", "case": label, "scheme": "moreau event-driven",
             "displacement_per_period": d_ref, "window": window}]

    def rel(d):
        return abs(d - d_ref) / abs(d_ref)

    mj_rate = None
    for theta in (0.5, 1.0):
        def go(theta=theta):
            return simulate(scene, (0.0, TWO_PI * periods), q0, v0, "moreau-jean",
                            h=TWO_PI / steps, theta=theta, save_every=steps)
        res = go()
        sec = median_time(go, repeat=repeat, warmup=1)
        d = float((res.q[periods, 1] - res.q[skip, 1]) / (periods - skip))
        rate = res.stats["steps"] / sec
        if theta == 0.5:
            mj_rate = rate
        rows.append({"table": "friction-drive", "case": label,
                     "scheme": f"moreau-jean theta={theta:g} (compiled)",
                     "steps": res.stats["steps"],
                     "seconds": sec, "steps_per_s": rate, "displacement_per_period": d,
                     "error": rel(d), "window": window})
    if use_siconos:
        par = fd_params(scene, label)
        for osi in FD_OSIS:
            r = siconos_fd(osi, par, periods)
            row = {"table": "friction-drive", "case": label, "scheme": "siconos " + osi,
                   "window": window}
            if "error" in r:
                row["failure"] = r["error"] + (f" ({FD_WHY[osi]})" if osi in FD_WHY else "")
            else:
                u2 = r["u2_periods"]
                d = float((u2[periods] - u2[skip]) / (periods - skip))
                rate = r["steps"] / r["seconds"]
                row.update(steps=r["steps"], seconds=r["seconds"], steps_per_s=rate,
                           displacement_per_period=d, error=rel(d),
                           moreau_mj_speedup=mj_rate / rate)
                if osi in FD_NOTES:
                    row["note"] = FD_NOTES[osi]
            rows.append(row)
    return rows


def moreau_row(label, scheme, options, scene, energy, t_end, h, repeat):
    q0, v0 = scene.initial_state()
    # a fixed-step scheme gets the step; an adaptive one its own options (the compliant
    # schemes record at the same spacing)
    takes = scheme_options(get_integrator(scheme)) or ()
    opts = dict(options, h=h) if "h" in takes else dict(options)
    if "sample_dt" in takes and "h" not in takes and "sample_dt" not in opts \
            and scheme.startswith("compliant"):
        opts["sample_dt"] = h

    def go():
        return simulate(scene, (0.0, t_end), q0, v0, scheme, **opts)

    res = go()
    sec = median_time(go, repeat=repeat, warmup=1)
    en = energy(res.q[:, 0], res.v[:, 0])
    steps = res.stats.get("steps", len(res.t) - 1)
    return {"scheme": label, "steps": steps, "seconds": sec, "q": float(res.q[-1, 0]),
            "v": float(res.v[-1, 0]), "status": res.status,
            "energy_drift": float(np.max(np.abs(en - en[0])) / abs(en[0])),
            "final_energy_drift": float(abs(en[-1] - en[0]) / abs(en[0]))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out")
    ap.add_argument("--quick", action="store_true", help="1e4 steps in the energy table, one run")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-siconos", action="store_true")
    ap.add_argument("--friction-drive-only", action="store_true",
                    help="only the friction-drive table")
    ap.add_argument("--energy-only", action="store_true", help="only the energy table")
    a = ap.parse_args()
    if os.path.exists(a.out) and not os.path.isdir(a.out):
        sys.exit(f"`--out` must be a folder, but {a.out!r} is a file")
    os.makedirs(a.out, exist_ok=True)
    repeat = 1 if a.quick else a.repeat
    use_siconos = not a.no_siconos and shutil.which("/usr/bin/python3") is not None
    rows = []
    h = 1e-3
    for name, t_end in (() if a.friction_drive_only or a.energy_only
                        else (("ball", 2.0), ("oscillator", 20.0))):
        scene, energy = cases()[name]
        q_ref, v_ref = reference(name, scene, t_end)
        for scheme, opts, label in (time_stepping_schemes() + tolerance_schemes()
                                    + (("event-driven", {}, "moreau event-driven"),)):
            r = moreau_row(label, scheme, opts, scene, energy, t_end, h, repeat)
            rows.append(dict(r, table="accuracy", case=name,
                             error=max(abs(r["q"] - q_ref), abs(r["v"] - v_ref))))
        if use_siconos:
            for osi in SICONOS_OSIS:
                r = siconos(name, osi, h, t_end, 0.5)
                r["failure"] = r.pop("error", None)
                err = (max(abs(r["q"] - q_ref), abs(r["v"] - v_ref)) if "q" in r else None)
                rows.append(dict(r, table="accuracy", case=name, scheme="siconos " + osi,
                                 error=err))
    if not a.energy_only:
        rows += friction_drive_rows(a.quick, repeat, use_siconos)
    # the energy table: 1e5 steps (1e4 quick) at h = 1e-3, elastic ball and oscillator
    t_energy = 10.0 if a.quick else 100.0
    for name in (() if a.friction_drive_only else ("ball", "oscillator")):
        scene, energy = cases(e_ball=1.0)[name]
        for scheme, opts, label in (time_stepping_schemes() + tolerance_schemes()
                                    + stiffness_schemes()):
            r = moreau_row(label, scheme, opts, scene, energy, t_energy, h, 1)
            rows.append(dict(r, table="energy", case=name))
        if use_siconos:
            for osi in SICONOS_OSIS:
                r = siconos(name, osi, h, t_energy, 1.0)
                r["failure"] = r.pop("error", None)
                rows.append(dict(r, table="energy", case=name, scheme="siconos " + osi))
    base = {r["case"]: r["steps"] / r["seconds"] for r in rows
            if r["table"] == "accuracy" and r["scheme"] == "siconos MoreauJeanOSI"
            and r.get("seconds")}
    for r in rows:
        if (r.get("seconds") and r["scheme"] not in ("moreau event-driven", "siconos LsodarOSI")
                and " tol=" not in r["scheme"]):
            r["steps_per_s"] = r["steps"] / r["seconds"]
            if r["table"] == "accuracy" and r["case"] in base:
                r["ratio_to_siconos_mj"] = r["steps_per_s"] / base[r["case"]]
    with open(os.path.join(a.out, "scheme_family.json"), "w") as fh:
        json.dump(rows, fh, indent=1)
    fields = ("table", "case", "scheme", "steps", "seconds", "steps_per_s", "ratio_to_siconos_mj",
              "moreau_mj_speedup", "error", "displacement_per_period", "window", "energy_drift",
              "final_energy_drift", "status", "failure", "note")
    with open(os.path.join(a.out, "scheme_family.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields + ("q", "v"), extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print_friction_drive(rows)
    for table in ("accuracy", "energy"):
        print(f"\n{table} (h = {h:g})")
        for r in (x for x in rows if x["table"] == table):
            if r.get("failure"):
                print(f"  {r['case']:10s} {r['scheme']:40s} failed: {r['failure']}")
                continue
            extra = (f"error {r['error']:.2e}  {r['seconds'] * 1e3:.3g} ms"
                     + (f", {r['steps_per_s']:.3g} steps/s" if "steps_per_s" in r else "")
                     + (f" ({r['ratio_to_siconos_mj']:.3g}x Siconos MJ)"
                        if "ratio_to_siconos_mj" in r else "")
                     if table == "accuracy" else
                     f"max drift {r['energy_drift']:.2e}"
                     + (f", final {r['final_energy_drift']:.2e}" if "final_energy_drift" in r
                        else ""))
            print(f"  {r['case']:10s} {r['scheme']:40s} {extra}")


def print_friction_drive(rows):
    fd = [r for r in rows if r["table"] == "friction-drive"]
    if not fd:
        return
    print(f"\nfriction drive {fd[0]['case']} (h = T/1000), displacement per period over "
          f"{fd[0]['window']}")
    for r in fd:
        if r.get("failure"):
            print(f"  {r['scheme']:40s} failed: {r['failure']}")
        elif "error" not in r:
            print(f"  {r['scheme']:40s} d = {r['displacement_per_period']:.10g} (reference)")
        else:
            extra = (f", moreau MJ theta=1/2 {r['moreau_mj_speedup']:.3g}x faster"
                     if "moreau_mj_speedup" in r else "")
            print(f"  {r['scheme']:40s} d = {r['displacement_per_period']:.8g}  error "
                  f"{r['error']:.2e}  {r['steps_per_s']:.3g} steps/s{extra}"
                  + (f"\n      note: {r['note']}" if "note" in r else ""))


if __name__ == "__main__":
    main()
