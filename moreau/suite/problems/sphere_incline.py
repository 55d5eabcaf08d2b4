"""The sphere rolling down a rough incline in space: distance, speed and spin in closed form."""

from ...scenes.sphere_incline import SphereInclineCase, sphere_incline_exact
from ..problem import Problem, register_problem


@register_problem
class SphereInclineProblem(Problem):
    """The sphere of :mod:`moreau.scenes.sphere_incline` at its defaults (slope 0.3 rad, ``mu = 0.5``).

    ``mu = 0.5 >= (2/7) tan(alpha)`` so it rolls at ``(5/7) g sin(alpha)``.
    Measured at the end of the window (10 units of ``sqrt(r / g)``): the
    distance down the slope, the speed down the slope and ``r w``; each
    relative to its reference, tolerance 1 %. Only Moreau–Jean steps a
    spatial scene; the other schemes are refused by name.
    """

    name = "sphere-incline"
    title = "Sphere rolling down a rough incline (spatial, the friction cone)"
    scene = "sphere-incline"
    reference_kind = "closed form"
    source = ("closed form: rolling at (5/7) g sin(alpha) while mu >= (2/7) tan(alpha) "
              "(moreau.scenes.sphere_incline)")
    tolerance = 1e-2
    steps = (100, 1000, 10000)
    quick_steps = (100, 1000)
    case_class = SphereInclineCase

    def reference(self):
        case = self._the_case()
        sc = case.scene
        s, sd, w = sphere_incline_exact(case.p, [self.window * sc.time])
        return {"distance": float(s[0]) / sc.length,
                "speed": float(sd[0]) * sc.time / sc.length,
                "rolling_speed": float(w[0]) * case.p.radius * sc.time / sc.length}

    def scales(self):
        return dict(self.reference())

    def measure(self, scene, res):
        return {"distance": float(res.q[-1, 0]), "speed": float(res.v[-1, 0]),
                "rolling_speed": float(res.v[-1, 4])}
