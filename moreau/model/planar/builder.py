"""The planar model builder: bodies, shapes, contacts and forces, built into a scene.

See :mod:`moreau.model.planar` for the kinematics and an example.
"""

import math

import numpy as np

from ..._validate import finite_scalar, in_closed_interval, nonnegative, positive
from ...compiled import CompiledModel
from ...errors import InputError
from ..drawing import circle, contact, line, polygon
from ..units import SIUnits
from ..scene import Scene
from . import _codegen
from . import _kernels as K

__all__ = ["Model", "Body", "TimeFunction", "Point", "Circle", "Segment", "Polygon",
           "HalfPlane", "PlanarScene", "JointRows"]


def _vec2(name, value):
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` must be a pair of real numbers, got {value!r}") from None
    if arr.shape != (2,):
        raise InputError(f"`{name}` must be a pair of real numbers (x, y), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"`{name}` must be finite, got {value!r}")
    return arr


class TimeFunction:
    """A prescribed function of time ``f(t) = value + rate t + accel t^2 / 2 + sum A sin(w t + phi)``.

    The family the compiled model evaluates (with its exact first and second
    derivatives): a driven body's coordinates (a crank turning at a constant
    rate, a stator vibrating) and given forces and torques. SI units: ``t``
    in s, the value in the unit of the quantity it drives.

    Parameters
    ----------
    value, rate, accel : float
        The polynomial part.
    harmonics : sequence of (amplitude, angular_frequency, phase)
        ``w`` in rad/s. A phase of ``math.pi / 2`` makes the harmonic the
        cosine ``A cos(w t)``, evaluated as one (exact at ``t = 0``, where
        ``sin(w t + pi/2)`` would round ``pi/2``).

    Examples
    --------
    >>> f = TimeFunction(1.0, rate=2.0, harmonics=[(0.5, math.pi, 0.0)])
    >>> [round(x, 12) for x in f(0.5)]
    [2.5, 2.0, -4.934802200545]
    """

    def __init__(self, value=0.0, rate=0.0, accel=0.0, harmonics=()):
        self.value = finite_scalar("value", value)
        self.rate = finite_scalar("rate", rate)
        self.accel = finite_scalar("accel", accel)
        hs = []
        for k, h in enumerate(harmonics):
            if len(h) != 3:
                raise InputError(f"`harmonics[{k}]` must be (amplitude, angular_frequency, phase)")
            hs.append(tuple(finite_scalar(f"harmonics[{k}]", x) for x in h))
        self.harmonics = tuple(hs)

    @classmethod
    def of(cls, name, value):
        """``value`` as a TimeFunction (a number is a constant)."""
        if isinstance(value, TimeFunction):
            return value
        return cls(finite_scalar(name, value))

    def __call__(self, t):
        """``(f, f', f'')`` at ``t`` [s]."""
        t = float(t)
        f = self.value + t * (self.rate + 0.5 * self.accel * t)
        d1 = self.rate + self.accel * t
        d2 = self.accel
        for A, w, ph in self.harmonics:
            if ph == K.QUARTER:
                f += A * math.cos(w * t)
                d1 -= A * w * math.sin(w * t)
                d2 -= A * w * w * math.cos(w * t)
                continue
            f += A * math.sin(w * t + ph)
            d1 += A * w * math.cos(w * t + ph)
            d2 -= A * w * w * math.sin(w * t + ph)
        return f, d1, d2

    def packed(self, unit, time):
        """The record of :func:`moreau.model.planar._kernels.time_function` in scaled units."""
        out = [self.value / unit, self.rate * time / unit, self.accel * time ** 2 / unit,
               float(len(self.harmonics))]
        for A, w, ph in self.harmonics:
            out += [A / unit, w * time, ph, *K.KEPT_SLOTS]
        return out


# -- shapes (body frame, SI) -------------------------------------------------------------


class Point:
    """A point of a body at ``at`` (body frame, m)."""

    def __init__(self, at=(0.0, 0.0)):
        self.at = _vec2("at", at)

    def extent(self):
        return float(np.hypot(*self.at))


class Circle:
    """A disk of ``radius`` [m] centred at ``centre`` (body frame)."""

    def __init__(self, radius, centre=(0.0, 0.0)):
        self.radius = positive("radius", radius)
        self.centre = _vec2("centre", centre)

    def extent(self):
        return float(np.hypot(*self.centre)) + self.radius


class Polygon:
    """A convex polygon, its vertices counter-clockwise in the body frame [m].

    Examples
    --------
    >>> Polygon.box(0.2, 0.4).vertices.tolist()
    [[-0.1, -0.2], [0.1, -0.2], [0.1, 0.2], [-0.1, 0.2]]
    >>> Polygon([(0, 0), (1, 0), (2, 0)])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `vertices` must make a convex polygon of nonzero area, ...
    """

    def __init__(self, vertices):
        v = np.asarray(vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise InputError(f"`vertices` must be three or more (x, y) pairs, got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InputError("`vertices` must be finite")
        e = np.roll(v, -1, axis=0) - v
        cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        scale = float(np.max(np.abs(v))) or 1.0
        if not np.all(cross > 1e-12 * scale ** 2):
            raise InputError("`vertices` must make a convex polygon of nonzero area, its "
                             "vertices counter-clockwise with no three on a line; got "
                             f"{v.tolist()}")
        self.vertices = v

    @classmethod
    def box(cls, width, height, centre=(0.0, 0.0)):
        """A ``width`` x ``height`` rectangle, vertices from the bottom-left corner, counter-clockwise."""
        a = 0.5 * positive("width", width)
        b = 0.5 * positive("height", height)
        c = _vec2("centre", centre)
        return cls([(c[0] - a, c[1] - b), (c[0] + a, c[1] - b), (c[0] + a, c[1] + b),
                    (c[0] - a, c[1] + b)])

    def extent(self):
        return float(np.max(np.hypot(self.vertices[:, 0], self.vertices[:, 1])))


class Segment:
    """A segment from ``a`` to ``b`` (body frame, m); two-sided."""

    def __init__(self, a, b):
        self.vertices = np.array([_vec2("a", a), _vec2("b", b)])
        if np.allclose(self.vertices[0], self.vertices[1], rtol=0, atol=0):
            raise InputError("`a` and `b` of a segment must differ")

    def extent(self):
        return float(np.max(np.hypot(self.vertices[:, 0], self.vertices[:, 1])))


class HalfPlane:
    """The half-plane of a body behind the line through ``point`` with outward ``normal`` (body frame).

    The body's material lies on the side opposite to ``normal``: a floor is
    ``HalfPlane((0, 0), (0, 1))`` on the ground.
    """

    def __init__(self, point=(0.0, 0.0), normal=(0.0, 1.0)):
        self.point = _vec2("point", point)
        n = _vec2("normal", normal)
        ln = float(np.hypot(*n))
        if ln == 0.0:
            raise InputError("`normal` of a half-plane must not be zero")
        self.normal = n / ln

    def extent(self):
        return 0.0


class Body:
    """A body of a :class:`Model` (returned by its ``add_*`` methods)."""

    def __init__(self, model, index, kind, name):
        self.model, self.index, self.kind, self.name = model, index, kind, name

    def __repr__(self):
        return f"Body({self.name!r}, {('fixed', 'free', 'driven', 'guided')[self.kind]})"


class _ShapeRef:
    def __init__(self, body, shape, index):
        self.body, self.shape, self.index = body, shape, index


class Model:
    """A planar mechanism: rigid bodies with shapes, unilateral contacts and forces.

    Each free body has three coordinates ``(x, y, theta)`` of its centre of
    mass, in the order the bodies are added. Every argument is in SI units
    (m, kg, s, rad, N); the built scene works in units of ``length``,
    ``mass`` and ``time`` (by default the largest shape's size, the largest
    body's mass and ``sqrt(length / g)``), and converts at its edges.

    Parameters
    ----------
    gravity : pair of float
        [m/s^2], applied to every free body.
    length, mass, time : float, optional
        The scene's units [m, kg, s].

    Examples
    --------
    >>> m = Model()
    >>> disk = m.add_body(mass=2.0, inertia=0.01, position=(0.0, 0.1))
    >>> m.add_contact(m.add_shape(disk, Circle(0.1)), m.add_shape(m.ground, HalfPlane()), mu=0.5)
    [0]
    >>> scene = m.build()
    >>> scene.ndof, [round(float(g), 12) for g in scene.gaps(*scene.initial_state()[:1], 0.0)]
    (3, [0.0])
    """

    def __init__(self, gravity=(0.0, -9.81), length=None, mass=None, time=None):
        self.gravity = _vec2("gravity", gravity)
        self._units = {k: (None if u is None else positive(k, u))
                       for k, u in (("length", length), ("mass", mass), ("time", time))}
        self.bodies = []          # dicts
        self.shapes = []          # _ShapeRef
        self.contacts = []        # dicts
        self.forces = []          # dicts
        self.joints = []          # dicts
        self.ground = self._add(dict(kind=K.FIXED, pose=(0.0, 0.0, 0.0)), "ground")

    def _add(self, rec, name):
        body = Body(self, len(self.bodies), rec["kind"], name or f"body{len(self.bodies)}")
        rec["body"] = body
        self.bodies.append(rec)
        return body

    def _body(self, name, body):
        if not isinstance(body, Body) or body.model is not self:
            raise InputError(f"`{name}` must be a body of this model, got {body!r}")
        return body

    def _movable(self, body):
        # a body with a coordinate of its own: free, or guided with a free coordinate
        return body.kind == K.FREE or (body.kind == K.GUIDED and any(
            f is None for f in self.bodies[body.index]["motion"]))

    def _free(self, name, body):
        self._body(name, body)
        if not self._movable(body):
            raise InputError(f"`{name}` must be a free body: a given force on {body!r} moves nothing")
        return body

    # -- bodies --------------------------------------------------------------------------
    def add_body(self, mass, inertia, position=(0.0, 0.0), angle=0.0, velocity=(0.0, 0.0),
                 angular_velocity=0.0, name=None):
        """A free body: ``mass`` [kg], centroidal ``inertia`` [kg m^2], initial pose and velocity."""
        m = finite_scalar("mass", mass)
        if m <= 0.0:
            raise InputError(f"`mass` of a body must be > 0, got {m!r} (a body without mass "
                             "has no equations of motion: make it fixed or driven)")
        rec = dict(kind=K.FREE, mass=m, inertia=positive("inertia", inertia),
                   pose=(*_vec2("position", position), finite_scalar("angle", angle)),
                   vel=(*_vec2("velocity", velocity),
                        finite_scalar("angular_velocity", angular_velocity)))
        return self._add(rec, name)

    def add_guided(self, mass, inertia, x=None, y=None, theta=None, position=(0.0, 0.0),
                   angle=0.0, velocity=(0.0, 0.0), angular_velocity=0.0, centre=(0.0, 0.0),
                   name=None):
        """A body with some coordinates prescribed and the others free: a rod hinged on a moving stator, a slider on a guide.

        Each of ``x``, ``y`` [m] and ``theta`` [rad] is ``None`` (free: its
        initial value and rate from ``position``, ``velocity``, ``angle``,
        ``angular_velocity``) or a number or :class:`TimeFunction`
        (prescribed). Unlike :meth:`add_body`, ``x, y`` are the coordinates
        of the origin of the body's frame, and ``centre`` [m] is its centre of
        mass in that frame (``inertia`` about the centre, kg m^2): a body
        turning about a moving pivot has ``x`` and ``y`` prescribed and its
        frame's origin at the pivot. A centre off the origin needs ``x`` and
        ``y`` prescribed (otherwise the translations and the turn would share
        a mass matrix that is not diagonal). The free coordinates follow
        those of the bodies added before, in the order ``x, y, theta``.

        Equations (derived in :mod:`moreau.model.planar`, "Guided bodies"):
        a free ``x`` or ``y`` has the mass; a free ``theta`` the inertia
        about the origin, ``inertia + mass |centre|^2``, and with the origin
        at ``a(t)`` the torque ``(R centre) x mass (g - a)`` of gravity and of
        the frame's acceleration.

        Examples
        --------
        >>> m = Model(gravity=(0.0, -9.81))
        >>> rod = m.add_guided(1.0, 1.0 / 12.0, x=0.0, y=0.0, centre=(0.5, 0.0))
        >>> sc = m.build()
        >>> sc.ndof, round(float(sc.mass([0.0])[0, 0]), 12), round(float(sc.forces([0.0], [0.0], 0.0)[0]), 12)
        (1, 0.333333333333, -0.5)
        """
        m = finite_scalar("mass", mass)
        if m <= 0.0:
            raise InputError(f"`mass` of a body must be > 0, got {m!r}")
        motion = tuple(None if f is None else TimeFunction.of(nm, f)
                       for nm, f in (("x", x), ("y", y), ("theta", theta)))
        if all(f is not None for f in motion):
            raise InputError("`x`, `y` and `theta` are all prescribed: that is a driven body "
                             "(`add_driven`); leave at least one `None` (free)")
        c = _vec2("centre", centre)
        if np.any(c != 0.0) and (motion[0] is None or motion[1] is None):
            raise InputError("`centre` off the frame's origin needs `x` and `y` prescribed "
                             "(a body turning about a pivot); with a free translation put the "
                             "frame's origin at the centre of mass")
        rec = dict(kind=K.GUIDED, mass=m, inertia=positive("inertia", inertia), motion=motion,
                   centre=c, pose=(*_vec2("position", position), finite_scalar("angle", angle)),
                   vel=(*_vec2("velocity", velocity),
                        finite_scalar("angular_velocity", angular_velocity)))
        return self._add(rec, name)

    def add_fixed(self, position=(0.0, 0.0), angle=0.0, name=None):
        """A body that does not move (a frame, a wall)."""
        return self._add(dict(kind=K.FIXED, pose=(*_vec2("position", position),
                                                  finite_scalar("angle", angle))), name)

    def add_driven(self, x=0.0, y=0.0, theta=0.0, name=None):
        """A body moved as prescribed: ``x``, ``y`` [m], ``theta`` [rad], each a number or a :class:`TimeFunction`."""
        return self._add(dict(kind=K.DRIVEN, motion=(TimeFunction.of("x", x),
                                                     TimeFunction.of("y", y),
                                                     TimeFunction.of("theta", theta))), name)

    # -- shapes and contacts ---------------------------------------------------------------
    def add_shape(self, body, shape):
        """Attach ``shape`` (:class:`Point`, :class:`Circle`, :class:`Segment`, :class:`Polygon`, :class:`HalfPlane`) to ``body``."""
        self._body("body", body)
        if not isinstance(shape, (Point, Circle, Segment, Polygon, HalfPlane)):
            raise InputError(f"`shape` must be a Point, Circle, Segment, Polygon or HalfPlane, "
                             f"got {type(shape).__name__}")
        ref = _ShapeRef(body, shape, len(self.shapes))
        self.shapes.append(ref)
        return ref

    def add_contact(self, a, b, mu=0.0, restitution=0.0, vertices=None):
        """Unilateral contacts between shapes ``a`` and ``b``; returns the new contacts' indices.

        The candidate pairs are fixed here, each one contact row:

        * a circle or a point against any shape: one contact (centre to the
          nearest feature of the other);
        * a polygon or segment against a half-plane: one contact per vertex
          (``vertices`` selects some, by index);
        * a polygon or segment against a polygon or segment: each vertex of
          ``a`` against ``b`` (its nearest feature), then, without
          ``vertices``, each vertex of ``b`` against ``a``.

        ``mu`` (Coulomb) and ``restitution`` (Newton) hold for every contact of the pair.
        """
        for name, s in (("a", a), ("b", b)):
            if not isinstance(s, _ShapeRef) or s.body.model is not self:
                raise InputError(f"`{name}` must be a shape added to this model")
        if a.body is b.body:
            raise InputError("`a` and `b` are shapes of one body: a body does not touch itself")
        if not self._movable(a.body) and not self._movable(b.body):
            raise InputError("`a` and `b` are both on fixed or driven bodies: one must be free")
        mu = nonnegative("mu", mu)
        e = in_closed_interval("restitution", restitution, 0.0, 1.0)
        sa, sb = a.shape, b.shape
        pts = (Point, Circle)
        poly = (Segment, Polygon)
        if isinstance(sa, HalfPlane) or (isinstance(sb, pts) and not isinstance(sa, pts)):
            a, b, sa, sb = b, a, sb, sa
        if isinstance(sa, HalfPlane):
            raise InputError("two half-planes do not make a contact")
        if isinstance(sa, Point) and isinstance(sb, Point):
            raise InputError("two points do not make a contact (no normal): give one a radius")
        rows = []
        if isinstance(sa, pts):
            rA, rho = (sa.at, 0.0) if isinstance(sa, Point) else (sa.centre, sa.radius)
            if vertices is not None:
                raise InputError("`vertices` selects vertices of a polygon or segment; "
                                 f"{type(sa).__name__} has none")
            rows.append(self._target(a.body, rA, rho, b))
        else:
            nv = len(sa.vertices)
            sel = range(nv) if vertices is None else tuple(vertices)
            for k in sel:
                if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < nv:
                    raise InputError(f"`vertices` must be indices in [0, {nv}), got {k!r}")
                rows.append(self._target(a.body, sa.vertices[k], 0.0, b))
            if isinstance(sb, poly) and vertices is None:
                for k in range(len(sb.vertices)):
                    rows.append(self._target(b.body, sb.vertices[k], 0.0, a))
        first = len(self.contacts)
        for r in rows:
            r.update(mu=mu, restitution=e)
            self.contacts.append(r)
        return list(range(first, len(self.contacts)))

    def _target(self, body_a, rA, rho, b):
        s = b.shape
        rec = dict(A=body_a.index, B=b.body.index, rA=np.asarray(rA, float), rho=rho, shape=s)
        if isinstance(s, HalfPlane):
            rec.update(kind=K.PLANE, p=(*s.point, *s.normal))
        elif isinstance(s, (Point, Circle)):
            rB, rhoB = (s.at, 0.0) if isinstance(s, Point) else (s.centre, s.radius)
            rec.update(kind=K.POINTS, p=(*rB, rhoB))
        else:
            rec.update(kind=K.POLY, vertices=s.vertices)
        return rec

    def add_clearance_revolute(self, body_i, point_i, body_j, point_j, hole_radius, pin_radius,
                               mu=0.0, restitution=0.0):
        """A revolute joint with clearance: a pin of ``body_j`` in a hole of ``body_i``; returns its contact's index.

        The hole (radius ``hole_radius`` [m]) is centred at ``point_i`` of
        ``body_i``, the pin (radius ``pin_radius``) at ``point_j`` of
        ``body_j`` (body frames). It is one unilateral contact, not a joint
        row: with ``d`` the pin's centre less the hole's and ``c =
        hole_radius - pin_radius``, the gap is ``c - |d|`` and the normal
        ``-d / |d|`` (kinematics in :mod:`moreau.model.planar`), with
        Coulomb friction ``mu`` and Newton restitution ``restitution``
        between the pin and the wall. Where ``d = 0`` its direction is not
        defined: ``body_i``'s ``x`` axis stands for it (the gap is then ``c``,
        the contact open). The pin must start inside the hole.
        """
        bi, bj = self._joint_bodies(body_i, body_j)
        ri, rj = _vec2("point_i", point_i), _vec2("point_j", point_j)
        Rh = positive("hole_radius", hole_radius)
        Rp = nonnegative("pin_radius", pin_radius)
        if not Rp < Rh:
            raise InputError(f"`pin_radius` ({Rp!r}) must be less than `hole_radius` ({Rh!r}): "
                             "the clearance is their difference")
        gap = Rh - Rp - float(np.hypot(*(self._initial_point(bj, rj)
                                         - self._initial_point(bi, ri))))
        if gap < -1e-12 * Rh:
            raise InputError(f"the pin of {bj.name!r} starts {-gap:.6g} m beyond the clearance "
                             f"{Rh - Rp:.6g} m of the hole of {bi.name!r}: place `point_j` "
                             "within the clearance of `point_i`")
        mu = nonnegative("mu", mu)
        e = in_closed_interval("restitution", restitution, 0.0, 1.0)
        self.contacts.append(dict(kind=K.HOLE, A=bj.index, B=bi.index, rA=rj, rho=Rp,
                                  p=(*ri, Rh), shape=None, mu=mu, restitution=e))
        return len(self.contacts) - 1

    def add_clearance_prismatic(self, body_i, point_i, axis, body_j, point_j, half_width,
                                pin_radius, mu=0.0, restitution=0.0):
        """A prismatic joint with clearance: a pin of ``body_j`` in a slot of ``body_i``; returns its two contacts' indices.

        The slot of ``body_i`` runs along ``axis`` (its frame) through
        ``point_i``, its walls ``half_width`` [m] either side; the pin
        (radius ``pin_radius``) is centred at ``point_j`` of ``body_j``. Two
        unilateral contacts, each the pin against one wall (a point against a
        line, kinematics in :mod:`moreau.model.planar`): with ``n0`` the unit
        normal to the axis and ``s = n0 . (P_j - Q_i)`` the pin's offset
        from the slot's centre line, the gaps ``half_width - pin_radius + s``
        (the wall on the ``-n0`` side, its normal ``n0``) and
        ``half_width - pin_radius - s``. The slot is unbounded along its axis
        and the pin turns freely in it. The pin must start inside the slot.
        """
        bi, bj = self._joint_bodies(body_i, body_j)
        ri, rj = _vec2("point_i", point_i), _vec2("point_j", point_j)
        u = _vec2("axis", axis)
        ln = float(np.hypot(*u))
        if ln == 0.0:
            raise InputError("`axis` of a prismatic joint must not be zero")
        W = positive("half_width", half_width)
        Rp = nonnegative("pin_radius", pin_radius)
        if not Rp < W:
            raise InputError(f"`pin_radius` ({Rp!r}) must be less than `half_width` ({W!r}): "
                             "the clearance is their difference")
        mu = nonnegative("mu", mu)
        e = in_closed_interval("restitution", restitution, 0.0, 1.0)
        n0 = np.array([-u[1], u[0]]) / ln
        # the pin's offset from the centre line, in body i's frame, at the initial poses
        xi, yi, thi = self._initial_pose(bi)
        c, s = math.cos(thi), math.sin(thi)
        rel = self._initial_point(bj, rj) - self._initial_point(bi, ri)
        off = float(n0 @ np.array([c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1]]))
        if abs(off) > W - Rp + 1e-12 * W:
            raise InputError(f"the pin of {bj.name!r} starts {abs(off):.6g} m off the slot's "
                             f"centre line, beyond the clearance {W - Rp:.6g} m of the slot of "
                             f"{bi.name!r}: place `point_j` within the slot")
        first = len(self.contacts)
        for sign in (1.0, -1.0):
            wall = ri - sign * W * n0
            self.contacts.append(dict(kind=K.PLANE, A=bj.index, B=bi.index, rA=rj, rho=Rp,
                                      p=(*wall, *(sign * n0)), shape=None, mu=mu,
                                      restitution=e))
        return [first, first + 1]

    # -- forces ------------------------------------------------------------------------------
    def add_spring(self, body_i, point_i, body_j, point_j, stiffness, rest_length=None,
                   damping=0.0):
        """A linear spring and dashpot between ``point_i`` of ``body_i`` and ``point_j`` of ``body_j`` (body frames).

        Tension ``stiffness (l - rest_length) + damping l'`` [N], ``l`` the
        distance between the points; ``rest_length`` defaults to the initial one.
        """
        bi, bj = self._body("body_i", body_i), self._body("body_j", body_j)
        if bi is bj:
            raise InputError("`body_i` and `body_j` are one body: a spring joins two bodies")
        rec = dict(kind=K.SPRING, i=bi.index, j=bj.index, ri=_vec2("point_i", point_i),
                   rj=_vec2("point_j", point_j), k=nonnegative("stiffness", stiffness),
                   c=nonnegative("damping", damping),
                   l0=None if rest_length is None else nonnegative("rest_length", rest_length))
        if rec["l0"] is None:
            pi, pj = (self._initial_point(b, r) for b, r in ((bi, rec["ri"]), (bj, rec["rj"])))
            rec["l0"] = float(np.hypot(*(pi - pj)))
        if rec["l0"] == 0.0 and rec["k"] > 0.0:
            raise InputError("`rest_length` must be > 0: a spring of zero length has no direction")
        self.forces.append(rec)

    def add_axial_spring(self, body_i, point_i, body_j, point_j, axis, stiffness,
                         rest_length=None, damping=0.0):
        """A linear spring and dashpot acting along the fixed world direction ``axis`` between two body points.

        Its length is ``l = e . (P_i - P_j)`` with ``e`` the unit ``axis``
        (a spring held in a guide, a suspension): tension ``stiffness (l -
        rest_length) + damping l'`` [N], the force ``-tension e`` on
        ``point_i`` of ``body_i`` and its opposite on ``point_j`` of
        ``body_j`` (body frames). ``rest_length`` [m] defaults to the initial
        ``l`` and may be negative.
        """
        bi, bj = self._body("body_i", body_i), self._body("body_j", body_j)
        if bi is bj:
            raise InputError("`body_i` and `body_j` are one body: a spring joins two bodies")
        u = _vec2("axis", axis)
        ln = float(np.hypot(*u))
        if ln == 0.0:
            raise InputError("`axis` of a spring must not be zero")
        rec = dict(kind=K.AXIAL, i=bi.index, j=bj.index, ri=_vec2("point_i", point_i),
                   rj=_vec2("point_j", point_j), k=nonnegative("stiffness", stiffness),
                   c=nonnegative("damping", damping), axis=u / ln,
                   l0=None if rest_length is None else finite_scalar("rest_length", rest_length))
        if rec["l0"] is None:
            pi, pj = (self._initial_point(b, r) for b, r in ((bi, rec["ri"]), (bj, rec["rj"])))
            rec["l0"] = float(rec["axis"] @ (pi - pj))
        self.forces.append(rec)

    def add_damper(self, body_i, point_i, body_j, point_j, damping):
        """A linear dashpot between two body points (a spring of zero stiffness)."""
        self.add_spring(body_i, point_i, body_j, point_j, 0.0, rest_length=None,
                        damping=damping)

    def add_torsion_spring(self, body_i, body_j, stiffness, rest_angle=None, damping=0.0):
        """Torque ``-stiffness (theta_i - theta_j - rest_angle) - damping (w_i - w_j)`` on ``body_i``, its opposite on ``body_j``."""
        bi, bj = self._body("body_i", body_i), self._body("body_j", body_j)
        if bi is bj:
            raise InputError("`body_i` and `body_j` are one body: a torsion spring joins two")
        if rest_angle is None:
            rest_angle = self._initial_pose(bi)[2] - self._initial_pose(bj)[2]
        self.forces.append(dict(kind=K.TORSION, i=bi.index, j=bj.index,
                                k=nonnegative("stiffness", stiffness),
                                th0=finite_scalar("rest_angle", rest_angle),
                                c=nonnegative("damping", damping)))

    def add_force(self, body, force, point=(0.0, 0.0)):
        """A given force ``(fx, fy)`` [N] (world frame; numbers or :class:`TimeFunction`) at ``point`` of ``body``."""
        b = self._free("body", body)
        if len(force) != 2:
            raise InputError("`force` must be a pair (fx, fy)")
        self.forces.append(dict(kind=K.FORCE, i=b.index, r=_vec2("point", point),
                                f=(TimeFunction.of("force[0]", force[0]),
                                   TimeFunction.of("force[1]", force[1]))))

    def add_torque(self, body, torque):
        """A given torque [N m] (a number or a :class:`TimeFunction`) on ``body``."""
        b = self._free("body", body)
        self.forces.append(dict(kind=K.TORQUE, i=b.index, f=TimeFunction.of("torque", torque)))

    # -- joints (their rows; the solution waits for the mixed LCP) ------------------------
    def _joint_bodies(self, body_i, body_j):
        bi, bj = self._body("body_i", body_i), self._body("body_j", body_j)
        if bi is bj:
            raise InputError("`body_i` and `body_j` are one body: a joint joins two bodies")
        for nm, b in (("body_i", bi), ("body_j", bj)):
            if b.kind == K.GUIDED:
                raise InputError(f"`{nm}` is a guided body: its prescribed coordinates are its "
                                 "joints; a joint joins free, fixed or driven bodies")
        if bi.kind != K.FREE and bj.kind != K.FREE:
            raise InputError("`body_i` and `body_j` are both fixed or driven: a joint needs a "
                             "free body")
        return bi, bj

    def add_revolute(self, body_i, point_i, body_j, point_j):
        """A pin: ``point_i`` of ``body_i`` stays on ``point_j`` of ``body_j`` (two rows ``P_i - P_j = 0``)."""
        bi, bj = self._joint_bodies(body_i, body_j)
        self.joints.append(dict(kind=K.JPOINT, i=bi.index, j=bj.index,
                                ri=_vec2("point_i", point_i), rj=_vec2("point_j", point_j),
                                joint=self._joint_name("revolute", bi, bj)))

    def add_prismatic(self, body_i, point_i, body_j, point_j, axis):
        """A slider: ``point_i`` of ``body_i`` moves along the line of ``body_j`` through ``point_j`` along ``axis`` (body ``j``'s frame), the relative angle fixed at its initial value.

        Two rows: ``n . (P_i - Q_j) = 0`` with ``n`` normal to the axis, and
        ``theta_i - theta_j - theta_0 = 0``.
        """
        bi, bj = self._joint_bodies(body_i, body_j)
        u = _vec2("axis", axis)
        ln = float(np.hypot(*u))
        if ln == 0.0:
            raise InputError("`axis` of a prismatic joint must not be zero")
        th0 = self._initial_pose(bi)[2] - self._initial_pose(bj)[2]
        self.joints.append(dict(kind=K.JLINE, i=bi.index, j=bj.index, ri=_vec2("point_i", point_i),
                                rj=_vec2("point_j", point_j), n0=np.array([u[1], -u[0]]) / ln,
                                joint=self._joint_name("prismatic", bi, bj)))
        self.joints.append(dict(kind=K.JANGLE, i=bi.index, j=bj.index, th0=th0,
                                joint=self.joints[-1]["joint"]))

    def add_weld(self, body_i, body_j):
        """``body_i`` held to ``body_j`` in their initial relative pose (three rows)."""
        bi, bj = self._joint_bodies(body_i, body_j)
        xi, yi, thi = self._initial_pose(bi)
        xj, yj, thj = self._initial_pose(bj)
        c, s = math.cos(thj), math.sin(thj)
        rj = np.array([c * (xi - xj) + s * (yi - yj), -s * (xi - xj) + c * (yi - yj)])
        name = self._joint_name("weld", bi, bj)
        self.joints.append(dict(kind=K.JPOINT, i=bi.index, j=bj.index, ri=np.zeros(2), rj=rj,
                                joint=name))
        self.joints.append(dict(kind=K.JANGLE, i=bi.index, j=bj.index, th0=thi - thj,
                                joint=name))

    def _joint_name(self, kind, bi, bj):
        # the joint's name in messages: its kind, its number among the joints, its bodies
        number = len({j["joint"] for j in self.joints})
        return f"{kind} joint {number} ({bi.name!r}-{bj.name!r})"

    def _check_joints(self):
        """Refuse joints whose rows are dependent at the initial poses, naming them."""
        rows = JointRows(self)
        q0 = self.initial_coordinates()[0]
        W, _ = rows.jacobians(q0, 0.0)
        names = [j["joint"] for j in self.joints
                 for _ in range(2 if j["kind"] == K.JPOINT else 1)]
        # the left null space of W (combinations of rows that vanish), from the SVD of W^T
        U, sv, _ = np.linalg.svd(W, full_matrices=True)
        top = float(sv[0]) if sv.size else 0.0
        rank = int(np.sum(sv > 1e-10 * max(top, 1e-300)))
        if rank == W.shape[0]:
            return
        dependent = set()
        for k in range(rank, W.shape[0]):
            c = U[:, k]
            dependent.update(np.flatnonzero(np.abs(c) > 1e-8 * np.max(np.abs(c))).tolist())
        which = sorted({names[r] for r in dependent})
        raise InputError(f"the joints are redundant: their {W.shape[0]} rows have rank {rank} at "
                         f"the initial poses, rows {sorted(dependent)} depend on each other "
                         f"({'; '.join(which)}); remove the joint that repeats a constraint")

    def joint_rows(self):
        """The bilateral rows of the joints (:class:`JointRows`), in the built scene's units.

        The built scene states the same rows through the scene interface
        (``joint_residuals``, ``joint_jacobians``, ``joint_drift``).
        """
        if not self.joints:
            raise InputError("the model has no joints: add one with `add_revolute`, "
                             "`add_prismatic` or `add_weld`")
        return JointRows(self)

    def _initial_pose(self, body):
        rec = self.bodies[body.index]
        if rec["kind"] == K.DRIVEN:
            return tuple(f(0.0)[0] for f in rec["motion"])
        if rec["kind"] == K.GUIDED:
            return tuple(p if f is None else f(0.0)[0] for f, p in zip(rec["motion"], rec["pose"]))
        return rec["pose"]

    def initial_coordinates(self):
        """``(q0, v0, angles)``: the free coordinates' initial values and rates in scene units, and which are angles."""
        L, _, T = self.units()
        q0, v0, angles = [], [], []
        for b in self.bodies:
            free = (True,) * 3 if b["kind"] == K.FREE else (
                tuple(f is None for f in b["motion"]) if b["kind"] == K.GUIDED else ())
            for j, is_free in enumerate(free):
                if is_free:
                    scale = 1.0 if j == 2 else L
                    if j == 2:
                        angles.append(len(q0))
                    q0.append(b["pose"][j] / scale)
                    v0.append(b["vel"][j] * T / scale)
        return np.array(q0), np.array(v0), tuple(angles)

    def _initial_point(self, body, r):
        x, y, th = self._initial_pose(body)
        c, s = math.cos(th), math.sin(th)
        return np.array([x + c * r[0] - s * r[1], y + s * r[0] + c * r[1]])

    # -- building ------------------------------------------------------------------------------
    def units(self):
        """``(length [m], mass [kg], time [s])`` of the built scene."""
        L, Mu, T = self._units["length"], self._units["mass"], self._units["time"]
        if L is None:
            L = max([s.shape.extent() for s in self.shapes], default=0.0) or 1.0
        if Mu is None:
            Mu = max([b["mass"] for b in self.bodies if b["kind"] in (K.FREE, K.GUIDED)],
                     default=1.0)
        if T is None:
            g = float(np.hypot(*self.gravity))
            T = math.sqrt(L / g) if g > 0.0 else 1.0
        return L, Mu, T

    def pack(self):
        """``(par, ndof)``: the description in the layout of :mod:`moreau.model.planar._kernels`."""
        L, Mu, T = self.units()
        F = Mu * L / T ** 2
        tail = []
        base = [0.0] * K.HEADER

        shared = {}

        def put(values, share=False):
            # the offset the values will have once the tables are laid out; equal time
            # functions share one record (and so the memory of their harmonics)
            values = tuple(float(x) for x in values)
            if share and values in shared:
                return shared[values]
            off = len(tail)
            tail.extend(values)
            if share:
                shared[values] = off
            return off

        brecs, dof = [], 0
        for rec in self.bodies:
            r = [0.0] * K.BREC
            r[0] = rec["kind"]
            if rec["kind"] == K.FREE:
                r[1], r[2], r[3] = dof, rec["mass"] / Mu, rec["inertia"] / (Mu * L * L)
                dof += 3
            elif rec["kind"] == K.FIXED:
                r[1] = -1
            else:
                # the memory of the angle's sine and cosine (the kernels' kept_sincos); a
                # constant angle's are written here once (the generated code reads them)
                th = rec["motion"][2]
                const = th is not None and not th.harmonics and th.rate == 0 and th.accel == 0
                r[1] = ("T", put((th.value, math.sin(th.value), math.cos(th.value)) if const
                                 else K.KEPT_SLOTS))
            if rec["kind"] == K.FIXED:
                th = rec["pose"][2]
                r[4:9] = [rec["pose"][0] / L, rec["pose"][1] / L, th, math.cos(th), math.sin(th)]
            elif rec["kind"] == K.DRIVEN:
                fx, fy, ft = rec["motion"]
                r[7:10] = [("T", put(fx.packed(L, T), share=True)),
                           ("T", put(fy.packed(L, T), share=True)),
                           ("T", put(ft.packed(1.0, T), share=True))]
            elif rec["kind"] == K.GUIDED:
                cx, cy = rec["centre"]
                r[2] = rec["mass"] / Mu
                r[3] = (rec["inertia"] + rec["mass"] * (cx * cx + cy * cy)) / (Mu * L * L)
                for j, f in enumerate(rec["motion"]):
                    if f is None:
                        r[4 + j] = dof
                        dof += 1
                    else:
                        r[4 + j] = ("N", put(f.packed(1.0 if j == 2 else L, T), share=True))
                r[7:9] = [cx / L, cy / L]
            brecs.append(r)
        crecs = []
        for rec in self.contacts:
            r = [0.0] * K.CREC
            r[0:6] = [rec["kind"], rec["A"], rec["B"], rec["rA"][0] / L, rec["rA"][1] / L,
                      rec["rho"] / L]
            if rec["kind"] == K.PLANE:
                px, py, nx, ny = rec["p"]
                r[6:10] = [px / L, py / L, nx, ny]
            elif rec["kind"] in (K.POINTS, K.HOLE):
                r[6:9] = [rec["p"][0] / L, rec["p"][1] / L, rec["p"][2] / L]
            else:
                r[6] = len(rec["vertices"])
                r[7] = ("T", put((rec["vertices"] / L).ravel()))
            crecs.append(r)
        frecs = []
        for rec in self.forces:
            r = [0.0] * K.FREC
            r[0] = rec["kind"]
            if rec["kind"] in (K.SPRING, K.AXIAL):
                r[1:10] = [rec["i"], rec["j"], rec["ri"][0] / L, rec["ri"][1] / L,
                           rec["rj"][0] / L, rec["rj"][1] / L, rec["k"] * L / F,
                           rec["l0"] / L, rec["c"] * L / (F * T)]
                if rec["kind"] == K.AXIAL:
                    r[10:12] = [rec["axis"][0], rec["axis"][1]]
            elif rec["kind"] == K.TORSION:
                r[1:6] = [rec["i"], rec["j"], rec["k"] / (F * L), rec["th0"],
                          rec["c"] / (F * L * T)]
            elif rec["kind"] == K.FORCE:
                r[1:6] = [rec["i"], rec["r"][0] / L, rec["r"][1] / L,
                          ("T", put(rec["f"][0].packed(F, T), share=True)),
                          ("T", put(rec["f"][1].packed(F, T), share=True))]
            else:
                r[1:3] = [rec["i"], ("T", put(rec["f"].packed(F * L, T), share=True))]
            frecs.append(r)
        jrecs = []
        for rec in self.joints:
            r = [0.0] * K.JREC
            r[0:3] = [rec["kind"], rec["i"], rec["j"]]
            if rec["kind"] != K.JANGLE:
                r[3:7] = [rec["ri"][0] / L, rec["ri"][1] / L, rec["rj"][0] / L, rec["rj"][1] / L]
            if rec["kind"] == K.JLINE:
                r[7:9] = [rec["n0"][0], rec["n0"][1]]
            if rec["kind"] == K.JANGLE:
                r[9] = rec["th0"]
            jrecs.append(r)
        ob = K.HEADER
        oc = ob + K.BREC * len(brecs)
        of = oc + K.CREC * len(crecs)
        oj = of + K.FREC * len(frecs)
        ot = oj + K.JREC * len(jrecs)
        g = self.gravity * T * T / L
        base[:] = [len(brecs), len(crecs), len(frecs), ob, oc, of, dof, g[0], g[1],
                   len(jrecs), oj]
        par = base + [x for r in brecs + crecs + frecs + jrecs for x in r]
        # "T": an offset into the tail; "N": a guided body's prescribed coordinate, -1 - offset
        par = [(ot + x[1] if x[0] == "T" else -1 - (ot + x[1])) if isinstance(x, tuple) else x
               for x in par] + tail
        return np.array(par, dtype=float), dof

    def build(self, name="planar-model", valid_region=None, inside=None, default_window=None):
        """The scene of this model (:class:`PlanarScene`).

        Parameters
        ----------
        name : str
        valid_region : str, optional
            The states the model is meant for, in words.
        inside : callable, optional
            ``inside(t, q, v) -> bool array`` over rows of scene-unit states,
            the test of ``valid_region``.
        default_window : float, optional
            A run's natural length in the scene's time.
        """
        if not any(self._movable(b["body"]) for b in self.bodies):
            raise InputError("the model has no free body: add one with `add_body`")
        if self.joints:
            self._check_joints()
        if (valid_region is None) != (inside is None):
            raise InputError("`valid_region` and `inside` go together: the words and the test")
        return PlanarScene(self, name, valid_region, inside, default_window)


class _GeneratedFunctions:
    """Holds ``_fn``, the functions of the module generated for ``par``, and pickles without it.

    The generated module is found again from ``par``: a worker process
    imports it, or compiles it, where the object is unpickled.
    """

    def __getstate__(self):
        state = dict(self.__dict__)
        del state["_fn"]
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._fn = _codegen.compiled_functions(self.par)


class PlanarScene(_GeneratedFunctions, SIUnits, Scene):
    """A scene built by :class:`Model`: its Python methods run its compiled model's functions.

    Built by :meth:`Model.build`, not directly.
    """

    def __init__(self, model, name, valid_region, inside, default_window):
        self.name = str(name)
        self.description = model
        self.par, self.ndof = model.pack()
        L, Mu, T = model.units()
        self.length, self.time, self.force = L, T, Mu * L / T ** 2
        self.mu = np.array([c["mu"] for c in model.contacts], dtype=float)
        self.restitution = np.array([c["restitution"] for c in model.contacts], dtype=float)
        q0, v0, self.angle_coordinates = model.initial_coordinates()
        self.valid_region = valid_region
        self._inside = inside
        self.default_window = default_window
        self._has_jac = len(model.forces) > 0 or any(b["kind"] == K.GUIDED
                                                     for b in model.bodies)
        self._q0, self._v0 = q0, v0
        self._fn = _codegen.compiled_functions(self.par)
        self._joints = JointRows(model) if model.joints else None
        self.n_joint_rows = 0 if self._joints is None else self._joints.nrows

    def _qscale(self):
        s = np.full(self.ndof, self.length)
        s[list(self.angle_coordinates)] = 1.0
        return s

    def _qv(self, q, v=None):
        q = np.ascontiguousarray(q, dtype=float).reshape(self.ndof)
        if v is None:
            return q
        return q, np.ascontiguousarray(v, dtype=float).reshape(self.ndof)

    # -- Scene interface: the compiled functions -----------------------------------------------
    def mass(self, q):
        M = np.zeros((self.ndof, self.ndof))
        self._fn.mass(self.par, self._qv(q), M)
        return M

    def _forces(self, q, v, t, jac):
        n = self.ndof
        D = np.zeros((n, 1 + 2 * n))
        q, v = self._qv(q, v)
        self._fn.forces(self.par, q, v, float(t), D, jac)
        return D

    def forces(self, q, v, t):
        return self._forces(q, v, t, False)[:, 0]

    def force_jacobians(self, q, v, t):
        n = self.ndof
        D = self._forces(q, v, t, True)
        return D[:, 1:1 + n].copy(), D[:, 1 + n:].copy()

    def _contacts(self, q, t, need_T):
        G = np.zeros((max(self.ncontacts, 1), 3 + 2 * self.ndof))
        self._fn.contacts(self.par, self._qv(q), float(t), G, True, need_T)
        return G[:self.ncontacts]

    def gaps(self, q, t):
        return self._contacts(q, t, False)[:, 0].copy()

    def contact_jacobians(self, q, t):
        n = self.ndof
        G = self._contacts(q, t, True)
        fr = self.frictional_index
        return (G[:, 3:3 + n].copy(), G[:, 1].copy(), G[fr, 3 + n:].copy(), G[fr, 2].copy())

    def contact_drift(self, q, v, t):
        Dr = np.zeros((max(self.ncontacts, 1), 2))
        q, v = self._qv(q, v)
        self._fn.drift(self.par, q, v, float(t), Dr)
        Dr = Dr[:self.ncontacts]
        return Dr[:, 0].copy(), Dr[self.frictional_index, 1].copy()

    def joint_residuals(self, q, t):
        if self._joints is None:
            return np.zeros(0)
        return self._joints.values(self._qv(q), t)

    def joint_jacobians(self, q, t):
        if self._joints is None:
            return np.zeros((0, self.ndof)), np.zeros(0)
        return self._joints.jacobians(self._qv(q), t)

    def joint_drift(self, q, v, t):
        if self._joints is None:
            return np.zeros(0)
        return self._joints.drift(*self._qv(q, v), t)

    def compiled_model(self):
        """The compiled model: the functions generated for this model's structure, with its ``par``.

        It holds no joint rows (:meth:`compiled_joints` gives them): Moreau–Jean
        runs a model with joints in its own compiled loop, the other schemes
        take their generic step.
        """
        f = self._fn
        return CompiledModel(f.mass, f.forces, f.contacts, f.drift, self.par, self.ndof,
                             self.ncontacts, True, self._has_jac, gaps=f.gaps)

    def compiled_joints(self):
        """The generated ``joints(par, q, t, G, need_gap)`` of the joint rows (the rows of
        :class:`JointRows`, with :meth:`compiled_model`'s ``par``), or None without joints.

        Moreau–Jean's compiled loop for joints reads it
        (:mod:`moreau.integrators._mj_joint_kernels`).
        """
        return None if self._joints is None else self._fn.joints

    def poses(self, q, t):
        """``(x, y, theta)`` of every body (the ground first), scene units, shape (bodies, 3)."""
        P = np.zeros((len(self.description.bodies), 3))
        q = self._qv(q)
        self._fn.poses(self.par, q, q, float(t), P)
        return P

    def contact_frames(self, q, t):
        """Per contact: body A's contact point (world), the normal, and the contact point's
        offsets ``s_A``, ``s_B`` from the centres of mass of A and B; shape (ncontacts, 8)."""
        F = np.zeros((max(self.ncontacts, 1), 8))
        q = self._qv(q)
        self._fn.frames(self.par, q, q, float(t), F)
        return F[:self.ncontacts]

    def initial_state(self):
        """The bodies' initial poses and velocities, in the order added (scene units)."""
        return self._q0.copy(), self._v0.copy()

    def inside_valid_region(self, t, q, v):
        if self._inside is None:
            return np.ones(np.shape(t), dtype=bool)
        return np.asarray(self._inside(np.asarray(t), np.asarray(q), np.asarray(v)), dtype=bool)

    # -- drawing -----------------------------------------------------------------------------
    def shapes(self, q, t=0.0):
        """Every shape at SI coordinates ``q`` and time ``t`` [s], and the contacts' points and normals."""
        q = np.asarray(q, dtype=float) / self._qscale()
        tt = float(t) / self.time
        L = self.length
        out = []
        poses = [(x * L, y * L, th) for x, y, th in self.poses(q, tt)]
        for ref in self.description.shapes:
            x, y, th = poses[ref.body.index]
            c, s = math.cos(th), math.sin(th)

            def world(p, x=x, y=y, c=c, s=s):
                return (x + c * p[0] - s * p[1], y + s * p[0] + c * p[1])

            role = "body" if self.description._movable(ref.body) else "ground"
            sh = ref.shape
            if isinstance(sh, Circle):
                out.append(circle(world(sh.centre), sh.radius, role))
            elif isinstance(sh, Polygon):
                out.append(polygon([world(p) for p in sh.vertices], role))
            elif isinstance(sh, Segment):
                out.append(line([world(p) for p in sh.vertices], role))
            elif isinstance(sh, HalfPlane):
                d = np.array([sh.normal[1], -sh.normal[0]]) * 10.0 * L
                out.append(line([world(sh.point - d), world(sh.point + d)], "ground"))
        for i, fr in enumerate(self.contact_frames(q, tt)):
            out.append(contact(i, (fr[0] * L, fr[1] * L), (fr[2], fr[3])))
        return out


class JointRows(_GeneratedFunctions):
    """The bilateral rows of a model's joints: ``g(q, t) = 0``, their Jacobian and drift terms.

    Rows in the order the joints were added (a revolute joint two, a
    prismatic joint two, a weld three)::

        dg/dt     = W v + w
        d2g/dt2   = W a + wbar

    in the scene units of :meth:`Model.build`'s scene (the same ``q`` and
    ``v``), from the generated functions ``joints`` and ``joint_drift``.
    """

    def __init__(self, model):
        self.par, self.ndof = model.pack()
        self.nrows = sum(2 if j["kind"] == K.JPOINT else 1 for j in model.joints)
        self._fn = _codegen.compiled_functions(self.par)

    def _G(self, q, t):
        q = np.ascontiguousarray(q, dtype=float).reshape(self.ndof)
        G = np.zeros((self.nrows, 3 + 2 * self.ndof))
        self._fn.joints(self.par, q, float(t), G, True)
        return G

    def values(self, q, t):
        """``g(q, t)``, shape (nrows,)."""
        return self._G(q, t)[:, 0].copy()

    def jacobians(self, q, t):
        """``(W, w)``: shapes (nrows, ndof) and (nrows,)."""
        G = self._G(q, t)
        return G[:, 3:3 + self.ndof].copy(), G[:, 1].copy()

    def drift(self, q, v, t):
        """``wbar``, shape (nrows,)."""
        Dr = np.zeros((self.nrows, 2))
        self._fn.joint_drift(self.par, np.ascontiguousarray(q, dtype=float),
                             np.ascontiguousarray(v, dtype=float), float(t), Dr)
        return Dr[:, 0].copy()
