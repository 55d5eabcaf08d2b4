"""The billiard ball struck with backspin: its distance, final speed and spin in closed form."""

from ...scenes.billiard_backspin import BilliardCase, billiard_exact
from ..problem import register_problem
from .sphere_incline import SphereInclineProblem


@register_problem
class BilliardBackspinProblem(SphereInclineProblem):
    """The ball of :mod:`moreau.scenes.billiard_backspin` at its defaults (2 m/s, -40 rad/s).

    It slides until ``t* = 2 (v0 - r w0) / (7 mu g)`` = 0.458 s, then rolls
    at ``(5 v0 + 2 r w0) / 7`` = 1.10 m/s. Measured at the end of the window
    (20 units of ``sqrt(r / g)``, 1.08 s): the distance, the speed and ``r
    w``; each relative to its reference, tolerance 1 %, as for the sphere on
    the incline (the same quantities along ``x``). Only Moreau–Jean steps a
    spatial scene.
    """

    name = "billiard-backspin"
    title = "Billiard ball with backspin: sliding, then rolling (spatial)"
    scene = "billiard-backspin"
    source = ("closed form: t* = 2 (v0 - r w0) / (7 mu g), v* = (5 v0 + 2 r w0) / 7 "
              "(moreau.scenes.billiard_backspin)")
    case_class = BilliardCase
    exact = staticmethod(billiard_exact)
