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


# -- time history per machine (issue 21): bookkeeping on fabricated records, no timing --

HERE = {"cpu": "AMD EPYC", "cpu_count": 2, "architecture": "x86_64", "system": "Linux"}
THERE = {"cpu": "Apple M2", "cpu_count": 8, "architecture": "arm64", "system": "Darwin"}


def _history(*runs, info=HERE):
    h = {}
    for ratios in runs:
        h = reg.record_times(h, ratios, info, run_provenance={"time_utc": "t"})
    return h


def test_the_machine_id_leaves_out_the_host_name(monkeypatch):
    import platform
    import socket

    from moreau.provenance import machine

    monkeypatch.setattr(platform, "node", lambda: "host-a")
    monkeypatch.setattr(socket, "gethostname", lambda: "host-a")
    a = machine()
    monkeypatch.setattr(platform, "node", lambda: "host-b")
    monkeypatch.setattr(socket, "gethostname", lambda: "host-b")
    assert machine() == a and "host" not in reg.machine_id(a)
    assert reg.machine_id(HERE) != reg.machine_id(dict(HERE, cpu_count=4))


def test_times_are_flagged_against_the_same_machine_only():
    hist = _history({"k": 1.0}, {"k": 1.2}, {"k": 1.1})
    hist = reg.record_times(hist, {"k": 100.0}, THERE, run_provenance={})
    here, there = reg.machine_id(HERE), reg.machine_id(THERE)
    assert reg.reference_time_ratios(hist, here) == {"k": 1.1}
    # 1.7 / 1.1 > 1.5 here; the other machine's 100 is no reference
    t = reg.compare_times({"k": 1.7}, hist, here)
    assert t["flagged"] == ["k"] and t["compared"]
    assert t["flags"]["k"][0] == pytest.approx(1.7 / 1.1)
    assert t["note"] == ("1 time regression(s) over 1.5x the median of this machine's last 3 "
                         "runs (AMD EPYC / 2 cores / x86_64 / Linux)")
    assert reg.compare_times({"k": 1.6}, hist, here)["flagged"] == []


def test_a_machine_without_history_is_not_compared_with_another():
    hist = _history({"k": 1.0}, info=THERE)
    t = reg.compare_times({"k": 50.0}, hist, reg.machine_id(HERE))
    assert t["compared"] is False and t["flagged"] == [] and t["flags"] == {"k": (None, False)}
    assert t["note"].startswith("no time history for this machine (AMD EPYC / 2 cores / "
                                "x86_64 / Linux): times not compared (the history holds 1 "
                                "other machine)")


def test_the_reference_is_the_median_of_the_latest_runs():
    ratios = [{"k": r} for r in (9.0, 9.0, 1.0, 2.0, 3.0, 4.0, 5.0)]
    hist = _history(*ratios)
    # the last HISTORY_RUNS (5) runs: 1..5, median 3; the two old 9.0 do not count
    assert reg.HISTORY_RUNS == 5
    assert reg.reference_time_ratios(hist, reg.machine_id(HERE)) == {"k": 3.0}
    # a case new in the latest run has a reference of its own run only
    hist = reg.record_times(hist, {"k": 3.0, "new": 0.5}, HERE, run_provenance={})
    assert reg.reference_time_ratios(hist, reg.machine_id(HERE))["new"] == 0.5


def test_recording_keeps_the_latest_runs_and_their_provenance():
    hist = {}
    for r in range(25):
        hist = reg.record_times(hist, {"k": float(r)}, HERE, run_provenance={"n": r})
    runs = hist[reg.machine_id(HERE)]["runs"]
    assert len(runs) == reg.HISTORY_KEEP == 20
    assert runs[0] == {"provenance": {"n": 5}, "time_ratios": {"k": 5.0}}
    assert hist[reg.machine_id(HERE)]["machine"] == HERE
    # the given history is left as it was
    before = _history({"k": 1.0})
    reg.record_times(before, {"k": 2.0}, HERE, run_provenance={})
    assert len(before[reg.machine_id(HERE)]["runs"]) == 1


def test_a_recorded_run_carries_versions_threads_and_time():
    hist = reg.record_times({}, {"k": 1.0}, HERE)
    prov = hist[reg.machine_id(HERE)]["runs"][0]["provenance"]
    for key in ("moreau_version", "code_version", "numpy_version", "scipy_version",
                "numba_version", "threads", "cpu", "time_utc"):
        assert prov[key] is not None, key


def test_baselines_file_round_trip_drops_machineless_time_ratios(tmp_path):
    path = tmp_path / "baselines.json"
    hist = _history({"k": 1.0})
    # an older file's time_ratio has no machine: it is not carried over
    reg.save_baselines({"k": {"error": 1e-3, "trajectory_error": 2e-3, "time_ratio": 0.5}},
                       path, machines=hist)
    assert reg.load_baselines(path) == {"k": {"error": 1e-3, "trajectory_error": 2e-3}}
    assert reg.load_time_history(path) == hist
    assert reg.load_time_history(tmp_path / "none.json") == {}


def test_the_stored_baselines_carry_a_machine_history():
    machines = reg.load_time_history()
    assert machines, "benchmarks/baselines.json holds no time history"
    for mid, rec in machines.items():
        assert reg.machine_id(rec["machine"]) == mid
        for run in rec["runs"]:
            assert set(run["time_ratios"]) <= set(reg.CASES)
            assert run["provenance"]["cpu"] == rec["machine"]["cpu"]
    assert all("time_ratio" not in c for c in BASELINES.values())
