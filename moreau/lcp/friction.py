"""The velocity-level LCP of 2D contact with Coulomb friction and Newton impacts.

Given the Delassus matrix ``W`` and free velocity ``v_free`` of one time step,
the post-step contact velocities are ``v = v_free + W p`` where ``p`` stacks
the contact impulses. Rows (and columns) of ``W``, ``v_free`` and ``p`` are in
the order used by :class:`moreau.model.scene.Scene`::

    [N_0, ..., N_{nc-1},  T_{f_0}, ..., T_{f_{nf-1}}]

all normal rows first, then one tangential row per *frictional* contact
(``mu > 0``), in increasing contact index ``f_0 < f_1 < ...``.

LCP variables and rows
----------------------
Contact ``i`` with ``mu_i > 0`` owns four consecutive LCP variables, and the
rows of ``w = M z + q`` in the same places::

    z:  p_N      p_T+          p_T-           beta
    w:  v_N + e v_N_pre^-    v_T + beta    -v_T + beta    mu p_N - p_T+ - p_T-

with ``p_T = p_T+ - p_T-`` and ``v_N_pre^- = min(v_N_pre, 0)`` (Newton's
impact law: the normal velocity after the step must reach ``-e`` times the
approach velocity, or more). Contact ``i`` with ``mu_i = 0`` owns one
variable, ``p_N``, and one row. Blocks follow contact order, so the LCP size
is ``nc + 3 nf``. :class:`FrictionLayout` holds the indices.

Reading the solution: ``beta`` equals ``|v_T|``; in stick ``v_T = 0`` and
``|p_T| <= mu p_N``; in slip ``|p_T| = mu p_N`` with ``p_T`` opposite to
``v_T``.
"""

from typing import NamedTuple

import numpy as np

from .._validate import finite_array
from ..errors import InputError

__all__ = [
    "FrictionLayout",
    "FrictionLCP",
    "build_friction_lcp",
    "friction_impulses",
    "contact_velocities",
]


class FrictionLayout:
    """Where each contact's variables sit in the friction LCP.

    Attributes
    ----------
    n_contacts : int
        Number of contacts ``nc``.
    frictional : ndarray of int
        Contacts with ``mu > 0``, increasing; contact ``frictional[k]`` owns
        row ``nc + k`` of ``W``.
    normal, tplus, tminus, beta : ndarray of int, shape (nc,)
        LCP index of each contact's ``p_N``, ``p_T+``, ``p_T-``, ``beta``;
        ``-1`` for a frictionless contact's tangential entries.
    mu, e : ndarray, shape (nc,)
        Friction and restitution coefficients.
    size : int
        Size of the LCP, ``nc + 3 nf``.
    """

    __slots__ = ("n_contacts", "frictional", "normal", "tplus", "tminus", "beta", "mu", "e", "size")

    def __init__(self, mu, e):
        mu = np.asarray(mu, dtype=float)
        nc = mu.shape[0]
        self.n_contacts = nc
        self.mu = mu
        self.e = np.asarray(e, dtype=float)
        self.frictional = np.flatnonzero(mu > 0.0)
        self.normal = np.empty(nc, dtype=np.int64)
        self.tplus = np.full(nc, -1, dtype=np.int64)
        self.tminus = np.full(nc, -1, dtype=np.int64)
        self.beta = np.full(nc, -1, dtype=np.int64)
        k = 0
        for i in range(nc):
            self.normal[i] = k
            if mu[i] > 0.0:
                self.tplus[i] = k + 1
                self.tminus[i] = k + 2
                self.beta[i] = k + 3
                k += 4
            else:
                k += 1
        self.size = k

    @property
    def n_frictional(self):
        return len(self.frictional)

    def __repr__(self):
        return f"FrictionLayout(n_contacts={self.n_contacts}, n_frictional={self.n_frictional}, size={self.size})"


class FrictionLCP(NamedTuple):
    """``M``, ``q`` and the layout of a friction LCP; unpacks as ``M, q, layout``."""

    M: np.ndarray
    q: np.ndarray
    layout: FrictionLayout


def _coefficients(mu, e, nc=None):
    mu = finite_array("mu", mu)
    if mu.ndim == 0:
        mu = mu.reshape(1) if nc is None else np.full(nc, float(mu))
    if mu.ndim != 1:
        raise InputError(f"`mu` must be a scalar or a 1-D array over contacts, got shape {mu.shape}")
    if np.any(mu < 0.0):
        raise InputError("`mu` must be >= 0 for every contact")
    nc = mu.shape[0]
    e = finite_array("e", e)
    if e.ndim == 0:
        e = np.full(nc, float(e))
    if e.shape != (nc,):
        raise InputError(f"`e` must be a scalar or have one entry per contact ({nc}), got shape {e.shape}")
    if np.any(e < 0.0) or np.any(e > 1.0):
        raise InputError("`e` must lie in [0, 1] for every contact")
    return mu, e


def build_friction_lcp(W, v_free, mu, e, vN_pre=None):
    """Build the velocity-level 2D Coulomb friction LCP.

    Parameters
    ----------
    W : array_like, shape (nc + nf, nc + nf)
        Delassus matrix over the stacked rows ``[N (all contacts); T
        (frictional contacts)]``, symmetric positive semidefinite in practice
        (``W = J M^-1 J^T``).
    v_free : array_like, shape (nc + nf,)
        Free (impulse-less) velocity at the end of the step, same order.
    mu : array_like, shape (nc,)
        Friction coefficients, ``>= 0``; ``mu = 0`` contacts get no
        tangential variables.
    e : float or array_like, shape (nc,)
        Newton restitution coefficients in ``[0, 1]``.
    vN_pre : array_like, shape (nc,), optional
        Normal velocity before the step (the impact law uses its negative
        part). Defaults to the normal part of ``v_free``, which is right when
        no smooth force acts during the step.

    Returns
    -------
    FrictionLCP
        ``(M, q, layout)``; solve ``LCP(M, q)`` and read the impulses with
        :func:`friction_impulses`.

    Raises
    ------
    InputError
        Shapes that do not match the number of contacts, negative ``mu``,
        ``e`` outside ``[0, 1]``, non-finite values.

    Examples
    --------
    A block sliding at speed 1 on the ground, unit mass, ``mu = 0.5``, with
    a normal approach velocity ``-1`` and ``e = 0``:

    >>> import numpy as np
    >>> from moreau.lcp import solve_lcp
    >>> W = np.eye(2)
    >>> M, q, layout = build_friction_lcp(W, np.array([-1.0, 1.0]), [0.5], 0.0)
    >>> pN, pT = friction_impulses(solve_lcp(M, q).z, layout)
    >>> round(float(pN[0]), 12), round(float(pT[0]), 12)
    (1.0, -0.5)
    """
    mu, e = _coefficients(mu, e)
    nc = mu.shape[0]
    layout = FrictionLayout(mu, e)
    nf = layout.n_frictional
    m = nc + nf
    W = finite_array("W", W, shape=(m, m))
    v_free = finite_array("v_free", v_free, shape=(m,))
    if vN_pre is None:
        vN_pre = v_free[:nc]
    else:
        vN_pre = finite_array("vN_pre", vN_pre, shape=(nc,))

    size = layout.size
    # signed selection S: p_stacked = S z, so M's W-part is S^T W S
    S = np.zeros((m, size))
    S[np.arange(nc), layout.normal] = 1.0
    fr = layout.frictional
    S[nc + np.arange(nf), layout.tplus[fr]] = 1.0
    S[nc + np.arange(nf), layout.tminus[fr]] = -1.0
    M = S.T @ W @ S
    q = S.T @ v_free
    q[layout.normal] += e * np.minimum(vN_pre, 0.0)
    if nf:
        bp, tp, tm, nrm = layout.beta[fr], layout.tplus[fr], layout.tminus[fr], layout.normal[fr]
        M[tp, bp] = 1.0
        M[tm, bp] = 1.0
        M[bp, nrm] = mu[fr]
        M[bp, tp] = -1.0
        M[bp, tm] = -1.0
    return FrictionLCP(M, q, layout)


def friction_impulses(z, layout, stacked=False):
    """Read the contact impulses back from a friction-LCP solution.

    Parameters
    ----------
    z : array_like, shape (layout.size,)
        LCP solution.
    layout : FrictionLayout
        From :func:`build_friction_lcp`.
    stacked : bool
        If True, return one vector in ``W``'s row order instead.

    Returns
    -------
    pN, pT : ndarray, shape (nc,)
        Normal and tangential impulse of each contact (``pT = 0`` where
        ``mu = 0``). With ``stacked=True``, a single array ``p`` of shape
        ``(nc + nf,)`` such that ``v = v_free + W @ p``.

    Examples
    --------
    >>> import numpy as np
    >>> layout = FrictionLayout([0.5, 0.0], [0.0, 0.0])
    >>> pN, pT = friction_impulses(np.array([2.0, 0.3, 0.0, 0.0, 1.0]), layout)
    >>> pN.tolist(), pT.tolist()
    ([2.0, 1.0], [0.3, 0.0])
    """
    z = np.asarray(z, dtype=float)
    if z.shape != (layout.size,):
        raise InputError(f"`z` must have shape ({layout.size},) to match `layout`, got {z.shape}")
    pN = z[layout.normal].copy()
    fr = layout.frictional
    pT = np.zeros(layout.n_contacts)
    pT[fr] = z[layout.tplus[fr]] - z[layout.tminus[fr]]
    if stacked:
        return np.concatenate([pN, pT[fr]])
    return pN, pT


def contact_velocities(W, v_free, z, layout):
    """Post-step contact velocities ``(vN, vT)`` for a friction-LCP solution.

    Parameters
    ----------
    W, v_free : array_like
        As given to :func:`build_friction_lcp`.
    z : array_like, shape (layout.size,)
    layout : FrictionLayout

    Returns
    -------
    vN, vT : ndarray, shape (nc,)
        ``vT`` is zero for frictionless contacts (which have no tangential row).

    Examples
    --------
    >>> import numpy as np
    >>> M, q, layout = build_friction_lcp(np.eye(2), [-1.0, 1.0], [0.5], 0.0)
    >>> vN, vT = contact_velocities(np.eye(2), [-1.0, 1.0], [1.0, 0.0, 0.5, 0.5], layout)
    >>> vN.tolist(), vT.tolist()
    ([0.0], [0.5])
    """
    p = friction_impulses(z, layout, stacked=True)
    v = np.asarray(v_free, dtype=float) + np.asarray(W, dtype=float) @ p
    nc = layout.n_contacts
    vT = np.zeros(nc)
    vT[layout.frictional] = v[nc:]
    return v[:nc].copy(), vT
