"""The compiled functions of every planar model: one set, the model's description packed into ``par``.

A built model is data, not code: the bodies, contacts and forces are records
in the float vector ``par`` (layout below, written by
:mod:`moreau.model.planar.builder`), and the four functions of
:mod:`moreau.compiled` read them. They are compiled once for every planar
model and kept in numba's disk cache; the engine's own loop for them is
shared by every built model too. The Python methods of a built scene call
these same functions, so a model is written once.

Layout of ``par`` (integers stored as floats)
---------------------------------------------
``par[0:9]`` header: number of bodies, contacts, force records; offsets of
the body, contact and force tables; ``ndof``; gravity ``(gx, gy)``.

Body record (``BREC`` floats): ``kind`` (0 fixed, 1 free, 2 driven), first
coordinate index (free bodies), mass, inertia, fixed pose ``(x, y, theta)``,
offsets of the three time functions of a driven body.

Time function at offset ``o``: ``c0, c1, c2, nh, (A, w, phi) * nh``, the value
``c0 + c1 t + c2 t^2 / 2 + sum A sin(w t + phi)``.

Contact record (``CREC`` floats): ``kind``, body ``A``, body ``B``, the point
``rA`` of ``A`` (body frame) and its radius ``rhoA``, then by kind:
``PLANE`` a line of ``B`` (point ``p0``, unit normal ``n0``, body frame);
``POINTS`` a point ``rB`` of ``B`` with radius ``rhoB``; ``POLY`` a convex
polygon of ``B`` (``nv`` counter-clockwise vertices at an offset; two
vertices: a segment, two-sided).

Force record (``FREC`` floats): ``SPRING`` (bodies ``i, j``, points
``ri, rj``, stiffness, rest length, damping), ``TORSION`` (bodies ``i, j``,
stiffness, rest angle, damping), ``FORCE`` (body, point, offsets of the time
functions of the world components), ``TORQUE`` (body, offset of its time
function).

The contact kinematics are derived in :mod:`moreau.model.planar` (module
docstring).
"""

import math

from numba import njit

HEADER = 9
BREC = 10
CREC = 14
FREC = 12

FIXED, FREE, DRIVEN = 0, 1, 2
PLANE, POINTS, POLY = 0, 1, 2
SPRING, TORSION, FORCE, TORQUE = 0, 1, 2, 3


@njit(cache=True)
def time_function(par, o, t):
    """``(f, f', f'')`` of the time function at offset ``o``."""
    c1 = par[o + 1]
    c2 = par[o + 2]
    f = par[o] + t * (c1 + 0.5 * c2 * t)
    d1 = c1 + c2 * t
    d2 = c2
    nh = int(par[o + 3])
    for k in range(nh):
        A = par[o + 4 + 3 * k]
        w = par[o + 5 + 3 * k]
        ph = par[o + 6 + 3 * k]
        s = math.sin(w * t + ph)
        c = math.cos(w * t + ph)
        f += A * s
        d1 += A * w * c
        d2 -= A * w * w * s
    return f, d1, d2


@njit(cache=True)
def body_state(par, k, q, v, t):
    """``(kind, dof, x, y, th, vx, vy, w, ax, ay, al)`` of body ``k``.

    A free body's accelerations are returned as zero: the drift terms are the
    parts of the contact accelerations that do not depend on them.
    """
    o = int(par[3]) + BREC * k
    kind = int(par[o])
    dof = int(par[o + 1])
    if kind == FREE:
        return (kind, dof, q[dof], q[dof + 1], q[dof + 2], v[dof], v[dof + 1], v[dof + 2],
                0.0, 0.0, 0.0)
    if kind == FIXED:
        return kind, -1, par[o + 4], par[o + 5], par[o + 6], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    x, vx, ax = time_function(par, int(par[o + 7]), t)
    y, vy, ay = time_function(par, int(par[o + 8]), t)
    th, w, al = time_function(par, int(par[o + 9]), t)
    return kind, -1, x, y, th, vx, vy, w, ax, ay, al


@njit(cache=True)
def mass(par, q, M):
    nb = int(par[0])
    for k in range(nb):
        o = int(par[3]) + BREC * k
        if int(par[o]) == FREE:
            d = int(par[o + 1])
            M[d, d] = par[o + 2]
            M[d + 1, d + 1] = par[o + 2]
            M[d + 2, d + 2] = par[o + 3]


@njit(cache=True)
def _add_point_force(D, need_jac, n, dof, rx, ry, fx, fy):
    # a force (fx, fy) at the body point r' = (rx, ry) from the centre of mass:
    # (fx, fy, r' x f); its explicit angle derivative d(r' x f)/dth = -r'.f
    D[dof, 0] += fx
    D[dof + 1, 0] += fy
    D[dof + 2, 0] += rx * fy - ry * fx
    if need_jac:
        D[dof + 2, 1 + dof + 2] -= rx * fx + ry * fy


@njit(cache=True)
def forces(par, q, v, t, D, need_jac):
    n = int(par[6])
    for i in range(n):
        D[i, 0] = 0.0
        if need_jac:
            for j in range(2 * n):
                D[i, 1 + j] = 0.0
    nb = int(par[0])
    gx = par[7]
    gy = par[8]
    for k in range(nb):
        o = int(par[3]) + BREC * k
        if int(par[o]) == FREE:
            d = int(par[o + 1])
            D[d, 0] += par[o + 2] * gx
            D[d + 1, 0] += par[o + 2] * gy
    nf = int(par[2])
    for f in range(nf):
        o = int(par[5]) + FREC * f
        kind = int(par[o])
        if kind == SPRING:
            _spring(par, o, q, v, t, D, need_jac, n)
        elif kind == TORSION:
            _torsion(par, o, q, v, t, D, need_jac, n)
        elif kind == FORCE:
            s = body_state(par, int(par[o + 1]), q, v, t)
            c = math.cos(s[4])
            sn = math.sin(s[4])
            rx = c * par[o + 2] - sn * par[o + 3]
            ry = sn * par[o + 2] + c * par[o + 3]
            fx = time_function(par, int(par[o + 4]), t)[0]
            fy = time_function(par, int(par[o + 5]), t)[0]
            _add_point_force(D, need_jac, n, s[1], rx, ry, fx, fy)
        else:
            s = body_state(par, int(par[o + 1]), q, v, t)
            D[s[1] + 2, 0] += time_function(par, int(par[o + 2]), t)[0]


@njit(cache=True)
def _torsion(par, o, q, v, t, D, need_jac, n):
    si = body_state(par, int(par[o + 1]), q, v, t)
    sj = body_state(par, int(par[o + 2]), q, v, t)
    k = par[o + 3]
    c = par[o + 5]
    tau = -k * (si[4] - sj[4] - par[o + 4]) - c * (si[7] - sj[7])
    for s, sg in ((si, 1.0), (sj, -1.0)):
        if s[0] == FREE:
            a = s[1] + 2
            D[a, 0] += sg * tau
            if need_jac:
                for r, rg in ((si, 1.0), (sj, -1.0)):
                    if r[0] == FREE:
                        b = r[1] + 2
                        D[a, 1 + b] -= sg * rg * k
                        D[a, 1 + n + b] -= sg * rg * c


@njit(cache=True)
def _spring(par, o, q, v, t, D, need_jac, n):
    # a spring-damper along the line between P_i and P_j: tension f = k (l - l0) + c l',
    # force -f e on P_i and +f e on P_j, e = (P_i - P_j) / l
    si = body_state(par, int(par[o + 1]), q, v, t)
    sj = body_state(par, int(par[o + 2]), q, v, t)
    ci, sni = math.cos(si[4]), math.sin(si[4])
    cj, snj = math.cos(sj[4]), math.sin(sj[4])
    rix = ci * par[o + 3] - sni * par[o + 4]
    riy = sni * par[o + 3] + ci * par[o + 4]
    rjx = cj * par[o + 5] - snj * par[o + 6]
    rjy = snj * par[o + 5] + cj * par[o + 6]
    px = si[2] + rix - sj[2] - rjx
    py = si[3] + riy - sj[3] - rjy
    # P' = V + w perp(r'), perp(r) = (-ry, rx)
    pdx = si[5] - si[7] * riy - sj[5] + sj[7] * rjy
    pdy = si[6] + si[7] * rix - sj[6] - sj[7] * rjx
    k = par[o + 7]
    l0 = par[o + 8]
    c = par[o + 9]
    ln = math.sqrt(px * px + py * py)
    ex = px / ln
    ey = py / ln
    ldot = ex * pdx + ey * pdy
    f = k * (ln - l0) + c * ldot
    Fx = -f * ex
    Fy = -f * ey
    if si[0] == FREE:
        _add_point_force(D, need_jac, n, si[1], rix, riy, Fx, Fy)
    if sj[0] == FREE:
        _add_point_force(D, need_jac, n, sj[1], rjx, rjy, -Fx, -Fy)
    if not need_jac:
        return
    # dF/dP = -[e (k e^T + (c / l) P'^T (I - e e^T)) + (f / l) (I - e e^T)], dF/dP' = -c e e^T
    Ixx = 1.0 - ex * ex
    Ixy = -ex * ey
    Iyy = 1.0 - ey * ey
    ux = (c / ln) * (pdx * Ixx + pdy * Ixy)
    uy = (c / ln) * (pdx * Ixy + pdy * Iyy)
    Axx = -(ex * (k * ex + ux) + f / ln * Ixx)
    Axy = -(ex * (k * ey + uy) + f / ln * Ixy)
    Ayx = -(ey * (k * ex + ux) + f / ln * Ixy)
    Ayy = -(ey * (k * ey + uy) + f / ln * Iyy)
    Bxx = -c * ex * ex
    Bxy = -c * ex * ey
    Byy = -c * ey * ey
    for a in range(2):
        sa = si if a == 0 else sj
        if sa[0] != FREE:
            continue
        ga = 1.0 if a == 0 else -1.0
        rax = rix if a == 0 else rjx
        ray = riy if a == 0 else rjy
        da = sa[1]
        for b in range(2):
            sb = si if b == 0 else sj
            if sb[0] != FREE:
                continue
            gb = 1.0 if b == 0 else -1.0
            rbx = rix if b == 0 else rjx
            rby = riy if b == 0 else rjy
            wb = sb[7]
            db = sb[1]
            # columns of dP/dq_b = gb [I | perp(r'_b)], dP'/dq_b = gb [0 | -w_b r'_b]
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
                # the generalized force on a is ga (F, r'_a x F)
                D[da, 1 + db + col] += ga * dFx
                D[da + 1, 1 + db + col] += ga * dFy
                D[da + 2, 1 + db + col] += ga * (rax * dFy - ray * dFx)
                D[da, 1 + n + db + col] += ga * cFx
                D[da + 1, 1 + n + db + col] += ga * cFy
                D[da + 2, 1 + n + db + col] += ga * (rax * cFy - ray * cFx)


@njit(cache=True)
def _closest_feature(par, o, lx, ly):
    """The feature of the polygon of contact record ``o`` nearest to the local point ``(lx, ly)``.

    Returns ``(is_face, ax, ay, nx, ny)``: a face (the line through ``(ax, ay)``
    with outward unit normal ``(nx, ny)``) or a vertex ``(ax, ay)``.
    """
    nv = int(par[o + 6])
    vo = int(par[o + 7])
    if nv == 2:
        x0, y0 = par[vo], par[vo + 1]
        ex, ey = par[vo + 2] - x0, par[vo + 3] - y0
        L2 = ex * ex + ey * ey
        lam = ((lx - x0) * ex + (ly - y0) * ey) / L2
        if lam < 0.0:
            return False, x0, y0, 0.0, 0.0
        if lam > 1.0:
            return False, par[vo + 2], par[vo + 3], 0.0, 0.0
        L = math.sqrt(L2)
        nx, ny = ey / L, -ex / L
        if nx * (lx - x0) + ny * (ly - y0) < 0.0:
            nx, ny = -nx, -ny
        return True, x0, y0, nx, ny
    best = -1.0e300
    kb = 0
    for k in range(nv):
        x0, y0 = par[vo + 2 * k], par[vo + 2 * k + 1]
        k1 = (k + 1) % nv
        ex, ey = par[vo + 2 * k1] - x0, par[vo + 2 * k1 + 1] - y0
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
        # inside: the face of least penetration
        x0, y0 = par[vo + 2 * kb], par[vo + 2 * kb + 1]
        k1 = (kb + 1) % nv
        ex, ey = par[vo + 2 * k1] - x0, par[vo + 2 * k1 + 1] - y0
        L = math.sqrt(ex * ex + ey * ey)
        return True, x0, y0, ey / L, -ex / L
    dmin = 1.0e300
    for k in range(nv):
        dx, dy = lx - par[vo + 2 * k], ly - par[vo + 2 * k + 1]
        d2 = dx * dx + dy * dy
        if d2 < dmin:
            dmin = d2
            kb = k
    return False, par[vo + 2 * kb], par[vo + 2 * kb + 1], 0.0, 0.0


@njit(cache=True)
def contact_frame(par, i, q, v, t):
    """The geometry of contact ``i``.

    Returns ``(sA, sB, g, nx, ny, sAx, sAy, sBx, sBy, plane, rAx, rAy, ux, uy, L)``:
    the states of bodies ``A`` and ``B`` (:func:`body_state`), the gap, the
    normal (from ``B`` to ``A``), the contact points' offsets ``sA = C_A - X_A``,
    ``sB = C_B - X_B``, whether the contact is point-on-line, ``r'_A``, and
    ``u = P_A - X_B`` (point-on-line) or ``r'_B`` (point-to-point) with the
    distance ``L`` between the points.
    """
    o = int(par[4]) + CREC * i
    kind = int(par[o])
    sA = body_state(par, int(par[o + 1]), q, v, t)
    sB = body_state(par, int(par[o + 2]), q, v, t)
    cA, snA = math.cos(sA[4]), math.sin(sA[4])
    cB, snB = math.cos(sB[4]), math.sin(sB[4])
    rAx = cA * par[o + 3] - snA * par[o + 4]
    rAy = snA * par[o + 3] + cA * par[o + 4]
    rhoA = par[o + 5]
    PAx = sA[2] + rAx
    PAy = sA[3] + rAy
    plane = True
    rhoB = 0.0
    if kind == PLANE:
        p0x, p0y, n0x, n0y = par[o + 6], par[o + 7], par[o + 8], par[o + 9]
    elif kind == POINTS:
        plane = False
        p0x, p0y = par[o + 6], par[o + 7]
        n0x, n0y = 0.0, 0.0
        rhoB = par[o + 8]
    else:
        dx, dy = PAx - sB[2], PAy - sB[3]
        lx = cB * dx + snB * dy
        ly = -snB * dx + cB * dy
        plane, p0x, p0y, n0x, n0y = _closest_feature(par, o, lx, ly)
    if plane:
        nx = cB * n0x - snB * n0y
        ny = snB * n0x + cB * n0y
        ux = PAx - sB[2]
        uy = PAy - sB[3]
        Qx = cB * p0x - snB * p0y
        Qy = snB * p0x + cB * p0y
        g = nx * (ux - Qx) + ny * (uy - Qy) - rhoA
        sBx = ux - rhoA * nx
        sBy = uy - rhoA * ny
        L = 0.0
    else:
        ux = cB * p0x - snB * p0y
        uy = snB * p0x + cB * p0y
        dx = PAx - sB[2] - ux
        dy = PAy - sB[3] - uy
        L = math.sqrt(dx * dx + dy * dy)
        nx, ny = dx / L, dy / L
        g = L - rhoA - rhoB
        sBx = ux + rhoB * nx
        sBy = uy + rhoB * ny
    sAx = rAx - rhoA * nx
    sAy = rAy - rhoA * ny
    return sA, sB, g, nx, ny, sAx, sAy, sBx, sBy, plane, rAx, rAy, ux, uy, L


@njit(cache=True)
def _row(G, i, col0, s, sg, ex, ey, sx, sy):
    # the velocity of the contact point of a body along e: (e, s x e) . (V, w); a free
    # body's coefficients go into its columns, a driven body's velocity into w
    cw = sx * ey - sy * ex
    if s[0] == FREE:
        G[i, col0 + s[1]] = sg * ex
        G[i, col0 + s[1] + 1] = sg * ey
        G[i, col0 + s[1] + 2] = sg * cw
        return 0.0
    return sg * (ex * s[5] + ey * s[6] + cw * s[7])


@njit(cache=True)
def contacts(par, q, t, G, need_gap, need_T):
    n = int(par[6])
    nc = int(par[1])
    for i in range(nc):
        sA, sB, g, nx, ny, sAx, sAy, sBx, sBy, plane, rAx, rAy, ux, uy, L = contact_frame(
            par, i, q, q, t)
        if need_gap:
            G[i, 0] = g
        G[i, 1] = (_row(G, i, 3, sA, 1.0, nx, ny, sAx, sAy)
                   + _row(G, i, 3, sB, -1.0, nx, ny, sBx, sBy))
        if need_T:
            tx, ty = ny, -nx
            G[i, 2] = (_row(G, i, 3 + n, sA, 1.0, tx, ty, sAx, sAy)
                       + _row(G, i, 3 + n, sB, -1.0, tx, ty, sBx, sBy))


@njit(cache=True)
def _acc(s, sg, ex, ey, sx, sy):
    # a driven body's prescribed acceleration along the row (zero for the others)
    return sg * (ex * s[8] + ey * s[9] + (sx * ey - sy * ex) * s[10])


@njit(cache=True)
def drift(par, q, v, t, Dr):
    nc = int(par[1])
    for i in range(nc):
        sA, sB, g, nx, ny, sAx, sAy, sBx, sBy, plane, rAx, rAy, ux, uy, L = contact_frame(
            par, i, q, v, t)
        tx, ty = ny, -nx
        wA, wB = sA[7], sB[7]
        dVx, dVy = sA[5] - sB[5], sA[6] - sB[6]
        if plane:
            # e rotates with B: (2 wA wB - wA^2) e.r'_A - wB^2 e.u - 2 wB e.perp(dV)
            cr = 2.0 * wA * wB - wA * wA
            pVx, pVy = -dVy, dVx
            dn = (cr * (nx * rAx + ny * rAy) - wB * wB * (nx * ux + ny * uy)
                  - 2.0 * wB * (nx * pVx + ny * pVy))
            dt = (cr * (tx * rAx + ty * rAy) - wB * wB * (tx * ux + ty * uy)
                  - 2.0 * wB * (tx * pVx + ty * pVy))
        else:
            # n = d / |d|: (t.d')^2 / L + n.d''_v and -(n.d')(t.d') / L + t.d''_v
            ddx = dVx - wA * rAy + wB * uy
            ddy = dVy + wA * rAx - wB * ux
            qx = -wA * wA * rAx + wB * wB * ux
            qy = -wA * wA * rAy + wB * wB * uy
            dnd = nx * ddx + ny * ddy
            dtd = tx * ddx + ty * ddy
            dn = dtd * dtd / L + nx * qx + ny * qy
            dt = -dnd * dtd / L + tx * qx + ty * qy
        Dr[i, 0] = (dn + _acc(sA, 1.0, nx, ny, sAx, sAy) + _acc(sB, -1.0, nx, ny, sBx, sBy))
        Dr[i, 1] = (dt + _acc(sA, 1.0, tx, ty, sAx, sAy) + _acc(sB, -1.0, tx, ty, sBx, sBy))
