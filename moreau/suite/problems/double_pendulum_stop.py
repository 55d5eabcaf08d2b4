"""The double pendulum against a wall (e = 1, frictionless): its energy, conserved through the impacts."""

import numpy as np

from ...scenes.double_pendulum_stop import DoublePendulumStopCase
from ..problem import Problem, register_problem


@register_problem
class DoublePendulumStopProblem(Problem):
    """The double pendulum of :mod:`moreau.scenes.double_pendulum_stop` at its defaults, over its first strike.

    Two 1 m, 1 kg bars released at rest horizontal; the lower tip strikes
    the wall ``x = 0.8 m`` at ``t = 2.4`` (scene time, units ``sqrt(l /
    g)``), elastically and without friction, so the energy (2 in the
    scene's units, above the hanging rest) is conserved. Quantities: the
    energy at the end of the window (3) and its lowest value over the
    run, each relative to the initial energy; tolerance 1 %. Moreau–Jean
    at its default ``theta = 1`` loses energy at first order, its numerical
    dissipation (3.2 % at 1000 steps): only its finer settings are
    accurate (``theta = 1/2`` keeps the energy to rounding).
    """

    name = "double-pendulum-stop"
    title = "Double pendulum against a wall (two revolute joints, e = 1): energy"
    scene = "double-pendulum-stop"
    reference_kind = "closed form (the energy, conserved)"
    source = ("energy conservation of a frictionless elastic impact; the mechanism of "
              "moreau.scenes.double_pendulum_stop (parameters chosen there)")
    case_class = DoublePendulumStopCase
    steps = (500, 5000, 20000)

    def reference(self):
        e0 = self._the_case().initial_energy()
        return {"energy_end": e0, "energy_lowest": e0}

    def scales(self):
        e0 = self._the_case().initial_energy()
        return {"energy_end": e0, "energy_lowest": e0}

    def measure(self, scene, res):
        e = self._the_case().energy(res.q, res.v)
        return {"energy_end": float(e[-1]), "energy_lowest": float(np.min(e))}
