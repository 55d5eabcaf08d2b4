"""The common part of the time-stepping schemes: :class:`TimeStepping` and its checks.

A time-stepping scheme advances on a grid of steps ``h`` (fixed, the last one
cut at ``t_bound``: :func:`next_time`; or chosen by the scheme, Studer's
extrapolation) and solves a contact problem on each step. What every such
scheme shares lives here, written once: the step and its work limits
(:func:`check_work`), the contact-problem options, the scene's contact
coefficients, the counters, the start of the recording and the choice of the
compiled path. A scheme states its options as a frozen dataclass
(:class:`StepOptions`), checked once when made, and adds its own start state
(``_setup_scheme``) and its step (``_step_impl``).
"""

import dataclasses
import math
import numpy as np

from .._validate import in_closed_interval, positive, positive_int
from ..errors import InputError
from ..model.scene import joint_row_count
from ._blocks import CompiledRecording
from ._mj_kernels import set_painleve_stop
from .base import Integrator, SchemeOptions
from .contact_problem import check_painleve, new_contact_counters, sliding_regimes

__all__ = ["TimeStepping", "StepOptions", "FixedStepOptions", "LCP_METHODS", "MAX_STEPS", "check_work",
           "check_step", "check_step_fits", "check_lcp_options", "check_scene_contacts",
           "next_time", "compiled_model_of", "bool_option", "optional"]

#: accepted values of the ``lcp_method`` option
LCP_METHODS = ("auto", "lemke", "qp")

#: default bound on the steps of one run (about two minutes at 1e7 steps/s); `max_steps` raises it
MAX_STEPS = 10**9
#: bound on the memory the recorded samples of one run may take
MAX_RECORD_BYTES = 2 * 1024**3


def check_work(scene, t0, t1, h, save_every, max_steps=MAX_STEPS):
    """Refuse, before any work, a run whose step count or recorded samples have no sane bound.

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> check_work(BouncingBall(), 0.0, 6.3, 1e-9, 1)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `h` = 1e-09 over [0, 6.3] takes 6.3e+09 steps, more than `max_steps` = 1e+09: take a larger `h` or raise `max_steps`
    >>> check_work(BouncingBall(), 0.0, 4.0, 1000.0, 1)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `h` = 1000 is longer than the run [0, 4]: a step may not exceed the window it integrates; take `h` <= 4
    """
    check_step_fits("h", h, t0, t1)
    steps = math.ceil((t1 - t0) / h - 1e-9)
    if steps > max_steps:
        raise InputError(f"`h` = {h:g} over [{t0:g}, {t1:g}] takes {steps:.2g} steps, more than "
                         f"`max_steps` = {max_steps:.2g}: take a larger `h` or raise `max_steps`")
    n, nc = int(scene.ndof), len(scene.mu)
    size = (steps // save_every + 2) * 8 * (1 + 2 * n + 5 * nc)
    if size > MAX_RECORD_BYTES:
        raise InputError(f"recording every {save_every} of {steps:.2g} steps would take "
                         f"{size / 1024**3:.3g} GiB, more than {MAX_RECORD_BYTES / 1024**3:g} GiB: "
                         f"raise `save_every` to at least {math.ceil(save_every * size / MAX_RECORD_BYTES)}")


def check_step_fits(name, h, t0, t1):
    """Refuse a step longer than the window ``[t0, t1]``.

    Such a step is cut to the window and taken as one step of another size
    than asked for, which no order statement covers.
    """
    if h > (t1 - t0) * (1.0 + 1e-12):
        raise InputError(f"`{name}` = {h:g} is longer than the run [{t0:g}, {t1:g}]: a step may "
                         f"not exceed the window it integrates; take `{name}` <= {t1 - t0:g}")
    return h


def check_step(scheme, h):
    """The time step ``h`` of a fixed-step scheme, required and > 0."""
    if h is None:
        raise InputError(f"`h` (the time step) is required for the {scheme} scheme")
    return positive("h", h)


def check_lcp_options(lcp_method, lemke_max_iter=None):
    """Validate the contact-problem options of a scheme; return them normalised.

    Examples
    --------
    >>> check_lcp_options("qp", 5)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `lemke_max_iter` limits Lemke's pivots; `lcp_method='qp'` runs no Lemke
    """
    if lcp_method not in LCP_METHODS:
        raise InputError(f"`lcp_method` must be one of {list(LCP_METHODS)}, got {lcp_method!r}")
    if lemke_max_iter is not None:
        lemke_max_iter = positive_int("lemke_max_iter", lemke_max_iter)
        if lcp_method == "qp":
            raise InputError("`lemke_max_iter` limits Lemke's pivots; `lcp_method='qp'` "
                             "runs no Lemke")
    return lcp_method, lemke_max_iter


def check_scene_contacts(scene):
    """Return ``(mu, e)`` of ``scene`` as float arrays after checking them."""
    nc = scene.ncontacts
    mu = np.asarray(scene.mu, dtype=float).reshape(-1)
    e = np.asarray(scene.restitution, dtype=float).reshape(-1)
    if e.shape != (nc,):
        raise InputError(f"`scene.restitution` must have one entry per contact ({nc}), got shape {e.shape}")
    if not (np.all(np.isfinite(mu)) and np.all(mu >= 0.0)):
        raise InputError("`scene.mu` must be finite and >= 0 for every contact")
    if not (np.all(np.isfinite(e)) and np.all((e >= 0.0) & (e <= 1.0))):
        raise InputError("`scene.restitution` must lie in [0, 1] for every contact")
    return mu, e


def next_time(t0, k, h, t_bound):
    """``(t_{k+1}, step)`` of the fixed-step grid ``t0 + k h``, the last step cut at ``t_bound``.

    Shared by the generic and the compiled path so that both see the same times.
    """
    t1 = t0 + (k + 1) * h
    if t1 >= t_bound - 1e-9 * h:
        return t_bound, t_bound - (t0 + k * h)
    return t1, h


def compiled_model_of(scene):
    """The scene's :class:`~moreau.compiled.CompiledModel`, or None.

    None when the scene has no ``compiled_model()``, or when a subclass
    overrides one of the model methods (``mass``, ``forces``,
    ``force_jacobians``, ``gaps``, ``contact_jacobians``) below the class that
    defined ``compiled_model``: its compiled form would then describe other
    equations than the Python ones.
    """
    get = getattr(scene, "compiled_model", None)
    if get is None:
        return None
    cls = type(scene)
    owner = next((k for k in cls.__mro__ if "compiled_model" in vars(k)), None)
    if owner is None:
        return None
    above = cls.__mro__[:cls.__mro__.index(owner)]
    for name in ("mass", "forces", "force_jacobians", "gaps", "contact_jacobians"):
        if any(name in vars(k) for k in above):
            return None
    model = get()
    if model is None:
        return None
    if model.ndof != scene.ndof or model.ncontacts != scene.ncontacts:
        raise InputError(f"`scene.compiled_model()` describes {model.ndof} dof and "
                         f"{model.ncontacts} contacts, the scene {scene.ndof} and {scene.ncontacts}")
    return model


def bool_option(name):
    """The check of an option that is True or False."""
    def check(value):
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"`{name}` must be True or False, got {value!r}")
        return bool(value)
    return check


def optional(check):
    """``check`` for an option whose default None means "not set"."""
    return lambda value: None if value is None else check(value)


def _fast_option(value):
    if value not in ("auto", True, False):
        raise InputError(f"`fast` must be 'auto', True or False, got {value!r}")
    return value


def _lcp_method_option(value):
    if value not in LCP_METHODS:
        raise InputError(f"`lcp_method` must be one of {list(LCP_METHODS)}, got {value!r}")
    return value


def _closed0_option(value):
    c0 = np.asarray(value)
    if c0.dtype != bool:
        raise InputError(f"`closed0` must be a bool or bools (one per contact), got {value!r}")
    return value


#: the rule of each option the time-stepping schemes share (a function of the value that
#: returns it normalised or raises an InputError naming the option and the rule)
RULES = {
    "h": optional(lambda v: positive("h", v)),
    "theta": lambda v: in_closed_interval("theta", v, 0.5, 1.0),
    "projection": bool_option("projection"),
    "position_level": bool_option("position_level"),
    "lcp_warm_start": bool_option("lcp_warm_start"),
    "lcp_method": _lcp_method_option,
    "lemke_max_iter": optional(lambda v: positive_int("lemke_max_iter", v)),
    "save_every": lambda v: positive_int("save_every", v),
    "fast": _fast_option,
    "max_steps": lambda v: positive_int("max_steps", v),
    "painleve": check_painleve,
    "closed0": optional(_closed0_option),
    "sample_dt": optional(lambda v: positive("sample_dt", v)),
}


@dataclasses.dataclass(frozen=True, kw_only=True)
class StepOptions(SchemeOptions):
    """Options of a time-stepping scheme: each field checked by its rule, in field order.

    The rules are :data:`RULES` and the scheme's own ``_rules``; ``h`` may be
    left None in the object (an analysis sets it from its steps per period)
    and is required when a run is made.
    """

    def _rule(self, name):
        return self._rules.get(name) or RULES.get(name)

    def _check(self):
        super()._check()
        if getattr(self, "lemke_max_iter", None) is not None and self.lcp_method == "qp":
            raise InputError("`lemke_max_iter` limits Lemke's pivots; `lcp_method='qp'` "
                             "runs no Lemke")


@dataclasses.dataclass(frozen=True, kw_only=True)
class FixedStepOptions(StepOptions):
    """The options of every fixed-step scheme (its own follow).

    Attributes
    ----------
    h : float
        Time step (dimensionless), > 0; the last step is shortened to end on
        ``t_bound``. Required by a run; an analysis sets it from its steps
        per period.
    lcp_method : {"auto", "lemke", "qp"}
        Solver of each contact problem
        (:func:`~moreau.integrators.contact_problem.solve_contact_problem`).
    save_every : int
        Record one sample every ``save_every`` steps (and the last one).
    fast : {"auto", True, False}
        Run the scheme's compiled loop (the same step, equal to rounding) on a
        scene with a ``compiled_model()``; ``"auto"`` does so unless
        ``lcp_method="qp"``; ``True`` insists; ``False`` takes the generic
        Python step. A step the loop cannot finish (Lemke fails, a Painlevé
        case) is taken by the generic step.
    max_steps : int
        Bound on the number of steps of the run, checked before any work.
    painleve : {"impulse", "stop"}
        At a one-contact step whose sliding piece has no solution (the
        discrete Painlevé condition fails the way the contact slides): take
        the step's unique answer, the impulsive stick (default; the tangential
        impact, counted in ``stats["tangential_impacts"]``), or stop with
        status ``-1`` wherever the pressed contact's free slip, of any size,
        runs that way
        (:func:`~moreau.integrators.contact_problem.solve_contact_problem`).

    Examples
    --------
    >>> from moreau.integrators.schatzman_paoli import SchatzmanPaoli
    >>> SchatzmanPaoli.Options(h=0.01).save_every
    1
    >>> SchatzmanPaoli.Options(h=0.01, painleve="jam")
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `painleve` must be one of ['impulse', 'stop'], got 'jam'
    """
    h: float | None = None
    lcp_method: str = "auto"
    save_every: int = 1
    fast: str | bool = "auto"
    max_steps: int = MAX_STEPS
    painleve: str = "impulse"


class TimeStepping(CompiledRecording, Integrator):
    """Base of the time-stepping schemes: the options, the step, the contacts, the counters.

    Parameters
    ----------
    scene, t0, q0, v0, t_bound
        See :class:`~moreau.integrators.base.Integrator`.
    options : StepOptions, optional
        The scheme's options object (``cls.Options``); or give them as
        keywords, from which it is made. Its fields become attributes
        (``self.h``, ``self.lcp_method``, ...).

    A subclass states its ``Options``, sets up its own start state in
    :meth:`_setup_scheme` (after the common part, before the compiled path is
    chosen) and steps in ``_step_impl``. With ``fixed_step`` (the default)
    the step ``h`` is required and the run's step count and recording are
    bounded (:func:`check_work`); ``self._k`` counts the steps taken
    (:func:`next_time`).

    Examples
    --------
    >>> from moreau.integrators.moreau_jean import MoreauJean
    >>> from moreau.scenes.bouncing_ball import BouncingBall
    >>> mj = MoreauJean(BouncingBall(), 0.0, [1.0], [0.0], 1.0, options=MoreauJean.Options(h=0.1))
    >>> mj.h, mj.theta, mj.counters["steps"]
    (0.1, 1.0, 0)
    >>> MoreauJean(BouncingBall(), 0.0, [1.0], [0.0], 1.0, theta=0.5)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `h` (the time step) is required for the moreau-jean scheme
    """

    takes_options_object = True
    #: the steps are ``h`` (:func:`next_time`); False where the scheme chooses them
    fixed_step = True

    def __init__(self, scene, t0, q0, v0, t_bound, options=None, **keywords):
        super().__init__(scene, t0, q0, v0, t_bound)
        self.options = options = self._take_options(options, keywords)
        for name, value in options.as_dict().items():
            setattr(self, name, value)
        if self.fixed_step:
            self.h = check_step(self.scheme, options.h)
            check_work(scene, self.t0, self.t_bound, self.h, self.save_every, options.max_steps)
            self._k = 0
        self.mu_c, self.e_c = check_scene_contacts(scene)
        nc = scene.ncontacts
        # contact -> its row in WT (frictional contacts only), -1 if frictionless
        self._trow = np.full(nc, -1, dtype=int)
        self._trow[scene.frictional_index] = np.arange(len(scene.frictional_index))
        self._closed = np.zeros(nc, dtype=bool)
        self.counters = self._new_counters()
        # the generic step's memory of its last LCP's support, one per place a step solves
        # one (solve_contact_problem's warm): see _lcp_warm
        self._lcp_memos = {}
        self._pending_initial = True
        self._setup_scheme()
        self._prev_reg = sliding_regimes(scene, self.q, self.v, self.t0)
        model = compiled_model_of(scene)
        if joint_row_count(scene):
            # a scheme's compiled loop solves no equality rows unless it has a loop of its
            # own for them (Moreau–Jean); otherwise a scene with joints takes the generic step
            model = self._joint_model(model, options)
            if model is None and options.fast is True:
                raise InputError(f"`fast=True`: the compiled loop of {self.scheme!r} solves no "
                                 f"joints of this scene ({joint_row_count(scene)} joint rows) "
                                 f"with these options; use fast='auto' or False (the generic "
                                 "step)")
        self._choose_compiled(options.fast, model, self.lcp_method,
                              getattr(options, "lemke_max_iter", None),
                              warm_start=self._warm_start())
        if self._fast:
            set_painleve_stop(self._lcp_ctl, nc, self.painleve == "stop")

    def _new_counters(self):
        """The run's statistics, all zero."""
        return {"steps": 0, **new_contact_counters(), "max_penetration": 0.0}

    def _setup_scheme(self):
        """The scheme's own start state (the options and the contacts are set)."""

    def _joint_model(self, model, options):
        """The compiled model to run a scene with joints on, or None for the generic step."""
        return None

    def _warm_start(self):
        """Whether the compiled path warm-starts its contact problems."""
        return False

    def _lcp_warm(self, site):
        """The generic step's warm-start memory for the contact problems solved at ``site``.

        Given to :func:`~moreau.integrators.contact_problem.solve_contact_problem`
        (``warm``, with the active contacts as ``warm_key``): where Lemke's path
        meets a tie it would finish in exact arithmetic, the support of the last
        problem solved there on the same contacts is tried before the QP,
        checked on the data. One memory per site, since a step may solve
        problems of several kinds (stages, iterates) whose supports differ.
        """
        return self._lcp_memos.setdefault(site, {})

    def _end_gaps(self, q1, t1, nc):
        """The ``nc`` gaps at the step's end ``(q1, t1)``, the deepest penetration counted."""
        if not nc:
            return np.zeros(0)
        gap = np.asarray(self.scene.gaps(q1, t1), dtype=float)
        self.counters["max_penetration"] = max(self.counters["max_penetration"],
                                               float(np.max(-gap, initial=0.0)))
        return gap
