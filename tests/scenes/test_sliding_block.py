"""Sliding block: input checks, scene formulas, exact stop and stick."""

import math

import numpy as np
import pytest

import moreau.integrators.moreau_jean  # noqa: F401  (registers "moreau-jean")
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.sliding_block import SlidingBlock, SlidingBlockParams


def central(f, s=1e-5):
    return (f(s) - f(-s)) / (2.0 * s)


# -- input checks -------------------------------------------------------------
@pytest.mark.parametrize("kwargs, match", [
    ({"mass": -1.0}, r"`mass` must be > 0"),
    ({"mu": -0.1}, r"`mu` must be >= 0"),
    ({"mu": float("nan")}, r"`mu` must be finite"),
    ({"incline": math.pi / 2}, r"`incline` must be in the open interval \(-pi/2, pi/2\)"),
    ({"gravity": 0.0}, r"`gravity` must be > 0"),
    ({"restitution": 2.0}, r"`restitution` must be in \[0.0, 1.0\]"),
    ({"length": "one"}, r"`length` must be a real number"),
])
def test_bad_parameters_raise_input_error(kwargs, match):
    with pytest.raises(InputError, match=match):
        SlidingBlock(**kwargs)


def test_exact_solution_needs_a_block_on_the_plane():
    block = SlidingBlock()
    with pytest.raises(InputError, match=r"`q0` must put the block on the plane"):
        block.exact_solution([1.0], [0.0, 0.1], [1.0, 0.0])
    with pytest.raises(InputError, match=r"`v0` must be tangent to the plane"):
        block.stopping_time([1.0, -0.2])
    with pytest.raises(InputError, match=r"`t` must be >= 0"):
        block.exact_solution([-0.5], [0.0, 0.0], [1.0, 0.0])


# -- scene formulas -------------------------------------------------------------
@pytest.mark.parametrize("mu", [0.0, 0.4])
def test_contact_kinematics_match_finite_differences(mu):
    block = SlidingBlock(mu=mu, incline=0.3)
    q, v, t = np.array([0.2, 0.05]), np.array([1.1, -0.4]), 0.7
    WN, wN, WT, wT = block.contact_jacobians(q, t)
    gdot = central(lambda s: block.gaps(q + s * v, t + s)[0])
    assert WN[0] @ v + wN[0] == pytest.approx(gdot, abs=1e-9)
    # slip velocity = rate of the contact point's position along the plane
    if mu > 0:
        assert WT[0] @ v + wT[0] == pytest.approx(central(lambda s: (q + s * v)[0]), abs=1e-9)
    else:
        assert WT.shape == (0, 2) and wT.shape == (0,)
    wNbar, wTbar = block.contact_drift(q, v, t)
    assert wNbar == pytest.approx([0.0]) and len(wTbar) == WT.shape[0]


def test_mass_and_forces_from_the_si_lagrangian():
    # L = 1/2 m (X'^2 + Y'^2) + m g sin(a) X - m g cos(a) Y  (x downhill, y normal)
    p = SlidingBlockParams(mass=2.5, mu=0.3, incline=0.2, gravity=9.7, length=0.4)
    block = SlidingBlock(p)
    L, T, F = block.length, block.time, block.force
    S = np.diag([L, L])
    M_si = p.mass * np.eye(2)
    h_si = p.mass * p.gravity * np.array([math.sin(p.incline), -math.cos(p.incline)])
    assert block.mass(None) == pytest.approx(S @ M_si @ S / (T ** 2 * F * L), rel=1e-14)
    assert block.forces(None, None, 0.0) == pytest.approx(S @ h_si / (F * L), rel=1e-14)


# -- exact solution ---------------------------------------------------------------
def test_level_plane_stopping_time_and_distance_in_si():
    v0_si, mu, g = 3.0, 0.3, 9.81
    block = SlidingBlock(mu=mu, gravity=g, length=0.5)
    v0 = [block.from_si(v=v0_si).v, 0.0]
    t_stop = block.to_si(t=block.stopping_time(v0)).t
    d_stop = block.to_si(q=block.stopping_distance(v0)).q
    assert t_stop == pytest.approx(v0_si / (mu * g), rel=1e-14)
    assert d_stop == pytest.approx(v0_si ** 2 / (2 * mu * g), rel=1e-14)
    # it stays where it stopped
    ts = block.stopping_time(v0)
    q, v = block.exact_solution([ts, 2 * ts, 10 * ts], [0.0, 0.0], v0)
    assert q[:, 0] == pytest.approx(np.full(3, block.stopping_distance(v0)), rel=1e-14)
    assert np.all(v == 0.0)


@pytest.mark.parametrize("alpha, mu, u0", [
    (0.2, 0.5, 1.5),     # downhill, sticks afterwards (tan a < mu)
    (0.2, 0.5, -1.5),    # uphill, sticks afterwards
    (0.6, 0.3, -1.0),    # uphill, then slides back down (tan a > mu)
    (0.6, 0.3, 1.0),     # downhill, accelerates for ever
])
def test_inclined_plane_motion_satisfies_coulomb(alpha, mu, u0):
    block = SlidingBlock(mu=mu, incline=alpha)
    s, c = math.sin(alpha), math.cos(alpha)
    assert block.sticks == (math.tan(alpha) <= mu)
    m = block.motion([u0, 0.0])
    if u0 > 0 and not block.sticks:
        assert m.t_stop == math.inf and block.stopping_distance([u0, 0.0]) == math.inf
    else:
        assert m.t_stop == pytest.approx(abs(u0) / (mu * c - math.copysign(1, u0) * s), rel=1e-14)
    # the motion obeys x'' = sin(a) - mu cos(a) sign(x') wherever it slides
    for t in np.linspace(0.05, 4.0, 9):
        if abs(t - m.t_stop) < 1e-3:
            continue
        q, v = block.exact_solution([t], [0.3, 0.0], [u0, 0.0])
        x = lambda h: block.exact_solution([t + h], [0.3, 0.0], [u0, 0.0])[0][0, 0]
        u = lambda h: block.exact_solution([t + h], [0.3, 0.0], [u0, 0.0])[1][0, 0]
        assert central(x) == pytest.approx(v[0, 0], abs=1e-8)
        if v[0, 0] != 0.0:
            assert central(u) == pytest.approx(s - mu * c * math.copysign(1.0, v[0, 0]), abs=1e-8)
        else:
            assert block.sticks and central(u) == 0.0
    t_after = m.t_stop + 1.0 if math.isfinite(m.t_stop) else 10.0
    lamN, lamT = block.contact_forces([0.01, t_after], [u0, 0.0])
    assert lamN == pytest.approx([c, c])
    assert lamT[0] == pytest.approx(-mu * c * math.copysign(1.0, u0))
    if math.isfinite(m.t_stop):
        assert lamT[1] == pytest.approx(-s if block.sticks else -mu * c)


def test_frictionless_block_never_stops():
    block = SlidingBlock(mu=0.0)
    assert block.stopping_time([1.0, 0.0]) == math.inf
    q, v = block.exact_solution([2.0], [0.0, 0.0], [1.0, 0.0])
    assert q[0, 0] == 2.0 and v[0, 0] == 1.0


# -- Moreau–Jean against the exact solution ---------------------------------------
def fitted_order(hs, errors):
    return np.polyfit(np.log(hs), np.log(errors), 1)[0]


def position_errors(block, u0, t_end, hs, theta):
    errors = []
    for h in hs:
        res = simulate(block, (0.0, t_end), [0.0, 0.0], [u0, 0.0], "moreau-jean", h=h,
                       theta=theta)
        assert res.status == 0
        q_exact, v_exact = block.exact_solution(res.t, [0.0, 0.0], [u0, 0.0])
        # the discrete velocity is exact at the grid points (constant
        # deceleration, stop caught by the contact problem)
        assert np.max(np.abs(res.v[:, 0] - v_exact[:, 0])) < 1e-12
        errors.append(np.max(np.abs(res.q[:, 0] - q_exact[:, 0])))
    return np.array(errors)


@pytest.mark.parametrize("alpha, mu, u0, t_end", [
    (0.0, 0.3, 1.0, 5.0),       # level plane, stops at 10/3
    (0.2, 0.5, 1.5, 6.5),       # downhill on a slope it sticks to, stops at 5.148
])
def test_moreau_jean_converges_at_first_order(alpha, mu, u0, t_end):
    block = SlidingBlock(mu=mu, incline=alpha)
    hs = 0.1 * 2.0 ** -np.arange(5)
    errors = position_errors(block, u0, t_end, hs, theta=1.0)
    assert 0.8 <= fitted_order(hs, errors) <= 1.3
    # theta = 1 integrates the exact (linear) velocity with the right-point
    # rule, which lags by h v0 / 2 once the block has stopped
    assert errors / hs == pytest.approx(np.full(len(hs), 0.5 * u0), rel=0.02)


def test_moreau_jean_theta_half_is_second_order_on_the_level_plane():
    # with the trapezoidal position update only the stopping step errs
    block = SlidingBlock(mu=0.3)
    hs = 0.1 * 2.0 ** -np.arange(4)
    errors = position_errors(block, 1.0, 5.0, hs, theta=0.5)
    assert 1.8 <= fitted_order(hs, errors) <= 2.2
