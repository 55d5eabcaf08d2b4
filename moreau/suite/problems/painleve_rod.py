"""The Painlevé rod sliding on its tip, on the well-posed side of the Painlevé condition."""

from ...scenes.painleve_rod import PainleveRodCase
from ..problem import Problem, register_problem


@register_problem
class PainleveRodProblem(Problem):
    """The rod (``mu = 0.5``) started sliding at ``phi = 0.9``, tip speed -1, ``dphi = 0.4``.

    Its tip stays on the ground and keeps sliding over the window (0.5), so the
    reference is the sliding ODE (normal force from the contact's acceleration
    constraint, Coulomb friction against the slip) integrated by DOP853 at
    ``rtol = 1e-13``. A scheme that stops on the Painlevé condition, or takes a
    tangential impact instead, is reported under its named cause.
    """

    name = "painleve-rod"
    title = "Painlevé rod (sliding, well-posed side)"
    scene = "painleve-rod"
    reference_kind = "high-precision reference (sliding ODE, DOP853, rtol 1e-13)"
    source = ("P. Painlevé, Sur les lois du frottement de glissement, C. R. Acad. Sci. 121 "
              "(1895) 112-115; the well-posedness condition as in F. Génot, B. Brogliato, New "
              "results on Painlevé paradoxes, Eur. J. Mech. A 18 (1999) 653-677")
    case_class = PainleveRodCase

    def scene_parameters(self):
        return {"mu": 0.5}

    _ref = None

    def reference(self):
        if self._ref is None:
            sol = self._the_case()._ode(self._the_case().tight_rtol)
            self._ref = {"x_centre_end": float(sol.y[0, -1]), "phi_end": float(sol.y[2, -1])}
        return dict(self._ref)

    def scales(self):
        # relative to the motion over the window
        q0, _ = self._the_case().start()
        ref = self.reference()
        return {"x_centre_end": float(abs(ref["x_centre_end"] - q0[0])),
                "phi_end": float(abs(ref["phi_end"] - q0[2]))}

    def measure(self, scene, res):
        return {"x_centre_end": float(res.q[-1, 0]), "phi_end": float(res.q[-1, 2])}
