"""The rocking block stated with the planar builder: the check of :mod:`moreau.model.planar` against a hand-written scene.

The same block as :mod:`moreau.scenes.rocking_block` (Housner 1963, "The
behavior of inverted pendulum structures during earthquakes", Bull. Seismol.
Soc. Am. 53(2), 403-417), at the same parameters: a uniform
``width`` x ``height`` box of centroidal inertia ``m (w^2 + h^2) / 12``,
released at rest on its left corner tilted by ``tilt``, its two bottom
corners (vertices 0 and 1 of :meth:`Polygon.box <moreau.model.planar.Polygon.box>`)
against the floor with friction ``mu`` and restitution ``e``. The builder's
units are those of the hand-written scene (the half-diagonal ``R``, the
block's mass, ``sqrt(R / g)``), so that both scenes state one set of
equations in one set of variables: the tests hold their Moreau–Jean runs
together to rounding, and the built block to Housner's ratio
``w+ / w- = 1 - (3/2) sin^2(alpha)`` (derived in
:mod:`moreau.scenes.rocking_block`).

The model in ten lines (:func:`rocking_block_model`)::

    m = Model(gravity=(0.0, -g))
    block = m.add_body(mass, mass * (width**2 + height**2) / 12, position=centre, angle=tilt)
    floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), (0.0, 1.0)))
    m.add_contact(m.add_shape(block, Polygon.box(width, height)), floor, mu=mu,
                  restitution=e, vertices=(0, 1))
"""

import math

import numpy as np

from ..analysis.cases import GRID
from ..model.planar import HalfPlane, Model, Polygon
from ..model.scene import params_with
from ..model.registry import SceneEntry, parameters_of, register_scene
from .rocking_block import RockingBlock, RockingBlockCase, RockingBlockParams

__all__ = ["rocking_block_model", "rocking_block_built"]


def rocking_block_model(params=None, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the rocking block (SI parameters of :class:`RockingBlockParams`)."""
    p = params_with(RockingBlockParams, params, overrides)
    a, b = 0.5 * p.width, 0.5 * p.height
    c, s = math.cos(p.tilt), math.sin(p.tilt)
    # the left corner (-a, -b) at the origin: the centre is minus that corner turned by tilt
    centre = (a * c - b * s, a * s + b * c)
    m = Model(gravity=(0.0, -p.gravity))
    block = m.add_body(p.mass, p.mass * (p.width ** 2 + p.height ** 2) / 12.0, position=centre,
                       angle=p.tilt, name="block")
    floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), (0.0, 1.0)))
    m.add_contact(m.add_shape(block, Polygon.box(p.width, p.height)), floor, mu=p.mu,
                  restitution=p.restitution, vertices=(0, 1))
    return m


def _upright(t, q, v):
    return np.abs(np.asarray(q).reshape(-1, 3)[:, 2]) < 0.5 * math.pi


def rocking_block_built(params=None, **overrides):
    """The built rocking block's scene (a :class:`~moreau.model.planar.PlanarScene`).

    Examples
    --------
    >>> sc = rocking_block_built(width=0.2, height=0.4)
    >>> q0, _ = sc.initial_state()
    >>> [round(float(g), 12) + 0.0 for g in sc.gaps(q0, 0.0)]
    [0.0, 0.044702727979]
    """
    return rocking_block_model(params, **overrides).build(
        "rocking-block-built", valid_region="|theta| < pi/2", inside=_upright,
        default_window=RockingBlock.default_window)


class RockingBlockBuiltCase(RockingBlockCase):
    """The hand-written block's comparison case (Housner's exact rocking) run on the built scene."""

    def __init__(self, **params):
        super().__init__(**params)
        self.exact = self.scene
        self.scene = rocking_block_built(**params)

    def reference(self, rtol):
        th, _ = self.exact.exact_solution([self.window])
        t1 = float(self.exact.impact_times(1)[0])
        return float(th[0]), [(t1, "0:F"), (t1, "1:S")]

    def reference_grid(self):
        th, _ = self.exact.exact_solution(np.linspace(0.0, self.window, GRID + 1))
        return th


register_scene(SceneEntry(
    name="rocking-block-built",
    factory=rocking_block_built,
    parameters=parameters_of(RockingBlockParams, {"mass": "kg", "width": "m", "height": "m",
                                                  "mu": "", "gravity": "m/s^2",
                                                  "restitution": "", "tilt": "rad"}),
    description=("the rocking block stated with the planar builder (moreau.model.planar): "
                 "the same equations as rocking-block"),
    case=RockingBlockBuiltCase,
    sweepable=("mu", "tilt", "width", "height"),
    mj_tolerance=2e-2,
))
