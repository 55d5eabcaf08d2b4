"""Natural continuation of periodic steady states along a line of parameter points.

A sweep or an atlas line asks for the steady state at many nearby parameter
points. A cold start shoots from the scene's rest state and spends most of
its period maps getting close to the orbit; the neighbour's orbit is
already close. :func:`continue_point` starts the shooting at a point from
the periodic state of the previous point (its state at its Poincaré
section, :func:`moreau.analysis.steady_state.find_steady_state`'s
``guess``), moved along the secant through the two previous orbits where
there are two (:func:`predicted_guess`: the predictor of natural
continuation, one order closer than the neighbour's orbit itself). Where
that does not converge, the parameter step is halved:
the orbit is continued to the midpoint first and from there to the point,
up to ``max_halvings`` times. Where even that fails the caller falls back
to a cold start (:func:`solve_line`), so continuation never loses a point a
cold start would have found; it can only land on another orbit where two
coexist (the neighbour's branch, as a slowly swept experiment would).

Examples
--------
>>> from dataclasses import asdict
>>> from moreau.scenes import make_scene
>>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
>>> from moreau.analysis.scheme_settings import ED_REFERENCE, steady_of
>>> def solve(point, guess):
...     p, f = point
...     return steady_of(make_scene("friction-drive", frequency=f, **p), ED_REFERENCE,
...                      guess=guess)
>>> pts = [(asdict(PAPER_DEFAULTS.with_(mu=m)), 2000.0) for m in (0.2, 0.22, 0.24)]
>>> out = solve_line(pts, solve)
>>> [(o["start"], o["steady"].mode) for o in out]
[('cold', 'NP'), ('continued', 'NP'), ('continued', 'NP')]
"""

import copy
import math
import numbers
import time

import numpy as np

__all__ = ["midpoint", "continue_point", "solve_line", "predicted_guess", "MAX_HALVINGS",
           "START_VALUES"]

#: halvings of the parameter step tried before a cold start
MAX_HALVINGS = 1

#: the values of a row's ``start`` column: from the neighbour's orbit, from the scene's
#: rest state (first point, or after a failed neighbour), or from rest after the
#: continuation failed at every step size
START_VALUES = ("continued", "cold", "cold-fallback")


def _is_number(x):
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def midpoint(a, b):
    """The parameter point halfway between two points ``(params, frequency)``.

    Numeric parameters that differ are averaged, a frequency geometrically
    (the grids are log-spaced in frequency); everything else is ``b``'s.

    Examples
    --------
    >>> midpoint(({"mu": 0.2, "law": "x"}, 100.0), ({"mu": 0.4, "law": "x"}, 400.0))
    ({'mu': 0.30000000000000004, 'law': 'x'}, 200.0)
    """
    (pa, fa), (pb, fb) = a, b
    p = {}
    for k, vb in pb.items():
        va = pa.get(k, vb)
        p[k] = 0.5 * (va + vb) if _is_number(va) and _is_number(vb) and va != vb else vb
    if fa is None or fb is None:
        f = fb
    elif fa > 0 and fb > 0:
        f = math.sqrt(fa * fb)
    else:
        f = 0.5 * (fa + fb)
    return p, f


def _step_ratio(a, b, c):
    """``|c - b| / |b - a|`` along the first quantity that varies, or None (unequal or no steps)."""
    (pa, fa), (pb, fb), (pc, fc) = a, b, c
    pairs = [(fa, fb, fc)] + [(pa.get(k), pb.get(k), pc.get(k)) for k in pc]
    for x, y, z in pairs:
        if not all(_is_number(v) for v in (x, y, z)) or x == y == z:
            continue
        if x == y:
            return None
        r = (z - y) / (y - x)
        return r if 0.0 < r <= 2.0 else None
    return None


def predicted_guess(older, previous, point):
    """The previous orbit moved along the secant of the last two: a start one order closer.

    ``older`` and ``previous`` are ``(point, SteadyState)`` of the two
    neighbours before ``point`` on the line. Where both orbits have the
    same mode, section and state size and the parameter steps are
    comparable, the guess is ``previous``'s orbit with its section state
    extrapolated linearly to ``point`` (the secant predictor of natural
    continuation: its error is second order in the step instead of first);
    otherwise ``previous``'s orbit itself.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> a = (({"mu": 0.1}, 100.0), NS(mode="NS", section_tau=0.0, state0=[1.0, 2.0]))
    >>> b = (({"mu": 0.2}, 100.0), NS(mode="NS", section_tau=0.0, state0=[1.5, 2.0]))
    >>> predicted_guess(a, b, ({"mu": 0.3}, 100.0)).state0.tolist()
    [2.0, 2.0]
    """
    (pa, sa), (pb, sb) = older, previous
    if sa is None or sb is None:
        return sb
    xa = np.asarray(getattr(sa, "state0", ()), dtype=float)
    xb = np.asarray(getattr(sb, "state0", ()), dtype=float)
    same = (getattr(sa, "mode", None) == getattr(sb, "mode", None)
            and getattr(sa, "section_tau", None) == getattr(sb, "section_tau", None)
            and xa.shape == xb.shape and xa.size > 0)
    r = _step_ratio(pa, pb, point) if same else None
    if r is None:
        return sb
    guess = copy.copy(sb)
    guess.state0 = xb + r * (xb - xa)
    return guess


def continue_point(solve, previous, steady, point, max_halvings=MAX_HALVINGS, first_guess=None):
    """The steady state at ``point`` continued from ``steady``, the orbit at ``previous``.

    Parameters
    ----------
    solve : callable
        ``solve(point, guess)`` returns the steady state at ``point`` shot
        from the orbit ``guess``, or raises (a
        :class:`~moreau.errors.MoreauError` where it finds none).
    previous, point : (dict, float)
        Parameter points ``(params, frequency)``.
    steady : SteadyState
        The period-1 orbit at ``previous``.
    max_halvings : int
        How often the step may be halved (the orbit continued to the
        midpoint first) where a step fails.
    first_guess : SteadyState, optional
        The start of the direct step (:func:`predicted_guess`); ``steady``
        by default. The halved steps start from ``steady``.

    Returns
    -------
    steady : SteadyState
    solves : int
        Shootings that converged on the way (1 for a direct step).

    Raises
    ------
    Exception
        The last failure, where no step size led to ``point``.
    """
    try:
        return solve(point, steady if first_guess is None else first_guess), 1
    except Exception:  # any failure of a step is a reason to halve it
        if max_halvings <= 0:
            raise
    mid = midpoint(previous, point)
    ss_mid, n1 = continue_point(solve, previous, steady, mid, max_halvings - 1)
    ss, n2 = continue_point(solve, mid, ss_mid, point, max_halvings - 1)
    return ss, n1 + n2


def _periodic(ss):
    return (ss is not None and not getattr(ss, "statistical", False)
            and getattr(ss, "period", 1) == 1)


def solve_line(points, solve, continuation=True, max_halvings=MAX_HALVINGS, predict=True):
    """Steady states along a line of points, each continued from the previous one's orbit.

    Parameters
    ----------
    points : list of (dict, float)
        Neighbouring parameter points, in order.
    solve : callable
        ``solve(point, guess)``: the steady state at ``point``, shot from the
        orbit ``guess`` (None: a cold start); raises where it finds none.
    continuation : bool
        False: every point starts cold.
    predict : bool
        Start each continued point from the secant prediction of the two
        previous orbits (:func:`predicted_guess`); False: from the
        neighbour's orbit itself.

    Returns
    -------
    list of dict
        Per point: ``steady`` (the SteadyState or None), ``error`` (the
        exception of a failed point or None), ``start`` (one of
        :data:`START_VALUES`) and ``solves`` (continuation shootings that
        converged; 0 for a cold start), ``seconds`` (spent on the point).
    """
    out = []
    prev = older = None
    for point in points:
        t0 = time.perf_counter()
        rec = {"steady": None, "error": None, "start": "cold", "solves": 0}
        if continuation and prev is not None:
            first = (predicted_guess(older, prev, point) if predict and older is not None
                     else None)
            try:
                rec["steady"], rec["solves"] = continue_point(solve, prev[0], prev[1], point,
                                                              max_halvings, first)
                rec["start"] = "continued"
            except Exception:  # the cold start below says why the point fails, if it does
                rec["start"] = "cold-fallback"
        if rec["steady"] is None:
            try:
                rec["steady"] = solve(point, None)
            except Exception as exc:  # a failed point is a row with its cause, never a stop
                rec["error"] = exc
        # the secant of the next prediction joins two orbits of one branch: not across a
        # cold fallback, which may have landed on another
        older = prev if rec["start"] != "cold-fallback" else None
        prev = (point, rec["steady"]) if _periodic(rec["steady"]) else None
        rec["seconds"] = time.perf_counter() - t0
        out.append(rec)
    return out
