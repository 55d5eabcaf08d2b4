"""Integrator base class and the :func:`simulate` front end.

Modelled on ``scipy.integrate``: the public :meth:`Integrator.step` owns the
status, the time and the counters; subclasses implement ``_step_impl`` and
record samples with ``_record``. :func:`simulate` drives any registered scheme
to the end of the interval and returns a :class:`SimulationResult`; an
interrupted run (Ctrl-C) keeps what it had finished.
"""


from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import inspect
from typing import Any, Callable, ClassVar, Sequence, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._validate import finite_scalar, positive, relative_tolerance
from ..errors import ContactLostError, InputError, LCPError, MoreauError, PainleveError
from ..model import registry as scene_registry
from ..model.scene import fill_docstring, is_spatial, joint_row_count, velocity_count
from ._dense import (OutputTracker, Piece, check_events, check_t_eval, interpolated_piece,
                     join_to_last, stack_rows)
from ._divergence import (GROWTH as DIVERGENCE_GROWTH, bounded_velocities, divergence,
                          explicit_step_note)
from .result import STATUS_MESSAGES, SimulationResult

if TYPE_CHECKING:  # annotations only: the scenes package imports this one at run time
    from ..model.scene import Scene

__all__ = ["Integrator", "simulate", "propagate_interrupts", "INTEGRATORS", "register_integrator", "get_integrator",
           "check_options", "SchemeOptions", "EventDrivenOptions", "scheme_of"]

#: registry name -> Integrator subclass, filled by :func:`register_integrator`
INTEGRATORS = {}


def get_integrator(name):
    """The :class:`Integrator` subclass registered as ``name``.

    A scene's own reference scheme registers itself in its scene's module, so
    an unknown name first has the scene modules discovered
    (:func:`moreau.model.registry.discover`); a name still unknown is an
    error that lists the known ones.

    Examples
    --------
    >>> get_integrator("moreau-jean").__name__
    'MoreauJean'
    >>> get_integrator("euler")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `method` must be one of 'compliant-radau', ..., 'moreau-jean', ...; got 'euler'
    """
    if name not in INTEGRATORS:
        scene_registry.discover()
    try:
        return INTEGRATORS[name]
    except (KeyError, TypeError):
        known = ", ".join(repr(k) for k in sorted(INTEGRATORS))
        raise InputError(f"`method` must be one of {known}; got {name!r}") from None


def check_options(name, options, scene=None):
    """Refuse an option that scheme ``name`` does not take, or a bad value, before any work.

    The options a scheme takes are the fields of its :class:`SchemeOptions`
    dataclass (``cls.Options``), or, for a scheme without one, the keyword
    parameters of its constructor (after ``scene, t0, q0, v0, t_bound``): one
    place states them, and a setting that would not act is an error naming
    the option and the scheme. A scheme that hands a scene to another one (the
    ``"event-driven"`` front, which picks the scene's own reference) states
    that by a ``resolve(scene)`` method, and the options are those of the
    scheme it picks.

    Examples
    --------
    >>> check_options("moreau-jean", {"h": 0.01, "theta": 0.5})
    >>> check_options("event-driven-generic", {"theta": 0.5})
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `theta` is not an option of scheme 'event-driven-generic'; its options: rtol, atol, max_step, sample_dt, vel_tol, ode_method, gap_tol, zeno_rtol, max_impacts, lcp_method, record_pieces
    >>> check_options("moreau-jean", {"theta": 2.0})
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `theta` must be in [0.5, 1.0], got 2.0
    """
    _options_object(name, options, scene)


def _options_object(name, options, scene=None):
    """The checked options object of scheme ``name`` (None for a scheme without one)."""
    cls = get_integrator(name)
    if scene is not None and hasattr(cls, "resolve"):
        cls = cls.resolve(scene)
    accepted = scheme_options(cls)
    if accepted is None:
        return None
    for key in options:
        if key not in accepted:
            raise InputError(f"`{key}` is not an option of scheme {name!r}; its options: "
                             + ", ".join(accepted))
    if cls.Options is None or not takes_options_object(cls):
        # a keyword constructor checks its own options
        return None
    return cls.Options(**options)


def scheme_options(cls):
    """Option names of an integrator class, or None where it takes any (``**options``).

    A subclass that states its own keyword constructor (a test double of a
    scheme) takes the options that constructor names.
    """
    if getattr(cls, "Options", None) is not None and (takes_options_object(cls) or not [
            p for p in list(inspect.signature(cls.__init__).parameters.values())[6:]]):
        return cls.Options.names()
    sig = inspect.signature(cls.__init__)
    params = list(sig.parameters.values())[6:]  # self, scene, t0, q0, v0, t_bound
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params):
        return getattr(cls, "options", None)
    return tuple(p.name for p in params)


@dataclasses.dataclass(frozen=True)
class SchemeOptions:
    """The typed options of one scheme: a frozen dataclass, checked once when made.

    Each registered scheme states its options as ``cls.Options``, a subclass
    with one field per option (its type and default); the values are checked
    in ``__post_init__`` (an :class:`~moreau.errors.InputError` names the field
    and the rule) and normalised (a float, a bool). An instance also names its
    scheme (:attr:`scheme`), so it is a whole scheme choice: pass it to
    :func:`simulate` as ``method``, or to an analysis as ``scheme``. What
    depends on the run (the step count of ``h`` over the interval, the
    scene's contacts) is checked when the run is made.

    Examples
    --------
    >>> from moreau.integrators.moreau_jean import MoreauJean
    >>> opts = MoreauJean.Options(h=1e-3, theta=0.5)
    >>> opts.scheme, opts.h, opts.replace(theta=1).theta
    ('moreau-jean', 0.001, 1.0)
    >>> MoreauJean.Options(h=-1.0)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `h` must be > 0, got -1.0
    """

    #: the registered name of the scheme (set by :func:`register_integrator`)
    scheme: ClassVar[str] = ""
    #: field name -> its rule: a function of the value that returns it normalised or
    #: raises an InputError naming the field and the rule
    _rules: ClassVar[dict] = {}

    def __post_init__(self):
        self._check()

    def _rule(self, name):
        return self._rules.get(name)

    def _check(self):
        """Check and normalise the fields by their rules, in field order."""
        for f in dataclasses.fields(self):
            rule = self._rule(f.name)
            if rule is not None:
                self._set(f.name, rule(getattr(self, f.name)))

    def _set(self, name, value):
        # normalising a field of a frozen instance while it is made
        object.__setattr__(self, name, value)

    def smooth_order(self):
        """The order of the global error in ``h`` where the motion is smooth, or None.

        None for a scheme that picks its own steps under an error tolerance
        (or follows the motion exactly), which states no order in a step.
        """
        return None

    @classmethod
    def names(cls):
        """The option names, in their order."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def from_keywords(cls, options):
        """The options from a dict of keywords; an unknown one is refused naming the scheme's."""
        cls._refuse_unknown(options)
        return cls(**options)

    @classmethod
    def _refuse_unknown(cls, options):
        accepted = cls.names()
        for key in options:
            if key not in accepted:
                raise InputError(f"`{key}` is not an option of scheme {cls.scheme!r}; its "
                                 "options: " + ", ".join(accepted))

    def replace(self, **changes):
        """A copy with ``changes`` (checked like a new instance)."""
        self._refuse_unknown(changes)
        return dataclasses.replace(self, **changes)

    def changed(self):
        """``{name: value}`` of the fields set away from their defaults.

        What a call by name would pass as keywords; an analysis that sets
        some options itself (the step from its steps per period) takes these.

        Examples
        --------
        >>> from moreau.integrators.moreau_jean import MoreauJean
        >>> MoreauJean.Options(h=0.01, theta=1, lcp_method="lemke").changed()
        {'h': 0.01, 'lcp_method': 'lemke'}
        """
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is f.default:
                continue
            if type(value) is type(f.default) and np.ndim(value) == 0 and value == f.default:
                continue
            out[f.name] = value
        return out

    def without_step(self, what="the analysis"):
        """:meth:`changed` without ``h``; a set ``h`` is refused: ``what`` sets the step."""
        out = self.changed()
        if "h" in out:
            raise InputError(f"`h` is set by {what} (from its steps per period); give the "
                             f"options of scheme {self.scheme!r} without `h`")
        return out

    def as_dict(self):
        """``{name: value}`` of every field (the constructor's keywords)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @property
    def integrator(self):
        """The :class:`Integrator` subclass these options are for."""
        return get_integrator(self.scheme)


@dataclasses.dataclass(frozen=True)
class EventDrivenOptions(SchemeOptions):
    """The options every event-driven scheme has: its smooth phases' ODE solver, its samples
    and its velocity tolerance (each scheme's own follow; see its class for their meaning)."""
    rtol: float = 1e-12
    atol: float = 1e-14
    max_step: float = 1.0
    sample_dt: float | None = None
    vel_tol: float = 1e-9

    _rules: ClassVar[dict] = {
        "rtol": lambda v: relative_tolerance("rtol", v, floor=False),
        "atol": lambda v: positive("atol", v),
        "max_step": lambda v: positive("max_step", v),
        "sample_dt": lambda v: None if v is None else positive("sample_dt", v),
        "vel_tol": lambda v: positive("vel_tol", v)}


def scheme_of(method, options=None):
    """``(name, options dict)`` of a scheme given by name or as a :class:`SchemeOptions`.

    ``options`` are keywords given beside it; with an options object they
    replace its fields. Lets an analysis take either form and pass one on.

    Examples
    --------
    >>> from moreau.integrators.moreau_jean import MoreauJean
    >>> scheme_of(MoreauJean.Options(h=0.01), {"theta": 0.5})[1]["theta"]
    0.5
    >>> scheme_of("event-driven", {"rtol": 1e-9})
    ('event-driven', {'rtol': 1e-09})
    """
    options = dict(options or {})
    if isinstance(method, SchemeOptions):
        return method.scheme, {**method.replace(**options).as_dict()}
    return method, options


def takes_options_object(cls):
    """Whether ``cls(scene, t0, q0, v0, t_bound, options=...)`` takes its options object.

    True for a scheme that says so (``takes_options_object``) unless a subclass
    replaced its constructor by one without ``options``.
    """
    return bool(getattr(cls, "takes_options_object", False)) and \
        "options" in inspect.signature(cls.__init__).parameters


def register_integrator(name):
    """Class decorator registering an :class:`Integrator` subclass under ``name``."""
    def deco(cls):
        INTEGRATORS[name] = cls
        cls.scheme = name
        base = vars(cls).get("Options") or getattr(cls, "Options", None)
        if base is not None:
            # every scheme's options name their scheme, also where a class shares its parent's
            opts = dataclasses.dataclass(frozen=True)(
                type("Options", (base,), {"scheme": name, "__module__": cls.__module__,
                                          "__qualname__": f"{cls.__qualname__}.Options",
                                          "__doc__": base.__doc__}))
            cls.Options = opts
        return cls
    return deco


class Integrator:
    """Base class of integration schemes over a :class:`~moreau.model.scene.Scene`.

    Parameters
    ----------
    scene : Scene
        The mechanical system.
    t0, t_bound : float
        Start and end of the (dimensionless) time interval, ``t_bound > t0``.
    q0, v0 : array_like, shape (ndof,)
        Initial coordinates and velocities.

    Attributes
    ----------
    t, q, v : current state
    status : str
        ``"running"``, ``"finished"`` or ``"failed"``.
    message : str
    counters : dict
        Scheme-specific statistics (steps, LCP solves, ...).
    """

    scheme = ""
    #: the entries of a scheme's Parameters section that the line ``{start}`` of its class
    #: docstring stands for: the scene and the start, this class's parameters
    START_PARAMETERS = ("scene : Scene", "t0, q0, v0, t_bound",
                        "    See :class:`~moreau.integrators.base.Integrator`.")
    #: True where the scheme hands its exact motion between samples to :func:`simulate`
    #: (event-driven schemes, through :meth:`_add_piece`); False where the motion between
    #: recorded samples is their linear interpolation (time stepping): ``t_eval`` samples
    #: and user events are then interpolated, events located to within one step
    exact_motion = False
    #: how ``moreau compare`` runs this scheme beside the reference and Moreau–Jean, or
    #: None: ``(setting, values, quick_values, fixed_options)``, one row per value of the
    #: option ``setting`` (e.g. a compliant contact's stiffness)
    compare_settings = None
    #: the scheme's typed options (a :class:`SchemeOptions` dataclass), or None
    Options = None
    #: True where the constructor takes the options as one object (``options=``)
    takes_options_object = False
    #: True where the scheme solves a scene's joint (equality) rows; the others refuse a
    #: scene with joints by name, before any work
    solves_joints = False
    #: True where the scheme steps spatial scenes (quaternion orientations, the friction
    #: cone, :mod:`moreau.model.space`); the others refuse one by name, before any work
    solves_space = False

    @classmethod
    def refusal(cls, scene):
        """Why the scheme refuses ``scene`` by its kind (joints, spatial bodies), or None.

        Examples
        --------
        >>> from moreau.scenes.bouncing_ball import BouncingBall
        >>> get_integrator("moreau-jean").refusal(BouncingBall()) is None
        True
        """
        nj = joint_row_count(scene)
        if nj and not cls.solves_joints:
            return (f"scheme {cls.scheme!r} solves no joints: `scene` "
                    f"{getattr(scene, 'name', type(scene).__name__)!r} has {nj} joint "
                    f"(bilateral) rows; use 'moreau-jean'")
        if is_spatial(scene) and not cls.solves_space:
            return (f"scheme {cls.scheme!r} steps no spatial scene: `scene` "
                    f"{getattr(scene, 'name', type(scene).__name__)!r} has spatial "
                    "bodies (quaternion orientations, the spatial friction cone); use "
                    "'moreau-jean'")
        return None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        fill_docstring(cls, "{start}", cls.START_PARAMETERS)

    def __init__(self, scene, t0, q0, v0, t_bound):
        refused = self.refusal(scene)
        if refused is not None:
            raise InputError(refused)
        self.scene = scene
        self.t0 = finite_scalar("t0", t0)
        self.t_bound = finite_scalar("t_bound", t_bound)
        if not self.t_bound > self.t0:
            raise InputError(f"`t_bound` must be > `t0` ({self.t0!r}), got {self.t_bound!r}")
        n = scene.ndof
        self.q = _state_vector("q0", q0, n)
        self.v = _state_vector("v0", v0, velocity_count(scene))
        self.t = self.t0
        #: where the run started, to tell a diverged state from the failure it caused
        self._start = (self.q.copy(), self.v.copy(), self.t0)
        self._judged = bounded_velocities(scene, velocity_count(scene))
        self._v_limit = DIVERGENCE_GROWTH * max(1.0, float(np.max(np.abs(self.v[self._judged]),
                                                                  initial=0.0)))
        # a run must start where the model holds (a scene states its valid region)
        outside = self.scene.check_valid(self.q, self.v, self.t0) if hasattr(
            self.scene, "check_valid") else None
        if outside is not None:
            raise InputError(f"`q0`, `v0` lie outside the scene's valid region: "
                             f"{outside.replace('the state left ', '')}")
        self.status = "running"
        self.status_code = 0
        self.message = ""
        self.counters = {"steps": 0}
        self.events = []
        self._samples = []
        # the motion handed to simulate's t_eval and events, only while it asks for it
        self._want_pieces = False
        self._pieces = []
        self._seen = 0
        #: the last sample handed to simulate's output (time stepping)
        self.last_handed = None
        # recorded samples checked against the scene's valid region so far, and the
        # time of the state where the run left it (None while inside)
        self._region_seen = 0
        self.region_left_at = None

    def _take_options(self, options, keywords):
        """The scheme's options object: ``options`` as given, or made from ``keywords``.

        For a constructor ``(scene, t0, q0, v0, t_bound, options=None, **keywords)``
        (``takes_options_object``): the object is checked once, where it is made.
        """
        if options is None:
            return self.Options.from_keywords(keywords)
        if keywords or not isinstance(options, self.Options):
            raise InputError(f"`options` must be a {type(self).__name__}.Options, without "
                             f"keywords beside it; got {type(options).__name__} and "
                             f"{sorted(keywords)}")
        return options

    # -- public API ---------------------------------------------------------
    def step(self):
        """Advance by one step (or to the next event); return the status string."""
        if self.status != "running":
            raise MoreauError(f"cannot step an integrator whose status is {self.status!r}")
        region = getattr(self.scene, "valid_region", None) is not None
        snapshot = self._snapshot() if region else None
        try:
            stepped = self._attempt(self._step_impl)
        except InputError:
            raise
        except (MoreauError, FloatingPointError) as exc:
            self._fail(-5, f"{STATUS_MESSAGES[-5]} {type(exc).__name__}: {exc}")
        else:
            if stepped:
                self.counters["steps"] += 1
                if self._stop_if_diverged():
                    return self.status
                if self.t >= self.t_bound:
                    self.status = "finished"
                    self.message = STATUS_MESSAGES[0]
        if region:
            self._check_region(snapshot)
        return self.status

    def _stop_if_diverged(self):
        """Fail the run as diverged where its velocities blew up; True if it did.

        Checked after every step, and by a compiled loop before it hands a step
        back to the Python step: stopped there, before its arithmetic overflows.
        """
        if float(np.max(np.abs(self.v[self._judged]), initial=0.0)) <= self._v_limit:
            return False
        why = divergence(self.scene, *self._start, self.q, self.v, self.t,
                         getattr(self, "h", None))
        if not why:
            return False
        self.status, self.status_code, self.message = "failed", -5, why
        return True

    def _snapshot(self):
        """What :meth:`_replay` needs to take the last call of ``_step_impl`` again (None: no replay)."""
        return None

    def _replay(self, snapshot, t, rows):
        """Take the last ``_step_impl`` again from ``snapshot``, stopping at the sample at ``t``.

        For a scheme that advances many steps a call (a compiled block): its
        counters and its state then end where the run left the valid region.
        ``rows`` are the times recorded by that call up to ``t``. Returns
        True when done; the default does nothing and returns False.
        """
        return False

    def _check_region(self, snapshot=None):
        """Stop at the first recorded sample outside the scene's valid region.

        The samples after it are dropped and the run ends there with status
        ``-6``: what a scheme computes beyond is not the scene's model. It
        overrides a failure of the same step, which came after. The recorded
        samples are what every scheme has, the generic and the compiled path
        alike (a compiled block is taken again up to that sample,
        :meth:`_replay`), so both stop on the same sample: with
        ``save_every = 1`` (the default) on the first step end outside.
        """
        sc = self.scene
        if getattr(sc, "valid_region", None) is None:
            return
        new = self._unchecked_states()
        if new is not None:
            t, q, v = new
            inside = np.asarray(sc.inside_valid_region(t, q, v), dtype=bool)
            if not inside.all():
                k = int(np.argmin(inside))
                if snapshot is not None and self._replay(snapshot, t[k], t[:k + 1]):
                    # the call taken again up to that sample, which now ends its rows
                    new = self._unchecked_states()
                    if new is None:
                        return
                    t, q, v = new
                    inside = np.asarray(sc.inside_valid_region(t, q, v), dtype=bool)
                    k = int(np.argmin(inside))
                if not inside[k]:
                    self._keep_checked(k + 1)
                    self._left_region(t[k], q[k], v[k])
                    return
            self._keep_checked(None)

    def _left_region(self, t, q, v):
        self.t, self.q, self.v = float(t), np.array(q, dtype=float), np.array(v, dtype=float)
        self.region_left_at = self.t
        self.events = [e for e in self.events if e.t <= self.t]
        note = ""
        if getattr(self, "explicit_step", False):
            note = explicit_step_note(self.scene, *self._start, self.h)
        self._fail(-6, self.scene.check_valid(self.q, self.v, self.t)
                   + "; the model does not apply beyond it, the run stops there" + note)

    def _unchecked_states(self):
        """``(t, q, v)`` of the samples recorded since the last check, or None."""
        new = self._samples[self._region_seen:]
        if not new:
            return None
        n = self.scene.ndof
        return (np.array([s[0] for s in new], dtype=float),
                np.array([s[1] for s in new], dtype=float).reshape(len(new), n),
                np.array([s[2] for s in new], dtype=float).reshape(len(new),
                                                                   velocity_count(self.scene)))

    def _keep_checked(self, count):
        """Keep ``count`` of the samples since the last check, drop the rest; mark them checked."""
        if count is not None:
            del self._samples[self._region_seen + count:]
        self._region_seen = len(self._samples)

    def interrupt(self, message=None):
        """Stop the run as interrupted (status ``-4``); what was recorded is kept.

        For drivers such as :func:`simulate` that catch ``KeyboardInterrupt``.
        """
        self._fail(-4, message or STATUS_MESSAGES[-4])

    def _attempt(self, fn):
        """``fn()`` and True, or False where it raised a failure of the run (a Painlevé
        paradox, a lost contact, a contact problem without solution), recorded as the run's
        status and message with its code (-1, -2, -3)."""
        try:
            fn()
        except PainleveError as exc:
            self._fail(-1, str(exc))
        except ContactLostError as exc:
            self._fail(-2, str(exc))
        except LCPError as exc:
            self._fail(-3, str(exc))
        else:
            return True
        return False

    def _fail(self, code, message):
        if code in (-1, -3, -5):
            # a blown-up state breaks the contact problem or the arithmetic on the way: the
            # cause to name is the divergence (the flexible rod with Schatzman-Paoli at 100
            # steps a period read "discrete Painleve condition violated (W_NN = 1.5e103)")
            why = divergence(self.scene, *self._start, self.q, self.v, self.t,
                             getattr(self, "h", None))
            if why:
                code, message = -5, f"{why}. The step then failed: {message}"
        self.status = "failed"
        self.status_code = code
        self.message = message

    # -- for subclasses -----------------------------------------------------
    def _step_impl(self):
        raise NotImplementedError

    def _add_piece(self, grid, state, sample):
        """Hand the exact motion over ``grid`` to :func:`simulate` (event-driven schemes).

        See :class:`moreau.integrators._dense.Piece`; a no-op unless the run
        asked for ``t_eval`` samples or events.
        """
        if self._want_pieces:
            self._pieces.append(Piece(grid, state, sample))

    def _follow_phase(self, sol, row):
        """Record the smooth phase ``sol`` (:func:`scipy.integrate.solve_ivp` with dense
        output, over ``y = (q, v)``) and move ``t`` to its end; returns ``y`` there.

        A failed integration raises :class:`~moreau.errors.MoreauError`. The phase's dense
        output is its exact motion (to the ODE tolerance), handed over by
        :meth:`_add_piece` with ``row(t, q, v)`` the sample at ``t``; its own steps are
        where an event function is checked. The samples due in the phase are recorded by
        ``_record_state``.
        """
        if sol.status < 0:
            raise MoreauError(f"smooth-phase integration failed at t = {sol.t[-1]:.12g}: "
                              f"{sol.message}")
        n = self.scene.ndof
        t_end = float(sol.t[-1])
        dense = sol.sol
        if self._want_pieces:
            grid = np.append(dense.ts[dense.ts < t_end], t_end)
            self._add_piece(grid, dense, lambda t: row(t, dense(t)[:n], dense(t)[n:]))
        while self._next_sample < t_end:
            ys = dense(self._next_sample)
            self._record_state(self._next_sample, ys[:n], ys[n:])
            self._next_sample += self.sample_dt
        self.t = t_end
        return sol.y[:, -1]

    def _take_pieces(self):
        """The motion since the previous call, as a list of pieces."""
        if self.exact_motion:
            out, self._pieces = self._pieces, []
            return out
        rows = self._rows_since()
        if rows is None:
            return []
        return [interpolated_piece(*rows)]

    def _rows_since(self):
        # the samples recorded since the previous call, after the last one of before
        new = self._samples[self._seen:]
        self._seen = len(self._samples)
        return join_to_last(self, stack_rows(new, self.scene.ndof, self.scene.ncontacts,
                                             velocity_count(self.scene)))

    def _record(self, t, q, v, regime, force_N, force_T, slip, gap):
        self._samples.append((t, np.array(q, float), np.array(v, float),
                              np.atleast_1d(regime), np.atleast_1d(force_N),
                              np.atleast_1d(force_T), np.atleast_1d(slip),
                              np.atleast_1d(gap)))

    def result(self):
        """Assemble the samples recorded so far into a :class:`SimulationResult`."""
        nc = self.scene.ncontacts
        n = self.scene.ndof
        nv = velocity_count(self.scene)
        if self._samples:
            cols = list(zip(*self._samples))
            t = np.array(cols[0], float)
            q, v = np.array(cols[1]).reshape(-1, n), np.array(cols[2]).reshape(-1, nv)
            reg = np.array(cols[3], int).reshape(len(t), -1)
            fN, fT, slip, gap = (np.array(c, float).reshape(len(t), -1) for c in cols[4:])
        else:
            t = np.zeros(0)
            q, v = np.zeros((0, n)), np.zeros((0, nv))
            reg = np.zeros((0, nc), int)
            fN = fT = slip = gap = np.zeros((0, nc))
        code = self.status_code
        message = self.message or STATUS_MESSAGES.get(code, "")
        return SimulationResult(t=t, q=q, v=v, regime=reg, force_N=fN, force_T=fT,
                                slip_velocity=slip, gap=gap, events=list(self.events),
                                status=code, message=message, scheme=self.scheme,
                                stats=dict(self.counters))


def _state_vector(name, value, n):
    a = np.asarray(value, dtype=float).reshape(-1) if np.ndim(value) else None
    if a is None or a.shape != (n,):
        raise InputError(f"`{name}` must have shape ({n},), got {np.shape(value)}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"`{name}` must contain only finite values (no NaN or inf)")
    return a.copy()


def simulate(scene: Scene, t_span: tuple[float, float], q0: ArrayLike, v0: ArrayLike,
             method: str, progress: bool = False, t_eval: ArrayLike | None = None,
             events: Callable | Sequence[Callable] | None = None,
             **options: Any) -> SimulationResult:
    """Integrate ``scene`` over ``t_span`` with the scheme registered as ``method``.

    Parameters
    ----------
    scene : Scene
    t_span : (float, float)
        Dimensionless start and end time.
    q0, v0 : array_like
        Initial state.
    method : str or SchemeOptions
        A key of :data:`INTEGRATORS` (e.g. ``"moreau-jean"``), or a scheme's
        options object (``MoreauJean.Options(h=1e-3)``), which names its
        scheme; keywords in ``options`` then replace its fields.
    progress : bool
        Show a tqdm progress bar over simulated time.
    t_eval : array_like, optional
        Times at which to sample the result, increasing, inside ``t_span``
        (as in :func:`scipy.integrate.solve_ivp`), for every scheme. An
        event-driven scheme samples its exact motion; a time-stepping scheme
        interpolates linearly between its step ends (the regime and forces
        are those of the step containing the time). Without it the result
        holds the scheme's own samples (set by ``h``, ``save_every``,
        ``sample_dt``, ``samples_per_period``).
    events : callable or list of callables, optional
        Functions ``event(t, y)`` of the time and the state ``y = (q, v)``
        (concatenated) whose zeros are located, as in ``solve_ivp``: an
        attribute ``terminal`` (True, or the number of occurrences) stops the
        run, ``direction`` (> 0 upwards, < 0 downwards, 0 both) selects the
        crossings. Event-driven schemes find the root on their exact motion
        (Brent's method); time-stepping schemes locate it to within one step
        (the sign change between two step ends, ``t_events`` holding the root
        of the linear interpolation). The times and states go to
        ``result.t_events`` and ``result.y_events``; a terminal event ends
        the run with status 1.
    **options
        The scheme's options (the fields of its ``Options``), checked before
        any work.

    Returns
    -------
    SimulationResult
        Status ``-4`` if interrupted by ``KeyboardInterrupt``; the samples
        recorded until then are kept. Status 1 if a terminal event stopped it.
        Status ``-6`` if a recorded state left the scene's valid region
        (:meth:`~moreau.model.scene.Scene.inside_valid_region`): the run ends
        on that sample, and the message names the region, the time and the
        state.

    Examples
    --------
    A ball dropped from height 1 (gravity 1) passes 0.5 going down at
    ``t = 1``; the event-driven reference finds it on its dense output:

    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> def half(t, y): return y[0] - 0.5
    >>> half.terminal, half.direction = True, -1
    >>> res = simulate(BouncingBall(), (0.0, 3.0), [1.0], [0.0], "event-driven", events=half,
    ...                t_eval=[0.0, 0.5, 1.5])
    >>> res.status, round(float(res.t_events[0][0]), 12), res.t.tolist()
    (1, 1.0, [0.0, 0.5])
    """
    if isinstance(method, SchemeOptions):
        given = method.replace(**options) if options else method
        method = given.scheme
        cls = get_integrator(method)
        options = given.as_dict()
    else:
        cls = get_integrator(method)
        given = _options_object(method, options, scene)
    t0, t1 = t_span
    if t_eval is not None:
        t_eval = check_t_eval(t_eval, finite_scalar("t_span[0]", t0), finite_scalar("t_span[1]", t1))
    funcs = check_events(events)
    if takes_options_object(cls.resolve(scene) if hasattr(cls, "resolve") else cls):
        integ = cls(scene, t0, q0, v0, t1, options=given)
    else:
        integ = cls(scene, t0, q0, v0, t1, **options)
    tracker = None
    if t_eval is not None or funcs:
        integ._want_pieces = True
        tracker = OutputTracker(integ.t0, np.concatenate([integ.q, integ.v]), t_eval, funcs,
                                integ.exact_motion)
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=float(t1 - t0), unit="t", leave=False, disable=None)  # terminals only
    last = integ.t
    try:
        while integ.status == "running":
            integ.step()
            if tracker is not None and tracker.feed(integ._take_pieces()):
                break
            if bar is not None:
                bar.update(integ.t - last)
                last = integ.t
        if tracker is not None and tracker.stop is None:
            # what a failed step still recorded
            tracker.feed(integ._take_pieces())
    except KeyboardInterrupt:
        if _PROPAGATE_INTERRUPTS.get():
            raise
        integ.interrupt()
    finally:
        if bar is not None:
            bar.close()
    result = integ.result()
    if tracker is not None:
        tracker.finish(result)
        cut = integ.region_left_at
        if cut is not None and (tracker.stop is None or tracker.stop[0] > cut):
            # the exact motion handed over may run past the state that left the region
            _cut_at(result, cut)
            result.status, result.message = integ.status_code, integ.message
    return result


def _cut_at(result, t):
    """Drop the samples and events of ``result`` after time ``t`` (in place)."""
    keep = result.t <= t
    for name in ("t", "q", "v", "regime", "force_N", "force_T", "slip_velocity", "gap"):
        setattr(result, name, getattr(result, name)[keep])
    result.events = [e for e in result.events if e.t <= t]
    for i, te in enumerate(result.t_events):
        k = np.asarray(te) <= t
        result.t_events[i], result.y_events[i] = te[k], result.y_events[i][k]


#: inside :func:`propagate_interrupts`: :func:`simulate` lets Ctrl-C through
_PROPAGATE_INTERRUPTS = contextvars.ContextVar("moreau_propagate_interrupts", default=False)


@contextlib.contextmanager
def propagate_interrupts(enabled=True):
    """Within this block, Ctrl-C stops :func:`simulate`'s caller too.

    ``enabled=False`` restores a lone run's behaviour inside a block that
    propagates (``moreau run`` keeps its partial history).

    A lone :func:`simulate` turns ``KeyboardInterrupt`` into its result's
    status ``-4`` and returns what it had: the run was the whole job. A batch
    of runs (a comparison table, the stress catalogue) must stop instead of
    going on to its next run with the interrupt swallowed; it runs its loop in
    this block and keeps its finished rows where it catches the interrupt.

    Examples
    --------
    >>> with propagate_interrupts():
    ...     _PROPAGATE_INTERRUPTS.get()
    True
    >>> _PROPAGATE_INTERRUPTS.get()
    False
    """
    token = _PROPAGATE_INTERRUPTS.set(bool(enabled))
    try:
        yield
    finally:
        _PROPAGATE_INTERRUPTS.reset(token)
