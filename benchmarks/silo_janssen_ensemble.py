"""Janssen's law in the silo, ensemble-averaged: one filling at a time, then the fit.

``python benchmarks/silo_janssen_ensemble.py run OUT --seeds 0 1 2 [--n-disks 160]``
runs :func:`moreau.studies.granular.janssen.sliding_profile` for each seed and appends
each filling's profile to ``OUT`` (one JSON line a filling, written as it finishes, so
that an interrupted run keeps the fillings done; run several such processes on
different seeds into one file).

``python benchmarks/silo_janssen_ensemble.py fit OUT [OUT ...] [--n-disks 160]`` reads
the fillings (of that size) and prints :func:`moreau.studies.granular.janssen.ensemble`'s
fits (the cuts and the floor; the cuts alone) and table: per cut, the mean mass above it, the load it carries, its standard error over
the fillings, the wall-supported fraction, the deviation from the fitted law.

Minutes a filling on one core (160 disks: settling and 150 sliding steps); the figures
are the study module's docstring's.
"""

import argparse
import json
import time

import numpy as np

from moreau.studies.granular.janssen import ensemble, sliding_profile


def run(out, seeds, n_disks):
    for s in seeds:
        t0 = time.process_time()
        r = sliding_profile(s, n_disks=n_disks)
        row = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in r.items()}
        row.update(seed=s, n_disks=n_disks, cpu_s=time.process_time() - t0)
        with open(out, "a") as f:
            f.write(json.dumps(row) + "\n")
        print(f"seed {s}: {row['cpu_s']:.0f} s CPU, {r['unconverged']} of {r['steps']} "
              f"sliding steps above tol", flush=True)


def fit(paths, n_disks):
    rows = []
    for path in paths:
        with open(path) as f:
            rows += [json.loads(line) for line in f if line.strip()]
    rows = [r for r in rows if n_disks is None or r.get("n_disks", n_disks) == n_disks]
    seen, profiles = set(), []
    for r in rows:
        if r["seed"] not in seen:
            seen.add(r["seed"])
            profiles.append({k: np.array(v) if isinstance(v, list) else v for k, v in r.items()})
    e = ensemble(profiles)
    ka, kw, kp = e["K_bounds"]
    print(f"{e['fillings']} fillings (seeds {sorted(seen)}), {e['unconverged']} of {e['steps']} "
          f"sliding steps above tol; walls' friction mobilised {e['mobilised']:.1%}")
    print(f"K = {e['K']:.3f} (K_a {ka:.2f}, K_w {kw:.2f}, K_p {kp:.2f}), m_sat = "
          f"{e['m_sat']:.1f}, lambda = {e['lam']:.1f} d; worst deviation "
          f"{e['max_deviation']:.1%}, rms {e['rms_deviation']:.1%}")
    c = ensemble(profiles, floor=False)
    print(f"the cuts alone fitted: K = {c['K']:.3f}, m_sat = {c['m_sat']:.1f}, worst deviation "
          f"{c['max_deviation']:.1%}, rms {c['rms_deviation']:.1%}; the floor "
          f"{c['floor_deviation']:+.1%} off that law")
    print("| depth (d) | mass above | load m_app | s.e. | wall-supported | deviation |")
    print("|---|---|---|---|---|---|")
    for row in zip(e["depth"], e["mass"], e["m_app"], e["m_app_sem"], e["wall_fraction"],
                   e["deviation"]):
        print("| {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1%} | {:+.1%} |".format(*row))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("run", "fit"))
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1])
    ap.add_argument("--n-disks", type=int, default=160)
    a = ap.parse_args()
    if a.mode == "run":
        run(a.paths[0], a.seeds, a.n_disks)
    else:
        fit(a.paths, a.n_disks)


if __name__ == "__main__":
    main()
