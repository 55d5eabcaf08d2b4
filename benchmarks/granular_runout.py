"""The granular column's runout against its aspect ratio, the power law fitted.

``python benchmarks/granular_runout.py run OUT 0.5:10 1:8 2:6 4:5 8:4`` collapses one
column per ``aspect:L0`` (``L0`` in diameters;
:func:`moreau.studies.granular.runout.runout_rows`) and appends each row to ``OUT`` as it
finishes (one JSON line a column; several processes may share one file).

``python benchmarks/granular_runout.py fit OUT [OUT ...] [--split 3]`` prints the rows and
:func:`moreau.scenes.granular_column.fit_runout` of them (runout ``lambda a`` up to the
split, ``c a^p`` beyond), beside the published exponent 2/3 of the large branch
(Lajeunesse, Monnier and Homsy 2005; Lube et al. 2005; the study module).
"""

import argparse
import json
import time

from moreau.scenes.granular_column import fit_runout
from moreau.studies.granular.runout import runout_rows


def run(out, cases, seeds):
    def write(row):
        row["cpu_s"] = time.process_time() - t0[0]
        row["seed"] = seed
        with open(out, "a") as f:
            f.write(json.dumps(row) + "\n")
        print(f"seed {seed}, a = {row['aspect']:.2f}: runout {row['runout']:.2f}, stopped {row['stopped']}, "
              f"{row['cpu_s']:.0f} s CPU", flush=True)
        t0[0] = time.process_time()

    t0 = [time.process_time()]
    pairs = [tuple(float(s) for s in c.split(":")) for c in cases]
    # (every aspect ratio with one seed before the next seed: an interrupted run keeps a
    # whole curve per seed done)
    for seed in seeds:
        runout_rows(pairs, on_row=write, seed=seed)


def fit(paths, split):
    rows = []
    for path in paths:
        with open(path) as f:
            rows += [json.loads(line) for line in f if line.strip()]
    rows.sort(key=lambda r: r["aspect"])
    print("| a aimed | L0 (d) | disks | a = H0/L0 | runout (L_inf - L0)/L0 | front stopped | "
          "steps above tol |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['aim']:g} | {r['L0']:g} | {r['n_disks']} | {r['aspect']:.2f} | "
              f"{r['runout']:.2f} | {r['stopped']} | {r['unconverged']} of {r['steps']} |")
    f = fit_runout([r["aspect"] for r in rows], [r["runout"] for r in rows], split)
    print(f"a <= {split:g}: lambda = {f['lambda']}, power p_small = {f['p_small']}; "
          f"a > {split:g}: runout = {f['c']} a^{f['p']} (published: a^(2/3))")


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
