"""The bouncing ball dropped from rest: impact time, rebound height and the Zeno (rest) time."""

import numpy as np

from ..problem import Problem, crossing_time, register_problem

#: a ball whose speed stays below this (relative to the first impact speed) to the end of
#: the window is at rest; the bounces left after it last under 2e-6 of the Zeno time
REST_SPEED = 1e-6


@register_problem
class BouncingBallProblem(Problem):
    """Dropped from rest with its centre at 0.6 (radius 0.1, ``e = 1/2``, gravity and length 1).

    Closed form (:meth:`moreau.scenes.bouncing_ball.BouncingBall.impacts`): first impact
    at ``t1 = sqrt(2 (h - r))`` with speed ``V = t1``, rebound of the centre to
    ``r + (e V)^2 / 2``, rest at the accumulation (Zeno) time ``t1 + 2 e V / (1 - e)``
    (here 1, 0.225 and 3).
    """

    name = "bouncing-ball"
    title = "Bouncing ball"
    scene = "bouncing-ball"
    source = ("closed form of the ball's flights between Newton impacts (geometric series of "
              "flight times, accumulating at the Zeno time); see moreau.scenes.bouncing_ball")
    window = 4.0
    steps = (400, 4000, 40000)
    height = 0.6

    def scene_parameters(self):
        return {"restitution": 0.5, "radius": 0.1, "length": 1.0, "gravity": 9.81}

    def start(self, scene):
        return np.array([self.height]), np.zeros(1)

    def reference(self):
        scene = self.make_scene()
        q0, v0 = self.start(scene)
        imp = scene.impacts(q0, v0, 1)
        speed = float(imp.v_after[0])
        return {"first_impact_time": float(imp.t[0]),
                "rebound_height": float(scene.r + 0.5 * speed ** 2),
                "rest_time": float(scene.zeno_time(q0, v0))}

    def scales(self):
        # times relative to the Zeno time, heights to the drop
        return {"first_impact_time": 3.0, "rebound_height": self.height - 0.1, "rest_time": 3.0}

    def measure(self, scene, res):
        t, y, v = res.t, res.q[:, 0], res.v[:, 0]
        t1 = crossing_time(t, v, 0.0, direction=+1)
        out = {"first_impact_time": t1, "rebound_height": None, "rest_time": None}
        if t1 is not None:
            # in flight the height plus v^2 / 2 (gravity 1) is the apex: read at the first
            # sample going up, it needs no sample at the apex itself
            up = np.flatnonzero((t >= t1) & (v > 0.0))
            if up.size:
                i = up[0]
                out["rebound_height"] = float(y[i] + 0.5 * v[i] ** 2)
        moving = np.flatnonzero(np.abs(v) > REST_SPEED)
        if moving.size and moving[-1] + 1 < len(t):
            out["rest_time"] = float(t[moving[-1] + 1])
        return out
