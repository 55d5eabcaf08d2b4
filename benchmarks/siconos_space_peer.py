"""Siconos's 3D Moreau–Jean beside ours on the sphere, the puck and the tippe top: agreement and speed, one run.

Run from the project's venv::

    python benchmarks/siconos_space_peer.py [--steps 1000] [--theta 1] [--repeat 5]
                                            [--no-inversion]

Three registered scenes at their defaults, with Moreau–Jean at the same
``h`` and theta on both sides, from the same start:

- ``sphere-incline`` (:mod:`moreau.scenes.sphere_incline`: slope 0.3 rad,
  ``mu = 0.5``, launched rolling at 0.2 m/s) over its default window (10 units);
- ``puck-incline`` (:mod:`moreau.scenes.puck_incline`: the thin puck lying
  on its face, one contact point at its centre, launched across the slope at 1
  m/s with ``mu = tan(slope)``) over its default window (16 units);
- ``tippe-top`` (:mod:`moreau.scenes.tippe_top`: the eccentric sphere,
  its centre ``a`` above the centre of mass on the symmetry axis, spun at 180
  rad/s, tilted 0.1 rad) over its first 2 units (0.078 s: the slip that ends
  at 0.036 s in the exact motion and the rolling after it).

Siconos runs under the system interpreter (``/usr/bin/python3``, Debian's
``python3-siconos`` 4.4; this file's ``--siconos`` mode, which does not import
``moreau``): a ``NewtonEulerDS`` (centre, unit quaternion ``(w, x, y, z)``,
world velocity, body-frame angular velocity, the same mass and inertia
tensor, the gyroscopic term on), a constant external force ``m g``, Newton's
impact law with 3D Coulomb friction (``NewtonImpactFrictionNSL``, size 3,
restitution 0), the ``MoreauJeanOSI`` at the same theta and the
``FrictionContact(3)`` one-step problem with its default fc3d solver. The
sphere and the puck use Siconos's own ``SphereNEDSPlanR`` (the plane
``z = 0``; the puck as a sphere of radius 0: its contact point is its centre,
as in our model). Siconos has no built-in relation for a sphere whose centre
is off the body's centre of mass, so the tippe top's relation is written here:
a Python subclass of ``NewtonEuler3DR`` (the Debian version's name of
``NewtonEulerFrom3DLocalFrameR``) whose ``computeh`` puts the contact point at
the sphere's lowest point ``x + R_q c - R z`` (``c`` the sphere's centre in
the body frame), the normal ``z`` and the gap ``z_centre - R``; Siconos builds
the contact Jacobian from them. It is checked in every run on the sphere:
with ``c = 0`` it gives Siconos's ``SphereNEDSPlanR`` run bit for bit (a row
under the sphere's). Its ``computeh`` is a Python callback each step, so the
tippe top's Siconos time includes that; the same row measures it (about 25
us a step, more than Siconos's whole step on the sphere). All three scenes
are stated in Siconos's Python API; none is left out. A row under the tippe
top's gives our time a step on Leine and Glocker's top with its contact
patch (``contact_radius=5e-4``: Coulomb–Contensou friction, the exact cone),
which Siconos's frictional contact does not model.

The table gives, per scene, the largest difference over the window between
the two codes (position and velocity [SI], every step; for the tippe top also
the axis height ``cos(theta)``), and the CPU time per step (``process_time``,
the median of ``--repeat`` runs) of ours on the compiled path users get (the
whole ``moreau.simulate(scene, ..., "moreau-jean")`` call, its setup spread
over the steps, the loop compiled beforehand) with the exact cone and with
the default cone (8 facets), of Siconos (its stepping loop only, the model's
construction excluded), and their ratio. Ours with 8 facets is a different problem (the
polyhedral cone), so only the exact cone's agreement is a like-for-like check.

On the tippe top the two codes differ at O(h) (the difference halves with
the step: the row gives it at twice the steps too): they are two first-order
discretisations of the same motion whose rotation enters the contact, while
on the sphere and the puck (whose rotation does not) they agree to rounding.

A last row runs the tippe top over its whole window (100 units, 3.9 s) at
2000 and at 32000 steps on both sides and gives the axis height at the end
and when it first passes horizontal: our Moreau–Jean inverts it at the
coarse step (its dissipation) and not at the fine one, where the exact
motion (rolling after 0.036 s) stays upright; Siconos's ``MoreauJeanOSI``
does the same (2026-11-28: past horizontal at 1.62 s against our 1.49 s at
the coarse step, upright to 4 digits beside ours at the fine one).
The machine's load (``os.getloadavg``) is printed beside the table.
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


# ---------------------------------------------------------------- the Siconos side

def siconos_run(job):
    """The Siconos side (system interpreter): ``job`` states one body on the plane ``z = 0``
    in SI units; one recorded run (every step's state), then ``job["repeat"]`` timed runs."""
    track = _siconos_once(job, record=True)["track"]
    times = [_siconos_once(job, record=False) for _ in range(job.get("repeat", 1))]
    last = times[-1]
    return {"steps": last["steps"], "cpu_seconds": statistics.median(r["cpu_seconds"] for r in times),
            "seconds": statistics.median(r["seconds"] for r in times), "track": track}


def _offset_sphere_relation(sk, np, radius, centre):
    class OffsetSpherePlane(sk.NewtonEuler3DR):
        """A sphere of ``radius`` whose centre is ``centre`` (body frame) from the centre of
        mass, against the plane ``z = 0``: contact point, normal and gap for Siconos."""

        def __init__(self):
            self.radius, self.centre = radius, np.asarray(centre, dtype=float)
            super().__init__()

        def computeh(self, time, q0, y):
            w, x, yq, z = q0[3], q0[4], q0[5], q0[6]
            # the third column of the body-to-world matrix is not enough: c may be any vector
            rot = np.array([[1 - 2 * (yq * yq + z * z), 2 * (x * yq - w * z), 2 * (x * z + w * yq)],
                            [2 * (x * yq + w * z), 1 - 2 * (x * x + z * z), 2 * (yq * z - w * x)],
                            [2 * (x * z - w * yq), 2 * (yq * z + w * x), 1 - 2 * (x * x + yq * yq)]])
            c = np.asarray(q0[0:3]) + rot @ self.centre
            # pc1(), pc2(), nc() are views of Siconos's vectors: written in place (setpc1 from
            # Python crashes the 4.4 bindings)
            p1 = self.pc1()
            p1[0], p1[1], p1[2] = c[0], c[1], c[2] - self.radius
            p2 = self.pc2()
            p2[0], p2[1], p2[2] = c[0], c[1], 0.0
            n = self.nc()
            n[0], n[1], n[2] = 0.0, 0.0, 1.0
            y[0] = c[2] - self.radius

    return OffsetSpherePlane()


def _siconos_once(job, record):
    import numpy as np
    import siconos.kernel as sk
    from siconos.mechanics.collision.bodies import SphereNEDSPlanR

    ds = sk.NewtonEulerDS(np.array(job["q0"], dtype=float), np.array(job["v0"], dtype=float),
                          job["mass"], np.array(job["inertia"], dtype=float))
    ds.setFExtPtr(np.array(job["force"], dtype=float))
    contact = job["contact"]
    if contact["kind"] == "plane":
        rel = SphereNEDSPlanR(contact["radius"], 0.0, 0.0, 1.0, 0.0)
    else:
        rel = _offset_sphere_relation(sk, np, contact["radius"], contact["centre"])
    inter = sk.Interaction(sk.NewtonImpactFrictionNSL(0.0, 0.0, job["mu"], 3), rel)
    T, n = job["window"], job["steps"]
    nsds = sk.NonSmoothDynamicalSystem(0.0, T)
    nsds.insertDynamicalSystem(ds)
    nsds.link(inter, ds)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, T / n), sk.MoreauJeanOSI(job["theta"]),
                          sk.FrictionContact(3))
    track = [list(ds.q()) + list(ds.velocity())] if record else None
    steps = 0
    t0, c0 = time.perf_counter(), time.process_time()
    while sim.hasNextEvent():
        sim.computeOneStep()
        sim.nextStep()
        steps += 1
        if record:
            track.append(list(ds.q()) + list(ds.velocity()))
    seconds, cpu_seconds = time.perf_counter() - t0, time.process_time() - c0
    if not record:
        track = [list(ds.q()) + list(ds.velocity())]
    return {"steps": steps, "seconds": seconds, "cpu_seconds": cpu_seconds, "track": track}


def call_siconos(job):
    """Run ``job`` on the Siconos side; its answer, or ``None`` and the error's tail."""
    done = subprocess.run([SYSTEM_PYTHON, __file__, "--siconos"], input=json.dumps(job),
                          capture_output=True, text=True, timeout=900)
    if done.returncode != 0:
        return None, done.stderr[-2000:]
    return json.loads(done.stdout.splitlines()[-1]), ""


# ---------------------------------------------------------------- our side

def scene_job(sc, window, steps, theta, repeat):
    """The Siconos job of one of our spatial scenes (one body, one contact on ``z = 0``), SI."""
    import numpy as np

    name = sc.name
    L, T, M = sc.length, sc.time, sc.mass
    q0, v0 = sc.initial_state()
    p = sc.params
    if name == "sphere-incline":
        r = p.radius
        inertia = np.eye(3) * 0.4 * p.mass * r * r
        contact = {"kind": "plane", "radius": r}
        g = (p.gravity * math.sin(p.slope), 0.0, -p.gravity * math.cos(p.slope))
    elif name == "puck-incline":
        r = p.radius
        inertia = np.diag([0.25 * p.mass * r * r, 0.25 * p.mass * r * r, 0.5 * p.mass * r * r])
        contact = {"kind": "plane", "radius": 0.0}
        g = (p.gravity * math.sin(p.slope), 0.0, -p.gravity * math.cos(p.slope))
    elif name == "tippe-top":
        inertia = np.diag([p.inertia_transverse, p.inertia_transverse, p.inertia_axial])
        contact = {"kind": "offset", "radius": p.radius, "centre": [0.0, 0.0, p.offset * p.radius]}
        g = (0.0, 0.0, -p.gravity)
    else:
        raise ValueError(f"no Siconos statement of scene {name!r}")
    q = [*(q0[:3] * L), *q0[3:7]]
    v = [*(v0[:3] * L / T), *(v0[3:6] / T)]
    return {"mass": p.mass, "inertia": inertia.tolist(), "q0": [float(x) for x in q],
            "v0": [float(x) for x in v], "force": [p.mass * x for x in g], "contact": contact,
            "mu": p.mu, "window": window * T, "steps": steps, "theta": theta, "repeat": repeat}


def ours(sc, window, steps, theta, cone, repeat, record):
    """Our run on the default (compiled) path: every step's SI state if ``record``, and the
    median CPU time of ``repeat`` timed runs."""
    import numpy as np
    from moreau.integrators import simulate

    q0, v0 = sc.initial_state()
    h = window / steps
    kw = {"theta": theta, "cone": cone}
    simulate(sc, (0.0, window), q0, v0, "moreau-jean", h=window / 20, **kw)  # compile, load
    track = None
    if record:
        res = simulate(sc, (0.0, window), q0, v0, "moreau-jean", h=h, save_every=1, **kw)
        L, T = sc.length, sc.time
        track = np.column_stack([res.q[:, :3] * L, res.q[:, 3:7], res.v[:, :3] * L / T,
                                 res.v[:, 3:6] / T])
    times, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = simulate(sc, (0.0, window), q0, v0, "moreau-jean", h=h, save_every=steps, **kw)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return {"steps": steps, "seconds": statistics.median(times),
            "cpu_seconds": statistics.median(cpu), "track": track, "last_q": res.q[-1]}


def differences(ours_track, peer_track):
    """Largest differences over the window: position [m], velocity [m/s], angular velocity
    [rad/s], axis height ``cos(theta)``."""
    import numpy as np
    from moreau.scenes.tippe_top import axis_height

    a, b = np.asarray(ours_track), np.asarray(peer_track)
    n = min(len(a), len(b))
    a, b = a[:n], b[:n]
    return {"position": float(np.max(np.abs(a[:, :3] - b[:, :3]))),
            "velocity": float(np.max(np.abs(a[:, 7:10] - b[:, 7:10]))),
            "angular": float(np.max(np.abs(a[:, 10:13] - b[:, 10:13]))),
            "axis": float(np.max(np.abs(axis_height(a[:, :7]) - axis_height(b[:, :7])))),
            "rows": n}


SCENES = (("sphere-incline", None), ("puck-incline", None), ("tippe-top", 2.0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1000, help="steps over each window")
    ap.add_argument("--theta", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=5, help="timed runs per side (median)")
    ap.add_argument("--no-inversion", action="store_true",
                    help="leave out the tippe top's whole-window row (2000 and 32000 steps)")
    ap.add_argument("--siconos", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.siconos:
        print(json.dumps(siconos_run(json.load(sys.stdin))))
        return
    from moreau.model.registry import make_scene
    import numpy as np
    from moreau.scenes.tippe_top import axis_height

    loads = [os.getloadavg()[0]]
    print(f"Moreau–Jean, theta = {args.theta:g}, {args.steps} steps over each window; CPU "
          f"time per step, median of {args.repeat} runs; {os.cpu_count()} cores")
    head = (f"{'scene':<15} {'window [s]':>10} {'h [s]':>9} {'max |dx| [m]':>12} "
            f"{'max |dv| [m/s]':>14} {'max |dw| [1/s]':>14} {'max |d cos|':>11} "
            f"{'ours exact [us]':>15} {'ours d=8 [us]':>13} {'Siconos [us]':>12} "
            f"{'x exact':>7} {'x d=8':>6}")
    lines = []
    for name, window in SCENES:
        # Siconos has no drilling friction: the tippe top side by side is the point contact
        sc = make_scene(name, **({"contact_radius": 0.0} if name == "tippe-top" else {}))
        window = sc.default_window if window is None else window
        exact = ours(sc, window, args.steps, args.theta, "exact", args.repeat, record=True)
        facet = ours(sc, window, args.steps, args.theta, 8, args.repeat, record=False)
        peer, err = call_siconos(scene_job(sc, window, args.steps, args.theta, args.repeat))
        loads.append(os.getloadavg()[0])
        if peer is None:
            lines.append(f"{name:<15} not run: {err.strip().splitlines()[-1] if err else '?'}")
            continue
        d = differences(exact["track"], peer["track"])
        us = [1e6 * r["cpu_seconds"] / r["steps"] for r in (exact, facet, peer)]
        axis = f"{d['axis']:11.2e}" if name == "tippe-top" else f"{'':>11}"
        note = " (Siconos: a Python relation)" if name == "tippe-top" else ""
        if name == "tippe-top":
            # the two schemes differ at O(h) here (the rotation enters the contact): the
            # difference at twice the steps, to show that it halves
            half = ours(sc, window, 2 * args.steps, args.theta, "exact", 1, record=True)
            peer2, _ = call_siconos(scene_job(sc, window, 2 * args.steps, args.theta, 1))
            if peer2 is not None:
                d2 = differences(half["track"], peer2["track"])
                note += (f"; at {2 * args.steps} steps max |dx| {d2['position']:.2e}, max |d cos| "
                         f"{d2['axis']:.2e} (ratio {d['position'] / d2['position']:.2f}, "
                         f"{d['axis'] / d2['axis']:.2f})")
        lines.append(f"{name:<15} {window * sc.time:10.4g} {window * sc.time / args.steps:9.2e} "
                     f"{d['position']:12.2e} {d['velocity']:14.2e} {d['angular']:14.2e} {axis} "
                     f"{us[0]:15.1f} {us[1]:13.1f} {us[2]:12.1f} {us[2] / us[0]:7.1f} "
                     f"{us[2] / us[1]:6.1f}{note}")
        if name == "tippe-top":
            # Leine and Glocker's top with its contact patch (Coulomb–Contensou friction, the
            # exact cone only; Siconos has no drilling friction): ours alone, same window
            from moreau.scenes.tippe_top import LEINE_GLOCKER_PATCH
            patched = make_scene(name, contact_radius=LEINE_GLOCKER_PATCH)
            run = ours(patched, window, args.steps, args.theta, "exact", args.repeat,
                       record=False)
            lines.append(f"  (tippe-top with its patch, contact_radius {LEINE_GLOCKER_PATCH:g} m, "
                         f"exact cone: ours {1e6 * run['cpu_seconds'] / run['steps']:.1f} us a "
                         f"step)")
        if name == "sphere-incline":
            # the tippe top's Python relation on the sphere (centre offset 0): the same run
            # as SphereNEDSPlanR's, and the cost of its Python callback
            job = scene_job(sc, window, args.steps, args.theta, args.repeat)
            job["contact"] = {"kind": "offset", "radius": sc.params.radius,
                              "centre": [0.0, 0.0, 0.0]}
            alt, _ = call_siconos(job)
            if alt is not None:
                da = differences(alt["track"], peer["track"])
                ua = 1e6 * alt["cpu_seconds"] / alt["steps"]
                lines.append(f"{'  (Siconos, the Python relation of the tippe top, offset 0: '}"
                             f"max |dx| {da['position']:.1e} m, max |dv| {da['velocity']:.1e} m/s "
                             f"from SphereNEDSPlanR's run; {ua:.1f} us a step, "
                             f"{ua - us[2]:.1f} us of it the Python callback)")
    if not args.no_inversion:
        sc = make_scene("tippe-top", contact_radius=0.0)
        W = sc.default_window
        ends = []
        for n in (2000, 32000):
            run = ours(sc, W, n, args.theta, "exact", 1, record=True)
            peer, err = call_siconos(scene_job(sc, W, n, args.theta, 1))
            loads.append(os.getloadavg()[0])
            h = W * sc.time / n
            cells = []
            for side, track in (("ours", run["track"]),
                                ("Siconos", None if peer is None else peer["track"])):
                if track is None:
                    cells.append(f"{side}: not run")
                    continue
                up = axis_height(np.asarray(track)[:, :7])
                down = np.flatnonzero(up < 0.0)
                when = f"horizontal at {down[0] * h:.3g} s" if down.size else "never horizontal"
                cells.append(f"{side} {up[-1]:+.4f} ({when})")
            ends.append(f"{n} steps (h = {h:.2e} s): " + ", ".join(cells))
        lines.append(f"tippe-top over {W * sc.time:.3g} s, axis height cos(theta) at the end "
                     f"(exact cone): " + "; ".join(ends))
    print(f"load average (1 min) {min(loads):.2f}-{max(loads):.2f}")
    print(head)
    for line in lines:
        print(line)


if __name__ == "__main__":
    main()
