"""Why the silo's floor load is not Janssen's within 10 %: the walls' friction, measured.

``python benchmarks/silo_janssen_probe.py rest [--seed S] [--pours P]`` fills the silo
(:func:`moreau.scenes.silo.fill`) and prints the floor's Janssen fit and the profile at
rest of the last pour (:func:`moreau.scenes.silo.wall_profile`): the load across cuts
every ``2 d``, the walls' mobilised friction, the stress ratio at the walls.

``... slide [--seed S] [--pours P] [--steps N]`` pours without sliding the walls, then
slides them up for ``N`` steps and averages the cut profile over the last two thirds
(the profile of a moving column, Vanel and Clement's protocol).

``... roll [--seed S] [--pours P]`` slides the walls under a few pours for 100 steps and
prints each wall contact: its normal force, ``T / (mu_w N)``, the disk's ``v_y`` and
``omega r`` and the slip ``u_T`` at the wall (0: the disk rolls or climbs with the wall).

``--mu-r M`` gives every contact a rolling-resistance length of ``M`` grain diameters;
``--scatter S`` (``rest``, ``slide``) pours each disk with a horizontal speed uniform in ``[-S, S]``.

Minutes a run on one core (12 pours of 30 disks: 6 to 17 minutes, the machine's load).
The figures are the silo module's docstring's.
"""

import argparse
import math
import time

import numpy as np

from moreau.integrators.granular import settle, simulate_disks
from moreau.model.granular import random_fill
from moreau.scenes.silo import SiloParams, fill, fit_janssen, silo_system, wall_profile


def _pour(p, pours, h=0.01, tol=1e-6, scatter=0.0):
    """Pours that settle with the walls at rest (no slide); the state and the last impulses."""
    W = p.width / p.diameter
    x, v, phi, radii = np.zeros((0, 2)), np.zeros((0, 3)), np.zeros(0), np.zeros(0)
    warm, top = None, 0.0
    for k in range(pours):
        r_new, x_new = random_fill(p.per_pour, W, 0.5 * p.spread, 0.5, y0=top + 0.2,
                                   seed=p.seed + 7919 * k)
        radii = np.concatenate([radii, r_new])
        x = np.concatenate([x, x_new])
        v_new = np.zeros((p.per_pour, 3))
        if scatter > 0.0:
            # (the same draws as fill's)
            v_new[:, 0] = np.random.default_rng(p.seed + 7919 * k + 1).uniform(
                -scatter, scatter, p.per_pour)
        v = np.concatenate([v, v_new])
        phi = np.concatenate([phi, np.zeros(p.per_pour)])
        run = settle(silo_system(radii, p), x, v, h, phi0=phi, warm=warm, max_steps=1500,
                     speed_tol=2e-3, theta=1.0, tol=100 * tol, max_sweeps=500)
        x, v, phi, warm = run.x[-1], run.v[-1], run.phi[-1], run.impulses
        top = float(np.max(x[:, 1] + radii))
    return radii, x, v, phi, warm


def _show_fit(label, mass, m_app, rho, W, mu_wall):
    f = fit_janssen(mass, m_app, rho=rho, width=W, mu_wall=mu_wall)
    rms = math.sqrt(float(np.mean(f["deviation"] ** 2)))
    print(f"{label}: K = {f['K']:.3f}, worst deviation {f['max_deviation']:.1%}, rms {rms:.1%}")
    return f


def rest(p, pours, scatter=0.0):
    t0 = time.process_time()
    r = fill(pours, p, scatter=scatter)
    print(f"fill: {time.process_time() - t0:.0f} s CPU, {int(np.sum(r['unconverged']))} weighing "
          f"steps above tol (worst residual {np.max(r['max_residual']):.1e})")
    print("pour   mass   m_app  wall_friction/(mu_w wall_normal)")
    for row in zip(range(1, r["mass"].size + 1), r["mass"], r["m_app"],
                   r["wall_friction"] / (p.mu_wall * r["wall_normal"])):
        print("{:4d} {:7.1f} {:7.1f} {:9.3f}".format(*row))
    W = r["width"]
    _show_fit("floor against the poured mass", r["mass"], r["m_app"], r["rho"], W, p.mu_wall)
    prof = r["profile"]
    f = _show_fit("cuts against the mass above", prof["mass"], prof["m_app"], r["rho"], W,
                  p.mu_wall)
    print("depth   mass   m_app  mobilised  deviation   K_band (below the cut)")
    kb = np.append(prof["K_band"], np.nan)
    for row in zip(prof["depth"], prof["mass"], prof["m_app"], prof["mobilised"],
                   f["deviation"], kb):
        print("{:5.1f} {:7.1f} {:7.1f} {:9.3f} {:9.3f} {:9.3f}".format(*row))


def slide(p, pours, steps, V=0.05, h=0.01, tol=1e-5, chunk=5, dz=2.0, scatter=0.0):
    t0 = time.process_time()
    radii, x, v, phi, warm = _pour(p, pours, h, scatter=scatter)
    moving = silo_system(radii, p, wall_speed=V)
    acc = None
    n = unconverged = 0
    for c in range(steps // chunk):
        run = simulate_disks(moving, x, v, chunk, h, phi0=phi, warm=warm, save_every=chunk,
                             theta=1.0, tol=tol, max_sweeps=1000)
        unconverged += run.unconverged.size
        x, v, phi, warm = run.x[-1], run.v[-1], run.phi[-1], run.impulses
        if 3 * c * chunk < steps:
            continue
        prof = wall_profile(moving, x, warm, h, dz=dz)
        if acc is None:
            depth = prof["depth"]
            acc = {k: np.zeros(depth.size) for k in ("mass", "m_app", "wall_normal",
                                                      "wall_friction")}
        m = min(depth.size, prof["depth"].size)
        for k in acc:
            acc[k][:m] += prof[k][:m]
        n += 1
    print(f"{pours} pours and {steps} steps of sliding: {time.process_time() - t0:.0f} s CPU, "
          f"{unconverged} steps above tol {tol:g}")
    mean = {k: a / n for k, a in acc.items()}
    W = p.width / p.diameter
    rho = float(moving.masses.sum()) / (W * float(np.max(x[:, 1] + radii)))
    mob = mean["wall_friction"][-1] / (p.mu_wall * mean["wall_normal"][-1])
    print(f"walls' friction mobilised to {mob:.1%} over the column")
    f = _show_fit("cuts against the mass above (sliding)", mean["mass"], mean["m_app"], rho, W,
                  p.mu_wall)
    for row in zip(depth, mean["mass"], mean["m_app"], f["deviation"]):
        print("{:5.1f} {:7.1f} {:7.1f} {:9.3f}".format(*row))


def roll(p, pours, V=0.05, h=0.01):
    radii, x, v, phi, warm = _pour(p, pours, h)
    moving = silo_system(radii, p, wall_speed=V)
    run = simulate_disks(moving, x, v, 100, h, phi0=phi, warm=warm, save_every=100, theta=1.0,
                         tol=1e-5, max_sweeps=3000)
    cs, r = run.impulses
    f = r.reshape(cs.size, -1) / h
    x, v = run.x[-1], run.v[-1]
    print("wall      y      N   T/(mu N)     v_y   omega r   slip u_T")
    for i in np.flatnonzero((cs.a == -2) | (cs.a == -3)):
        b = cs.b[i]
        # u_T = t . (v_b - V_wall) - r omega, t = (0, 1) on the left wall, (0, -1) on the right
        t_y = 1.0 if cs.a[i] == -2 else -1.0
        slip = t_y * (v[b, 1] - V) - radii[b] * v[b, 2]
        name = "left " if cs.a[i] == -2 else "right"
        ratio = f[i, 1] / (p.mu_wall * f[i, 0] + 1e-300)
        print(f"{name} {x[b, 1]:6.2f} {f[i, 0]:6.2f} {ratio:8.2f} {v[b, 1]:8.4f}"
              f" {radii[b] * v[b, 2]:8.4f} {slip:9.4f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("rest", "slide", "roll"))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pours", type=int, default=None)
    ap.add_argument("--per-pour", type=int, default=30)
    ap.add_argument("--spread", type=float, default=0.8)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--mu-r", type=float, default=0.0)
    ap.add_argument("--scatter", type=float, default=0.0)
    a = ap.parse_args()
    p = SiloParams(per_pour=a.per_pour, seed=a.seed, spread=a.spread,
                   mu_r=a.mu_r * SiloParams.diameter)
    if a.mode == "rest":
        rest(p, a.pours or 12, a.scatter)
    elif a.mode == "slide":
        slide(p, a.pours or 12, a.steps, scatter=a.scatter)
    else:
        roll(p, a.pours or 4)


if __name__ == "__main__":
    main()
