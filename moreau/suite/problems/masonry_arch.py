"""The semicircular masonry arch of four voussoirs, 9 % above its thrust-line limit: it stands."""

import numpy as np

from ...scenes.masonry_arch import STAND_BOUND, STAND_WINDOW, limit_thickness
from ..problem import Problem, register_problem

#: why the quick suite leaves the event-driven references out (measured on this problem)
_ED_REASON = ("every one of the arch's 10 frictional contacts is closed and sticking at once: "
              "their 20 rows on the 12 coordinates are redundant, and the event-driven "
              "reference decides the start's contact mode by enumerating the modes (275 000 "
              "candidates checked, 33 s of CPU a run; the arch then rests in one phase, error "
              "0); the full suite runs it")


@register_problem
class MasonryArchProblem(Problem):
    """The arch of :mod:`moreau.scenes.masonry_arch` with four voussoirs at ``t / R = 0.11``.

    Its thrust-line limit (the safe theorem, an LP: :func:`limit_thickness`)
    is 0.10086 for four voussoirs (0.10746 for ten, Milankovitch's 0.1075 for
    the continuous arch), so the arch stands: every voussoir stays where it
    is. Measured: the largest centroid displacement over the window (one
    unit of ``sqrt(R / g)``), against 0, relative to ``1e-4 R``, tolerance
    1 %: a run is accurate when nothing moves by more than the stand
    criterion's ``1e-6 R``. Every joint is a closed frictional contact at
    once, a degenerate contact problem at each step.

    The quick suite runs Schatzman–Paoli at its coarsest step count only
    (1.6 s of CPU at 100 steps, ten times that at 1000) and leaves out the
    event-driven references (``quick_declines``, the reason with them).
    """

    name = "masonry-arch"
    title = "Masonry arch (4 voussoirs, t/R = 0.11 above the limit 0.10086): stands"
    scene = "masonry-arch"
    source = ("the safe theorem of limit analysis (Heyman 1966), the thrust-line LP of "
              "moreau.scenes.masonry_arch; Milankovitch 1907 for the continuous arch (0.1075)")
    window = STAND_WINDOW
    quick_settings = {"schatzman-paoli": (100,)}
    quick_declines = {"event-driven": _ED_REASON, "event-driven-generic": _ED_REASON}

    def scene_parameters(self):
        return {"voussoirs": 4, "thickness": 0.11}

    _limit = None

    def limit(self):
        """The thrust-line limit ``t / R`` of the four voussoirs (the LP, to 1e-5)."""
        if MasonryArchProblem._limit is None:
            MasonryArchProblem._limit = float(limit_thickness(4, tol=1e-5))
        return MasonryArchProblem._limit

    def reference(self):
        # the safe theorem: above the limit a thrust line fits, rest is an equilibrium
        if not self.limit() < self.scene_parameters()["thickness"]:
            raise AssertionError("the problem's thickness must lie above the limit")
        return {"largest_displacement": 0.0}

    def scales(self):
        return {"largest_displacement": 100.0 * STAND_BOUND}

    def measure(self, scene, res):
        q0 = res.q[0]
        dq = (res.q - q0).reshape(len(res.t), -1, 3)[:, :, :2]
        return {"largest_displacement": float(np.max(np.hypot(dq[..., 0], dq[..., 1])))}
