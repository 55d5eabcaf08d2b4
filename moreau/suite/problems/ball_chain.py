"""The striker on a chain of touching balls (Newton's cradle): the block result of the simultaneous impact."""

import numpy as np

from ...scenes.ball_chain import simultaneous_impact
from ..problem import Problem, register_problem


@register_problem
class BallChainProblem(Problem):
    """The scene's default chain (3 balls, ``e = 1``): velocities after the impact, last ball's position.

    The model's impact law treats the closing contacts as one block (one
    complementarity problem with Newton's law on each contact), so its answer
    is :func:`moreau.scenes.ball_chain.simultaneous_impact`, not the
    sequential ("cradle") answer.
    """

    name = "ball-chain"
    title = "Newton's cradle (ball chain, simultaneous impact)"
    scene = "ball-chain"
    source = ("the simultaneous (block) impact of Moreau's sweeping process with Newton's law "
              "per contact, one LCP (see moreau.scenes.ball_chain); cf. B. Brogliato, "
              "Nonsmooth Mechanics, 3rd ed., Springer 2016, ch. 6")

    @property
    def window(self):
        return self.make_scene().impact_time + 2.0

    def reference(self):
        sc = self.make_scene()
        q0, v0 = sc.initial_state()
        after = simultaneous_impact(sc.masses, v0, sc.params.restitution)
        return {"striker_speed_after": float(after[0]), "last_speed_after": float(after[-1]),
                "last_position_end": float(q0[-1] + after[-1] * (self.window - sc.impact_time))}

    def scales(self):
        sc = self.make_scene()
        speed = float(np.max(np.abs(sc.initial_state()[1])))
        return {"striker_speed_after": speed, "last_speed_after": speed,
                "last_position_end": 2.0 * speed}

    def measure(self, scene, res):
        return {"striker_speed_after": float(res.v[-1, 0]),
                "last_speed_after": float(res.v[-1, -1]),
                "last_position_end": float(res.q[-1, -1])}
