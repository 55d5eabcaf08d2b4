"""Integrator base class and the :func:`simulate` front end.

Modelled on ``scipy.integrate``: the public :meth:`Integrator.step` owns the
status, the time and the counters; subclasses implement ``_step_impl`` and
record samples with ``_record``. :func:`simulate` drives any registered scheme
to the end of the interval and returns a :class:`SimulationResult`; an
interrupted run (Ctrl-C) keeps what it had finished.
"""

import numpy as np

from .._validate import finite_scalar
from ..errors import ContactLostError, InputError, LCPError, MoreauError, PainleveError
from .result import STATUS_MESSAGES, SimulationResult

__all__ = ["Integrator", "simulate", "INTEGRATORS", "register_integrator"]

#: registry name -> Integrator subclass, filled by :func:`register_integrator`
INTEGRATORS = {}


def register_integrator(name):
    """Class decorator registering an :class:`Integrator` subclass under ``name``."""
    def deco(cls):
        INTEGRATORS[name] = cls
        cls.scheme = name
        return cls
    return deco


class Integrator:
    """Base class of integration schemes over a :class:`~moreau.scenes.base.Scene`.

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

    def __init__(self, scene, t0, q0, v0, t_bound):
        self.scene = scene
        self.t0 = finite_scalar("t0", t0)
        self.t_bound = finite_scalar("t_bound", t_bound)
        if not self.t_bound > self.t0:
            raise InputError(f"`t_bound` must be > `t0` ({self.t0!r}), got {self.t_bound!r}")
        n = scene.ndof
        self.q = _state_vector("q0", q0, n)
        self.v = _state_vector("v0", v0, n)
        self.t = self.t0
        self.status = "running"
        self.status_code = 0
        self.message = ""
        self.counters = {"steps": 0}
        self.events = []
        self._samples = []

    # -- public API ---------------------------------------------------------
    def step(self):
        """Advance by one step (or to the next event); return the status string."""
        if self.status != "running":
            raise MoreauError(f"cannot step an integrator whose status is {self.status!r}")
        try:
            self._step_impl()
        except PainleveError as exc:
            self._fail(-1, str(exc))
        except ContactLostError as exc:
            self._fail(-2, str(exc))
        except LCPError as exc:
            self._fail(-3, str(exc))
        except InputError:
            raise
        except (MoreauError, FloatingPointError) as exc:
            self._fail(-5, f"{STATUS_MESSAGES[-5]} {type(exc).__name__}: {exc}")
        else:
            self.counters["steps"] += 1
            if self.t >= self.t_bound:
                self.status = "finished"
                self.message = STATUS_MESSAGES[0]
        return self.status

    def interrupt(self, message=None):
        """Stop the run as interrupted (status ``-4``); what was recorded is kept.

        For drivers such as :func:`simulate` that catch ``KeyboardInterrupt``.
        """
        self._fail(-4, message or STATUS_MESSAGES[-4])

    def _fail(self, code, message):
        self.status = "failed"
        self.status_code = code
        self.message = message

    # -- for subclasses -----------------------------------------------------
    def _step_impl(self):
        raise NotImplementedError

    def _record(self, t, q, v, regime, force_N, force_T, slip, gap):
        self._samples.append((t, np.array(q, float), np.array(v, float),
                              np.atleast_1d(regime), np.atleast_1d(force_N),
                              np.atleast_1d(force_T), np.atleast_1d(slip),
                              np.atleast_1d(gap)))

    def result(self):
        """Assemble the samples recorded so far into a :class:`SimulationResult`."""
        nc = self.scene.ncontacts
        n = self.scene.ndof
        if self._samples:
            cols = list(zip(*self._samples))
            t = np.array(cols[0], float)
            q, v = np.array(cols[1]).reshape(-1, n), np.array(cols[2]).reshape(-1, n)
            reg = np.array(cols[3], int).reshape(len(t), -1)
            fN, fT, slip, gap = (np.array(c, float).reshape(len(t), -1) for c in cols[4:])
        else:
            t = np.zeros(0)
            q = v = np.zeros((0, n))
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


def simulate(scene, t_span, q0, v0, method, progress=False, **options):
    """Integrate ``scene`` over ``t_span`` with the scheme registered as ``method``.

    Parameters
    ----------
    scene : Scene
    t_span : (float, float)
        Dimensionless start and end time.
    q0, v0 : array_like
        Initial state.
    method : str
        A key of :data:`INTEGRATORS` (e.g. ``"moreau-jean"``).
    progress : bool
        Show a tqdm progress bar over simulated time.
    **options
        Passed to the integrator's constructor.

    Returns
    -------
    SimulationResult
        Status ``-4`` if interrupted by ``KeyboardInterrupt``; the samples
        recorded until then are kept.
    """
    if method not in INTEGRATORS:
        raise InputError(f"`method` must be one of {sorted(INTEGRATORS)}, got {method!r}")
    t0, t1 = t_span
    integ = INTEGRATORS[method](scene, t0, q0, v0, t1, **options)
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=float(t1 - t0), unit="t", leave=False)
    last = integ.t
    try:
        while integ.status == "running":
            integ.step()
            if bar is not None:
                bar.update(integ.t - last)
                last = integ.t
    except KeyboardInterrupt:
        integ.interrupt()
    finally:
        if bar is not None:
            bar.close()
    return integ.result()
