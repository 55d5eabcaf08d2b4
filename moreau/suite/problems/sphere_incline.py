"""The sphere rolling down a rough incline in space: distance, speed and spin in closed form."""

from ...scenes.sphere_incline import SphereInclineCase, sphere_incline_exact
from ..problem import register_problem
from .disk_incline import DiskInclineProblem


@register_problem
class SphereInclineProblem(DiskInclineProblem):
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
    source = ("closed form: rolling at (5/7) g sin(alpha) while mu >= (2/7) tan(alpha) "
              "(moreau.scenes.sphere_incline)")
    case_class = SphereInclineCase
    exact = staticmethod(sphere_incline_exact)

    def measure(self, scene, res):
        return {"distance": float(res.q[-1, 0]), "speed": float(res.v[-1, 0]),
                "rolling_speed": float(res.v[-1, 4])}
