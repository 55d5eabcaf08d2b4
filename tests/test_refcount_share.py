"""benchmarks/refcount_share.py: its classification of perf samples, and what it refuses."""

import pathlib
import runpy

import pytest

BENCH = pathlib.Path(__file__).resolve().parents[1] / "benchmarks" / "refcount_share.py"


@pytest.fixture(scope="module")
def bench():
    return runpy.run_path(str(BENCH), run_name="refcount_share_under_test")


def test_samples_on_the_two_count_functions_and_in_the_allocator_are_told_apart(bench):
    nrt = {"NRT_incref": 0x1050, "NRT_decref": 0x1060}
    samples = [(0x1050, ""), (0x1059, ""), (0x1069, ""),       # the counts (entry .. +15)
               (0x1070, ""),                                   # past decref's span
               (0x2000, "NRT_MemInfo_alloc_aligned"), (0x3000, "free"),
               (0x4000, "__sincos_fma"), (0x4008, "")]
    got = bench["classify"](samples, nrt)
    assert got == {"refcount": 3 / 8, "allocation": 2 / 8, "samples": 8}
    assert bench["classify"]([], nrt) == {"refcount": 0.0, "allocation": 0.0, "samples": 0}


@pytest.mark.parametrize("argv, message", [
    (["--steps", "0"], "--steps: must be a positive integer, got '0'"),
    (["--repeats", "-2"], "--repeats: must be a positive integer, got '-2'"),
    (["--h", "0"], "--h must be > 0, got 0.0"),
])
def test_bad_arguments_are_refused_before_any_run(bench, capsys, argv, message):
    with pytest.raises(SystemExit):
        bench["main"](argv)
    assert message in capsys.readouterr().err


def test_without_perf_it_says_why_and_measures_nothing(bench, capsys, monkeypatch):
    monkeypatch.setattr(bench["shutil"], "which", lambda name: None)
    assert bench["main"](["--scenes", "bouncing-ball"]) == 1
    assert capsys.readouterr().out.strip() == "not measured: perf is not installed"
