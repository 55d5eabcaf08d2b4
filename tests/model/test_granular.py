"""Disks among walls with contacts found each step (issue 38): the broad phase, the contact
rows, and the Moreau–Jean path with NSGS (moreau.model.granular, moreau.integrators.granular)."""

import math

import numpy as np
import pytest

from moreau.contact._sparse import disk_jacobian
from moreau.errors import InputError
from moreau.integrators.granular import simulate_disks
from moreau.model.granular import DiskSystem, HalfPlane, Segment, brute_pairs, grid_pairs


def _packing(seed, n, spread):
    rng = np.random.default_rng(seed)
    radii = rng.uniform(0.3, 0.7, n)
    side = spread * math.sqrt(n)
    x = rng.uniform(0.0, side, (n, 2))
    if seed % 2:
        # a stretched cloud (a collapsing column): many empty cells, the density kept
        x[:, 0] *= 6.0
        x[:, 1] /= 6.0
    return x, radii


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("margin", [0.0, 0.05, 0.8])
def test_the_grid_finds_exactly_the_pairs_of_the_brute_force_search(seed, margin):
    x, radii = _packing(seed, 300 + 50 * seed, 1.0 + 0.2 * seed)
    i, j = grid_pairs(x, radii, margin)
    bi, bj = brute_pairs(x, radii, margin)
    assert bi.size > 50          # a packing, not a gas: the check means something
    assert np.array_equal(i, bi) and np.array_equal(j, bj)


def test_the_grid_holds_pairs_exactly_at_touching_and_none_across_distant_cells():
    # touching disks on a lattice whose spacing is exactly the cell side (2 r_max + margin)
    x = np.array([[0.0, 0.0], [2.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 9.0]])
    r = np.ones(5)
    i, j = grid_pairs(x, r)
    assert list(zip(i.tolist(), j.tolist())) == [(0, 1), (1, 2), (2, 3)]
    assert grid_pairs(x[:1], r[:1])[0].size == 0


def _touching_cloud(seed):
    # disks that touch their neighbours exactly: a chain of random directions, plus a floor
    rng = np.random.default_rng(seed)
    n = 12
    radii = rng.uniform(0.4, 0.6, n)
    x = np.zeros((n, 2))
    x[0] = (0.0, radii[0])
    for k in range(1, n):
        ang = rng.uniform(0.2, 0.8) * math.pi
        d = radii[k - 1] + radii[k]
        x[k] = x[k - 1] + d * np.array([math.cos(ang), math.sin(ang)])
    return radii, x


def test_the_contact_rows_are_the_generic_rigid_body_jacobian_and_the_gap_rate():
    radii, x = _touching_cloud(3)
    n = radii.size
    sys = DiskSystem(radii, np.linspace(1.0, 2.0, n), walls=[HalfPlane((0.0, 0.0), (0.0, 2.0))])
    cs = sys.contacts(x, margin=1e-9)
    assert cs.size >= n and np.all(np.abs(cs.gap) < 1e-12)
    H = sys.jacobian(cs).toarray()
    # moreau.contact's generic 2D rigid-body Jacobian, at the contact point (c_b - r_b n)
    rows = []
    for a, b, nrm in zip(cs.a, cs.b, cs.normal):
        p = x[b] - radii[b] * nrm
        rows.append((int(a) if a >= 0 else -1, int(b), p, nrm))
    ref = disk_jacobian(rows, x, n).toarray()
    assert np.allclose(H, ref, rtol=0.0, atol=1e-14)
    # and the normal rows are the rate of the gaps (central differences along a velocity)
    rng = np.random.default_rng(0)
    v = rng.standard_normal((n, 3))
    eps = 1e-6

    def gaps(y):
        c = sys.contacts(y, margin=1.0)
        return dict(zip(c.key.tolist(), c.gap))

    gp, gm = gaps(x + eps * v[:, :2]), gaps(x - eps * v[:, :2])
    rate = np.array([(gp[k] - gm[k]) / (2 * eps) for k in cs.key.tolist()])
    assert np.allclose(H[0::2] @ v.ravel(), rate, atol=1e-8)
    # W = H M^-1 H^T against the dense product
    W = sys.delassus(sys.jacobian(cs)).toarray()
    assert np.allclose(W, H @ np.diag(sys.inv_mass) @ H.T, rtol=1e-14, atol=1e-14)


def test_a_segment_is_touched_at_its_ends_and_from_both_sides():
    sys = DiskSystem([0.5, 0.5, 0.5], [1.0] * 3, walls=[Segment((0.0, 0.0), (2.0, 0.0))])
    x = np.array([[1.0, 0.6], [1.0, -0.7], [2.0 + 0.3, 0.4]])
    cs = sys.contacts(x, margin=0.3)
    by_disk = {int(b): (g, nrm) for b, g, nrm in zip(cs.b, cs.gap, cs.normal) if cs.a[0] < 0
               or True}
    assert by_disk[0][0] == pytest.approx(0.1) and np.allclose(by_disk[0][1], (0.0, 1.0))
    assert by_disk[1][0] == pytest.approx(0.2) and np.allclose(by_disk[1][1], (0.0, -1.0))
    assert by_disk[2][0] == pytest.approx(0.0, abs=1e-15) and np.allclose(by_disk[2][1], (0.6, 0.8))


def test_bad_input_is_refused_by_name():
    with pytest.raises(InputError, match="`walls\\[0\\]` must be a HalfPlane or a Segment"):
        DiskSystem([1.0], [1.0], walls=[(0, 0)])
    sys = DiskSystem([1.0, 1.0], [1.0, 1.0])
    with pytest.raises(InputError, match="same centre"):
        sys.contacts([[0.0, 0.0], [0.0, 0.0]])
    with pytest.raises(InputError, match="`on_unconverged`"):
        simulate_disks(sys, [[0, 0], [3, 0]], np.zeros((2, 3)), 1, 0.1, on_unconverged="warn")


def test_a_struck_chain_leaves_with_the_block_result_in_one_step():
    # frictionless, elastic, no gravity: Newton's law at every contact of the chain gives
    # the block result (moreau.contact._sparse.chain_impact_problem): w = (1 + e) / N
    N, e = 6, 1.0
    sys = DiskSystem(np.ones(N), np.ones(N), mu=0.0, restitution=e, gravity=(0.0, 0.0))
    x = np.column_stack([2.0 * np.arange(N), np.zeros(N)])
    v0 = np.zeros((N, 3))
    v0[0, 0] = 1.0
    res = simulate_disks(sys, x, v0, 1, 1e-3, tol=1e-12, max_sweeps=100_000)
    w = (1.0 + e) / N
    assert res.status == 0 and res.steps["contacts"][0] == N - 1
    assert np.allclose(res.v[-1, :, 0], [w - e] + [w] * (N - 1), atol=1e-10)


def test_a_disk_rolls_down_a_rough_incline_at_two_thirds_g_sin_alpha():
    # the tangential row with the spin: rolling without slip, a = (2/3) g sin(alpha)
    alpha, r = math.radians(20.0), 0.5
    n = (-math.sin(alpha), math.cos(alpha))
    sys = DiskSystem([r], [1.0], walls=[HalfPlane((0.0, 0.0), n)], mu=0.8)
    x0 = np.array([[r * n[0], r * n[1]]])
    h, steps = 1e-3, 500
    res = simulate_disks(sys, x0, np.zeros((1, 3)), steps, h, theta=0.5, tol=1e-12)
    down = (x0[0] - res.x[-1, 0]) @ np.array([math.cos(alpha), math.sin(alpha)])
    T = steps * h
    assert res.status == 0
    assert down == pytest.approx((2.0 / 3.0) * math.sin(alpha) * T ** 2 / 2, rel=2e-3)
    # and it rolls: the spin matches the speed (down to the left: counter-clockwise)
    vel = res.v[-1, 0]
    assert vel[2] * r == pytest.approx(math.hypot(vel[0], vel[1]), rel=1e-6)


def _pile():
    # 3 rows of disks in a box of two walls and a floor, settling under gravity
    rows, cols = 3, 5
    radii = np.full(rows * cols, 0.5)
    x = np.array([[0.5 + c + 0.05 * (r % 2), 0.5 + 1.02 * r] for r in range(rows) for c in range(cols)])
    walls = [HalfPlane((0.0, 0.0), (0.0, 1.0)), HalfPlane((0.0, 0.0), (1.0, 0.0)),
             HalfPlane((cols + 0.1, 0.0), (-1.0, 0.0))]
    return DiskSystem(radii, np.ones(rows * cols), walls=walls, mu=0.4), x


def test_a_solve_that_ends_above_tol_is_reported_or_stops_the_run():
    sys, x = _pile()
    v0 = np.zeros((x.shape[0], 3))
    res = simulate_disks(sys, x, v0, 60, 0.01, tol=1e-14, max_sweeps=2, check_every=1)
    assert res.status == 1 and not res.success
    assert res.unconverged.size > 0 and "above tol" in res.message
    assert np.all(res.steps["residual"][res.unconverged] > 1e-14)
    stopped = simulate_disks(sys, x, v0, 60, 0.01, tol=1e-14, max_sweeps=2, check_every=1,
                             on_unconverged="stop")
    assert stopped.status == -3 and "did not converge" in stopped.message
    k = stopped.unconverged[0]
    assert stopped.steps["t"].size == k + 1 and stopped.t[-1] == pytest.approx(0.01 * (k + 1))


def test_warm_start_by_pair_makes_a_resting_pile_cost_one_check():
    sys, x = _pile()
    v0 = np.zeros((x.shape[0], 3))
    # (NSGS is slow on a hyperstatic pile: 7348 sweeps to 1e-10 on one step, cold)
    res = simulate_disks(sys, x, v0, 300, 0.01, tol=1e-6, max_sweeps=5000, theta=1.0)
    assert res.status == 0, res.message
    # at rest: the last steps start at their solution (same pairs, same impulses)
    assert np.all(res.steps["sweeps"][-20:] <= 4) and np.max(res.steps["sweeps"]) > 20
    assert res.steps["contacts"][-1] >= 20
    assert np.max(np.abs(res.v[-1])) < 1e-6
