"""The rocking block released tilted on one corner: first impact, Housner's ratio, settling time."""

import math

import numpy as np

from ..problem import Problem, crossing_time, register_problem

#: a block whose angular velocity stays below this fraction of its first impact's to the end
#: of the window lies flat; the rocking left after it lasts under 1e-5 of the settling time
REST_FRACTION = 1e-6


def _line_at(t, w, i, j, t1):
    """``w`` at ``t1`` on the line through samples ``i`` and ``j`` (the nearer one where they coincide)."""
    if t[j] == t[i]:
        return float(w[j] if abs(t[j] - t1) <= abs(t[i] - t1) else w[i])
    return float(w[i] + (w[j] - w[i]) * (t1 - t[i]) / (t[j] - t[i]))


def impact_ratio(t, w, t1):
    """``w+ / w-`` at the first impact (at ``t1``) of a sampled angular velocity ``w``; None if unread.

    The jump is the largest change of ``w`` between two samples before the
    block turns back on its other corner (``w`` changes sign); ``w-`` and
    ``w+`` are extrapolated linearly to ``t1`` from the two samples on each
    side of it. A time-stepping scheme may cross ``theta = 0`` a step before
    its velocity jumps, and an event-driven run records the impact twice at
    the same time, so neither the crossing nor the sample times locate the jump.

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 2.0, 3.0, 4.0])
    >>> round(impact_ratio(t, np.array([-2.8, -2.9, -3.0, -2.1, -2.0, -1.9]), 2.0), 12)
    0.7
    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(w, dtype=float)
    pre = w[(t < t1) & (w != 0.0)]
    if not pre.size:
        return None
    # the fall's sign is kept through the impact until the block turns back
    back = np.flatnonzero((t > t1) & (w * pre[-1] <= 0.0))
    end = back[0] if back.size else len(t)
    if end < 4:
        return None
    k = int(np.argmax(np.abs(np.diff(w[:end]))))
    if k < 1 or k + 2 >= len(t):
        return None
    before = _line_at(t, w, k - 1, k, t1)
    after = _line_at(t, w, k + 1, k + 2, t1)
    return None if before == 0.0 else after / before


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
    ratio of the angular velocities extrapolated linearly to it from the two
    samples on each side; the settling time at the sample that follows the
    last one turning faster than ``REST_FRACTION`` of the first impact's
    angular velocity. Times are relative to the settling time, the ratio to
    itself; tolerance 1 %.
    """

    name = "rocking-block"
    title = "Rocking block (Housner's impacts, Zeno settling)"
    scene = "rocking-block"
    reference_kind = "closed form"
    source = ("G. W. Housner, The behavior of inverted pendulum structures during earthquakes, "
              "Bull. Seismol. Soc. Am. 53(2) (1963) 403-417: the ratio 1 - (3/2) sin^2(alpha) "
              "of the angular velocities over an impact; phase times by quadrature and the "
              "Zeno sum of the settling time (moreau.scenes.rocking_block)")
    tolerance = 1e-2
    window = 4.0
    steps = (500, 5000, 50000)
    quick_steps = (500, 5000)

    def scene_parameters(self):
        return {"width": 0.2, "height": 0.4, "mu": 10.0, "restitution": 0.0, "tilt": 0.05}

    def start(self, scene):
        return scene.initial_state()

    _ref = None

    def reference(self):
        if self._ref is None:
            blk = self.make_scene()
            self._ref = {"first_impact_time": float(blk.phase_time(blk.params.tilt)),
                         "impact_ratio": float(blk.housner_ratio),
                         "settling_time": float(blk.settling_time())}
        return dict(self._ref)

    def impact_speed(self):
        """``|theta'|`` at the first impact, by energy: ``(2/3) w^2 = cos(alpha - theta0) - cos(alpha)``."""
        blk = self.make_scene()
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
        if t1 is not None:
            out["impact_ratio"] = impact_ratio(t, w, t1)
        moving = np.flatnonzero(np.abs(w) > REST_FRACTION * self.impact_speed())
        if moving.size and moving[-1] + 1 < len(t):
            out["settling_time"] = float(t[moving[-1] + 1])
        return out
