"""A sphere on a rough incline in space: rolling at ``(5/7) g sin(alpha)``, slipping below ``mu = (2/7) tan(alpha)``.

A uniform sphere (mass ``m``, radius ``r``, ``J = (2/5) m r^2``) on a plane
inclined at ``alpha``, one frictional contact (Coulomb ``mu``), launched
rolling down the slope at ``speed``. With ``s`` the distance down the slope
and ``w`` the rotation about the across-slope axis, rolling ``s' = r w`` and
``m s'' = m g sin(alpha) - F``, ``J w' = r F`` give

.. math::

    s'' = \\frac{g \\sin\\alpha}{1 + J / (m r^2)} = \\tfrac57 g \\sin\\alpha, \\qquad
    F = \\tfrac27 m g \\sin\\alpha,

which needs ``F <= mu m g cos(alpha)``: ``mu >= (2/7) tan(alpha)``. Below
it the sphere slips from the start, ``s'' = g (sin(alpha) - mu cos(alpha))``
and ``r w' = (5/2) mu g cos(alpha)``; the slip rate ``g (sin(alpha) - (7/2)
mu cos(alpha))`` is positive, so it never rolls again (the textbook result,
e.g. Meriam and Kraige, Engineering Mechanics: Dynamics, the rolling sphere
on an incline; Goldstein, Poole and Safko, Classical Mechanics, 3rd ed.,
2002, ch. 5).

The scene is stated in the incline's frame: ``x`` down the slope, ``y``
across, ``z`` the plane's normal, gravity ``g (sin(alpha), 0, -cos(alpha))``;
units: lengths in ``r``, time in ``sqrt(r / g)``, mass in ``m``
(:class:`moreau.model.space.SpaceModel`). Coordinates: the centre (3) and
the unit quaternion (4); velocities: the centre's (3) and the body-frame
angular velocity (3).
"""

import math
from dataclasses import dataclass

from ..analysis.cases import SpatialCase
from ..model.params import RADIUS
from ..model.registry import SceneEntry, register_scene
from ..model.scene import as_params, params_with
from ._sphere_on_plane import sphere_on_plane
from .disk_incline import InclineCase, InclineParams, incline_motion, rolls_down

__all__ = ["SphereInclineParams", "sphere_incline", "sphere_incline_exact", "rolls"]


@dataclass(frozen=True)
class SphereInclineParams(InclineParams):
    """SI parameters of the sphere on an incline: those of :class:`InclineParams`, radius
    5 cm by default."""

    radius: float = RADIUS(0.05)


def rolls(p):
    """Whether the sphere rolls: ``mu >= (2/7) tan(alpha)``.

    Examples
    --------
    >>> rolls(SphereInclineParams(slope=0.3, mu=0.0884)), rolls(SphereInclineParams(mu=0.0883))
    (True, False)
    """
    return rolls_down(p, 0.4)


def sphere_incline(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the sphere on the incline.

    Examples
    --------
    >>> sc = sphere_incline()
    >>> q0, v0 = sc.initial_state()
    >>> q0.tolist(), round(float(v0[4] * v0[0] ** -1), 12)      # rolling: w = s' / r
    ([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0], 1.0)
    """
    p = params_with(SphereInclineParams, params, overrides)
    g, a = p.gravity, p.slope
    return sphere_on_plane("sphere-incline", p, (g * math.sin(a), 0.0, -g * math.cos(a)),
                           p.speed / p.radius, "sphere", 10.0)


sphere_incline.Params = SphereInclineParams


def sphere_incline_exact(params, t):
    """``(s, s', w)``: distance and speed down the slope, rotation rate, at times ``t`` [s] (SI).

    Examples
    --------
    >>> s, sd, w = sphere_incline_exact(SphereInclineParams(speed=0.0), [1.0])
    >>> round(float(sd[0]) / (9.81 * math.sin(0.3)), 12)     # rolling: 5/7 g sin(alpha)
    0.714285714286
    """
    p = as_params(SphereInclineParams, params)
    return incline_motion(p, t, 0.4)


class SphereInclineCase(InclineCase, SpatialCase):
    """The sphere over the window: distance down the slope against the closed form."""

    inertia = 0.4
    scene_factory = staticmethod(sphere_incline)

    def coordinate(self, q):
        return q[:, 0]


register_scene(SceneEntry(
    name="sphere-incline",
    factory=sphere_incline,
    description=("sphere rolling down a rough incline in space at (5/7) g sin(alpha), slipping "
                 "below mu = (2/7) tan(alpha) (closed form)"),
    case=SphereInclineCase,
))
