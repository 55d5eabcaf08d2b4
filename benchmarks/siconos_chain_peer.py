"""Siconos's 3D Moreau–Jean beside ours on ``ball-chain-3d``: the spheres' velocities and CPU per step.

Run from the project's venv::

    python benchmarks/siconos_chain_peer.py [--steps 1000] [--repeat 3]

The registered chain at its defaults (three spheres of 0.1 kg and 1 cm, the
striker at 1 m/s, ``e = 1``, ``mu = 0``) over its default window, at the
same ``h`` and ``theta = 1`` on both sides. Siconos runs under the system
interpreter (``/usr/bin/python3``, Debian's ``python3-siconos``; this file's
``--siconos`` mode, which does not import ``moreau``): one ``NewtonEulerDS``
per sphere, its own sphere–sphere relation ``SphereNEDSSphereNEDSR`` between
neighbours, Newton's impact law with 3D Coulomb friction
(``NewtonImpactFrictionNSL(1, 0, 0, 3)``), ``MoreauJeanOSI(1)`` and the
``FrictionContact(3)`` one-step problem with its default fc3d solver.

The table gives each code's velocities along the chain at the end against
the block result ``(2 - N) V / N, 2 V / N`` (the scene's closed form) and
the last sphere's position, and the CPU time per step (``process_time``,
the median of ``--repeat`` runs; ours the whole ``simulate`` call, setup
included): Moreau–Jean's compiled spatial loop on the exact cone, on 8
facets and with the default options (``cone="auto"``), and its Python step
(``fast=False``) on the exact cone; the last column is Siconos's time over
ours.
"""

import argparse
import json
import statistics
import subprocess
import sys
import time

SYSTEM_PYTHON = "/usr/bin/python3"


def _siconos(job):
    import numpy as np
    import siconos.kernel as sk
    from siconos.mechanics.collision.bodies import SphereNEDSSphereNEDSR
    r, m, V, gap, n = job["radius"], job["mass"], job["speed"], job["gap"], job["n"]
    T, steps = job["window"], job["steps"]
    dss = []
    for i in range(n):
        x = 2 * r * (i - 1) - (gap if i == 0 else 0.0)
        dss.append(sk.NewtonEulerDS(np.array([x, 0, 0, 1.0, 0, 0, 0]),
                                    np.array([V if i == 0 else 0.0, 0, 0, 0, 0, 0]), m,
                                    np.eye(3) * 0.4 * m * r * r))
    nsds = sk.NonSmoothDynamicalSystem(0.0, T)
    for ds in dss:
        nsds.insertDynamicalSystem(ds)
    for i in range(n - 1):
        inter = sk.Interaction(sk.NewtonImpactFrictionNSL(job["e"], 0.0, job["mu"], 3),
                               SphereNEDSSphereNEDSR(r, r))
        nsds.link(inter, dss[i], dss[i + 1])
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, T / steps), sk.MoreauJeanOSI(1.0),
                          sk.FrictionContact(3))
    c0 = time.process_time()
    k = 0
    while sim.hasNextEvent():
        sim.computeOneStep()
        sim.nextStep()
        k += 1
    cpu = time.process_time() - c0
    return {"steps": k, "cpu": cpu, "v": [list(ds.velocity())[0] for ds in dss],
            "x_last": list(dss[-1].q())[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    import numpy as np
    from moreau.integrators import simulate
    from moreau.scenes.ball_chain_3d import ball_chain_3d, block_result
    sc = ball_chain_3d()
    p, W = sc.params, sc.default_span()
    q0, v0 = sc.initial_state()
    job = {"radius": p.radius, "mass": p.mass, "speed": p.striker_speed, "gap": p.striker_gap,
           "n": p.n_balls, "e": p.restitution, "mu": p.mu, "window": W * sc.time,
           "steps": args.steps}
    runs = []
    for _ in range(args.repeat):
        done = subprocess.run([SYSTEM_PYTHON, __file__, "--siconos"], input=json.dumps(job),
                              capture_output=True, text=True, timeout=900)
        if done.returncode != 0:
            print("Siconos failed:", done.stderr[-2000:])
            return 1
        runs.append(json.loads(done.stdout.splitlines()[-1]))
    block = block_result(p.n_balls, p.striker_speed)
    sic = runs[-1]
    rows = [("siconos", np.array(sic["v"]), sic["x_last"],
             statistics.median(r["cpu"] / r["steps"] for r in runs))]
    for label, options in (("cone=exact", {"cone": "exact"}), ("cone=8", {"cone": 8}),
                           ("default", {}), ("python step", {"cone": "exact", "fast": False})):
        simulate(sc, (0.0, 0.1), q0, v0, "moreau-jean", h=W / args.steps, **options)
        cpus = []
        for _ in range(args.repeat):
            c0 = time.process_time()
            res = simulate(sc, (0.0, W), q0, v0, "moreau-jean", h=W / args.steps, **options)
            cpus.append((time.process_time() - c0) / args.steps)
        rows.append((f"moreau {label}", res.v[-1, 0::6] * sc.length / sc.time,
                     res.q[-1, 7 * (p.n_balls - 1)] * sc.length, statistics.median(cpus)))
    print(f"ball-chain-3d, {args.steps} steps of {W * sc.time / args.steps:.3g} s; block result "
          f"{np.round(block, 12).tolist()} m/s")
    print(f"{'code':<24}{'max |v - block| [m/s]':>24}{'last sphere x [m]':>20}{'us/step':>10}"
          f"{'x Siconos':>11}")
    for name, v, x, cpu in rows:
        print(f"{name:<24}{np.max(np.abs(v - block)):>24.3g}{x:>20.9f}{cpu * 1e6:>10.1f}"
              f"{rows[0][3] / cpu:>11.2f}")
    print("load average", " ".join(f"{x:.1f}" for x in __import__("os").getloadavg()))
    return 0


if __name__ == "__main__":
    if "--siconos" in sys.argv[1:]:
        print(json.dumps(_siconos(json.loads(sys.stdin.read()))))
    else:
        sys.exit(main())
