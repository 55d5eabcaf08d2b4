"""The contact problem of one time step, and its solution, as objects.

Row layout
----------
``W``, ``u_free`` and the impulse ``p`` stack ``m = n_eq + nc + nf`` rows::

    [E_0, ..., E_{n_eq-1},  N_0, ..., N_{nc-1},  T_{f_0}, ..., T_{f_{nf-1}}]

the bilateral (equality) rows first, then the normal row of every contact,
then one tangential row per *frictional* contact (``mu > 0``) in increasing
contact index ``f_0 < f_1 < ...``. A frictionless contact has no tangential
row. Without equality rows this is the order of
:func:`moreau.lcp.friction.build_friction_lcp` and of the schemes.

The laws, on the local velocities ``U = u_free + W p``:

* equality rows: ``U_E = eq_target``, ``p_E`` free (a joint; ``eq_target``
  holds a stabilisation term or a prescribed velocity, zero by default);
* normal rows, Newton's impact law:
  ``0 <= U_N + e min(vN_pre, 0)  _|_  p_N >= 0``;
* tangential rows, 2D Coulomb friction: ``|p_T| <= mu p_N``, and
  ``p_T = -mu p_N sign(U_T)`` where ``U_T != 0``.
"""

from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np

from ..errors import InputError

__all__ = ["ContactProblem", "ContactSolution", "SOLVED", "MAX_ITER", "FAILED"]

_NO_ROWS = np.zeros(0)
_NO_ROWS.setflags(write=False)

#: statuses of a :class:`ContactSolution`
SOLVED = "solved"
MAX_ITER = "max-iter"
FAILED = "failed"


def _array(name, value, ndim):
    # a read-only float copy, its rank and finiteness checked (one copy, no np.all wrapper:
    # the checks are most of a small problem's construction)
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` must be an array of real numbers, got {type(value).__name__}") from None
    if a.ndim != ndim:
        raise InputError(f"`{name}` must be {ndim}-D, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise InputError(f"`{name}` must be finite (no NaN or inf)")
    a.flags.writeable = False
    return a


def _support(name, value, n):
    # distinct integer indices in [0, n), as an int64 array
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim != 1 or (a.size and not np.issubdtype(a.dtype, np.integer)):
        raise InputError(f"`{name}` must be a 1-d sequence of integer indices, got {value!r}")
    a = a.astype(np.int64)
    if a.size and (a.min() < 0 or a.max() >= n or np.unique(a).size != a.size):
        raise InputError(f"`{name}` must hold distinct indices in [0, {n}) (the friction LCP's "
                         f"variables), got {a.tolist()}")
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class ContactProblem:
    """The velocity-level contact problem of one step (rows: module docstring).

    Parameters
    ----------
    W : array_like, shape (m, m)
        Delassus matrix over the stacked rows, ``m = n_eq + nc + nf``; a
        dense array (sparse storage is for the sparse solvers to come).
    u_free : array_like, shape (m,)
        Local velocities without impulses.
    mu : array_like, shape (nc,)
        Friction coefficients, ``>= 0``; ``mu = 0`` gives no tangential row.
    e : float or array_like, shape (nc,)
        Newton restitution coefficients in ``[0, 1]``.
    vN_pre : array_like, shape (nc,), optional
        Normal velocities before the step; the impact law uses their
        negative part. Default: the normal rows of ``u_free``.
    n_eq : int
        Number of leading equality (bilateral) rows.
    eq_target : array_like, shape (n_eq,), optional
        What the equality rows' velocities must equal; default zero.
    warm : array_like of int, optional
        A warm start without equality rows: the indices of the variables of
        the friction LCP (:func:`moreau.lcp.friction.build_friction_lcp`'s
        layout, ``nc + 3 nf`` of them) that were positive in the solution of
        an earlier problem with the same rows, the step before's. ``"auto"``
        tries that support's point where Lemke's path would be finished in
        exact arithmetic (:func:`moreau.lcp.solve_lcp`), checked on the data
        like any answer; other solvers ignore it.

    Raises
    ------
    InputError
        A shape that does not fit the layout, a negative ``mu``, ``e``
        outside ``[0, 1]``, a non-finite entry, a bad ``n_eq``; the message
        names the argument.

    Examples
    --------
    A mass sliding onto the ground (one frictional contact, rows N, T):

    >>> pb = ContactProblem(np.eye(2), [-1.0, 1.0], [0.5])
    >>> pb.n_contacts, pb.n_frictional, pb.n_rows
    (1, 1, 2)
    >>> ContactProblem(np.eye(2), [-1.0, 1.0], [0.0])
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `W` must have shape (1, 1) (n_eq = 0 equality rows, 1 normal rows, 0 tangential rows: one per contact with mu > 0), got (2, 2)
    """

    W: np.ndarray
    u_free: np.ndarray
    mu: np.ndarray
    e: np.ndarray = 0.0
    vN_pre: np.ndarray = None
    n_eq: int = 0
    eq_target: np.ndarray = None
    warm: np.ndarray = None

    def __post_init__(self):
        n_eq = self.n_eq
        if isinstance(n_eq, (bool, np.bool_)) or not isinstance(n_eq, (int, np.integer)) or n_eq < 0:
            raise InputError(f"`n_eq` must be an integer >= 0, got {n_eq!r}")
        mu = _array("mu", self.mu, 1)
        if np.any(mu < 0.0):
            raise InputError(f"`mu` must be >= 0 for every contact, got {mu.tolist()}")
        nc = mu.size
        e = self.e
        if np.ndim(e) == 0:
            e = np.full(nc, float(_array("e", e, 0)))
        e = _array("e", e, 1)
        if e.shape != (nc,):
            raise InputError(f"`e` must be a scalar or have one entry per contact ({nc}), got shape {e.shape}")
        if np.any(e < 0.0) or np.any(e > 1.0):
            raise InputError(f"`e` must lie in [0, 1] for every contact, got {e.tolist()}")
        frictional = np.flatnonzero(mu > 0.0)
        m = int(n_eq) + nc + frictional.size
        W = _array("W", self.W, 2)
        if W.shape != (m, m):
            raise InputError(f"`W` must have shape ({m}, {m}) (n_eq = {n_eq} equality rows, {nc} "
                             f"normal rows, {frictional.size} tangential rows: one per contact "
                             f"with mu > 0), got {W.shape}")
        u = _array("u_free", self.u_free, 1)
        if u.shape != (m,):
            raise InputError(f"`u_free` must have shape ({m},) like the rows of `W`, got {u.shape}")
        if self.vN_pre is None:
            vN = u[n_eq:n_eq + nc]
        else:
            vN = _array("vN_pre", self.vN_pre, 1)
            if vN.shape != (nc,):
                raise InputError(f"`vN_pre` must have one entry per contact ({nc}), got shape {vN.shape}")
        if self.eq_target is None:
            tgt = np.zeros(n_eq)
            tgt.setflags(write=False)
        else:
            tgt = _array("eq_target", self.eq_target, 1)
            if tgt.shape != (n_eq,):
                raise InputError(f"`eq_target` must have one entry per equality row ({n_eq}), "
                                 f"got shape {tgt.shape}")
        warm = None if self.warm is None else _support("warm", self.warm, nc + 3 * frictional.size)
        if warm is not None and n_eq:
            raise InputError(f"`warm` is a support of the friction LCP, which has no equality rows; "
                             f"got n_eq = {n_eq}")
        self.__dict__.update(W=W, u_free=u, mu=mu, e=e, vN_pre=vN, n_eq=int(n_eq), eq_target=tgt,
                             warm=warm, frictional=frictional)

    @classmethod
    def trusted(cls, W, u_free, mu, e, vN_pre, n_eq=0, eq_target=None, warm=None):
        """A problem from float arrays already in the layout, taken as they are (no checks, no copies).

        For the schemes' per-step path, whose data are built in the layout;
        ``mu``, ``e`` and ``vN_pre`` are float arrays over the contacts,
        ``warm`` None or an int64 array of distinct indices of the friction
        LCP's variables.
        """
        self = object.__new__(cls)
        # (the instance dict directly: a frozen dataclass's fields, without its per-field calls)
        self.__dict__.update(W=W, u_free=u_free, mu=mu, e=e, vN_pre=vN_pre, n_eq=n_eq, warm=warm,
                             eq_target=_NO_ROWS if eq_target is None and not n_eq
                             else np.zeros(n_eq) if eq_target is None else eq_target)
        return self

    @cached_property
    def frictional(self):
        """Indices of the frictional contacts (``mu > 0``), increasing: contact
        ``frictional[k]`` owns tangential row ``n_eq + nc + k``."""
        return np.flatnonzero(self.mu > 0.0)

    @property
    def n_contacts(self):
        """Number of contacts ``nc``."""
        return self.mu.size

    @property
    def n_frictional(self):
        """Number of frictional contacts ``nf`` (tangential rows)."""
        return self.frictional.size

    @property
    def n_rows(self):
        """``m = n_eq + nc + nf``."""
        return self.n_eq + self.mu.size + self.frictional.size

    @property
    def normal_rows(self):
        """Slice of the normal rows in ``W``."""
        return slice(self.n_eq, self.n_eq + self.mu.size)

    @property
    def tangential_rows(self):
        """Slice of the tangential rows in ``W``."""
        return slice(self.n_eq + self.mu.size, self.n_rows)

    def impact_shift(self):
        """``e min(vN_pre, 0)``, the shift of each normal row by Newton's law."""
        return self.e * np.minimum(self.vN_pre, 0.0)

    def velocities(self, p):
        """``U = u_free + W p``."""
        return self.u_free + self.W @ np.asarray(p, dtype=float)

    def __repr__(self):
        return (f"ContactProblem(n_eq={self.n_eq}, n_contacts={self.n_contacts}, "
                f"n_frictional={self.n_frictional})")


class ContactSolution(NamedTuple):
    """What :func:`moreau.contact.solve` returns (immutable).

    Attributes
    ----------
    p : ndarray, shape (m,)
        All impulses, stacked like the rows of the problem's ``W``.
    p_eq : ndarray, shape (n_eq,)
        The equality rows' impulses.
    pN, pT : ndarray, shape (nc,)
        Normal and tangential impulse of each contact (``pT = 0`` where
        ``mu = 0``).
    status : str
        ``"solved"`` (certified on the caller's data), ``"max-iter"`` or ``"failed"``.
    residual : float
        Scaled residual recomputed on the caller's data: for the friction
        LCP :func:`moreau.lcp.lcp_residual` of
        :func:`~moreau.lcp.friction.build_friction_lcp` (the one-contact closed
        form computes the same number without building it), with equality
        rows :func:`moreau.lcp.mlcp.mlcp_residual` of the friction MLCP.
        For ``"nsgs"`` and ``"apgd"``, the natural map of FCLib's problem,
        ``||F(r)|| / (1 + ||q||)``, in the units of their ``tol``.
        A diagnostic; success is decided by the certified violation
        (:func:`moreau.lcp.lcp_violation`) at the solver's tolerance.
    method : str
        What produced ``p``: ``"closed-form"``, ``"lemke"``, ``"qp"``,
        ``"lp"``, ``"enumerate"``, ``"pieces"``, ``"mlcp"``, ...
    iterations : int
        Pivots (Lemke) or iterations of the method that produced ``p``.
    message : str
        What happened, in words.
    path : tuple of str
        Every method that ran, in order.
    lcp : LCPResult or None
        The raw result of the last LCP solve, where one ran.
    """

    p: np.ndarray
    p_eq: np.ndarray
    pN: np.ndarray
    pT: np.ndarray
    status: str
    residual: float
    method: str
    iterations: int = 0
    message: str = ""
    path: tuple = ()
    lcp: object = None

    @property
    def success(self):
        """``status == "solved"``."""
        return self.status == SOLVED

    def __repr__(self):
        return (f"ContactSolution(status={self.status!r}, method={self.method!r}, "
                f"iterations={self.iterations}, residual={self.residual:.3g}, n={self.p.size})")
