"""Siconos's 3D Moreau–Jean beside ours on the sphere on an incline: agreement and steps/s, one run.

Run from the project's venv::

    python benchmarks/siconos_space_peer.py [--steps 1000] [--theta 1] [--repeat 5]

It runs :mod:`moreau.scenes.sphere_incline` at its defaults (slope 0.3 rad,
``mu = 0.5``, launched rolling at 0.2 m/s; it rolls at ``(5/7) g sin(alpha)``)
with Moreau–Jean and the exact cone and with the 8-direction cone, then the
same problem in Siconos under the system interpreter (``/usr/bin/python3``,
Debian's ``python3-siconos``; this file's ``--siconos`` mode, which does not
import ``moreau``): a ``SphereNEDS`` (Newton–Euler sphere: centre, unit
quaternion, body-frame angular velocity) on the plane ``z = 0`` of a
``SphereNEDSPlanR`` relation, gravity tilted by the slope, Newton's impact
law with 3D Coulomb friction (``NewtonImpactFrictionNSL``, size 3), the
``MoreauJeanOSI`` at the same theta and the ``FrictionContact(3)`` one-step
problem with its default fc3d solver. The table gives, for each, the
distance and speed down the slope at the end of the window against the
closed form, and the steps per second (wall clock of the stepping loop
only; construction excluded) and per CPU second of the process (steadier on a
shared machine), the medians of ``--repeat`` runs on each side.
Ours runs on the compiled spatial loop (the default) and, for the exact
cone, on the Python step too (``fast=False``, the reference), with the
machine's load (``os.getloadavg``) printed beside the table.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

SYSTEM_PYTHON = "/usr/bin/python3"


def siconos_run(job):
    """The Siconos side (system interpreter): ``job`` is the problem in SI units, run
    ``job["repeat"]`` times; the last run's state and the median time."""
    times, cpu = [], []
    for _ in range(job.get("repeat", 1)):
        row = _siconos_once(job)
        times.append(row["seconds"])
        cpu.append(row["cpu_seconds"])
    row["seconds"], row["cpu_seconds"] = statistics.median(times), statistics.median(cpu)
    return row


def _siconos_once(job):
    import numpy as np
    import siconos.kernel as sk
    from siconos.mechanics.collision.bodies import SphereNEDS, SphereNEDSPlanR

    g, a, r, m = job["gravity"], job["slope"], job["radius"], job["mass"]
    ds = SphereNEDS(r, m, np.eye(3) * 0.4 * m * r * r, [0.0, 0.0, r, 1.0, 0.0, 0.0, 0.0],
                    [job["speed"], 0.0, 0.0, 0.0, job["speed"] / r, 0.0])
    ds.setFExtPtr(np.array([m * g * math.sin(a), 0.0, -m * g * math.cos(a)]))
    inter = sk.Interaction(sk.NewtonImpactFrictionNSL(0.0, 0.0, job["mu"], 3),
                           SphereNEDSPlanR(r, 0.0, 0.0, 1.0, 0.0))
    T, n = job["window"], job["steps"]
    nsds = sk.NonSmoothDynamicalSystem(0.0, T)
    nsds.insertDynamicalSystem(ds)
    nsds.link(inter, ds)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, T / n), sk.MoreauJeanOSI(job["theta"]),
                          sk.FrictionContact(3))
    steps = 0
    t0, c0 = time.perf_counter(), time.process_time()
    while sim.hasNextEvent():
        sim.computeOneStep()
        sim.nextStep()
        steps += 1
    seconds, cpu_seconds = time.perf_counter() - t0, time.process_time() - c0
    q, v = list(ds.q()), list(ds.velocity())
    return {"steps": steps, "seconds": seconds, "cpu_seconds": cpu_seconds, "distance": q[0],
            "speed": v[0],
            "quaternion_norm": math.sqrt(sum(x * x for x in q[3:7]))}


def ours(steps, theta, cone, fast="auto", repeat=1):
    from moreau.integrators import simulate
    from moreau.scenes.sphere_incline import sphere_incline
    sc = sphere_incline()
    q0, v0 = sc.initial_state()
    span = sc.default_window
    simulate(sc, (0.0, span), q0, v0, "moreau-jean", h=span / 20, theta=theta, cone=cone,
             fast=fast)  # load
    times, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = simulate(sc, (0.0, span), q0, v0, "moreau-jean", h=span / steps, theta=theta,
                       cone=cone, save_every=steps, fast=fast)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    seconds = statistics.median(times)
    return sc, {"steps": steps, "seconds": seconds, "cpu_seconds": statistics.median(cpu), "distance": res.q[-1, 0] * sc.length,
                "speed": res.v[-1, 0] * sc.length / sc.time,
                "quaternion_norm": float(sum(x * x for x in res.q[-1, 3:7]) ** 0.5)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--theta", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=5, help="runs per side (median time)")
    ap.add_argument("--siconos", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.siconos:
        print(json.dumps(siconos_run(json.load(sys.stdin))))
        return
    from moreau.scenes.sphere_incline import sphere_incline_exact
    rows = []
    load = os.getloadavg()[0]
    for cone in ("exact", 8):
        sc, row = ours(args.steps, args.theta, cone, repeat=args.repeat)
        rows.append((f"moreau-jean cone={cone}", row))
    _, row = ours(args.steps, args.theta, "exact", fast=False, repeat=max(1, args.repeat // 2))
    python_row = ("moreau-jean cone=exact, Python step", row)
    p = sc.params
    window = sc.default_window * sc.time
    job = {"gravity": p.gravity, "slope": p.slope, "radius": p.radius, "mass": p.mass,
           "mu": p.mu, "speed": p.speed, "window": window, "steps": args.steps,
           "theta": args.theta, "repeat": args.repeat}
    done = subprocess.run([SYSTEM_PYTHON, __file__, "--siconos"], input=json.dumps(job),
                          capture_output=True, text=True, timeout=600)
    if done.returncode == 0:
        rows.append(("siconos MoreauJeanOSI + fc3d", json.loads(done.stdout.splitlines()[-1])))
    else:
        print(f"siconos run failed: {done.stderr[-2000:]}")
    rows.insert(2, python_row)
    load = max(load, os.getloadavg()[0])
    s, sd, _ = sphere_incline_exact(p, [window])
    print(f"sphere-incline, {args.steps} steps over {window:.4g} s, theta = {args.theta:g}: "
          f"closed form s = {s[0]:.9g} m, s' = {sd[0]:.9g} m/s; median of {args.repeat} runs, "
          f"load average {load:.2f} on {os.cpu_count()} cores")
    print(f"{'run':<38} {'s error [m]':>12} {'speed error [m/s]':>17} {'|q|-1':>9} "
          f"{'steps/s':>9} {'CPU steps/s':>11}")
    for name, r in rows:
        print(f"{name:<38} {r['distance'] - s[0]:12.3e} {r['speed'] - sd[0]:17.3e} "
              f"{r['quaternion_norm'] - 1.0:9.1e} {r['steps'] / r['seconds']:9.0f} "
              f"{r['steps'] / r['cpu_seconds']:11.0f}")
    if len(rows) == 4:
        a, p, b = rows[0][1], rows[2][1], rows[3][1]
        d8 = rows[1][1]
        rate = {k: r["seconds"] for k, r in (("a", a), ("d", d8), ("p", p))}
        cpu = {k: r["cpu_seconds"] for k, r in (("a", a), ("d", d8), ("p", p))}
        print(f"agreement (ours exact vs Siconos): s differs by "
              f"{abs(a['distance'] - b['distance']):.3e} m, the speed by "
              f"{abs(a['speed'] - b['speed']):.3e} m/s")
        print("steps/s ours/Siconos (wall; CPU): exact cone "
              f"{b['seconds'] / rate['a']:.2f}; {b['cpu_seconds'] / cpu['a']:.2f}, cone=8 "
              f"{b['seconds'] / rate['d']:.2f}; {b['cpu_seconds'] / cpu['d']:.2f}, the Python "
              f"step {b['seconds'] / rate['p']:.2f}; {b['cpu_seconds'] / cpu['p']:.2f}")


if __name__ == "__main__":
    main()
