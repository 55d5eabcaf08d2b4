r"""The ideal slider-crank with a driven crank, stated with the planar builder (joints).

A crank of radius ``r`` turns about the ground's origin at a constant
angular speed ``omega`` (a driven body, ``theta = omega t``); a rod of
length ``l`` is pinned to the crank's tip and to a slider, which moves on a
prismatic joint along the ground's ``x`` axis. Three revolute and prismatic
joints (six rows) hold the rod's and the slider's six coordinates: the
mechanism has no degree of freedom of its own, so its motion is the
closed-form kinematics (e.g. Shigley and Uicker, *Theory of Machines and
Mechanisms*, the offset-free slider-crank; Flores et al. 2008, *Kinematics
and Dynamics of Multibody Systems with Imperfect Joints*, Springer, use
it with clearance).

Closed form
-----------
The crank pin is ``A = r (cos theta, sin theta)`` and the slider pin
``B = (x, 0)``; ``|B - A| = l`` gives ``(x - r c)^2 + r^2 s^2 = l^2``
(``c = cos theta``, ``s = sin theta``), whose root with the slider on the
right is::

    x = r c + S,                 S = sqrt(l^2 - r^2 s^2)

Differentiating, ``dS/dtheta = -r^2 s c / S``; with ``theta' = omega``::

    x'  = -omega (r s + r^2 s c / S)
    x'' = -omega^2 (r c + r^2 (c^2 - s^2) / S + r^4 s^2 c^2 / S^3)

(:func:`slider_kinematics`; the tests hold the second against central
differences of the first). At ``theta = 0`` the rod lies along ``x`` from
``(r, 0)`` to ``(r + l, 0)``, the slider is at rest and the rod turns at
``-omega r / l``: the scene's initial state, consistent with the joints.

The scene's units are ``l``, the rod's mass and ``1 / omega``: one crank
turn is ``2 pi`` in the scene's time. Coordinates: the rod's ``x, y,
theta`` (its centre), then the slider's.

The model (:func:`slider_crank_model`)::

    m = Model(gravity=(0.0, -g), length=l, mass=rod_mass, time=1 / omega)
    crank = m.add_driven(theta=TimeFunction(0.0, rate=omega))
    rod = m.add_body(rod_mass, rod_mass * l**2 / 12, position=(r + l / 2, 0.0),
                     velocity=(0.0, omega * r / 2), angular_velocity=-omega * r / l)
    slider = m.add_body(slider_mass, slider_inertia, position=(r + l, 0.0))
    m.add_revolute(crank, (r, 0.0), rod, (-l / 2, 0.0))
    m.add_revolute(rod, (l / 2, 0.0), slider, (0.0, 0.0))
    m.add_prismatic(slider, (0.0, 0.0), m.ground, (0.0, 0.0), axis=(1.0, 0.0))
"""

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.cases import GRID, TWO_PI, ExactReference, FactoryCase
from ..errors import InputError
from ..model.planar import Model, Polygon, Segment, TimeFunction
from ..model.params import Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with

__all__ = ["SliderCrankParams", "slider_crank_model", "slider_crank", "slider_kinematics"]


@dataclass(frozen=True)
class SliderCrankParams(Declared):
    """SI parameters of the ideal slider-crank (checked where the model is built)."""

    crank_radius: float = param(0.05, "m", doc="Crank radius")
    rod_length: float = param(0.2, "m", doc="Rod length", note="It must exceed ``crank_radius``.")
    crank_speed: float = param(10.0, "rad/s", doc="Crank angular speed")
    rod_mass: float = param(0.5, "kg", doc="Rod mass", note="A uniform bar.")
    slider_mass: float = param(0.3, "kg", doc="Slider mass")
    gravity: float = param(9.81, "m/s^2", doc="Gravity, along -y")


#: the slider's drawn block [m] (its inertia is that of this block)
_SLIDER_SIZE = (0.04, 0.02)


def _checked(p):
    for name in ("crank_radius", "rod_length", "crank_speed", "rod_mass", "slider_mass"):
        value = getattr(p, name)
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"`{name}` must be finite and > 0, got {value!r}")
    if not p.rod_length > p.crank_radius:
        raise InputError(f"`rod_length` ({p.rod_length!r}) must exceed `crank_radius` "
                         f"({p.crank_radius!r}): a shorter rod cannot follow the crank round")
    if not math.isfinite(p.gravity):
        raise InputError(f"`gravity` must be finite, got {p.gravity!r}")
    return p


def slider_kinematics(theta, r, l, omega=1.0):
    """The slider's ``(x, x', x'')`` at crank angle ``theta`` [rad] (module docstring), in the units of ``r``, ``l``, ``omega``.

    Examples
    --------
    >>> [round(float(a), 12) for a in slider_kinematics(0.0, 1.0, 4.0, 2.0)]
    [5.0, -0.0, -5.0]
    """
    c, s = np.cos(theta), np.sin(theta)
    S = np.sqrt(l * l - r * r * s * s)
    x = r * c + S
    dx = -omega * (r * s + r * r * s * c / S)
    ddx = -omega ** 2 * (r * c + r * r * (c * c - s * s) / S + r ** 4 * s * s * c * c / S ** 3)
    return x, dx, ddx


def slider_crank_model(params=None, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the ideal slider-crank (SI parameters of :class:`SliderCrankParams`)."""
    p = _checked(params_with(SliderCrankParams, params, overrides))
    r, l, w = p.crank_radius, p.rod_length, p.crank_speed
    a, b = _SLIDER_SIZE
    m = Model(gravity=(0.0, -p.gravity), length=l, mass=p.rod_mass, time=1.0 / w)
    crank = m.add_driven(theta=TimeFunction(0.0, rate=w), name="crank")
    rod = m.add_body(p.rod_mass, p.rod_mass * l * l / 12.0, position=(r + 0.5 * l, 0.0),
                     velocity=(0.0, 0.5 * w * r), angular_velocity=-w * r / l, name="rod")
    slider = m.add_body(p.slider_mass, p.slider_mass * (a * a + b * b) / 12.0,
                        position=(r + l, 0.0), name="slider")
    m.add_revolute(crank, (r, 0.0), rod, (-0.5 * l, 0.0))
    m.add_revolute(rod, (0.5 * l, 0.0), slider, (0.0, 0.0))
    m.add_prismatic(slider, (0.0, 0.0), m.ground, (0.0, 0.0), axis=(1.0, 0.0))
    # shapes for drawing only (no contact is added)
    m.add_shape(crank, Segment((0.0, 0.0), (r, 0.0)))
    m.add_shape(rod, Segment((-0.5 * l, 0.0), (0.5 * l, 0.0)))
    m.add_shape(slider, Polygon.box(a, b))
    return m


def slider_crank(params=None, **overrides):
    """The ideal slider-crank's scene (a :class:`~moreau.model.planar.PlanarScene`, six joint rows).

    Examples
    --------
    >>> sc = slider_crank()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ndof, sc.n_joint_rows, float(np.max(np.abs(sc.joint_residuals(q0, 0.0)))) < 1e-15
    (6, 6, True)
    """
    return slider_crank_model(params, **overrides).build(
        "slider-crank", default_window=TWO_PI)


slider_crank.Params = SliderCrankParams


class SliderCrankCase(ExactReference, FactoryCase):
    """One crank turn: the slider's position against the closed form."""

    headline_name = "slider position at the end of the window"
    window = 0.75 * TWO_PI
    trajectory_scale = 0.25
    # no contact: no regime, no switch
    compares_switches = False

    scene_factory = staticmethod(slider_crank)

    def __init__(self, **params):
        super().__init__(**params)
        p = params_with(self.scene_factory.Params, None, params)
        # in the scene's units (length l, time 1 / omega)
        self._r, self._l = p.crank_radius / p.rod_length, 1.0

    def coordinate(self, q):
        return q[:, 3]

    def reference(self, rtol):
        return float(slider_kinematics(self.window, self._r, self._l)[0]), []

    def reference_grid(self):
        return slider_kinematics(np.linspace(0.0, self.window, GRID + 1), self._r, self._l)[0]


register_scene(SceneEntry(
    name="slider-crank",
    factory=slider_crank,
    description=("the ideal slider-crank, crank driven at constant speed, built with joints "
                 "(moreau.model.planar): Moreau-Jean against the closed-form kinematics"),
    case=SliderCrankCase,
))
