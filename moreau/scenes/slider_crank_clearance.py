r"""The slider-crank with a revolute clearance joint between the rod and the slider (Flores et al.).

The mechanism of Flores and Ambrósio, "Revolute joints with clearance in
multibody systems", *Computers & Structures* 82 (2004) 1359-1369, and of
Flores, Ambrósio, Claro and Lankarani, *Kinematics and Dynamics of
Multibody Systems with Imperfect Joints* (Springer, Lecture Notes in
Applied and Computational Mechanics 34, 2008): a crank of ``0.05 m``
driven at ``5000 rpm``, a connecting rod of ``0.12 m``, a slider on a
horizontal guide, and a clearance of ``0.5 mm`` in the joint between the
rod and the slider (the example's values as they are usually quoted from
these works). The journal's radius (``10 mm``, the bearing's ``10.5
mm``) and the masses and centroidal inertias (rod ``0.21 kg``, ``2.5e-4
kg m^2``; slider ``0.14 kg``, ``1e-4 kg m^2``; the driven crank's own
inertia does not enter) are our reading of the publications' tables, not
checked against them here. Those works model the journal-bearing contact
with a continuous (Hertzian, Lankarani-Nikravesh) force with restitution
``0.9``; here it is a rigid
unilateral contact with Newton's restitution ``e = 0.9`` (the
non-smooth formulation of Flores, Leine and Glocker, *Multibody Syst.
Dyn.* 23 (2010) 165-190, for a translational clearance), frictionless by
default.

The model (:func:`slider_crank_clearance_model`): the ideal slider-crank
of :mod:`moreau.scenes.slider_crank` with the rod-slider revolute joint
replaced by :meth:`Model.add_clearance_revolute
<moreau.model.planar.Model.add_clearance_revolute>`, the hole at the rod's
end and the pin at the slider's centre::

    m = Model(gravity=(0.0, -g), length=l, mass=rod_mass, time=1 / omega)
    crank = m.add_driven(theta=TimeFunction(0.0, rate=omega))
    rod = m.add_body(rod_mass, rod_inertia, position=(r + l / 2, 0.0),
                     velocity=(0.0, omega * r / 2), angular_velocity=-omega * r / l)
    slider = m.add_body(slider_mass, slider_inertia, position=(r + l + c, 0.0))
    m.add_revolute(crank, (r, 0.0), rod, (-l / 2, 0.0))
    m.add_clearance_revolute(rod, (l / 2, 0.0), slider, (0.0, 0.0), R_h, R_p, mu, e)
    m.add_prismatic(slider, (0.0, 0.0), m.ground, (0.0, 0.0), axis=(1.0, 0.0))

Coordinates: the rod's ``x, y, theta`` (its centre), then the slider's;
units ``l``, the rod's mass and ``1 / omega`` (one crank turn is ``2 pi``).
It starts at ``theta = 0`` with the ideal mechanism's velocities and the
pin against the bearing's wall on the side the rod pulls it (``d = (c,
0)``, the slider at ``r + l + c``): the slider decelerates there at
``r omega^2 (1 + r / l)``, so the contact is closed and stays closed.

The regimes of a clearance joint (free flight, impact, continuous contact,
Flores and Ambrósio 2004, section 2) come from the sign of the joint's
force, which is about the slider's inertia force ``-m_s x''``: continuous
contact while it keeps its sign, a free flight across the clearance where
the slider's acceleration changes sign, and impacts when the pin meets the
other side. The slider's acceleration follows the ideal one's (its closed
form, :func:`moreau.scenes.slider_crank.slider_kinematics`) between
impacts, with a peak at each impact. As ``c -> 0`` the motion tends to
the ideal mechanism's: the slider's position to within about ``c``.
"""

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.cases import GRID, TWO_PI
from ..errors import InputError, MoreauError
from ..integrators.base import simulate
from ..model.planar import Circle, Model, Polygon, Segment, TimeFunction
from ..model.params import Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import params_with
from .slider_crank import SliderCrankCase

__all__ = ["SliderCrankClearanceParams", "slider_crank_clearance_model",
           "slider_crank_clearance"]


@dataclass(frozen=True)
class SliderCrankClearanceParams(Declared):
    """SI parameters of the slider-crank with a clearance joint (Flores and Ambrósio 2004),
    checked where the model is built."""

    crank_radius: float = param(0.05, "m", doc="Crank radius")
    rod_length: float = param(0.12, "m", doc="Rod length, crank pin to the bearing's centre",
                              note="It must exceed ``crank_radius``.")
    crank_speed: float = param(5000.0 * 2.0 * math.pi / 60.0, "rad/s",
                               doc="Crank angular speed", note="5000 rpm.")
    rod_mass: float = param(0.21, "kg", doc="Rod mass")
    rod_inertia: float = param(2.5e-4, "kg m^2", doc="Rod centroidal inertia")
    slider_mass: float = param(0.14, "kg", doc="Slider mass")
    slider_inertia: float = param(1e-4, "kg m^2", doc="Slider centroidal inertia")
    clearance: float = param(5e-4, "m", doc="Radial clearance ``R_h - R_p``")
    pin_radius: float = param(0.01, "m", doc="Journal (pin) radius ``R_p``")
    mu: float = param(0.0, doc="Coulomb friction between journal and bearing")
    restitution: float = param(0.9, doc="Newton restitution of the journal-bearing impacts")
    gravity: float = param(9.81, "m/s^2", doc="Gravity, along -y")


def _checked(p):
    for name in ("crank_radius", "rod_length", "crank_speed", "rod_mass", "rod_inertia",
                 "slider_mass", "slider_inertia", "clearance", "pin_radius"):
        value = getattr(p, name)
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"`{name}` must be finite and > 0, got {value!r}")
    if not p.rod_length > p.crank_radius + p.clearance:
        raise InputError(f"`rod_length` ({p.rod_length!r}) must exceed `crank_radius` + "
                         f"`clearance` ({p.crank_radius + p.clearance!r}): a shorter rod "
                         "cannot follow the crank round")
    if not p.clearance < 0.1 * p.rod_length:
        raise InputError(f"`clearance` ({p.clearance!r}) must be less than a tenth of "
                         f"`rod_length` ({p.rod_length!r}): a clearance joint, not a slot")
    if not (math.isfinite(p.mu) and p.mu >= 0.0):
        raise InputError(f"`mu` must be finite and >= 0, got {p.mu!r}")
    if not 0.0 <= p.restitution <= 1.0:
        raise InputError(f"`restitution` must be in [0, 1], got {p.restitution!r}")
    if not math.isfinite(p.gravity):
        raise InputError(f"`gravity` must be finite, got {p.gravity!r}")
    return p


#: the slider's drawn block [m]
_SLIDER_SIZE = (0.04, 0.02)


def slider_crank_clearance_model(params=None, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the slider-crank with clearance (SI parameters of :class:`SliderCrankClearanceParams`)."""
    p = _checked(params_with(SliderCrankClearanceParams, params, overrides))
    r, l, w, c = p.crank_radius, p.rod_length, p.crank_speed, p.clearance
    m = Model(gravity=(0.0, -p.gravity), length=l, mass=p.rod_mass, time=1.0 / w)
    crank = m.add_driven(theta=TimeFunction(0.0, rate=w), name="crank")
    rod = m.add_body(p.rod_mass, p.rod_inertia, position=(r + 0.5 * l, 0.0),
                     velocity=(0.0, 0.5 * w * r), angular_velocity=-w * r / l, name="rod")
    slider = m.add_body(p.slider_mass, p.slider_inertia, position=(r + l + c, 0.0),
                        name="slider")
    m.add_revolute(crank, (r, 0.0), rod, (-0.5 * l, 0.0))
    m.add_clearance_revolute(rod, (0.5 * l, 0.0), slider, (0.0, 0.0),
                             hole_radius=p.pin_radius + c, pin_radius=p.pin_radius,
                             mu=p.mu, restitution=p.restitution)
    m.add_prismatic(slider, (0.0, 0.0), m.ground, (0.0, 0.0), axis=(1.0, 0.0))
    # shapes for drawing only (no contact is added)
    a, b = _SLIDER_SIZE
    m.add_shape(crank, Segment((0.0, 0.0), (r, 0.0)))
    m.add_shape(rod, Segment((-0.5 * l, 0.0), (0.5 * l, 0.0)))
    m.add_shape(rod, Circle(p.pin_radius + c, (0.5 * l, 0.0)))
    m.add_shape(slider, Polygon.box(a, b))
    m.add_shape(slider, Circle(p.pin_radius))
    return m


def slider_crank_clearance(params=None, **overrides):
    """The slider-crank with a clearance joint (a :class:`~moreau.model.planar.PlanarScene`: four joint rows, one contact).

    Examples
    --------
    >>> sc = slider_crank_clearance()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ndof, sc.n_joint_rows, sc.ncontacts, abs(float(sc.gaps(q0, 0.0)[0])) < 1e-15
    (6, 4, 1, True)
    """
    return slider_crank_clearance_model(params, **overrides).build(
        "slider-crank-clearance", default_window=TWO_PI)


slider_crank_clearance.Params = SliderCrankClearanceParams


class SliderCrankClearanceCase(SliderCrankCase):
    """Three quarters of a crank turn: the slider's position against the event-driven reference.

    The reference is ``event-driven-generic`` on the same model (its free
    flights, impacts and continuous contact located as events, the joints
    held by index reduction and projection); the ideal mechanism's closed
    form differs from it by the clearance's own effect, a few ``c / l``,
    which no step size removes. Contact switches are not compared.
    """

    listed_reference = None
    ref_scheme = "event-driven-generic"

    scene_factory = staticmethod(slider_crank_clearance)

    def _reference_run(self, rtol):
        rtol = 1e-10 if rtol is None else rtol
        q0, v0 = self.start()
        res = simulate(self.scene, (0.0, self.window), q0, v0, "event-driven-generic",
                       rtol=rtol, t_eval=np.linspace(0.0, self.window, GRID + 1))
        if res.status != 0:
            raise MoreauError(f"slider-crank-clearance: the event-driven reference stopped at "
                              f"t = {res.t[-1]!r} (status {res.status}): {res.message}")
        return np.array(res.q[:, 3], dtype=float)

    def reference(self, rtol):
        grid = self._reference_run(rtol)
        self._tight = grid
        return float(grid[-1]), []

    def reference_grid(self):
        grid = getattr(self, "_tight", None)
        return self._reference_run(None) if grid is None else grid


register_scene(SceneEntry(
    name="slider-crank-clearance",
    factory=slider_crank_clearance,
    description=("the slider-crank of Flores and Ambrosio (2004) with a revolute clearance "
                 "joint between rod and slider (moreau.model.planar), Moreau-Jean only"),
    case=SliderCrankClearanceCase,
))
