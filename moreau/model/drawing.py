"""Primitive shapes with which a scene draws itself (``Scene.shapes``), in SI units.

A scene's ``shapes(q, t)`` takes its coordinates in SI (m, rad: the ``q_i``
columns of ``moreau run``'s table) and the time in seconds, and returns a list
of dicts, each one of:

``{"kind": "circle", "centre": (x, y), "radius": r}``
``{"kind": "polygon", "points": [(x, y), ...]}`` (closed)
``{"kind": "line", "points": [(x, y), ...]}`` (open)
``{"kind": "contact", "index": i, "point": (x, y), "normal": (nx, ny), "tangent": (tx, ty)}``

A contact's normal is the unit direction in which its normal force
``force_N_i`` acts on the body drawn on the gap's positive side, its tangent
the direction of ``force_T_i``; the animation draws the force as the arrow
``force_N normal + force_T tangent`` at ``point``. A shape may carry
``"role"`` (``"ground"`` is drawn grey).

Examples
--------
>>> circle((0.0, 1.0), 0.5)["kind"]
'circle'
>>> from moreau.scenes.bouncing_ball import BouncingBall
>>> [s["kind"] for s in BouncingBall().shapes([0.5], 0.0)]
['line', 'circle', 'contact']
"""

import math

import numpy as np

from ..errors import InputError
from ..model.units import DriveUnits

__all__ = ["circle", "polygon", "line", "contact", "scene_state", "rod_drive_shapes"]


def _pt(p):
    return (float(p[0]), float(p[1]))


def circle(centre, radius, role="body"):
    return {"kind": "circle", "centre": _pt(centre), "radius": float(radius), "role": role}


def polygon(points, role="body"):
    return {"kind": "polygon", "points": [_pt(p) for p in points], "role": role}


def line(points, role="body"):
    return {"kind": "line", "points": [_pt(p) for p in points], "role": role}


def contact(index, point, normal, tangent=None):
    n = np.asarray(normal, dtype=float)
    t = np.array([n[1], -n[0]]) if tangent is None else np.asarray(tangent, dtype=float)
    return {"kind": "contact", "index": int(index), "point": _pt(point), "normal": _pt(n),
            "tangent": _pt(t)}


def scene_state(scene, q, t):
    """``(q, t)`` in the scene's own units from SI coordinates ``q`` and time ``t`` [s]."""
    q = np.asarray(q, dtype=float).reshape(-1)
    if q.size != scene.ndof:
        raise InputError(f"`q` must have {scene.ndof} coordinates for scene {scene.name!r}, "
                         f"got {q.size}")
    if isinstance(scene, DriveUnits):     # a drive: lengths over the rod length, tau = w t
        angles = set(getattr(scene, "angle_coordinates", ()))
        scale = np.array([1.0 if i in angles else scene.params.length for i in range(q.size)])
        return q / scale, float(t) * scene.omega
    scale = np.broadcast_to(np.asarray(scene._qscale(), dtype=float), q.shape)
    return q / scale, float(t) / scene.time


def rod_drive_shapes(scene, q, t, rods, rotor):
    """Shapes of a rod drive: each rod from its hinge on the stator to its tip on the rotor.

    ``rods`` are ``(angle coordinate, side)`` pairs (side +1: tip towards
    ``+x``), ``rotor`` the rotor's coordinate. The tip's height is read from
    the scene's own gap (the rotor surface, at ``l sin phi0``, minus the
    gap), so a stator that moves (prescribed or a coordinate of its own) and a
    bending rod are placed where the scene has them; the rod is drawn as the
    chord from its hinge to its tip.
    """
    qs, tau = scene_state(scene, q, t)
    ell = scene.params.length
    s0 = scene.sin_phi0
    c0 = math.sqrt(1.0 - s0 * s0)
    gaps = np.asarray(scene.gaps(qs, tau), dtype=float)
    x_rotor = c0 + qs[rotor]
    out = [polygon([(x_rotor - 0.6, s0), (x_rotor + 0.6, s0), (x_rotor + 0.6, s0 + 0.15),
                    (x_rotor - 0.6, s0 + 0.15)])]
    contacts = []
    for i, (k, side) in enumerate(rods):
        phi = qs[k]
        hinge_x = 0.0 if side > 0 else 2.0 * c0
        tip = (hinge_x + side * math.cos(phi), s0 - gaps[i])
        hinge = (hinge_x, tip[1] - math.sin(phi))
        out.append(polygon([(hinge[0] - 0.1, hinge[1] - 0.1), (hinge[0] + 0.1, hinge[1] - 0.1),
                            (hinge[0] + 0.1, hinge[1]), (hinge[0] - 0.1, hinge[1])],
                           role="stator"))
        out.append(line([hinge, tip]))
        # the normal force pushes the tip down, away from the rotor; friction along x
        contacts.append(contact(i, tip, (0.0, -1.0), (1.0, 0.0)))
    scaled = []
    for s in out + contacts:
        s = dict(s)
        for key in ("centre", "point"):
            if key in s:
                s[key] = (s[key][0] * ell, s[key][1] * ell)
        if "points" in s:
            s["points"] = [(x * ell, y * ell) for x, y in s["points"]]
        scaled.append(s)
    return scaled
