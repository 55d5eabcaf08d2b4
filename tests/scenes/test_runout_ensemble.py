"""The column's runout over seeds (issue 38): the ensemble's bookkeeping and its refusals."""

import math

import numpy as np
import pytest
from scipy.stats import linregress

from moreau.errors import InputError
from moreau.studies.granular.runout import runout_ensemble, runout_summary


def _rows():
    # three seeds of four columns (two below a = 3, two above), made-up runouts; the measured
    # aspect ratios scatter about the aims as the real columns' do
    aims = [(1.0, 8.0), (2.0, 6.0), (4.0, 5.0), (8.0, 4.0)]
    aspect = {1.0: [1.2, 1.3, 1.25], 2.0: [2.5, 2.4, 2.6], 4.0: [4.7, 4.9, 4.6],
              8.0: [9.6, 9.8, 9.5]}
    runout = {1.0: [0.4, 0.6, 0.5], 2.0: [1.6, 1.5, 1.9], 4.0: [3.0, 3.4, 3.1],
              8.0: [5.2, 5.6, 5.0]}
    return [{"aim": a, "L0": L0, "seed": s, "aspect": aspect[a][s], "runout": runout[a][s]}
            for s in range(3) for a, L0 in aims]


def test_the_runout_summary_gives_each_columns_mean_and_spread_over_seeds():
    s = runout_summary(_rows())
    assert s["aim"].tolist() == [1.0, 2.0, 4.0, 8.0] and s["n"].tolist() == [3, 3, 3, 3]
    assert s["L0"].tolist() == [8.0, 6.0, 5.0, 4.0]
    assert np.allclose(s["runout"], [0.5, 5.0 / 3.0, 9.5 / 3.0, 15.8 / 3.0], rtol=1e-12)
    assert np.allclose(s["aspect"], [1.25, 2.5, 14.2 / 3.0, 28.9 / 3.0], rtol=1e-12)
    # sample standard deviations (n - 1): 0.4, 0.6, 0.5 -> 0.1; 3.0, 3.4, 3.1 -> sqrt(0.13/3)
    assert s["runout_std"][0] == pytest.approx(0.1, rel=1e-12)
    assert s["runout_std"][2] == pytest.approx(math.sqrt(0.13 / 3.0), rel=1e-12)
    assert np.allclose(s["runout_sem"], s["runout_std"] / math.sqrt(3.0), rtol=1e-12)
    # the tall branch on every run above a = 3: slope and its standard error as linregress's
    tall = [r for r in _rows() if r["aspect"] > 3.0]
    ref = linregress(np.log([r["aspect"] for r in tall]), np.log([r["runout"] for r in tall]))
    assert s["p"] == pytest.approx(ref.slope, rel=1e-10)
    assert s["p_se"] == pytest.approx(ref.stderr, rel=1e-10)
    assert s["c"] == pytest.approx(math.exp(ref.intercept), rel=1e-10)
    # the short branch through the origin: lambda = sum(a r) / sum(a^2), by hand
    short = [(r["aspect"], r["runout"]) for r in _rows() if r["aspect"] <= 3.0]
    a, y = np.array(short).T
    lam = a @ y / (a @ a)
    assert s["lambda"] == pytest.approx(lam, rel=1e-12)
    assert s["lambda_se"] == pytest.approx(
        math.sqrt(np.sum((y - lam * a) ** 2) / 5 / (a @ a)), rel=1e-12)


def test_a_single_seed_has_no_spread_and_too_few_runs_no_fit():
    rows = [r for r in _rows() if r["seed"] == 0]
    s = runout_summary(rows)
    assert np.all(np.isnan(s["runout_std"])) and s["n"].tolist() == [1, 1, 1, 1]
    # two runs above the split: a line through two points has no error estimate, so no fit
    assert s["p"] is None and s["p_se"] is None and s["lambda"] is not None


def test_the_runout_ensemble_refuses_bad_input_by_name_before_any_run():
    with pytest.raises(InputError, match="`seeds`"):
        runout_ensemble([(1.0, 8.0)], [])
    with pytest.raises(InputError, match="`seeds`"):
        runout_ensemble([(1.0, 8.0)], [0, 0])
    with pytest.raises(InputError, match="`seeds`"):
        runout_ensemble([(1.0, 8.0)], [-1])
    with pytest.raises(InputError, match="`seeds`"):
        runout_ensemble([(1.0, 8.0)], ["x"])
    with pytest.raises(InputError, match="`cases`"):
        runout_ensemble([], [0, 1])
    with pytest.raises(InputError, match="`a_split`"):
        runout_ensemble([(1.0, 8.0)], [0], a_split=0.0)
    with pytest.raises(InputError, match="`rows`"):
        runout_summary([])
    with pytest.raises(InputError, match="`rows`.*lacks runout"):
        runout_summary([{"aim": 1.0, "L0": 8.0, "aspect": 1.2}])
