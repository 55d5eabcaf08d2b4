"""``"qp"``: the friction LCP by the QP method of :mod:`moreau.lcp.qp` (a Tresca
fixed point on OSQP; ``max_iter`` its iterations), the fallback of ``"auto"``.

Examples
--------
>>> import numpy as np
>>> from moreau.contact import ContactProblem, solve
>>> sol = solve(ContactProblem(np.eye(2), [-1.0, 1.0], [0.5]), "qp")
>>> sol.status, sol.method, np.round(sol.p, 6).tolist()
('solved', 'qp', [1.0, -0.5])
"""

from ..registry import register_solver
from ._friction_lcp import friction_lcp_solver

__all__ = ["solve"]

solve = register_solver("qp", friction_lcp_solver("qp"),
                        summary="dense friction LCP, QP (Tresca fixed point, OSQP)")
