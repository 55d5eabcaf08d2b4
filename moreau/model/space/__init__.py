r"""Spatial rigid bodies, their shapes and their contacts with a half-space.

A :class:`SpaceModel` holds free rigid bodies and the ground's half-spaces,
and contacts between a body's shape and a half-space; :meth:`SpaceModel.build`
returns a :class:`SpaceScene`, which Moreau–Jean steps on SO(3)
(:mod:`moreau.integrators.moreau_jean`, option ``cone``).

Coordinates and velocities
--------------------------
Body ``b`` owns seven coordinates, its centre of mass ``x`` (3, world) and a
unit quaternion ``p = (w, x, y, z)`` mapping body to world (``R(p)``,
:func:`moreau.model.spatial.rotation_matrix`), and six velocities, the
centre's velocity ``x'`` (3, world) and the angular velocity ``omega`` (3,
body frame). So a scene's ``ndof = 7 nb`` counts coordinates and ``nvel =
6 nb`` velocities; ``q' = (x', 1/2 p ⊗ (0, omega))`` is not ``v``, and a
scheme moves the orientation by the exponential map
(:func:`moreau.model.spatial.rotate_body`).

Equations of motion (Newton–Euler, body frame for the rotation):

.. math::

    m \ddot x = m g + F_c, \qquad
    J \dot\omega = -\omega \times J\omega + \tau_c,

so ``mass(q) = diag(m I, J)`` per body (constant), ``forces = (m g, -omega x
J omega)``, and ``dh/dv`` has the gyroscopic block ``-([omega]x J - [J
omega]x)`` (:meth:`SpaceScene.force_jacobians`).

Contact kinematics
------------------
Every contact is a point of a body against a ground half-space ``{y : n . (y
- y0) >= 0}`` with a fixed unit normal ``n`` and two fixed unit tangents
``t1, t2`` (``(n, t1, t2)`` right-handed). A contact point sits at the
offset ``s`` (world) from the body's centre:

* a :class:`Sphere` of radius ``rho``: ``s = -rho n`` (the support point),
  ``g = n . (x - y0) - rho``; a sphere whose centre sits at ``c`` (body
  frame) from the centre of mass (an eccentric sphere, the tippe top):
  ``s = R c - rho n`` and ``g = n . (x + R c - y0) - rho``;
* a :class:`Puck` (a flat cylinder of radius ``a`` and thickness ``c``): its
  bottom face, ``z = -c/2`` in the body frame, touches through ``k`` rim
  points ``b_i = (a cos 2 pi i/k, a sin 2 pi i/k, -c/2)``, ``s_i = R b_i``
  and ``g_i = n . (x + s_i - y0)``. Lying on its face the puck carries its
  weight at these points (three make the normal forces determinate); the
  face's distributed pressure is represented by them, which holds the
  motion while the puck neither tips nor lifts a rim point. A thin puck
  (``c = 0``) may touch through its face's centre alone (``k = 1``);
* a :class:`Box` touches through the corners it names, material points
  ``b_k = (+-hx, +-hy, +-hz)`` as the puck's.
* a :class:`Capsule` (radius ``r`` about the segment ``z in [-l, l]``)
  touches as its two end spheres, eccentric spheres with ``c = (0, 0, +-l)``:
  the segment's lowest point along ``n`` is an end (both, lying parallel).

* a :class:`Disk` (a thin rim of radius ``r`` about the body's z axis, its
  centre the centre of mass) touches through the rim's lowest point. With
  the axis ``a = R e_z`` and ``u`` the unit part of ``n`` in the disk's plane,

  .. math::

      u = \frac{n - (n . a)\, a}{\sigma}, \quad \sigma = |n - (n . a) a|
        = \sqrt{1 - (n . a)^2}, \qquad s = -r u, \quad g = n . (x - y0) - r \sigma

  (the rim's points are ``x + r (cos phi e1 + sin phi e2)`` for ``(e1, e2)``
  spanning the plane; ``n .`` of them is least where the in-plane direction is
  ``-u``). Lying flat (``a`` parallel to ``n``, ``sigma = 0``) every rim
  point is lowest and the contact point is undefined: it is refused by name
  (:data:`FLAT_SIN`), when the contact is added and during a run.

The body's material point at ``x + s`` moves at ``x' + (R omega) x s``. For
a direction ``e`` (``n``, ``t1`` or ``t2``), ``e . ((R omega) x s) = omega .
R^T (s x e)``, so the row of ``e`` in the body's six columns is

.. math::

    (e^T, \; (R^T (s \times e))^T),

one formula for the gap rate (``e = n``; for the sphere ``s x n = 0``) and
the two slip rates. Differentiating a row times ``v`` at zero accelerations
(``d(R omega)/dt = R omega'``: the body-frame rate's own turning term
``omega x omega`` is zero) gives the drift ``e . (w x (w x s))`` with ``w =
R omega`` for a material point (the puck); the sphere's support point is
not material, only its centre's offset ``R c`` turns with the body (``d(R
c)/dt = w x R c``, ``-rho n`` is constant), so its drift is ``e . (w x (w
x R c))``, zero for a centred sphere. The disk's rim point is not material
either: it slides round the rim as the axis turns, ``s' = -r u'``, and the
drift is ``e . (w x s')`` with

.. math::

    u' = \frac{\dot m - (u . \dot m)\, u}{\sigma}, \quad
    \dot m = -(n . \dot a)\, a - (n . a)\, \dot a, \quad \dot a = w \times a

(``m = n - (n . a) a``). Because the rim point is the lowest, the gap's rate
is the material point's normal velocity (the rate of ``r sigma`` is ``-r u .
\dot m``, which equals ``n . (w x s)``): the same row serves the gap and the slip.

Every row is held to central differences of the gap and of the material
point's position along the exponential-map motion in ``tests/model``.

Contacts between two spheres
----------------------------
:meth:`SpaceModel.add_pair_contact` joins a sphere of body ``a`` (radius
``r_a``, centre ``p_a = x_a + R_a c_a``) and one of body ``b``. With ``d =
p_b - p_a`` and ``L = |d|``, the normal ``n = d / L`` points from ``a`` to
``b`` and

.. math::

    g = L - r_a - r_b, \qquad s_a = R_a c_a + r_a n, \qquad s_b = R_b c_b - r_b n,

``s_a``, ``s_b`` the offsets of the two surface points facing each other
from the centres of mass; the tangents ``t1, t2`` are :func:`tangent_basis`
of ``n``, so the frame turns with the line of centres. The contact's
velocity is that of ``b``'s material point at ``x_b + s_b`` less that of
``a``'s at ``x_a + s_a``, and a row is the difference of the two point rows,

.. math::

    e . \Delta = (e^T, (R_b^T (s_b \times e))^T)\, v_b
              - (e^T, (R_a^T (s_a \times e))^T)\, v_a ,
    \qquad e \in \{n, t1, t2\}.

The gap's rate is ``n . (p_b' - p_a')`` (``L' = n . d'``) and equals ``n .
Delta``, because the parts ``r_a w_a x n`` and ``-r_b w_b x n`` that the
surface points add to the centres' velocities are normal to ``n``: one row
serves the gap and the slip, as on a half-space. Differentiating ``e .
Delta`` at zero accelerations (``w = R omega`` constant in the world, the
centres' velocities too) gives the drift

.. math::

    \dot e . \Delta + e . (w_b \times \dot s_b - w_a \times \dot s_a), \quad
    \dot n = \frac{(I - n n^T)(p_b' - p_a')}{L}, \quad
    \dot s_a = w_a \times R_a c_a + r_a \dot n, \quad
    \dot s_b = w_b \times R_b c_b - r_b \dot n,

with ``p' = x' + w x R c``. The tangents' rates follow from their
definition: ``t1 = m / |m|``, ``m = e_k - n_k n`` for the fixed axis
``e_k``, so ``t1' = (m' - (t1 . m') t1) / |m|`` with ``m' = -n_k' n - n_k
n'``, and ``t2' = n' x t1 + n x t1'``. Two spheres whose centres meet
(``L <= CONCENTRIC_TOL (r_a + r_b)``) have no normal: refused when the
contact is added and raised (:class:`~moreau.errors.IllPosedError`) during
a run. These rows are held to central differences of the gap and of the two
material points' relative position in ``tests/model``.

Contacts with boxes
-------------------
A :class:`Box` (half-extents ``h``, body frame) touches a half-space
through its corners, material points (above: a face resting on the plane
carries its weight on four). :meth:`SpaceModel.add_box_contact` joins a
sphere or a box of body ``a`` to a box of body ``b``; its points are found
at every configuration ``q``, each with a normal ``n`` from ``a`` to ``b``,
a gap ``g`` and the offsets ``s_a``, ``s_b`` (world, from the centres of
mass) of the two points whose relative velocity the rows give, by the same
formula as the spheres' pair: ``e . Delta = (e^T, (R_b^T (s_b x e))^T) v_b
- (e^T, (R_a^T (s_a x e))^T) v_a``, ``e in {n, t1, t2}``, ``(t1, t2) =
tangent_basis(n)``. For each kind of point ``g' = n . Delta`` holds exactly,
so one row serves the gap and the slip; ``w = R omega`` below.

* *Vertex of b on a face of a* (outward normal ``n = R_a (+-e_i)``, half-extent
  ``h_i``): ``p = x_b + R_b c`` (``c`` the corner), ``g = n . (p - x_a) -
  h_i``, ``s_a = p - x_a``, ``s_b = p - x_b``. As ``n' = w_a x n``, ``n' . (p
  - x_a) = -n . (w_a x s_a)`` and ``g' = n . (x_b' + w_b x s_b - x_a' - w_a x
  s_a)``. A vertex of ``a`` on a face of ``b`` is the same with the roles
  swapped, ``n = -R_b (+-e_j)``.
* *Edge against edge*: the lines ``P_a + t d_a`` and ``P_b + u d_b`` (unit
  directions, ``c = d_a . d_b``) have the closest points ``c_a``, ``c_b`` at
  ``t = (r . d_a - c r . d_b) / (1 - c^2)``, ``u = (c r . d_a - r . d_b) / (1
  - c^2)``, ``r = P_b - P_a``; ``n = +-(d_a x d_b) / |d_a x d_b|`` (turned
  from ``a`` to ``b``), ``g = n . (c_b - c_a)``, ``s_a = c_a - x_a``, ``s_b =
  c_b - x_b``. As ``c_b - c_a = g n`` and ``n' . n = 0``, and the points'
  slides along the edges are normal to ``n``, ``g' = n . Delta``.
* *Sphere a against box b*: the box's point ``y`` closest to the sphere's
  centre ``p`` (the centre's box coordinates clamped to ``+-h``), ``n = (y -
  p) / |y - p|``, ``g = |y - p| - r``, ``s_a = R_a c + r n``, ``s_b = y -
  x_b``; ``y`` slides only along the box's surface, normal to ``n``. A
  centre inside the box has no closest point on the surface: raised
  (:class:`~moreau.errors.IllPosedError`).

Which points. Two boxes are tested on the 15 separating axes (the six face
normals and the nine products ``R_a e_i x R_b e_j``, those of parallel edges
left out): the separation along a unit axis ``L`` is ``|L . (x_b - x_a)| -
sum_i h_a,i |L . R_a e_i| - sum_j h_b,j |L . R_b e_j|``, and the axis of the
largest separation decides (a face of ``a`` before one of ``b``, a face before
an edge pair unless the pair separates more by :data:`._boxes.EDGE_PREFERENCE`
of the least half-extent). Beyond the contact's ``margin`` there is no point;
a penetration past it is raised (:class:`~moreau.errors.IllPosedError`: the
step let the boxes sink into each other). On a face axis that face is the
reference, the other box's face most anti-parallel to it the incident face,
and the incident quadrilateral is clipped by the reference face's four side
planes (Sutherland–Hodgman): each vertex of the clipped polygon is an incident
vertex on the reference face, an incident edge crossing a reference edge, or
a reference vertex on the incident face, and is stated by its kind as above;
those with ``g <= margin`` are the points, up to eight. On an edge axis the
two supporting edges give one point. A contact between two boxes keeps eight
slots; a slot without a point has the gap ``margin`` and zero rows
(:meth:`SpaceScene.contacts_in_use`), and Moreau–Jean's step leaves it out.

Drift (the rows' rate at constant velocities): ``d/dt (e . Delta) = e' .
Delta + e . (w_b x s_b' - w_a x s_a')``, ``t1'``, ``t2'`` from ``n'`` as for
the spheres' pair. A vertex of ``b`` on a face of ``a``: ``n' = w_a x n``,
``s_b' = w_b x s_b``, ``s_a' = x_b' + w_b x s_b - x_a'``. Edges: ``d' = w x
d``, ``n' = +-(m' - (n . m') n) / |m|`` with ``m = d_a x d_b``, and the
closest points' slides ``t'``, ``u'`` solve ``t' - c u' = Delta . d_a + r .
d_a'``, ``c t' - u' = Delta . d_b + r . d_b'`` (``r = c_b - c_a``, the rates
of ``r . d_a = r . d_b = 0``), ``s_a' = w_a x s_a + t' d_a``, ``s_b' = w_b x
s_b + u' d_b``. Sphere and box: the centre moves at ``p' = x_a' + w_a x R_a
c``, ``y' = x_b' + w_b x s_b + R_b P R_b^T (p' - x_b' - w_b x (p - x_b))``
(``P`` keeps the free coordinates), ``n' = ((y' - p') - (n . (y' - p')) n) /
|y - p|``, ``s_a' = w_a x R_a c + r n'``. The rows and drifts are held to
central differences of the gaps, of the two material points' relative
position and of the rows on tumbling bodies in ``tests/model``.

Coulomb–Contensou friction
--------------------------
A contact added with ``contact_radius = r > 0`` touches through a flat
patch of radius ``r`` about the contact point, with the uniform pressure
``N / (pi r^2)``. Spinning about the normal at ``omega_n`` without sliding,
every patch element at the distance ``rho`` slides at ``omega_n rho``, and
Coulomb's law there gives the drilling torque

.. math::

    M_{max} = \int_0^r \mu \frac{N}{\pi r^2}\, \rho \; 2\pi\rho\, d\rho
            = \mu N \frac{2 r}{3} = \mu N r^*, \qquad r^* = \tfrac{2}{3} r

(:data:`DRILLING_LEVER`); sliding without spin, the force is ``mu N``. The
set of the patch's admissible (force, torque) pairs is convex; Leine and
Glocker ("A set-valued force law for spatial Coulomb–Contensou friction",
Eur. J. Mech. A/Solids 22 (2003) 193) replace it by the ellipsoid through
these two extremes,

.. math::

    \frac{|F_T|^2}{(\mu N)^2} + \frac{M_d^2}{(\mu N r^*)^2} \le 1 .

With the scaled torque ``M_d / r*`` and the scaled spin ``r* omega_n`` the
power ``F_T . v_T + M_d omega_n`` keeps its form and the ellipsoid is the
round ball ``|(F_T, M_d / r*)| <= mu N``: maximal dissipation puts the
generalized force opposite the generalized slip ``(v_T, r* omega_n)``, and
the contact is the Coulomb cone of :mod:`moreau.contact.cone3d` with three
tangential rows, ``[n, t1, t2, d]``, the drilling row ``d = r* n . (R
omega)`` (:meth:`SpaceScene.drilling_rows`). A Hertzian pressure would give
``r* = 3 pi r / 16`` instead; ``r`` is the patch the user names, its
pressure uniform.

Examples
--------
A ball of radius 0.1 m on the floor, sliding at 1 m/s without spin:

>>> import numpy as np
>>> m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.1)
>>> floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
>>> ball = m.add_body(1.0, [0.004] * 3, position=(0.0, 0.0, 0.1), velocity=(1.0, 0.0, 0.0))
>>> m.add_contact(ball, Sphere(0.1), floor, mu=0.2)
[0]
>>> sc = m.build("ball")
>>> q0, v0 = sc.initial_state()
>>> sc.ndof, sc.nvel, float(sc.gaps(q0, 0.0)[0])
(7, 6, 0.0)
>>> WN, wN, WT, wT = sc.contact_jacobians(q0, 0.0)
>>> (WT @ v0 * sc.length / sc.time).round(12).tolist()   # the slip [t1, t2], m/s
[1.0, 0.0]
"""

import math

import numpy as np

from ..._validate import finite_array, finite_scalar, nonnegative, positive
from ...errors import IllPosedError, InputError
from ..drawing import circle, contact, line, polygon
from ..scene import Scene
from ..units import SI_UNITS, columns_of
from ..spatial import check_inertia, check_unit_quaternion, rotate_body, rotation_matrix
from ._boxes import box_box, sphere_box
from ._boxes import drift as _box_drift

__all__ = ["Sphere", "Puck", "Box", "Capsule", "Disk", "HalfSpace", "SpaceModel", "SpaceScene", "tangent_basis",
           "point_rows", "advance_coordinates", "rim_offset", "FLAT_SIN", "DRILLING_LEVER",
           "CONCENTRIC_TOL", "BOX_MARGIN"]

#: ``r* / r``: a uniform pressure on a patch of radius ``r`` resists pure spin with the torque
#: ``mu N r*`` (the module docstring's "Coulomb–Contensou friction")
DRILLING_LEVER = 2.0 / 3.0

#: a disk whose axis makes a sine below this with the half-space's normal lies flat: its rim
#: has no single lowest point (the rim point's direction is rounding over this sine)
FLAT_SIN = 1e-8

#: two spheres whose centres are closer than this fraction of their radii's sum have no
#: normal (the line of centres is rounding): refused when added and during a run
CONCENTRIC_TOL = 1e-8


#: the default margin of a contact with a box between two bodies, as a fraction of the least
#: half-extent of its two shapes: points with gaps up to it are listed, a penetration past it
#: is refused during a run
BOX_MARGIN = 0.5

#: the contact kinds with a box between two bodies, whose points change as the bodies move
_BOX_KINDS = ("sphere-box", "box-box")


def tangent_basis(normal):
    """Two unit tangents ``(t1, t2)`` of a unit normal, ``(n, t1, t2)`` right-handed.

    ``t1`` is the unit part of ``e_k`` orthogonal to ``n``, for the axis
    ``e_k`` least aligned with ``n`` (ties to the first); ``t2 = n x t1``.

    Examples
    --------
    >>> [t.tolist() for t in tangent_basis([0.0, 0.0, 1.0])]
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    """
    n = np.asarray(normal, dtype=float)
    e = np.zeros(3)
    e[int(np.argmin(np.abs(n)))] = 1.0
    t1 = e - (e @ n) * n
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def point_rows(R, s, directions):
    """The rows ``(e^T, (R^T (s x e))^T)`` of the velocity of the point ``x + s`` along each ``e``.

    Parameters
    ----------
    R : ndarray, shape (3, 3)
        Body-to-world rotation.
    s : ndarray, shape (3,)
        The point's offset from the centre, world frame.
    directions : ndarray, shape (k, 3)
        Unit directions, world frame.

    Returns
    -------
    ndarray, shape (k, 6)
        Against the body's velocities ``(x', omega)`` (omega in the body frame).

    Examples
    --------
    >>> point_rows(np.eye(3), np.array([0.0, 0.0, -1.0]), np.eye(3)[:1]).tolist()
    [[1.0, 0.0, 0.0, 0.0, -1.0, 0.0]]
    """
    e = np.asarray(directions, dtype=float)
    # s x e, row by row
    c = np.column_stack([s[1] * e[:, 2] - s[2] * e[:, 1], s[2] * e[:, 0] - s[0] * e[:, 2],
                         s[0] * e[:, 1] - s[1] * e[:, 0]])
    return np.hstack([e, c @ R])


def advance_coordinates(scene, q, v_mid, h):
    """``q`` moved over ``h`` at the velocities ``v_mid``: centres by ``h x'``, orientations on SO(3).

    Each body's quaternion becomes ``p ⊗ exp((0, h omega / 2))``
    (:func:`moreau.model.spatial.rotate_body`), unit to rounding.

    Examples
    --------
    >>> m = SpaceModel()
    >>> b = m.add_body(1.0, [1.0, 1.0, 1.0])
    >>> sc = m.build("free")
    >>> q = advance_coordinates(sc, sc.initial_state()[0], [1.0, 0, 0, 0, 0, np.pi], 1.0)
    >>> q.round(12).tolist()
    [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    """
    q = np.asarray(q, dtype=float)
    v = np.asarray(v_mid, dtype=float)
    out = np.empty_like(q)
    for b in range(q.size // 7):
        out[7 * b:7 * b + 3] = q[7 * b:7 * b + 3] + h * v[6 * b:6 * b + 3]
        # unchecked: a scheme's own quaternions, unit to rounding
        out[7 * b + 3:7 * b + 7] = rotate_body(q[7 * b + 3:7 * b + 7], v[6 * b + 3:6 * b + 6], h,
                                               check=False)
    return out


class Sphere:
    """A sphere of ``radius`` [m] whose centre is at ``centre`` [m] (body frame) from the centre of mass.

    The default ``centre = (0, 0, 0)`` is a sphere about the centre of mass;
    an eccentric sphere (the tippe top) has its centre of mass off the
    sphere's centre.
    """

    def __init__(self, radius, centre=(0.0, 0.0, 0.0)):
        self.radius = positive("radius", radius)
        self.centre = finite_array("centre", centre, shape=(3,))

    def points(self, scale):
        return None


class Puck:
    """A flat cylinder (disk) of ``radius`` and ``thickness`` [m], axis the body's z.

    Its bottom face (``z = -thickness / 2``) touches a half-space through
    ``rim_points`` points on its rim (see the module docstring), ``>= 3``;
    or, for a thin puck (``thickness = 0``) with ``rim_points = 1``, through
    its face's centre, the centre of mass: there friction has no tipping
    moment, and a uniform pressure's resultant acts at the centre while the
    puck slides without spin, so one contact carries the face exactly.
    """

    def __init__(self, radius, thickness, rim_points=3):
        self.radius = positive("radius", radius)
        self.thickness = nonnegative("thickness", thickness)
        if isinstance(rim_points, bool) or not isinstance(rim_points, (int, np.integer)) \
                or not (rim_points >= 3 or (rim_points == 1 and self.thickness == 0.0)):
            raise InputError(f"`rim_points` must be an integer >= 3 (fewer do not hold a face "
                             f"up), or 1 for a thin puck (thickness 0), got {rim_points!r}")
        self.rim_points = int(rim_points)

    def points(self, scale):
        if self.rim_points == 1:
            return np.zeros((1, 3))
        a = 2.0 * np.pi * np.arange(self.rim_points) / self.rim_points
        r = self.radius / scale
        return np.column_stack([r * np.cos(a), r * np.sin(a),
                                np.full(a.size, -0.5 * self.thickness / scale)])


class Box:
    """A box of half-edges ``half_extents`` [m] (body x, y, z) about the centre of mass, touching
    through its corners ``corners`` (default all eight).

    Corner ``k`` is ``(+-hx, +-hy, +-hz)`` with the sign of ``x`` from bit 0 of
    ``k`` (set: ``+``), of ``y`` from bit 1, of ``z`` from bit 2: the corners
    ``0..3`` are the bottom face's (``z = -hz``). Each corner is a material
    point, a contact of its own (as a :class:`Puck`'s rim points); a scene
    names only the corners that can touch.

    Examples
    --------
    >>> Box((1.0, 2.0, 3.0), corners=(0, 3)).points(1.0).tolist()
    [[-1.0, -2.0, -3.0], [1.0, 2.0, -3.0]]
    """

    def __init__(self, half_extents, corners=None):
        self.half_extents = finite_array("half_extents", half_extents, shape=(3,))
        if np.any(self.half_extents <= 0.0):
            raise InputError(f"`half_extents` must be > 0, got {self.half_extents.tolist()}")
        if corners is None:
            corners = range(8)
        ks = list(corners)
        if not ks or any(isinstance(k, bool) or not isinstance(k, (int, np.integer))
                         or not 0 <= k < 8 for k in ks) or len(set(ks)) != len(ks):
            raise InputError(f"`corners` must be distinct corner numbers in 0..7, got {corners!r}")
        self.corners = [int(k) for k in ks]

    def inertia(self, mass):
        """The principal moments [kg m^2] of a uniform box of ``mass`` [kg], ``> 0``:
        ``m (h_y^2 + h_z^2) / 3`` and its turns.

        Examples
        --------
        >>> Box((1.0, 2.0, 3.0)).inertia(3.0).tolist()
        [13.0, 10.0, 5.0]
        """
        m = positive("mass", mass)
        h2 = self.half_extents ** 2
        return m / 3.0 * np.array([h2[1] + h2[2], h2[0] + h2[2], h2[0] + h2[1]])

    def points(self, scale):
        k = np.array(self.corners)
        signs = np.column_stack([2 * (k & 1) - 1, 2 * ((k >> 1) & 1) - 1, 2 * ((k >> 2) & 1) - 1])
        return signs * self.half_extents / scale


class Capsule:
    """A capsule: the points within ``radius`` [m] of the segment ``z in [-half_length, half_length]``
    on the body's z axis, about the centre of mass.

    Against a half-space the segment's lowest point is one of its ends (both
    when it lies parallel to the plane), so the capsule touches as two
    eccentric spheres (:class:`Sphere` with ``centre = (0, 0, +-half_length)``),
    two contacts.

    Examples
    --------
    >>> [s.centre.tolist() for s in Capsule(0.1, 0.3).spheres()]
    [[0.0, 0.0, -0.3], [0.0, 0.0, 0.3]]
    """

    def __init__(self, radius, half_length):
        self.radius = positive("radius", radius)
        self.half_length = positive("half_length", half_length)

    def spheres(self):
        return [Sphere(self.radius, (0.0, 0.0, -self.half_length)),
                Sphere(self.radius, (0.0, 0.0, self.half_length))]


class Disk:
    """A thin disk: a rim of ``radius`` [m] about the body's z axis, centred on the centre of mass.

    It touches a half-space at its rim's lowest point, one contact at any
    tilt but flat (see the module docstring); a disk lying on its face is a
    :class:`Puck`.

    Examples
    --------
    >>> Disk(0.05).radius
    0.05
    """

    def __init__(self, radius):
        self.radius = positive("radius", radius)

    def points(self, scale):
        return None


def rim_offset(R, n, radius):
    """``(s, sigma, u)``: the rim's lowest point's offset ``s = -radius u`` (world) from
    the disk's centre, for the body rotation ``R`` and the half-space's unit normal ``n``.

    Raises :class:`~moreau.errors.IllPosedError` where the disk lies flat
    (``sigma = |n - (n . a) a| <= FLAT_SIN``, ``a = R e_z``).

    Examples
    --------
    >>> s, sigma, u = rim_offset(np.eye(3), np.array([0.0, 1.0, 0.0]), 2.0)
    >>> (s + 0.0).tolist(), sigma
    ([0.0, -2.0, 0.0], 1.0)
    """
    a = R[:, 2]
    m = n - (n @ a) * a
    sigma = math.sqrt(m @ m)
    if sigma <= FLAT_SIN:
        raise IllPosedError(f"a disk lies flat on a half-space (its axis parallel to the "
                            f"normal, sine {sigma:.3g} <= FLAT_SIN): its rim has no single "
                            f"lowest point")
    u = m / sigma
    return -radius * u, sigma, u


class HalfSpace:
    """The ground's half-space ``{y : normal . (y - point) >= 0}``; tangents default to :func:`tangent_basis`."""

    def __init__(self, point, normal, tangent=None):
        self.point = finite_array("point", point, shape=(3,))
        n = finite_array("normal", normal, shape=(3,))
        nn = float(np.linalg.norm(n))
        if nn == 0.0:
            raise InputError("`normal` must be a nonzero vector")
        self.normal = n / nn
        if tangent is None:
            self.t1, self.t2 = tangent_basis(self.normal)
        else:
            t = finite_array("tangent", tangent, shape=(3,))
            t = t - (t @ self.normal) * self.normal
            if float(np.linalg.norm(t)) < 1e-12:
                raise InputError("`tangent` must not be parallel to `normal`")
            self.t1 = t / np.linalg.norm(t)
            self.t2 = np.cross(self.normal, self.t1)


def _friction_and_restitution(mu, restitution):
    """A contact's checked ``(mu, e)``: ``mu >= 0``, ``restitution`` in [0, 1]."""
    mu = nonnegative("mu", mu)
    e = finite_scalar("restitution", restitution)
    if not 0.0 <= e <= 1.0:
        raise InputError(f"`restitution` must be in [0, 1], got {e!r}")
    return mu, e


def _two_bodies(body_a, body_b, nbodies):
    """Refuse by name a contact's bodies that are not two distinct added ones."""
    for name, value in (("body_a", body_a), ("body_b", body_b)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) \
                or not 0 <= value < nbodies:
            raise InputError(f"`{name}` must be the index of an added body "
                             f"(0..{nbodies - 1}), got {value!r}")
    if body_a == body_b:
        raise InputError(f"`body_b` must be another body than `body_a`, got {body_b!r} twice")


class SpaceModel:
    """Free rigid bodies in space and their contacts with the ground's half-spaces.

    Parameters
    ----------
    gravity : array_like, shape (3,)
        [m/s^2], world frame.
    length, mass : float
        The scene's units of length [m] and mass [kg]; its time unit is
        ``sqrt(length / |gravity|)`` (1 s without gravity), so that gravity
        is of size 1 inside.
    time : float, optional
        The time unit [s] of a scene without gravity (e.g. a length over a
        speed), > 0; refused with gravity, whose time unit is the one above.
    """

    def __init__(self, gravity=(0.0, 0.0, 0.0), length=1.0, mass=1.0, time=None):
        self.gravity = finite_array("gravity", gravity, shape=(3,))
        self.length = positive("length", length)
        self.mass_unit = positive("mass", mass)
        g = float(np.linalg.norm(self.gravity))
        self.time = math.sqrt(self.length / g) if g > 0.0 else 1.0
        if time is not None:
            if g > 0.0:
                raise InputError("`time` must be None with gravity: the time unit is then "
                                 "sqrt(length / |gravity|)")
            self.time = positive("time", time)
        self.bodies = []
        self.planes = []
        self.contacts = []

    def add_body(self, mass, inertia, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0),
                 velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0), name=None):
        """Add a free body; SI values, ``angular_velocity`` in the body frame. Returns its index.

        ``inertia`` (about the centre, body frame) is three principal moments
        or a 3x3 matrix (:func:`moreau.model.spatial.check_inertia`: positive,
        symmetric, the triangle inequality); ``orientation`` a unit quaternion.
        """
        m = positive("mass", mass)
        J = check_inertia(inertia)
        p = check_unit_quaternion(orientation, "orientation")
        x = finite_array("position", position, shape=(3,))
        xd = finite_array("velocity", velocity, shape=(3,))
        w = finite_array("angular_velocity", angular_velocity, shape=(3,))
        self.bodies.append({"mass": m, "inertia": J, "position": x, "orientation": p / np.linalg.norm(p),
                            "velocity": xd, "angular_velocity": w,
                            "name": name or f"body {len(self.bodies)}"})
        return len(self.bodies) - 1

    def add_half_space(self, point, normal, tangent=None):
        """Add a ground half-space (:class:`HalfSpace`, SI point); returns its index."""
        self.planes.append(HalfSpace(point, normal, tangent))
        return len(self.planes) - 1

    def add_contact(self, body, shape, plane, mu=0.0, restitution=0.0, contact_radius=0.0):
        """Contacts of ``body``'s ``shape`` with the half-space ``plane``; returns their indices.

        A :class:`Sphere` gives one contact, a :class:`Puck` one per rim point, a
        :class:`Box` one per named corner, a :class:`Capsule` two (its end spheres),
        a :class:`Disk` one (its rim's lowest point; refused, naming
        ``orientation``, where the body lies flat on the half-space).

        ``contact_radius`` [m], ``>= 0``: the radius ``r`` of a flat contact
        patch of uniform pressure about each contact point, which adds the
        drilling (Contensou) friction torque about the normal, coupled with
        the sliding force in Leine and Glocker's ellipsoid (the module
        docstring's "Coulomb–Contensou friction"); ``0``, the default, is the
        point contact. Refused, naming it, on a :class:`Disk`'s rim.
        """
        if isinstance(body, bool) or not isinstance(body, (int, np.integer)) \
                or not 0 <= body < len(self.bodies):
            raise InputError(f"`body` must be the index of an added body (0..{len(self.bodies) - 1}), "
                             f"got {body!r}")
        if isinstance(plane, bool) or not isinstance(plane, (int, np.integer)) \
                or not 0 <= plane < len(self.planes):
            raise InputError(f"`plane` must be the index of an added half-space, got {plane!r}")
        if not isinstance(shape, (Sphere, Puck, Box, Capsule, Disk)):
            raise InputError(f"`shape` must be a Sphere, a Puck, a Box, a Capsule or a Disk, "
                             f"got {type(shape).__name__}")
        if isinstance(shape, Capsule):
            return [k for s in shape.spheres()
                    for k in self.add_contact(body, s, plane, mu, restitution)]
        mu, e = _friction_and_restitution(mu, restitution)
        r_patch = nonnegative("contact_radius", contact_radius)
        if r_patch > 0.0 and isinstance(shape, Disk):
            raise InputError("`contact_radius` must be 0 on a Disk: its rim touches along a "
                             "line, with no flat patch about the contact point")
        if isinstance(shape, Disk):
            R = rotation_matrix(self.bodies[body]["orientation"], check=False)
            n = self.planes[plane].normal
            if float(np.linalg.norm(n - (n @ R[:, 2]) * R[:, 2])) <= FLAT_SIN:
                raise InputError("`orientation` of a Disk's body must tilt its axis (the "
                                 "body's z) off the half-space's normal: lying flat, its rim "
                                 "has no single lowest point (use a Puck)")
            self.contacts.append({"kind": "rim", "body": int(body), "plane": int(plane),
                                  "mu": mu, "e": e, "radius": shape.radius / self.length,
                                  "point": None, "centre": None})
            return [len(self.contacts) - 1]
        pts = shape.points(self.length)
        out = []
        for k in range(1 if pts is None else len(pts)):
            self.contacts.append({"kind": "sphere" if pts is None else "point",
                                  "body": int(body), "plane": int(plane), "mu": mu, "e": e,
                                  "radius": shape.radius / self.length if pts is None else 0.0,
                                  "point": None if pts is None else pts[k],
                                  "centre": (shape.centre / self.length if pts is None
                                             and np.any(shape.centre != 0.0) else None)})
            if r_patch > 0.0:
                # the key only where there is a patch: a point contact's data stay as they were
                self.contacts[-1]["contact_radius"] = r_patch / self.length
            out.append(len(self.contacts) - 1)
        return out

    def add_pair_contact(self, body_a, sphere_a, body_b, sphere_b, mu=0.0, restitution=0.0):
        """A contact between a sphere of ``body_a`` and a sphere of ``body_b``; returns ``[index]``.

        The module docstring's "Contacts between two spheres": the normal
        points from ``a``'s sphere centre to ``b``'s, the gap is the centres'
        distance less the radii. Both shapes are :class:`Sphere` (eccentric
        ones too); the bodies are two different added bodies; spheres whose
        centres meet at the bodies' initial positions have no normal and are
        refused, naming ``body_b``. ``mu`` >= 0, ``restitution`` in [0, 1]
        as in :meth:`add_contact` (point contacts: no ``contact_radius``).

        Examples
        --------
        >>> m = SpaceModel()
        >>> a = m.add_body(1.0, [0.004] * 3)
        >>> b = m.add_body(1.0, [0.004] * 3, position=(0.25, 0.0, 0.0))
        >>> m.add_pair_contact(a, Sphere(0.1), b, Sphere(0.1), mu=0.3)
        [0]
        >>> q = np.array([0, 0, 0, 1, 0, 0, 0, 0.25, 0, 0, 1, 0, 0, 0])
        >>> round(float(m.build("pair").gaps(q, 0.0)[0]), 12)      # 0.25 - 0.1 - 0.1
        0.05
        """
        _two_bodies(body_a, body_b, len(self.bodies))
        for name, shape in (("sphere_a", sphere_a), ("sphere_b", sphere_b)):
            if not isinstance(shape, Sphere):
                raise InputError(f"`{name}` must be a Sphere (contacts between two bodies are "
                                 f"sphere against sphere), got {type(shape).__name__}")
        mu, e = _friction_and_restitution(mu, restitution)
        centres = []
        for b, shape in ((body_a, sphere_a), (body_b, sphere_b)):
            body = self.bodies[b]
            centres.append(body["position"]
                           + rotation_matrix(body["orientation"], check=False) @ shape.centre)
        if float(np.linalg.norm(centres[1] - centres[0])) <= CONCENTRIC_TOL * (
                sphere_a.radius + sphere_b.radius):
            raise InputError("`body_b`'s sphere must not be concentric with `body_a`'s at the "
                             "initial positions: the line of centres, the contact's normal, "
                             "is undefined")
        L = self.length
        self.contacts.append({"kind": "pair", "body": int(body_a), "body_b": int(body_b),
                              "plane": None, "mu": mu, "e": e, "radius": sphere_a.radius / L,
                              "radius_b": sphere_b.radius / L, "point": None,
                              "centre": sphere_a.centre / L, "centre_b": sphere_b.centre / L})
        return [len(self.contacts) - 1]

    def add_box_contact(self, body_a, shape_a, body_b, box_b, mu=0.0, restitution=0.0,
                        margin=None):
        """A contact between a :class:`Sphere` or a :class:`Box` of ``body_a`` and a :class:`Box`
        of ``body_b``; returns the indices of its points.

        The module docstring's "Contacts with boxes": a sphere against a box
        touches at the box's point closest to the sphere's centre (one
        contact); two boxes touch at up to eight points found each time the
        contact is evaluated (the separating-axis test, then the clipped
        faces or the two edges), eight contacts whose unused ones report the
        gap ``margin`` and zero rows. The normal points from ``a`` to ``b``.
        A box's ``corners`` name its contacts with half-spaces only.

        ``margin`` [m], ``> 0``: points with gaps up to it are listed, and a
        penetration past it is raised during a run
        (:class:`~moreau.errors.IllPosedError`); default :data:`BOX_MARGIN`
        times the least half-extent (or radius) of the two shapes. ``mu`` >=
        0, ``restitution`` in [0, 1] as in :meth:`add_contact`. Refused by
        name: a body that is not an added one, the same body twice, a
        ``shape_a`` that is not a Sphere or a Box, a ``box_b`` that is not a
        Box, and shapes that interpenetrate past the margin (a sphere's
        centre in the box) at the bodies' initial positions.

        Examples
        --------
        >>> m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
        >>> a = m.add_body(1.0, Box((0.1, 0.1, 0.05)).inertia(1.0), position=(0.0, 0.0, 0.05))
        >>> b = m.add_body(1.0, Box((0.1, 0.1, 0.05)).inertia(1.0), position=(0.0, 0.0, 0.15))
        >>> m.add_box_contact(a, Box((0.1, 0.1, 0.05)), b, Box((0.1, 0.1, 0.05)), mu=0.5)
        [0, 1, 2, 3, 4, 5, 6, 7]
        >>> sc = m.build("two boxes")
        >>> q0, _ = sc.initial_state()
        >>> (sc.gaps(q0, 0.0).round(12) + 0.0).tolist()    # four corners touch, four unused
        [0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 0.5]
        """
        _two_bodies(body_a, body_b, len(self.bodies))
        if not isinstance(shape_a, (Sphere, Box)):
            raise InputError(f"`shape_a` must be a Sphere or a Box, got {type(shape_a).__name__}")
        if not isinstance(box_b, Box):
            raise InputError(f"`box_b` must be a Box (a sphere against a box names the sphere "
                             f"first), got {type(box_b).__name__}")
        mu, e = _friction_and_restitution(mu, restitution)
        L = self.length
        least = min(float(box_b.half_extents.min()),
                    shape_a.radius if isinstance(shape_a, Sphere) else float(shape_a.half_extents.min()))
        margin = BOX_MARGIN * least if margin is None else positive("margin", margin)
        base = {"body": int(body_a), "body_b": int(body_b), "plane": None, "mu": mu, "e": e,
                "point": None, "half_b": box_b.half_extents / L, "margin": margin / L}
        if isinstance(shape_a, Sphere):
            new = [dict(base, kind="sphere-box", radius=shape_a.radius / L,
                        centre=shape_a.centre / L)]
        else:
            first = len(self.contacts)
            new = [dict(base, kind="box-box", radius=0.0, centre=None,
                        half=shape_a.half_extents / L, first=first, slot=k) for k in range(8)]
        # the initial positions must be stated (a sphere's centre outside the box, boxes not
        # interpenetrating past the margin)
        xa, xb = (self.bodies[k]["position"] / L for k in (body_a, body_b))
        Ra, Rb = (rotation_matrix(self.bodies[k]["orientation"], check=False)
                  for k in (body_a, body_b))
        try:
            if isinstance(shape_a, Sphere):
                sphere_box(xa, Ra, new[0]["centre"], new[0]["radius"], xb, Rb, new[0]["half_b"])
            else:
                box_box(xa, Ra, new[0]["half"], xb, Rb, new[0]["half_b"], margin / L)
        except IllPosedError as exc:
            raise InputError(f"`body_b`'s box and `body_a`'s shape must not interpenetrate at "
                             f"the initial positions: {exc}") from None
        self.contacts.extend(new)
        return list(range(len(self.contacts) - len(new), len(self.contacts)))

    def build(self, name, default_window=None):
        """The :class:`SpaceScene` of the model, in the scene's units."""
        if not self.bodies:
            raise InputError("the model has no body: add one with `add_body`")
        return SpaceScene(self, name, default_window)


class SpaceScene(Scene):
    """A scene of spatial rigid bodies (:class:`SpaceModel`); ``ndof = 7 nb``, ``nvel = 6 nb``.

    Contacts have three rows each, ``[N, T1, T2]``: ``WT`` holds the two
    tangent rows of each frictional contact, in turn (``2 nf`` rows), and a
    scheme solves the spatial Coulomb cone on them.
    """

    spatial = True

    def __init__(self, model, name, default_window=None):
        L, M, T = model.length, model.mass_unit, model.time
        self.name = name
        self.length, self.time, self.mass_unit = L, T, M
        self.time_unit_s = T
        self.default_window = default_window
        nb = len(model.bodies)
        self.nbodies = nb
        self.ndof, self.nvel = 7 * nb, 6 * nb
        self.body_names = [b["name"] for b in model.bodies]
        self.masses = np.array([b["mass"] / M for b in model.bodies])
        self.inertias = np.array([b["inertia"] / (M * L * L) for b in model.bodies])
        self.gravity = model.gravity * T * T / L
        self._M = np.zeros((self.nvel, self.nvel))
        for b in range(nb):
            self._M[6 * b:6 * b + 3, 6 * b:6 * b + 3] = self.masses[b] * np.eye(3)
            self._M[6 * b + 3:6 * b + 6, 6 * b + 3:6 * b + 6] = self.inertias[b]
        q0, v0 = np.empty(self.ndof), np.empty(self.nvel)
        for b, body in enumerate(model.bodies):
            q0[7 * b:7 * b + 3] = body["position"] / L
            q0[7 * b + 3:7 * b + 7] = body["orientation"]
            v0[6 * b:6 * b + 3] = body["velocity"] * T / L
            v0[6 * b + 3:6 * b + 6] = body["angular_velocity"] * T
        self._q0, self._v0 = q0, v0
        self._Minv = np.linalg.inv(self._M)
        #: the bodies whose inertia is not isotropic: only their omega x J omega is not zero
        self.gyroscopic_bodies = [b for b in range(nb) if np.max(np.abs(
            self.inertias[b] - np.trace(self.inertias[b]) / 3.0 * np.eye(3))) > 0.0]
        self._rot_cache = []
        self._planes = [(p.point / L, p.normal, p.t1, p.t2) for p in model.planes]
        self._contacts = model.contacts
        #: the body of each contact (a contact between two bodies: its first, ``a``)
        self.contact_bodies = [c["body"] for c in model.contacts]
        #: ``(a, b)`` of each contact: its bodies, ``b = -1`` for a half-space
        self.contact_pairs = [(c["body"], c.get("body_b", -1)) for c in model.contacts]
        #: the contacts between two bodies' spheres (:meth:`SpaceModel.add_pair_contact`)
        self.pair_index = [i for i, c in enumerate(model.contacts) if c["kind"] == "pair"]
        #: the contacts with a box between two bodies (:meth:`SpaceModel.add_box_contact`),
        #: whose points the scene finds at each configuration
        self.box_index = [i for i, c in enumerate(model.contacts) if c["kind"] in _BOX_KINDS]
        self._box_cache = []
        self.mu = np.array([c["mu"] for c in model.contacts])
        self.restitution = np.array([c["e"] for c in model.contacts])
        #: each contact's patch radius ``r`` (scene units; 0: a point contact)
        self.contact_radii = np.array([c.get("contact_radius", 0.0) for c in model.contacts])
        #: ``r* = 2 r / 3``: the drilling torque's lever in the friction ellipsoid
        self.drilling_levers = DRILLING_LEVER * self.contact_radii
        #: True where a frictional contact has a patch (Coulomb–Contensou friction)
        self.drilling = bool(np.any((self.drilling_levers > 0.0) & (self.mu > 0.0)))

    def initial_state(self):
        return self._q0.copy(), self._v0.copy()

    # -- dynamics ----------------------------------------------------------------------
    def mass(self, q):
        return self._M.copy()

    def mass_inverse(self, q):
        """``M^-1`` (constant: the inertia is in the body frame, the velocities too)."""
        return self._Minv.copy()

    def forces(self, q, v, t):
        v = np.asarray(v, dtype=float)
        out = np.empty(self.nvel)
        for b in range(self.nbodies):
            out[6 * b:6 * b + 3] = self.masses[b] * self.gravity
            out[6 * b + 3:6 * b + 6] = _gyro(self.inertias[b], v[6 * b + 3:6 * b + 6])
        return out

    def gyroscopic(self, v):
        """The gyroscopic part ``-omega x J omega`` of :meth:`forces` (zero on the centres)."""
        v = np.asarray(v, dtype=float)
        out = np.zeros(self.nvel)
        for b in self.gyroscopic_bodies:
            # (an isotropic body's is zero but for rounding: it stays in the forces' rest)
            out[6 * b + 3:6 * b + 6] = _gyro(self.inertias[b], v[6 * b + 3:6 * b + 6])
        return out

    def force_jacobians(self, q, v, t):
        """``(dh/dq, dh/dv)``, shapes (nvel, ndof) and (nvel, nvel): only the gyroscopic block.

        ``d(omega x J omega)/d omega = [omega]x J - [J omega]x`` with ``[a]x b = a x b``.
        """
        v = np.asarray(v, dtype=float)
        K = np.zeros((self.nvel, self.ndof))
        C = np.zeros((self.nvel, self.nvel))
        for b in range(self.nbodies):
            w = v[6 * b + 3:6 * b + 6]
            J = self.inertias[b]
            C[6 * b + 3:6 * b + 6, 6 * b + 3:6 * b + 6] = -(_cross_matrix(w) @ J
                                                           - _cross_matrix(J @ w))
        return K, C

    # -- contacts ----------------------------------------------------------------------
    def _rotations(self, q):
        # the last two states' rotations are kept: a step asks for them at its start and
        # end, and the next step starts where this one ended
        key = q.tobytes()
        for k, Rs in self._rot_cache:
            if k == key:
                return Rs
        Rs = [rotation_matrix(q[7 * b + 3:7 * b + 7] / np.linalg.norm(q[7 * b + 3:7 * b + 7]),
                              check=False) for b in range(self.nbodies)]
        self._rot_cache = [self._rot_cache[-1], (key, Rs)] if self._rot_cache else [(key, Rs)]
        return Rs

    def _contact_geometry(self, q, i, Rs=None):
        c = self._contacts[i]
        b = c["body"]
        x = q[7 * b:7 * b + 3]
        R = (Rs or self._rotations(q))[b]
        y0, n, t1, t2 = self._planes[c["plane"]]
        if c["kind"] == "rim":
            s = rim_offset(R, n, c["radius"])[0]
        elif c["point"] is None:
            s = -c["radius"] * n
            if c["centre"] is not None:
                s = s + R @ c["centre"]
        else:
            s = R @ c["point"]
        return b, x, R, s, y0, n, t1, t2

    def _pair_geometry(self, q, i, Rs=None):
        # the module docstring's "Contacts between two spheres": (a, b, Ra, Rb, the centres'
        # offsets R c (world), the centres p, n, L, s_a, s_b)
        c = self._contacts[i]
        a, b = c["body"], c["body_b"]
        Rs = Rs or self._rotations(q)
        Ra, Rb = Rs[a], Rs[b]
        ca, cb = Ra @ c["centre"], Rb @ c["centre_b"]
        d = (q[7 * b:7 * b + 3] + cb) - (q[7 * a:7 * a + 3] + ca)
        L = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        if L <= CONCENTRIC_TOL * (c["radius"] + c["radius_b"]):
            raise IllPosedError(f"the spheres of contact {i} (bodies {a} and {b}) are "
                                f"concentric (centres {L:.3g} apart): the contact has no normal")
        n = d / L
        return a, b, Ra, Rb, ca, cb, n, L, ca + c["radius"] * n, cb - c["radius_b"] * n

    def _box_point(self, q, i, Rs=None):
        # (a, b, Ra, Rb, the point of contact i or None for an unused slot): the module
        # docstring's "Contacts with boxes"; a pair's points are found once per configuration
        c = self._contacts[i]
        a, b = c["body"], c["body_b"]
        Rs = Rs or self._rotations(q)
        key = q.tobytes()
        entry = next((d for k, d in self._box_cache if k == key), None)
        if entry is None:
            entry = {}
            self._box_cache = ([self._box_cache[-1], (key, entry)] if self._box_cache
                               else [(key, entry)])
        first = c.get("first", i)
        if first not in entry:
            xa, xb = q[7 * a:7 * a + 3], q[7 * b:7 * b + 3]
            try:
                if c["kind"] == "sphere-box":
                    entry[first] = [sphere_box(xa, Rs[a], c["centre"], c["radius"], xb, Rs[b],
                                               c["half_b"])]
                else:
                    entry[first] = box_box(xa, Rs[a], c["half"], xb, Rs[b], c["half_b"],
                                           c["margin"])
            except IllPosedError as exc:
                raise IllPosedError(f"contact {first} (bodies {a} and {b}): {exc}") from None
        pts = entry[first]
        slot = c.get("slot", 0)
        return a, b, Rs[a], Rs[b], (pts[slot] if slot < len(pts) else None)

    def contacts_in_use(self, q):
        """Whether each contact has a point at ``q``: False only for the unused slots of a
        contact between two boxes (:meth:`SpaceModel.add_box_contact`). Shape (nc,)."""
        q = np.asarray(q, dtype=float)
        out = np.ones(self.ncontacts, dtype=bool)
        Rs = self._rotations(q)
        for i in self.box_index:
            out[i] = self._box_point(q, i, Rs)[4] is not None
        return out

    def gaps(self, q, t):
        q = np.asarray(q, dtype=float)
        out = np.empty(self.ncontacts)
        Rs = self._rotations(q)
        for i in range(self.ncontacts):
            if self._contacts[i]["kind"] in _BOX_KINDS:
                pt = self._box_point(q, i, Rs)[4]
                out[i] = self._contacts[i]["margin"] if pt is None else pt.g
                continue
            if self._contacts[i]["kind"] == "pair":
                c = self._contacts[i]
                out[i] = self._pair_geometry(q, i, Rs)[7] - c["radius"] - c["radius_b"]
                continue
            _, x, _, s, y0, n, _, _ = self._contact_geometry(q, i, Rs)
            out[i] = n @ (x + s - y0)
        return out

    def contact_frames(self, q, t):
        """``(R, s)`` per contact: the body's rotation and the contact point's offset (world)
        (a contact between two bodies: its body ``a``'s, :meth:`material_points` has both)."""
        q = np.asarray(q, dtype=float)
        out = []
        for i in range(self.ncontacts):
            if self._contacts[i]["kind"] in _BOX_KINDS:
                _, _, Ra, _, pt = self._box_point(q, i)
                out.append((Ra, np.zeros(3) if pt is None else pt.sa))
                continue
            if self._contacts[i]["kind"] == "pair":
                g = self._pair_geometry(q, i)
                out.append((g[2], g[8]))
            else:
                out.append(self._contact_geometry(q, i)[2:4])
        return out

    def material_points(self, q, q_at):
        """Each contact point as material points fixed in their bodies at ``q_at``, moved to ``q``.

        Row ``i`` is the contact point of ``q_at`` carried with its body to
        the configuration ``q`` (world, scene units); for a contact between
        two bodies, ``b``'s point less ``a``'s: the rates of these along a
        motion are the contacts' relative velocities, which the rows give
        (:func:`moreau.check.check_scene` differentiates them). Shape (nc, 3).
        """
        q, q_at = np.asarray(q, dtype=float), np.asarray(q_at, dtype=float)
        Rs, R0s = self._rotations(q), self._rotations(q_at)
        out = np.empty((self.ncontacts, 3))
        for i in range(self.ncontacts):
            if self._contacts[i]["kind"] in _BOX_KINDS:
                a, b, _, _, pt = self._box_point(q_at, i, R0s)
                out[i] = 0.0 if pt is None else (
                    q[7 * b:7 * b + 3] + Rs[b] @ (R0s[b].T @ pt.sb)
                    - q[7 * a:7 * a + 3] - Rs[a] @ (R0s[a].T @ pt.sa))
                continue
            if self._contacts[i]["kind"] == "pair":
                a, b, _, _, _, _, _, _, sa, sb = self._pair_geometry(q_at, i, R0s)
                out[i] = (q[7 * b:7 * b + 3] + Rs[b] @ (R0s[b].T @ sb)
                          - q[7 * a:7 * a + 3] - Rs[a] @ (R0s[a].T @ sa))
            else:
                b, _, R0, s0, _, _, _, _ = self._contact_geometry(q_at, i, R0s)
                out[i] = q[7 * b:7 * b + 3] + Rs[b] @ (R0.T @ s0)
        return out

    def contact_rows(self, q):
        """Every contact's three rows ``[n, t1, t2]`` against the velocities, shape (nc, 3, nvel)."""
        q = np.asarray(q, dtype=float)
        out = np.zeros((self.ncontacts, 3, self.nvel))
        Rs = self._rotations(q)
        for i in range(self.ncontacts):
            if self._contacts[i]["kind"] in _BOX_KINDS:
                a, b, Ra, Rb, pt = self._box_point(q, i, Rs)
                if pt is not None:
                    E = _frame(pt.n)
                    out[i, :, 6 * b:6 * b + 3] = E
                    out[i, :, 6 * b + 3:6 * b + 6] = _cross_rows(pt.sb, E) @ Rb
                    out[i, :, 6 * a:6 * a + 3] = -E
                    out[i, :, 6 * a + 3:6 * a + 6] = -(_cross_rows(pt.sa, E) @ Ra)
                continue
            if self._contacts[i]["kind"] == "pair":
                a, b, Ra, Rb, _, _, n, _, sa, sb = self._pair_geometry(q, i, Rs)
                E = _frame(n)
                out[i, :, 6 * b:6 * b + 3] = E
                out[i, :, 6 * b + 3:6 * b + 6] = _cross_rows(sb, E) @ Rb
                out[i, :, 6 * a:6 * a + 3] = -E
                out[i, :, 6 * a + 3:6 * a + 6] = -(_cross_rows(sa, E) @ Ra)
                continue
            b, _, R, s, _, n, t1, t2 = self._contact_geometry(q, i, Rs)
            out[i, :, 6 * b:6 * b + 6] = point_rows(R, s, np.array([n, t1, t2]))
        return out

    def drilling_rows(self, q):
        """Every contact's drilling row ``r* n . (R omega)`` against the velocities, (nc, nvel).

        The spin about the half-space's normal, scaled by the contact's lever
        ``r*`` (:attr:`drilling_levers`; zero rows for point contacts): with
        it the friction ellipsoid is the round cone of the module docstring.

        Examples
        --------
        >>> m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.1)
        >>> b = m.add_body(1.0, [0.004] * 3, position=(0.0, 0.0, 0.1))
        >>> _ = m.add_contact(b, Sphere(0.1), m.add_half_space((0, 0, 0), (0, 0, 1)), mu=0.2,
        ...                   contact_radius=0.03)
        >>> m.build("ball").drilling_rows(np.array([0, 0, 1.0, 1, 0, 0, 0])).round(12).tolist()
        [[0.0, 0.0, 0.0, 0.0, 0.0, 0.2]]
        """
        q = np.asarray(q, dtype=float)
        out = np.zeros((self.ncontacts, self.nvel))
        Rs = self._rotations(q)
        for i in np.flatnonzero(self.drilling_levers > 0.0):
            b, _, R, _, _, n, _, _ = self._contact_geometry(q, i, Rs)
            out[i, 6 * b + 3:6 * b + 6] = self.drilling_levers[i] * (n @ R)
        return out

    def contact_jacobians(self, q, t):
        rows = self.contact_rows(q)
        fi = self.frictional_index
        WN = rows[:, 0, :].copy()
        WT = rows[fi, 1:, :].reshape(2 * len(fi), self.nvel)
        return WN, np.zeros(self.ncontacts), WT, np.zeros(WT.shape[0])

    def contact_drift(self, q, v, t):
        q = np.asarray(q, dtype=float)
        v = np.asarray(v, dtype=float)
        fi = list(self.frictional_index)
        wN = np.zeros(self.ncontacts)
        wT = np.zeros(2 * len(fi))
        for i in range(self.ncontacts):
            c = self._contacts[i]
            if c["kind"] in _BOX_KINDS:
                a, b, Ra, Rb, pt = self._box_point(q, i)
                if pt is not None:
                    d = _box_drift(pt, v[6 * a:6 * a + 3], Ra @ v[6 * a + 3:6 * a + 6],
                                   v[6 * b:6 * b + 3], Rb @ v[6 * b + 3:6 * b + 6], Rb)
                    wN[i] = d[0]
                    if i in fi:
                        j = fi.index(i)
                        wT[2 * j], wT[2 * j + 1] = d[1], d[2]
                continue
            if c["kind"] == "pair":
                dN, dT = self._pair_drift(q, v, i)
                wN[i] = dN
                if i in fi:
                    j = fi.index(i)
                    wT[2 * j], wT[2 * j + 1] = dT
                continue
            b, _, R, s, _, n, t1, t2 = self._contact_geometry(q, i)
            w = R @ v[6 * b + 3:6 * b + 6]
            if c["kind"] == "rim":
                a = np.cross(w, _rim_point_rate(R, n, c["radius"], w))
            else:
                if c["point"] is None:
                    if c["centre"] is None:
                        continue        # a sphere's support point: s = -rho n is constant
                    s = R @ c["centre"]     # only the sphere's centre turns with the body
                a = np.cross(w, np.cross(w, s))
            wN[i] = n @ a
            if i in fi:
                j = fi.index(i)
                wT[2 * j], wT[2 * j + 1] = t1 @ a, t2 @ a
        return wN, wT

    def _pair_drift(self, q, v, i):
        # d/dt (e . Delta) at zero accelerations, e = n, t1, t2 (the module docstring's
        # "Contacts between two spheres"); returns (normal, (t1, t2))
        c = self._contacts[i]
        a, b, Ra, Rb, ca, cb, n, L, sa, sb = self._pair_geometry(q, i)
        wa, wb = Ra @ v[6 * a + 3:6 * a + 6], Rb @ v[6 * b + 3:6 * b + 6]
        xa, xb = v[6 * a:6 * a + 3], v[6 * b:6 * b + 3]
        delta = xb + np.cross(wb, sb) - xa - np.cross(wa, sa)
        dd = xb + np.cross(wb, cb) - xa - np.cross(wa, ca)        # p_b' - p_a'
        nd = (dd - (n @ dd) * n) / L
        sad = np.cross(wa, ca) + c["radius"] * nd
        sbd = np.cross(wb, cb) - c["radius_b"] * nd
        acc = np.cross(wb, sbd) - np.cross(wa, sad)
        _, t1, t2 = _frame(n)
        k = _least_axis(n)        # tangent_basis's axis e_k
        m = -n[k] * n
        m[k] += 1.0
        md = -nd[k] * n - n[k] * nd
        t1d = (md - (t1 @ md) * t1) / math.sqrt(m @ m)
        t2d = np.cross(nd, t1) + np.cross(n, t1d)
        return (nd @ delta + n @ acc,
                (t1d @ delta + t1 @ acc, t2d @ delta + t2 @ acc))

    # -- SI units and drawing ------------------------------------------------------------
    @property
    def force(self):
        """Newtons per unit of the scene's force, ``M L / T^2``."""
        return self.mass_unit * self.length / self.time ** 2

    def force_to_si(self, f):
        """A force in the scene's units to newtons."""
        return np.asarray(f, dtype=float) * self.force

    def _qscale(self):
        # centres in the length unit, quaternions dimensionless
        return np.tile([self.length] * 3 + [1.0] * 4, self.nbodies)

    def _vscale(self):
        return np.tile([self.length / self.time] * 3 + [1.0 / self.time] * 3, self.nbodies)

    def to_si(self, result):
        """SI time histories of a run: ``t`` [s], ``q`` (centres [m], quaternions), ``v``
        (centre velocities [m/s], body-frame angular velocities [rad/s]), ``force_N``,
        ``force_T`` [N] (the tangential one a magnitude), ``slip_velocity`` [m/s] (a
        magnitude), ``gap`` [m], ``regime``."""
        L, T, F = self.length, self.time, self.force
        return {"t": result.t * T, "q": result.q * self._qscale(), "v": result.v * self._vscale(),
                "force_N": result.force_N * F, "force_T": result.force_T * F,
                "slip_velocity": result.slip_velocity * (L / T), "gap": result.gap * L,
                "regime": result.regime.copy()}

    def si_columns(self, result):
        """The SI histories of ``result`` as ``[(name, unit, column)]`` (``1`` for a quaternion's)."""
        units = dict(SI_UNITS, q=["m"] * 3 + ["1"] * 4, v=["m/s"] * 3 + ["rad/s"] * 3)
        units["q"] = units["q"] * self.nbodies
        units["v"] = units["v"] * self.nbodies
        return columns_of(self.to_si(result), units)

    def shapes(self, q, t=0.0):
        """A side view (the world's ``x``, ``z``) at SI coordinates ``q``: bodies, planes, contacts."""
        qs = np.asarray(q, dtype=float) / self._qscale()
        L = self.length
        out = []
        for y0, n, t1, _ in self._planes:
            p0 = np.array([y0[0], y0[2]]) * L
            d = np.array([n[2], -n[0]])
            d = d / (np.hypot(*d) or 1.0) * 20.0 * L
            out.append(line([p0 - d, p0 + d], "ground"))
        Rs = self._rotations(qs)
        boxes = {}
        for c in self._contacts:
            if c["kind"] in _BOX_KINDS:
                boxes[c["body_b"]] = c["half_b"]
                if c["kind"] == "box-box":
                    boxes[c["body"]] = c["half"]
        for b, h in boxes.items():
            # the box's side view: the outline (x, z) of its corners
            pts = (qs[7 * b:7 * b + 3] + Box(h).points(1.0) @ Rs[b].T) * L
            out.append(polygon(_hull(pts[:, [0, 2]])))
        for i, c in enumerate(self._contacts):
            b = c["body"]
            x = qs[7 * b:7 * b + 3] * L
            if c["kind"] in _BOX_KINDS:
                if c["kind"] == "sphere-box":
                    y = x + Rs[b] @ c["centre"] * L
                    out.append(circle((y[0], y[2]), c["radius"] * L))
            elif c["kind"] == "pair":
                for bb, cc, rr in ((b, c["centre"], c["radius"]),
                                   (c["body_b"], c["centre_b"], c["radius_b"])):
                    y = (qs[7 * bb:7 * bb + 3] + Rs[bb] @ cc) * L
                    out.append(circle((y[0], y[2]), rr * L))
            elif c["kind"] == "rim":
                # the rim seen from the side: its points' (x, z), an ellipse's outline
                R = self._rotations(qs)[b]
                phi = np.linspace(0.0, 2.0 * np.pi, 49)
                rim = x + c["radius"] * L * (np.outer(np.cos(phi), R[:, 0])
                                             + np.outer(np.sin(phi), R[:, 1]))
                out.append(line(rim[:, [0, 2]]))
            elif c["point"] is None:
                if c["centre"] is not None:
                    x = x + self._rotations(qs)[b] @ c["centre"] * L
                out.append(circle((x[0], x[2]), c["radius"] * L))
        for b in range(self.nbodies):
            if b not in boxes and not any((c["body"] == b or c.get("body_b") == b)
                                          and c["point"] is None for c in self._contacts):
                x = qs[7 * b:7 * b + 3] * L
                out.append(circle((x[0], x[2]), 0.05 * L))
        for i in range(self.ncontacts):
            if self._contacts[i]["kind"] in _BOX_KINDS:
                a, _, _, _, pt = self._box_point(qs, i, Rs)
                if pt is None:
                    # an unused slot of a box-box contact: listed, marked open (not drawn),
                    # as every contact index is in a drawing
                    x = qs[7 * a:7 * a + 3] * L
                    c = contact(i, (x[0], x[2]), (0.0, 1.0))
                    c["open"] = True
                    out.append(c)
                    continue
                x, s, n = qs[7 * a:7 * a + 3], pt.sa, pt.n
            elif self._contacts[i]["kind"] == "pair":
                a, _, _, _, _, _, n, _, s, _ = self._pair_geometry(qs, i, Rs)
                x = qs[7 * a:7 * a + 3]
            else:
                _, x, _, s, _, n, _, _ = self._contact_geometry(qs, i, Rs)
            p = (x + s) * L
            nn = np.array([n[0], n[2]])
            out.append(contact(i, (p[0], p[2]), nn / (np.hypot(*nn) or 1.0)))
        return out

    def contact_bases(self, q=None):
        """``(n, t1, t2)`` of every contact (world), one row each.

        A half-space's frame is fixed; a contact between two spheres has the
        frame of their line of centres at ``q``, which it then needs (an
        :class:`~moreau.errors.InputError` naming ``q`` without it).
        """
        if q is None and (self.pair_index or self.box_index):
            raise InputError(f"`q` must be given: scene {self.name!r} has contacts between "
                             f"two bodies, whose frames turn with them")
        out = []
        for i, c in enumerate(self._contacts):
            if c["kind"] in _BOX_KINDS:
                # (an unused slot: the world's z frame, its rows being zero)
                pt = self._box_point(np.asarray(q, dtype=float), i)[4]
                out.append(tuple(_frame(np.array([0.0, 0.0, 1.0]) if pt is None else pt.n)))
                continue
            if c["kind"] == "pair":
                out.append(tuple(_frame(self._pair_geometry(np.asarray(q, dtype=float), i)[6])))
            else:
                out.append(self._planes[c["plane"]][1:])
        return out

    def contact_table(self):
        """Every contact's data in one float array for a compiled step, or None.

        Row ``i``: ``[body, kind, radius, c (3), y0 (3), n (3), t1 (3), t2
        (3)]`` in the scene's units, ``kind`` 0 for a sphere about the centre
        of mass (``s = -radius n``), 1 for an eccentric sphere (``s = R c -
        radius n``, ``c`` its centre) and 2 for a material point (``s = R
        c``, ``c`` the point), as in the module docstring, and 3 for a
        contact between two bodies' spheres (:meth:`SpaceModel.add_pair_contact`):
        ``body`` and ``radius``, ``c`` of its sphere on body ``a``, the rest
        in :meth:`pair_table`. None where a contact is of none of these
        kinds. A contact patch (``contact_radius > 0``) leaves its row as it
        is: its lever is :attr:`drilling_levers`.

        Examples
        --------
        >>> m = SpaceModel(gravity=(0.0, 0.0, -9.81))
        >>> b = m.add_body(1.0, [0.004] * 3, position=(0.0, 0.0, 0.1))
        >>> _ = m.add_contact(b, Sphere(0.1), m.add_half_space((0, 0, 0), (0, 0, 1)), mu=0.2)
        >>> m.build("ball").contact_table()[0, :3].tolist()
        [0.0, 0.0, 0.1]
        """
        out = np.zeros((self.ncontacts, 18))
        for i, c in enumerate(self._contacts):
            if c["kind"] == "pair":
                out[i, :6] = [c["body"], 3, c["radius"], *c["centre"]]
                continue
            # a contact's shape is read from these keys only: any other kind has no row
            if not set(c) <= _TABLE_KEYS or c.get("kind", "sphere") not in ("sphere", "point"):
                return None
            y0, n, t1, t2 = self._planes[c["plane"]]
            if c["point"] is not None:
                kind, offset = 2, c["point"]
            elif c["centre"] is not None:
                kind, offset = 1, c["centre"]
            else:
                kind, offset = 0, np.zeros(3)
            out[i] = np.concatenate([[c["body"], kind, c["radius"]], offset, y0, n, t1, t2])
        return out

    def pair_table(self):
        """Each contact's body ``b`` for a compiled step: None without contacts between bodies.

        Row ``i``: ``[b, radius, c (3), L_min]`` of a contact between two
        bodies' spheres (:meth:`SpaceModel.add_pair_contact`; its body ``a``'s
        sphere is in :meth:`contact_table`), in the scene's units: body
        ``b``, its sphere's radius and centre (body frame), and the distance
        of centres ``L_min = CONCENTRIC_TOL (r_a + r_b)`` at or below which
        the contact has no normal; ``[-1, 0, ...]`` for a contact with a
        half-space.

        Examples
        --------
        >>> m = SpaceModel()
        >>> a = m.add_body(1.0, [0.004] * 3)
        >>> b = m.add_body(1.0, [0.004] * 3, position=(0.25, 0.0, 0.0))
        >>> _ = m.add_pair_contact(a, Sphere(0.1), b, Sphere(0.15))
        >>> m.build("pair").pair_table()[0, :5].tolist()
        [1.0, 0.15, 0.0, 0.0, 0.0]
        """
        if not self.pair_index:
            return None
        out = np.zeros((self.ncontacts, 6))
        out[:, 0] = -1.0
        for i in self.pair_index:
            c = self._contacts[i]
            out[i] = [c["body_b"], c["radius_b"], *c["centre_b"],
                      CONCENTRIC_TOL * (c["radius"] + c["radius_b"])]
        return out


#: the keys of a contact that :meth:`SpaceScene.contact_table` knows
_TABLE_KEYS = {"kind", "body", "plane", "mu", "e", "radius", "point", "centre",
               "contact_radius"}


def _hull(points):
    # the convex hull of 2D points, counter-clockwise (Andrew's monotone chain)
    pts = sorted(map(tuple, np.asarray(points, dtype=float)))
    if len(pts) < 3:
        return pts

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0.0:
                out.pop()
            out.append(p)
        return out[:-1]

    return half(pts) + half(pts[::-1])


def _least_axis(n):
    # np.argmin(np.abs(n)), ties to the first, without the array calls
    a0, a1, a2 = abs(n[0]), abs(n[1]), abs(n[2])
    return (0 if a0 <= a2 else 2) if a0 <= a1 else (1 if a1 <= a2 else 2)


def _frame(n):
    # [n, t1, t2] of tangent_basis(n) in one (3, 3) array, written out (a pair contact's
    # frame, evaluated every step)
    k = _least_axis(n)
    n0, n1, n2 = float(n[0]), float(n[1]), float(n[2])
    nk = (n0, n1, n2)[k]
    t = [-nk * n0, -nk * n1, -nk * n2]
    t[k] += 1.0
    f = 1.0 / math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    a, b, c = t[0] * f, t[1] * f, t[2] * f
    return np.array([[n0, n1, n2], [a, b, c],
                     [n1 * c - n2 * b, n2 * a - n0 * c, n0 * b - n1 * a]])


def _cross_rows(s, E):
    # s x E[k] for each row k
    return np.column_stack([s[1] * E[:, 2] - s[2] * E[:, 1], s[2] * E[:, 0] - s[0] * E[:, 2],
                            s[0] * E[:, 1] - s[1] * E[:, 0]])


def _rim_point_rate(R, n, radius, w):
    # s' = -r u' of the rim's lowest point as the axis turns at w (module docstring)
    a = R[:, 2]
    _, sigma, u = rim_offset(R, n, radius)
    ad = np.cross(w, a)
    md = -(n @ ad) * a - (n @ a) * ad
    return -radius * (md - (u @ md) * u) / sigma


def _gyro(J, w):
    # -omega x J omega, written out (three components, no np.cross call)
    Jw = J @ w
    return np.array([-(w[1] * Jw[2] - w[2] * Jw[1]), -(w[2] * Jw[0] - w[0] * Jw[2]),
                     -(w[0] * Jw[1] - w[1] * Jw[0])])


def _cross_matrix(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
