"""The billiard ball struck with backspin: its distance, final speed and spin in closed form."""

from ...scenes.billiard_backspin import BilliardCase, billiard_exact
from ..problem import Problem, register_problem


@register_problem
class BilliardBackspinProblem(Problem):
    """The ball of :mod:`moreau.scenes.billiard_backspin` at its defaults (2 m/s, -40 rad/s).

    It slides until ``t* = 2 (v0 - r w0) / (7 mu g)`` = 0.458 s, then rolls
    at ``(5 v0 + 2 r w0) / 7`` = 1.10 m/s. Measured at the end of the window
    (20 units of ``sqrt(r / g)``, 1.08 s): the distance, the speed and ``r
    w``; each relative to its reference, tolerance 1 %. Only Moreau–Jean
    steps a spatial scene.
    """

    name = "billiard-backspin"
    title = "Billiard ball with backspin: sliding, then rolling (spatial)"
    scene = "billiard-backspin"
    reference_kind = "closed form"
    source = ("closed form: t* = 2 (v0 - r w0) / (7 mu g), v* = (5 v0 + 2 r w0) / 7 "
              "(moreau.scenes.billiard_backspin)")
    tolerance = 1e-2
    steps = (100, 1000, 10000)
    quick_steps = (100, 1000)
    case_class = BilliardCase

    def reference(self):
        case = self._the_case()
        sc = case.scene
        x, v, w = billiard_exact(case.p, [self.window * sc.time])
        return {"distance": float(x[0]) / sc.length, "speed": float(v[0]) * sc.time / sc.length,
                "rolling_speed": float(w[0]) * case.p.radius * sc.time / sc.length}

    def scales(self):
        return dict(self.reference())

    def measure(self, scene, res):
        return {"distance": float(res.q[-1, 0]), "speed": float(res.v[-1, 0]),
                "rolling_speed": float(res.v[-1, 4])}
