"""Siconos 4.4 Moreau–Jean on the bouncing ball: the benchmark peer of ``bench_moreau_jean.py``.

Runs under the system interpreter (Debian ``python3-siconos``), not the
project's venv, and does not import ``moreau``. Prints one JSON object:
``{"available": bool, "version": str, "bouncing_ball": {"steps_per_s": ...,
"steps": ..., "median_s": ...}}`` or ``{"available": false, "reason": ...}``.

The model is the project's :class:`BouncingBall` in its dimensionless form
(mass 1, gravity 1, radius 0.05, restitution 0.5, dropped from one unit
above the floor), a ``LagrangianLinearTIDS`` with a ``LagrangianLinearTIR``
and ``NewtonImpactNSL``, ``MoreauJeanOSI(theta)`` and an ``LCP`` one-step
problem, stepped with ``computeOneStep()``/``nextStep()``.

Usage::

    /usr/bin/python3 benchmarks/siconos_peer.py [--steps 20000] [--repeats 5] [--theta 1.0]
"""

import argparse
import json
import statistics
import time


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
    t0 = time.perf_counter()
    while sim.hasNextEvent():
        sim.computeOneStep()
        sim.nextStep()
        n += 1
    return n, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--theta", type=float, default=1.0)
    args = ap.parse_args()
    try:
        import siconos
        import siconos.kernel  # noqa: F401
    except Exception as exc:  # any import failure means: no peer here
        print(json.dumps({"available": False, "reason": f"{type(exc).__name__}: {exc}"}))
        return
    # the Debian package reports its release in `siconos.version` (4.4.0+dfsg ships "4.5.0")
    version = str(getattr(siconos, "version", "") or getattr(siconos, "__version__", "") or "?")
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
