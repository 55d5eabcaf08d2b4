"""Regression suite: accuracy and run time of every scheme on every scene (pytest-benchmark).

Run the full suite (about a minute; documented in docs/benchmarks.md)::

    python -m pytest benchmarks/test_regression.py -n 0

Each case (:data:`moreau.analysis.regression.CASES`) is timed by
pytest-benchmark (median over its rounds); its errors are measured once and
must not be worse than the stored baselines (``benchmarks/baselines.json``).
A run time whose ratio to a fixed workload timed around it in the same run exceeds
the median of this machine's recorded ratios by more than 1.5x is flagged in
the summary (``--strict-time`` makes it fail); a machine without a history
is not compared (its noise: :mod:`moreau.analysis.regression`).
``--update-baselines`` stores the current errors and adds the time ratios to
this machine's history; ``--regression-report PATH`` writes them as JSON. The normal test suite
checks the accuracy of a quick subset (``tests/test_regression_baselines.py``).
"""

import pytest

from moreau.analysis import regression as reg

BASELINES = reg.load_baselines()


@pytest.mark.parametrize("key", list(reg.CASES))
def test_case(key, benchmark, regression_session):
    fn = reg.runner(key)
    fn()   # compile and warm up outside the timing
    # the time baseline, measured around the case so that machine load hits both alike
    cal = reg.calibration_time(7)
    # slow cases (the forced-QP path) get a few rounds only
    benchmark.pedantic(fn, rounds=3 if "qp" in key else 7, iterations=1, warmup_rounds=0)
    cal = 0.5 * (cal + reg.calibration_time(7))
    m = reg.measure(key)
    base = BASELINES.get(key, {})
    regression_session.results[key] = dict(m, time_s=benchmark.stats.stats.median,
                                           calibration_s=cal)
    benchmark.extra_info.update(m)
    if not regression_session.config.getoption("--update-baselines"):
        assert base, f"no baseline for {key}: run with --update-baselines"
        problems = reg.check_accuracy(m, base)
        assert not problems, f"{key}: " + "; ".join(problems)
