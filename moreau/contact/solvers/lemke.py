"""``"lemke"``: the dense friction LCP by Lemke's method (:mod:`moreau.lcp.lemke`),
then the enumeration of the pieces where it ends on a ray (``max_iter``: the pivot limit)."""

from ..registry import register_solver
from ._friction_lcp import friction_lcp_solver

__all__ = ["solve"]

solve = register_solver("lemke", friction_lcp_solver("lemke"),
                        summary="dense friction LCP, Lemke's method")
