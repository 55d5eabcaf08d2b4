"""The Painlevé rod from a paradoxical sliding start: the tangential impact (jam) and the stick after it.

Derivation
----------
Scene units of :mod:`moreau.scenes.painleve_rod`: half-length 1, unit mass,
centroidal inertia ``1/3``, gravity 1; ``q = (x, y, phi)``, the tip at
``(x - cos phi, y - sin phi)``, i.e. at ``r = (-c, -s)`` from the centre
(``c = cos phi``, ``s = sin phi``). Its velocity is
``u = (u_T, u_N) = (x' + s phi', y' - c phi')``.

*The jam.* An impulse ``(P_T, P_N)`` at the tip changes the velocities by
Newton-Euler, ``dx' = P_T``, ``dy' = P_N`` and
``(1/3) dphi' = r x P = -c P_N + s P_T``, so the tip's velocity changes by::

    du_N = (1 + 3 c^2) P_N - 3 s c P_T
    du_T = -3 s c P_N + (1 + 3 s^2) P_T

(the Delassus matrix ``W``, symmetric, determinant 4). Started sliding at
``phi = atan 2`` with ``u = (-1, 0)`` and ``mu = 2 > 4/3``, the Painlevé
indicator ``1 + 3 c^2 + 3 mu sign(u_T) s c = -0.8`` is negative: no sliding
motion and no lift-off is consistent (Génot & Brogliato 1999), and the one
solution of the contact problem is the impulsive stick of the tip:
``u+ = 0``, i.e. ``W P = -u``. Here ``W = [[1.6, -1.2], [-1.2, 3.4]]`` in
``(N, T)`` order, ``P_N = 0.3``, ``P_T = 0.4`` (inside the cone,
``|P_T| <= 2 P_N``), and the rod leaves the jam with
``(x', y', phi') = (-0.6, 0.3, 1.5 / sqrt 5 = 0.6708)``.

*The stick after it.* With the tip fixed the rod is a pendulum about it,
``(4/3) phi'' = -c`` (inertia ``1/3 + 1`` about the tip), the centre at
``tip + (c, s)``, and the contact force is ``(F_T, F_N) = a_G + (0, 1)`` with
``a_G = (-s phi'' - c phi'^2, c phi'' - s phi'^2)``. :meth:`PainleveJamProblem.reference`
integrates the pendulum by DOP853 (``rtol = 1e-13``) from the jam over the
window and checks that the stick holds (``F_N > 0``, ``|F_T| <= mu F_N``) all
along it.
"""

import math

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import MoreauError
from ..problem import Problem, register_problem

#: where the rod starts: the angle with minimal critical friction (tan phi = 2), the tip
#: sliding towards the rod's foot at unit speed, on a floor with mu = 2
PHI0 = math.atan(2.0)
TIP_SPEED = -1.0
MU = 2.0


def rod_jam(phi, u_T, u_N=0.0):
    """The tip's impulse ``(P_N, P_T)`` that stops it and the velocity change ``(dx', dy', dphi')``.

    From the Newton-Euler equations of the module docstring (scene units).

    Examples
    --------
    >>> (PN, PT), dv = rod_jam(math.atan(2.0), -1.0)
    >>> round(PN, 12), round(PT, 12), [round(float(d), 12) for d in dv]
    (0.3, 0.4, [0.4, 0.3, 0.67082039325])
    """
    c, s = math.cos(phi), math.sin(phi)
    W = np.array([[1.0 + 3.0 * c * c, -3.0 * s * c], [-3.0 * s * c, 1.0 + 3.0 * s * s]])
    PN, PT = np.linalg.solve(W, -np.array([u_N, u_T]))
    return (float(PN), float(PT)), np.array([PT, PN, 3.0 * (-c * PN + s * PT)])


def stick_forces(phi, dphi):
    """``(F_T, F_N)`` on the stuck tip of the pendulum at ``(phi, dphi)`` (module docstring)."""
    c, s = np.cos(phi), np.sin(phi)
    ddphi = -0.75 * c
    return -s * ddphi - c * dphi ** 2, c * ddphi - s * dphi ** 2 + 1.0


@register_problem
class PainleveJamProblem(Problem):
    """The rod (``mu = 2``) started sliding at ``phi = atan 2``, tip speed -1: it jams, then sticks.

    The headline quantities are the rod's velocities at the end of the window
    (0.5, scene units) and the tip's ``x`` there (0: it stuck at the jam);
    the reference is the closed-form jam followed by the stick pendulum (the
    module docstring). Velocities are relative to the tip's speed before the
    jam (1), the tip's position to the half-length (1); tolerance 1 %. The
    event-driven schemes cannot continue a sliding mode that has no solution:
    they stop, naming the Painlevé configuration.
    """

    name = "painleve-jam"
    title = "Painlevé rod: jam from a paradoxical slide"
    scene = "painleve-rod"
    reference_kind = "closed form (the jam) and the stick pendulum by DOP853 (rtol 1e-13)"
    source = ("F. Génot, B. Brogliato, New results on Painlevé paradoxes, Eur. J. Mech. A/Solids "
              "18 (1999) 653-677: the tangential impact (dynamic jam) as the solution from a "
              "paradoxical sliding state; the jam impulse from the rod's Newton-Euler equations")
    window = 0.5

    def scene_parameters(self):
        return {"mu": MU}

    def start(self, scene):
        return scene.sliding_state(PHI0, TIP_SPEED)

    def jam(self):
        """``((P_N, P_T), v+)``: the jam's impulse and the velocity it leaves (closed form)."""
        scene = self.make_scene()
        q0, v0 = self.start(scene)
        c, s = math.cos(q0[2]), math.sin(q0[2])
        (PN, PT), dv = rod_jam(q0[2], v0[0] + s * v0[2], v0[1] - c * v0[2])
        if not (PN > 0.0 and abs(PT) <= MU * PN):
            raise MoreauError(f"the jam's impulse (P_N, P_T) = ({PN:g}, {PT:g}) is outside the "
                              f"friction cone mu = {MU:g}: the tip would not stick")
        return (PN, PT), v0 + dv

    _ref = None

    def reference(self):
        if self._ref is None:
            scene = self.make_scene()
            q0, _ = self.start(scene)
            _, vj = self.jam()

            def rhs(_, y):
                return [y[1], -0.75 * math.cos(y[0])]

            sol = solve_ivp(rhs, (0.0, self.window), [q0[2], vj[2]], method="DOP853",
                            rtol=1e-13, atol=1e-15, dense_output=True)
            phi, dphi = sol.sol(np.linspace(0.0, self.window, 1001))
            FT, FN = stick_forces(phi, dphi)
            if not (np.all(FN > 0.0) and np.all(np.abs(FT) <= MU * FN)):
                raise MoreauError("the stick after the jam does not hold over the window")
            ph, w = float(sol.y[0, -1]), float(sol.y[1, -1])
            self._ref = {"vx_end": -math.sin(ph) * w, "vy_end": math.cos(ph) * w,
                         "dphi_end": w, "tip_x_end": 0.0}
        return dict(self._ref)

    def scales(self):
        return {"vx_end": abs(TIP_SPEED), "vy_end": abs(TIP_SPEED), "dphi_end": abs(TIP_SPEED),
                "tip_x_end": 1.0}

    def measure(self, scene, res):
        q, v = res.q[-1], res.v[-1]
        return {"vx_end": float(v[0]), "vy_end": float(v[1]), "dphi_end": float(v[2]),
                "tip_x_end": float(q[0] - math.cos(q[2]))}
