"""Statistical steady states of the friction drive in flight: do the schemes and the starts agree?

Above the contact-loss limit (12.3 kHz for the paper's parameters) the rod
hops and hits the rotor, and at 15 kHz with ``e = 1`` the motion has no
periodic orbit. :func:`moreau.analysis.statistical.statistical_steady_state`
gives its long-run mean displacement per period with a 95 % interval. This
script checks that mean three ways, at ``--frequency`` and ``--restitution``:

1. **Starts.** The event-driven reference from rest and from rest with the
   rotor already turning (at a quarter and half the tip's speed amplitude).
2. **Attractors.** Moreau–Jean at 2000 steps a period from rest, and the
   reference from the state where that run ended. For ``e = 1`` there are
   two attractors: the reference from every start of part 1 spins the
   rotor up, over about 20 000 periods, onto a chaotic attractor, while
   Moreau–Jean's run ends on a regular one (quasi-periodic, one impact a
   period, a lower mean), which the reference keeps when started there.
   The reference's runs are grouped by attractor (means that agree within
   the sum of their intervals' half-widths).
3. **Schemes.** On the regular attractor, Moreau–Jean at 2000 to 128 000
   steps a period, from the same start as the reference. Moreau–Jean places
   each impact at a step, so its mean carries a bias of about first order
   in the step: its order is fitted to ``log |mean - reference|`` against
   ``log h``, and the step counts whose interval overlaps the reference's
   (the sum of the half-widths covers the difference) are listed.
4. **Residence.** Moreau–Jean started on the chaotic attractor (the
   reference's state after ``--spin-up`` periods) leaves it for the regular
   one after a number of periods that grows as the step shrinks; the
   reference stayed for 300 000 periods. Reported: the periods until the
   running mean of 1000 periods falls below the middle of the two
   attractors' means.

Writes ``statistical_agreement.json``, ``.csv`` and ``.png`` into ``--out``.

Run: ``python benchmarks/statistical_agreement.py --out DIR [--quick]``
(about 4 CPU minutes for ``e = 1``; ``--quick``: a coarse subset, about 12 s).
"""

import argparse
import csv
import json
import math
import os
import time

import numpy as np

from moreau.analysis.section_runs import section_states
from moreau.analysis.statistical import statistical_steady_state
from moreau.errors import BudgetExhaustedError
from moreau.scenes import make_scene

TWO_PI = 2.0 * math.pi


def _stat(scene, scheme, q0, v0, precision, budget, **opts):
    t0 = time.process_time()
    try:
        ss = statistical_steady_state(scene, scheme, q0=q0, v0=v0, precision=precision,
                                      max_periods=budget, **opts)
    except BudgetExhaustedError as exc:
        return {"status": "budget exhausted", "message": str(exc),
                "cpu_s": time.process_time() - t0}
    lo, hi = ss.confidence_interval
    si = scene.displacement_to_si
    return {"status": "converged", "mean_m": si(ss.displacement_per_period),
            "half_width_m": si(0.5 * (hi - lo)), "periods_used": ss.periods_used,
            "transient_periods": ss.stats["transient_periods"],
            "periods_simulated": ss.stats["periods_simulated"],
            "end_state": ss.state0.tolist(), "cpu_s": time.process_time() - t0}


def _agree(a, b):
    return abs(a["mean_m"] - b["mean_m"]) <= a["half_width_m"] + b["half_width_m"]


def _starts(scene):
    q, v = (np.array(x, float) for x in scene.rest_state())
    tip = float(np.max(np.abs(scene.velocity_scale)))
    out = {"rest": (q, v)}
    for frac in (0.25, 0.5):
        vv = v.copy()
        vv[1] = frac * tip
        out[f"rotor at {frac:g} of the tip speed"] = (q, vv)
    return out


def _start_of(scene, name, report):
    if name in _starts(scene):
        return _starts(scene)[name]
    end = np.asarray(report["moreau_jean_from_rest"]["end_state"])
    return end[:2], end[2:]


def _show(rows, part, start, scheme, r, ref=None):
    rows.append({"part": part, "start": start, "scheme": scheme,
                 **{k: r.get(k) for k in ("status", "mean_m", "half_width_m",
                                          "transient_periods", "periods_used", "cpu_s")}})
    if r["status"] != "converged":
        print(f"  {start:30s} {scheme:20s} {r['status']}")
        return
    err = "" if ref is None else f", {(r['mean_m'] - ref['mean_m']) / ref['mean_m']:+.2e}"
    print(f"  {start:30s} {scheme:20s} {r['mean_m']:.5e} +- {r['half_width_m']:.2e} m{err} "
          f"(transient {r['transient_periods']}, {r['cpu_s']:.1f} CPU s)", flush=True)


def _residence(scene, q, v, steps, periods, threshold, block=1000):
    """Periods Moreau-Jean stays with block means above ``threshold`` (``periods`` if always)."""
    opts = {"h": TWO_PI / steps, "save_every": steps}
    q, v = q.copy(), v.copy()
    done = 0
    while done < periods:
        q[1] = 0.0
        qs, vs, _ = section_states(scene, "moreau-jean", opts, 0.0, q, v, block)
        q, v = qs[-1].copy(), vs[-1].copy()
        if scene.displacement_to_si(qs[-1, 1] / block) < threshold:
            return done
        done += block
    return done


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output folder (created; must not hold results)")
    ap.add_argument("--frequency", type=float, default=15000.0)
    ap.add_argument("--restitution", type=float, default=1.0)
    ap.add_argument("--precision", type=float, default=1e-2,
                    help="relative half-width wanted of the runs from the starts (part 1)")
    ap.add_argument("--fine-precision", type=float, default=1e-3,
                    help="the same for the runs on the regular attractor (parts 2-3)")
    ap.add_argument("--budget", type=int, default=640000, help="periods per statistical run")
    ap.add_argument("--spin-up", type=int, default=30000)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    names = ("statistical_agreement.json", "statistical_agreement.csv",
             "statistical_agreement.png")
    os.makedirs(args.out, exist_ok=True)
    taken = [n for n in names if os.path.exists(os.path.join(args.out, n))]
    if taken:
        ap.error(f"`--out` {args.out!r} already holds {taken[0]}: give an empty folder")

    scene = make_scene("friction-drive", frequency=args.frequency,
                       restitution=args.restitution)
    steps_list = (2000, 8000) if args.quick else (2000, 8000, 32000, 128000)
    budget = min(args.budget, 40000) if args.quick else args.budget
    prec = max(args.precision, 2e-2) if args.quick else args.precision
    fine = max(args.fine_precision, 2e-2) if args.quick else args.fine_precision
    report = {"frequency_hz": args.frequency, "restitution": args.restitution,
              "precision": prec, "fine_precision": fine, "budget_periods": budget, "starts": {}, "schemes": {}}
    rows = []

    print("1. the reference from several starts")
    for name, (q, v) in _starts(scene).items():
        report["starts"][name] = r = _stat(scene, "event-driven", q, v, prec, budget)
        _show(rows, "starts", name, "event-driven", r)
    print("2. Moreau-Jean (2000 steps) from rest, and the reference from where it ended")
    q, v = _starts(scene)["rest"]
    # Moreau-Jean without position projection, as measured in docs/benchmarks.md (the statistical
    # steady state projects by default, as Moreau-Jean's shooting and `moreau steady` do)
    mj = _stat(scene, "moreau-jean", q, v, fine, budget, steps_per_period=2000, projection=False)
    _show(rows, "starts", "rest", "moreau-jean N=2000", mj)
    report["moreau_jean_from_rest"] = mj
    if mj["status"] == "converged":
        end = np.asarray(mj["end_state"])
        name = "Moreau-Jean's end state"
        report["starts"][name] = r = _stat(scene, "event-driven", end[:2], end[2:], fine, budget)
        _show(rows, "starts", name, "event-driven", r)

    # the reference's runs grouped by attractor: means that agree within their intervals
    conv = {n: r for n, r in report["starts"].items() if r["status"] == "converged"}
    groups = []
    for n, r in sorted(conv.items(), key=lambda kv: kv[1]["mean_m"]):
        if groups and _agree(conv[groups[-1][0]], r):
            groups[-1].append(n)
        else:
            groups.append([n])
    report["attractors"] = [{"starts": g, "mean_m": [conv[n]["mean_m"] for n in g]}
                            for g in groups]
    report["starts_agree_per_attractor"] = all(
        _agree(conv[a], conv[b]) for g in groups for a in g for b in g)
    print(f"  {len(groups)} attractor(s) among the reference's runs: "
          + "; ".join(f"{g} at {conv[g[0]]['mean_m']:.4e} m" for g in groups))
    if not groups:
        raise SystemExit("no reference run converged: raise --budget")

    # the schemes compared from one start: the lowest attractor's (Moreau-Jean's end state)
    reg_name = groups[0][0]
    ref = conv[reg_name]
    q, v = _start_of(scene, reg_name, report)
    print(f"3. Moreau-Jean against the reference from {reg_name!r}")
    hs, means = [], []
    for n in steps_list:
        r = _stat(scene, "moreau-jean", q, v, fine, budget, steps_per_period=n, projection=False)
        report["schemes"][f"moreau-jean N={n}"] = r
        _show(rows, "schemes", reg_name, f"moreau-jean N={n}", r, ref)
        if r["status"] == "converged":
            hs.append(TWO_PI / n)
            means.append(r["mean_m"])
    # the order of Moreau-Jean's bias, fitted to log |mean - reference| against log h, and
    # the first step count whose interval overlaps the reference's
    fit = {}
    errs = [abs(m - ref["mean_m"]) for m in means]
    if len(means) >= 2 and all(e > 0 for e in errs):
        p, _ = np.polyfit(np.log(hs), np.log(errs), 1)
        fit["order"] = float(p)
        print(f"  Moreau-Jean's bias falls at order {p:.2f} in the step")
    within = [n for n in steps_list
              if report["schemes"][f"moreau-jean N={n}"]["status"] == "converged"
              and _agree(report["schemes"][f"moreau-jean N={n}"], ref)]
    fit["agreeing_step_counts"] = within
    print("  within the sum of the two intervals' half-widths at N = "
          + (", ".join(map(str, within)) if within else "none of the step counts"))
    report["bias"] = fit

    if len(groups) > 1 and not args.quick:
        print(f"4. Moreau-Jean's residence on the chaotic attractor after {args.spin_up} "
              "reference periods from rest")
        q, v = _starts(scene)["rest"]
        qs, vs, _ = section_states(scene, "event-driven", {}, 0.0, q, v, args.spin_up)
        hi_mean = conv[groups[-1][0]]["mean_m"]
        thr = 0.5 * (ref["mean_m"] + hi_mean)
        res = {}
        for n in (8000, 32000):
            res[n] = _residence(scene, qs[-1].copy(), vs[-1].copy(), n, 60000, thr)
            print(f"  N = {n}: left after {res[n]} periods (block means of 1000 below "
                  f"{thr:.3e} m)")
        report["residence_periods"] = {str(k): v for k, v in res.items()}

    with open(os.path.join(args.out, names[0]), "w") as fh:
        json.dump(report, fh, indent=1)
    with open(os.path.join(args.out, names[1]), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    if hs:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        yerr = [report["schemes"][f"moreau-jean N={n}"].get("half_width_m") for n in steps_list
                if report["schemes"][f"moreau-jean N={n}"]["status"] == "converged"]
        ax.errorbar(hs, means, yerr=yerr, fmt="o-",
                    label="Moreau-Jean" + (f" (bias order {fit['order']:.2f})"
                                           if "order" in fit else ""))
        ax.axhspan(ref["mean_m"] - ref["half_width_m"], ref["mean_m"] + ref["half_width_m"],
                   color="k", alpha=0.2, label="event-driven (95 %)")
        ax.set_xscale("symlog", linthresh=min(hs) / 2)
        ax.set_xlabel("step h (dimensionless)")
        ax.set_ylabel("mean displacement per period (m)")
        ax.set_title(f"{args.frequency / 1000:g} kHz, e = {args.restitution:g}, start: {reg_name}")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, names[2]), dpi=120)
    print("wrote", ", ".join(os.path.join(args.out, n) for n in names if hs or n[-3:] != "png"))


if __name__ == "__main__":
    main()
