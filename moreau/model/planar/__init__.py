"""Planar mechanisms from a description: rigid bodies, shapes, unilateral contacts and forces.

A :class:`Model` holds bodies in maximal coordinates (each free body's
``x, y, theta`` of its centre of mass, in the order added), fixed bodies
and driven ones (a prescribed :class:`TimeFunction` motion: cranks,
stators), guided ones (some coordinates prescribed, the others free: a
rod hinged on a moving stator, a slider on a guide), shapes
(:class:`Point`, :class:`Circle`, :class:`Segment`, convex
:class:`Polygon`, :class:`HalfPlane`), contacts between shapes with their
own ``mu`` and ``e``, and forces (gravity, springs and dashpots between body
points, along their distance or along a fixed direction, torsion springs,
given forces and torques). :meth:`Model.build`
returns a scene that every scheme and analysis takes. Its compiled model
is numba source generated from the model's structure (which bodies are free,
fixed or driven, each contact's kind, each force), with every number in
``par`` (:mod:`moreau.model.planar._codegen`): models of one structure share
one module, kept with numba's disk cache under ``~/.cache/moreau/planar``
(or ``$MOREAU_PLANAR_CACHE``). The first build of a new structure compiles
them (about 4 s for a block on a floor, 15 s for a model with every contact
kind and force, on the development machine); later builds, in any process,
load them. Its Python methods call those same functions, so the model is
written once.

Example: a disk rolling down a rough incline, in ten lines.

>>> import math
>>> from moreau.model.planar import Model, Circle, HalfPlane
>>> from moreau.integrators import simulate
>>> slope, r = math.radians(20.0), 0.1
>>> normal = (-math.sin(slope), math.cos(slope))
>>> m = Model(gravity=(0.0, -9.81))
>>> floor = m.add_shape(m.ground, HalfPlane((0.0, 0.0), normal))
>>> disk = m.add_body(mass=1.0, inertia=0.5 * r ** 2, position=(r * normal[0], r * normal[1]))
>>> m.add_contact(m.add_shape(disk, Circle(r)), floor, mu=0.5)
[0]
>>> scene = m.build("disk-on-incline")
>>> res = simulate(scene, (0.0, 10.0), *scene.initial_state(), "moreau-jean", h=1e-2)
>>> q = scene.to_si(res)                          # SI: t [s], q [m, rad]
>>> down = -(q["q"][-1, 0] * math.cos(slope) + q["q"][-1, 1] * math.sin(slope))
>>> round(float(down / (9.81 * math.sin(slope) / 3.0 * q["t"][-1] ** 2)), 2)   # 2/3 g sin
1.0

Contact pairs
-------------
The engine works with a fixed number of contacts, so :meth:`Model.add_contact`
fixes the candidate pairs when the model is built, each one contact row
with its own gap, normal and tangent: a circle or a point against any
shape is one row (its centre against the other shape's nearest feature,
chosen at each evaluation); a polygon or segment against a half-plane is one
row per vertex (``vertices`` selects some); two polygons give each vertex of
each against the other. The distance to a polygon is continuous; inside it
(a deep penetration) it is the least penetration over the faces, with kinks
where that face changes, and a point passing through a two-sided segment
sees its distance turn at zero: a model is meant to stay near its surfaces.

Contact kinematics
------------------
A contact row is a point ``P_A = X_A + R(theta_A) r_A`` of body ``A`` with a
radius ``rho_A`` (a circle's centre, a vertex with ``rho_A = 0``) against a
feature of body ``B``, fixed when the model is built (a polygon's nearest
face or vertex is chosen at each evaluation). Write ``r' = R(theta) r``,
``perp(x) = (-x_y, x_x)``, ``a x b = a_x b_y - a_y b_x``, and
``V, w`` (``A, alpha``) a body's velocities (accelerations); a material
point ``X + s`` moves at ``V + w perp(s)``.

*Point on a line* of ``B`` (half-plane, polygon face; ``p0`` and the unit
normal ``n0`` in ``B``'s frame): ``n = R_B n0``,
``g = n . (P_A - X_B - R_B p0) - rho_A``. Differentiating, with
``n' = w_B perp(n)`` and ``perp(n) . d = -n . perp(d)``, the ``w_B`` terms
gather into ``-w_B n . perp(P_A - X_B)``:
``g' = n . (v_A(C) - v_B(C))``, the two bodies' velocities at the contact
point ``C = P_A - rho_A n``. The slip velocity is ``gammaT = t . (v_A(C) -
v_B(C))`` with ``t = (n_y, -n_x)``; ``t . perp(n) = -1`` puts the rolling
term ``rho_A (w_A - w_B)`` in it.

*Point to point* (circle to circle, a polygon's nearest vertex):
``d = P_A - P_B``, ``n = d / |d|``, ``g = |d| - rho_A - rho_B``, contact
points ``C_A = P_A - rho_A n`` and ``C_B = P_B + rho_B n``.

*Pin in a hole* (:meth:`Model.add_clearance_revolute`, a revolute joint
with clearance: pin ``P_A`` of radius ``R_p`` on ``A``, hole centre
``P_B`` of radius ``R_h`` on ``B``): ``d = P_A - P_B``, ``c = R_h - R_p``,
``g = c - |d|``, ``n = -d / |d|`` (from the wall towards the centre, the
direction of the force on the pin), contact points ``C_A = P_A - R_p n``
and ``C_B = P_B - R_h n``. Then ``g' = -(d / |d|) . d' = n . d'``, and as
``n . perp(d) = 0`` the contact points' levers add nothing to the normal
row; ``t = (n_y, -n_x) = perp(d / |d|)`` and ``t . perp(d / |d|) = 1`` put
``R_p w_A - R_h w_B`` in the slip. With ``n' = -t (t . d') / |d|`` and
``t' = n (t . d') / |d|`` the drift terms are ``-(t . d')^2 / |d| + n .
d''`` and ``(n . d')(t . d') / |d| + t . d''``. At ``d = 0`` the normal is
undefined: ``B``'s ``x`` axis stands for ``d / |d|`` and the ``1 / |d|``
terms are dropped there (below ``|d| = 1e-12 R_h``); the gap is then the
whole clearance, far from closing, so the contact is open and nothing is NaN.
A pin in a slot (:meth:`Model.add_clearance_prismatic`) is two points on
lines, the slot's walls.

All three give the rows ``W v + w = e . (v_A(C_A) - v_B(C_B))`` for ``e`` in
``{n, t}``: body ``A``'s entries ``(e_x, e_y, s_A x e)`` with ``s_A = C_A -
X_A``, body ``B``'s the negatives with ``s_B = C_B - X_B``; a free body's
go into ``W``, a driven body's times its prescribed velocity into the
rheonomic term ``w``.

Drift (``d/dt (W v + w)`` at zero free accelerations), with ``dV = V_A -
V_B``: on a line ``e`` turns with ``B`` (``e' = w_B perp(e)``) and
``u = P_A - X_B``; differentiating ``e . dV + w_A e . perp(r'_A) - w_B e .
perp(u) + rho_A (w_A - w_B) [e = t]`` gives
``(2 w_A w_B - w_A^2) e . r'_A - w_B^2 e . u - 2 w_B e . perp(dV)``. Point to
point, ``n' = t (t . d') / |d|`` and ``t' = -n (t . d') / |d|`` give
``(t . d')^2 / |d| + n . d''`` and ``-(n . d')(t . d') / |d| + t . d''`` with
``d'' = -w_A^2 r'_A + w_B^2 r'_B``. A driven body's prescribed
accelerations add the row's entries times them. Every term is held to
central differences by :func:`moreau.check_scene` on every built model.

Guided bodies
-------------
:meth:`Model.add_guided` adds a body some of whose coordinates ``x, y,
theta`` are prescribed functions of time and the others free. Its ``x, y``
are those of its frame's origin ``X``, its centre of mass is ``X + R c``
(``c`` in its frame, mass ``m``, centroidal inertia ``I``). The rows above
hold with ``X`` for the body's position (they are kinematics of material
points): a free coordinate's entry goes into ``W``, a prescribed one's
entry times its prescribed rate into ``w``, and times its prescribed
acceleration into the drift terms. Its kinetic energy is ``T = m |X' + w
perp(R c)|^2 / 2 + I w^2 / 2``. With ``c = 0`` the mass matrix of its free
coordinates is ``diag(m, m, I)`` as for a free body. With ``c != 0`` the
builder asks for ``x`` and ``y`` prescribed (a body turning about a moving
pivot), and Lagrange's equation for ``theta`` reads, with ``a = X''``,
``dT/dw = m X' . perp(R c) + (I + m |c|^2) w`` and ``dT/dtheta = -m w X'
. R c``::

    (I + m |c|^2) theta'' = (R c) x m (g - a) + (the applied torques about X)

since ``d/dt (m X' . perp(R c)) = m a . perp(R c) - m w X' . R c`` and
``perp(u) . v = u x v``. Its derivative in ``theta`` is ``-(R c) . m (g -
a)`` (``d(R c)/dtheta = perp(R c)`` and ``perp(u) x v = -u . v``).

An axial spring (:meth:`Model.add_axial_spring`) measures its length along
a fixed world direction ``e``: ``l = e . (P_i - P_j)``, tension ``f = k (l -
l0) + c l'``, ``F = -f e`` on ``P_i``; ``dF/dP = -k e e^T``, ``dF/dP' = -c e
e^T``, and the generalized forces and their Jacobians follow as for the
spring below.

Forces: a spring-dashpot of tension ``f = k (l - l0) + c l'`` along ``e =
(P_i - P_j) / l`` puts ``F = -f e`` on ``P_i``, its generalized force
``(F, r'_i x F)``; with ``dF/dP = -[e (k e^T + (c / l) P'^T (I - e e^T)) +
(f / l)(I - e e^T)]``, ``dF/dP' = -c e e^T``, ``dP/dq_i = [I | perp(r'_i)]``,
``dP'/dtheta_i = -w_i r'_i`` and ``d(r'_i x F)/dtheta_i = -r'_i . F`` at fixed
``F``, the Jacobians follow by the chain rule.
"""

from .builder import (Body, Circle, HalfPlane, JointRows, Model, PlanarScene, Point, Polygon,
                      Segment, TimeFunction)

__all__ = ["Model", "Body", "TimeFunction", "Point", "Circle", "Segment", "Polygon",
           "HalfPlane", "PlanarScene", "JointRows"]
