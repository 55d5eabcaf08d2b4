"""The thin disk rolling in steady precession on a plane: tilt and precession angle in closed form."""

from ...scenes.rolling_disk import RollingDiskCase, tilt_and_heading
from ..problem import Problem, register_problem


@register_problem
class RollingDiskProblem(Problem):
    """The disk of :mod:`moreau.scenes.rolling_disk` at its defaults (tilt 1.2 rad), started on its steady motion.

    Measured at the end of the window (a quarter of the precession period):
    the tilt, which the steady motion keeps, and the precession angle
    ``Omega t`` (Routh's relation ``Omega^2 = 4 g cot(theta) / (6 b + a
    cos(theta))``); each relative to a quarter turn, tolerance 1 %. Only
    Moreau–Jean steps a spatial scene.
    """

    name = "rolling-disk"
    title = "Thin disk rolling in steady precession (spatial, a rim contact)"
    scene = "rolling-disk"
    source = ("closed form: Omega^2 = 4 g cot(theta) / (6 b + a cos(theta)) for the thin disk "
              "(E. J. Routh, Advanced Rigid Dynamics, art. 244; moreau.scenes.rolling_disk)")
    steps = (200, 1000, 5000)
    quick_steps = (200, 2000)
    case_class = RollingDiskCase

    def reference(self):
        case = self._the_case()
        return {"tilt": float(case.p.tilt), "precession_angle": float(case.reference(0.0)[0])}

    def scales(self):
        return {"tilt": 0.5 * 3.141592653589793, "precession_angle": 0.5 * 3.141592653589793}

    def measure(self, scene, res):
        tilt, heading = tilt_and_heading(res.q[-1:])
        return {"tilt": float(tilt[0]), "precession_angle": float(heading[0])}
