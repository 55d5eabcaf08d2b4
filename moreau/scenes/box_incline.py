r"""A box on a rough incline in space, on its four bottom corners: sliding at ``g (sin a - mu cos a)``.

A uniform box (mass ``m``, half-edges ``a`` down the slope, ``b`` across,
``c`` along the normal) lies flat on a plane inclined at ``alpha`` and
touches it through its four bottom corners
(:class:`moreau.model.space.Box`, corners ``0..3``), each with Coulomb
friction ``mu``; it is launched down the slope line at ``speed``. While it
stays flat (below) it translates: with ``s`` the distance down the slope,
``N = m g cos(alpha)`` the plane's total normal force and ``F`` the total
friction force (up the slope),

.. math::

    m \ddot s = m g \sin\alpha - F, \qquad
    F = \mu N \text{ sliding (} \dot s > 0\text{)}, \qquad
    F = m g \sin\alpha \text{ at rest},

so it slides at ``s'' = g (sin(alpha) - mu cos(alpha))``: for ``mu <
tan(alpha)`` it speeds up from any start, for ``mu > tan(alpha)`` it slows
down and stops at ``t* = v0 / (g (mu cos(alpha) - sin(alpha)))``, then stays
at rest (the textbook block on an incline, e.g. Meriam and Kraige,
Engineering Mechanics: Dynamics, the block on the incline with Coulomb friction).

The corners' normal forces. Four corners on a plane carry the weight in a
statically indeterminate way: only the three resultants that the rigid box
fixes are determinate, the total ``N``, its moment about the slope line (zero:
the two sides carry the same) and its moment about the across-slope axis.
Moments about the centre along ``y`` (the corner forces ``(-F_i, 0, N_i)`` at
``(+-a, +-b, -c)``) give ``c F - a (N_front - N_back) = 0``, with
``N_front`` the sum over the two down-slope corners:

.. math::

    N_{front} = \frac N2 \Bigl(1 + \frac{c F}{a N}\Bigr), \qquad
    N_{back} = \frac N2 \Bigl(1 - \frac{c F}{a N}\Bigr).

The box stays flat while ``N_back > 0``: ``mu c < a`` sliding, ``c tan(alpha)
< a`` at rest; beyond it tips over its front edge (the parameters are refused
there, naming the rule: the tipping has no closed form, and the box's four
bottom corners stop describing it when it lands on its front face). The
split of ``N_front`` between its two corners (and the friction between all
four) is the indeterminate part: a solver returns one admissible split.

The scene is stated in the incline's frame: ``x`` down the slope, ``y``
across, ``z`` the normal, gravity ``g (sin(alpha), 0, -cos(alpha))``; units:
lengths in ``a``, time in ``sqrt(a / g)``, mass in ``m``
(:class:`moreau.model.space.SpaceModel`).
"""

import math
from dataclasses import dataclass

import numpy as np

from .._validate import times
from ..analysis.cases import GRID, ExactReference, SpatialCase
from ..errors import InputError
from ..model.params import GRAVITY, MASS, MU, POSITIVE, SLOPE, SPEED, Declared, param
from ..model.registry import SceneEntry, register_scene
from ..model.scene import as_params, params_with
from ..model.space import Box, SpaceModel

__all__ = ["BoxInclineParams", "box_incline", "box_incline_motion", "slides", "stop_time"]


@dataclass(frozen=True)
class BoxInclineParams(Declared):
    """SI parameters of the box on the incline.

    {attributes}

    Raises
    ------
    InputError
        Where the box would tip over its front edge (``mu c >= a`` while it
        slides, ``c tan(alpha) >= a`` at rest), naming ``mu`` or ``slope``.
    """

    mass: float = MASS(0.5)
    half_length: float = param(0.1, "m", POSITIVE, "Half-edge down the slope")
    half_width: float = param(0.05, "m", POSITIVE, "Half-edge across the slope")
    half_height: float = param(0.05, "m", POSITIVE, "Half-edge along the slope's normal")
    slope: float = SLOPE(0.3, "Inclination ``alpha``")
    mu: float = MU(0.2, "Coulomb friction at each corner",
                   note="The default 0.2 is below ``tan(0.3) = 0.309``: the box slides, "
                        "speeding up.")
    gravity: float = GRAVITY(9.81)
    speed: float = SPEED(0.5, "Launch speed down the slope line")

    sweepable = ("mu", "slope", "speed")

    def __post_init__(self):
        super().__post_init__()
        a, c = self.half_length, self.half_height
        if slides(self) and self.mu * c >= a:
            raise InputError(f"`mu` times `half_height` must be below `half_length` while the "
                             f"box slides (else it tips over its front edge), got mu c = "
                             f"{self.mu * c!r} >= a = {a!r}")
        if c * math.tan(self.slope) >= a:
            raise InputError(f"`slope`'s tangent times `half_height` must be below "
                             f"`half_length` (else the box at rest tips over its front edge), "
                             f"got c tan(slope) = {c * math.tan(self.slope)!r} >= a = {a!r}")


def slides(p):
    """Whether the box slides at some time: launched (``speed > 0``) or ``mu < tan(slope)``."""
    return p.speed > 0.0 or p.mu < math.tan(p.slope)


def box_incline(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the box on the incline.

    Examples
    --------
    >>> sc = box_incline()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ncontacts, sc.gaps(q0, 0.0).tolist(), round(float(v0[0] * sc.length / sc.time), 12)
    (4, [0.0, 0.0, 0.0, 0.0], 0.5)
    """
    p = params_with(BoxInclineParams, params, overrides)
    g, al = p.gravity, p.slope
    a, b, c = p.half_length, p.half_width, p.half_height
    m = SpaceModel(gravity=(g * math.sin(al), 0.0, -g * math.cos(al)), length=a, mass=p.mass)
    plane = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    # a uniform box's principal moments: m (b^2 + c^2) / 3 about x, and so on
    J = [p.mass * (b * b + c * c) / 3.0, p.mass * (a * a + c * c) / 3.0,
         p.mass * (a * a + b * b) / 3.0]
    box = m.add_body(p.mass, J, position=(0.0, 0.0, c), velocity=(p.speed, 0.0, 0.0), name="box")
    m.add_contact(box, Box((a, b, c), corners=(0, 1, 2, 3)), plane, mu=p.mu)
    sc = m.build("box-incline", default_window=10.0)
    sc.params = p
    return sc


box_incline.Params = BoxInclineParams


def box_incline_motion(params, t):
    """``(s, s', N_front, N_back)`` at times ``t`` [s] (SI): the distance and speed down the
    slope, and the normal forces [N] on the two down-slope and the two up-slope corners.

    The closed form of the module docstring; at rest from ``t*`` where the
    box stops (``mu > tan(slope)``).

    Examples
    --------
    >>> p = BoxInclineParams(speed=0.0)
    >>> s, sd, nf, nb = box_incline_motion(p, [1.0])
    >>> round(float(sd[0]) / (9.81 * (math.sin(0.3) - 0.2 * math.cos(0.3))), 12)
    1.0
    >>> round(float((nf[0] - nb[0]) / (nf[0] + nb[0])), 12)     # mu c / a
    0.1
    """
    p = as_params(BoxInclineParams, params)
    tt = times("t", t)
    g, al, v0 = p.gravity, p.slope, p.speed
    acc = g * (math.sin(al) - p.mu * math.cos(al))
    N = p.mass * g * math.cos(al)
    t_stop = stop_time(p)
    moving = tt < t_stop
    tm = np.minimum(tt, t_stop)
    s = v0 * tm + 0.5 * acc * tm * tm
    sd = np.where(moving, v0 + acc * tt, 0.0)
    F = np.where(moving, p.mu * N, p.mass * g * math.sin(al))
    ratio = p.half_height * F / (p.half_length * N)
    return s, sd, 0.5 * N * (1.0 + ratio), 0.5 * N * (1.0 - ratio)


def stop_time(p):
    """The time [s] the box comes to rest (``inf`` where it never does, 0 at rest from the start)."""
    acc = p.gravity * (math.sin(p.slope) - p.mu * math.cos(p.slope))
    if acc > 0.0 or (acc == 0.0 and p.speed > 0.0):
        return math.inf
    return p.speed / -acc if acc < 0.0 else 0.0


class BoxInclineCase(ExactReference, SpatialCase):
    """The box over the window: its distance down the slope against the closed form."""

    headline_name = "distance down the slope"
    window = 10.0
    compares_switches = False

    scene_factory = staticmethod(box_incline)

    def reference(self, rtol):
        s, _, _, _ = box_incline_motion(self.p, [self.window * self.scene.time])
        ts = stop_time(self.p) / self.scene.time
        switches = [(0.0, "S" if ts == 0.0 else "P")]
        if 0.0 < ts < self.window:
            switches.append((ts, "S"))
        return float(s[0]) / self.scene.length, switches

    def reference_grid(self):
        s, _, _, _ = box_incline_motion(self.p, np.linspace(0.0, self.window, GRID + 1)
                                        * self.scene.time)
        return s / self.scene.length


register_scene(SceneEntry(
    name="box-incline",
    factory=box_incline,
    description=("box on its four bottom corners sliding down a rough incline in space at "
                 "g (sin a - mu cos a), at rest for mu > tan a; the front and back corners' "
                 "normal forces (closed form)"),
    case=BoxInclineCase,
))
