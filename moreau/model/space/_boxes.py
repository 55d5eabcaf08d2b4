"""Narrow phase of the box contacts between two bodies: sphere against box, box against box.

The derivations (gap, normal, offsets, rows and drift of each kind of
point) are in :mod:`moreau.model.space`'s docstring, "Contacts with boxes";
this module computes them. Every point is a :class:`BoxPoint`: its normal
``n`` from body ``a`` to body ``b``, gap ``g``, offsets ``sa``, ``sb``
(world) of the two points whose relative velocity the rows give, and the
data its drift needs.
"""

import math
from collections import namedtuple

import numpy as np

from ...errors import IllPosedError

#: a point: ``kind`` is "fa" (a vertex of b on a face of a), "fb" (a vertex of a on a face of
#: b), "ee" (an edge of a against an edge of b) or "sb" (a sphere a against a box b); ``aux``
#: the data its drift needs
BoxPoint = namedtuple("BoxPoint", "n g sa sb kind aux")

#: an incident vertex within this fraction of the reference box's largest half-extent
#: outside a side plane counts as on it (the clipping makes no point beside it)
CLIP_TOL = 1e-9

#: a face axis is kept against an edge-edge axis unless the edge axis separates the boxes
#: more by this fraction of the smaller box's least half-extent (faces give stable sets)
EDGE_PREFERENCE = 1e-6

#: two edges whose directions make a sine below this are parallel: no edge-edge axis
PARALLEL_SIN = 1e-6


def signs_of(k):
    """The signs ``(+-1, +-1, +-1)`` of corner ``k`` (bit ``i`` set: ``+`` along axis ``i``)."""
    return np.array([2 * (k & 1) - 1, 2 * ((k >> 1) & 1) - 1, 2 * ((k >> 2) & 1) - 1], float)


def corner_of(signs):
    """The corner number of the signs ``(+-1, +-1, +-1)``."""
    return sum(1 << i for i in range(3) if signs[i] > 0)


def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


# -- the three kinds of point between two boxes -------------------------------------------------
def vertex_face(xa, Ra, ha, xb, Rb, hb, vertex_of_b, k, axis, sign):
    """A vertex against a face: ``vertex_of_b`` True for vertex ``k`` of ``b`` on the face
    ``(axis, sign)`` of ``a``, False for vertex ``k`` of ``a`` on that face of ``b``."""
    if vertex_of_b:
        p = xb + Rb @ (signs_of(k) * hb)
        nf = sign * Ra[:, axis]
        g = nf @ (p - xa) - ha[axis]
        return BoxPoint(nf, g, p - xa, p - xb, "fa", None)
    p = xa + Ra @ (signs_of(k) * ha)
    nf = sign * Rb[:, axis]
    g = nf @ (p - xb) - hb[axis]
    return BoxPoint(-nf, g, p - xa, p - xb, "fb", None)


def edge_frame(x, R, h, edge):
    """``(midpoint, unit direction, half-length)`` (world) of the box edge ``(axis, corner)``,
    ``corner`` the signs of the two other axes (its bit ``axis`` ignored)."""
    axis, k = edge
    s = signs_of(k)
    s[axis] = 0.0
    return x + R @ (s * h), R[:, axis].copy(), h[axis]


def edge_edge(xa, Ra, ha, xb, Rb, hb, edge_a, edge_b, toward):
    """The closest points of the lines of ``edge_a`` (of ``a``) and ``edge_b`` (of ``b``),
    the normal ``d_a x d_b`` turned along ``toward``; ``(point, t, u)`` with the parameters
    along the edges from their midpoints (the caller checks them against the half-lengths)."""
    Pa, da, _ = edge_frame(xa, Ra, ha, edge_a)
    Pb, db, _ = edge_frame(xb, Rb, hb, edge_b)
    m = _cross(da, db)
    mn = math.sqrt(m @ m)
    if mn <= 1e-14:
        raise IllPosedError("two edges in a box contact are parallel: their closest points, "
                            "and the contact's normal, are undefined")
    sgn = 1.0 if m @ toward >= 0.0 else -1.0
    n = sgn * m / mn
    r0 = Pb - Pa
    c = da @ db
    den = 1.0 - c * c
    t = (r0 @ da - c * (r0 @ db)) / den
    u = (c * (r0 @ da) - r0 @ db) / den
    ca, cb = Pa + t * da, Pb + u * db
    g = n @ (cb - ca)
    return BoxPoint(n, g, ca - xa, cb - xb, "ee", (da, db, sgn, mn, c)), t, u


# -- sphere against box ---------------------------------------------------------------------------
def sphere_box(xa, Ra, centre, radius, xb, Rb, hb):
    """The point of a sphere (body ``a``, centre ``xa + Ra centre``) against a box (body ``b``):
    the box's point closest to the sphere's centre; raises where the centre is in the box."""
    c = xa + Ra @ centre
    u = Rb.T @ (c - xb)
    ql = np.clip(u, -hb, hb)
    free = np.abs(u) < hb
    if free.all():
        raise IllPosedError("a sphere's centre is inside a box (it has sunk past its radius): "
                            "the closest point of the box, the contact's normal, is undefined")
    q = xb + Rb @ ql
    d = q - c
    L = math.sqrt(d @ d)
    if L <= 1e-12 * radius:
        raise IllPosedError("a sphere's centre is on a box's surface: the contact's normal is "
                            "undefined")
    n = d / L
    return BoxPoint(n, L - radius, Ra @ centre + radius * n, q - xb, "sb",
                    (Ra @ centre, radius, L, free.astype(float)))


# -- box against box: the separating axes, then the clipped faces or the edges ------------------
def box_box(xa, Ra, ha, xb, Rb, hb, margin):
    """The contact points of box ``a`` and box ``b`` whose gaps are at most ``margin``.

    The separating-axis test over the 15 axes (the 3 + 3 face normals, the
    9 edge cross products) finds the axis of largest separation; beyond
    ``margin`` there is no point; a penetration deeper than ``margin`` is
    raised (:class:`~moreau.errors.IllPosedError`). A face axis clips the
    incident face against the reference face's side planes (up to 8
    points), an edge axis gives the closest points of the two edges.
    """
    d = xb - xa
    size = min(ha.min(), hb.min())
    Aa, Ab = np.abs(Ra.T @ Rb), None
    Ab = Aa.T
    best_face, face = -math.inf, None
    for i in range(3):
        L = Ra[:, i]
        s = abs(L @ d) - ha[i] - hb @ Aa[i]
        if s > best_face + CLIP_TOL * size:
            best_face, face = s, ("a", i, 1.0 if L @ d >= 0.0 else -1.0)
    for j in range(3):
        L = Rb[:, j]
        s = abs(L @ d) - hb[j] - ha @ Ab[j]
        # b's face only where it separates more than a's by more than rounding
        if s > best_face + CLIP_TOL * size:
            best_face, face = s, ("b", j, 1.0 if L @ d <= 0.0 else -1.0)
    best_edge, edge = -math.inf, None
    for i in range(3):
        for j in range(3):
            L = _cross(Ra[:, i], Rb[:, j])
            ln = math.sqrt(L @ L)
            if ln <= PARALLEL_SIN:
                continue
            L = L / ln
            s = abs(L @ d) - ha @ np.abs(Ra.T @ L) - hb @ np.abs(Rb.T @ L)
            if s > best_edge:
                best_edge, edge = s, (i, j, L if L @ d >= 0.0 else -L)
    best = max(best_face, best_edge)
    if best > margin:
        return []
    if best < -margin:
        raise IllPosedError(f"two boxes interpenetrate by {-best:.3g} (scene units), past the "
                            f"contact's margin {margin:.3g}: the set of contact points is not "
                            f"stated (reduce the step)")
    if edge is not None and best_edge > best_face + EDGE_PREFERENCE * size:
        i, j, L = edge
        ka = corner_of(np.sign(Ra.T @ L) + (Ra.T @ L == 0.0))
        kb = corner_of(-np.sign(Rb.T @ L) + (Rb.T @ L == 0.0))
        pt, t, u = edge_edge(xa, Ra, ha, xb, Rb, hb, (i, ka), (j, kb), L)
        tol = CLIP_TOL * size
        if abs(t) > ha[i] + tol or abs(u) > hb[j] + tol:
            if pt.g > 0.0:
                return []
            raise IllPosedError("two boxes touch edge to edge with the closest points off the "
                                "edges: the contact set is not stated")
        return [pt] if pt.g <= margin else []
    return _face_face(xa, Ra, ha, xb, Rb, hb, face, margin)


def _face_face(xa, Ra, ha, xb, Rb, hb, face, margin):
    # the reference face (on `which`, axis i, outward sign sigma), the incident face of the
    # other box most anti-parallel to it, clipped by the reference face's four side planes
    which, i, sigma = face
    if which == "a":
        xr, Rr, hr, xi, Ri, hi = xa, Ra, ha, xb, Rb, hb
    else:
        xr, Rr, hr, xi, Ri, hi = xb, Rb, hb, xa, Ra, ha
    nf = sigma * Rr[:, i]
    dots = nf @ Ri
    j = int(np.argmax(np.abs(dots)))
    tau = -1.0 if dots[j] > 0.0 else 1.0
    j1, j2 = (j + 1) % 3, (j + 2) % 3
    corners = []
    for s1, s2 in ((-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)):
        s = np.zeros(3)
        s[j], s[j1], s[j2] = tau, s1, s2
        corners.append(corner_of(s))
    # polygon: (point, tag, carrier of the edge to the next vertex); a carrier is ("inc",
    # incident edge) or ("side", axis, sign) of the reference box
    poly = []
    for m in range(4):
        k, k2 = corners[m], corners[(m + 1) % 4]
        ax = int(np.flatnonzero(signs_of(k) != signs_of(k2))[0])
        poly.append((xi + Ri @ (signs_of(k) * hi), ("v", k), ("inc", (ax, k))))
    tol = CLIP_TOL * hr.max()
    for k in ((i + 1) % 3, (i + 2) % 3):
        for s in (1.0, -1.0):
            if not poly:
                break
            nk = s * Rr[:, k]
            dist = [nk @ (p - xr) - hr[k] for p, _, _ in poly]
            out = []
            for m in range(len(poly)):
                P, tagP, carP = poly[m]
                Q = poly[(m + 1) % len(poly)][0]
                dP, dQ = dist[m], dist[(m + 1) % len(poly)]
                if dP <= tol:
                    if dQ > tol and dP < -tol:
                        out.append((P, tagP, carP))
                        X = P + dP / (dP - dQ) * (Q - P)
                        out.append((X, _crossing(carP, k, s, i, sigma), ("side", k, s)))
                    elif dQ > tol:
                        out.append((P, tagP, ("side", k, s)))    # P on the plane: it is X
                    else:
                        out.append((P, tagP, carP))
                elif dQ < -tol:
                    X = P + dP / (dP - dQ) * (Q - P)
                    out.append((X, _crossing(carP, k, s, i, sigma), carP))
            poly = out
    points = []
    a_is_ref = which == "a"
    toward = nf if a_is_ref else -nf
    for _, tag, _ in poly:
        if tag[0] == "v":           # a vertex of the incident box on the reference face
            pt = vertex_face(xa, Ra, ha, xb, Rb, hb, a_is_ref, tag[1], i, sigma)
        elif tag[0] == "r":         # a vertex of the reference box on the incident face
            pt = vertex_face(xa, Ra, ha, xb, Rb, hb, not a_is_ref, tag[1], j, tau)
        else:                       # an incident edge across a reference face's edge
            ei, er = tag[1], tag[2]
            ea, eb = (er, ei) if a_is_ref else (ei, er)
            pt = edge_edge(xa, Ra, ha, xb, Rb, hb, ea, eb, toward)[0]
        if pt.g <= margin:
            points.append(pt)
    return points


def _crossing(carrier, k, s, i, sigma):
    # the tag of the point where a polygon edge on `carrier` crosses the side plane (k, s) of
    # the reference face (axis i, sign sigma)
    m = 3 - i - k
    if carrier[0] == "inc":
        sg = np.zeros(3)
        sg[i], sg[k] = sigma, s
        return ("e", carrier[1], (m, corner_of(sg + (sg == 0.0))))
    sg = np.zeros(3)
    sg[i], sg[k], sg[carrier[1]] = sigma, s, carrier[2]
    return ("r", corner_of(sg))


# -- rows' drift ---------------------------------------------------------------------------------
def frame(n):
    """``[n, t1, t2]`` of :func:`moreau.model.space.tangent_basis`, with ``k`` its axis."""
    a = np.abs(n)
    k = (0 if a[0] <= a[2] else 2) if a[0] <= a[1] else (1 if a[1] <= a[2] else 2)
    t = -n[k] * n
    t[k] += 1.0
    t1 = t / math.sqrt(t @ t)
    return np.array([n, t1, _cross(n, t1)]), k


def frame_rate(n, nd):
    """The rates of ``[n, t1, t2]`` when ``n`` turns at ``nd``."""
    E, k = frame(n)
    t1 = E[1]
    m = -n[k] * n
    m[k] += 1.0
    md = -nd[k] * n - n[k] * nd
    t1d = (md - (t1 @ md) * t1) / math.sqrt(m @ m)
    return E, np.array([nd, t1d, _cross(nd, t1) + _cross(n, t1d)])


def drift(pt, va, wa, vb, wb, Rb=None):
    """``d/dt [n, t1, t2] . (v_b(x_b + s_b) - v_a(x_a + s_a))`` at constant velocities
    (``va``, ``vb`` the centres', ``wa``, ``wb`` the world angular velocities)."""
    n, sa, sb = pt.n, pt.sa, pt.sb
    delta = vb + _cross(wb, sb) - va - _cross(wa, sa)
    if pt.kind == "fa":
        nd = _cross(wa, n)
        sbd = _cross(wb, sb)
        sad = vb + sbd - va
    elif pt.kind == "fb":
        nd = _cross(wb, n)
        sad = _cross(wa, sa)
        sbd = va + sad - vb
    elif pt.kind == "ee":
        da, db, sgn, mn, c = pt.aux
        dad, dbd = _cross(wa, da), _cross(wb, db)
        r = pt.g * n
        al = delta @ da + r @ dad
        be = delta @ db + r @ dbd
        den = 1.0 - c * c
        td = (al - c * be) / den
        ud = (c * al - be) / den
        sad = _cross(wa, sa) + td * da
        sbd = _cross(wb, sb) + ud * db
        md = _cross(dad, db) + _cross(da, dbd)
        nd = sgn * (md - (n @ md) * n) / mn
    else:                       # "sb": a sphere (a) against a box (b)
        ca, radius, L, free = pt.aux
        cd = va + _cross(wa, ca)
        # the closest point slides with the centre along the box's free coordinates
        ud = Rb @ (free * (Rb.T @ (cd - vb - _cross(wb, sb - L * n))))
        sbd = _cross(wb, sb) + ud
        qd = vb + sbd
        rel = qd - cd
        nd = (rel - (n @ rel) * n) / L
        sad = _cross(wa, ca) + radius * nd
    E, Ed = frame_rate(n, nd)
    acc = _cross(wb, sbd) - _cross(wa, sad)
    return Ed @ delta + E @ acc
