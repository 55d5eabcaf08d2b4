"""The rocking block released tilted on one corner: first impact, Housner's ratio, settling time."""

import math

import numpy as np

from ..problem import Problem, crossing_time, register_problem

#: a block whose angular velocity stays below this fraction of its first impact's to the end
#: of the window lies flat; the rocking left after it lasts under 1e-5 of the settling time
REST_FRACTION = 1e-6


def rebound_amplitude(t, th, t1):
    """Largest ``|theta|`` between the first impact at ``t1`` and the next return to ``theta = 0``.

    None when the block does not come back within the samples.

    Examples
    --------
    >>> rebound_amplitude([0.0, 1.0, 2.0, 3.0, 4.0, 5.0], [0.1, 0.0, -0.03, -0.04, -0.02, 0.01], 1.0)
    0.04
    """
    t = np.asarray(t, dtype=float)
    th = np.asarray(th, dtype=float)
    after = np.flatnonzero(t > t1)
    back = after[th[after] > 0.0]
    if not after.size or not back.size:
        return None
    seg = th[after[0]:back[0]]
    return float(-seg.min()) if seg.size else None


@register_problem
class RockingBlockProblem(Problem):
    """The block of width 0.2 m and height 0.4 m released from rest at 0.05 rad on its left corner.

    Housner (1963): on a corner the block is an inverted pendulum,
    ``I_O theta'' = -sin(alpha - theta)`` (scene units: half-diagonal 1,
    ``I_O = 4/3``, ``alpha = atan(width / height)``); it falls flat at the
    quadrature ``T(theta0)``. At the impact the landing corner sticks and the
    other lifts, the angular momentum about the landing corner is conserved,
    and the angular velocity drops by ``w+ / w- = 1 - (3/2) sin^2(alpha)``
    (0.7 here). The energy falls by that ratio squared at each impact; the
    amplitudes follow from energy and the block lies flat at the Zeno time
    ``T(theta0) + 2 sum_k T(theta_k)``. The scene computes all three
    (:class:`moreau.scenes.rocking_block.RockingBlock`): 0.5706, 0.7 and 3.0907
    (scene units, time ``sqrt(R / g)``).

    From a run: the first impact time where ``theta`` first crosses 0; the
    ratio of the angular velocities over that impact from the amplitude
    ``theta_1`` it leaves on the other corner (energy is conserved on each
    rocking phase, so ``r^2 = (cos(alpha - theta_1) - cos(alpha)) /
    (cos(alpha - theta_0) - cos(alpha))``; a velocity read across the impact
    would depend on how a scheme samples it: a compliant contact spreads the
    jump over many samples, a time-stepping scheme crosses ``theta = 0`` a
    step before its velocity jumps); the settling time at the sample that
    follows the last one turning faster than ``REST_FRACTION`` of the first
    impact's angular velocity. Times are relative to the settling time, the
    ratio to itself; tolerance 1 %.
    """

    name = "rocking-block"
    title = "Rocking block (Housner's impacts, Zeno settling)"
    scene = "rocking-block"
    reference_kind = "closed form (phase times by quadrature, rel. 1e-13)"
    source = ("G. W. Housner, The behavior of inverted pendulum structures during earthquakes, "
              "Bull. Seismol. Soc. Am. 53(2) (1963) 403-417: the ratio 1 - (3/2) sin^2(alpha) "
              "of the angular velocities over an impact; phase times by quadrature and the "
              "Zeno sum of the settling time (moreau.scenes.rocking_block)")
    window = 4.0
    # Moreau-Jean's settling time is first order (measured 2.6 %, 0.77 %, 0.33 % off at
    # 5000, 20000, 50000 steps): its finest quick setting is within the tolerance
    steps = (2000, 20000, 100000)
    # compliant-rk45 takes 10 to 19 s of CPU a quick cell here (an explicit method on the
    # stiff contact over the Zeno settling), for the values compliant-radau gives in 2 s
    quick_declines = {"compliant-rk45": (
        "the compliant contact model of compliant-radau, which the quick suite runs here "
        "(the same values to 2e-8), by an explicit method on its stiff contact: 10 to 19 s "
        "of CPU a cell against 2 s; the full suite runs it")}

    def scene_parameters(self):
        return {"width": 0.2, "height": 0.4, "mu": 10.0, "restitution": 0.0, "tilt": 0.05}

    def start(self, scene):
        return scene.initial_state()

    _ref = None

    def exact_scene(self):
        """The :class:`~moreau.scenes.rocking_block.RockingBlock` whose closed forms are the reference."""
        return self.make_scene()

    def reference(self):
        if self._ref is None:
            blk = self.exact_scene()
            self._ref = {"first_impact_time": float(blk.phase_time(blk.params.tilt)),
                         "impact_ratio": float(blk.housner_ratio),
                         "settling_time": float(blk.settling_time())}
        return dict(self._ref)

    def impact_speed(self):
        """``|theta'|`` at the first impact, by energy: ``(2/3) w^2 = cos(alpha - theta0) - cos(alpha)``."""
        blk = self.exact_scene()
        th0, al = blk.params.tilt, blk.alpha
        return math.sqrt(1.5 * 2.0 * math.sin(al - 0.5 * th0) * math.sin(0.5 * th0))

    def scales(self):
        ref = self.reference()
        return {"first_impact_time": ref["settling_time"], "impact_ratio": ref["impact_ratio"],
                "settling_time": ref["settling_time"]}

    def measure(self, scene, res):
        t, th, w = res.t, res.q[:, 2], res.v[:, 2]
        t1 = crossing_time(t, th, 0.0, direction=-1)
        out = {"first_impact_time": t1, "impact_ratio": None, "settling_time": None}
        th1 = None if t1 is None else rebound_amplitude(t, th, t1)
        if th1 is not None:
            blk = self.exact_scene()
            al, th0 = blk.alpha, float(blk.params.tilt)
            # cos(alpha - x) - cos(alpha) = 2 sin(alpha - x/2) sin(x/2), without cancellation
            out["impact_ratio"] = math.sqrt(
                math.sin(al - 0.5 * th1) * math.sin(0.5 * th1)
                / (math.sin(al - 0.5 * th0) * math.sin(0.5 * th0)))
        moving = np.flatnonzero(np.abs(w) > REST_FRACTION * self.impact_speed())
        if moving.size and moving[-1] + 1 < len(t):
            out["settling_time"] = float(t[moving[-1] + 1])
        return out
