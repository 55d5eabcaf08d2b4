"""The stored runs that hold the engine to its results while it is reshaped (issue 35).

Every time-stepping scheme runs every registered scene for ``STEPS`` steps
of ``h = (period or default span) / 1000`` from the scene's initial state,
with the scheme's default options (an adaptive scheme over the same span), and Moreau–Jean also with ``theta = 1/2``
and with ``lcp_method = "lemke"``. For each run the file keeps the SHA-256 of
the full ``t``, ``q``, ``v``, regime and force arrays (the bit-for-bit check)
and every tenth sample of ``t``, ``q``, ``v`` (to say how far a changed run
moved).

Run ``python tests/engine/golden_runs.py`` to write ``tests/data/golden_runs.npz``;
only do so where a change of results is intended and explained. A scene with
joints is run only by the schemes that solve them. A new scene's
runs are added, every stored run kept as it is, by ``python
tests/engine/golden_runs.py --add-missing``.
"""

import hashlib
import json
import os
import platform
import sys

import numpy as np

STEPS = 400
RUNS = [("moreau-jean", {}), ("moreau-jean", {"theta": 0.5}),
        ("moreau-jean", {"lcp_method": "lemke"}), ("schatzman-paoli", {}),
        ("nonsmooth-generalized-alpha", {}), ("studer-extrapolation", {}),
        ("time-discontinuous-galerkin", {})]
SPATIAL_RUNS = [("moreau-jean", {})]
#: the spatial scene whose exact-cone run is stored too (the Python step costs ~1 ms)
SPATIAL_EXACT = "puck-incline"
#: the granular scenes (tests/engine/test_conformance.py's GRANULAR) store no runs: their
#: registered Scene is a start with its contacts fixed, 50 contacts on the generic Python
#: step of every scheme, while their physics runs on moreau.integrators.granular
GRANULAR = {"granular-column", "silo"}
#: scenes whose runs are too dear for the default run's budget: the masonry arch's contact
#: problem is a degenerate friction LCP every step (2 (n + 1) contacts closed at once on
#: 3 n coordinates), 400 steps of six voussoirs cost 0.1-6.6 s of CPU a scheme (20 s in all,
#: measured; four, the default, about half) and Lemke forced on it minutes; its dynamics is
#: held to the thrust-line LP by
#: tests/scenes/test_masonry_arch.py
UNSTORED = {"masonry-arch"}
PATH = os.path.join(os.path.dirname(__file__), "..", "data", "golden_runs.npz")


def key(scene, scheme, options):
    return "|".join([scene, scheme, json.dumps(options, sort_keys=True)])


def machine():
    """What the bits depend on besides the code: CPU, and numpy's and numba's versions."""
    import numba
    flags = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith(("model name", "flags")):
                    flags += line
                if line.startswith("flags"):
                    break
    except OSError:
        flags = platform.processor()
    return hashlib.sha256("|".join([flags, np.__version__, numba.__version__,
                                    platform.machine()]).encode()).hexdigest()


def run(scene_name, scheme, options):
    """``(digest, t, q, v)`` of one run (every tenth sample of t, q, v)."""
    from moreau.integrators import simulate
    from moreau.scenes import registry
    scene = registry.make_scene(scene_name)
    q0, v0 = scene.initial_state()
    h = (scene.period or scene.default_span()) / 1000
    from moreau.integrators.base import get_integrator, scheme_options
    if "h" in (scheme_options(get_integrator(scheme)) or ()):
        options = {"h": h, **options}
    res = simulate(scene, (0.0, STEPS * h), q0, v0, scheme, **options)
    digest = hashlib.sha256()
    for name in ("t", "q", "v", "regime", "force_N", "force_T"):
        digest.update(np.ascontiguousarray(getattr(res, name)).tobytes())
    digest.update(str(res.status).encode())
    return digest.hexdigest(), res.t[::10].copy(), res.q[::10].copy(), res.v[::10].copy()


def all_keys():
    """Every (scene, scheme, options) run; a scheme that solves no joints refuses a scene with
    joints before any work (InputError naming it), so that pair has no run; likewise a
    scheme that steps no spatial scene (``solves_space``). A spatial scene's contact
    problem is the friction cone, not an LCP chosen by ``lcp_method``: its runs are
    Moreau–Jean's default (the 8-direction cone), and on the puck the exact cone too."""
    from moreau.integrators.base import get_integrator
    from moreau.model.scene import is_spatial, joint_row_count
    from moreau.scenes import registry
    out = []
    for s in registry.scene_names():
        if s in GRANULAR or s in UNSTORED:
            continue
        scene = registry.make_scene(s)
        joints = joint_row_count(scene) > 0
        if is_spatial(scene):
            out += [(s, scheme, opts) for scheme, opts in SPATIAL_RUNS]
            if s == SPATIAL_EXACT:
                out.append((s, "moreau-jean", {"cone": "exact"}))
            continue
        out += [(s, scheme, opts) for scheme, opts in RUNS
                if not joints or get_integrator(scheme).solves_joints]
    return out


def write():
    out = {"machine": np.array(machine())}
    for scene, scheme, opts in all_keys():
        k = key(scene, scheme, opts)
        digest, t, q, v = run(scene, scheme, opts)
        out[k + "|digest"] = np.array(digest)
        out[k + "|t"], out[k + "|q"], out[k + "|v"] = t, q, v
        print(k, digest[:12], flush=True)
    np.savez_compressed(PATH, **out)


def add_missing():
    """Store the runs of the keys not in the file yet (new scenes), keeping every stored one."""
    out = dict(np.load(PATH))
    if str(out["machine"]) != machine():
        raise SystemExit("the stored runs were made on another machine: regenerate them all")
    for scene, scheme, opts in all_keys():
        k = key(scene, scheme, opts)
        if k + "|digest" in out:
            continue
        digest, t, q, v = run(scene, scheme, opts)
        out[k + "|digest"] = np.array(digest)
        out[k + "|t"], out[k + "|q"], out[k + "|v"] = t, q, v
        print("added", k, digest[:12], flush=True)
    np.savez_compressed(PATH, **out)


if __name__ == "__main__":
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))
    add_missing() if "--add-missing" in sys.argv[1:] else write()
