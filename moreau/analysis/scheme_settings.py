"""The settings of one steady-state computation under any registered scheme.

A :class:`Scheme` names a registered scheme with its step, its ``theta``,
the shooting tolerance and the scheme's other options, checked against the
scheme when the settings are made (so that a setting the scheme does not
take never reaches a worker process). Sweeps, atlases and ``moreau steady``
carry one; :func:`steady_of` computes the steady state it describes.
"""

import math

from ..errors import InputError
from ..integrators import INTEGRATORS, get_integrator
from ..integrators.base import SchemeOptions, check_options, scheme_options
from .steady_state import find_steady_state

__all__ = ["Scheme", "make_scheme", "steady_of", "ED_REFERENCE", "ADAPTIVE_SHOOTING_RTOL"]

#: shooting tolerance of a scheme that picks its own steps (a compliant contact's Radau or
#: RK45), when none is given: its period map is only as smooth as its error control
ADAPTIVE_SHOOTING_RTOL = 1e-8


class Scheme(tuple):
    """Settings of one steady-state computation: ``(name, theta, steps_per_period, rtol, options)``.

    ``name`` is any registered scheme (:data:`moreau.integrators.INTEGRATORS`),
    or a scheme's options object (``MoreauJean.Options(theta=0.5)``), whose
    scheme, ``theta`` and other options it takes (not ``h``: the step is
    ``steps_per_period``).
    ``steps_per_period`` applies to the time-stepping schemes (those with a
    step ``h``) and ``theta`` to those with a ``theta``; both are None
    otherwise. ``rtol`` is the shooting tolerance. ``options`` holds the
    scheme's other options as sorted ``(name, value)`` pairs (a compliant
    contact's ``stiffness``), checked against the scheme when the settings are
    made, so that a setting the scheme does not take never reaches a worker.

    Examples
    --------
    A scheme's names: short, in full, and in words.

    >>> mj = Scheme.moreau_jean(0.5, 2000)
    >>> mj.label, mj.full_label, mj.description
    ('mj_theta0.5', 'moreau-jean_theta0.5_N2000', 'Moreau–Jean θ = 0.5 (2000 steps/period)')
    >>> rk = Scheme("compliant-rk45", options={"stiffness": 1e6})
    >>> rk.label, rk.description
    ('compliant-rk45_stiffness1e+06', 'compliant-rk45 (stiffness=1e+06)')
    >>> from moreau.integrators.moreau_jean import MoreauJean
    >>> Scheme(MoreauJean.Options(theta=0.5), steps_per_period=2000).label
    'mj_theta0.5'
    >>> Scheme("event-driven", theta=0.5)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `theta` is not an option of scheme 'event-driven'
    """

    def __new__(cls, name, theta=None, steps_per_period=None, rtol=None, options=None):
        name, theta, options = _from_object(name, theta, options)
        takes = _takes(name)
        opts = dict(options or {})
        for key, val in (("theta", theta), ("steps_per_period", steps_per_period)):
            if key in opts:
                raise InputError(f"`{key}` is a setting of its own, not one of `options`")
        if "h" in opts:
            raise InputError("give the step as `steps_per_period`, not as the option `h`")
        if theta is not None:
            if "theta" not in takes:
                raise InputError(f"`theta` is not an option of scheme {name!r}")
            theta = float(theta)
            if not 0.5 <= theta <= 1.0:
                raise InputError(f"`theta` must be in [1/2, 1], got {theta!r}")
        elif "theta" in takes:
            raise InputError(f"`theta` is required for scheme {name!r}")
        if steps_per_period is not None:
            if "h" not in takes:
                raise InputError(f"`steps_per_period` applies only to time-stepping schemes; "
                                 f"scheme {name!r} chooses its own steps")
            if isinstance(steps_per_period, bool) or int(steps_per_period) != steps_per_period \
                    or int(steps_per_period) < 8:
                raise InputError(f"`steps_per_period` must be an integer >= 8, got "
                                 f"{steps_per_period!r}")
            steps_per_period = int(steps_per_period)
        elif "h" in takes:
            raise InputError(f"`steps_per_period` is required for scheme {name!r}")
        if rtol is not None and not (math.isfinite(rtol) and rtol > 0):
            raise InputError(f"`rtol` must be > 0, got {rtol!r}")
        check_options(name, opts)
        return super().__new__(cls, (name, theta, steps_per_period,
                                     None if rtol is None else float(rtol),
                                     tuple(sorted(opts.items()))))

    @classmethod
    def moreau_jean(cls, theta, steps_per_period, rtol=None):
        return cls("moreau-jean", theta, steps_per_period, rtol)

    name = property(lambda self: self[0])
    theta = property(lambda self: self[1])
    steps_per_period = property(lambda self: self[2])
    rtol = property(lambda self: self[3])
    options = property(lambda self: dict(self[4]))

    @property
    def label(self):
        """A short name for columns and file names: ``ed``, ``mj_theta1``, or the scheme's name
        with its step and options."""
        if self.name == "event-driven" and not self[4]:
            return "ed"
        if self.name == "moreau-jean" and not self[4]:
            return f"mj_theta{self.theta:g}"
        return self.full_label

    @property
    def record(self):
        """The scheme as a JSON sidecar records it (name, theta, steps, rtol, options)."""
        return {"name": self.name, "theta": self.theta, "steps_per_period": self.steps_per_period,
                "rtol": self.rtol, "options": self.options}

    @property
    def full_label(self):
        """:attr:`label` without the short forms: the scheme's name, its step and its options."""
        return "_".join([self.name] + self._parts("theta{:g}", "N{}", ""))

    @property
    def description(self):
        """The settings in words, for figure legends (examples: :class:`Scheme`)."""
        if self.name == "moreau-jean":
            return f"Moreau\u2013Jean \u03b8 = {self.theta:g} ({self.steps_per_period} steps/period)"
        extra = self._parts("\u03b8 = {:g}", "{} steps/period", "=")
        return self.name + (f" ({', '.join(extra)})" if extra else "")

    def _parts(self, theta, steps, sep):
        # the settings made, each in its format: theta's, the steps', an option's `name sep value`
        parts = [theta.format(self.theta)] if self.theta is not None else []
        if self.steps_per_period is not None:
            parts.append(steps.format(self.steps_per_period))
        return parts + [f"{k}{sep}{v:g}" if isinstance(v, float) else f"{k}{sep}{v}"
                        for k, v in self[4]]

    def __getnewargs__(self):
        return (self[0], self[1], self[2], self[3], dict(self[4]))


def _from_object(scheme, theta, options):
    """``(name, theta, options)`` of a scheme given by name or as its options object."""
    if not isinstance(scheme, SchemeOptions):
        return scheme, theta, options
    given = scheme.without_step("`steps_per_period`")
    if "theta" in scheme.names():
        given.pop("theta", None)
        if theta is not None:
            raise InputError("`theta` is given by the options object; do not give it beside it")
        theta = scheme.theta
    return scheme.scheme, theta, {**given, **dict(options or {})}


def _takes(name):
    """The options scheme ``name`` takes (an unknown name lists the registered ones)."""
    return scheme_options(get_integrator(name)) or ()


ED_REFERENCE = Scheme("event-driven", rtol=1e-10)


def make_scheme(scheme="event-driven", theta=None, steps_per_period=None, rtol=None, options=None):
    """The :class:`~moreau.analysis.engine.Scheme` of a sweep; refuses settings that would not act.

    ``theta`` applies to the schemes that take one (Moreau–Jean, default 1),
    ``steps_per_period`` to the time-stepping schemes (default 1000);
    ``rtol`` is the shooting tolerance of any scheme (default 1e-10 for the
    event-driven one, the scheme's own otherwise); ``options`` are the
    scheme's other options.

    Examples
    --------
    >>> make_scheme("moreau-jean", steps_per_period=500)
    ('moreau-jean', 1.0, 500, None, ())
    >>> make_scheme("compliant-radau", options={"stiffness": 1e5})
    ('compliant-radau', None, None, None, (('stiffness', 100000.0),))
    >>> make_scheme("event-driven", theta=0.5)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `--theta` does not act with `--scheme event-driven`: it applies to schemes with a theta (moreau-jean, moreau-jean-projected)
    """
    scheme, theta, options = _from_object(scheme, theta, options)
    takes = _takes(scheme)
    for flag, key, val in (("--theta", "theta", theta),
                           ("--steps-per-period", "h", steps_per_period)):
        if val is not None and key not in takes:
            users = [n for n in sorted(INTEGRATORS) if key in (scheme_options(INTEGRATORS[n]) or ())]
            what = "schemes with a theta" if key == "theta" else "time-stepping schemes"
            raise InputError(f"`{flag}` does not act with `--scheme {scheme}`: it applies to "
                             f"{what} ({', '.join(users)})")
    if "theta" in takes and theta is None:
        theta = 1.0
    if "h" in takes and steps_per_period is None:
        steps_per_period = 1000
    if scheme == "event-driven" and rtol is None:
        rtol = 1e-10
    return Scheme(scheme, theta, steps_per_period, rtol, options)


def _adaptive_rtol(scheme):
    """The shooting tolerance of an adaptive scheme: :data:`ADAPTIVE_SHOOTING_RTOL`, or
    ``100 tol`` where the scheme states its error tolerance (``error_tolerance_option``)
    and that is tighter: a weakly contracting map (the friction drive at 2000 Hz, slope
    of P - I about 7e-3) turns the shooting's residual into an orbit error 1/slope larger,
    which at 1e-8 capped Studer's scheme at 2e-6 whatever its own tolerance.

    It is never below ``10 tol`` (the given tolerance or the scheme's default): the map
    is only as accurate as its error control, so a residual below about ``tol`` is out
    of reach (Studer's default ``tol = 1e-6`` stalled at a residual of 6.3e-7 for 60
    Newton steps against a target of 1e-8 at 185 Hz).

    Examples
    --------
    >>> float(f"{_adaptive_rtol(make_scheme('studer-extrapolation')):.3g}")
    1e-05
    >>> _adaptive_rtol(make_scheme("studer-extrapolation", options={"tol": 1e-10}))
    1e-08
    """
    cls = get_integrator(scheme.name)
    name = getattr(cls, "error_tolerance_option", None)
    opts = dict(scheme.options)
    if not name:
        return ADAPTIVE_SHOOTING_RTOL
    tol = float(opts.get(name, getattr(cls.Options(), name)))
    return max(min(ADAPTIVE_SHOOTING_RTOL, 100.0 * tol), 10.0 * tol)


def steady_of(scene, scheme, max_period=1, statistical=False, guess=None, max_iter=None,
              statistical_options=None):
    """:func:`find_steady_state` of ``scene`` with the settings of a :class:`Scheme`.

    ``scheme`` may be a scheme's options object, with :func:`make_scheme`'s defaults.

    Sweeps, atlases and comparisons want a periodic orbit or a failure, so
    the statistical steady state (:mod:`moreau.analysis.statistical`) is
    only the fallback with ``statistical=True`` (``moreau steady``).
    ``guess`` is a neighbouring point's period-1 orbit to start the
    shooting from (continuation, :mod:`moreau.analysis.continuation`);
    ``max_iter`` bounds its iterations (the solver's default otherwise);
    ``statistical_options`` (``max_periods``, ``precision``, ``starts``, ...)
    go to the statistical steady state.

    Examples
    --------
    >>> from moreau.scenes import make_scene
    >>> steady_of(make_scene("friction-drive", frequency=20.0), ED_REFERENCE).mode
    'NS'
    """
    if isinstance(scheme, SchemeOptions):
        scheme = make_scheme(scheme)
    extra = dict(statistical_options or {})
    stat = {}
    if "max_periods" in extra:
        stat["statistical_budget"] = extra.pop("max_periods")
    if extra:
        stat["statistical_options"] = extra
    if scheme.name == "moreau-jean":
        # the compiled discrete period map names its tolerance `tol`
        kw = {} if scheme.rtol is None else {"tol": scheme.rtol}
        if max_iter is not None:
            kw["max_iter"] = max_iter
        return find_steady_state(scene, scheme="moreau-jean", theta=scheme.theta,
                                 steps_per_period=scheme.steps_per_period, max_period=max_period,
                                 statistical=statistical, guess=guess, **stat, **kw,
                                 **scheme.options)
    # an adaptive scheme's period map carries its own error tolerance: the shooting
    # aims above it unless told otherwise (a fixed-step map is deterministic)
    kw = {"rtol": scheme.rtol if scheme.rtol is not None else
          1e-10 if scheme.steps_per_period is not None else _adaptive_rtol(scheme)}
    if scheme.steps_per_period is not None:
        kw["steps_per_period"] = scheme.steps_per_period
    if scheme.theta is not None:
        kw["theta"] = scheme.theta
    if max_iter is not None:
        kw["max_iter"] = max_iter
    if scheme.options:
        kw["scheme_options"] = scheme.options
    return find_steady_state(scene, scheme=scheme.name, max_period=max_period,
                             statistical=statistical, guess=guess, **stat, **kw)
