"""The disk rolling down a rough incline (built with the planar builder): distance, speed and spin in closed form."""

import math

from ...scenes.disk_incline import DiskInclineCase, disk_incline_exact
from ..problem import Problem, register_problem


@register_problem
class DiskInclineProblem(Problem):
    """The disk of :mod:`moreau.scenes.disk_incline` at its defaults (slope 0.3 rad, ``mu = 0.5``).

    ``mu = 0.5 >= tan(0.3) / 3`` so it rolls: ``s'' = (2/3) g sin(alpha)``
    from the launch speed, and the spin keeps ``r w = s'`` (the contact
    point at rest). Measured at the end of the window (10 scene units of
    ``sqrt(r / g)``): the distance down the slope, the speed down the slope
    and ``r w``; each relative to its reference, tolerance 1 %.
    """

    name = "disk-incline"
    title = "Disk rolling down a rough incline (planar builder, sticks)"
    scene = "disk-incline"
    source = ("closed form: rolling at (2/3) g sin(alpha) while mu >= tan(alpha) / 3 "
              "(moreau.scenes.disk_incline)")
    case_class = DiskInclineCase
    #: the closed form ``(s, s', w)`` at SI times
    exact = staticmethod(disk_incline_exact)

    def reference(self):
        case = self._the_case()
        sc = case.scene
        s, sd, w = self.exact(case.p, [self.window * sc.time])
        return {"distance": float(s[0]) / sc.length,
                "speed": float(sd[0]) * sc.time / sc.length,
                "rolling_speed": float(w[0]) * case.p.radius * sc.time / sc.length}

    def scales(self):
        return dict(self.reference())

    def measure(self, scene, res):
        a = self._the_case().p.slope
        ca, sa = math.cos(a), math.sin(a)
        r = self._the_case().p.radius / scene.length
        return {"distance": float(-(res.q[-1, 0] * ca + res.q[-1, 1] * sa)),
                "speed": float(-(res.v[-1, 0] * ca + res.v[-1, 1] * sa)),
                "rolling_speed": float(r * res.v[-1, 2])}
