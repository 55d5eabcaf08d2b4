"""Siconos's one-step integrators on two impact scenes: the peer of ``bench_scheme_family.py``.

Runs under the system interpreter (Debian ``python3-siconos``) and does not
import ``moreau``. One OSI per process (a Siconos assertion aborts the
interpreter): ``/usr/bin/python3 benchmarks/siconos_osis.py CASE OSI [--h H]
[--t-end T]`` prints one JSON object ``{"osi", "case", "steps", "seconds",
"q", "v", "energy_drift"}`` (``energy_drift``: the largest ``|E - E0| / E0``
over the recorded steps) or ``{"osi", "case", "error": ...}``.

Cases, in the dimensionless units of the project's scenes:

``ball``
    the project's bouncing ball: mass 1, gravity 1, radius 0.05, dropped
    from rest with its centre at 1.05, restitution ``--e`` (default 0.5);
    ``q`` is the height of the centre. The free ball is a
    ``LagrangianLinearTIDS`` (``LagrangianLinearDiagonalDS`` with stiffness
    0 makes MoreauJeanBilbaoOSI fail an assertion on a NaN).
``oscillator``
    a unit mass on a unit spring (``q'' = -q``) with a wall at ``q = -0.5``
    (gap ``q + 0.5``), restitution 1, from ``q = 1`` at rest: a conservative
    system with one unilateral contact, energy ``(v^2 + q^2) / 2 = 1/2``.

OSIs: MoreauJeanOSI (theta 1/2, LCP), MoreauJeanGOSI (theta 1/2,
GlobalFrictionContact in 3D with mu = 0, the 3-dof form it requires),
MoreauJeanCombinedProjectionOSI and MoreauJeanDirectProjectionOSI (their
time-stepping variants with MLCPProjectOnConstraints), MoreauJeanBilbaoOSI
(a LagrangianLinearDiagonalDS; oscillator only), LsodarOSI (EventDriven with
impact and acceleration LCPs).
"""

import argparse
import json
import time

OSIS = ("MoreauJeanOSI", "MoreauJeanGOSI", "MoreauJeanCombinedProjectionOSI",
        "MoreauJeanDirectProjectionOSI", "MoreauJeanBilbaoOSI", "LsodarOSI")


def build(case, osi_name, h, t_end, e):
    import numpy as np
    import siconos.kernel as sk

    if case == "ball":
        q0, k, c0 = 1.05, 0.0, -0.05
    else:
        q0, k, c0 = 1.0, 1.0, 0.5
    e = e if case == "ball" else 1.0
    if osi_name == "MoreauJeanGOSI":
        # GlobalFrictionContact wants 3D contacts: the line is the third coordinate
        ds = sk.LagrangianLinearTIDS([0.0, 0.0, q0], [0.0, 0.0, 0.0], np.eye(3))
        if k:
            ds.setKPtr(np.diag([0.0, 0.0, k]))
        else:
            ds.setFExtPtr([0.0, 0.0, -1.0])
        rel = sk.LagrangianLinearTIR([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                                     [c0, 0.0, 0.0])
        law = sk.NewtonImpactFrictionNSL(e, 0.0, 0.0, 3)
    elif osi_name == "MoreauJeanBilbaoOSI":
        if not k:
            raise ValueError("MoreauJeanBilbaoOSI needs a stiffness (it fails an assertion on "
                             "a NaN for the free ball)")
        ds = sk.LagrangianLinearDiagonalDS(np.array([q0]), np.array([0.0]), np.array([k]),
                                           np.array([0.0]), np.array([1.0]))
        rel = sk.LagrangianLinearTIR([[1.0]], [c0])
        law = sk.NewtonImpactNSL(e)
    else:
        ds = sk.LagrangianLinearTIDS([q0], [0.0], [[1.0]])
        if k:
            ds.setKPtr([[k]])
        else:
            ds.setFExtPtr([-1.0])
        rel = sk.LagrangianLinearTIR([[1.0]], [c0])
        law = sk.NewtonImpactNSL(e)
    inter = sk.Interaction(law, rel)
    nsds = sk.NonSmoothDynamicalSystem(0.0, t_end)
    nsds.insertDynamicalSystem(ds)
    nsds.link(inter, ds)
    td = sk.TimeDiscretisation(0.0, h)
    if osi_name == "MoreauJeanOSI":
        sim = sk.TimeStepping(nsds, td, sk.MoreauJeanOSI(0.5), sk.LCP())
    elif osi_name == "MoreauJeanBilbaoOSI":
        sim = sk.TimeStepping(nsds, td, sk.MoreauJeanBilbaoOSI(), sk.LCP())
    elif osi_name == "MoreauJeanGOSI":
        sim = sk.TimeStepping(nsds, td, sk.MoreauJeanGOSI(0.5), sk.GlobalFrictionContact(3))
    elif osi_name == "MoreauJeanCombinedProjectionOSI":
        sim = sk.TimeSteppingCombinedProjection(nsds, td, sk.MoreauJeanCombinedProjectionOSI(0.5),
                                                sk.LCP(), sk.MLCPProjectOnConstraints(), 2)
    elif osi_name == "MoreauJeanDirectProjectionOSI":
        sim = sk.TimeSteppingDirectProjection(nsds, td, sk.MoreauJeanDirectProjectionOSI(0.5),
                                              sk.LCP(), sk.MLCPProjectOnConstraints(), 2)
    elif osi_name == "LsodarOSI":
        sim = sk.EventDriven(nsds, td)
        sim.insertIntegrator(sk.LsodarOSI())
        sim.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_IMPACT)
        sim.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_SMOOTH_ACC)
    else:
        raise ValueError(f"unknown OSI {osi_name!r}; one of {', '.join(OSIS)}")
    return ds, sim, k


def run(case, osi_name, h, t_end, e):
    ds, sim, k = build(case, osi_name, h, t_end, e)

    def energy():
        q, v = float(ds.q()[-1]), float(ds.velocity()[-1])
        return 0.5 * v * v + (0.5 * k * q * q if k else q)

    e0 = energy()
    drift = 0.0
    steps = 0
    event_driven = osi_name == "LsodarOSI"
    t0 = time.perf_counter()
    while sim.hasNextEvent():
        if event_driven:
            sim.advanceToEvent()
            sim.processEvents()
        else:
            sim.computeOneStep()
            sim.nextStep()
        steps += 1
        drift = max(drift, abs(energy() - e0))
    seconds = time.perf_counter() - t0
    return {"osi": osi_name, "case": case, "steps": steps, "seconds": seconds,
            "q": float(ds.q()[-1]), "v": float(ds.velocity()[-1]),
            "energy_drift": drift / abs(e0)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", choices=("ball", "oscillator"))
    ap.add_argument("osi", choices=OSIS)
    ap.add_argument("--h", type=float, default=1e-3)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--e", type=float, default=0.5)
    a = ap.parse_args()
    try:
        out = run(a.case, a.osi, a.h, a.t_end, a.e)
    except Exception as exc:  # a Siconos failure is a result of the comparison
        out = {"osi": a.osi, "case": a.case, "error": f"{type(exc).__name__}: {exc}"}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
