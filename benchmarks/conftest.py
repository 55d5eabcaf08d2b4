"""pytest options of the regression benchmarks (``benchmarks/test_regression.py``)."""

import json

import pytest

from moreau.analysis import regression as reg


def pytest_addoption(parser):
    parser.addoption("--update-baselines", action="store_true",
                     help="write the measured errors and time ratios to benchmarks/baselines.json")
    parser.addoption("--strict-time", action="store_true",
                     help="fail (not only flag) a case whose time ratio grew by more than 1.5x")
    parser.addoption("--regression-report", default=None, metavar="PATH",
                     help="also write the per-case errors, ratios and flags as JSON to PATH")


class _Session:
    def __init__(self, config):
        self.config = config
        self.results = {}


@pytest.fixture(scope="session")
def regression_session(request):
    s = _Session(request.config)
    yield s
    flagged = []
    for key, r in s.results.items():
        # each case carries its own baseline, timed just before and after it
        r["time_ratio"] = r["time_s"] / r["calibration_s"]
        base = r.get("baseline_time_ratio")
        r["slowdown"], r["flagged"] = reg.time_ratio_flag(r["time_ratio"], base)
        if r["flagged"]:
            flagged.append(f"{key}: {r['slowdown']:.2f}x slower than its baseline")
    lines = []
    for key, r in sorted(s.results.items()):
        sl = f"{r['slowdown']:.2f}x" if r["slowdown"] is not None else "  new"
        lines.append(f"{key:<34} {r['time_s'] * 1e3:9.2f} ms  error {r['error']:.2e}  "
                     f"{sl}{'  FLAGGED' if r['flagged'] else ''}")
    lines.append(f"{len(flagged)} time regression(s) over {reg.TIME_FACTOR}x")
    request.config._moreau_regression_lines = lines
    path = request.config.getoption("--regression-report")
    if path:
        with open(path, "w") as fh:
            json.dump({"cases": s.results}, fh, indent=1)
    if request.config.getoption("--update-baselines") and s.results:
        try:
            cases = reg.load_baselines()
        except FileNotFoundError:
            cases = {}
        for key, r in s.results.items():
            cases[key] = {"error": r["error"], "trajectory_error": r["trajectory_error"],
                          "time_ratio": r["time_ratio"]}
        reg.save_baselines(cases)
    if request.config.getoption("--strict-time") and flagged:
        pytest.fail("time regressions: " + "; ".join(flagged), pytrace=False)


def pytest_terminal_summary(terminalreporter, config):
    lines = getattr(config, "_moreau_regression_lines", None)
    if lines:
        terminalreporter.write_sep("-", "regression: time ratio (to a fixed workload timed in "
                                        "the same run) against the stored one")
        for line in lines:
            terminalreporter.write_line(line)
