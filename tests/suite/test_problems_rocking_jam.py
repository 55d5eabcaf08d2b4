"""The suite's rocking-block and painleve-jam problems: references against independent computations."""

import math

import numpy as np
import pytest
from PIL import Image
from scipy.integrate import solve_ivp

from moreau.cli import main
from moreau.lcp import build_friction_lcp, friction_impulses, lcp_violation, solve_lcp
from moreau.suite.problem import PENDING, get_problem, problem_names
from moreau.suite.report import animate_problem
from moreau.suite.run import run_suite


def _fall(al, th0, w0, rtol=1e-12):
    """Time and angular velocity at which the pendulum about the left corner reaches theta = 0.

    ``(4/3) theta'' = -sin(alpha - theta)`` integrated directly, from ``(th0, w0)``.
    """
    def rhs(_, y):
        return [y[1], -0.75 * math.sin(al - y[0])]

    def flat(_, y):
        return y[0]

    flat.terminal, flat.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 50.0), [th0, w0], method="DOP853", rtol=rtol, atol=1e-20,
                    events=flat)
    return float(sol.t_events[0][0]), float(sol.y_events[0][0][1])


def test_rocking_block_references_against_the_ode_and_the_impact_lcp():
    prob = get_problem("rocking-block")
    ref = prob.reference()
    blk = prob.make_scene()
    al, th0, r = blk.alpha, blk.params.tilt, 1.0 - 1.5 * math.sin(blk.alpha) ** 2
    # the first impact: the quadrature against the pendulum integrated directly
    t1, w1 = _fall(al, th0, 0.0)
    assert ref["first_impact_time"] == pytest.approx(t1, rel=1e-10)
    assert abs(w1) == pytest.approx(prob.impact_speed(), rel=1e-10)
    # Housner's ratio against the impulse LCP on both corners (the scene's Jacobians, e = 0,
    # mu = 10) at the landing: the velocity after it turns about the right corner at r w
    q, v = blk.state_on_corner(0.0, w1)
    WN, _, WT, _ = blk.contact_jacobians(q, 0.0)
    J = np.vstack([WN, WT])
    Minv = np.linalg.inv(blk.mass(q))
    W = J @ Minv @ J.T
    M, qv, layout = build_friction_lcp(W, J @ v, blk.mu, 0.0)
    sol = solve_lcp(M, qv, method="lemke")
    assert lcp_violation(M, qv, sol.z) <= 1e-12
    p = friction_impulses(sol.z, layout, stacked=True)
    v_after = v + Minv @ J.T @ p
    assert v_after[2] / v[2] == pytest.approx(ref["impact_ratio"], rel=1e-10)
    assert ref["impact_ratio"] == pytest.approx(r, rel=1e-15)
    # (the whole velocity is the rotation about the right corner: it sticks, the left lifts)
    assert np.allclose(v_after, blk.state_on_corner(-1e-300, v_after[2])[1], atol=1e-12)
    # the settling time: the phases integrated one by one (by symmetry each later phase is
    # the fall from theta = 0 up and back: the pendulum from (0, -r w) to its return), the
    # impacts Housner's; after 30 impacts the phases are small and their times fall like r^k
    total, w = t1, w1
    for _ in range(30):
        t_up, w = _fall(al, 0.0, -r * w)
        total += t_up
    tail = t_up * r / (1 - r)
    assert tail < 1e-4 * total
    assert ref["settling_time"] == pytest.approx(total + tail, abs=1e-9)   # measured 1.1e-12


def test_painleve_jam_reference_against_the_impulse_lcp_and_energy():
    prob = get_problem("painleve-jam")
    rod = prob.make_scene()
    q0, v0 = prob.start(rod)
    assert rod.painleve_indicator(q0, v0) == pytest.approx(-0.8, rel=1e-12)
    # the impulse problem at the start: W from the scene's Jacobians, the tip's velocity,
    # e = 0, solved by Lemke; its solution is the problem's closed-form jam
    WN, _, WT, _ = rod.contact_jacobians(q0, 0.0)
    J = np.vstack([WN, WT])
    Minv = np.linalg.inv(rod.mass(q0))
    M, qv, layout = build_friction_lcp(J @ Minv @ J.T, J @ v0, rod.mu, 0.0)
    sol = solve_lcp(M, qv, method="lemke")
    assert lcp_violation(M, qv, sol.z) <= 1e-12
    pN, pT = friction_impulses(sol.z, layout)
    (PN, PT), v_jam = prob.jam()
    assert (pN[0], pT[0]) == (pytest.approx(PN, abs=1e-12), pytest.approx(PT, abs=1e-12))
    assert np.allclose(v0 + Minv @ J.T @ np.array([pN[0], pT[0]]), v_jam, atol=1e-12)
    assert np.allclose(J @ v_jam, 0.0, atol=1e-14)                 # the tip stuck
    # the stick over the window: the pendulum about the tip keeps (2/3) phi'^2 + sin(phi)
    ref = prob.reference()
    w = ref["dphi_end"]
    phi = math.atan2(-ref["vx_end"], ref["vy_end"])
    assert 2 / 3 * w ** 2 + math.sin(phi) == pytest.approx(
        2 / 3 * v_jam[2] ** 2 + math.sin(q0[2]), rel=1e-12)
    assert phi > q0[2] and 0.0 < w < v_jam[2]                       # still rising, slower


def _rows(problems, schemes):
    rep = run_suite(problems=problems, schemes=schemes, quick=True, progress=False)
    return {(r["problem"], r["scheme"], r["setting"]): r for r in rep["rows"]}


def test_subset_table_on_the_new_problems():
    assert {"rocking-block", "painleve-jam"} <= set(problem_names()) and not PENDING
    # (the event-driven cells of the rocking block take seconds: the slow test below)
    rows = _rows(["rocking-block"], ["moreau-jean"])
    rows.update(_rows(["painleve-jam"], ["moreau-jean", "event-driven"]))
    for prob, finest in (("rocking-block", "N=20000"), ("painleve-jam", "N=1000")):
        r = rows[(prob, "moreau-jean", finest)]
        assert r["outcome"] == "ok", r
        p = get_problem(prob)
        ref, sc = p.reference(), p.scales()
        assert all(abs(r["values"][k] - ref[k]) / sc[k] <= p.tolerance for k in ref)
    # the event-driven scheme cannot slide the rod on from the paradoxical start: it names why
    ed = [r for k, r in rows.items() if k[:2] == ("painleve-jam", "event-driven")]
    assert len(ed) == 2
    for r in ed:
        assert r["outcome"] == "failed" and "Painlevé configuration at t = 0" in r["cause"]


@pytest.mark.slow
def test_event_driven_rocks_to_the_zeno_time():
    # measured: every quantity within 1.2e-6 of Housner's closed forms at both tolerances
    rows = _rows(["rocking-block"], ["event-driven", "event-driven-generic"])
    assert len(rows) == 4
    for r in rows.values():
        assert r["outcome"] == "ok" and r["max_error"] <= 1e-5, r


def test_cli_takes_names_separated_by_spaces(tmp_path, capsys):
    assert main(["suite", "--problems", "painleve-jam", "no-such,rocking-block", "--out",
                 str(tmp_path / "o")]) == 2
    assert "`problems` must name problems of the suite" in capsys.readouterr().err
    assert main(["suite", "--problems", "painleve-jam", "painleve-jam", "--out",
                 str(tmp_path / "o")]) == 2
    assert "`--problems` names one twice" in capsys.readouterr().err


def test_the_jams_page_animation_is_moreau_jeans_run(tmp_path):
    # the event-driven run stops at t = 0 on the jam: the page draws Moreau-Jean's run instead
    path, cause = animate_problem("painleve-jam", str(tmp_path / "jam.gif"), frames=3)
    assert cause is None
    with Image.open(path) as im:
        assert im.n_frames == 3
