"""Where a compiled loop's time goes on reference counts and allocations, sampled by ``perf``.

numba counts the references of its arrays with atomic instructions
(``NRT_incref``, ``NRT_decref``). Where LLVM cannot pair an increment with
its decrement (an array handed to a function inlined at numba's IR level,
a view made every step), each step pays them, and no timing shows it
apart from the arithmetic. This script runs each (scheme, scene) pair
through ``simulate`` in a fresh process, after a warm-up run that compiles
or loads the loop, samples the timed runs with ``perf record -e
cpu-clock:u`` (a software clock: no hardware counters needed), and reports
the share of samples on the two reference-count functions and in the
allocator (numba's ``NRT_MemInfo_*``, ``malloc``, ``free``).

    python benchmarks/refcount_share.py [--scenes bidirectional-drive,sliding-box]
        [--schemes moreau-jean,schatzman-paoli] [--steps 100000] [--shared | --specialised]

Needs ``perf`` and ``kernel.perf_event_paranoid`` at most 2 (profiling
one's own processes); without, it says why and measures nothing. The same
sampling, made by hand, found the counts removed on 2026-11-29
(``docs/benchmarks.md``, "Moreau–Jean against Siconos").
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

#: bytes of machine code from each reference-count function's entry that count as its own
#: (NRT_incref and NRT_decref are a test, a locked add and a return or a tail jump)
NRT_SPAN = 16

CHILD = r"""
import json, math, os, subprocess, sys, time
os.environ["MOREAU_SPECIALISE"] = {specialise!r}
import numba
from numba.core.runtime.nrt import rtsys
from moreau.integrators import simulate
from moreau.model import registry
sc = registry.make_scene({scene!r})
q0, v0 = sc.initial_state()
h = {h!r}
opts = dict(h=h, save_every={steps!r})
simulate(sc, (0.0, 100 * h), q0, v0, {scheme!r}, h=h, save_every=100)
lib = rtsys.library
nrt = {{n: lib.get_pointer_to_function(n) for n in ("NRT_incref", "NRT_decref")}}
perf = subprocess.Popen(["perf", "record", "-q", "-e", "cpu-clock:u", "-o", {data!r},
                         "-p", str(os.getpid())], stderr=subprocess.DEVNULL)
time.sleep(1.0)     # perf attaches before the timed runs
t = time.process_time()
for _ in range({repeats!r}):
    simulate(sc, (0.0, {steps!r} * h), q0, v0, {scheme!r}, **opts)
dt = time.process_time() - t
perf.send_signal(2)
perf.wait()
print(json.dumps({{"steps_per_s": {repeats!r} * {steps!r} / dt, "nrt": nrt}}))
"""


def perf_available():
    """None where ``perf`` can sample this user's processes, else the reason it cannot."""
    if shutil.which("perf") is None:
        return "perf is not installed"
    try:
        with open("/proc/sys/kernel/perf_event_paranoid") as fh:
            level = int(fh.read().strip())
    except (OSError, ValueError):
        return None
    if level > 2:
        return f"kernel.perf_event_paranoid is {level}; sampling one's own processes needs <= 2"
    return None


def classify(samples, nrt):
    """Shares of ``samples`` (``(ip, symbol)``) on reference counts and in allocation."""
    counts = {"refcount": 0, "allocation": 0}
    for ip, sym in samples:
        if any(a <= ip < a + NRT_SPAN for a in nrt.values()):
            counts["refcount"] += 1
        elif sym.startswith("NRT_MemInfo") or sym in ("malloc", "free", "_int_free",
                                                       "_int_malloc", "cfree"):
            counts["allocation"] += 1
    n = max(len(samples), 1)
    return {k: v / n for k, v in counts.items()} | {"samples": len(samples)}


def read_samples(data):
    out = subprocess.run(["perf", "script", "-i", data, "-F", "ip,sym"], capture_output=True,
                         text=True, check=True)
    samples = []
    for line in out.stdout.splitlines():
        parts = line.split(None, 1)
        if not parts:
            continue
        try:
            ip = int(parts[0], 16)
        except ValueError:
            continue
        samples.append((ip, parts[1].strip() if len(parts) > 1 else ""))
    return samples


def measure(scheme, scene, h, steps, repeats, specialise, folder):
    data = os.path.join(folder, f"{scheme}-{scene}.data")
    code = CHILD.format(specialise=specialise, scene=scene, h=h, steps=steps, scheme=scheme,
                        repeats=repeats, data=data)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=1800)
    if run.returncode != 0:
        tail = run.stderr.strip().splitlines()[-1:] or [""]
        return {"error": tail[0]}
    got = json.loads(run.stdout.strip().splitlines()[-1])
    return {"steps_per_s": got["steps_per_s"], **classify(read_samples(data), got["nrt"])}


def positive_int(text):
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text!r}")
    return value


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="bidirectional-drive,sliding-box,bouncing-ball")
    ap.add_argument("--schemes", default="moreau-jean,moreau-jean-projected,schatzman-paoli,"
                                         "time-discontinuous-galerkin,nonsmooth-generalized-alpha")
    ap.add_argument("--h", type=float, default=1e-3, help="step, in the scene's time")
    ap.add_argument("--steps", type=positive_int, default=100_000, help="steps per timed run")
    ap.add_argument("--repeats", type=positive_int, default=3, help="timed runs per pair")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--shared", action="store_const", dest="mode", const="0",
                      help="the scheme's shared loop (a first use; the default)")
    mode.add_argument("--specialised", action="store_const", dest="mode", const="1",
                      help="the scene's own loop (compiled on first use)")
    ap.add_argument("--json", help="write the rows to this file")
    args = ap.parse_args(argv)
    if not args.h > 0.0:
        ap.error(f"--h must be > 0, got {args.h!r}")
    why = perf_available()
    if why:
        print(f"not measured: {why}")
        return 1
    from moreau.model import registry
    scenes = [s for s in args.scenes.split(",") if s]
    unknown = [s for s in scenes if s not in registry.scene_names()]
    if unknown:
        ap.error(f"--scenes: unknown scene(s) {unknown}; known: {registry.scene_names()}")
    rows = []
    print(f"{'scheme':30s} {'scene':22s} {'steps/s':>10s} {'refcount':>9s} {'alloc':>7s}")
    with tempfile.TemporaryDirectory() as folder:
        for scene in scenes:
            h = args.h
            for scheme in [s for s in args.schemes.split(",") if s]:
                t = time.perf_counter()
                r = measure(scheme, scene, h, args.steps, args.repeats, args.mode or "0",
                            folder)
                r.update(scheme=scheme, scene=scene, h=h, wall_s=time.perf_counter() - t)
                rows.append(r)
                if "error" in r:
                    print(f"{scheme:30s} {scene:22s} failed: {r['error']}")
                else:
                    print(f"{scheme:30s} {scene:22s} {r['steps_per_s']:10.3e} "
                          f"{100 * r['refcount']:8.1f}% {100 * r['allocation']:6.1f}%")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
