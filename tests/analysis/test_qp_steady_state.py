"""A forced-QP Moreau–Jean steady state: the QP map's own fixed point, its derivatives by Lemke."""

import numpy as np
import pytest

from moreau.analysis.mj_steady_state import PeriodMap, moreau_jean_steady_state
from moreau.scenes.friction_drive import FrictionDrive


@pytest.mark.parametrize("frequency", [185.0, 2000.0])
def test_forced_qp_is_a_fixed_point_of_the_qp_map(frequency):
    # 50 steps a period (was 100: the QP path is Python, 8.9 against 4.1 CPU s for both
    # frequencies); the same mode NP, the two solvers' orbits equal to 5e-15 either way
    scene = FrictionDrive(frequency=frequency)
    qp = moreau_jean_steady_state(scene, 50, lcp_method="qp")
    lemke = moreau_jean_steady_state(scene, 50)
    # Newton's matrix came from the Lemke twin ...
    assert qp.stats["derivative_period_maps"] > 0 and lemke.stats["derivative_period_maps"] == 0
    # ... and the state is a fixed point of the QP map itself, checked by an independent run
    pm = PeriodMap(scene, 50, lcp_method="qp")
    y, disp, _ = pm(qp.state0, qp.stats["closed_at_section"])
    scale = np.concatenate([np.ones(len(pm.kept)), np.full(scene.ndof, scene.velocity_scale)])
    assert np.max(np.abs(y - qp.state0) / scale) <= 1e-10
    assert disp == pytest.approx(qp.displacement_per_period, rel=1e-12)
    # the two solvers answer the same contact problems: the same orbit and multipliers
    assert qp.mode == lemke.mode
    assert qp.displacement_per_period == pytest.approx(lemke.displacement_per_period, rel=1e-6)
    assert np.allclose(qp.floquet_multipliers, lemke.floquet_multipliers, atol=1e-6)
