"""Scalar pieces of the planar models' compiled functions, shared by every generated model.

The generated functions (:mod:`moreau.model.planar._codegen`) read the
bodies' states and the parameters from ``q``, ``v`` and ``par`` themselves
and call these functions with scalars (and tuples of scalars) only: a call
that passes arrays costs the caller reference counting on every call, a
call with scalars is inlined by LLVM. These functions are not cached on
disk on their own: a function loaded from numba's cache is linked as
object code, which its callers cannot inline; the generated functions are
cached with these inlined in them (and the generated module's name digests
this file, so an edit here never runs stale code). The formulas are derived in
:mod:`moreau.model.planar`.

Layout of ``par`` (integers stored as floats)
---------------------------------------------
``par[0:11]`` header: number of bodies, contacts, force records; offsets of
the body, contact and force tables; ``ndof``; gravity ``(gx, gy)``; number
and offset of the joint records.

Body record (``BREC`` floats): ``kind`` (0 fixed, 1 free, 2 driven, 3
guided), first coordinate index (free bodies), mass, inertia, then a fixed
body's pose ``(x, y, theta)`` with ``cos theta, sin theta``, or the offsets
of a driven body's three time functions. A guided body (some coordinates
free, the others prescribed) keeps its inertia about its frame's origin,
then per coordinate ``x, y, theta`` one code: its coordinate index where it
is free, ``-1 - offset`` of its time function where it is prescribed; then
its centre of mass ``(cx, cy)`` in its frame. A driven or guided body's
second entry is the offset of the memory of its angle's sine and cosine
(:func:`kept_sincos`).

Time function at offset ``o``: ``c0, c1, c2, nh, (A, w, phi, x, sin x, cos x) *
nh``, the value ``c0 + c1 t + c2 t^2 / 2 + sum A sin(w t + phi)``; each harmonic
keeps the last argument ``x`` of its sine and cosine with their values
(:func:`kept_sincos`).

Contact record (``CREC`` floats): ``kind``, body ``A``, body ``B``, the point
``rA`` of ``A`` (body frame) and its radius ``rhoA``, then by kind:
``PLANE`` a line of ``B`` (point ``p0``, unit normal ``n0``, body frame);
``POINTS`` a point ``rB`` of ``B`` with radius ``rhoB``; ``POLY`` a convex
polygon of ``B`` (``nv`` counter-clockwise vertices at an offset; two
vertices: a segment, two-sided); ``HOLE`` a hole of ``B`` (centre ``h``,
radius ``rhoB``) around the pin ``rA`` of radius ``rhoA`` (a revolute joint
with clearance).

Force record (``FREC`` floats): ``SPRING`` (bodies ``i, j``, points
``ri, rj``, stiffness, rest length, damping), ``AXIAL`` (the same, then the
world direction ``(ex, ey)`` its length is measured along), ``TORSION`` (bodies ``i, j``,
stiffness, rest angle, damping), ``FORCE`` (body, point, offsets of the time
functions of the world components), ``TORQUE`` (body, offset of its time
function).

Joint record (``JREC`` floats): ``kind``, bodies ``i, j``, points ``ri, rj``
(body frames), the unit normal ``n0`` of a slot (body ``j``'s frame), the
rest angle: ``JPOINT`` (two rows, ``P_i - P_j = 0``), ``JLINE`` (one row,
``n . (P_i - Q_j) = 0``), ``JANGLE`` (one row, ``theta_i - theta_j - th0 = 0``).
"""

import math

from numba import njit

# a driven angle's or a harmonic's sine and cosine, kept in ``par`` (the drives' kernel)
from ...compiled import memo_sincos as kept_sincos

HEADER = 11
JREC = 10
BREC = 10
CREC = 14
FREC = 12

#: floats of a harmonic of a time function: A, w, phi and the memory of its sine and cosine
HREC = 6
#: what a memory of :func:`kept_sincos` starts at: an argument with its sine and cosine
KEPT_SLOTS = (0.0, 0.0, 1.0)

FIXED, FREE, DRIVEN, GUIDED = 0, 1, 2, 3
PLANE, POINTS, POLY = 0, 1, 2
SPRING, TORSION, FORCE, TORQUE, AXIAL = 0, 1, 2, 3, 4
JPOINT, JLINE, JANGLE = 0, 1, 2


@njit
def poly_part(c0, c1, c2, t):
    """``(f, f', f'')`` of ``c0 + c1 t + c2 t^2 / 2``."""
    return c0 + t * (c1 + 0.5 * c2 * t), c1 + c2 * t, c2


@njit
def harmonic_part(f, d1, d2, A, w, ph, t):
    """``(f, f', f'')`` plus those of ``A sin(w t + ph)``."""
    s = math.sin(w * t + ph)
    c = math.cos(w * t + ph)
    return f + A * s, d1 + A * w * c, d2 - A * w * w * s


#: the phase that makes a harmonic a cosine, evaluated as one (``sin(w t + pi/2)`` would
#: round ``pi/2``: its rate at ``t = 0`` would be ``A w 6e-17``, not 0)
QUARTER = 0.5 * math.pi


@njit
def kept_harmonic(par, a, f, d1, d2, t):
    """``(f, f', f'')`` plus those of the harmonic at ``par[a:a + 6]`` (``A, w, phi`` and its memory).

    A phase of :data:`QUARTER` is the cosine ``A cos(w t)``.
    """
    A = par[a]
    w = par[a + 1]
    ph = par[a + 2]
    if ph == QUARTER:
        s, c = kept_sincos(par, a + 3, w * t)
        return f + A * c, d1 - A * w * s, d2 - A * w * w * c
    s, c = kept_sincos(par, a + 3, w * t + ph)
    return f + A * s, d1 + A * w * c, d2 - A * w * w * s


@njit
def turn(c, s, x, y):
    """``R(theta) (x, y)`` with ``c, s = cos, sin theta``."""
    return c * x - s * y, s * x + c * y


@njit
def frame_plane(xA, yA, cA, snA, rx, ry, rhoA, xB, yB, cB, snB, p0x, p0y, n0x, n0y):
    """A point of ``A`` (radius ``rhoA``) against the line of ``B`` through ``p0`` with normal ``n0``.

    Returns ``(g, nx, ny, sAx, sAy, sBx, sBy, rAx, rAy, ux, uy)``: the gap, the
    normal (from ``B`` to ``A``), the contact point's offsets from each centre
    of mass, ``r'_A`` and ``u = P_A - X_B``.
    """
    rAx, rAy = turn(cA, snA, rx, ry)
    nx, ny = turn(cB, snB, n0x, n0y)
    Qx, Qy = turn(cB, snB, p0x, p0y)
    ux = xA + rAx - xB
    uy = yA + rAy - yB
    g = nx * (ux - Qx) + ny * (uy - Qy) - rhoA
    return (g, nx, ny, rAx - rhoA * nx, rAy - rhoA * ny, ux - rhoA * nx, uy - rhoA * ny,
            rAx, rAy, ux, uy)


@njit
def frame_points(xA, yA, cA, snA, rx, ry, rhoA, xB, yB, cB, snB, qx, qy, rhoB):
    """A point of ``A`` (radius ``rhoA``) against a point ``(qx, qy)`` of ``B`` (radius ``rhoB``).

    Returns ``(g, nx, ny, sAx, sAy, sBx, sBy, rAx, rAy, rBx, rBy, L)`` with
    ``L`` the distance between the points.
    """
    rAx, rAy = turn(cA, snA, rx, ry)
    rBx, rBy = turn(cB, snB, qx, qy)
    dx = xA + rAx - xB - rBx
    dy = yA + rAy - yB - rBy
    L = math.sqrt(dx * dx + dy * dy)
    nx = dx / L
    ny = dy / L
    return (L - rhoA - rhoB, nx, ny, rAx - rhoA * nx, rAy - rhoA * ny, rBx + rhoB * nx,
            rBy + rhoB * ny, rAx, rAy, rBx, rBy, L)


@njit
def closest_feature(verts, lx, ly):
    """The feature of a convex polygon (``verts`` = ``(x0, y0, x1, y1, ...)``, body frame) nearest to ``(lx, ly)``.

    Returns ``(is_face, ax, ay, nx, ny)``: a face (the line through
    ``(ax, ay)`` with outward unit normal ``(nx, ny)``) or a vertex ``(ax, ay)``.
    Two vertices are a segment, its normal turned towards the point. Inside
    the polygon, the face of least penetration.
    """
    nv = len(verts) // 2
    if nv == 2:
        x0, y0 = verts[0], verts[1]
        ex, ey = verts[2] - x0, verts[3] - y0
        L2 = ex * ex + ey * ey
        lam = ((lx - x0) * ex + (ly - y0) * ey) / L2
        if lam < 0.0:
            return False, x0, y0, 0.0, 0.0
        if lam > 1.0:
            return False, verts[2], verts[3], 0.0, 0.0
        L = math.sqrt(L2)
        nx, ny = ey / L, -ex / L
        if nx * (lx - x0) + ny * (ly - y0) < 0.0:
            nx, ny = -nx, -ny
        return True, x0, y0, nx, ny
    best = -1.0e300
    kb = 0
    for k in range(nv):
        x0, y0 = verts[2 * k], verts[2 * k + 1]
        k1 = (k + 1) % nv
        ex, ey = verts[2 * k1] - x0, verts[2 * k1 + 1] - y0
        L = math.sqrt(ex * ex + ey * ey)
        s = (ey * (lx - x0) - ex * (ly - y0)) / L
        if s > best:
            best = s
            kb = k
        if s > 0.0:
            lam = ((lx - x0) * ex + (ly - y0) * ey) / (L * L)
            if 0.0 <= lam <= 1.0:
                return True, x0, y0, ey / L, -ex / L
    if best <= 0.0:
        x0, y0 = verts[2 * kb], verts[2 * kb + 1]
        k1 = (kb + 1) % nv
        ex, ey = verts[2 * k1] - x0, verts[2 * k1 + 1] - y0
        L = math.sqrt(ex * ex + ey * ey)
        return True, x0, y0, ey / L, -ex / L
    dmin = 1.0e300
    for k in range(nv):
        dx, dy = lx - verts[2 * k], ly - verts[2 * k + 1]
        d2 = dx * dx + dy * dy
        if d2 < dmin:
            dmin = d2
            kb = k
    return False, verts[2 * kb], verts[2 * kb + 1], 0.0, 0.0


@njit
def frame_poly(xA, yA, cA, snA, rx, ry, rhoA, xB, yB, cB, snB, verts):
    """A point of ``A`` against the nearest feature of a polygon of ``B``.

    Returns the point-on-line tuple of :func:`frame_plane` with ``L = 0``, or
    the point-to-point one of :func:`frame_points` with ``L > 0`` (``u`` then
    stands for ``r'_B``), as ``(g, nx, ny, sAx, sAy, sBx, sBy, rAx, rAy, ux, uy, L)``.
    """
    rAx, rAy = turn(cA, snA, rx, ry)
    dx = xA + rAx - xB
    dy = yA + rAy - yB
    # the point in B's frame: R_B^T (P_A - X_B)
    face, ax, ay, nx, ny = closest_feature(verts, cB * dx + snB * dy, -snB * dx + cB * dy)
    if face:
        r = frame_plane(xA, yA, cA, snA, rx, ry, rhoA, xB, yB, cB, snB, ax, ay, nx, ny)
        return r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9], r[10], 0.0
    return frame_points(xA, yA, cA, snA, rx, ry, rhoA, xB, yB, cB, snB, ax, ay, 0.0)


@njit
def lever(sx, sy, ex, ey):
    """``s x e``: the rotation's coefficient in the velocity of the point ``X + s`` along ``e``."""
    return sx * ey - sy * ex


@njit
def drift_plane(wA, wB, dVx, dVy, ex, ey, rAx, rAy, ux, uy):
    """Velocity part of ``d/dt (e . (v_A(C) - v_B(C)))`` for ``e`` turning with ``B``.

    ``(2 wA wB - wA^2) e . r'_A - wB^2 e . u - 2 wB e . perp(dV)``.
    """
    return ((2.0 * wA * wB - wA * wA) * (ex * rAx + ey * rAy) - wB * wB * (ex * ux + ey * uy)
            - 2.0 * wB * (ey * dVx - ex * dVy))


# inlined by numba: as a function of its own it cost the drift kernels' compile 0.06 CPU s more
@njit(inline="always")
def relative_rates(wA, wB, dVx, dVy, rAx, rAy, rBx, rBy):
    """``d'`` and the velocity part of ``d''`` of ``d = P_A - P_B``, the points at arms ``r``.

    ``d' = dV + wA perp(r_A) - wB perp(r_B)`` (``perp(r) = (-r_y, r_x)``) and
    ``d'' = -wA^2 r_A + wB^2 r_B``, as ``(d'_x, d'_y, d''_x, d''_y)``.
    """
    return (dVx - wA * rAy + wB * rBy, dVy + wA * rAx - wB * rBx,
            -wA * wA * rAx + wB * wB * rBx, -wA * wA * rAy + wB * wB * rBy)


@njit
def drift_points(wA, wB, dVx, dVy, nx, ny, rAx, rAy, rBx, rBy, L):
    """Velocity parts of the normal and tangential rows' rates, point to point.

    ``(t . d')^2 / L + n . d''`` and ``-(n . d')(t . d') / L + t . d''``, with
    ``d'' = -wA^2 r'_A + wB^2 r'_B`` and ``t = (ny, -nx)``.
    """
    ddx, ddy, qx, qy = relative_rates(wA, wB, dVx, dVy, rAx, rAy, rBx, rBy)
    tx, ty = ny, -nx
    dnd = nx * ddx + ny * ddy
    dtd = tx * ddx + ty * ddy
    return dtd * dtd / L + nx * qx + ny * qy, -dnd * dtd / L + tx * qx + ty * qy


@njit
def spring_terms(xi, yi, ci, si, vxi, vyi, wi, pix, piy, xj, yj, cj, sj, vxj, vyj, wj, pjx,
                 pjy, k, l0, c):
    """A spring-dashpot between ``P_i`` and ``P_j``: the force on ``P_i`` and its derivatives.

    Returns ``(Fx, Fy, Axx, Axy, Ayx, Ayy, Bxx, Bxy, Byy, rix, riy, rjx, rjy)``:
    ``F = -f e`` with the tension ``f = k (l - l0) + c l'``, ``A = dF/dP`` and
    ``B = dF/dP'`` (symmetric) with ``P = P_i - P_j``, and the arms ``r'``.
    """
    rix, riy = turn(ci, si, pix, piy)
    rjx, rjy = turn(cj, sj, pjx, pjy)
    px = xi + rix - xj - rjx
    py = yi + riy - yj - rjy
    pdx = vxi - wi * riy - vxj + wj * rjy
    pdy = vyi + wi * rix - vyj - wj * rjx
    ln = math.sqrt(px * px + py * py)
    ex = px / ln
    ey = py / ln
    f = k * (ln - l0) + c * (ex * pdx + ey * pdy)
    Ixx = 1.0 - ex * ex
    Ixy = -ex * ey
    Iyy = 1.0 - ey * ey
    ux = (c / ln) * (pdx * Ixx + pdy * Ixy)
    uy = (c / ln) * (pdx * Ixy + pdy * Iyy)
    return (-f * ex, -f * ey,
            -(ex * (k * ex + ux) + f / ln * Ixx), -(ex * (k * ey + uy) + f / ln * Ixy),
            -(ey * (k * ex + ux) + f / ln * Ixy), -(ey * (k * ey + uy) + f / ln * Iyy),
            -c * ex * ex, -c * ex * ey, -c * ey * ey, rix, riy, rjx, rjy)


@njit
def axial_spring_terms(xi, yi, ci, si, vxi, vyi, wi, pix, piy, xj, yj, cj, sj, vxj, vyj, wj,
                       pjx, pjy, k, l0, c, ex, ey):
    """A spring-dashpot along the fixed world direction ``e``: the terms of :func:`spring_terms`.

    Its length is ``l = e . P`` with ``P = P_i - P_j``, its tension ``f = k (l
    - l0) + c l'``, the force on ``P_i`` is ``F = -f e``; ``e`` does not turn,
    so ``dF/dP = -k e e^T`` and ``dF/dP' = -c e e^T``.
    """
    rix, riy = turn(ci, si, pix, piy)
    rjx, rjy = turn(cj, sj, pjx, pjy)
    ln = ex * (xi + rix - xj - rjx) + ey * (yi + riy - yj - rjy)
    ld = ex * (vxi - wi * riy - vxj + wj * rjy) + ey * (vyi + wi * rix - vyj - wj * rjx)
    f = k * (ln - l0) + c * ld
    return (-f * ex, -f * ey, -k * ex * ex, -k * ex * ey, -k * ey * ex, -k * ey * ey,
            -c * ex * ex, -c * ex * ey, -c * ey * ey, rix, riy, rjx, rjy)


@njit
def spring_block(ga, gb, rax, ray, rbx, rby, wb, Axx, Axy, Ayx, Ayy, Bxx, Bxy, Byy):
    """The 3 x 3 blocks ``dh_a/dq_b`` and ``dh_a/dv_b`` of a spring, as 18 numbers (row-major).

    ``h_a = ga (F, r'_a x F)``; ``dP/dq_b = gb [I | perp(r'_b)]``,
    ``dP'/dq_b = gb [0 | -w_b r'_b]`` (the explicit ``d(r'_a x F)/dtheta_a``
    is added by the caller).
    """
    k00 = k01 = k02 = k10 = k11 = k12 = k20 = k21 = k22 = 0.0
    c00 = c01 = c02 = c10 = c11 = c12 = c20 = c21 = c22 = 0.0
    for col in range(3):
        if col == 0:
            jx, jy, kx, ky = gb, 0.0, 0.0, 0.0
        elif col == 1:
            jx, jy, kx, ky = 0.0, gb, 0.0, 0.0
        else:
            jx, jy = -gb * rby, gb * rbx
            kx, ky = -gb * wb * rbx, -gb * wb * rby
        dFx = Axx * jx + Axy * jy + Bxx * kx + Bxy * ky
        dFy = Ayx * jx + Ayy * jy + Bxy * kx + Byy * ky
        cFx = Bxx * jx + Bxy * jy
        cFy = Bxy * jx + Byy * jy
        a0, a1, a2 = ga * dFx, ga * dFy, ga * (rax * dFy - ray * dFx)
        b0, b1, b2 = ga * cFx, ga * cFy, ga * (rax * cFy - ray * cFx)
        if col == 0:
            k00, k10, k20, c00, c10, c20 = a0, a1, a2, b0, b1, b2
        elif col == 1:
            k01, k11, k21, c01, c11, c21 = a0, a1, a2, b0, b1, b2
        else:
            k02, k12, k22, c02, c12, c22 = a0, a1, a2, b0, b1, b2
    return (k00, k01, k02, k10, k11, k12, k20, k21, k22,
            c00, c01, c02, c10, c11, c12, c20, c21, c22)


#: contact kind of a revolute joint with clearance: a pin of ``A`` in a hole of ``B``
HOLE = 3


@njit
def frame_hole(xA, yA, cA, snA, rx, ry, rhoA, xB, yB, cB, snB, hx, hy, rhoB):
    """A pin of ``A`` (centre ``r``, radius ``rhoA``) in a hole of ``B`` (centre ``h``, radius ``rhoB``).

    Returns ``(g, nx, ny, sAx, sAy, sBx, sBy, rAx, rAy, rBx, rBy, L)``: the gap
    ``rhoB - rhoA - |d|`` with ``d`` the pin's centre less the hole's, the
    normal ``-d / |d|`` (from the wall towards the centre: the force on the
    pin), the contact points' offsets ``r' + rho d / |d|`` and ``L = |d|``.
    Below ``|d| = 1e-12 rhoB`` the direction of ``d`` is not defined: ``B``'s
    ``x`` axis stands for it and ``L = 0`` tells :func:`drift_hole` (the gap
    is then the whole clearance, far from closing).
    """
    rAx, rAy = turn(cA, snA, rx, ry)
    rBx, rBy = turn(cB, snB, hx, hy)
    dx = xA + rAx - xB - rBx
    dy = yA + rAy - yB - rBy
    L = math.sqrt(dx * dx + dy * dy)
    g = rhoB - rhoA - L
    if L > 1e-12 * rhoB:
        ux, uy = dx / L, dy / L
    else:
        ux, uy = cB, snB
        L = 0.0
    return (g, -ux, -uy, rAx + rhoA * ux, rAy + rhoA * uy, rBx + rhoB * ux, rBy + rhoB * uy,
            rAx, rAy, rBx, rBy, L)


@njit
def drift_hole(wA, wB, dVx, dVy, nx, ny, rAx, rAy, rBx, rBy, L):
    """Velocity parts of the normal and tangential rows' rates of a pin in a hole.

    With ``n = -d / L`` and ``t = (ny, -nx)``: ``-(t . d')^2 / L + n . d''`` and
    ``(n . d')(t . d') / L + t . d''``, ``d'' = -wA^2 r'_A + wB^2 r'_B``; at
    ``L = 0`` (the centre) without the terms in ``1 / L``.
    """
    ddx, ddy, qx, qy = relative_rates(wA, wB, dVx, dVy, rAx, rAy, rBx, rBy)
    tx, ty = ny, -nx
    dn = nx * qx + ny * qy
    dt = tx * qx + ty * qy
    if L > 0.0:
        dnd = nx * ddx + ny * ddy
        dtd = tx * ddx + ty * ddy
        dn -= dtd * dtd / L
        dt += dnd * dtd / L
    return dn, dt
