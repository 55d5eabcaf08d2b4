"""The adapter point to FCLib's layout of a frictional contact problem (the layout, not its files).

FCLib's local problem (``FrictionContactProblem``; Acary, Brémond, Koziol,
Pérignon 2014, "FCLib: a collection of discrete 3D frictional contact
problems", JOTA 160) is ``U = W r + q`` over ``nc`` contacts of dimension
``d`` (here 2), each contact's rows interleaved ``[N_i, T_i]``, every
contact with its Coulomb cone ``|r_T| <= mu r_N`` (and De Saxcé's
complementarity, the same law as this package's at a contact). Solvers
written in that layout (``moreau.contact.solvers.nsgs``, ...) reach a
:class:`~moreau.contact.ContactProblem` through :func:`to_fclib` and
:func:`from_fclib`:

* ``q`` is ``u_free`` with each normal row shifted by Newton's law,
  ``e min(vN_pre, 0)``, so that the law becomes ``0 <= U_N _|_ r_N >= 0``;
* a frictionless contact (no tangential row here) gets a tangential row
  with ``W_TT = 1``, no coupling, ``q_T = 0`` and ``mu = 0``: its cone
  forces ``r_T = 0``, so the added row changes nothing;
* equality rows are not in FCLib's local problem: eliminate them first
  (:func:`moreau.contact.solvers.mlcp.eliminate_equalities`).

``W`` comes out dense, like the problem's; a sparse solver converts it
(``scipy.sparse.csr_array(local.W)``). A solver ``fn(W, q, mu) -> r`` in this
layout becomes a registered one as
``register_solver(name, lambda problem, *, max_iter=None, tol=None: ...)``
that calls ``from_fclib(problem, fn(*to_fclib(problem)[:3]))`` and returns a
:class:`~moreau.contact.ContactSolution` with its residual and status.
"""

from typing import NamedTuple

import numpy as np

from ..errors import InputError

__all__ = ["LocalProblem", "fclib_rows", "to_fclib", "from_fclib"]


class LocalProblem(NamedTuple):
    """FCLib's local frictional contact problem: ``U = W r + q``, rows ``[N_0, T_0, N_1, T_1, ...]``."""

    W: np.ndarray
    q: np.ndarray
    mu: np.ndarray
    dimension: int = 2


def fclib_rows(problem):
    """Where each FCLib row comes from: the row of ``problem.W``, or -1 for an added tangential row.

    Examples
    --------
    >>> from moreau.contact import ContactProblem
    >>> fclib_rows(ContactProblem(np.eye(3), [0.0] * 3, [0.5, 0.0])).tolist()
    [0, 2, 1, -1]
    """
    nc = problem.n_contacts
    rows = np.full(2 * nc, -1, dtype=np.int64)
    rows[0::2] = np.arange(nc)
    rows[2 * problem.frictional + 1] = nc + np.arange(problem.n_frictional)
    return rows


def to_fclib(problem):
    """``problem`` (no equality rows) in FCLib's interleaved layout.

    Examples
    --------
    >>> from moreau.contact import ContactProblem
    >>> lp = to_fclib(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5], e=0.5, vN_pre=[-2.0]))
    >>> lp.q.tolist(), lp.mu.tolist()
    ([-2.0, 1.0], [0.5])
    """
    if problem.n_eq:
        raise InputError(f"`problem` has n_eq = {problem.n_eq} equality rows, which FCLib's local "
                         f"problem does not hold: eliminate them first "
                         f"(moreau.contact.solvers.mlcp.eliminate_equalities)")
    rows = fclib_rows(problem)
    have = rows >= 0
    n = rows.size
    W = np.zeros((n, n))
    W[np.ix_(have, have)] = problem.W[np.ix_(rows[have], rows[have])]
    W[~have, ~have] = 1.0
    q = np.zeros(n)
    q[have] = problem.u_free[rows[have]]
    q[0::2] += problem.impact_shift()
    return LocalProblem(W, q, problem.mu.copy(), 2)


def from_fclib(problem, r):
    """The stacked impulse ``p`` of ``problem`` (its rows) from FCLib's ``r``.

    Examples
    --------
    >>> from moreau.contact import ContactProblem
    >>> pb = ContactProblem(np.eye(3), [0.0] * 3, [0.5, 0.0])
    >>> from_fclib(pb, np.array([1.0, -0.5, 2.0, 0.0])).tolist()
    [1.0, 2.0, -0.5]
    """
    rows = fclib_rows(problem)
    r = np.asarray(r, dtype=float)
    if r.shape != rows.shape:
        raise InputError(f"`r` must have shape {rows.shape} (2 rows per contact), got {r.shape}")
    p = np.zeros(problem.n_rows)
    have = rows >= 0
    p[rows[have]] = r[have]
    return p
