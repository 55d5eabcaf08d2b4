"""The chain of spheres in space: Moreau–Jean's velocities after the impact are the block result."""

import numpy as np
import pytest

from moreau.integrators import simulate
from moreau.model.space import SpaceModel, Sphere
from moreau.regimes import Regime
from moreau.scenes.ball_chain import simultaneous_impact
from moreau.scenes.ball_chain_3d import ball_chain_3d, block_result, pyramid_forces, sphere_pyramid


def test_the_block_result_is_the_simultaneous_impacts_lcp():
    for n in range(2, 8):
        lcp = simultaneous_impact(np.ones(n), np.r_[1.0, np.zeros(n - 1)], 1.0)
        assert np.max(np.abs(lcp - block_result(n))) <= 1e-15
    assert block_result(4).tolist() == [-0.5, 0.5, 0.5, 0.5]


@pytest.mark.parametrize("cone", ["exact", 8])
def test_moreau_jean_gives_the_block_result_on_the_default_chain(cone):
    sc = ball_chain_3d(n_balls=4)        # e = 1, the impact at t* = 1.1
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 1.3), q0, v0, "moreau-jean", h=0.01, cone=cone)
    assert res.status == 0, res.message
    after = res.t > sc.impact_time + 0.01
    assert np.max(np.abs(res.v[after][:, 0::6] - block_result(4))) <= 1e-12
    # a central impact: nothing off the line, no spin
    assert np.max(np.abs(res.v[:, [1, 2]]), initial=0.0) == 0.0
    assert np.max(np.abs(np.delete(res.v, np.arange(0, 24, 6), axis=1))) <= 1e-15
    # before it, the chain at rest and the striker at its speed
    before = res.t < sc.impact_time - 0.01
    assert np.all(res.v[before][:, 0::6] == [1.0, 0.0, 0.0, 0.0])


def test_an_oblique_rough_chain_gives_the_block_result_along_its_line():
    # five spheres on a line along (2, 1, 2)/3 in space, mu = 0.3: the tangent frames are
    # oblique and turn with nothing; the friction stays idle on a central impact
    u = np.array([2.0, 1.0, 2.0]) / 3.0
    r, n = 0.02, 5
    m = SpaceModel(length=r, mass=0.05, time=r / 0.5)
    # (the chain squeezed by 1e-13 radii a contact, so that rounding leaves every one closed)
    bodies = [m.add_body(0.05, [0.4 * 0.05 * r * r] * 3,
                         position=(2.0 * r * (1.0 - 5e-14) * (i - 1) - (0.01 if i == 0 else 0.0))
                         * u, velocity=0.5 * u if i == 0 else (0.0, 0.0, 0.0)) for i in range(n)]
    for i in range(n - 1):
        m.add_pair_contact(bodies[i], Sphere(r), bodies[i + 1], Sphere(r), mu=0.3,
                           restitution=1.0)
    sc = m.build("oblique chain")
    q0, v0 = sc.initial_state()
    assert np.all(sc.gaps(q0, 0.0)[1:] < 0.0) and np.all(sc.gaps(q0, 0.0)[1:] > -1e-12)
    res = simulate(sc, (0.0, 1.0), q0, v0, "moreau-jean", h=0.02, cone="exact")
    assert res.status == 0, res.message
    V = res.v[-1].reshape(n, 6)
    along = V[:, :3] @ u
    assert np.max(np.abs(along - block_result(n))) <= 1e-12
    assert np.max(np.abs(V[:, :3] - np.outer(along, u))) <= 1e-12 and np.max(np.abs(V[:, 3:])) <= 1e-12


# -- the resting pyramid ------------------------------------------------------------------------

@pytest.mark.parametrize("cone, fast", [("exact", "auto"), (8, "auto"), (8, False)])
def test_the_pyramids_contact_forces_are_the_closed_form(cone, fast):
    sc = sphere_pyramid()                  # mu = 0.5 >= tan(beta/2) = 0.4025 / cos(pi/8)
    f = pyramid_forces(sc.params)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 2.0), q0, v0, "moreau-jean", h=0.1, cone=cone, fast=fast)
    assert res.status == 0, res.message
    if fast is False:
        # the polyhedral LCP (six sticking contacts, 60 unknowns) of a step after the first
        # has rounding noise in its data, on which Lemke's exact lexicographic path is 75
        # pivots on integers of thousands of bits (35 s); the step before's support solves
        # it: every Lemke solve is a short one (17 pivots on the first step's clean data)
        st = res.stats
        assert st["lcp_solves"] == 20 and st["warm_starts"] >= 5          # measured: 17
        assert st["pivots"] <= 20 * (st["lcp_solves"] - st["warm_starts"])
    assert np.all(res.regime == int(Regime.STICK))
    fN, fT = res.force_N[1:] * sc.force, res.force_T[1:] * sc.force
    for got, want in ((fN[:, :3], f["normal_floor"]), (fN[:, 3:], f["normal_top"]),
                      (fT[:, :3], f["friction_floor"]), (fT[:, 3:], f["friction_top"])):
        assert np.max(np.abs(got - want)) <= 1e-10 * want
    # at rest throughout
    assert np.max(np.abs(res.v)) <= 1e-14 and np.max(np.abs(res.q - q0)) <= 1e-14


def test_the_pyramid_holds_from_mu_tan_half_beta_and_collapses_below():
    mu_min = pyramid_forces()["mu_min"]
    for factor, holds in ((1.01, True), (0.99, False)):
        sc = sphere_pyramid(mu=factor * mu_min)
        q0, v0 = sc.initial_state()
        res = simulate(sc, (0.0, 0.5), q0, v0, "moreau-jean", h=0.1, cone="exact")
        assert res.status == 0, res.message
        if holds:
            assert np.max(np.abs(res.v)) <= 1e-14 and np.all(res.regime == int(Regime.STICK))
        else:
            # the top sphere sinks (measured: 1.6e-4 sqrt(g r) after the first step), sliding
            # on its three supports; the bottom ones stick on the floor (mu > tan(beta/2) / 4)
            assert np.all(np.diff(res.v[:, 6 * 3 + 2]) < -1e-4)
            assert np.all(res.regime[:, 3:] == int(Regime.POSITIVE))
            assert np.all(res.regime[:, :3] == int(Regime.STICK))
