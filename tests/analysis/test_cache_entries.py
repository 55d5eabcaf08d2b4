"""Issue 16, part 7: a cache entry is checked against the inputs it was computed for."""

import logging
import shutil
from dataclasses import asdict

import pytest

from moreau.analysis.engine import ED_REFERENCE, run_points
from moreau.scenes.friction_drive import PAPER_DEFAULTS

POINTS = [(asdict(PAPER_DEFAULTS), 20.0), (asdict(PAPER_DEFAULTS.with_(mu=0.3)), 20.0)]


def entries(cache):
    return sorted(p.parent for p in cache.rglob("output.pkl"))


def test_an_entry_copied_from_another_point_is_recomputed(tmp_path, caplog):
    cache = tmp_path / "cache"
    rows, st = run_points(POINTS, ED_REFERENCE, cache_dir=cache, n_jobs=1)
    assert st == {"cached": 0, "computed": 2}
    assert rows[0]["displacement_per_period_m"] != rows[1]["displacement_per_period_m"]
    a, b = entries(cache)
    # give point b the (valid) entry of point a, as a careless copy would
    shutil.copy(a / "output.pkl", b / "output.pkl")
    with caplog.at_level(logging.WARNING, logger="moreau.analysis.engine"):
        again, st = run_points(POINTS, ED_REFERENCE, cache_dir=cache, n_jobs=1)
    assert st == {"cached": 1, "computed": 1}
    for r, s in zip(again, rows):
        assert r["displacement_per_period_m"] == s["displacement_per_period_m"]
        assert r["mode"] == s["mode"] and "_inputs" not in r
    assert "1 cache entry" in caplog.text and "other parameters" in caplog.text
    # the entry was put right: the next run takes both from the cache
    assert run_points(POINTS, ED_REFERENCE, cache_dir=cache, n_jobs=1)[1] == {"cached": 2,
                                                                              "computed": 0}


def test_a_garbage_entry_is_recomputed_with_one_line_and_a_true_count(tmp_path, caplog, capfd):
    cache = tmp_path / "cache"
    rows, _ = run_points(POINTS[:1], ED_REFERENCE, cache_dir=cache, n_jobs=1)
    (entry,) = entries(cache)
    (entry / "output.pkl").write_bytes(b"not a pickle")
    with caplog.at_level(logging.WARNING, logger="moreau.analysis.engine"):
        again, st = run_points(POINTS[:1], ED_REFERENCE, cache_dir=cache, n_jobs=1)
    assert st == {"cached": 0, "computed": 1}
    assert again[0]["displacement_per_period_m"] == rows[0]["displacement_per_period_m"]
    assert "could not be read" in caplog.text
    assert "Traceback" not in capfd.readouterr().err
