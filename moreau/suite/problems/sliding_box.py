"""The box sliding on its two corners: the two-contact version of the stopping block."""

from ...scenes.sliding_box import SlidingBoxCase
from ..problem import register_problem
from .sliding_block import StoppingProblem


@register_problem
class SlidingBoxProblem(StoppingProblem):
    """The box launched at 1 (scene units) with ``mu = 0.4``: both corners stop together."""

    name = "sliding-box"
    title = "Sliding box (two frictional contacts, stops)"
    scene = "sliding-box"
    source = ("closed form: both corners stay down (mu b < a) and the box decelerates at mu g "
              "(see moreau.scenes.sliding_box)")
    case_class = SlidingBoxCase

    def case_parameters(self):
        return {"speed": 1.0, "mu": 0.4}
