"""Issue 21: bench_lcp.py without quantecon says the peer is missing and writes no numba cache."""

import pathlib
import runpy
import sys

BENCH = pathlib.Path(__file__).resolve().parents[1] / "benchmarks" / "bench_lcp.py"


def test_bench_lcp_names_a_missing_peer_and_caches_nothing_on_disk(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "quantecon", None)  # as if quantecon were not installed
    monkeypatch.setitem(sys.modules, "quantecon.optimize", None)
    mod = runpy.run_path(str(BENCH), run_name="bench_lcp_under_test")
    out = capsys.readouterr().out
    assert "quantecon is not installed: its column is skipped (pip install quantecon)" in out
    assert "quantecon" not in [name for name, _ in mod["solvers"]()]
    # compiled in memory only: numba's disk cache would land in benchmarks/__pycache__
    assert type(mod["_kernel_loop"]._cache).__name__ == "NullCache"
