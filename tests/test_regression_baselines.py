"""Accuracy must not get worse than the stored baselines (quick subset of benchmarks/test_regression.py)."""

import pytest

from moreau.analysis import regression as reg
from moreau.errors import InputError

BASELINES = reg.load_baselines()


def test_every_case_has_a_baseline():
    assert set(reg.CASES) <= set(BASELINES)
    assert set(reg.QUICK) <= set(reg.CASES)


@pytest.mark.parametrize("key", reg.QUICK)
def test_accuracy_not_worse_than_baseline(key):
    m = reg.measure(key)
    assert reg.check_accuracy(m, BASELINES[key]) == []


def test_a_worse_error_is_caught():
    base = {"error": 1e-3, "trajectory_error": 2e-3}
    assert reg.check_accuracy({"error": 1.05e-3, "trajectory_error": 2e-3}, base) == []
    (msg,) = reg.check_accuracy({"error": 1.2e-3, "trajectory_error": 2e-3}, base)
    assert msg.startswith("error: 1.200e-03 is worse than the baseline 1.000e-03 (1.20x)")
    assert reg.check_accuracy({"error": float("nan"), "trajectory_error": None}, base)
    assert reg.time_ratio_flag(1.4, 1.0) == (1.4, False)
    assert reg.time_ratio_flag(1.6, 1.0)[1] is True
    with pytest.raises(InputError, match="`key`"):
        reg.measure("nope")
