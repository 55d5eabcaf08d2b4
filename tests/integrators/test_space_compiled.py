"""Moreau–Jean's compiled spatial loop against the Python step it replaces by default."""

import numpy as np
import pytest

import moreau.integrators.moreau_jean as mj_module
from moreau.contact import cone3d
from moreau.contact.cone3d import exact_gauss_seidel, exact_newton_polish, solve_exact
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.integrators.moreau_jean import MoreauJean
from moreau.model.scene import is_spatial
from moreau.model.space import Puck, SpaceModel, Sphere
from moreau.regimes import Regime
from moreau.scenes import registry

_SPATIAL = {s: sc for s in registry.scene_names()
            if is_spatial(sc := registry.make_scene(s))}
#: the spatial scenes whose every contact the compiled loop knows (spheres and material points)
COMPILED = [s for s, sc in _SPATIAL.items() if sc.contact_table() is not None]
#: scenes whose contact forces are statically indeterminate (a box's four corners on a
#: plane): two solvers' rounding picks different admissible splits, so the loop is held to the
#: Python step on their motion and determinate resultants instead (test below)
INDETERMINATE = {"box-incline"}
FIELDS = ("t", "q", "v", "force_N", "force_T", "slip_velocity", "gap")


def _assert_same(a, b, fields=FIELDS, rtol=1e-12):
    # relative to each history's own size; the gaps, zero to rounding while a contact is
    # closed, to the scene's length unit (the size of its bodies)
    for f in fields:
        x, y = getattr(a, f), getattr(b, f)
        assert x.shape == y.shape, f
        scale = float(np.max(np.abs(x), initial=0.0))
        if f == "gap":
            scale = max(scale, 1.0)
        assert np.max(np.abs(x - y), initial=0.0) <= rtol * max(scale, 1e-300), f


def _python_steps(monkeypatch):
    # counts the steps the Python step takes (a compiled run hands it the steps it leaves)
    calls = [0]
    step = mj_module.space_step

    def counting(*args, **kwargs):
        calls[0] += 1
        return step(*args, **kwargs)
    monkeypatch.setattr(mj_module, "space_step", counting)
    return calls


@pytest.mark.parametrize("options", [{"cone": "exact"}, {"cone": 8, "theta": 0.5}],
                         ids=["exact", "d8-theta-half"])
@pytest.mark.parametrize("name", [s for s in COMPILED if s not in INDETERMINATE])
def test_the_compiled_loop_is_the_python_step_on_every_spatial_scene(name, options, monkeypatch):
    sc = registry.make_scene(name)
    if sc.drilling and options["cone"] != "exact":
        # a contact patch takes the exact cone only (the tippe top's default): the polyhedral
        # cone runs on the same scene with point contacts
        sc = registry.make_scene(name, contact_radius=0.0)
    q0, v0 = sc.initial_state()
    h = (sc.period or sc.default_span()) / 1000
    ref = simulate(sc, (0.0, 60 * h), q0, v0, "moreau-jean", h=h, fast=False, **options)
    calls = _python_steps(monkeypatch)
    mj = MoreauJean(sc, 0.0, q0, v0, 60 * h, h=h, **options)
    assert mj._fast
    while mj.status == "running":
        mj.step()
    res = mj.result()
    # one contact: every step in the loop, none handed back
    assert calls[0] == 0 and res.status == 0
    _assert_same(ref, res)
    assert np.array_equal(ref.regime, res.regime)
    assert res.stats["lcp_solves"] == ref.stats["lcp_solves"] > 0
    assert res.stats["max_residual"] == pytest.approx(ref.stats["max_residual"], rel=1e-9,
                                                      abs=1e-15)


def _puck_and_ball(mu_puck, mu_ball=0.3, spin=20.0):
    # two bodies, five contacts: a three-point puck spinning across the floor and a ball
    # rolling into a tilted wall (length unit 5 cm, time unit 71 ms)
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    wall = m.add_half_space((0.2, 0.0, 0.0), (-1.0, 0.0, 0.2))
    J = 0.2 * 0.05 ** 2
    p = m.add_body(0.2, [0.25 * J, 0.25 * J, 0.5 * J], position=(0.0, 0.0, 0.005),
                   velocity=(0.8, 0.3, 0.0) if spin else (0.0, 0.0, 0.0),
                   angular_velocity=(0.0, 0.0, spin))
    m.add_contact(p, Puck(0.05, 0.01, rim_points=3), floor, mu=mu_puck)
    b = m.add_body(0.1, [0.4 * 0.1 * 0.03 ** 2] * 3, position=(0.1, 0.1, 0.03),
                   velocity=(1.0, -0.2, 0.0), angular_velocity=(5.0, 0.0, 0.0))
    m.add_contact(b, Sphere(0.03), floor, mu=mu_ball)
    m.add_contact(b, Sphere(0.03), wall, mu=mu_ball, restitution=0.5)
    return m.build("puck-and-ball")


def _two_balls():
    # two bodies, three contacts: a ball rolling into a tilted wall, another sliding with spin
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.03)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    wall = m.add_half_space((0.1, 0.0, 0.0), (-1.0, 0.0, 0.2))
    J = 0.4 * 0.1 * 0.03 ** 2
    a = m.add_body(0.1, [J] * 3, position=(0.0, 0.0, 0.03), velocity=(1.0, -0.2, 0.0),
                   angular_velocity=(5.0, 0.0, 0.0))
    m.add_contact(a, Sphere(0.03), floor, mu=0.3)
    m.add_contact(a, Sphere(0.03), wall, mu=0.3, restitution=0.5)
    b = m.add_body(0.1, [J] * 3, position=(0.0, 0.2, 0.03), velocity=(-0.5, 0.3, 0.0),
                   angular_velocity=(0.0, 20.0, -10.0))
    m.add_contact(b, Sphere(0.03), floor, mu=0.2)
    return m.build("two-balls")


def test_several_contacts_and_bodies_in_the_loop_with_the_polyhedral_cone(monkeypatch):
    sc = _two_balls()
    q0, v0 = sc.initial_state()
    ref = simulate(sc, (0.0, 4.0), q0, v0, "moreau-jean", h=0.02, fast=False, cone=8)
    calls = _python_steps(monkeypatch)
    res = simulate(sc, (0.0, 4.0), q0, v0, "moreau-jean", h=0.02, cone=8)
    assert calls[0] == 0
    # the first ball hits the wall and bounces back while both slide on the floor
    assert np.max(ref.force_N[:, 1]) > 0.0 and np.min(ref.v[:, 0]) < 0.0
    assert {Regime.POSITIVE, Regime.STICK} <= set(ref.regime[:, 0]) | set(ref.regime[:, 2])
    _assert_same(ref, res)
    assert np.array_equal(ref.regime, res.regime)


def test_a_statically_indeterminate_stick_keeps_the_motion():
    # mu = 1.5, the puck at rest on its three points: their tangential impulses are not
    # determined by the rigid body, and Lemke's two paths may split them otherwise
    sc = _puck_and_ball(1.5, spin=0.0)
    q0, v0 = sc.initial_state()
    ref = simulate(sc, (0.0, 0.2), q0, v0, "moreau-jean", h=0.02, fast=False, cone=8)
    res = simulate(sc, (0.0, 0.2), q0, v0, "moreau-jean", h=0.02, cone=8)
    assert np.all(ref.regime[-1, :3] == Regime.STICK)
    _assert_same(ref, res, fields=("t", "q", "v", "force_N", "slip_velocity", "gap"))
    assert np.array_equal(ref.regime, res.regime)


def test_the_exact_cone_s_newton_polish_runs_in_the_loop(monkeypatch):
    # three contacts on one body: Gauss–Seidel alone stalls above the tolerance and Newton's
    # polish, compiled, ends the step as the Python step's solver does
    sc = _puck_and_ball(0.3)
    q0, v0 = sc.initial_state()
    polished = []
    solve = cone3d.solve_exact

    def counting(*args, **kwargs):
        sol = solve(*args, **kwargs)
        polished.append(sol.iterations["newton"])
        return sol
    monkeypatch.setattr(cone3d, "solve_exact", counting)
    ref = simulate(sc, (0.0, 0.2), q0, v0, "moreau-jean", h=0.01, fast=False, cone="exact")
    assert sum(n > 0 for n in polished) >= 10
    calls = _python_steps(monkeypatch)
    res = simulate(sc, (0.0, 0.2), q0, v0, "moreau-jean", h=0.01, cone="exact")
    assert calls[0] == 0
    _assert_same(ref, res)
    assert np.array_equal(ref.regime, res.regime)
    assert res.stats["max_residual"] <= 1e-10


def test_exact_newton_polish_is_solve_exact_s_newton():
    # from Gauss–Seidel's point the compiled polish takes solve_exact's Newton steps and
    # ends at its answer; where solve_exact restarts, the polish says it did not converge
    rng = np.random.default_rng(11)
    polished = 0
    for _ in range(40):
        nc = int(rng.integers(2, 5))
        A = rng.normal(size=(3 * nc, 3 * nc))
        W = A @ A.T + 0.1 * np.eye(3 * nc)
        W = 0.5 * (W + W.T)
        q = rng.normal(size=3 * nc)
        mu = rng.uniform(0.0, 1.5, nc)
        r, u = np.zeros(3 * nc), q.copy()
        ok, _, _ = exact_gauss_seidel(W, q, mu, r, u, 1e-10, 1e-6, 500)
        if ok:
            continue
        ref = solve_exact(W, q, mu)
        ok, res, qn, steps = exact_newton_polish(W, q, mu, r, u, 1e-10, 15)
        assert ok == ("restarted" not in ref.detail)
        if ok:
            polished += 1
            assert steps == ref.iterations["newton"]
            # both at the rounding of the data, or both the same residual above it
            assert res <= 1e-10 * qn and abs(res - ref.residual) <= 1e-3 * res + 1e-13 * qn
            assert np.max(np.abs(r - ref.r)) <= 1e-12 * np.max(np.abs(ref.r))
            assert np.max(np.abs(u - (W @ r + q))) <= 1e-13 * qn
    assert polished >= 10


def test_exact_gauss_seidel_is_solve_exact_where_it_converges():
    rng = np.random.default_rng(7)
    converged = missed = 0
    for _ in range(60):
        nc = int(rng.integers(1, 4))
        A = rng.normal(size=(3 * nc, 3 * nc))
        W = A @ A.T + 0.1 * np.eye(3 * nc)
        W = 0.5 * (W + W.T)
        q = rng.normal(size=3 * nc)
        mu = rng.uniform(0.0, 1.0, nc)
        r, u = np.zeros(3 * nc), q.copy()
        ok, res, qn = exact_gauss_seidel(W, q, mu, r, u, 1e-10, 1e-6, 500)
        ref = solve_exact(W, q, mu)
        assert qn == pytest.approx(np.linalg.norm(q), rel=1e-15)
        if ok:
            converged += 1
            assert res <= 1e-10 * qn
            assert np.array_equal(r, ref.r)
        else:
            # where solve_exact needs its Newton polish the kernel says so
            missed += 1
            assert ref.iterations["newton"] > 0 and res > 1e-10 * qn
    assert converged >= 20 and missed >= 5


def test_integer_times_run_the_same_compiled_loop():
    # the loop has one compiled signature: an integer span is cast, not refused
    sc = registry.make_scene("billiard-backspin")
    q0, v0 = sc.initial_state()
    a = simulate(sc, (0, 2), q0, v0, "moreau-jean", h=0.25)
    b = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean", h=0.25)
    assert a.status == b.status == 0 and np.array_equal(a.q, b.q) and len(a.t) == 9


def test_a_contact_the_loop_does_not_know_takes_the_python_step():
    # a contact of another kind than a sphere or a material point has no compiled row
    assert {"sphere-incline", "billiard-backspin", "puck-incline", "tippe-top",
            "box-incline"} <= set(COMPILED)
    sc = _two_balls()
    sc._contacts[2] = dict(sc._contacts[2], kind="rim")
    q0, v0 = sc.initial_state()
    assert sc.contact_table() is None
    assert not MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1)._fast
    with pytest.raises(InputError, match="`fast=True`: the compiled spatial step knows"):
        MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, fast=True)


def test_fast_false_keeps_the_python_step_and_fast_true_is_accepted():
    sc = registry.make_scene("sphere-incline")
    q0, v0 = sc.initial_state()
    assert not MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, fast=False)._fast
    assert MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, fast=True)._fast
    with pytest.raises(InputError, match="`fast=True` solves contacts"):
        MoreauJean(sc, 0.0, q0, v0, 1.0, h=0.1, fast=True, lcp_method="qp")


def test_a_box_s_four_corners_run_in_the_loop_with_the_exact_cone(monkeypatch):
    # four corners on a plane: the normal forces are statically indeterminate (their split
    # between diagonal corners is free), so the two steps agree on the motion and on the
    # determinate resultants, to the cone solver's tolerance (1e-10 of the step's velocity)
    sc = registry.make_scene("box-incline")
    q0, v0 = sc.initial_state()
    ref = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.04, fast=False, cone="exact")
    calls = _python_steps(monkeypatch)
    res = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.04, cone="exact")
    assert calls[0] == 0 and res.stats["max_residual"] <= 1e-10
    _assert_same(ref, res, fields=("t", "q", "v", "gap"), rtol=1e-9)
    for pair in ([1, 3], [0, 2]):
        assert np.max(np.abs(ref.force_N[:, pair].sum(axis=1)
                             - res.force_N[:, pair].sum(axis=1))) <= 1e-9
    # at rest every corner sticks and Newton's Jacobian is singular (W has a null space):
    # the least-norm steps end every step in the loop, where solve_exact restarts
    rest = registry.make_scene("box-incline", mu=0.5, speed=0.0)
    q0, v0 = rest.initial_state()
    res = simulate(rest, (0.0, 1.0), q0, v0, "moreau-jean", h=0.04, cone="exact")
    assert calls[0] == 0 and res.stats["max_residual"] <= 1e-10
    assert np.max(np.abs(res.v)) <= 1e-10


def test_a_contact_patch_runs_in_the_loop_as_the_python_step(monkeypatch):
    # Leine and Glocker's top with its patch: Coulomb–Contensou's four rows (drilling) in the
    # compiled loop, every step there, the Python step's run to rounding (300 steps of the
    # turning, the patch spinning and sliding)
    from moreau.scenes.tippe_top import LEINE_GLOCKER_PATCH
    sc = registry.make_scene("tippe-top", contact_radius=LEINE_GLOCKER_PATCH)
    assert sc.drilling
    q0, v0 = sc.initial_state()
    h = sc.default_window / 2000
    ref = simulate(sc, (0.0, 300 * h), q0, v0, "moreau-jean", h=h, cone="exact", fast=False)
    calls = _python_steps(monkeypatch)
    res = simulate(sc, (0.0, 300 * h), q0, v0, "moreau-jean", h=h, cone="exact")
    assert calls[0] == 0 and res.status == 0
    _assert_same(ref, res)
    assert np.array_equal(ref.regime, res.regime)
    assert {Regime.POSITIVE} <= set(res.regime[:, 0])
    assert res.stats["max_residual"] == pytest.approx(ref.stats["max_residual"], rel=1e-9,
                                                      abs=1e-15)


@pytest.mark.parametrize("cone", ["exact", 8])
@pytest.mark.parametrize("n", [2, 3, 4])
def test_the_ball_chain_s_pair_contacts_run_in_the_loop_as_the_python_step(n, cone, monkeypatch):
    # contacts between two bodies: rows on both bodies' six velocities, the Delassus blocks of
    # contacts sharing a sphere (n >= 3: the exact cone's Newton polish compiled in), every
    # step in the loop, the Python step's run to rounding, the block result after the impact
    from moreau.scenes.ball_chain_3d import ball_chain_3d, block_result
    sc = ball_chain_3d(n_balls=n)
    q0, v0 = sc.initial_state()
    span = (0.0, sc.impact_time + 0.3)
    ref = simulate(sc, span, q0, v0, "moreau-jean", h=0.01, fast=False, cone=cone)
    calls = _python_steps(monkeypatch)
    res = simulate(sc, span, q0, v0, "moreau-jean", h=0.01, fast=True, cone=cone)
    assert calls[0] == 0 and res.status == 0
    _assert_same(ref, res)
    assert np.array_equal(ref.regime, res.regime)
    assert res.stats["lcp_solves"] == ref.stats["lcp_solves"] > 0
    after = res.t > sc.impact_time + 0.01
    assert np.max(np.abs(res.v[after][:, 0::6] - block_result(n))) <= 1e-12
    assert np.max(np.abs(ref.v[after][:, 0::6] - block_result(n))) <= 1e-12


def test_concentric_spheres_in_the_loop_are_the_python_step_s_failure(monkeypatch):
    # the loop hands the step back where a pair's centres meet; the Python step names it
    from moreau.scenes.ball_chain_3d import ball_chain_3d
    sc = ball_chain_3d(n_balls=2)
    q0, v0 = sc.initial_state()
    q0[7:10] = q0[0:3]
    calls = _python_steps(monkeypatch)
    res = simulate(sc, (0.0, 0.1), q0, v0, "moreau-jean", h=0.01, fast=True)
    assert calls[0] == 1 and res.status == -5
    assert "IllPosedError: the spheres of contact 0 (bodies 0 and 1) are concentric" in res.message


def _tumbling_pair():
    # two tumbling bodies with eccentric spheres: they hit each other (mu = 0.3, e = 0.4) and
    # a tilted floor, slipping and sticking; the pair's rows turn with both bodies
    from moreau.model.spatial import quat_exp
    rng = np.random.default_rng(3)
    m = SpaceModel(gravity=(0.0, 0.0, -9.81), length=0.05)
    floor = m.add_half_space((0.0, 0.0, 0.0), (0.1, -0.2, 1.0))
    a = m.add_body(1.0, [0.002, 0.003, 0.0025], position=(0.0, 0.0, 0.06),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)), velocity=(0.3, 0.1, 0.0),
                   angular_velocity=(2.0, -3.0, 5.0))
    b = m.add_body(2.0, [0.004, 0.003, 0.0045], position=(0.09, 0.06, 0.12),
                   orientation=quat_exp(0.5 * rng.standard_normal(3)),
                   velocity=(-0.4, -0.3, 0.0), angular_velocity=(-4.0, 1.0, 3.0))
    ca, cb = (0.01, -0.005, 0.002), (-0.003, 0.004, 0.01)
    m.add_pair_contact(a, Sphere(0.05, centre=ca), b, Sphere(0.04, centre=cb), mu=0.3,
                       restitution=0.4)
    m.add_contact(a, Sphere(0.05, centre=ca), floor, mu=0.2)
    m.add_contact(b, Sphere(0.04, centre=cb), floor, mu=0.5)
    return m.build("tumbling pair")


@pytest.mark.parametrize("cone", ["exact", 8])
def test_eccentric_spheres_of_two_tumbling_bodies_run_in_the_loop_as_the_python_step(cone,
                                                                                      monkeypatch):
    sc = _tumbling_pair()
    q0, v0 = sc.initial_state()
    ref = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=0.02, fast=False, cone=cone)
    calls = _python_steps(monkeypatch)
    res = simulate(sc, (0.0, 3.0), q0, v0, "moreau-jean", h=0.02, fast=True, cone=cone)
    assert calls[0] == 0 and res.status == 0
    # every contact carries a force, the pair's too, and some slip while others stick
    assert np.all(np.max(ref.force_N, axis=0) > 10.0)
    assert {Regime.POSITIVE, Regime.STICK} <= set(ref.regime.ravel())
    _assert_same(ref, res)
    assert np.array_equal(ref.regime, res.regime)
