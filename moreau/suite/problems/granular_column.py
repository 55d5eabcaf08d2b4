"""A tiny granular column released: its first settling, against the event-driven reference."""

import numpy as np

from ...integrators.base import simulate
from ..problem import Problem, register_problem

#: the event-driven reference's tolerance
REFERENCE_RTOL = 1e-10

_COMPLIANT_REASON = ("the compliant contacts take 26 s of CPU a cell at their softest "
                     "stiffness (1e3, Radau on the 24 stiff contacts of the ten disks), more "
                     "than the quick suite's budget for a problem; the full suite runs them")


@register_problem
class GranularColumnProblem(Problem):
    """The column of :mod:`moreau.scenes.granular_column` four grains wide at aspect ratio 0.5.

    Ten disks (radii 0.4 to 0.5 grain diameters ``d``, seed 0) on their
    loose start lattice against the left wall, released without the gate,
    over two units of ``sqrt(d / g)``: the disks fall onto the floor and on
    one another (ten plastic frictional impacts, ``e = 0``, ``mu = 0.5``) and
    the column starts to lean out. Measured at the end of the window: the
    front (rightmost edge of any disk), the top (highest edge) and the mean
    height of the centres, each against the event-driven reference on the
    same model (rtol 1e-10), relative to ``d``, tolerance 1 %.

    Why not the runout against the aspect ratio: the event-driven reference
    stops at ``t = 3.88`` (no solution of an impact's LCP, Lemke's secondary
    ray) as the column spreads (the registered scene itself follows the
    collapse: every pair of disks is a candidate contact); and the model's
    runout departs from the published laws (Lube et al. 2004, Balmforth and
    Kerswell 2005, Staron and Hinch 2005; the scene's docstring), so that no
    published runout can judge a scheme on it. :func:`~moreau.scenes.granular_column.runout_study`
    measures the runout with the broad phase.
    """

    name = "granular-column"
    title = "Granular column (10 disks, aspect 0.5): the first settling after release"
    scene = "granular-column"
    reference_kind = "event-driven reference"
    source = ("the model's event-driven run (rtol 1e-10: 10 plastic impacts in the window); "
              "the column of moreau.scenes.granular_column (Lube et al. 2004, Staron and Hinch "
              "2005 for the collapse it starts)")
    window = 2.0
    steps = (200, 2000, 20000)
    quick_declines = {"compliant-radau": _COMPLIANT_REASON, "compliant-rk45": _COMPLIANT_REASON}
    # Studer's extrapolation at tol 1e-10 takes 10 s of CPU here; 1e-4 is already 2e-5 off
    quick_settings = {"studer-extrapolation": (1e-4,)}
    _reference = None

    def scene_parameters(self):
        return {"width": 0.02, "aspect": 0.5}

    def reference(self):
        if GranularColumnProblem._reference is None:
            scene = self.make_scene()
            q0, v0 = self.start(scene)
            res = simulate(scene, (0.0, self.window), q0, v0, "event-driven", rtol=REFERENCE_RTOL)
            if not res.success:
                raise AssertionError(f"the event-driven reference stopped: {res.message}")
            GranularColumnProblem._reference = self.measure(scene, res)
        return dict(GranularColumnProblem._reference)

    def scales(self):
        # lengths in grain diameters, the scene's unit
        return {"front": 1.0, "top": 1.0, "mean_height": 1.0}

    def measure(self, scene, res):
        x = np.asarray(res.q[-1]).reshape(-1, 3)
        r = scene.system.radii
        return {"front": float(np.max(x[:, 0] + r)), "top": float(np.max(x[:, 1] + r)),
                "mean_height": float(np.mean(x[:, 1]))}
