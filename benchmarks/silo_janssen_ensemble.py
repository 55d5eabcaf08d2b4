"""Janssen's law in the silo, ensemble-averaged: one filling at a time, then the fit.

``python benchmarks/silo_janssen_ensemble.py run OUT --seeds 0 1 2 [--n-disks 160]
[--tag NAME --slide-tol 1e-6 --slide-sweeps 3000 --transient-steps 200 ...]`` runs
:func:`moreau.studies.granular.janssen.sliding_profile` for each seed and appends each
filling's profile to ``OUT`` (one JSON line a filling, written as it finishes, so that an
interrupted run keeps the fillings done). ``--tag`` names a variant of the protocol (the
options given after it); rows of other tags are kept apart when fitting.

``python benchmarks/silo_janssen_ensemble.py fit OUT [OUT ...] [--n-disks 160] [--tag NAME]
[--seeds ...]`` reads the fillings (of that size and tag, and those seeds if given) and
prints :func:`moreau.studies.granular.janssen.ensemble`'s fits (the cuts and the floor; the
cuts alone) and table: per cut, the mean mass above it, the load it carries, its standard
error over the fillings, the wall-supported fraction, the deviation from the fitted law;
per band between cuts, the share of its weight its walls carry (measured, and by the law),
their friction's mobilisation and ``K``; and the floor's checks: the floor's load read from
its own impulses over every sliding step less the momentum gained, against the load read at
the samples (mass less the walls' friction), and the momentum gained over the weight.

Half a minute to minutes a filling on one core (160 disks: settling and 150 sliding steps);
the figures are the study module's docstring's.
"""

import argparse
import json
import math
import time

import numpy as np

from moreau.scenes.silo import SiloParams
from moreau.studies.granular.janssen import ensemble, sliding_profile

#: the silo's default wall speed in grain units
WALL_SPEED = SiloParams.wall_speed / math.sqrt(SiloParams.diameter * SiloParams.gravity)

VARIANT = ("tol", "max_sweeps", "slide_tol", "slide_sweeps", "transient_steps",
           "measure_steps", "settle_steps", "mu_floor", "mu_wall")


def run(out, seeds, n_disks, tag, options):
    for s in seeds:
        t0 = time.process_time()
        r = sliding_profile(s, n_disks=n_disks, **options)
        row = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in r.items()}
        row.update(seed=s, n_disks=n_disks, tag=tag, options=options,
                   cpu_s=time.process_time() - t0)
        with open(out, "a") as f:
            f.write(json.dumps(row) + "\n")
        print(f"seed {s}: {row['cpu_s']:.0f} s CPU, {r['unconverged']} of {r['steps']} "
              f"sliding steps above tol (worst {r['max_residual']:.1e}), settled in "
              f"{r['settle_steps']} steps", flush=True)


def fit(paths, n_disks, tag, seeds):
    rows = []
    for path in paths:
        with open(path) as f:
            rows += [json.loads(line) for line in f if line.strip()]
    rows = [r for r in rows if (n_disks is None or r.get("n_disks", n_disks) == n_disks)
            and r.get("tag", "") == tag and (not seeds or r["seed"] in seeds)]
    seen, profiles = set(), []
    for r in rows:
        if r["seed"] not in seen:
            seen.add(r["seed"])
            profiles.append({k: np.array(v) if isinstance(v, list) else v for k, v in r.items()})
    e = ensemble(profiles, floor=True)
    ka, kw, kp = e["K_bounds"]
    res = max(p["max_residual"] for p in profiles)
    print(f"{e['fillings']} fillings (seeds {sorted(seen)}, tag {tag!r}), {e['unconverged']} of "
          f"{e['steps']} sliding steps above tol (worst {res:.1e}); walls' friction mobilised "
          f"{e['mobilised']:.1%}; settled in {min(p['settle_steps'] for p in profiles)}-"
          f"{max(p['settle_steps'] for p in profiles)} steps")
    print(f"K = {e['K']:.3f} (K_a {ka:.2f}, K_w {kw:.2f}, K_p {kp:.2f}), m_sat = "
          f"{e['m_sat']:.1f}, lambda = {e['lam']:.1f} d; worst deviation "
          f"{e['max_deviation']:.1%}, rms {e['rms_deviation']:.1%}")
    c = ensemble(profiles, floor=False)
    sem = e["m_app_sem"][-1] / e["m_app"][-1]
    print(f"the cuts alone fitted: K = {c['K']:.3f}, m_sat = {c['m_sat']:.1f}, worst deviation "
          f"{c['max_deviation']:.1%}, rms {c['rms_deviation']:.1%}; the floor "
          f"{c['floor_deviation']:+.1%} off that law (s.e. {sem:.1%})")
    print("| depth (d) | mass above | load m_app | s.e. | wall-supported | deviation | "
          "band: walls carry | by the law | mobilised | K |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for row in zip(e["depth"], e["mass"], e["m_app"], e["m_app_sem"], e["wall_fraction"],
                   e["deviation"], e["band_wall_share"], e["band_law_share"],
                   e["band_mobilised"], e["band_K"]):
        print("| {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1%} | {:+.1%} | {:.1%} | {:.1%} | "
              "{:.1%} | {:.2f} |".format(*row))
    # the floor's load two ways: its own impulses over every sliding step less the momentum
    # gained (the step's vertical balance), and the mass less the walls' friction at samples
    read = np.array([p["floor_load"] - p["momentum_change"] for p in profiles])
    sampled = np.array([p["floor_m_app"] for p in profiles])
    gained = np.array([p["momentum_change"] / p["floor_mass"] for p in profiles])
    kin = np.array([p["kinetic"] for p in profiles])
    n = len(profiles)
    print(f"floor load, every step (impulses) {read.mean():.2f} vs at the samples "
          f"{sampled.mean():.2f}: differ by {np.mean(sampled / read - 1):+.2%} "
          f"(s.e. {np.std(sampled / read - 1, ddof=1) / math.sqrt(n):.2%}); momentum gained "
          f"over the weight {gained.mean():+.2%} (s.e. {gained.std(ddof=1) / math.sqrt(n):.2%}); "
          f"kinetic energy {kin.mean():.2e} g d a unit mass (the walls' speed squared over "
          f"two: {0.5 * WALL_SPEED ** 2:.2e})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("run", "fit"))
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--seeds", type=int, nargs="*", default=None)
    ap.add_argument("--n-disks", type=int, default=160)
    ap.add_argument("--tag", default="")
    for key in VARIANT:
        ap.add_argument("--" + key.replace("_", "-"), type=float, default=None)
    a = ap.parse_args()
    options = {k: getattr(a, k) for k in VARIANT if getattr(a, k) is not None}
    options = {k: int(v) if k.endswith(("steps", "sweeps")) else v for k, v in options.items()}
    if a.mode == "run":
        run(a.paths[0], a.seeds if a.seeds is not None else [0, 1], a.n_disks, a.tag, options)
    else:
        fit(a.paths, a.n_disks, a.tag, a.seeds)


if __name__ == "__main__":
    main()
