"""The granular scenes' studies (issue 38): the silo's floor load, the column's runout."""

import numpy as np
import pytest

from moreau.scenes.granular_column import collapse, fit_runout, runout_study
import math

from scipy.optimize import brentq

from moreau.errors import InputError
from moreau.scenes.silo import (fill, fill_average, fit_janssen, janssen, janssen_k_bounds,
                                wall_profile)


def test_a_silo_at_rest_balances_its_weight_between_floor_and_walls():
    r = fill(2, per_pour=12, settle_steps=400)
    assert np.all(r["unconverged"] == 0) and np.all(r["max_residual"] <= 1e-6)
    # at rest the floor and the walls' friction carry the weight (per unit of density d^2 g);
    # at this size the walls' share has either sign (the load of rigid grains is statically
    # indeterminate: the pours' history picks it; Janssen's saturation is the slow test's)
    assert np.allclose(r["m_app"] + r["wall_friction"], r["mass"], rtol=2e-2)
    assert np.all(r["m_app"] > 0.5 * r["mass"])
    # the profile's deepest cut holds every disk and carries the floor's load (the last step's
    # against the mean over the weighing: at rest they agree), its shallowest little
    prof = r["profile"]
    assert prof["mass"][-1] == pytest.approx(r["mass"][-1], rel=1e-12)
    assert prof["m_app"][-1] == pytest.approx(r["m_app"][-1], rel=2e-2)
    assert np.all(np.diff(prof["mass"]) > 0.0) and prof["mass"][0] < 0.5 * r["mass"][-1]
    assert np.allclose(prof["m_app"] + prof["wall_friction"], prof["mass"], rtol=1e-12)
    assert np.all(np.abs(prof["wall_friction"]) <= 0.5 * prof["wall_normal"] * (1 + 1e-9))
    assert prof["K_band"].shape == (prof["depth"].size - 1,)


def test_janssens_k_bounds_match_the_mohr_circle():
    # an independent construction: a circle of centre 1, radius sin(phi), the point at the
    # wall where tau = mu_w sigma on its lower (active) side, between the point where the
    # circle's tangent passes through the origin (cos = -sin(phi)) and sigma's minimum, the
    # vertical stress opposite
    for phi, mu_w in ((math.radians(30.0), 0.3), (math.radians(40.0), 0.7), (0.4, 0.1)):
        s = math.sin(phi)
        ang = brentq(lambda a: s * math.sin(a) - mu_w * (1 + s * math.cos(a)), math.acos(-s),
                     math.pi)
        sig_w = 1 + s * math.cos(ang)
        k_a, k_w, k_p = janssen_k_bounds(phi, mu_w)
        assert k_w == pytest.approx(sig_w / (2 - sig_w), rel=1e-10)
        assert k_a == pytest.approx((1 - s) / (1 + s)) and k_p == pytest.approx(1 / k_a)
        assert k_a < k_w < 1.0
    assert math.isnan(janssen_k_bounds(math.radians(20.0), 0.5)[1])
    with pytest.raises(InputError, match="`phi`"):
        janssen_k_bounds(2.0, 0.5)


def test_a_column_collapses_and_spreads_and_says_how_well_each_step_was_solved():
    c = collapse(width=0.015, aspect=2.0, h=0.02, settle_time=10.0, max_time=20.0)
    # the column settled near the aspect ratio it was filled to, and spread beyond its base
    assert abs(c["aspect"] - 2.0) < 0.5
    assert c["runout"] > 0.5 and c["L_inf"] > c["L0"] + 1.0
    assert c["n_disks"] > 15 and 0 <= c["unconverged"] < c["steps"]
    assert c["max_residual"] > 0.0


def test_the_runout_fit_recovers_a_known_law():
    a = np.array([0.25, 0.5, 1.0, 3.0, 6.0, 12.0])
    r = np.where(a <= 1.5, 1.7 * a, 1.7 * 1.5 ** (1 / 3) * a ** (2 / 3))
    f = fit_runout(a, r, a_split=1.5)
    assert f["lambda"] == pytest.approx(1.7) and f["p"] == pytest.approx(2 / 3)
    assert f["p_small"] == pytest.approx(1.0) and f["c_small"] == pytest.approx(1.7)
    # a column that stood (runout <= 0) leaves the small range's power unfitted, not wrong
    f = fit_runout([0.6, 1.2, 1.6, 4.0, 8.0], [3.1, -0.02, 2.5, 5.2, 10.7], a_split=2.0)
    assert f["p_small"] is None and f["c_small"] is None and f["p"] is not None


@pytest.mark.slow
def test_taller_columns_run_out_further():
    # (the fitted exponents are reported, not asserted: at six grains wide, without rolling
    # resistance, the measured runout does not follow the experiments' a^(2/3); see
    # the granular_column module)
    rows, fit = runout_study((2.0, 4.0, 8.0), width=0.03, a_split=1.5, max_time=80.0,
                             settle_time=30.0)
    runout = [r["runout"] for r in rows]
    assert all(np.diff(runout) > 0) and fit["c"] > 0.0


def test_the_janssen_fit_recovers_k_from_a_saturating_load():
    m = np.linspace(10.0, 150.0, 8)
    f = fit_janssen(m, janssen(m, 80.0), rho=0.75, width=6.0, mu_wall=0.5)
    # m_sat = rho W lam, K = W / (2 mu_w lam)
    assert f["m_sat"] == pytest.approx(80.0, rel=1e-6)
    assert f["K"] == pytest.approx(6.0 / (2 * 0.5 * 80.0 / (0.75 * 6.0)), rel=1e-6)


@pytest.mark.slow
def test_the_silo_floor_load_saturates_as_janssen_predicts():
    # measured (12 pours of 30 disks, W = 6 d, mu_wall = 0.5): m_sat = 58.9, lam = 12.9 d,
    # K = 0.46; deviations from the fitted law -8 % .. +12.4 %, 7.8 % rms: the pour-to-pour
    # scatter of a statically indeterminate load exceeds issue 38's 10 % at three pours
    r = fill(12, per_pour=30)
    f = fit_janssen(r["mass"], r["m_app"], rho=r["rho"], width=r["width"], mu_wall=0.5)
    assert np.sqrt(np.mean(f["deviation"] ** 2)) <= 0.10 and f["max_deviation"] <= 0.15
    # saturated: the last pours add (almost) nothing to the floor's load, the walls carry it
    assert r["m_app"][-1] < 0.35 * r["mass"][-1] and r["mass"][-1] > 3.0 * f["m_sat"]
    assert np.allclose(r["m_app"] + r["wall_friction"], r["mass"], rtol=2e-2)
    # why the fit is not closer (issue 38's 10 %; the silo module): inside this packing, at rest,
    # Janssen's premises fail. Measured: the walls' friction mobilised to 43 % of mu_w over the
    # column, the load across cuts every 2 d non-monotonic (87 at depth 30 d, 59 on the floor),
    # Janssen's law fitted to it off by 42 % at worst (rms 17 %)
    prof = r["profile"]
    assert prof["m_app"][-1] == pytest.approx(r["m_app"][-1], rel=2e-2)
    assert prof["mobilised"][-1] < 0.6
    fp = fit_janssen(prof["mass"], prof["m_app"], rho=r["rho"], width=r["width"], mu_wall=0.5)
    assert fp["max_deviation"] > 0.2 and np.max(prof["m_app"]) > 1.2 * prof["m_app"][-1]


@pytest.mark.slow
def test_the_silo_floor_load_averaged_over_four_fills_saturates_near_janssens_law():
    # four fills (seeds 0-3, 12 pours of 30 disks, W = 6 d, mu_wall = 0.5), the floor's load
    # averaged pour by pour. Measured: each fill's own fit K = 0.46, 0.37, 0.30, 0.18 (its
    # saturation mass 59 .. 150: the load of rigid grains is statically indeterminate, and
    # each fill's history mobilises the walls differently); the average's fit m_sat = 88.6,
    # lam = 19.5 d, K = 0.31, deviations -10 % .. +16 % (rms 9.4 %). Issue 38's 10 % at every
    # depth is not reached, and more fills do not reach it: eight (seeds 0-7, measured once,
    # too dear for a test) fit K = 0.29 with deviations -12 % .. +22 % (rms 12.9 %), the
    # averaged load rising faster than Janssen's exponential over the first pours and
    # saturating more sharply (chi^2 / dof 2.9 against the standard error of the mean): a
    # systematic difference, not scatter. This test holds the four-fill figures.
    r = fill_average(12, (0, 1, 2, 3), per_pour=30)
    f = fit_janssen(r["mass"], r["m_app"], rho=r["rho"], width=r["width"], mu_wall=0.5)
    assert np.sqrt(np.mean(f["deviation"] ** 2)) <= 0.12 and f["max_deviation"] <= 0.20
    # saturated: the walls carry two thirds of the last pour's weight; K of the order
    # Rankine's active ratio (1 - sin phi) / (1 + sin phi) = 0.38 at tan phi = 0.5
    assert r["m_app"][-1] < 0.4 * r["mass"][-1] and 0.2 < f["K"] < 0.5
    assert np.allclose(r["m_app"] + r["wall_friction"], r["mass"], rtol=2e-2)


@pytest.mark.slow
def test_rolling_resistance_mobilises_the_silo_walls_more_but_not_to_janssens_premise():
    # measured (8 pours of 24 disks, seed 0, mu_r = 0.1 d, scatter 0.5; the silo module):
    # the floor fits K = 0.168 with a worst deviation of 34.3 % (rms 14.0 %); the walls'
    # friction over the column is mobilised to 42.6 % of mu_w at the last pour (82.5 % at
    # the sixth; the same fill without rolling resistance: 4.4 % and K = 0.090, worst 28 %)
    r = fill(8, per_pour=24, mu_r=0.1 * 0.005, scatter=0.5)
    assert np.all(r["unconverged"] == 0)
    assert np.allclose(r["m_app"] + r["wall_friction"], r["mass"], rtol=2e-2)
    mobilised = r["wall_friction"] / (0.5 * r["wall_normal"])
    assert 0.35 < mobilised[-1] < 0.5 and np.max(mobilised) > 0.75
    f = fit_janssen(r["mass"], r["m_app"], rho=r["rho"], width=r["width"], mu_wall=0.5)
    assert 0.14 < f["K"] < 0.2 and 0.3 < f["max_deviation"] < 0.4
