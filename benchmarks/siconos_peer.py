"""Siconos 4.4 Moreau–Jean on the bouncing ball and the friction drive: the peer of ``bench_moreau_jean.py``.

Runs under the system interpreter (Debian ``python3-siconos``), not the
project's venv, and does not import ``moreau``. Prints one JSON object:
``{"available": bool, "version": str, "bouncing_ball": {"steps_per_s": ...,
"steps": ..., "median_s": ...}}`` or ``{"available": false, "reason": ...}``
(``--case bouncing-ball``, the default), or with ``--case friction-drive``
``{"available": true, "version": ..., "friction_drive": {label: {...}}}``
where each entry has the rate and the final state (for the caller's check
that Siconos ran the same model), or ``{"measured": false, "reason": ...}``.

The model is the project's :class:`BouncingBall` in its dimensionless form
(mass 1, gravity 1, radius 0.05, restitution 0.5, dropped from one unit
above the floor), a ``LagrangianLinearTIDS`` with a ``LagrangianLinearTIR``
and ``NewtonImpactNSL``, ``MoreauJeanOSI(theta)`` and an ``LCP`` one-step
problem, stepped with ``computeOneStep()``/``nextStep()``.

The friction drive is the project's ``FrictionDrive`` in its dimensionless
form, with the parameters given by the caller (``--fd-params``, a JSON list of
``{"label", "J", "P", "u10", "fL", "sin_phi0", "mu", "e", "q0", "v0"}``): a
``LagrangianDS`` whose forces and a ``LagrangianRheonomousR`` whose gap,
Jacobian and gap rate are C plugins compiled here with ``gcc`` (no compiler:
not measured), ``NewtonImpactFrictionNSL(e, 0, mu, 2)``, ``FrictionContact(2)``
(its default 2D NSGS, exact for one contact), ``MoreauJeanOSI(theta)``,
``h = 2 pi / 1000``, the default Newton loop (one iteration per step here).
The only departure from Siconos's defaults is the constraint activation
threshold of the index set (``--fd-threshold``, 1e-5): Siconos keeps a contact
while ``g + h/2 gdot <= threshold`` (0 by default), moreau while that holds or
the contact carried an impulse in the previous step. At threshold 0 the
velocity-level drift of the curved, moving contact (about 4e-8 per step)
opens the closed contact for one step every few dozen steps (175 spurious
flights in 5 periods at 185 Hz) and the rotor displacement differs by 0.1 %;
1e-5 lies above the drifted gaps of the closed contact (|g| < 7e-6), so both
index sets hold the contact at every step and the runs agree to 4e-4 of the
rotor displacement over 20 000 steps. That is where each scheme linearises its
step: Siconos's Newton loop starts from the predictor ``q_k + h v_k`` and
stops after one iteration, moreau linearises at ``q_k``. Replayed at Siconos's
point on our scene (``benchmarks/siconos_replica.py``) the final states agree
to 7e-14 at 185 and 2000 Hz.

The ball chain (``--case ball-chain``) is the project's ``BallChain`` in its
dimensionless form (radius 1, unit balls, striker mass ratio ``ratio`` at
speed 1, ``gap`` from the resting chain): one ``LagrangianLinearTIDS`` per
ball, one ``LagrangianLinearTIR`` (``y = q_{i+1} - q_i - 2``) with
``NewtonImpactNSL(e)`` per neighbouring pair, ``MoreauJeanOSI(theta)`` and an
``LCP``. ``--chain-params`` (JSON ``{"sizes", "ratio", "e", "gap", "h",
"t_end"}``) sets the runs; each size reports its median time, steps and
final velocities (for the caller's check that Siconos ran the same model).

Usage::

    /usr/bin/python3 benchmarks/siconos_peer.py [--steps 20000] [--repeats 5] [--theta 1.0]
    /usr/bin/python3 benchmarks/siconos_peer.py --case friction-drive --fd-params JSON
    /usr/bin/python3 benchmarks/siconos_peer.py --case ball-chain --chain-params JSON
"""

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import tempfile
import time

#: the clock of every timing: wall time, or the process's CPU time (--clock cpu: a figure
#: a shared, loaded machine distorts less)
CLOCK = time.perf_counter


def bouncing_ball(steps, h, theta):
    import siconos.kernel as sk

    r, e = 0.05, 0.5
    ball = sk.LagrangianLinearTIDS([r + 1.0], [0.0], [[1.0]])
    ball.setFExtPtr([-1.0])
    rel = sk.LagrangianLinearTIR([[1.0]], [-r])
    inter = sk.Interaction(sk.NewtonImpactNSL(e), rel)
    nsds = sk.NonSmoothDynamicalSystem(0.0, steps * h)
    nsds.insertDynamicalSystem(ball)
    nsds.link(inter, ball)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h), sk.MoreauJeanOSI(theta), sk.LCP())
    n = 0
    t0 = CLOCK()
    while sim.hasNextEvent():
        sim.computeOneStep()
        sim.nextStep()
        n += 1
    return n, CLOCK() - t0


# The friction drive (moreau.scenes.friction_drive) as Siconos C plugins. A
# LagrangianRheonomousR built without plugin names has no hDot vector and
# MoreauJeanOSI::computeFreeOutput dereferences it (SIGSEGV, Siconos 4.4;
# python-overridden computehDot cannot allocate it), so the model is compiled
# once per parameter set with gcc into a plugin library. Sign conventions:
# Siconos's LagrangianDS is M q'' + fInt = p, so fInt = -h(q, tau); the
# relation output is y = (gap, tangential position) with Jacobian rows
# WN = (-cos phi, 0), WT = (sin phi, 1) (column-major) and dy/dtau = (-u1', 0).
FD_PLUGIN_C = r"""
#include <math.h>
#define J_   %(J)r
#define P_   %(P)r
#define U10_ %(u10)r
#define FL_  %(fL)r
#define SP0_ %(sin_phi0)r
void fint(double t, unsigned int n, double *q, double *v, double *f, unsigned int nz, double *z)
{
  double s = sin(q[0]), c = cos(q[0]);
  f[0] = -(P_ * c * (SP0_ - s) - 0.5 * U10_ * cos(t) * c);
  f[1] = FL_;
}
void jac_fint_q(double t, unsigned int n, double *q, double *v, double *K, unsigned int nz, double *z)
{
  double s = sin(q[0]), c = cos(q[0]);
  K[0] = -(P_ * (-s * (SP0_ - s) - c * c) + 0.5 * U10_ * cos(t) * s);
  K[1] = 0.0; K[2] = 0.0; K[3] = 0.0;
}
void jac_fint_v(double t, unsigned int n, double *q, double *v, double *K, unsigned int nz, double *z)
{
  K[0] = 0.0; K[1] = 0.0; K[2] = 0.0; K[3] = 0.0;
}
void h(unsigned int n, double *q, double t, unsigned int ny, double *y, unsigned int nz, double *z)
{
  y[0] = SP0_ - sin(q[0]) - U10_ * (1.0 - cos(t));
  y[1] = q[1] - cos(q[0]);
}
void jac_h_q(unsigned int n, double *q, double t, unsigned int ny, double *H, unsigned int nz, double *z)
{
  H[0] = -cos(q[0]); H[1] = sin(q[0]); H[2] = 0.0; H[3] = 1.0;
}
void h_dot(unsigned int n, double *q, double t, unsigned int ny, double *y, unsigned int nz, double *z)
{
  y[0] = -U10_ * sin(t);
  y[1] = 0.0;
}
"""


def build_fd_plugin(par, folder):
    """Compile the friction-drive plugin for one parameter set; returns its path without ``.so``."""
    base = os.path.join(folder, "fd_" + "".join(c if c.isalnum() else "_" for c in par["label"]))
    with open(base + ".c", "w") as fh:
        fh.write(FD_PLUGIN_C % par)
    subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", base + ".so", base + ".c", "-lm"],
                   check=True, capture_output=True, text=True)
    return base


def friction_drive(lib, par, steps, h, theta, threshold, count_flights=False):
    """One Siconos Moreau–Jean run of the friction drive; ``(steps, seconds, q, v, flights)``."""
    import siconos.kernel as sk

    ds = sk.LagrangianDS(list(par["q0"]), list(par["v0"]), [[1.0 / 3.0, 0.0], [0.0, par["J"]]])
    ds.setComputeFIntFunction(lib, "fint")
    ds.setComputeJacobianFIntqFunction(lib, "jac_fint_q")
    ds.setComputeJacobianFIntqDotFunction(lib, "jac_fint_v")
    rel = sk.LagrangianRheonomousR(lib + ":h", lib + ":jac_h_q", lib + ":h_dot")
    inter = sk.Interaction(sk.NewtonImpactFrictionNSL(par["e"], 0.0, par["mu"], 2), rel)
    nsds = sk.NonSmoothDynamicalSystem(0.0, steps * h)
    nsds.insertDynamicalSystem(ds)
    nsds.link(inter, ds)
    osi = sk.MoreauJeanOSI(theta)
    osi.setConstraintActivationThreshold(threshold)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h), osi, sk.FrictionContact(2))
    n = flights = 0
    t0 = CLOCK()
    if count_flights:                 # untimed check run: steps without a normal impulse
        while sim.hasNextEvent():
            sim.computeOneStep()
            flights += inter.lambda_(1)[0] <= 0.0
            sim.nextStep()
            n += 1
    else:
        while sim.hasNextEvent():
            sim.computeOneStep()
            sim.nextStep()
            n += 1
    dt = CLOCK() - t0
    return n, dt, list(ds.q()), list(ds.velocity()), int(flights)


def measure_friction_drive(params, steps, repeats, theta, threshold):
    if shutil.which("gcc") is None:
        return {"measured": False, "reason": "no gcc to compile the Siconos plugins of the model"}
    h = 2.0 * math.pi / 1000
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for par in params:
            try:
                lib = build_fd_plugin(par, tmp)
            except subprocess.CalledProcessError as exc:
                return {"measured": False, "reason": f"gcc failed: {exc.stderr.strip()[-300:]}"}
            # warm-up run, also the check run (final state and flight steps)
            n, _, q, v, flights = friction_drive(lib, par, steps, h, theta, threshold, True)
            times = [friction_drive(lib, par, steps, h, theta, threshold)[1]
                     for _ in range(repeats)]
            med = statistics.median(times)
            out[par["label"]] = {"steps": n, "h": h, "median_s": med, "steps_per_s": n / med,
                                 "theta": theta, "activation_threshold": threshold,
                                 "q_end": q, "v_end": v, "flight_steps": flights}
    return out


def ball_chain(n, ratio, e, gap, h, t_end, theta):
    """One Siconos Moreau–Jean run of the ball chain; ``(steps, seconds, v_end)``."""
    import siconos.kernel as sk

    balls = []
    for i in range(n):
        q = 2.0 * i - 2.0 - (gap if i == 0 else 0.0)
        balls.append(sk.LagrangianLinearTIDS([q], [1.0 if i == 0 else 0.0],
                                             [[ratio if i == 0 else 1.0]]))
    nsds = sk.NonSmoothDynamicalSystem(0.0, t_end)
    for b in balls:
        nsds.insertDynamicalSystem(b)
    for i in range(n - 1):
        # y = q_{i+1} - q_i - 2 over the two balls' stacked coordinates
        rel = sk.LagrangianLinearTIR([[-1.0, 1.0]], [-2.0])
        nsds.link(sk.Interaction(sk.NewtonImpactNSL(e), rel), balls[i], balls[i + 1])
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h), sk.MoreauJeanOSI(theta), sk.LCP())
    k = 0
    t0 = CLOCK()
    while sim.hasNextEvent():
        sim.computeOneStep()
        sim.nextStep()
        k += 1
    dt = CLOCK() - t0
    return k, dt, [float(b.velocity()[0]) for b in balls]


def measure_ball_chain(par, repeats, theta):
    out = {}
    for n in par["sizes"]:
        args = (int(n), par["ratio"], par["e"], par["gap"], par["h"], par["t_end"], theta)
        k, _, v = ball_chain(*args)          # warm-up, and the state for the caller's check
        med = statistics.median(ball_chain(*args)[1] for _ in range(repeats))
        out[str(n)] = {"steps": k, "median_s": med, "us_per_step": med / k * 1e6,
                       "theta": theta, "v_end": v}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--theta", type=float, default=1.0)
    ap.add_argument("--case", choices=("bouncing-ball", "friction-drive", "ball-chain"),
                    default="bouncing-ball")
    ap.add_argument("--chain-params", default='{"sizes": [2, 10], "ratio": 1.0, "e": 1.0, '
                    '"gap": 1.0, "h": 0.01, "t_end": 1.5}', help="JSON of the ball-chain runs")
    ap.add_argument("--fd-params", default="[]", help="JSON list of friction-drive parameter sets")
    ap.add_argument("--fd-threshold", type=float, default=1e-5,
                    help="constraint activation threshold of the index set (see the docstring)")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="time with the wall clock or the process's CPU time")
    args = ap.parse_args()
    global CLOCK
    CLOCK = time.process_time if args.clock == "cpu" else time.perf_counter
    try:
        import siconos
        import siconos.kernel  # noqa: F401
    except Exception as exc:  # any import failure means: no peer here
        print(json.dumps({"available": False, "reason": f"{type(exc).__name__}: {exc}"}))
        return
    # the Debian package reports its release in `siconos.version` (4.4.0+dfsg ships "4.5.0")
    version = str(getattr(siconos, "version", "") or getattr(siconos, "__version__", "") or "?")
    if args.case == "friction-drive":
        fd = measure_friction_drive(json.loads(args.fd_params), args.steps, args.repeats,
                                    args.theta, args.fd_threshold)
        print(json.dumps({"available": True, "version": version, "friction_drive": fd}))
        return
    if args.case == "ball-chain":
        chain = measure_ball_chain(json.loads(args.chain_params), args.repeats, args.theta)
        print(json.dumps({"available": True, "version": version, "ball_chain": chain}))
        return
    bouncing_ball(200, 1e-3, args.theta)      # warm-up
    times = []
    n = 0
    for _ in range(args.repeats):
        n, dt = bouncing_ball(args.steps, 1e-3, args.theta)
        times.append(dt)
    med = statistics.median(times)
    print(json.dumps({"available": True, "version": version,
                      "bouncing_ball": {"steps": n, "median_s": med, "steps_per_s": n / med,
                                        "theta": args.theta}}))


if __name__ == "__main__":
    main()
