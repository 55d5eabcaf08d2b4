"""The suite's masonry arch and granular column: their references, quick settings and cells."""

import math

import numpy as np
import pytest

from moreau.suite.problem import get_problem
from moreau.suite.run import DECLINED, run_suite, settings_of


def test_masonry_arch_stands_by_the_safe_theorem_and_its_quick_settings():
    prob = get_problem("masonry-arch")
    # the thrust-line LP of four voussoirs: 0.10086 (the scene's docstring), below t / R = 0.11
    assert prob.limit() == pytest.approx(0.10086, abs=2e-5)
    assert prob.reference() == {"largest_displacement": 0.0}
    scene = prob.make_scene()
    # the quick suite's Schatzman-Paoli at 100 steps only, the full one at its three
    assert [lb for lb, _ in settings_of("schatzman-paoli", prob, scene, quick=True)] == ["N=100"]
    assert [lb for lb, _ in settings_of("schatzman-paoli", prob, scene)] == \
        ["N=100", "N=1000", "N=10000"]
    assert [lb for lb, _ in settings_of("event-driven", prob, scene)] == \
        ["rtol=0.0001", "rtol=1e-07", "rtol=1e-10"]
    rep = run_suite(problems=["masonry-arch"], schemes=["moreau-jean", "event-driven"],
                    quick=True, progress=False)
    rows = {(r["scheme"], r["setting"]): r for r in rep["rows"]}
    assert sorted(rows) == [("event-driven", DECLINED), ("moreau-jean", "N=100"),
                            ("moreau-jean", "N=1000")]
    for n in (100, 1000):
        r = rows[("moreau-jean", f"N={n}")]
        # standing: no voussoir moved by the stand criterion's 1e-6 R
        assert r["outcome"] == "ok" and r["values"]["largest_displacement"] <= 1e-6, r
    ed = rows[("event-driven", DECLINED)]
    assert ed["outcome"] == "refused" and ed["steps"] is None
    assert ed["cause"].startswith("the problem declines event-driven: every one of the arch's "
                                  "10 frictional contacts")
