"""The contact problem's solve as it was before the object (main at e09dfb8), kept as the reference.

``solve_contact_problem`` of ``moreau/integrators/contact_problem.py`` then,
without the Painlevé policy (which stayed with the schemes): the object
(:func:`moreau.contact.solve`) must give the same impulses, bit for bit, and
the same statistics. Kept until the package's tests no longer need it.
"""

import numpy as np

from moreau.contact.closed_form import (MAX_PIECES_CONTACTS, friction_pieces,
                                        one_contact_impulse, one_contact_residual)
from moreau.errors import LCPError
from moreau.lcp import MAX_ITER, lcp_residual, solve_lcp
from moreau.lcp.friction import build_friction_lcp, friction_impulses


def old_solve(W, U_free, mu, e, vN_pre, lcp_method="auto", lemke_max_iter=None):
    c = {"lcp_solves": 0, "direct_solves": 0, "pivots": 0, "fallbacks": 0, "max_residual": 0.0}
    mu = np.asarray(mu, dtype=float)
    e = np.asarray(e, dtype=float)
    vN_pre = np.asarray(vN_pre, dtype=float)
    na = mu.size
    c["lcp_solves"] += 1
    if na == 1 and lcp_method == "auto":
        c["direct_solves"] += 1
        if mu[0] > 0.0:
            pn, pt = one_contact_impulse(W, U_free, mu[0], e[0], vN_pre[0])
            res = one_contact_residual(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U_free[0], U_free[1],
                                       mu[0], e[0], vN_pre[0], pn, pt)
            p = np.array([pn, pt])
        else:
            pn, pt = one_contact_impulse(W[:1, :1], U_free[:1], 0.0, e[0], vN_pre[0])
            res = one_contact_residual(W[0, 0], 0.0, 0.0, 0.0, U_free[0], 0.0, 0.0, e[0],
                                       vN_pre[0], pn, 0.0)
            p = np.array([pn])
        c["max_residual"] = max(c["max_residual"], float(res))
        return (p, np.array([pn]), np.array([pt])), c
    Ml, ql, layout = build_friction_lcp(W, U_free, mu, e, vN_pre)
    r = solve_lcp(Ml, ql, method=lcp_method, friction=layout, max_iter=lemke_max_iter)
    if r.method == "lemke":
        c["pivots"] += int(r.pivots)
    if r.fallback_used:
        c["fallbacks"] += 1
    z = r.z if r.success else None
    if z is None and r.status != MAX_ITER and na <= MAX_PIECES_CONTACTS:
        z = friction_pieces(W, U_free, mu, e, vN_pre, Ml, ql, layout)
        if z is not None:
            c["piece_enumerations"] = c.get("piece_enumerations", 0) + 1
    if z is None:
        raise LCPError(f"contact problem not solved: {r.message}")
    pN, pT = friction_impulses(z, layout)
    c["max_residual"] = max(c["max_residual"], float(lcp_residual(Ml, ql, z)))
    return (friction_impulses(z, layout, stacked=True), np.asarray(pN), np.asarray(pT)), c


def random_problem(rng, nc, ndof=None, frictionless=0.3, restitution=True):
    """A well-posed contact problem of ``nc`` contacts: ``W = J M^-1 J^T`` of a random body.

    ``(W, U_free, mu, e, vN_pre)`` in the schemes' row order; ``ndof`` at
    least the number of rows makes ``W`` positive definite.
    """
    mu = np.where(rng.random(nc) < frictionless, 0.0, rng.uniform(0.1, 1.5, nc))
    m = nc + int(np.sum(mu > 0.0))
    ndof = m + 1 if ndof is None else ndof
    R = rng.standard_normal((ndof, ndof))
    Minv = np.linalg.inv(R @ R.T + ndof * np.eye(ndof))
    J = rng.standard_normal((m, ndof))
    W = J @ Minv @ J.T
    U = rng.standard_normal(m)
    e = rng.uniform(0.0, 1.0, nc) if restitution else np.zeros(nc)
    vN = rng.standard_normal(nc)
    return W, U, mu, e, vN
