"""The suite's masonry arch and granular column: their references, quick settings and cells."""

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


def test_granular_column_measures_the_edges_and_declines_the_compliant_contacts():
    from moreau.scenes.granular_column import column_system

    prob = get_problem("granular-column")
    scene = prob.make_scene()
    q0, _ = prob.start(scene)
    # the start lattice of column_system (ten disks, four grains wide): its right edge, top
    # and mean height, read independently of the problem's measure
    _, x0, L0 = column_system(width=0.02, aspect=0.5)
    sys = scene.system
    assert L0 == 4.0 and sys.n_disks == 10
    start = prob.measure(scene, type("Run", (), {"q": q0[None]})())
    assert start == {"front": pytest.approx(float(np.max(x0[:, 0] + sys.radii)), abs=1e-15),
                     "top": pytest.approx(float(np.max(x0[:, 1] + sys.radii)), abs=1e-15),
                     "mean_height": pytest.approx(float(np.mean(x0[:, 1])), abs=1e-15)}
    assert prob.scales() == {"front": 1.0, "top": 1.0, "mean_height": 1.0}
    for scheme in ("compliant-radau", "compliant-rk45"):
        assert settings_of(scheme, prob, scene, quick=True) == [(DECLINED, {})]
        assert [lb for lb, _ in settings_of(scheme, prob, scene)] == \
            ["stiffness=1000", "stiffness=10000", "stiffness=100000"]


@pytest.mark.slow
def test_granular_column_table_against_the_event_driven_reference():
    prob = get_problem("granular-column")
    scene = prob.make_scene()
    start = prob.measure(scene, type("Run", (), {"q": prob.start(scene)[0][None]})())
    ref = prob.reference()
    # the column settles: its centres sink, its top falls, its front moves by less than a
    # tenth of a grain in the window
    assert ref["mean_height"] < start["mean_height"] and ref["top"] < start["top"]
    assert abs(ref["front"] - start["front"]) < 0.1
    rep = run_suite(problems=["granular-column"], schemes=["moreau-jean", "compliant-rk45"],
                    quick=True, progress=False)
    rows = {(r["scheme"], r["setting"]): r for r in rep["rows"]}
    fine, coarse = rows[("moreau-jean", "N=2000")], rows[("moreau-jean", "N=200")]
    assert fine["outcome"] == "ok", fine
    assert all(abs(fine["values"][k] - v) <= prob.tolerance for k, v in ref.items())
    assert coarse["max_error"] > fine["max_error"]
    declined = rows[("compliant-rk45", DECLINED)]
    assert declined["outcome"] == "refused" and "26 s of CPU" in declined["cause"]
