"""pytest options of the regression benchmarks (``benchmarks/test_regression.py``)."""

import json

import pytest

from moreau.analysis import regression as reg
from moreau.provenance import provenance


def pytest_addoption(parser):
    parser.addoption("--update-baselines", action="store_true",
                     help="write the measured errors to benchmarks/baselines.json and add the "
                          "time ratios to this machine's history there")
    parser.addoption("--strict-time", action="store_true",
                     help="fail (not only flag) a case whose time ratio is more than 1.5x this "
                          "machine's reference")
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
    for r in s.results.values():
        # each case carries its own baseline, timed just before and after it
        r["time_ratio"] = r["time_s"] / r["calibration_s"]
    machines = reg.load_time_history()
    mid = reg.machine_id()
    # against this machine's own history only: another machine's ratios are no reference
    times = reg.compare_times({k: r["time_ratio"] for k, r in s.results.items()}, machines, mid)
    for key, r in s.results.items():
        r["slowdown"], r["flagged"] = times["flags"][key]
    lines = []
    for key, r in sorted(s.results.items()):
        sl = f"{r['slowdown']:.2f}x" if r["slowdown"] is not None else "    -"
        lines.append(f"{key:<34} {r['time_s'] * 1e3:9.2f} ms  ratio {r['time_ratio']:8.4f}  "
                     f"error {r['error']:.2e}  {sl}{'  FLAGGED' if r['flagged'] else ''}")
    lines.append(times["note"])
    request.config._moreau_regression_lines = lines
    path = request.config.getoption("--regression-report")
    if path:
        with open(path, "w") as fh:
            json.dump({"machine_id": mid, "provenance": provenance(), "cases": s.results}, fh,
                      indent=1)
    if request.config.getoption("--update-baselines") and s.results:
        try:
            cases = reg.load_baselines()
        except FileNotFoundError:
            cases = {}
        for key, r in s.results.items():
            cases[key] = {"error": r["error"], "trajectory_error": r["trajectory_error"]}
        machines = reg.record_times(machines, {k: r["time_ratio"] for k, r in s.results.items()})
        reg.save_baselines(cases, machines=machines)
    if request.config.getoption("--strict-time") and times["flagged"]:
        pytest.fail("time regressions: " + "; ".join(
            f"{k}: {s.results[k]['slowdown']:.2f}x slower than this machine's reference"
            for k in times["flagged"]), pytrace=False)


def pytest_terminal_summary(terminalreporter, config):
    lines = getattr(config, "_moreau_regression_lines", None)
    if lines:
        terminalreporter.write_sep("-", "regression: time ratio (to a fixed workload timed in "
                                        "the same run) against this machine's history")
        for line in lines:
            terminalreporter.write_line(line)
