"""The contact-problem solvers by name, and :func:`solve`.

A solver is a function ``fn(problem, *, max_iter=None, tol=None, **options)
-> ContactSolution``, registered under a name with
:func:`register_solver`. Each lives in a module of its own under
:mod:`moreau.contact.solvers`; every module there is imported (and so
registered) with :mod:`moreau.contact`.
"""

import inspect
from typing import Callable, NamedTuple

import numpy as np

from ..errors import InputError
from .problem import SOLVED, ContactSolution

__all__ = ["SolverEntry", "register_solver", "solver_names", "get_solver", "solve"]


class SolverEntry(NamedTuple):
    """A registered solver.

    Attributes
    ----------
    name : str
    fn : callable
        ``fn(problem, *, max_iter=None, tol=None, **options) -> ContactSolution``.
    equality_rows : bool
        Whether it solves problems with equality rows (``n_eq > 0``).
    max_contacts : int or None
        The most contacts it solves (None: any number).
    summary : str
        One line for listings.
    options : frozenset of str
        Its keyword options beyond ``max_iter`` and ``tol``.
    """

    name: str
    fn: Callable
    equality_rows: bool
    max_contacts: object
    summary: str
    options: frozenset


_SOLVERS = {}
_COMMON = ("max_iter", "tol")


def register_solver(name, fn, *, equality_rows=False, max_contacts=None, summary="", replace=False):
    """Register a contact-problem solver under ``name``.

    Parameters
    ----------
    name, fn, equality_rows, max_contacts, summary
        The fields of :class:`SolverEntry`; :func:`solve` refuses a problem
        with equality rows, or with more than ``max_contacts`` contacts, to a
        solver that does not take it.
    replace : bool
        Allow replacing a registered solver of the same name.

    Returns
    -------
    callable
        ``fn``, so that this can decorate.

    Examples
    --------
    >>> register_solver("lemke", lambda problem: None)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `name` 'lemke' is registered already (pass replace=True to replace it)
    """
    if not isinstance(name, str) or not name:
        raise InputError(f"`name` must be a non-empty string, got {name!r}")
    if name in _SOLVERS and not replace:
        raise InputError(f"`name` {name!r} is registered already (pass replace=True to replace it)")
    if not callable(fn):
        raise InputError(f"`fn` must be callable, got {type(fn).__name__}")
    params = inspect.signature(fn).parameters
    options = frozenset(k for k, p in params.items()
                        if p.kind is inspect.Parameter.KEYWORD_ONLY and k not in _COMMON)
    _SOLVERS[name] = SolverEntry(name, fn, bool(equality_rows), max_contacts, summary, options)
    return fn


def solver_names():
    """The registered solvers' names, sorted.

    Examples
    --------
    >>> from moreau.contact import solver_names
    >>> [n for n in ("auto", "closed-form", "lemke", "mlcp", "qp") if n in solver_names()]
    ['auto', 'closed-form', 'lemke', 'mlcp', 'qp']
    """
    return sorted(_SOLVERS)


def get_solver(name):
    """The :class:`SolverEntry` registered under ``name``.

    Raises
    ------
    InputError
        ``name`` is not registered (the message lists those that are).
    """
    try:
        return _SOLVERS[name]
    except (KeyError, TypeError):
        known = ", ".join(repr(k) for k in sorted(_SOLVERS))
        raise InputError(f"`method` must be one of {known}; got {name!r}") from None


def solve(problem, method="auto", *, max_iter=None, tol=None, **options):
    """Solve a :class:`~moreau.contact.ContactProblem`.

    Parameters
    ----------
    problem : ContactProblem
    method : str
        A registered solver (:func:`solver_names`): ``"auto"`` (one contact
        in closed form, up to 32 by Lemke with the QP fallback, more by
        NSGS, equality rows by ``"mlcp"``), ``"closed-form"``, ``"lemke"``,
        ``"qp"``, ``"mlcp"``, ``"nsgs"``, ``"apgd"``.
    max_iter : int, optional
        Pivot or iteration limit.
    tol : float, optional
        Bound on the certified violation; each solver has its default.
    **options
        The solver's own options.

    Returns
    -------
    ContactSolution
        Its ``status`` says whether it was solved; nothing uncertified is
        called solved.

    Raises
    ------
    InputError
        An unknown ``method`` or option, or a problem the method does not
        solve (equality rows, too many contacts).
    PainleveError
        One contact whose singular Delassus matrix gives no unique answer.
    moreau.lcp.mlcp.RankDeficientError
        Equality rows that are linearly dependent (redundant or inconsistent joints).

    Examples
    --------
    >>> import numpy as np
    >>> from moreau.contact import ContactProblem, solve
    >>> sol = solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]))
    >>> sol.status, sol.method, sol.pN.tolist(), sol.pT.tolist()
    ('solved', 'closed-form', [1.0], [-0.5])
    """
    entry = get_solver(method)
    if problem.n_eq and not entry.equality_rows:
        raise InputError(f"`method` {method!r} solves no equality rows; this problem has "
                         f"n_eq = {problem.n_eq} (use 'mlcp' or 'auto')")
    if entry.max_contacts is not None and problem.mu.size > entry.max_contacts:
        raise InputError(f"`method` {method!r} solves at most {entry.max_contacts} contact(s); "
                         f"this problem has {problem.mu.size}")
    for key in options:
        if key not in entry.options:
            raise InputError(f"`{key}` is not an option of method {method!r}; its options: "
                             + (", ".join(sorted(entry.options)) or "none beyond max_iter and tol"))
    if problem.n_rows == 0:
        none = np.zeros(0)
        return ContactSolution(none, none, none, none, SOLVED, 0.0, "none", 0,
                               "Nothing to solve: the problem has no rows.", ())
    return entry.fn(problem, max_iter=max_iter, tol=tol, **options)
