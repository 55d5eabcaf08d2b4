"""The block launched on a rough floor: stopping distance and time in closed form."""

import numpy as np

from ...scenes.sliding_block import SlidingBlockCase
from ..problem import Problem, crossing_time, register_problem

#: the stopping time is read where the speed falls below this fraction of the launch speed
STOP_FRACTION = 1e-3


class StoppingProblem(Problem):
    """Shared by the block and the box: launched at ``speed``, decelerated by ``mu g`` until it sticks."""

    def scene_parameters(self):
        return {"mu": self.case_parameters()["mu"]}

    def reference(self):
        case = self._the_case()
        _, v0 = case.start()
        t_stop = float(case.scene.stopping_time(v0))
        # constant deceleration: the speed is STOP_FRACTION v0 at (1 - STOP_FRACTION) t_stop
        return {"stopping_distance": float(case.scene.stopping_distance(v0)),
                "stopping_time": (1.0 - STOP_FRACTION) * t_stop}

    def scales(self):
        ref = self.reference()
        return {"stopping_distance": ref["stopping_distance"],
                "stopping_time": ref["stopping_time"]}

    def measure(self, scene, res):
        _, v0 = self._the_case().start()
        return {"stopping_distance": float(res.q[-1, 0] - res.q[0, 0]),
                "stopping_time": crossing_time(res.t, res.v[:, 0], STOP_FRACTION * v0[0])}


@register_problem
class SlidingBlockProblem(StoppingProblem):
    """The block launched at 2 (scene units) with ``mu = 0.5``: ``d = v0^2 / (2 mu g)``, ``t = v0 / (mu g)``."""

    name = "sliding-block"
    title = "Sliding block (Coulomb friction, stops)"
    scene = "sliding-block"
    source = ("closed form: uniform deceleration mu g until the block sticks (see "
              "moreau.scenes.sliding_block)")
    case_class = SlidingBlockCase

    def case_parameters(self):
        return {"speed": 2.0, "mu": 0.5}
