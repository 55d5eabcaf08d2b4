"""The ball chain: closed forms, the two impact pictures, and what each scheme gives.

The references here are derived by hand, apart from the module's solvers:

* two balls: momentum ``m0 V = m0 v0 + m1 v1`` and Newton's law
  ``v1 - v0 = e V`` give ``v0 = (m0 - e m1) V / (m0 + m1)``,
  ``v1 = (1 + e) m0 V / (m0 + m1)``, at ``t* = gap / V``;
* the simultaneous Newton impact of a striker (mass ratio ``mu``, speed 1)
  on ``N - 1`` resting, touching unit balls: the resting contacts have no
  approach velocity, so Newton's law asks only that they do not close; the
  chain ``1 .. N-1`` leaves as a block at ``w`` and the striker at ``u``
  with ``w - u = e`` and ``mu u + (N - 1) w = mu``:
  ``w = mu (1 + e) / (mu + N - 1)``, ``u = w - e``. The impulse through
  contact ``i >= 1`` is ``(N - 1 - i) w > 0`` and through contact 0 it is
  ``(N - 1) w > 0``, so every contact is loaded and this is the LCP's
  (unique) solution;
* its kinetic energy change is ``sum_i P_i (U+_i + U-_i) / 2``, zero at
  ``e = 1`` (``U+_0 = -U-_0`` and ``U+_i = U-_i = 0`` elsewhere): the block
  keeps the energy; at ``e = 0`` all move at ``mu / (mu + N - 1)``.
"""

import math

import numpy as np
import pytest

from moreau.compiled import check_compiled_model
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes import registry
from moreau.integrators.moreau_jean import SPARSE_TOL, MoreauJean
from moreau.scenes import ball_chain
from moreau.scenes.ball_chain import (SPARSE_FROM, BallChain, BallChainCase, sequential_impacts,
                                      simultaneous_impact, two_ball_impact)

EPS = np.finfo(float).eps


def _run(chain, scheme, t_end=None, **options):
    if scheme in ("moreau-jean", "schatzman-paoli"):
        # a few hundred steps: the generic step, no compile of a loop per chain length
        options.setdefault("fast", False)
    q0, v0 = chain.initial_state()
    t_end = chain.impact_time + 2.0 if t_end is None else t_end
    r = simulate(chain, (0.0, t_end), q0, v0, scheme, **options)
    assert r.success, r.message
    return r


def _block(n, mu, e):
    """Velocities after the simultaneous Newton impact, by hand (module docstring)."""
    w = mu * (1.0 + e) / (mu + n - 1.0)
    v = np.full(n, w)
    v[0] = w - e
    return v


def _exact_q(chain, v_after, t):
    # free flight before and after the impact at t*
    q0, v0 = chain.initial_state()
    ts = chain.impact_time
    return q0 + v0 * ts + v_after * (t - ts)


# -- two balls: one contact, one answer ----------------------------------------------------------

def test_two_ball_closed_form_by_hand():
    assert two_ball_impact(1.0, 1.0, 1.0, 1.0) == (0.0, 1.0)
    # m0 = 3, m1 = 1, e = 0.8, V = 2: v0 = (3 - 0.8) 2 / 4, v1 = 1.8 * 3 * 2 / 4
    assert two_ball_impact(3.0, 1.0, 2.0, 0.8) == pytest.approx((1.1, 2.7), rel=1e-15)
    # a perfectly plastic impact: one common velocity
    assert two_ball_impact(1.0, 3.0, 2.0, 0.0) == pytest.approx((0.5, 0.5), rel=1e-15)


@pytest.mark.parametrize("e, ratio", [(1.0, 1.0), (0.5, 1.0), (0.0, 1.0), (0.8, 3.0), (1.0, 0.25)])
def test_two_balls_every_scheme_gives_the_closed_form(e, ratio):
    chain = BallChain(n_balls=2, restitution=e, striker_mass=0.1 * ratio, striker_gap=0.0123)
    exact = two_ball_impact(ratio, 1.0, 1.0, e)
    assert exact[0] * ratio + exact[1] == pytest.approx(ratio, rel=1e-15)
    assert exact[1] - exact[0] == pytest.approx(e, abs=1e-15)
    assert chain.impact_time == pytest.approx(1.23, rel=1e-15)   # gap / radius, speed 1
    t_end = chain.impact_time + 2.0
    for scheme, opts in [("moreau-jean", {"h": 0.01}), ("moreau-jean", {"h": 0.01, "fast": True}),
                         ("moreau-jean", {"h": 0.01, "lcp_method": "qp"}),
                         ("schatzman-paoli", {"h": 0.01}), ("event-driven", {}),
                         ("event-driven-generic", {"rtol": 1e-12, "atol": 1e-12})]:
        r = _run(chain, scheme, **opts)
        # Schatzman-Paoli's velocities are position differences over h: rounding / h
        tol = 1e-13 if scheme == "schatzman-paoli" else 4 * EPS
        assert r.v[-1] == pytest.approx(exact, abs=tol), (scheme, opts)
        if scheme.startswith("event-driven"):
            # the impact found at t* = gap / V: positions to rounding
            assert r.q[-1] == pytest.approx(_exact_q(chain, np.array(exact), t_end), abs=1e-13)


# -- longer chains: the simultaneous impact against the sequential picture ----------------------

def test_newtons_cradle_sequential_against_simultaneous():
    m = np.ones(3)
    v = [1.0, 0.0, 0.0]
    assert sequential_impacts(m, v, 1.0).tolist() == [0.0, 0.0, 1.0]
    # the module's LCP against the hand-derived block
    assert simultaneous_impact(m, v, 1.0) == pytest.approx([-1 / 3, 2 / 3, 2 / 3], abs=4 * EPS)
    assert simultaneous_impact(m, v, 0.0) == pytest.approx([1 / 3] * 3, abs=4 * EPS)


@pytest.mark.parametrize("n", [3, 4, 10, 25])
def test_sequential_impacts_send_the_striker_speed_to_the_last_ball(n):
    chain = BallChain(n_balls=n)
    v0 = chain.initial_state()[1]
    seq = sequential_impacts(chain.masses, v0, 1.0)
    assert seq.tolist() == np.eye(n)[-1].tolist()
    assert chain.kinetic_energy(seq) == 0.5


@pytest.mark.parametrize("n, ratio, e", [(3, 1.0, 1.0), (3, 1.0, 0.5), (10, 1.0, 1.0),
                                         (10, 1.0, 0.5), (10, 1.0, 0.0), (6, 2.5, 0.7)])
def test_every_scheme_moves_the_chain_as_a_block(n, ratio, e):
    chain = BallChain(n_balls=n, restitution=e, striker_mass=0.1 * ratio)
    block = _block(n, ratio, e)
    v0 = chain.initial_state()[1]
    assert simultaneous_impact(chain.masses, v0, e) == pytest.approx(block, abs=8 * EPS)
    for scheme, opts in [("moreau-jean", {"h": 0.01}), ("moreau-jean", {"h": 0.01, "lcp_method": "qp"}),
                         ("schatzman-paoli", {"h": 0.01}), ("event-driven", {}),
                         ("event-driven-generic", {"rtol": 1e-12, "atol": 1e-12})]:
        r = _run(chain, scheme, **opts)
        tol = (1e-13 if scheme == "schatzman-paoli" else 1e-14) * n
        assert r.v[-1] == pytest.approx(block, abs=tol), (scheme, opts)
        if scheme.startswith("event-driven"):
            assert r.q[-1] == pytest.approx(_exact_q(chain, block, r.t[-1]), abs=1e-13 * n)


def test_the_block_numbers_for_equal_balls_and_e_1():
    # n = 3: striker -1/3, the others 2/3; n = 10: -0.8 and 0.2; in general (2 - n) / n and 2 / n
    assert _block(3, 1.0, 1.0) == pytest.approx([-1 / 3, 2 / 3, 2 / 3], rel=1e-15)
    chain = BallChain(n_balls=10)
    r = _run(chain, "moreau-jean", h=0.01)
    assert r.v[-1] == pytest.approx([-0.8] + [0.2] * 9, abs=2e-15)
    r = _run(chain, "event-driven")
    assert r.v[-1] == pytest.approx([-0.8] + [0.2] * 9, abs=2e-15)


# -- energy and momentum ------------------------------------------------------------------------

@pytest.mark.parametrize("n, e, energy", [
    (3, 1.0, 0.5), (10, 1.0, 0.5),          # kept: ((n-2)^2 + 4 (n-1)) / (2 n^2) = 1/2
    (10, 0.5, 0.1625),                      # (0.35^2 + 9 * 0.15^2) / 2
    (10, 0.0, 0.05), (3, 0.0, 1 / 6),       # all at 1/n: 1 / (2 n)
])
def test_kinetic_energy_after_the_impact(n, e, energy):
    chain = BallChain(n_balls=n, restitution=e)
    assert chain.kinetic_energy(_block(n, 1.0, e)) == pytest.approx(energy, rel=1e-14)
    for scheme in ("moreau-jean", "event-driven"):
        r = _run(chain, scheme, **({"h": 0.01} if scheme == "moreau-jean" else {}))
        assert chain.kinetic_energy(r.v[-1]) == pytest.approx(energy, rel=1e-14), scheme


def test_sequential_impacts_keep_the_energy_at_e_1_and_lose_it_below():
    m = np.array([2.5, 1.0, 1.0, 1.0, 1.0])
    v = np.array([1.0, 0.0, 0.0, 0.0, 0.0])
    ke0 = 0.5 * m @ v**2
    seq = sequential_impacts(m, v, 1.0)
    assert 0.5 * m @ seq**2 == pytest.approx(ke0, rel=1e-14)
    assert m @ seq == pytest.approx(m @ v, rel=1e-14)
    assert np.all(np.diff(seq) >= 0.0)          # no pair approaches at the end
    # three equal balls at e = 1/2, by hand: (1,0,0) -> (1/4,3/4,0) -> (1/4,3/16,9/16)
    # -> (13/64,15/64,9/16); kinetic energy 0.2063 of 0.5
    seq = sequential_impacts(np.ones(3), [1.0, 0.0, 0.0], 0.5)
    assert seq.tolist() == [13 / 64, 15 / 64, 9 / 16]
    assert 0.5 * np.sum(seq**2) == pytest.approx(0.206298828125, rel=1e-15)


@pytest.mark.parametrize("n", [2, 3, 5, 17, 40])
@pytest.mark.parametrize("lcp", ["auto", "qp"])
def test_moreau_jean_conserves_momentum_at_every_step(n, lcp):
    # the impulses enter as WN^T P and every row of WN sums to zero: momentum is kept
    # to rounding, whatever the solver returns
    e = [0.0, 0.3, 1.0][n % 3]
    chain = BallChain(n_balls=n, restitution=e, striker_mass=0.37)
    r = _run(chain, "moreau-jean", h=0.013, lcp_method=lcp)
    p = r.v @ chain.masses
    assert np.max(np.abs(p - p[0])) <= 8 * EPS * n
    assert p[0] == pytest.approx(3.7, rel=1e-15)


# -- where Moreau-Jean places the impact ---------------------------------------------------------

def test_moreau_jean_places_the_impact_at_the_nearest_grid_time():
    # the contact enters the index set at the first t_k with g(t_k) + h/2 g'(t_k) <= 0,
    # the grid time nearest t*; from t_k on every ball flies at its post-impact speed, so
    # every coordinate is off by (v+ - v-)(t* - t_k), and nothing else
    chain = BallChain(n_balls=3, restitution=1.0, striker_gap=0.0123)
    ts = chain.impact_time
    v0 = chain.initial_state()[1]
    jump = _block(3, 1.0, 1.0) - v0
    for h in (0.3, 0.15, 0.075, 0.0375, 0.01875, 0.01):
        r = _run(chain, "moreau-jean", h=h)
        tk = math.ceil(ts / h - 0.5) * h
        offset = r.q[-1] - _exact_q(chain, _block(3, 1.0, 1.0), r.t[-1])
        assert offset == pytest.approx(jump * (ts - tk), abs=1e-13), h


def test_moreau_jean_impact_placement_is_first_order():
    # steps h_j = t* / (m_j + 0.3), m_j doubling: t* lies 0.3 h_j past a grid time at every
    # level, so the error is 0.3 h_j |jump| and the fitted order is 1
    chain = BallChain(n_balls=4, restitution=0.5, striker_gap=0.0123)
    ts = chain.impact_time
    ref = _block(4, 1.0, 0.5)
    hs, errs = [], []
    for m in (4, 8, 16, 32, 64):
        h = ts / (m + 0.3)
        r = _run(chain, "moreau-jean", h=h)
        hs.append(h)
        errs.append(np.max(np.abs(r.q[-1] - _exact_q(chain, ref, r.t[-1]))))
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert order == pytest.approx(1.0, abs=0.01)
    assert errs[-1] == pytest.approx(0.3 * hs[-1] * (1.0 - ref[0]), rel=1e-9)


# -- the compiled loop ---------------------------------------------------------------------------

def test_the_compiled_model_equals_the_python_model_at_100_balls():
    chain = BallChain(n_balls=100, striker_mass=0.23)
    rng = np.random.default_rng(7)
    q = chain.initial_state()[0] + 0.1 * rng.standard_normal(100)
    v = rng.standard_normal(100)
    assert check_compiled_model(chain, q, v, 0.4) <= 1e-12


def test_the_compiled_loop_runs_100_balls_like_the_generic_step():
    # 99 contacts in one Lemke problem per step; one compile of the loop for this size
    chain = BallChain(n_balls=100, restitution=0.5, striker_gap=0.001)
    t_end = chain.impact_time + 0.3
    fast = _run(chain, "moreau-jean", t_end, h=0.01, fast=True)
    slow = _run(chain, "moreau-jean", t_end, h=0.01, fast=False)
    assert np.max(np.abs(fast.q - slow.q)) < 1e-12 and np.max(np.abs(fast.v - slow.v)) < 1e-12
    # rounding grows with the size of the 99 x 99 problem: 1.1e-13 measured
    assert fast.v[-1] == pytest.approx(_block(100, 1.0, 0.5), abs=1e-12)
    assert fast.v[-1, 0] == pytest.approx(-0.485, abs=1e-12)
    assert fast.stats["fallbacks"] == 0


def test_a_compliant_contact_carries_a_wave_down_the_chain():
    # springs between the balls let the impacts happen one after another: the last ball
    # takes most of the speed (measured 0.878 at stiffness 1e4 for n = 10), far from the
    # rigid block's 0.2 and short of the sequential picture's 1
    chain = BallChain(n_balls=10, restitution=1.0)
    r = _run(chain, "compliant-rk45", stiffness=1e4)
    assert 0.8 < r.v[-1, -1] < 0.95
    assert chain.masses @ r.v[-1] == pytest.approx(1.0, rel=1e-9)


# -- input --------------------------------------------------------------------------------------

BAD = [
    ({"n_balls": 1}, "n_balls"), ({"n_balls": 10_001}, "n_balls"), ({"n_balls": 2.5}, "n_balls"),
    ({"n_balls": True}, "n_balls"), ({"n_balls": math.nan}, "n_balls"),
    ({"n_balls": "3"}, "n_balls"), ({"mass": -1.0}, "mass"), ({"mass": math.nan}, "mass"),
    ({"striker_mass": 0.0}, "striker_mass"), ({"radius": math.inf}, "radius"),
    ({"restitution": 1.5}, "restitution"), ({"restitution": math.nan}, "restitution"),
    ({"restitution": -0.1}, "restitution"), ({"striker_speed": math.nan}, "striker_speed"),
    ({"striker_speed": -1.0}, "striker_speed"), ({"striker_gap": -1e-3}, "striker_gap"),
]


@pytest.mark.parametrize("params, name", BAD)
def test_bad_parameters_are_refused_by_name(params, name):
    with pytest.raises(InputError, match=f"`{name}`"):
        BallChain(**params)
    # the same refusal through the registry and the comparison case, before any run
    with pytest.raises(InputError, match=f"`{name}`"):
        registry.make_scene("ball-chain", **params)
    with pytest.raises(InputError, match=f"`{name}`"):
        BallChainCase(**params)


def test_unknown_parameter_is_refused():
    with pytest.raises(InputError, match="`balls`"):
        BallChain(balls=3)


@pytest.mark.parametrize("call, name", [
    (lambda: two_ball_impact(-1.0, 1.0, 1.0, 0.5), "m0"),
    (lambda: two_ball_impact(1.0, 1.0, math.nan, 0.5), "V"),
    (lambda: two_ball_impact(1.0, 1.0, 1.0, 2.0), "e"),
    (lambda: simultaneous_impact([1.0, 1.0], [1.0, 0.0, 0.0], 0.5), "masses"),
    (lambda: simultaneous_impact([1.0, 0.0], [1.0, 0.0], 0.5), "masses"),
    (lambda: simultaneous_impact([1.0, 1.0], [1.0, math.nan], 0.5), "v"),
    (lambda: simultaneous_impact([1.0, 1.0], [1.0, 0.0], -0.5), "e"),
    (lambda: sequential_impacts([1.0, 1.0], [1.0, 0.0], 1.5), "e"),
    (lambda: sequential_impacts([1.0], [1.0], 1.0), "masses"),
])
def test_the_impact_laws_refuse_bad_input(call, name):
    with pytest.raises(InputError, match=f"`{name}`"):
        call()


def test_si_units_come_back():
    chain = BallChain(n_balls=2, radius=0.02, striker_speed=2.0, mass=0.5, striker_mass=0.5,
                      striker_gap=0.01)
    assert chain.time == pytest.approx(0.01) and chain.force == pytest.approx(0.5 * 4 / 0.02)
    assert chain.velocity_to_si(1.0) == pytest.approx(2.0)
    # the impact at gap / speed = 5 ms
    assert chain.impact_time * chain.time_unit_s == pytest.approx(0.005, rel=1e-15)
    r = _run(chain, "event-driven")
    cols = {name: (unit, col) for name, unit, col in chain.si_columns(r)}
    assert cols["t"][0] == "s" and cols["v_1"][0] == "m/s" and cols["q_0"][0] == "m"
    assert cols["v_1"][1][-1] == pytest.approx(2.0, rel=1e-14)      # the last ball leaves at V
    assert cols["v_0"][1][-1] == pytest.approx(0.0, abs=1e-14)


# -- long chains: the sparse step ---------------------------------------------------------------

def test_the_sparse_model_is_the_compiled_one_from_sparse_from_balls():
    assert BallChain(n_balls=SPARSE_FROM - 1).sparse_contacts() is None
    chain = BallChain(n_balls=SPARSE_FROM, striker_mass=0.23)
    inv_m, f, jacobian, gaps = chain.sparse_contacts()
    rng = np.random.default_rng(3)
    q = chain.initial_state()[0] + 0.1 * rng.standard_normal(SPARSE_FROM)
    WN = np.asarray(chain.contact_jacobians(q, 0.0)[0])
    assert np.array_equal(jacobian(q).toarray(), WN)
    assert np.array_equal(gaps(q), np.asarray(chain.gaps(q, 0.0)))
    assert np.array_equal(1.0 / inv_m, np.diag(chain.mass(q))) and not f.any()


def test_the_sparse_step_runs_like_the_generic_step(monkeypatch):
    # a short chain put on the sparse step (the generic step's dense Lemke at SPARSE_FROM
    # balls takes seconds), e = 0.5, striker twice as heavy, the default window
    monkeypatch.setattr(ball_chain, "SPARSE_FROM", 2)
    chain = BallChain(n_balls=30, restitution=0.5, striker_mass=0.2)
    q0, v0 = chain.initial_state()
    sparse = simulate(chain, (0.0, chain.default_window), q0, v0, "moreau-jean", h=0.01)
    dense = _run(chain, "moreau-jean", h=0.01)
    assert sparse.success and sparse.stats["lcp_solves"] >= 1
    for name in ("t", "q", "v", "force_N", "gap"):
        assert np.max(np.abs(getattr(sparse, name) - getattr(dense, name))) < 1e-11, name
    # after the impact the block's closed contacts meet approach velocities of rounding size,
    # which one solver may answer with impulses of 1e-15 and the other with none: the
    # regimes agree wherever a force is above rounding
    loaded = np.maximum(sparse.force_N, dense.force_N) > 1e-9
    assert loaded.any() and np.array_equal(sparse.regime[loaded], dense.regime[loaded])


def test_moreau_jean_takes_the_sparse_step_from_sparse_from_balls():
    for n, sparse in [(SPARSE_FROM - 1, False), (SPARSE_FROM, True)]:
        chain = BallChain(n_balls=n)
        mj = MoreauJean(chain, 0.0, *chain.initial_state(), 1.0, h=0.01)
        assert (mj._sparse is not None) == sparse
        # a named dense solver, or the generic step, keeps the dense path
        mj = MoreauJean(chain, 0.0, *chain.initial_state(), 1.0, h=0.01, lcp_method="lemke")
        assert mj._sparse is None


@pytest.mark.parametrize("ratio, e", [(1.0, 1.0), (2.5, 0.5)])
def test_a_thousand_balls_move_as_the_block(ratio, e):
    # the registered scene by name, the default options: the sparse step
    n = 1000
    chain = registry.make_scene("ball-chain", n_balls=n, restitution=e, striker_mass=0.1 * ratio)
    q0, v0 = chain.initial_state()
    r = simulate(chain, (0.0, chain.default_window), q0, v0, "moreau-jean", h=0.01)
    assert r.success and r.stats["lcp_solves"] >= 1
    assert r.stats["max_residual"] <= SPARSE_TOL
    block = _block(n, ratio, e)
    # the solver's tolerance on the residual bounds the velocities' error far above what
    # the exact active set leaves (2.6e-14 measured)
    assert r.v[-1] == pytest.approx(block, abs=1e-12)
    assert r.v[-1] == pytest.approx(simultaneous_impact(chain.masses, v0, e), abs=1e-12)
    momentum = r.v @ chain.masses
    assert momentum == pytest.approx(np.full(len(r.t), ratio), abs=1e-12)
    if ratio == 1.0:
        assert r.v[-1] == pytest.approx([2 / n - 1] + [2 / n] * (n - 1), abs=1e-12)


@pytest.mark.slow
def test_ten_thousand_balls_move_as_the_block():
    n = 10_000
    chain = registry.make_scene("ball-chain", n_balls=n, restitution=0.7, striker_mass=0.2)
    q0, v0 = chain.initial_state()
    r = simulate(chain, (0.0, chain.default_window), q0, v0, "moreau-jean", h=0.01)
    assert r.success and r.stats["max_residual"] <= SPARSE_TOL
    block = _block(n, 2.0, 0.7)
    assert simultaneous_impact(chain.masses, v0, 0.7) == pytest.approx(block, abs=1e-12)
    # 2.5e-13 measured at e = 1
    assert r.v[-1] == pytest.approx(block, abs=1e-11)
