"""Comparison cases: a scene set up for ``moreau compare`` (reference, start, headline).

A registered scene names its case in its registry entry
(:class:`moreau.model.registry.SceneEntry`, field ``case``); the case class
lives in the scene's own module and derives from the generic classes here:

:class:`CompareCase`
    the base: the reference (``reference(rtol)``, ``reference_grid()``), the
    start state, the headline quantity of a Moreau–Jean run, and how errors
    and switching times are measured;
:class:`DriveCase`
    a periodically driven scene whose headline is the displacement of a
    cyclic coordinate over one steady period, with the generic event-driven
    steady state as its reference;
:class:`SceneCase`
    any scene instance, registered or not, over a window from a given state:
    the generic event-driven scheme at a tight tolerance is the reference and
    the headline is the main coordinate at the end of the window (what
    :func:`moreau.analysis.compare.compare` uses for a user's own scene).

Examples
--------
>>> import numpy as np
>>> from moreau.scenes.bouncing_ball import BouncingBall
>>> case = SceneCase(BouncingBall(), (0.0, 1.0), [1.0], [0.0])
>>> value, switches = case.reference(1e-10)
>>> round(value, 6) == round(float(BouncingBall().exact_solution(np.array([1.0]), [1.0], [0.0])[0][0, 0]), 6)
True
"""

import math

import numpy as np

from .._validate import finite_array
from ..errors import InputError, MoreauError, ResidualFloorError
from ..integrators import get_integrator, simulate
from ..integrators.base import scheme_options
from ..model.registry import MJ_TOLERANCE
from ..regimes import REGIME_LETTERS
from .mj_steady_state import moreau_jean_steady_state
from .scheme_settings import make_scheme, steady_of
from .steady_state import find_steady_state

__all__ = ["CompareCase", "DriveCase", "FactoryCase", "SceneCase", "SpatialCase", "ExactReference", "ClosedFormPath", "GRID", "switching_error", "flatten",
           "contact_switches", "regime_switches", "switches", "drop_reversal_sticks"]

TWO_PI = 2.0 * math.pi
#: samples per period of the common grid of the trajectory error
GRID = 50


def switches(letters, times):
    """``[(t, letter)]`` at every change of the per-sample letter (first entry excluded)."""
    out = []
    for i in range(1, len(letters)):
        if letters[i] != letters[i - 1]:
            out.append((float(times[i]), letters[i]))
    return out


def drop_reversal_sticks(sw, h):
    # a one-step stick between slips of opposite sign is a reversal inside
    # the step (see moreau.analysis.mj_steady_state): the continuous system
    # has no stick there
    out = []
    i = 0
    while i < len(sw):
        if (i + 1 < len(sw) and sw[i][1] == "S" and sw[i + 1][0] - sw[i][0] <= 1.5 * h
                and out and {out[-1][1], sw[i + 1][1]} == {"N", "P"}):
            out.append((0.5 * (sw[i][0] + sw[i + 1][0]), sw[i + 1][1]))
            i += 2
            continue
        out.append(sw[i])
        i += 1
    merged = []
    for t, s in out:
        if not merged or merged[-1][1] != s:
            merged.append((t, s))
    return merged


def switching_error(ref, got):
    """Largest shift between matched switching times, None if the sequences differ or are empty.

    Examples
    --------
    >>> switching_error([(1.0, "P"), (2.0, "S")], [(1.1, "P"), (1.95, "S")])
    0.1
    >>> switching_error([(1.0, "P")], [(1.0, "S")]) is None
    True
    """
    if not ref or len(ref) != len(got) or any(a[1] != b[1] for a, b in zip(ref, got)):
        return None
    return float(round(max(abs(a[0] - b[0]) for a, b in zip(ref, got)), 15))


def regime_switches(regimes):
    """Switches of a steady state's ``[[tau, letter], ...]`` (the entry at tau = 0 dropped)."""
    return [(float(t), s) for t, s in regimes[1:]]


def contact_switches(regimes, tau_s, contact, h=0.0):
    """Switches ``[(tau, letter)]`` of one contact over ``[0, 2 pi)`` from a steady state's regimes.

    ``regimes`` holds ``[tau - tau_s, key]`` with one letter per contact in
    ``key``; one-step sticks at a slip reversal (``h`` > 0) are dropped as in
    the single-contact case.
    """
    pts = sorted(((float(t) + tau_s) % TWO_PI, k[contact]) for t, k in regimes)
    sw = [(0.0, pts[-1][1] if pts[0][0] > 1e-12 else pts[0][1])]
    for t, letter in pts:
        if letter != sw[-1][1]:
            sw.append((t, letter))
    return drop_reversal_sticks(sw, h)[1:]


def flatten(per_contact):
    """One switch list from per-contact lists: ``(tau, "c:letter")``, contact by contact.

    Examples
    --------
    >>> flatten([[(2.0, "S")], [(1.0, "P"), (3.0, "N")]])
    [(2.0, '0:S'), (1.0, '1:P'), (3.0, '1:N')]
    """
    return [(t, f"{c}:{s}") for c, sw in enumerate(per_contact) for t, s in sw]


class CompareCase:
    """One scene set up for comparison (a subclass per scene)."""

    #: the scene's conformance tolerance, its registry entry's ``mj_tolerance``: how close
    #: Moreau–Jean at 1000 steps must come to the reference, relative to its size
    mj_tolerance = MJ_TOLERANCE
    #: the reference the scene's registry entry lists (its ``reference``): "exact" for the
    #: model's exact motion (:class:`ExactReference`), None for the generic event-driven scheme
    listed_reference = None
    #: the name of the reference's rows in ``moreau compare``
    ref_scheme = "exact"
    ref_rtols = (None,)
    tight_rtol = None
    window = TWO_PI            # the "period" the steps are counted over
    headline_name = ""
    projection = False
    #: whether a Moreau–Jean row's switching times are measured against the reference's
    #: (False: the row is compared on its headline and trajectory only)
    compares_switches = True

    def parameters(self):
        return {}

    # reference ---------------------------------------------------------------
    def reference(self, rtol):
        """``(headline, switches)`` of the reference at ``rtol``."""
        raise NotImplementedError

    def reference_grid(self):
        """The main coordinate of the tight reference on the common grid."""
        raise NotImplementedError

    # Moreau–Jean ---------------------------------------------------------------
    def start(self):
        """``(q0, v0)`` at ``t = 0`` for the runs."""
        raise NotImplementedError

    def coordinate(self, q):
        return q[:, 0]

    def headline_of_run(self, res):
        """The headline of a run: by default its :meth:`coordinate` at the last sample."""
        return float(self.coordinate(res.q[-1:])[0])

    def run_mj(self, n, theta, lcp):
        q0, v0 = self.start()
        # every step is kept: the switching times need each step's regime
        opts = dict(h=self.window / n, theta=theta, projection=self.projection)
        if lcp is not None:
            opts["lcp_method"] = lcp
        return simulate(self.scene, (0.0, self.window), q0, v0, "moreau-jean", **opts)

    def mj(self, n, theta, lcp):
        """``(headline, run)``: the timed work of one Moreau–Jean row."""
        res = self.run_mj(n, theta, lcp)
        if not res.success:
            raise MoreauError(f"Moreau–Jean run failed: {res.message}")
        return self.headline_of_run(res), res

    def run_scheme(self, name, options):
        """A run of the registered scheme ``name`` over the window, sampled on the grid.

        ``steps_per_period`` in ``options`` is a time-stepping scheme's number
        of steps over the window (its ``h``), as in the Moreau–Jean rows.
        """
        q0, v0 = self.start()
        return simulate(self.scene, (0.0, self.window), q0, v0, name,
                        **self._run_options(name, options))

    def _run_options(self, name, options):
        opts = dict(options)
        n = opts.pop("steps_per_period", None)
        if n is not None:
            opts["h"] = self.window / n
        if "sample_dt" in (scheme_options(get_integrator(name)) or ()):
            opts.setdefault("sample_dt", self.window / GRID)
        return opts

    def scheme(self, name, options):
        """``(headline, run)``: the timed work of one row of another scheme."""
        res = self.run_scheme(name, options)
        if not res.success:
            raise MoreauError(f"{name} run failed: {res.message}")
        return self.headline_of_run(res), res

    def measure_scheme(self, name, options, out):
        """The trajectory error of another scheme's row, from its timed output."""
        return self._trajectory_error(out[1])

    def measure(self, n, theta, lcp, out):
        """``(trajectory_error, switches, mode)`` of a Moreau–Jean row from its timed output."""
        _, res = out
        switches = self._run_switches(res, self.window / n) if self.compares_switches else []
        return self._trajectory_error(res), switches, None

    def _on_grid(self, res):
        """Whether the run ``res`` has a sample at every time of the comparison grid."""
        grid = np.linspace(0.0, self.window, GRID + 1)
        idx = np.minimum(np.searchsorted(res.t, grid - 1e-9 * self.window), len(res.t) - 1)
        return bool(np.max(np.abs(res.t[idx] - grid)) <= 1e-9 * self.window)

    def _trajectory_error(self, res):
        grid = np.linspace(0.0, self.window, GRID + 1)
        idx = np.searchsorted(res.t, grid - 1e-9 * self.window)
        idx = np.minimum(idx, len(res.t) - 1)
        if np.max(np.abs(res.t[idx] - grid)) > 1e-9 * self.window:
            # the samples are not on the grid (steps not a multiple of GRID): interpolate
            y = np.interp(grid, res.t, self.coordinate(res.q))
        else:
            y = self.coordinate(res.q)[idx]
        return float(np.max(np.abs(y - self.reference_grid())) / self.trajectory_scale)

    trajectory_scale = 1.0

    def _run_switches(self, res, h):
        return self._run_switches_of(res, h, 0)

    def _run_switches_of(self, res, h, contact):
        letters = res.regime_letters(contact)
        t = res.t - h
        # a step's regime is recorded at its end: the switch happened in that step.
        # The regime in force at the start goes in front, so that a one-step
        # stick at the first switch is recognised as a reversal too
        sw = [(float(t[0]), letters[0])] + switches(letters, t)
        return drop_reversal_sticks(sw, h)[1:]


class FactoryCase(CompareCase):
    """A case on one scene, ``scene_factory(**params)``, from its initial state.

    A subclass names its factory (``scene_factory = staticmethod(make)``); the
    case keeps the scene, its SI parameters as ``p`` (where the scene has
    them), and reports the scene's keyword parameters with the window.
    """

    scene_factory = None

    def __init__(self, **params):
        self._params = dict(params)
        self.scene = type(self).scene_factory(**params)
        self.p = getattr(self.scene, "params", None)

    def parameters(self):
        return dict(self._params, window=self.window)

    def start(self):
        return self.scene.initial_state()


class SpatialCase(FactoryCase):
    """A spatial scene's case: its Moreau–Jean rows solve the exact friction cone.

    The default cone of Moreau–Jean (8 directions) carries the facets' error
    (:mod:`moreau.contact.cone3d`); the case's own rows measure the time
    step's error, on the exact cone.
    """

    cone = "exact"

    def run_mj(self, n, theta, lcp):
        # `lcp` "cone=d" or "cone=exact" forces that cone (compare's facet rows)
        cone = self.cone
        if isinstance(lcp, str) and lcp.startswith("cone="):
            c = lcp.split("=", 1)[1]
            cone = int(c) if c.isdigit() else c
        q0, v0 = self.start()
        return simulate(self.scene, (0.0, self.window), q0, v0, "moreau-jean",
                        h=self.window / n, theta=theta, cone=cone)


class ExactReference:
    """A mixin for a case whose reference is the model's exact motion (a closed form where
    there is one): the scene's registry entry lists its reference as "exact"."""

    listed_reference = "exact"


class ClosedFormPath(ExactReference):
    """A mixin for a case whose reference is a closed form of its coordinate in time.

    The subclass gives :meth:`path`; the reference is that path at the end
    of the window and on the comparison grid, the headline the coordinate at
    the run's last sample, and no switch is compared (the regime holds over
    the window, :meth:`first_regime`).
    """

    compares_switches = False

    def path(self, tau):
        """The coordinate (scene units) at the scene times ``tau`` (an array)."""
        raise NotImplementedError

    def first_regime(self):
        """The regime letter that holds over the window."""
        return "S"

    def reference(self, rtol):
        return float(self.path(np.array([self.window]))[0]), [(0.0, self.first_regime())]

    def reference_grid(self):
        return self.path(np.linspace(0.0, self.window, GRID + 1))


class DriveCase(CompareCase):
    """A periodically driven scene (``scene.period``) whose headline is the
    displacement of its cyclic coordinate over one steady period.

    The reference is the scene's event-driven steady state
    (:func:`moreau.analysis.steady_state.find_steady_state`) at each of
    :attr:`ref_rtols`; Moreau–Jean rows are the discrete steady states
    (the fixed point of the compiled period map). ``_tight()`` gives the
    reference's periodic state at ``tau = 0`` and its trajectory on the
    comparison grid. A subclass names its :attr:`scene_class` (and may
    override the reference where the scene has its own walker);
    ``Case(frequency=None, **params)`` builds the scene and keeps the
    parameters for :meth:`parameters`.
    """

    ref_scheme = "event-driven"
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10)
    tight_rtol = 1e-12
    headline_name = "displacement per period"
    projection = True
    _ref = None
    #: the scene, built as ``scene_class(frequency=..., **params)``
    scene_class = None
    #: its drive frequency [Hz] when the caller gives none
    default_frequency = 185.0
    #: parameters given to the scene where the caller does not give them
    default_params = {}

    def __init__(self, frequency=None, **params):
        for key, value in self.default_params.items():
            params[key] = params.pop(key, value)
        f = self.default_frequency if frequency is None else frequency
        self.scene = self.scene_class(frequency=f, **params)
        self.frequency = self.scene.frequency
        self._params = params
        self.trajectory_scale = self.scale_of(self.scene)

    @staticmethod
    def scale_of(scene):
        """The size of the cyclic coordinate's motion, the unit of the trajectory errors."""
        return scene.u10

    def parameters(self):
        return dict(frequency=self.frequency, **self._params)

    @property
    def cyclic(self):
        return int(self.scene.cyclic_coordinates[0])

    def reference_grid(self):
        return self._tight()["grid"]

    def start(self):
        r = self._tight()
        return r["q0"].copy(), r["v0"].copy()

    def coordinate(self, q):
        return q[:, self.cyclic]

    def headline_of_run(self, res):
        return float(res.q[-1, self.cyclic] - res.q[0, self.cyclic])

    def mj(self, n, theta, lcp):
        # every row's headline is its scheme's own steady state, and its time the time
        # to compute it, whichever contact solver the steps use
        ss = moreau_jean_steady_state(self.scene, n, theta=theta, projection=self.projection,
                                      lcp_method=lcp or "auto")
        return ss.displacement_per_period, ss

    def scheme(self, name, options):
        # any scheme's headline on a drive is its own periodic steady state (the fixed
        # point of the period map it computes), as for the reference and Moreau-Jean
        opts = dict(options)
        n = opts.pop("steps_per_period", None)
        theta = opts.pop("theta", None)
        scheme = make_scheme(name, theta, n, None, opts)
        try:
            ss = steady_of(self.scene, scheme)
        except ResidualFloorError:
            # a time-stepping map whose fixed point exists only to a residual floor (its
            # switches locked to the step grid): its long-run mean, as `moreau steady`
            # gives it (the piezo drive under Schatzman-Paoli, the generalized-alpha and
            # TDG failed at every setting; their means are within 1.7 to 46 %)
            ss = steady_of(self.scene, scheme, statistical=True)
        return ss.displacement_per_period, ss

    def measure_scheme(self, name, options, out):
        # the trajectory: one period of the same scheme from the reference's periodic state
        res = self.run_scheme(name, options)
        if not res.success:
            raise MoreauError(f"{name} run failed: {res.message}")
        if self._on_grid(res):
            return self._trajectory_error(res)
        # samples off the grid, e.g. an adaptive scheme's steps (Studer's extrapolation, no
        # sample_dt): interpolating them onto the grid measured the interpolation, not the
        # scheme (friction drive, 185 Hz, tol 1e-11: 6.1e-4, for samples within ~3e-6 of the
        # reference). Measure at the scheme's own samples, against the reference's exact
        # motion at those times.
        t, first = np.unique(res.t, return_index=True)     # one sample per time
        inside = (t >= 0.0) & (t <= TWO_PI * (1.0 + 1e-12))
        t, first = np.minimum(t[inside], TWO_PI), first[inside]
        r = self._tight()
        ref = simulate(self.scene, (0.0, TWO_PI), r["q0"], r["v0"], "event-driven",
                       rtol=1e-12, t_eval=t)
        if not ref.success or len(ref.t) != len(t):
            raise MoreauError(f"the reference run at {name}'s samples failed: {ref.message}")
        y = self.coordinate(res.q)[first]
        return float(np.max(np.abs(y - self.coordinate(ref.q))) / self.trajectory_scale)

    def _switches_of_steady(self, ss, h=0.0):
        tau_s = float(getattr(ss, "section_tau", 0.0) or 0.0)
        return [contact_switches(ss.regimes, tau_s, c, h) for c in range(self.scene.ncontacts)]

    def reference(self, rtol):
        # the value and the switching times only: the multipliers would cost 2 n more
        # period maps on a scene whose reference shoots by finite differences
        ss = find_steady_state(self.scene, "event-driven", rtol=rtol, statistical=False,
                               floquet=False)
        return ss.displacement_per_period, flatten(self._switches_of_steady(ss))

    def _tight(self):
        if self._ref is None:
            ss = find_steady_state(self.scene, "event-driven", rtol=self.tight_rtol,
                                   statistical=False, floquet=False)
            n = self.scene.ndof
            q, v = ss.state0[:n].copy(), ss.state0[n:].copy()
            tau_s = float(getattr(ss, "section_tau", 0.0) or 0.0)
            if tau_s > 0.0:
                # carry the periodic state from the section to tau = 2 pi = 0
                r = simulate(self.scene, (tau_s, TWO_PI), q, v, "event-driven", rtol=1e-12)
                q, v = r.q[-1].copy(), r.v[-1].copy()
            for c in self.scene.cyclic_coordinates:
                q[c] = 0.0
            run = simulate(self.scene, (0.0, TWO_PI), q, v, "event-driven", rtol=1e-12,
                           sample_dt=TWO_PI / (8 * GRID))
            grid = np.linspace(0.0, TWO_PI, GRID + 1)
            self._ref = dict(q0=q, v0=v, grid=np.interp(grid, run.t, run.q[:, self.cyclic]))
        return self._ref

    def measure(self, n, theta, lcp, out):
        # the trajectory and the switching times: one period of the same scheme
        # from the reference's periodic state (the Moreau–Jean steady state names
        # the regimes of the first contact only)
        res = self.run_mj(n, theta, lcp)
        h = self.window / n
        sw = [self._run_switches_of(res, h, c) for c in range(self.scene.ncontacts)]
        mode = out[1].mode
        return self._trajectory_error(res), flatten(sw), mode


class SceneCase(CompareCase):
    """Any scene over ``t_span`` from ``(q0, v0)``: the case of a user's own scene.

    The reference is ``simulate(scene, ..., "event-driven")`` (the scene's own
    reference scheme where it names one, else the generic event-driven
    scheme) at ``rtol`` in :attr:`ref_rtols`, the tightest being
    :attr:`tight_rtol`. The headline is coordinate ``coordinate_index`` at the
    end of the window; the switching times are the reference's located
    regime changes (``"c:X"`` for contact ``c`` entering regime ``X``).

    Parameters
    ----------
    scene : Scene
        Any scene instance.
    t_span : (float, float)
        The window, in the scene's time.
    q0, v0 : array_like
        The start state.
    coordinate_index : int
        The coordinate whose end value is the headline.
    """

    ref_scheme = "event-driven"
    ref_rtols = (1e-4, 1e-6, 1e-8, 1e-10)
    tight_rtol = 1e-12
    projection = False

    def __init__(self, scene, t_span, q0, v0, coordinate_index=0):
        t0, t1 = (float(t) for t in np.asarray(t_span, dtype=float).reshape(2))
        if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
            raise InputError(f"`t_span` must be two finite times with t1 > t0, got {t_span!r}")
        n = int(scene.ndof)
        self.scene = scene
        self.t0 = t0
        self.window = t1 - t0
        self.q0 = finite_array("q0", q0, (n,))
        self.v0 = finite_array("v0", v0, (n,))
        idx = int(coordinate_index)
        if not 0 <= idx < n:
            raise InputError(f"`coordinate_index` must be in [0, {n}), got {coordinate_index!r}")
        self.index = idx
        self.headline_name = f"coordinate q[{idx}] at the end of the window"
        self.name = getattr(scene, "name", type(scene).__name__)
        self._grid = None

    def parameters(self):
        return {"t0": self.t0, "window": self.window, "q0": self.q0.tolist(),
                "v0": self.v0.tolist()}

    def start(self):
        return self.q0.copy(), self.v0.copy()

    def coordinate(self, q):
        return q[:, self.index]

    def headline_of_run(self, res):
        return float(res.q[-1, self.index])

    def _reference_run(self, rtol, sample_dt=None):
        opts = {"rtol": rtol}
        if sample_dt is not None:
            opts["sample_dt"] = sample_dt
        res = simulate(self.scene, (self.t0, self.t0 + self.window), self.q0, self.v0,
                       "event-driven", **opts)
        if not res.success:
            raise MoreauError(f"the event-driven reference failed: {res.message}")
        return res

    def reference(self, rtol):
        res = self._reference_run(rtol)
        sw = [(float(e.t) - self.t0, f"{e.contact}:{REGIME_LETTERS[e.after]}")
              for e in res.events if e.after != e.before]
        return float(res.q[-1, self.index]), sw

    def reference_grid(self):
        if self._grid is None:
            res = self._reference_run(self.tight_rtol, sample_dt=self.window / (8 * GRID))
            grid = np.linspace(0.0, self.window, GRID + 1)
            self._grid = np.interp(grid, res.t - self.t0, res.q[:, self.index])
        return self._grid

    def run_scheme(self, name, options):
        res = simulate(self.scene, (self.t0, self.t0 + self.window), self.q0, self.v0, name,
                       sample_dt=self.window / GRID, **options)
        res.t = res.t - self.t0
        return res

    def run_mj(self, n, theta, lcp):
        opts = dict(h=self.window / n, theta=theta, projection=self.projection)
        if lcp is not None:
            opts["lcp_method"] = lcp
        res = simulate(self.scene, (self.t0, self.t0 + self.window), self.q0, self.v0,
                       "moreau-jean", **opts)
        # the comparison grid and the switching times count from the window's start
        res.t = res.t - self.t0
        return res

    def _run_switches(self, res, h):
        return flatten([self._run_switches_of(res, h, c) for c in range(self.scene.ncontacts)])
