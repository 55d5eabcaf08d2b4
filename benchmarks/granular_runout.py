"""The granular column's runout against its aspect ratio over seeds, the power law fitted.

``python benchmarks/granular_runout.py run OUT 0.5:10 1:8 2:6 4:5 8:4 --seeds 0 1 2``
collapses one column per ``aspect:L0`` (``L0`` in diameters) and seed
(:func:`moreau.studies.granular.runout.runout_ensemble`: every column with one seed before
the next seed) and appends each row to ``OUT`` as it finishes (one JSON line a column).

``python benchmarks/granular_runout.py fit OUT [OUT ...] [--split 3]`` prints the rows, then
:func:`moreau.studies.granular.runout.runout_summary` of them: per column the mean runout and
its spread over the seeds, and both branches fitted on every run (runout ``lambda a`` up to
the split, ``c a^p`` beyond, with standard errors), beside the experiments' exponents
(``a`` and ``a^(2/3)``: Lajeunesse, Monnier and Homsy 2005; Lube et al. 2005; the study
module).
"""

import argparse
import json
import time

from moreau.studies.granular.runout import runout_ensemble, runout_summary


def run(out, cases, seeds):
    def write(row):
        row["cpu_s"] = time.process_time() - t0[0]
        with open(out, "a") as f:
            f.write(json.dumps(row) + "\n")
        print(f"seed {row['seed']}, a = {row['aspect']:.2f}: runout {row['runout']:.2f}, "
              f"stopped {row['stopped']}, {row['cpu_s']:.0f} s CPU", flush=True)
        t0[0] = time.process_time()

    t0 = [time.process_time()]
    runout_ensemble([tuple(float(s) for s in c.split(":")) for c in cases], seeds, on_row=write)


def fit(paths, split):
    rows = []
    for path in paths:
        with open(path) as f:
            rows += [json.loads(line) for line in f if line.strip()]
    rows.sort(key=lambda r: (r["aim"], r.get("seed", 0)))
    print("| a aimed | L0 (d) | seed | disks | a = H0/L0 | runout (L_inf - L0)/L0 | stopped | "
          "steps above tol | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['aim']:g} | {r['L0']:g} | {r.get('seed', 0)} | {r['n_disks']} | "
              f"{r['aspect']:.2f} | {r['runout']:.2f} | {r['stopped']} | "
              f"{r.get('unconverged')} of {r.get('steps')} | {r.get('cpu_s', 0):.0f} |")
    s = runout_summary(rows, a_split=split)
    print("| a aimed | runs | a (mean +- sd) | runout mean | sd | s.e. |")
    print("|---|---|---|---|---|---|")
    for k in range(s["aim"].size):
        print(f"| {s['aim'][k]:g} | {s['n'][k]} | {s['aspect'][k]:.2f} +- "
              f"{s['aspect_std'][k]:.2f} | {s['runout'][k]:.2f} | {s['runout_std'][k]:.2f} | "
              f"{s['runout_sem'][k]:.2f} |")

    def show(v, fmt=".2f"):
        return "n/a" if v is None else format(v, fmt)

    print(f"a > {split:g}: runout = {show(s['c'])} a^({show(s['p'])} +- {show(s['p_se'])}) "
          f"(experiments: a^(2/3))")
    print(f"a <= {split:g}: lambda = {show(s['lambda'])} +- {show(s['lambda_se'])}; power "
          f"{show(s['c_small'])} a^({show(s['p_small'])} +- {show(s['p_small_se'])}) "
          f"(experiments: proportional to a)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("run", "fit"))
    ap.add_argument("out")
    ap.add_argument("more", nargs="*")
    ap.add_argument("--split", type=float, default=3.0)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    a = ap.parse_args()
    if a.mode == "run":
        run(a.out, a.more, a.seeds)
    else:
        fit([a.out] + a.more, a.split)


if __name__ == "__main__":
    main()
