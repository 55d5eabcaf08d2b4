"""Output at requested times (``t_eval``) and user events, the same for every scheme.

As in :func:`scipy.integrate.solve_ivp`: ``t_eval`` gives the times at which
the result is sampled, and ``events`` are functions ``event(t, y)`` of the
time and the state ``y = (q, v)`` whose zeros are located; an event with a
true ``terminal`` attribute stops the run, its ``direction`` attribute
restricts it to zeros crossed upwards (> 0) or downwards (< 0).

Each scheme hands :func:`~moreau.integrators.simulate` the motion of a step as
:class:`Piece` objects: a grid of times, the state between them and the
full sample (forces, slip, gap, regime) at any time in between.

* An event-driven scheme knows its motion between events exactly (the dense
  output of its smooth phases, or closed forms): its pieces are that motion,
  and an event is the root of the event function on it (Brent's method to a
  few ulps of time).
* A time-stepping scheme knows its state at the step ends only: its pieces
  are the linear interpolation between consecutive recorded samples (every
  step, or every ``save_every`` steps), so that an event is located to
  within one step by the sign change of the event function between two
  step ends, and ``t_eval`` samples are interpolated (the regime and the
  forces are those of the step that contains the time).
"""

import math

import numpy as np
from scipy.optimize import brentq

from .._validate import as_float, finite_scalar, float_array
from ..errors import InputError, MoreauError
from .result import STATUS_MESSAGES

__all__ = ["Piece", "OutputTracker", "check_t_eval", "check_events", "interpolated_piece",
           "stack_rows", "join_to_last"]


class Piece:
    """The motion of a scheme over ``[grid[0], grid[-1]]``.

    Parameters
    ----------
    grid : array_like
        Increasing times; an event function is checked for a sign change
        between consecutive ones.
    state : callable
        ``state(t) -> y``, the state ``(q, v)`` concatenated.
    sample : callable
        ``sample(t) -> (t, q, v, regime, force_N, force_T, slip, gap)``, the
        record of a :class:`~moreau.integrators.result.SimulationResult` row.
    states : ndarray, optional
        The states at the grid times, one row each, where they are at hand
        (recorded samples): they spare an evaluation of ``state`` per step.
    """

    __slots__ = ("grid", "state", "sample", "states")

    def __init__(self, grid, state, sample, states=None):
        self.grid = np.asarray(grid, dtype=float)
        self.state = state
        self.sample = sample
        self.states = states

    def state_at(self, k):
        """The state at ``grid[k]``."""
        return self.states[k] if self.states is not None else self.state(float(self.grid[k]))


def interpolated_piece(t, q, v, regime, force_N, force_T, slip, gap):
    """The piece of a time-stepping scheme between recorded samples (linear interpolation).

    Each argument holds the recorded samples in rows, the first row being the
    last sample of the previous piece. A time between two samples gets the
    linear interpolation of ``q, v``, the slip velocity and the gap, and the
    regime and the forces of the step that ends at the later sample (the
    scheme's own values over that step).

    Examples
    --------
    >>> import numpy as np
    >>> z = np.zeros((2, 1))
    >>> p = interpolated_piece(np.array([0.0, 0.5]), np.array([[1.0], [0.0]]), z,
    ...                        np.array([[0], [1]]), z, z, z, z)
    >>> p.state(0.125)
    array([0.75, 0.  ])
    >>> int(p.sample(0.125)[3][0])
    1
    """
    y = np.hstack([q, v])
    cont = np.hstack([q, v, slip, gap])
    n, nv = q.shape[1], v.shape[1]     # (a spatial scene: 7 coordinates, 6 velocities a body)
    nc = slip.shape[1]

    def state(s):
        return np.array([np.interp(s, t, col) for col in y.T])

    def sample(s):
        j = min(max(int(np.searchsorted(t, s, side="left")), 1), len(t) - 1)
        w = (s - t[j - 1]) / (t[j] - t[j - 1]) if t[j] > t[j - 1] else 1.0
        c = (1.0 - w) * cont[j - 1] + w * cont[j]
        return (s, c[:n], c[n:n + nv], regime[j].copy(), force_N[j].copy(), force_T[j].copy(),
                c[n + nv:n + nv + nc], c[n + nv + nc:])

    return Piece(t, state, sample, y)


def stack_rows(rows, n, nc, nv=None):
    """Recorded sample tuples as the arrays of :func:`interpolated_piece` (None if none).

    ``n`` coordinates, ``nv`` velocities (default ``n``), ``nc`` contacts.
    """
    if not rows:
        return None
    cols = list(zip(*rows))
    m = len(rows)
    return (np.array(cols[0], float), np.array(cols[1], float).reshape(m, n),
            np.array(cols[2], float).reshape(m, n if nv is None else nv), np.array(cols[3], int).reshape(m, nc),
            *(np.array(c, float).reshape(m, nc) for c in cols[4:]))


def join_to_last(integ, arrays):
    """Prepend the last sample ``integ`` handed over before, so that its pieces join.

    Returns None while fewer than two samples make a piece.
    """
    if arrays is None:
        return None
    if integ.last_handed is not None:
        arrays = tuple(np.concatenate([a[None], b]) for a, b in zip(integ.last_handed, arrays))
    integ.last_handed = tuple(a[-1].copy() for a in arrays)
    return arrays if len(arrays[0]) >= 2 else None


def check_t_eval(t_eval, t0, t1):
    """``t_eval`` as a float array: finite, increasing, inside ``[t0, t1]``.

    Examples
    --------
    >>> check_t_eval([0.0, 0.5, 1.0], 0.0, 1.0)
    array([0. , 0.5, 1. ])
    >>> check_t_eval([0.5, 0.2], 0.0, 1.0)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `t_eval` must be sorted in increasing order; t_eval[1] = 0.2 follows 0.5
    """
    a = float_array("t_eval", t_eval, "an array of times")
    if a.ndim != 1:
        raise InputError(f"`t_eval` must be one-dimensional, got shape {a.shape}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InputError(f"`t_eval` must be finite; t_eval[{bad[0]}] = {float(a[bad[0]])!r}")
    down = np.flatnonzero(np.diff(a) <= 0.0)
    if down.size:
        k = down[0] + 1
        raise InputError(f"`t_eval` must be sorted in increasing order; t_eval[{k}] = "
                         f"{float(a[k])!r} follows {float(a[k - 1])!r}")
    out = np.flatnonzero((a < t0) | (a > t1))
    if out.size:
        k = out[0]
        raise InputError(f"`t_eval` must lie inside `t_span` = ({t0!r}, {t1!r}); "
                         f"t_eval[{k}] = {float(a[k])!r}")
    return a


def check_events(events):
    """The event functions as a list; each callable, with valid ``terminal``/``direction``.

    Examples
    --------
    >>> def down(t, y): return y[0] - 0.5
    >>> down.terminal, down.direction = True, -1
    >>> [f.__name__ for f in check_events(down)]
    ['down']
    >>> check_events([lambda t, y: y[0], 3])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `events[1]` must be a callable event(t, y), got 3
    """
    if events is None:
        return []
    funcs = list(events) if isinstance(events, (list, tuple)) else [events]
    for i, f in enumerate(funcs):
        if not callable(f):
            raise InputError(f"`events[{i}]` must be a callable event(t, y), got {f!r}")
        term = getattr(f, "terminal", False)
        if not isinstance(term, (bool, np.bool_, int, np.integer)) or term < 0:
            raise InputError(f"`events[{i}].terminal` must be a bool or a count >= 0 of "
                             f"occurrences, got {term!r}")
        finite_scalar(f"events[{i}].direction", getattr(f, "direction", 0.0))
    return funcs


def _limit(f):
    # solve_ivp's convention: True stops at the first occurrence, an int n at the n-th
    term = getattr(f, "terminal", False)
    if isinstance(term, (bool, np.bool_)):
        return 1 if term else 0
    return int(term)


class OutputTracker:
    """Collects ``t_eval`` samples and locates events over the pieces of a run.

    Parameters
    ----------
    t0, y0 : float, ndarray
        Start of the run.
    t_eval : ndarray or None
    events : list of callables
    exact : bool
        Whether the pieces are the scheme's exact motion (event-driven) or
        interpolated between step ends (time stepping).
    """

    def __init__(self, t0, y0, t_eval, events, exact):
        self.t_eval = t_eval
        self.events = events
        self.exact = exact
        self.samples = []
        self.t_events = [[] for _ in events]
        self.y_events = [[] for _ in events]
        self.counts = [0] * len(events)
        self.limits = [_limit(f) for f in events]
        self.directions = [float(getattr(f, "direction", 0.0)) for f in events]
        self.stop = None        # (t, bracket) of the terminal event
        self._stop_piece = None
        self._k = 0             # next t_eval index
        self._t_last = float(t0)
        self._g_last = [self._g(i, t0, y0) for i in range(len(events))]

    def _g(self, i, t, y):
        g = as_float(f"events[{i}]", self.events[i](t, y), "return a real number")
        if not math.isfinite(g):
            raise MoreauError(f"`events[{i}]` returned {g!r} at t = {t!r}")
        return g

    def feed(self, pieces):
        """Take the pieces of one step; return True when a terminal event stops the run."""
        for p in pieces:
            if self.stop is None:
                self._events_on(p)
                if self.stop is not None:
                    self._stop_piece = p
            end = p.grid[-1] if self.stop is None else self.stop[0]
            self._samples_on(p, end)
            if self.stop is not None:
                return True
        return False

    def _samples_on(self, p, end):
        te = self.t_eval
        if te is None:
            return
        # the pieces follow one another: every time left before `end` lies in this one
        while self._k < len(te) and te[self._k] <= end:
            s = te[self._k]
            self.samples.append(p.sample(min(max(s, p.grid[0]), p.grid[-1])))
            self._k += 1

    def _events_on(self, p):
        grid = p.grid
        if not self.events or len(grid) == 0:
            return
        # a jump between pieces (an impact changes the velocities): a sign change across
        # it is an event at the jump
        ta = float(grid[0])
        ya = p.state_at(0)
        prev = self._g_last
        ga = [self._g(i, ta, ya) for i in range(len(self.events))]
        found = self._crossings(prev, ga, lambda i: (ta, ya), (self._t_last, ta))
        if found:
            return
        for k in range(1, len(grid)):
            a, b = float(grid[k - 1]), float(grid[k])
            if b <= a:
                continue
            yb = p.state_at(k)
            gb = [self._g(i, b, yb) for i in range(len(self.events))]

            def root(i, a=a, b=b, ga=ga, gb=gb):
                if gb[i] == 0.0:
                    t = b
                else:
                    t = brentq(lambda s: self._g(i, s, p.state(s)), a, b,
                               xtol=4.0 * np.finfo(float).eps * max(1.0, abs(b)), rtol=1e-15,
                               maxiter=200)
                return t, p.state(t)

            if self._crossings(ga, gb, root, (a, b)):
                return
            ga = gb
        self._t_last = float(grid[-1])
        self._g_last = ga

    def _crossings(self, ga, gb, locate, bracket):
        """Record the events whose sign changes from ``ga`` to ``gb``; True if one stops the run."""
        hits = []
        for i, d in enumerate(self.directions):
            up = ga[i] < 0.0 <= gb[i]
            down = ga[i] > 0.0 >= gb[i]
            if (up and d >= 0.0) or (down and d <= 0.0):
                t, y = locate(i)
                hits.append((t, i, y))
        stop = None
        for t, i, y in sorted(hits, key=lambda h: h[0]):
            self.t_events[i].append(t)
            self.y_events[i].append(np.array(y, dtype=float))
            self.counts[i] += 1
            if self.limits[i] and self.counts[i] >= self.limits[i]:
                stop = (t, bracket)
                break
        if stop is not None:
            # events after the stopping one did not happen
            for i in range(len(self.events)):
                while self.t_events[i] and self.t_events[i][-1] > stop[0]:
                    self.t_events[i].pop()
                    self.y_events[i].pop()
            self.stop = stop
            self._t_last = stop[0]
            return True
        return False

    def finish(self, result):
        """Apply the samples, the events and the terminal stop to ``result`` (in place)."""
        result.t_events = [np.array(t, dtype=float) for t in self.t_events]
        result.y_events = [np.array(y, dtype=float).reshape(len(t), -1) if t else
                           np.zeros((0, result.q.shape[1] * 2))
                           for t, y in zip(self.t_events, self.y_events)]
        if self.stop is not None:
            # the stop came before anything the scheme did after it (a compiled block runs
            # on past it, and may fail there)
            t_stop, (a, b) = self.stop
            result.status = 1
            if self.exact:
                how = (f"at t = {t_stop!r}, a root of the event function on the scheme's own "
                       f"continuous motion (its dense output)")
            else:
                how = (f"between the step ends t = {a!r} and {b!r} (by the sign change of the "
                       f"event function; t_events holds the linear interpolation's root, "
                       f"{t_stop!r}, to within one step)")
            result.message = f"{STATUS_MESSAGES[1]} It is located {how}."
            result.events = [e for e in result.events if e.t <= t_stop]
            if self.t_eval is None:
                # the run ends at the event (exact motion) or at the end of the step over which
                # it changed sign (time stepping)
                cut = t_stop if self.exact else b
                keep = result.t <= cut
                if self.exact and (not keep.any() or result.t[keep][-1] < t_stop):
                    row = self._stop_piece.sample(t_stop)
                    _truncate(result, keep)
                    _append(result, row)
                else:
                    _truncate(result, keep)
        if self.t_eval is not None:
            _replace(result, self.samples, result.q.shape[1], result.gap.shape[1],
                     result.v.shape[1])
        return result


_FIELDS = ("t", "q", "v", "regime", "force_N", "force_T", "slip_velocity", "gap")


def _truncate(result, keep):
    for name in _FIELDS:
        setattr(result, name, getattr(result, name)[keep])


def _append(result, row):
    for name, x in zip(_FIELDS, row):
        arr = getattr(result, name)
        setattr(result, name, np.concatenate([arr, np.asarray(x, arr.dtype).reshape(1, *arr.shape[1:])]))


def _replace(result, rows, n, nc, nv=None):
    nv = n if nv is None else nv
    if rows:
        cols = list(zip(*rows))
        arrays = [np.array(cols[0], float)]
        arrays += [np.array(cols[1], float).reshape(len(rows), n),
                   np.array(cols[2], float).reshape(len(rows), nv)]
        arrays += [np.array(cols[3], int).reshape(len(rows), nc)]
        arrays += [np.array(c, float).reshape(len(rows), nc) for c in cols[4:]]
    else:
        arrays = [np.zeros(0), np.zeros((0, n)), np.zeros((0, nv)), np.zeros((0, nc), int)]
        arrays += [np.zeros((0, nc)) for _ in range(4)]
    for name, a in zip(_FIELDS, arrays):
        setattr(result, name, a)
