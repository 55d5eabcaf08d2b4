"""Exception hierarchy of :mod:`moreau`.

Every exception the package raises on purpose derives from :class:`MoreauError`,
so ``except MoreauError`` catches them all, except :class:`Interrupted`: a
``KeyboardInterrupt`` carrying what an interrupted run kept, which no
``except Exception`` may swallow. Bad input additionally derives from
:class:`ValueError`, so code that already handles ``ValueError`` keeps working.
"""

__all__ = [
    "MoreauError",
    "InputError",
    "IllPosedError",
    "PainleveError",
    "ContactLostError",
    "LCPError",
    "ConvergenceError",
    "RunawayError",
    "BudgetExhaustedError",
    "ResidualFloorError",
    "WorkerError",
    "Interrupted",
]


class MoreauError(Exception):
    """Root of all errors raised by :mod:`moreau`."""


class InputError(MoreauError, ValueError):
    """An argument breaks a stated rule (shape, sign, range, finiteness).

    The message names the argument in backticks and states the rule.
    """


class IllPosedError(MoreauError):
    """The mechanical model has no (unique) solution at the current state."""


class PainleveError(IllPosedError):
    """The Painlevé condition ``1 - mu*tan(phi) > 0`` is violated."""


class ContactLostError(IllPosedError):
    """A method that assumes permanent contact met a state where contact is lost."""


class LCPError(MoreauError):
    """A linear complementarity problem could not be solved."""


class ConvergenceError(MoreauError):
    """An iterative procedure (shooting, root finding) did not converge."""


class RunawayError(ConvergenceError):
    """No steady state exists: the driven body runs away (e.g. past the motor's stall load)."""


class ResidualFloorError(ConvergenceError):
    """A period map whose fixed point exists only to a residual above the tolerance.

    A time-stepping scheme's period map is piecewise smooth (its switches
    are locked to the step grid), so ``P(x) - x`` can jump over zero.
    ``state`` is the best ``(q, v)`` found at the section (a start on or near
    the attractor for a statistical steady state), ``residual`` its residual
    relative to the velocity scale.
    """

    def __init__(self, message, state=None, residual=None):
        super().__init__(message)
        self.state, self.residual = state, residual


class BudgetExhaustedError(ConvergenceError):
    """A statistical steady state whose running mean was not stationary within its budget.

    ``status`` is ``"budget-exhausted"``; ``periods`` the drive periods
    simulated; ``mean`` and ``half_width`` the estimate so far (None where
    there was none), which is *not* a result: the run had not settled;
    ``series`` the displacements per period (for a look at the drift).
    """

    status = "budget-exhausted"

    def __init__(self, message, periods=0, mean=None, half_width=None, series=None):
        super().__init__(message)
        self.periods, self.mean, self.half_width = int(periods), mean, half_width
        self.series = series


class WorkerError(MoreauError):
    """A local worker process of a parallel run ended unexpectedly (a signal, out of memory).

    The run stops (its pool is broken); the points finished before are kept
    in the cache, so that the same command resumes.

    Attributes
    ----------
    done, total : int
        Points finished (computed or read from the cache) and asked for.
    cache_dir : str or None
        Where the finished points are kept.

    Examples
    --------
    >>> str(WorkerError("exit codes {SIGKILL(-9)}", 3, 10, "out/cache", "sweep mu"))
    'sweep mu: a worker process ended unexpectedly (exit codes {SIGKILL(-9)}; killed, or out of memory?): 3 of 10 points finished, kept in out/cache; run the same command again to resume'
    """

    def __init__(self, why, done, total, cache_dir=None, what="run"):
        self.done, self.total, self.cache_dir = int(done), int(total), cache_dir
        kept = (f", kept in {cache_dir}; run the same command again to resume"
                if cache_dir is not None else " (no cache: nothing kept)")
        super().__init__(f"{what}: a worker process ended unexpectedly ({why}; killed, or out "
                         f"of memory?): {self.done} of {self.total} points finished{kept}")


class Interrupted(KeyboardInterrupt):
    """A long run stopped by the user (Ctrl-C); the message says what was kept.

    A subclass of ``KeyboardInterrupt``, so that code catching
    ``Exception`` (a failing point becoming a status) never takes an
    interrupt for a failure.

    Attributes
    ----------
    done, total : int
        Points (or ``unit``) finished (computed or read from the cache) and asked for.
    cache_dir : str or None
        Where the finished points are kept; a rerun with the same cache
        reads them instead of computing them again.

    Examples
    --------
    >>> str(Interrupted(3, 10, "out/cache", "sweep mu"))
    'sweep mu: 3 of 10 points finished, kept in out/cache'
    >>> str(Interrupted(4, 6, "out/cache", "stress catalogue", unit="cells"))
    'stress catalogue: 4 of 6 cells finished, kept in out/cache'
    """

    def __init__(self, done, total, cache_dir=None, what="run", unit="points"):
        self.done, self.total, self.cache_dir = int(done), int(total), cache_dir
        kept = f", kept in {cache_dir}" if cache_dir is not None else " (no cache: nothing kept)"
        super().__init__(f"{what}: {self.done} of {self.total} {unit} finished{kept}")
