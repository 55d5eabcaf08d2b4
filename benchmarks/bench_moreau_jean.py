"""Speed of the compiled Moreau–Jean engine on every shipped scene, side by side with Siconos.

For each scene: the warm rate of the compiled loop (steps per second through
``simulate``, one sample kept) in both of its forms, the scheme's shared loop
(the model called through pointers, compiled once for every scene; what a
first use runs) and the model's specialised loop (compiled for the scene;
what a long run moves to, see ``moreau.integrators._loops``), the rate of the
generic Python path of the same scheme (``fast=False``, the in-process
baseline), and the first call in a fresh process (import, then the numba
cache load or compilation of the first run, timed separately). The peer is Siconos's Moreau–Jean on the
bouncing ball (``benchmarks/siconos_peer.py`` under ``/usr/bin/python3``;
skipped with a note when Siconos is absent), measured again just before each
scene, whose ratios are to that measurement. The goal of issue 9 is every
scene at >= 10x Siconos's bouncing-ball rate.

Every rate is a median over ``--repeats`` runs after a warm-up run. The shared
loop's rate differs from one process to the next by up to a third, and stays
put within one: it follows the address at which the loop's machine code is
loaded (loaded again elsewhere in the same process, the loop changes speed;
new copies of the model's functions or of the data do not change it); the
specialised loop varies less. The shared loop's rate is the median over
``--processes`` fresh processes, with the slowest and the fastest beside it,
and its ratio to Siconos is taken from that median. A scene
whose model holds only for a while from its start (the Painlevé rod falls
flat, :data:`SPANS`) is run at a finer step, so that every timed run stays
inside its valid region. Then
the discrete-map steady state of the friction drive (1000 steps per period)
is timed as before.

Usage::

    python benchmarks/bench_moreau_jean.py [--repeats 5] [--processes 5] [--json out.json]
                                           [--no-first-call] [--scenes friction-drive,bouncing-ball]
                                           [--clock cpu]

``--scenes`` keeps the scenes whose names contain one of the comma-separated
words (the Siconos rows are measured when a scene they compare with is kept).
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

# runnable from a checkout without installing the package
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from moreau.analysis.mj_steady_state import moreau_jean_steady_state
from moreau.integrators import _loops, simulate
# the user scene of the test suite (tests/engine/belt_scene.py), imported as a user would
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "tests", "engine"))
from belt_scene import CompiledBeltBlock  # noqa: E402
from moreau.scenes import (BidirectionalDrive, BouncingBall, FrictionDrive, PainleveRod,
                           SlidingBlock, SlidingBox, StickSlipMotor)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from siconos_replica import replay  # noqa: E402

TWO_PI = 2.0 * math.pi
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# name -> (constructor source, step); the constructors are strings so that
# the fresh-process first-call measurement builds exactly the same scene
USER_SCENE = "belt-block (user hook)"
SCENES = {
    "friction-drive 185 Hz": ("FrictionDrive(frequency=185.0)", TWO_PI / 1000),
    "friction-drive 2000 Hz": ("FrictionDrive(frequency=2000.0)", TWO_PI / 1000),
    "bouncing-ball": ("BouncingBall()", 1e-3),
    "sliding-block": ("SlidingBlock(mu=0.3, incline=0.2)", 1e-3),
    "painleve-rod (mu=0.5)": ("PainleveRod(mu=0.5)", 1e-3),
    "stick-slip-motor": ("StickSlipMotor()", TWO_PI / 1000),
    "bidirectional-drive": ("BidirectionalDrive()", TWO_PI / 1000),
    "sliding-box (2 contacts)": ("SlidingBox()", 1e-3),
    # a user's scene, not registered, through the hook of moreau.compiled (issue 17's
    # goal: >= 1e6 steps/s with one frictional contact)
    USER_SCENE: ("CompiledBeltBlock()", 1e-3),
}
#: scenes whose model holds only for a while from their start: name -> the time span
#: every timed run must fit in (the step is made finer for a long run). The Painlevé
#: rod (mu = 0.5) slides and falls flat, crossing phi = 0 at t = 1.378 where its
#: lower tip stops being its lowest point; every scheme stops there (status -6)
SPANS = {"painleve-rod (mu=0.5)": 1.2}
NAMESPACE = {"FrictionDrive": FrictionDrive, "BouncingBall": BouncingBall,
             "SlidingBlock": SlidingBlock, "PainleveRod": PainleveRod,
             "StickSlipMotor": StickSlipMotor, "BidirectionalDrive": BidirectionalDrive,
             "SlidingBox": SlidingBox, "CompiledBeltBlock": CompiledBeltBlock}


#: the clock of the rates, here and in the Siconos peer: "wall", or "cpu" (the process's CPU
#: time, which a machine shared with other work distorts less; ``--clock``)
CLOCK = "wall"


def _now():
    return time.process_time() if CLOCK == "cpu" else time.perf_counter()


def median_time(fn, repeats):
    fn()                       # warm-up (compilation or cache load, caches)
    times = []
    for _ in range(repeats):
        t0 = _now()
        fn()
        times.append(_now() - t0)
    return statistics.median(times)


def step_for(name, h, nsteps):
    """The step of ``nsteps`` steps of scene ``name``: ``h``, finer where :data:`SPANS` asks."""
    span = SPANS.get(name)
    return h if span is None else min(h, span / nsteps)


def rate(scene, h, nsteps, repeats, **opts):
    q0, v0 = scene.initial_state()
    holder = {}

    def run():
        res = simulate(scene, (0.0, nsteps * h), q0, v0, "moreau-jean", h=h,
                       save_every=nsteps, **opts)
        holder["res"] = res
    med = median_time(run, repeats)
    res = holder["res"]
    if not res.success or res.stats["steps"] != nsteps:
        raise RuntimeError(f"benchmark run failed: {res.message}")
    return nsteps / med, res.stats


FIRST_CALL = r"""
import json, sys, time
t0 = time.perf_counter()
from moreau.integrators import simulate
from moreau.integrators import _loops
import moreau.scenes as scenes
from belt_scene import CompiledBeltBlock
t1 = time.perf_counter()
name = {ctor!r}.split("(")[0]
cls = CompiledBeltBlock if name == "CompiledBeltBlock" else getattr(scenes, name)
sc = eval({ctor!r}, {{name: cls}})
q0, v0 = sc.initial_state()
t2 = time.perf_counter()
res = simulate(sc, (0.0, 10 * {h!r}), q0, v0, "moreau-jean", h={h!r})
t3 = time.perf_counter()
run = _loops.runner_for(sc.compiled_model())
disp = getattr(run, "dispatcher", run)
hits = sum(disp.stats.cache_hits.values())
print(json.dumps({{"import_s": t1 - t0, "first_call_s": t3 - t2, "cache_hit": hits > 0,
                  "ok": bool(res.success)}}))
"""


SHARED_RATE = r"""
import os, sys
os.environ[{env!r}] = "0"
sys.path.insert(0, {here!r})
import bench_moreau_jean as b
b.CLOCK = {clock!r}
sc = eval({ctor!r}, b.NAMESPACE)
print(b.rate(sc, {h!r}, {nsteps!r}, {repeats!r})[0])
"""


def shared_rates(ctor, h, nsteps, repeats, processes):
    """The shared loop's rate (as :func:`rate`) in each of ``processes`` fresh processes."""
    code = SHARED_RATE.format(env=_loops.SPECIALISE_ENV, here=HERE, clock=CLOCK, ctor=ctor, h=h,
                              nsteps=nsteps, repeats=repeats)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    rates = []
    for _ in range(processes):
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, cwd=ROOT, timeout=900)
        if out.returncode != 0:
            raise RuntimeError(f"shared-loop run failed: {out.stderr.strip()[-500:]}")
        rates.append(float(out.stdout.strip().splitlines()[-1]))
    return rates


def first_call(ctor, h, cache_dir=None):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [ROOT, os.path.join(ROOT, "tests", "engine"), os.environ.get("PYTHONPATH", "")]))
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    out = subprocess.run([sys.executable, "-c", FIRST_CALL.format(ctor=ctor, h=h)],
                         capture_output=True, text=True, env=env, cwd=ROOT, timeout=900)
    if out.returncode != 0:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr else "failed"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def siconos_peer(repeats, extra=()):
    exe = "/usr/bin/python3"
    if not os.path.exists(exe):
        return {"available": False, "reason": f"{exe} not found"}
    try:
        out = subprocess.run([exe, os.path.join(HERE, "siconos_peer.py"), "--repeats",
                              str(repeats), "--clock", CLOCK, *extra], capture_output=True, text=True, timeout=900)
        if out.returncode != 0:
            # a negative code is the signal that killed it (-11: segmentation fault)
            tail = out.stderr.strip().splitlines()[-1:] or [""]
            return {"available": False, "reason": f"peer exited with code {out.returncode} "
                                                  f"{tail[0]}".strip()}
        return json.loads(out.stdout.strip().splitlines()[-1])
    except Exception as exc:  # a broken peer must not stop the benchmark
        return {"available": False, "reason": f"{type(exc).__name__}: {exc}"}


# the friction-drive rows compared with Siconos: label -> scene of SCENES
FD_PEER = {"185 Hz": "friction-drive 185 Hz", "2000 Hz": "friction-drive 2000 Hz"}
FD_PEER_STEPS = 20_000


def siconos_friction_drive(repeats):
    """Siconos's Moreau–Jean on the friction drive: ``{label: {...}}`` or ``{"reason": ...}``."""
    params = []
    for label, name in FD_PEER.items():
        sc = eval(SCENES[name][0], NAMESPACE)
        q0, v0 = sc.initial_state()
        params.append({"label": label, "J": sc.J, "P": sc.P, "u10": sc.u10, "fL": sc.fL,
                       "sin_phi0": sc.sin_phi0, "mu": float(sc.mu[0]),
                       "e": float(sc.restitution[0]), "q0": [float(x) for x in q0],
                       "v0": [float(x) for x in v0]})
    peer = siconos_peer(repeats, ("--case", "friction-drive", "--steps", str(FD_PEER_STEPS),
                                  "--fd-params", json.dumps(params)))
    if not peer.get("available"):
        return {"reason": peer.get("reason", "Siconos not available")}
    fd = peer.get("friction_drive", {})
    if fd.get("measured") is False:
        return {"reason": fd.get("reason", "unknown")}
    return fd


def fd_agreement(name, ref):
    """Our compiled run over the peer's steps; differences of the final state to Siconos's."""
    ctor, h = SCENES[name]
    sc = eval(ctor, NAMESPACE)
    q0, v0 = sc.initial_state()
    n = ref["steps"]
    # every step recorded, for the steps without a normal impulse (Siconos's count)
    res = simulate(sc, (0.0, n * h), q0, v0, "moreau-jean", h=h, theta=1.0, save_every=1)
    q, v = res.q[-1], res.v[-1]
    qs, vs = np.asarray(ref["q_end"]), np.asarray(ref["v_end"])
    # Siconos's own linearisation (at the predictor q_k + h v_k) replayed on our scene
    # (siconos_replica.py): what is left of the difference once that is the same
    qr, _ = replay(sc, q0, v0, h, n, at="predictor")
    return {"u2_ours": float(q[1]), "u2_siconos": float(qs[1]),
            "replica_u2_rel_diff": float(abs(qs[1] - qr[1]) / abs(qr[1])),
            "replica_phi_abs_diff": float(abs(qs[0] - qr[0])),
            "u2_rel_diff": float(abs(qs[1] - q[1]) / abs(q[1])),
            "phi_abs_diff": float(abs(qs[0] - q[0])),
            "phi_dot_abs_diff": float(abs(vs[0] - v[0])), "u2_dot_abs_diff": float(abs(vs[1] - v[1])),
            "flight_steps_ours": int(np.count_nonzero(res.force_N[1:, 0] <= 0.0)),
            "flight_steps_siconos": ref["flight_steps"]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=200_000, help="steps per compiled run")
    ap.add_argument("--processes", type=int, default=5,
                    help="fresh processes over which the shared loop's rate is a median")
    ap.add_argument("--json", default=None, help="write the results to this file")
    ap.add_argument("--no-first-call", action="store_true",
                    help="skip the fresh-process first-call measurements")
    ap.add_argument("--scenes", default=None,
                    help="comma-separated words: keep the scenes whose names contain one")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="time the rates (ours and Siconos's) with the wall clock or the "
                         "process's CPU time (for a shared, loaded machine)")
    args = ap.parse_args(argv)
    for flag in ("repeats", "steps", "processes"):
        if getattr(args, flag) < 1:
            ap.error(f"--{flag} must be >= 1, got {getattr(args, flag)}")
    global CLOCK
    CLOCK = args.clock
    R = args.repeats
    scenes = SCENES
    if args.scenes:
        words = [w.strip() for w in args.scenes.split(",") if w.strip()]
        scenes = {k: v for k, v in SCENES.items() if any(w in k for w in words)}
        if not scenes:
            ap.error(f"--scenes {args.scenes!r} matches none of: {', '.join(SCENES)}")
    out = {"repeats": R, "clock": CLOCK, "scenes": {}}

    if not args.no_first_call:
        import tempfile
        print("first call in a fresh process with an empty numba cache (compilation)")
        what = {"friction-drive 185 Hz": "the lean shared Moreau-Jean loop, no Lemke",
                "bidirectional-drive": "the shared Moreau-Jean loop and Lemke's step"}
        out["cold_first_call"] = {}
        for name, compiled in what.items():
            with tempfile.TemporaryDirectory() as tmp:
                ctor, h = SCENES[name]
                cold = first_call(ctor, h, cache_dir=tmp)
            out["cold_first_call"][name] = cold
            if "error" in cold:
                print(f"  {name:26s} failed: {cold['error']}")
            else:
                print(f"  {name:26s} import {cold['import_s']:6.2f} s   first run "
                      f"{cold['first_call_s']:6.2f} s   (compiled: {compiled})")
        print("first call in a fresh process (import; first 10-step run = cache load or compile)")
        for name, (ctor, h) in scenes.items():
            fc = first_call(ctor, h)
            out["scenes"].setdefault(name, {})["first_call"] = fc
            if "error" in fc:
                print(f"  {name:26s} failed: {fc['error']}")
            else:
                print(f"  {name:26s} import {fc['import_s']:6.2f} s   first run "
                      f"{fc['first_call_s']:6.2f} s   ({'cache hit' if fc['cache_hit'] else 'compiled'})")
        print()

    peer = siconos_peer(R)
    out["siconos"] = peer
    if peer.get("available"):
        sic = peer["bouncing_ball"]["steps_per_s"]
        print(f"Siconos {peer['version']} Moreau-Jean, bouncing ball: {sic:.3e} steps/s")
    else:
        sic = None
        print(f"Siconos not available, peer skipped: {peer.get('reason')}")
    want_fd = any(name in scenes for name in FD_PEER.values())
    if not want_fd:
        sic_fd = {"reason": "no friction-drive scene selected"}
    elif peer.get("available"):
        sic_fd = siconos_friction_drive(R)
    else:
        sic_fd = {"reason": "Siconos not available"}
    out["siconos_friction_drive"] = sic_fd
    if "reason" in sic_fd:
        print(f"Siconos Moreau-Jean, friction drive: not measured: {sic_fd['reason']}")
    else:
        for label, r in sic_fd.items():
            print(f"Siconos {peer['version']} Moreau-Jean, friction drive {label}: "
                  f"{r['steps_per_s']:.3e} steps/s")
    print()
    print(f"{'scene':26s} {'shared/s':>10s} {'shared min-max':>15s} {'specialised/s':>13s} "
          f"{'generic/s':>10s} "
          f"{'x generic':>9s} {'Siconos BB/s':>12s} {'x Siconos BB':>12s} {'LCP solves':>10s} "
          f"{'Lemke':>7s} {'warm':>7s}")
    n_gen = 2000
    saved = os.environ.get(_loops.SPECIALISE_ENV)
    for name, (ctor, h) in scenes.items():
        sc = eval(ctor, NAMESPACE)
        if sic:
            # the peer again just before each scene: a machine whose speed drifts by a fifth
            # within minutes (a shared host) otherwise skews the later scenes' ratios
            again = siconos_peer(R)
            if again.get("available"):
                sic = again["bouncing_ball"]["steps_per_s"]
        os.environ[_loops.SPECIALISE_ENV] = "0"       # the shared loop, never moving on
        hs = step_for(name, h, args.steps)
        here, _ = rate(sc, hs, args.steps, R)
        # the shared loop's rate varies by process (module docstring): the median of several
        per_process = shared_rates(ctor, hs, args.steps, R, args.processes)
        shared = statistics.median(per_process)
        os.environ[_loops.SPECIALISE_ENV] = "1"       # the scene's own loop
        fast, st = rate(sc, hs, args.steps, R)
        slow, _ = rate(sc, step_for(name, h, n_gen), n_gen, max(1, R // 2), fast=False)
        row = out["scenes"].setdefault(name, {})
        row.update({"steps_per_s": fast, "shared_steps_per_s": shared,
                    "shared_steps_per_s_processes": per_process,
                    "shared_steps_per_s_this_process": here,
                    "shared_over_specialised": shared / fast, "generic_steps_per_s": slow,
                    "speedup_vs_generic": fast / slow,
                    "ratio_to_siconos_ball": (fast / sic) if sic else None,
                    "siconos_ball_steps_per_s": sic,
                    "lcp_solves": st["lcp_solves"], "direct_solves": st["direct_solves"]})
        # multi-contact solves: by Lemke's pivoting, or warm (in the regimes of the
        # step before, or on the last support) and certified as Lemke's answer
        warm = st["warm_starts"]
        lemke = st["lcp_solves"] - st["direct_solves"] - warm
        row["warm_starts"] = warm
        ratio = f"{sic:12.3e} {fast / sic:12.1f}" if sic else f"{'n/a':>12s} {'n/a':>12s}"
        span = f"{min(per_process) / 1e6:.2f}-{max(per_process) / 1e6:.2f}e6"
        print(f"{name:26s} {shared:10.3e} {span:>15s} {fast:13.3e} {slow:10.3e} "
              f"{fast / slow:9.0f} {ratio} "
              f"{st['lcp_solves']:10d} {lemke:7d} {warm:7d}")
    if saved is None:
        os.environ.pop(_loops.SPECIALISE_ENV, None)
    else:
        os.environ[_loops.SPECIALISE_ENV] = saved
    if USER_SCENE in scenes:
        user = out["scenes"][USER_SCENE]["steps_per_s"]
        out["goal_user_scene_1e6_met"] = bool(user >= 1e6)
        print(f"\ngoal: a user scene through the compiled hook >= 1e6 steps/s: "
              f"{'met' if user >= 1e6 else 'MISSED'} ({user:.2e} steps/s)")
    if sic:
        worst = min(r["ratio_to_siconos_ball"] for r in out["scenes"].values()
                    if "ratio_to_siconos_ball" in r)
        met = worst >= 10.0
        out["goal_10x_siconos_met"] = bool(met)
        print(f"\ngoal: every scene >= 10x Siconos's bouncing-ball rate: "
              f"{'met' if met else 'MISSED'} (worst ratio {worst:.1f})")
        worst_sh = min(r["shared_steps_per_s"] / r["siconos_ball_steps_per_s"]
                       for r in out["scenes"].values() if "shared_steps_per_s" in r)
        out["shared_worst_ratio_to_siconos_ball"] = worst_sh
        print(f"the shared loops (a first use, no compile of the scene's own; the median of "
              f"{args.processes} processes): worst ratio {worst_sh:.1f}")

    print()
    print(f"friction drive vs Siconos's friction drive (h = 2 pi/1000, theta = 1, "
          f"{FD_PEER_STEPS} steps)")
    if "reason" in sic_fd:
        print(f"  not measured: {sic_fd['reason']}")
    else:
        print(f"  {'case':10s} {'Siconos/s':>10s} {'compiled/s':>11s} {'ratio':>7s}   "
              f"final state against Siconos (u2 rel, phi abs, phi' abs, u2' abs; p_N = 0 "
              f"steps ours/Siconos; u2 rel, phi abs with Siconos's linearisation replayed)")
        fd_ratios = []
        for label, r in sic_fd.items():
            name = FD_PEER[label]
            if name not in scenes:
                continue
            ours = out["scenes"][name]["steps_per_s"]
            ratio = ours / r["steps_per_s"]
            fd_ratios.append(ratio)
            agree = fd_agreement(name, r)
            out["scenes"][name].update({"siconos_fd_steps_per_s": r["steps_per_s"],
                                        "ratio_to_siconos_fd": ratio, "siconos_agreement": agree})
            print(f"  {label:10s} {r['steps_per_s']:10.3e} {ours:11.3e} {ratio:7.1f}   "
                  f"{agree['u2_rel_diff']:.1e}, {agree['phi_abs_diff']:.1e}, "
                  f"{agree['phi_dot_abs_diff']:.1e}, {agree['u2_dot_abs_diff']:.1e}; "
                  f"{agree['flight_steps_ours']}/{agree['flight_steps_siconos']}; "
                  f"{agree['replica_u2_rel_diff']:.1e}, {agree['replica_phi_abs_diff']:.1e}")
        met_fd = min(fd_ratios) >= 10.0
        out["goal_fd_10x_siconos_fd_met"] = bool(met_fd)
        print(f"goal: friction drive >= 10x Siconos's friction drive per step: "
              f"{'met' if met_fd else 'MISSED'} (worst ratio {min(fd_ratios):.1f})")
        met_100 = min(fd_ratios) >= 100.0
        out["goal_fd_100x_siconos_fd_met"] = bool(met_100)
        print(f"goal (issue 17): friction drive >= 100x Siconos's friction drive per step: "
              f"{'met' if met_100 else 'MISSED'} (worst ratio {min(fd_ratios):.1f})")

    ss_rows = {}
    for f in (20.0, 185.0, 2000.0) if want_fd else ():
        if not ss_rows:
            print()
            print("steady state of the discrete map, friction drive, 1000 steps/period")
        sc = FrictionDrive(frequency=f)
        holder = {}

        def ss_run():
            holder["ss"] = moreau_jean_steady_state(sc, 1000)
        med = median_time(ss_run, R)
        ss = holder["ss"]
        ss_rows[f"{f:g}"] = med
        print(f"  {f:8g} Hz {med * 1e3:10.2f} ms  {ss.stats['period_maps']:4d} period maps  "
              f"mode {ss.mode}")
    out["steady_state_s"] = ss_rows
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=2, default=float)
    return 0


if __name__ == "__main__":
    np.seterr(all="raise")
    sys.exit(main())
