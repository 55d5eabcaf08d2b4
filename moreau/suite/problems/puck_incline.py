"""The thin puck launched across a rough incline: its position in closed form for ``mu = tan(alpha)``."""

import math

from ...scenes.puck_incline import PuckInclineCase, puck_incline_path
from ..problem import Problem, register_problem


@register_problem
class PuckInclineProblem(Problem):
    """The puck of :mod:`moreau.scenes.puck_incline` at its defaults (launched across at 1 m/s).

    With ``mu = tan(alpha)`` its path has a closed form. Measured at the end
    of the window (16 units of ``sqrt(r / g)``, 1.0 s): the distances down
    and across the slope and the speed, relative to the distance across
    (the path's size), tolerance 1 %. Moreau–Jean's default friction cone
    has 8 facets, whose error on the path is far above 1 % (the scene's
    docstring and tests measure it against ``d``); only Moreau–Jean steps a
    spatial scene.
    """

    name = "puck-incline"
    title = "Thin puck launched across a rough incline (spatial, mu = tan(alpha))"
    scene = "puck-incline"
    source = ("closed form: v (1 + cos psi) = const, the path in tan(psi/2) "
              "(moreau.scenes.puck_incline)")
    case_class = PuckInclineCase

    def reference(self):
        case = self._the_case()
        sc = case.scene
        z = puck_incline_path(case.p, [self.window * sc.time])[0]
        return {"down": float(z[0]) / sc.length, "across": float(z[1]) / sc.length,
                "speed": math.hypot(z[2], z[3]) * sc.time / sc.length}

    def scales(self):
        ref = self.reference()
        return {"down": ref["across"], "across": ref["across"], "speed": ref["speed"]}

    def measure(self, scene, res):
        return {"down": float(res.q[-1, 0]), "across": float(res.q[-1, 1]),
                "speed": math.hypot(res.v[-1, 0], res.v[-1, 1])}
