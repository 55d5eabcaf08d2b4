"""The stick–slip motor's displacement per period against its exact periodic solution."""

import math

from ...scenes.stick_slip_motor import StickSlipCase
from ..problem import Problem, register_problem


@register_problem
class StickSlipMotorProblem(Problem):
    """The sawtooth-driven slider (1000 Hz): one period from the exact periodic state.

    The reference is the scene's exact stick–slip solution (each stick and slip
    segment in closed form, the periodic state by its fixed point); a scheme
    runs one period from that state and its displacement is compared.
    """

    name = "stick-slip-motor"
    title = "Stick–slip motor (sawtooth drive)"
    scene = "stick-slip-motor"
    source = ("closed-form stick and slip segments of the piecewise-polynomial drive (see "
              "moreau.scenes.stick_slip_motor.exact)")
    window = 2.0 * math.pi
    case_class = StickSlipCase

    def reference(self):
        return {"displacement_per_period": float(self._the_case()._steady().displacement_per_period)}

    def scales(self):
        return {"displacement_per_period": abs(self.reference()["displacement_per_period"])}

    def measure(self, scene, res):
        return {"displacement_per_period": float(res.q[-1, 0] - res.q[0, 0])}
