"""Speed of each compiled scheme on the driver, against a reference checkout, in one process.

The reference (``--reference``, e.g. a checkout of ``main``) is loaded as a
second package, ``moreau_ref``: its ``moreau/`` folder is copied to a
temporary folder under that name (the package imports itself relatively;
the few absolute imports and the registries' import paths are rewritten). Each (scheme, scene) pair is then
run through ``simulate`` by both packages, alternately, and the best CPU time
(``time.process_time``) of ``--repeats`` runs is kept, after a warm-up run
that compiles (or loads from numba's cache) the scheme's shared loop. With
``--specialised`` the models' own loops are timed instead (a compile per
scene and scheme). CPU time, not wall time: the machine may be shared.

Usage::

    python benchmarks/bench_driver_schemes.py --reference /work/main [--repeats 5]
        [--steps 200000] [--schemes schatzman-paoli,moreau-jean] [--scenes bouncing-ball]
"""

import argparse
import hashlib
import importlib
import os
import re
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

SCHEMES = ("moreau-jean", "moreau-jean-projected", "schatzman-paoli",
           "time-discontinuous-galerkin", "nonsmooth-generalized-alpha")
SCENES = ("bouncing-ball", "rocking-block")


def load_reference(root):
    """The package of the checkout ``root`` imported as ``moreau_ref``."""
    src = os.path.join(root, "moreau")
    digest = hashlib.sha256()
    for folder, dirs, names in sorted(os.walk(src)):
        dirs.sort()
        for name in sorted(names):
            if name.endswith(".py"):
                with open(os.path.join(folder, name), "rb") as f:
                    digest.update(name.encode() + f.read())
    # one copy per reference contents: a later run loads its loops from numba's cache
    tmp = os.path.join(tempfile.gettempdir(), "moreau_ref_" + digest.hexdigest()[:16])
    dst = os.path.join(tmp, "moreau_ref")
    sys.path.insert(0, tmp)
    if os.path.isdir(dst):
        return importlib.import_module("moreau_ref")
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("__pycache__"))
    pattern = re.compile(r"^(\s*)(from|import) moreau(\.|\s)", re.M)
    for folder, _, names in os.walk(dst):
        for name in names:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                with open(path) as f:
                    text = f.read()
                new = pattern.sub(r"\1\2 moreau_ref\3", text)
                # the registries' import paths ("moreau.scenes", "module:function" hooks)
                new = re.sub(r"([\"'])moreau\.", r"\1moreau_ref.", new)
                if new != text:
                    with open(path, "w") as f:
                        f.write(new)
    return importlib.import_module("moreau_ref")


def runner(pkg, scene_name, scheme, steps):
    integ = importlib.import_module(pkg.__name__ + ".integrators")
    scene = importlib.import_module(pkg.__name__ + ".scenes").registry.make_scene(scene_name)
    q0, v0 = scene.initial_state()
    h = (scene.period or scene.default_span()) / 1000

    def run():
        return integ.simulate(scene, (0.0, steps * h), q0, v0, scheme, h=h,
                              save_every=steps)
    return run


def best_cpu(run, repeats):
    best = float("inf")
    for _ in range(repeats):
        t = time.process_time()
        res = run()
        best = min(best, time.process_time() - t)
    return best, res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference", required=True)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=200000)
    ap.add_argument("--schemes", default=",".join(SCHEMES))
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--specialised", action="store_true")
    args = ap.parse_args()
    if args.specialised:
        os.environ["MOREAU_SPECIALISE"] = "1"
    import moreau
    ref = load_reference(args.reference)
    print(f"{'scheme':30s} {'scene':15s} {'ref steps/s':>12s} {'new steps/s':>12s} {'new/ref':>8s}")
    for scheme in args.schemes.split(","):
        for scene in args.scenes.split(","):
            runs = {}
            for label, pkg in (("ref", ref), ("new", moreau)):
                try:
                    run = runner(pkg, scene, scheme, args.steps)
                    run()           # compile or load, and warm
                    runs[label] = run
                except Exception as exc:  # a scheme the reference lacks, a refused scene
                    print(f"{scheme:30s} {scene:15s} {label}: {type(exc).__name__}: {exc}")
            best = {label: float("inf") for label in runs}
            for _ in range(args.repeats):      # alternate, so that both see the same load
                for label, run in runs.items():
                    best[label] = min(best[label], best_cpu(run, 1)[0])
            rate = {label: args.steps / t for label, t in best.items()}
            r, nw = rate.get("ref", float("nan")), rate.get("new", float("nan"))
            print(f"{scheme:30s} {scene:15s} {r:12.3g} {nw:12.3g} {nw / r:8.2f}", flush=True)


if __name__ == "__main__":
    main()
