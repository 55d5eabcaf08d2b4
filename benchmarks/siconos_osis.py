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

``friction-drive``
    the project's friction drive (``moreau.scenes.friction_drive``) in its
    dimensionless form, parameters from ``--fd-params`` (JSON ``{"label",
    "J", "P", "u10", "fL", "sin_phi0", "mu", "e", "q0", "v0"}``), ``h = 2 pi
    / 1000`` over ``--periods`` drive periods; prints, besides the final
    state, ``u2_periods`` (the rotor position at each period's end) for the
    caller's displacement per period. Built as in ``siconos_peer.py`` (C
    plugins, ``LagrangianRheonomousR``, ``NewtonImpactFrictionNSL(e, 0, mu,
    2)``, ``FrictionContact(2)``, activation threshold 1e-5 for
    MoreauJeanOSI). MoreauJeanGOSI takes a 3D contact: a third, free unit
    mass carries the second tangent, and GlobalFrictionContact(3) with
    NSGS_WR (the default NSGS does not converge: a solver warning at every
    step, 5 periods not done in 300 s). MoreauJeanBilbaoOSI needs a
    LagrangianLinearDiagonalDS, a linear modal system: the drive's forces
    are nonlinear in ``phi``, so it is reported as not applicable. LsodarOSI
    is tried as for the ball (EventDriven with impact and acceleration LCPs,
    which take no friction law).

OSIs: MoreauJeanOSI (theta 1/2, LCP), MoreauJeanGOSI (theta 1/2,
GlobalFrictionContact in 3D with mu = 0, the 3-dof form it requires),
MoreauJeanCombinedProjectionOSI and MoreauJeanDirectProjectionOSI (their
time-stepping variants with MLCPProjectOnConstraints), MoreauJeanBilbaoOSI
(a LagrangianLinearDiagonalDS; oscillator only), LsodarOSI (EventDriven with
impact and acceleration LCPs).
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import tempfile
import time

# the friction drive's 2-dof plugin (forces, gap, Jacobian, gap rate) as the peer builds it
from siconos_peer import build_fd_plugin

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


# the friction drive embedded in 3 dof for GlobalFrictionContact(3): a free unit mass q[2]
# carries the second tangent direction (it stays at rest: no force drives it)
FD3_PLUGIN_C = r"""
#include <math.h>
#define P_   %(P)r
#define U10_ %(u10)r
#define FL_  %(fL)r
#define SP0_ %(sin_phi0)r
void fint(double t, unsigned int n, double *q, double *v, double *f, unsigned int nz, double *z)
{
  double s = sin(q[0]), c = cos(q[0]);
  f[0] = -(P_ * c * (SP0_ - s) - 0.5 * U10_ * cos(t) * c);
  f[1] = FL_;
  f[2] = 0.0;
}
void jac_fint_q(double t, unsigned int n, double *q, double *v, double *K, unsigned int nz, double *z)
{
  double s = sin(q[0]), c = cos(q[0]);
  int i;
  for (i = 0; i < 9; i++) K[i] = 0.0;
  K[0] = -(P_ * (-s * (SP0_ - s) - c * c) + 0.5 * U10_ * cos(t) * s);
}
void jac_fint_v(double t, unsigned int n, double *q, double *v, double *K, unsigned int nz, double *z)
{
  int i;
  for (i = 0; i < 9; i++) K[i] = 0.0;
}
void h(unsigned int n, double *q, double t, unsigned int ny, double *y, unsigned int nz, double *z)
{
  y[0] = SP0_ - sin(q[0]) - U10_ * (1.0 - cos(t));
  y[1] = q[1] - cos(q[0]);
  y[2] = q[2];
}
void jac_h_q(unsigned int n, double *q, double t, unsigned int ny, double *H, unsigned int nz, double *z)
{
  int i;
  for (i = 0; i < 9; i++) H[i] = 0.0;
  H[0] = -cos(q[0]); H[1] = sin(q[0]); H[4] = 1.0; H[8] = 1.0;
}
void h_dot(unsigned int n, double *q, double t, unsigned int ny, double *y, unsigned int nz, double *z)
{
  y[0] = -U10_ * sin(t);
  y[1] = 0.0;
  y[2] = 0.0;
}
"""

FD_STEPS_PER_PERIOD = 1000


def build_friction_drive(osi_name, par, periods, folder):
    import numpy as np
    import siconos.kernel as sk
    import siconos.numerics as sn

    if osi_name == "MoreauJeanBilbaoOSI":
        raise ValueError("MoreauJeanBilbaoOSI integrates a LagrangianLinearDiagonalDS (linear "
                         "modal system); the friction drive's forces are nonlinear in phi")
    h = 2.0 * math.pi / FD_STEPS_PER_PERIOD
    if osi_name == "MoreauJeanGOSI":
        base = os.path.join(folder, "fd3")
        with open(base + ".c", "w") as fh:
            fh.write(FD3_PLUGIN_C % par)
        subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", base + ".so", base + ".c",
                        "-lm"], check=True, capture_output=True, text=True)
        lib, q0, v0 = base, list(par["q0"]) + [0.0], list(par["v0"]) + [0.0]
        mass = np.diag([1.0 / 3.0, par["J"], 1.0])
        law = sk.NewtonImpactFrictionNSL(par["e"], 0.0, par["mu"], 3)
    else:
        lib, q0, v0 = build_fd_plugin(par, folder), list(par["q0"]), list(par["v0"])
        mass = [[1.0 / 3.0, 0.0], [0.0, par["J"]]]
        law = sk.NewtonImpactFrictionNSL(par["e"], 0.0, par["mu"], 2)
    ds = sk.LagrangianDS(q0, v0, mass)
    ds.setComputeFIntFunction(lib, "fint")
    ds.setComputeJacobianFIntqFunction(lib, "jac_fint_q")
    ds.setComputeJacobianFIntqDotFunction(lib, "jac_fint_v")
    rel = sk.LagrangianRheonomousR(lib + ":h", lib + ":jac_h_q", lib + ":h_dot")
    inter = sk.Interaction(law, rel)
    nsds = sk.NonSmoothDynamicalSystem(0.0, periods * FD_STEPS_PER_PERIOD * h)
    nsds.insertDynamicalSystem(ds)
    nsds.link(inter, ds)
    td = sk.TimeDiscretisation(0.0, h)
    if osi_name == "MoreauJeanOSI":
        osi = sk.MoreauJeanOSI(0.5)
        # see siconos_peer.py: at threshold 0 the drifted closed contact opens spuriously
        osi.setConstraintActivationThreshold(1e-5)
        sim = sk.TimeStepping(nsds, td, osi, sk.FrictionContact(2))
    elif osi_name == "MoreauJeanGOSI":
        sim = sk.TimeStepping(nsds, td, sk.MoreauJeanGOSI(0.5),
                              sk.GlobalFrictionContact(3, sn.SICONOS_GLOBAL_FRICTION_3D_NSGS_WR))
    elif osi_name == "MoreauJeanCombinedProjectionOSI":
        sim = sk.TimeSteppingCombinedProjection(nsds, td, sk.MoreauJeanCombinedProjectionOSI(0.5),
                                                sk.FrictionContact(2),
                                                sk.MLCPProjectOnConstraints(), 2)
    elif osi_name == "MoreauJeanDirectProjectionOSI":
        sim = sk.TimeSteppingDirectProjection(nsds, td, sk.MoreauJeanDirectProjectionOSI(0.5),
                                              sk.FrictionContact(2),
                                              sk.MLCPProjectOnConstraints(), 2)
    elif osi_name == "LsodarOSI":
        sim = sk.EventDriven(nsds, td)
        sim.insertIntegrator(sk.LsodarOSI())
        sim.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_IMPACT)
        sim.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_SMOOTH_ACC)
    else:
        raise ValueError(f"unknown OSI {osi_name!r}; one of {', '.join(OSIS)}")
    return ds, sim, h


def run_friction_drive(osi_name, par, periods):
    if shutil.which("gcc") is None:
        raise RuntimeError("no gcc to compile the Siconos plugins of the model")
    with tempfile.TemporaryDirectory() as tmp:
        ds, sim, h = build_friction_drive(osi_name, par, periods, tmp)
        event_driven = osi_name == "LsodarOSI"
        u2 = [float(ds.q()[1])]
        steps = 0
        t0 = time.perf_counter()
        while sim.hasNextEvent():
            if event_driven:
                sim.advanceToEvent()
                sim.processEvents()
            else:
                sim.computeOneStep()
                sim.nextStep()
            steps += 1
            if not event_driven and steps % FD_STEPS_PER_PERIOD == 0:
                u2.append(float(ds.q()[1]))
        seconds = time.perf_counter() - t0
        q, v = list(ds.q()), list(ds.velocity())
    return {"osi": osi_name, "case": "friction-drive", "label": par["label"], "steps": steps,
            "h": h, "seconds": seconds, "q": q[:2], "v": v[:2], "u2_periods": u2}


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
    ap.add_argument("case", choices=("ball", "oscillator", "friction-drive"))
    ap.add_argument("osi", choices=OSIS)
    ap.add_argument("--h", type=float, default=1e-3)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--e", type=float, default=0.5)
    ap.add_argument("--fd-params", default=None, help="friction drive: JSON of the parameters")
    ap.add_argument("--periods", type=int, default=20, help="friction drive: drive periods")
    a = ap.parse_args()
    try:
        if a.case == "friction-drive":
            out = run_friction_drive(a.osi, json.loads(a.fd_params), a.periods)
        else:
            out = run(a.case, a.osi, a.h, a.t_end, a.e)
    except Exception as exc:  # a Siconos failure is a result of the comparison
        out = {"osi": a.osi, "case": a.case, "error": f"{type(exc).__name__}: {exc}"}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
