r"""A stack of boxes in space: resting, sliding or on an incline, face on face.

``N`` equal cubes (mass ``m``, half-edge ``a``) stand on a rough plane
inclined at ``alpha`` (0: the ground), each shifted by ``offset`` along the
slope line from the one below. The bottom cube touches the plane through its
four bottom corners (:class:`moreau.model.space.Box`), each neighbouring
pair through a box–box contact
(:meth:`moreau.model.space.SpaceModel.add_box_contact`: the separating
axes, then the top face clipped against the bottom one: four points for an
aligned pair, two corners and two edge crossings for an offset one), all
with Coulomb's ``mu``; every cube starts at ``speed`` down the slope line.
The stack of boxes is the standard test of rigid-body engines for resting
contact (Bullet, ODE, Chrono); Erleben ("Stable, robust, and versatile
multibody dynamics animation", PhD thesis, University of Copenhagen, 2004)
uses stacks to judge the stability of time-stepping schemes.

Closed forms (the stack moves as one block)
-------------------------------------------
The plane's frame: ``x`` down the slope, ``z`` its normal, gravity ``g (sin
alpha, 0, -cos alpha)``. Let every cube move with the same acceleration
``s''`` along ``x``. The cubes from ``k`` up (``N - k`` of them) take, at
interface ``k`` (the plane for ``k = 0``), the normal force and friction

.. math::

    N_k = (N - k)\, m g \cos\alpha, \qquad
    F_k = (N - k)\, m (g \sin\alpha - s''),

so ``F_k / N_k`` is the same at every interface. Sliding on the plane
(``s' > 0``), ``F_0 = mu N_0`` gives

.. math::

    s'' = g (\sin\alpha - \mu \cos\alpha), \qquad F_k = \mu N_k ,

each interface above exactly at its Coulomb limit, so no cube slides on
another (a cube sliding on the one below would have its friction ``mu N_k``
against the slip and the same acceleration: the block is the motion). On
the ground (``alpha = 0``) the stack launched at ``v0`` decelerates at ``mu
g`` and stops after ``t* = v0 / (mu g)`` at the distance ``v0^2 / (2 mu
g)``; on the incline it stays at rest from rest when ``tan(alpha) <= mu``
(``F_k / N_k = tan(alpha)``), and slides at ``g (sin(alpha) - mu cos(alpha))``
when ``tan(alpha) > mu``. At rest on the ground, ``N_k = (N - k) m g``: the
normal impulse of a time step of ``h`` over interface ``k`` is ``h g`` times the
mass above it, and no friction acts.

The block stays upright while the resultant of each interface's forces
acts inside that interface's face. The ``N - k`` cubes above interface ``k``
have their centre of mass ``(N - k) a`` above it, at ``x = offset (k + N -
1) / 2``; with ``F_k / N_k = rho`` (``mu`` sliding, ``tan(alpha)`` at rest)
the normal resultant sits at ``x_k = offset (k + N - 1) / 2 + rho (N - k)
a`` (moments about the centre of mass), which must lie in the overlap of the
two faces, ``[k offset - a, (k - 1) offset + a]`` for ``offset >= 0`` (the
plane's ``[-a, a]`` for ``k = 0``). Parameters outside are refused by name:
the stack would topple, which has no closed form here. (This is the
harmonic stack's rule at ``rho = 0``.)

The split of each interface's ``N_k`` among its points is statically
indeterminate; the totals are not. Moreau–Jean keeps the resting stack at
rest to rounding and gives the totals to rounding; the sliding block's
velocity is exact at every step (a constant acceleration), its position at
``theta = 1/2``.

Scales: lengths in ``a``, time in ``sqrt(a / g)``, masses in ``m``. The
cubes start ``STACK_SQUEEZE`` half-edges into each other, so that rounding
leaves every interface closed at the first step.
"""

import math
from dataclasses import dataclass

import numpy as np

from .._validate import times
from ..analysis.cases import GRID, ExactReference, SpatialCase
from ..errors import InputError
from ..model.params import GRAVITY, MASS, MU, POSITIVE, SPEED, Declared, param, whole_number
from ..model.registry import SceneEntry, register_scene
from ..model.scene import as_params, params_with
from ..model.space import Box, SpaceModel

__all__ = ["BoxStack3DParams", "box_stack_3d", "block_motion", "MAX_BOXES", "STACK_SQUEEZE"]

#: the tallest stack the scene takes (its step is the Python one, a dense cone problem)
MAX_BOXES = 10

#: each cube starts this fraction of the half-edge into the one below
STACK_SQUEEZE = 1e-13


@dataclass(frozen=True)
class BoxStack3DParams(Declared):
    """SI parameters of the stack of cubes."""

    n_boxes: int = param(3, "", whole_number(1, MAX_BOXES), "Number of cubes ``N``",
                         "On resting cubes the contact problem is singular (four points a face, "
                         "more contact rows than freedoms); where the exact cone's Newton polish "
                         "stalls on it, the least-norm sticking impulse is its answer "
                         "(:func:`moreau.contact.cone3d.solve_exact`).")
    mass: float = MASS(1.0, "Each cube's mass")
    half_size: float = param(0.05, "m", POSITIVE, "Each cube's half-edge ``a``")
    mu: float = MU(0.5, "Coulomb friction at every contact")
    offset: float = param(0.0, "m", doc="Each cube's shift down the slope line from the one below",
                          note="With the slope, ``mu`` and the speed it must keep the stack "
                               "upright (the module docstring).")
    slope: float = param(0.0, "rad", doc="The plane's inclination", note="In [0, pi/2).")
    speed: float = SPEED(0.0, "Every cube's initial speed down the slope line")
    gravity: float = GRAVITY(9.81)

    sweepable = ("n_boxes", "mu", "offset", "slope", "speed")

    def __post_init__(self):
        super().__post_init__()
        if not (isinstance(self.offset, (int, float)) and math.isfinite(self.offset)):
            raise InputError(f"`offset` must be a finite number [m], got {self.offset!r}")
        if not (isinstance(self.slope, (int, float)) and 0.0 <= self.slope < 0.5 * math.pi):
            raise InputError(f"`slope` must be in [0, pi/2) [rad], got {self.slope!r}")
        k = _toppling_interface(self)
        if k is not None:
            raise InputError(f"`offset`, `mu`, `slope` and `speed` must keep every interface's "
                             f"normal resultant inside its face (the stack would topple at "
                             f"interface {k}, which has no closed form here), got offset = "
                             f"{self.offset!r}, mu = {self.mu!r}, slope = {self.slope!r}")


def _slides(p):
    return p.speed > 0.0 or p.mu < math.tan(p.slope)


def _toppling_interface(p):
    # the module docstring's rule: the first interface whose normal resultant leaves its face
    n, a, d = p.n_boxes, p.half_size, p.offset
    rho = p.mu if _slides(p) else math.tan(p.slope)
    for k in range(n):
        x = d * (k + n - 1) / 2.0 + rho * (n - k) * a
        # the bottom cube's face on the plane; above, the overlap of two cubes' faces
        lo, hi = (-a, a) if k == 0 else (max(k * d, (k - 1) * d) - a, min(k * d, (k - 1) * d) + a)
        if not lo < x < hi:
            return k
    return None


def box_stack_3d(params=None, **overrides):
    """The scene (a :class:`~moreau.model.space.SpaceScene`) of the stack.

    Contacts ``0..3`` are the bottom cube's corners on the plane, ``4 + 8 (k
    - 1) .. 11 + 8 (k - 1)`` the eight slots of interface ``k`` (cube ``k -
    1`` against cube ``k``).

    Examples
    --------
    >>> sc = box_stack_3d()
    >>> q0, v0 = sc.initial_state()
    >>> sc.ncontacts, int(sc.contacts_in_use(q0).sum())      # 4 + 2 x 8 slots, 12 points
    (20, 12)
    """
    p = params_with(BoxStack3DParams, params, overrides)
    g, al, a = p.gravity, p.slope, p.half_size
    m = SpaceModel(gravity=(g * math.sin(al), 0.0, -g * math.cos(al)), length=a, mass=p.mass)
    plane = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0))
    box = Box((a, a, a))
    cubes = [m.add_body(p.mass, box.inertia(p.mass),
                        position=(k * p.offset, 0.0, a * (2 * k + 1 - STACK_SQUEEZE * k)),
                        velocity=(p.speed, 0.0, 0.0), name=f"cube {k}")
             for k in range(p.n_boxes)]
    m.add_contact(cubes[0], Box((a, a, a), corners=(0, 1, 2, 3)), plane, mu=p.mu)
    for k in range(1, p.n_boxes):
        m.add_box_contact(cubes[k - 1], box, cubes[k], box, mu=p.mu)
    sc = m.build("box-stack-3d", default_window=4.0)
    sc.params = p
    return sc


box_stack_3d.Params = BoxStack3DParams


def block_motion(params, t):
    """``(s, s')``: the block's distance [m] and speed [m/s] down the slope at times ``t`` [s].

    The module docstring's closed form: acceleration ``g (sin(alpha) - mu
    cos(alpha))`` while it moves, at rest from the time it stops (or from
    the start, at rest with ``tan(alpha) <= mu``).

    Examples
    --------
    >>> s, sd = block_motion(BoxStack3DParams(n_boxes=1, speed=1.0), [10.0])
    >>> round(float(s[0]) * 2 * 0.5 * 9.81, 12), float(sd[0])    # v0^2 / (2 mu g), stopped
    (1.0, 0.0)
    """
    p = as_params(BoxStack3DParams, params)
    tt = times("t", t)
    acc = p.gravity * (math.sin(p.slope) - p.mu * math.cos(p.slope))
    if acc > 0.0 or (acc == 0.0 and p.speed > 0.0):
        t_stop = math.inf
    else:
        t_stop = p.speed / -acc if acc < 0.0 else 0.0
    tm = np.minimum(tt, t_stop)
    return p.speed * tm + 0.5 * acc * tm * tm, np.where(tt < t_stop, p.speed + acc * tt, 0.0)


class BoxStack3DCase(ExactReference, SpatialCase):
    """The top cube's height over the window: the block neither sinks nor lifts (its slide
    down the slope is held to :func:`block_motion` in ``tests/scenes``)."""

    headline_name = "top cube's height above the plane"
    window = 4.0
    compares_switches = False

    scene_factory = staticmethod(box_stack_3d)

    def _top(self, tau):
        height = self.scene.initial_state()[0][7 * (self.scene.nbodies - 1) + 2]
        return np.full(np.shape(tau), height)

    def coordinate(self, q):
        return q[:, 7 * (self.scene.nbodies - 1) + 2]

    def reference(self, rtol):
        moving = _slides(self.p)
        return float(self._top([self.window])[0]), [(0.0, "P" if moving else "S")]

    def reference_grid(self):
        return self._top(np.linspace(0.0, self.window, GRID + 1))

    def headline_of_run(self, res):
        return float(res.q[-1, 7 * (self.scene.nbodies - 1) + 2])


register_scene(SceneEntry(
    name="box-stack-3d",
    factory=box_stack_3d,
    description=("a stack of N cubes face on face (box-box contacts found every step) at rest, "
                 "sliding or on an incline: h g times the mass above on every interface, the "
                 "block's mu g deceleration (closed form)"),
    case=BoxStack3DCase,
))
