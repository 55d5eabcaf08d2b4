"""The rocking block stated with the planar builder: the hand-written block's problem on the built scene."""

from ...model.registry import make_scene
from ..problem import register_problem
from .rocking_block import RockingBlockProblem


@register_problem
class RockingBlockBuiltProblem(RockingBlockProblem):
    """:class:`RockingBlockProblem`'s block, run on ``rocking-block-built`` (:mod:`moreau.model.planar`).

    Same parameters, window, quantities and tolerance; the reference is
    Housner's closed forms of the hand-written scene
    (:class:`moreau.scenes.rocking_block.RockingBlock`), whose units and
    coordinates ``(x, y, theta)`` the built scene shares.
    """

    name = "rocking-block-built"
    title = "Rocking block, built with the planar builder (Housner's impacts, Zeno settling)"
    scene = "rocking-block-built"
    source = RockingBlockProblem.source + "; the scene stated with moreau.model.planar"
    _exact = None

    def exact_scene(self):
        if self._exact is None:
            self._exact = make_scene("rocking-block", **self.scene_parameters())
        return self._exact
