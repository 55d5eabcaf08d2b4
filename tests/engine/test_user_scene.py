"""A user's own scene, not registered, works everywhere a built-in one does."""

import numpy as np
import pytest

import moreau
from moreau.errors import InputError
from moreau.integrators import simulate

from belt_scene import BeltBlock


def test_check_scene_passes_and_notes_the_finite_difference_jacobians():
    report = moreau.check_scene(BeltBlock())
    assert report.ok, report.summary()
    assert any("central differences" in w for w in report.warnings)


def test_check_scene_names_a_wrong_jacobian():
    class Wrong(BeltBlock):
        def contact_jacobians(self, q, t):
            WN, wN, WT, wT = super().contact_jacobians(q, t)
            return 2.0 * WN, wN, WT, wT

    report = moreau.check_scene(Wrong())
    assert not report.ok
    assert any("gap rates (WN, wN)" in p for p in report.problems)


def test_check_scene_names_a_gap_that_jumps():
    # issue 34: a jump of 0.1 at x = 0.05 read "every check passed" (4 states checked,
    # nothing between them); the block rides the belt through x = 0.05 at t = 0.4
    class Jump(BeltBlock):
        def gaps(self, q, t):
            return np.array([q[1] + (0.1 if q[0] > 0.05 else 0.0)])

    report = moreau.check_scene(Jump())
    assert not report.ok
    (problem,) = report.problems
    assert problem.startswith("`gaps(q, t)` of contact 0 is not continuous: it changes by 0.1")
    assert "along the motion" in report.where[problem]
    assert moreau.check_scene(BeltBlock()).ok


def test_check_scene_names_a_wrong_sign_of_the_belts_rheonomic_term():
    from belt_scene import CompiledBeltBlock

    class Flipped(CompiledBeltBlock):
        def contact_jacobians(self, q, t):
            WN, wN, WT, wT = super().contact_jacobians(q, t)
            return WN, wN, WT, -wT

    # with the belt's position stated, the Python model alone is checked
    class Stated(BeltBlock):
        def slip_positions(self, q, t):
            return np.array([q[0] - self.vb * t])

    class StatedFlipped(Stated):
        def contact_jacobians(self, q, t):
            WN, wN, WT, wT = super().contact_jacobians(q, t)
            return WN, wN, WT, -wT

    assert moreau.check_scene(Stated()).ok
    report = moreau.check_scene(StatedFlipped())
    assert {p.split(":")[0] for p in report.problems} == {
        "slip rates (WT, wT)", "rheonomic terms (wT against d/dt of the slip positions)"}
    # without it, the compiled model is the second statement
    report = moreau.check_scene(Flipped())
    (problem,) = report.problems
    assert problem == ("the compiled model's wT (the tangential rows' rheonomic term) differs "
                       "from the Python model's")
    # one line for the 12 states where it appears (4 identical lines before)
    summary = report.summary()
    assert summary.count("problem:") == 1 and "at every one of the 12 states" in summary
    assert moreau.check_scene(CompiledBeltBlock()).ok


def test_check_scene_names_a_wrong_rheonomic_normal_term():
    # wN against the gaps' change in time at fixed positions: a belt whose surface rises
    class Rising(BeltBlock):
        def gaps(self, q, t):
            return np.array([q[1] - 0.1 * t])

        def contact_jacobians(self, q, t):
            WN, wN, WT, wT = super().contact_jacobians(q, t)
            return WN, wN + 0.1, WT, wT      # the sign of dg/dt = -0.1 wrong

    report = moreau.check_scene(Rising(), motion=False)
    assert any(p.startswith("rheonomic terms (wN against d/dt of the gaps)")
               for p in report.problems)


def test_check_scene_names_a_wrong_shape_and_a_mass_that_is_not_positive_definite():
    class Bad(BeltBlock):
        def mass(self, q):
            return np.diag([1.0, -1.0])

        def gaps(self, q, t):
            return np.array([q[1], q[1]])

    report = moreau.check_scene(Bad())
    assert "`mass(q)` is not positive definite" in report.problems
    assert any("`gaps(q, t)` has shape (2,), expected (1,)" in p for p in report.problems)


def test_default_force_jacobians_are_central_differences_not_zero():
    sc = BeltBlock(k=4.0)
    K, C = sc.force_jacobians(np.array([0.3, 0.0]), np.zeros(2), 0.0)
    np.testing.assert_allclose(K, [[-4.0, 0.0], [0.0, 0.0]], atol=1e-9)
    np.testing.assert_allclose(C, 0.0, atol=1e-9)


def test_theta_scheme_without_jacobians_is_not_explicit():
    # theta = 1/2 on the spring: with the finite-difference Jacobians the
    # scheme is the implicit midpoint rule, which keeps the stuck block's
    # spring energy; an explicit treatment would not. Same answer as with
    # the exact Jacobians, to the differences' error.
    class Exact(BeltBlock):
        def force_jacobians(self, q, v, t):
            return np.array([[-self.k, 0.0], [0.0, 0.0]]), np.zeros((2, 2))

    q0, v0 = BeltBlock().initial_state()
    runs = [simulate(cls(), (0.0, 6.0), q0, v0, "moreau-jean", h=0.01, theta=0.5)
            for cls in (BeltBlock, Exact)]
    np.testing.assert_allclose(runs[0].q, runs[1].q, atol=1e-8)


def test_event_driven_and_moreau_jean_agree_on_the_stick_slip_cycle():
    q0, v0 = BeltBlock().initial_state()
    ref = simulate(BeltBlock(), (0.0, 4.0), q0, v0, "event-driven", rtol=1e-10)
    assert ref.success
    # sticks until k x = mu, at x = 0.15, t = 0.3: then slips
    first = ref.events[0]
    assert first.t == pytest.approx(0.3, rel=1e-8)
    errs = []
    for n in (400, 800, 1600):
        mj = simulate(BeltBlock(), (0.0, 4.0), q0, v0, "moreau-jean", h=4.0 / n)
        errs.append(abs(mj.q[-1, 0] - ref.q[-1, 0]))
    assert errs[2] < errs[0] / 3.0 and errs[2] < 5e-3


def test_compare_takes_a_scene_instance_and_reports_like_the_cli():
    q0, v0 = BeltBlock().initial_state()
    rep = moreau.compare(BeltBlock(), t_span=(0.0, 2.0), q0=q0, v0=v0, steps=[100, 200, 400],
                         lcp_steps=[], thetas=[1.0], repeat=1, progress=False)
    assert rep["scene"] == "belt-block" and rep["reference"]["scheme"] == "event-driven"
    rows = [r for r in rep["rows"] if r["scheme"] == "moreau-jean"]
    assert [r["status"] for r in rows] == [0, 0, 0]
    assert rows[-1]["error"] < rows[0]["error"]
    assert 0.7 < rep["orders"][0]["order"] < 1.5
    with pytest.raises(InputError, match="needs `t_span`, `q0` and `v0`"):
        moreau.compare(BeltBlock())


def test_a_setting_the_scheme_does_not_use_is_refused_before_any_work():
    q0, v0 = BeltBlock().initial_state()
    with pytest.raises(InputError, match="`rtol` is not an option of scheme 'moreau-jean'"):
        simulate(BeltBlock(), (0.0, 1.0), q0, v0, "moreau-jean", h=0.01, rtol=1e-3)
    with pytest.raises(InputError, match="`theta` is not an option of scheme 'event-driven'"):
        simulate(BeltBlock(), (0.0, 1.0), q0, v0, "event-driven", theta=0.5)
