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

Rocking onset under a base acceleration
---------------------------------------
With ``base_acceleration = A`` [m/s^2] the floor moves ``x(t) = A t^2 / 2``
from rest. The scene states the block in the floor's frame (its coordinates
are relative to the floor): there the floor is fixed and the block feels the
inertial force ``-m A`` at its centre, so the model is the fixed-floor one
with gravity ``(-A, -g)`` (the same compiled functions; the time unit stays
``sqrt(R / g)``). :func:`rocking_block_model` with ``moving_floor=True``
states it instead with the floor a driven body in the ground frame (the
independent check of this frame change).

Write ``b = width / 2`` and ``h = height / 2``. About the trailing corner
(the left one for ``A > 0``: the corner at ``(-b, -h)`` from the centre, so
the centre at ``(b, h)`` from it when upright) the moments of gravity and
of the inertial force are ``-m g b`` and ``m A h`` (counter-clockwise
positive), so the block, held against sliding by friction, leaves its right
corner when ``m A h > m g b``: rocking starts for ``|A| > g b / h = g
tan(alpha)`` (Housner 1963; Makris and Roussos 2000, "Rocking response of
rigid blocks under near-source ground motions", Geotechnique 50(3),
243-262). Just above the onset, Newton–Euler about the pivot (fixed in the floor's frame, ``I_O = m (b^2 + h^2) 4/3``)
gives the initial angular acceleration::

    theta''(0+) = 3 (A h - g b) / (4 (b^2 + h^2))

(:func:`rocking_onset_acceleration`, :func:`initial_angular_acceleration`);
below the onset both corners stick and the block moves with the floor.
Friction must hold the horizontal force ``m A`` with the normal force
``m g``: ``mu >= |A| / g`` (the default ``mu = 10`` does).
"""

import math
from dataclasses import dataclass

import numpy as np

from .._validate import finite_scalar, positive
from ..errors import InputError
from ..model.planar import HalfPlane, Model, Polygon, TimeFunction
from ..model.params import FINITE, param
from ..model.scene import params_with
from ..model.registry import SceneEntry, register_scene
from .rocking_block import RockingBlock, RockingBlockCase, RockingBlockParams

__all__ = ["RockingBlockBuiltParams", "rocking_block_model", "rocking_block_built",
           "rocking_onset_acceleration", "initial_angular_acceleration"]


@dataclass(frozen=True)
class RockingBlockBuiltParams(RockingBlockParams):
    """SI parameters of the built rocking block: :class:`RockingBlockParams` and the floor's
    motion."""

    base_acceleration: float = param(0.0, "m/s^2", FINITE,
                                     "The floor's constant horizontal acceleration",
                                     "From rest at ``t = 0`` (0: a fixed floor).")


def rocking_onset_acceleration(width, height, gravity=9.81):
    """The base acceleration ``g b / h`` [m/s^2] above which a block that does not slide starts to rock.

    Examples
    --------
    >>> round(rocking_onset_acceleration(0.2, 0.4, 9.81), 12)
    4.905
    """
    w, h, g = positive("width", width), positive("height", height), positive("gravity", gravity)
    return g * w / h


def initial_angular_acceleration(width, height, base_acceleration, gravity=9.81):
    """``theta''(0+)`` [rad/s^2] of an upright block on its trailing corner under a base acceleration.

    ``3 (|A| h - g b) / (4 (b^2 + h^2))`` with the sign of ``A`` (module
    docstring), 0 at or below the onset.

    Examples
    --------
    >>> round(initial_angular_acceleration(0.2, 0.4, 2 * 4.905), 9)
    14.715
    """
    b, h = 0.5 * positive("width", width), 0.5 * positive("height", height)
    A, g = finite_scalar("base_acceleration", base_acceleration), positive("gravity", gravity)
    return math.copysign(max(0.0, 3.0 * (abs(A) * h - g * b) / (4.0 * (b * b + h * h))), A)


def rocking_block_model(params=None, *, moving_floor=False, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the rocking block (SI parameters of :class:`RockingBlockBuiltParams`).

    With ``moving_floor`` the floor is a driven body moving ``A t^2 / 2``
    (ground frame); otherwise the model is the floor's frame (module docstring).
    """
    p = params_with(RockingBlockBuiltParams, params, overrides)
    a, b = 0.5 * p.width, 0.5 * p.height
    c, s = math.cos(p.tilt), math.sin(p.tilt)
    # the left corner (-a, -b) at the origin: the centre is minus that corner turned by tilt
    centre = (a * c - b * s, a * s + b * c)
    A = p.base_acceleration
    if A == 0.0:
        m = Model(gravity=(0.0, -p.gravity))
    else:
        # the time unit of the fixed floor's scene, not of the tilted gravity's size
        time = math.sqrt(0.5 * math.hypot(p.width, p.height) / p.gravity)
        m = Model(gravity=(0.0 if moving_floor else -A, -p.gravity), time=time)
    block = m.add_body(p.mass, p.mass * (p.width ** 2 + p.height ** 2) / 12.0, position=centre,
                       angle=p.tilt, name="block")
    base = m.add_driven(x=TimeFunction(accel=A), name="floor") if moving_floor else m.ground
    floor = m.add_shape(base, HalfPlane((0.0, 0.0), (0.0, 1.0)))
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


rocking_block_built.Params = RockingBlockBuiltParams


class RockingBlockBuiltCase(RockingBlockCase):
    """The hand-written block's comparison case (Housner's exact rocking) run on the built scene."""

    def __init__(self, **params):
        if params.get("base_acceleration", 0.0) != 0.0:
            raise InputError("`base_acceleration` must be 0 in the rocking block's comparison "
                             "case: its reference is Housner's free rocking on a fixed floor")
        params.pop("base_acceleration", None)
        super().__init__(**params)
        self.exact = self.scene
        self.scene = rocking_block_built(**params)

    def _exact(self):
        return self.exact


register_scene(SceneEntry(
    name="rocking-block-built",
    factory=rocking_block_built,
    description=("the rocking block stated with the planar builder (moreau.model.planar): "
                 "the same equations as rocking-block"),
    case=RockingBlockBuiltCase,
))
