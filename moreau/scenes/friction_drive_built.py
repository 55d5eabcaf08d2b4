r"""The paper's friction drive stated with the planar builder: the check of :mod:`moreau.model.planar` against :mod:`moreau.scenes.friction_drive`.

The same drive as ``friction-drive`` (Liu, Zhou, Ruan, Fu; the paper's
second type, its parameters :data:`~moreau.scenes.friction_drive.PAPER_DEFAULTS`),
at the same parameters and drive frequency, in the same variables: the
builder's units are the hand-written scene's (``length = l``, ``mass = m``,
``time = 1 / w``), so that its coordinates are the rod angle ``phi`` and the
rotor's ``u2 = x2 / l``, in that order, against ``tau = w t``.

How the builder's parts give the hand-written equations
--------------------------------------------------------
* The **stator** is a driven body, ``y = x1(t) = x10 (1 - cos w t)``, the
  harmonic ``x10 - x10 sin(w t + pi/2)`` of a :class:`TimeFunction`.
* The **rod** is a guided body: its frame's origin is the hinge, moved with
  the stator (``x = 0``, ``y = x1(t)`` prescribed), its angle ``theta = phi``
  free, its centre of mass at ``(l/2, 0)`` with the centroidal inertia
  ``m l^2 / 12``. The builder gives it the inertia about the hinge, ``m
  l^2/12 + m l^2/4 = m l^2/3`` (the ``1/3`` of ``M``), and the torque of the
  hinge's acceleration at the centre of mass, ``(R c) x m (0, -x1'') = -m l/2
  x1'' cos phi`` (the ``-u1''/2 cos phi`` of ``h``).
* The **rotor** is a guided body moving along ``x`` only (``y`` and
  ``theta`` prescribed constants), its frame's origin on its lower surface
  at the height ``l sin phi0`` above the hinge's rest, a half-plane of
  normal ``(0, -1)``: the material above.
* The **contact** is the rod's tip, the point ``(l, 0)`` of the rod, against
  that half-plane: the gap ``n . (P - X_rotor) = l sin phi0 - x1 - l sin phi``
  (``g_N`` of the paper's model); its rows ``-cos phi`` (normal, with the
  stator's velocity ``-x1'`` in ``w_N``) and ``(sin phi, 1)`` (tangent
  ``(-1, 0)``: the rotor's velocity less the tip's), with ``mu`` and ``e``.
* The **spring** ``k`` acts on the tip's height above the hinge, ``l sin
  phi``: an axial spring along ``(0, 1)`` between the tip and the stator's
  origin, at rest at ``l sin phi0``, so ``V = k l^2 (sin phi0 - sin phi)^2 /
  2``.
* The **preload** ``F_p`` is the given force ``(0, F_p)`` at the tip
  (``V_p = F_p l (sin phi0 - sin phi)``), the **load** ``(-F_L, 0)`` on the
  rotor.

The model (:func:`friction_drive_model`), with ``x1`` the stator's
:class:`~moreau.model.planar.TimeFunction`::

    m = Model(gravity=(0, 0), length=l, mass=m_rod, time=1 / w)
    stator = m.add_driven(y=x1, name="stator")
    rod = m.add_guided(m_rod, m_rod * l**2 / 12, x=0.0, y=x1, angle=phi0, centre=(l / 2, 0))
    rotor = m.add_guided(m2, m2 * l**2, y=l * sin(phi0), theta=0.0)
    m.add_contact(m.add_shape(rod, Point((l, 0))),
                  m.add_shape(rotor, HalfPlane((0, 0), (0, -1))), mu=mu, restitution=e)
    m.add_axial_spring(rod, (l, 0), stator, (0, 0), (0, 1), k, rest_length=l * sin(phi0))
    m.add_force(rod, (0.0, F_p), point=(l, 0))
    m.add_force(rotor, (-F_L, 0.0))

The tests hold every time-stepping scheme's runs of the two scenes together
to 1e-12, at 185 Hz and 2000 Hz, and their Moreau–Jean steady states.
"""

import math

import numpy as np

from ..model.planar import HalfPlane, Model, Point, TimeFunction
from ..model.registry import SceneEntry, parameters_of, register_scene
from ..model.scene import params_with
from .._validate import positive
from .friction_drive import FrictionDriveParams, PAPER_DEFAULTS
from .friction_drive.scene import FREQUENCY, FrictionDriveCase

__all__ = ["friction_drive_model", "friction_drive_built"]


def friction_drive_model(params=None, frequency=185.0, **overrides):
    """The builder's :class:`~moreau.model.planar.Model` of the friction drive (SI parameters of :class:`~moreau.scenes.friction_drive.FrictionDriveParams`, ``frequency`` [Hz])."""
    p = params_with(FrictionDriveParams, PAPER_DEFAULTS if params is None else params, overrides)
    w = 2.0 * math.pi * positive("frequency", frequency)
    l, s0 = p.length, math.sin(p.phi0)
    x1 = TimeFunction(p.x10, harmonics=[(-p.x10, w, 0.5 * math.pi)])  # x10 (1 - cos w t)
    m = Model(gravity=(0.0, 0.0), length=l, mass=p.m, time=1.0 / w)
    stator = m.add_driven(y=x1, name="stator")
    rod = m.add_guided(p.m, p.m * l * l / 12.0, x=0.0, y=x1, angle=p.phi0, centre=(0.5 * l, 0.0),
                       name="rod")
    rotor = m.add_guided(p.m2, p.m2 * l * l, y=l * s0, theta=0.0, name="rotor")
    m.add_contact(m.add_shape(rod, Point((l, 0.0))),
                  m.add_shape(rotor, HalfPlane((0.0, 0.0), (0.0, -1.0))), mu=p.mu,
                  restitution=p.restitution)
    m.add_axial_spring(rod, (l, 0.0), stator, (0.0, 0.0), (0.0, 1.0), p.k, rest_length=l * s0)
    m.add_force(rod, (0.0, p.preload), point=(l, 0.0))
    m.add_force(rotor, (-p.load, 0.0))
    return m


def _leaning(t, q, v):
    phi = np.asarray(q).reshape(-1, 2)[:, 0]
    return (phi > 0.0) & (phi < 0.5 * math.pi)


def friction_drive_built(params=None, frequency=185.0, **overrides):
    """The built friction drive's scene (a :class:`~moreau.model.planar.PlanarScene`), ``q = (phi, u2)``.

    It carries the drive's period (``2 pi``), its cyclic rotor coordinate and
    its velocity scale, so that the steady-state analyses take it as they
    take ``friction-drive``.

    Examples
    --------
    >>> sc = friction_drive_built(frequency=185.0)
    >>> q0, v0 = sc.initial_state()
    >>> sc.ndof, sc.ncontacts, [round(float(x), 12) for x in q0], float(sc.gaps(q0, 0.0)[0])
    (2, 1, [0.785398163397, 0.0], 0.0)
    """
    p = params_with(FrictionDriveParams, PAPER_DEFAULTS if params is None else params, overrides)
    sc = friction_drive_model(p, frequency).build(
        "friction-drive-built", valid_region="0 < phi < pi/2 (the rod leans towards the rotor)",
        inside=_leaning)
    sc.params, sc.frequency = p, float(frequency)
    sc.period = 2.0 * math.pi
    sc.cyclic_coordinates = (1,)
    sc.u10 = p.x10 / p.length
    sc.velocity_scale = sc.u10
    sc.coordinate_names = ("phi", "x2")
    return sc


class FrictionDriveBuiltCase(FrictionDriveCase):
    """The hand-written drive's comparison case (the walker's steady state) run on the built scene."""

    def __init__(self, frequency=185.0, **params):
        self._hand = FrictionDriveCase(frequency, **params)
        super().__init__(frequency, **params)
        self.scene = friction_drive_built(frequency=frequency, **params)

    def reference(self, rtol):
        return self._hand.reference(rtol)

    def _tight(self):
        return self._hand._tight()


register_scene(SceneEntry(
    name="friction-drive-built",
    factory=friction_drive_built,
    parameters=parameters_of(FrictionDriveParams, extra=(FREQUENCY,)),
    description=("the paper's friction drive stated with the planar builder (moreau.model.planar): "
                 "the same equations as friction-drive"),
    case=FrictionDriveBuiltCase,
    sweepable=FrictionDriveParams.sweepable,
))
