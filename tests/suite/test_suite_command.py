"""`moreau suite`: the table against each problem's reference, a broken scheme flagged, the page."""

import json
import math
import os
import re

import numpy as np
import pytest

from moreau.cli import main
from moreau.errors import InputError, Interrupted
from moreau.integrators.base import INTEGRATORS
from moreau.integrators.moreau_jean import MoreauJean
from moreau.suite.peers import siconos_available
from moreau.suite.problem import PENDING, crossing_time, get_problem, problem_names
from moreau.suite.report import write_report
from moreau.suite.run import run_suite


class _TooFast(MoreauJean):
    """A test double: Moreau–Jean started 5 % too fast (a scheme with a wrong answer)."""

    def __init__(self, scene, t0, q0, v0, t_bound, h=None):
        super().__init__(scene, t0, q0, np.asarray(v0, float) * 1.05 - 0.05, t_bound, h=h)


class _Crashes(MoreauJean):
    """A test double whose step raises an exception that is not a MoreauError (a bug)."""

    def __init__(self, scene, t0, q0, v0, t_bound, h=None):
        super().__init__(scene, t0, q0, v0, t_bound, h=h)

    def _step_impl(self):
        raise RuntimeError("the double's step is broken")


@pytest.fixture
def doubles(monkeypatch):
    monkeypatch.setitem(INTEGRATORS, "too-fast-double", _TooFast)
    monkeypatch.setitem(INTEGRATORS, "crashing-double", _Crashes)


def test_references_are_the_closed_forms():
    # independent of the problem modules: drop from 0.6 onto r = 0.1 (g = 1): V = 1, t1 = 1,
    # rebound 0.1 + (e V)^2 / 2, Zeno time t1 + 2 e V / (1 - e); block: v0^2 / (2 mu g), v0 / (mu g)
    ball = get_problem("bouncing-ball").reference()
    assert ball["first_impact_time"] == pytest.approx(math.sqrt(2 * 0.5), rel=1e-14)
    assert ball["rebound_height"] == pytest.approx(0.1 + 0.5 ** 2 / 2, rel=1e-14)
    assert ball["rest_time"] == pytest.approx(1.0 + 2 * 0.5 / 0.5, rel=1e-14)
    block = get_problem("sliding-block").reference()
    assert block["stopping_distance"] == pytest.approx(2.0 ** 2 / (2 * 0.5), rel=1e-14)
    assert block["stopping_time"] == pytest.approx((1 - 1e-3) * 2.0 / 0.5, rel=1e-14)


def test_subset_table_flags_and_page(tmp_path, doubles):
    schemes = ["moreau-jean", "too-fast-double", "crashing-double", "stick-slip-exact"]
    cache = tmp_path / "cells"
    rep = run_suite(problems=["bouncing-ball", "sliding-block"], schemes=schemes, quick=True,
                    cache_dir=str(cache), progress=False)
    rows = {(r["problem"], r["scheme"], r["setting"]): r for r in rep["rows"]}
    # Moreau-Jean at its finest quick step: every quantity within tolerance of the closed form
    for prob, finest in (("bouncing-ball", "N=4000"), ("sliding-block", "N=1000")):
        r = rows[(prob, "moreau-jean", finest)]
        ref = get_problem(prob).reference()
        scales = get_problem(prob).scales()
        assert r["outcome"] == "ok", r
        for q, v in ref.items():
            assert abs(r["values"][q] - v) / scales[q] <= get_problem(prob).tolerance
        # first order: ten times the steps, the first impact / the stop ten times closer
        coarse = rows[(prob, "moreau-jean", "N=400" if prob == "bouncing-ball" else "N=100")]
        q = "first_impact_time" if prob == "bouncing-ball" else "stopping_distance"
        assert coarse["errors"][q] == pytest.approx(10 * r["errors"][q], rel=0.05)
    # the broken doubles are flagged, each with its cause, and the suite went on
    for prob in ("bouncing-ball", "sliding-block"):
        fast = [r for k, r in rows.items() if k[:2] == (prob, "too-fast-double")]
        assert fast and all(r["outcome"] == "inaccurate" for r in fast)
        assert all("off by" in r["cause"] or "no value" in r["cause"] for r in fast)
        crash = [r for k, r in rows.items() if k[:2] == (prob, "crashing-double")]
        assert crash and all(r["outcome"] == "failed" for r in crash)
        assert all(r["cause"].startswith("unexpected RuntimeError: the double's step")
                   for r in crash)
        # a scene's own reference scheme refuses another scene by name
        (ref_row,) = [r for k, r in rows.items() if k[:2] == (prob, "stick-slip-exact")]
        assert ref_row["outcome"] == "refused" and "StickSlipMotor" in ref_row["cause"]
    # every cell was kept; a rerun reads them all back
    again = run_suite(problems=["bouncing-ball", "sliding-block"], schemes=schemes, quick=True,
                      cache_dir=str(cache), progress=False)
    assert again["cells"]["cached"] == again["cells"]["total"] == len(rep["rows"])
    assert [r["max_error"] for r in again["rows"]] == [r["max_error"] for r in rep["rows"]]
    # the page links every figure it wrote, and every link resolves
    paths = write_report(rep, str(tmp_path), settings={"quick": True}, animation_frames=2)
    page = (tmp_path / "index.md").read_text()
    links = set(re.findall(r"\]\(([^)]+)\)", page))
    figures = {p.name for p in tmp_path.glob("*.png")} | {p.name for p in tmp_path.glob("*.gif")}
    assert figures == {"overview.png", "wp_bouncing-ball.png", "wp_sliding-block.png",
                       "anim_bouncing-ball.gif", "anim_sliding-block.gif"}
    assert figures <= links
    assert all((tmp_path / link).exists() for link in links)
    for p in ("bouncing-ball", "sliding-block"):
        assert get_problem(p).source in page
    doc = json.loads((tmp_path / "suite.json").read_text())
    assert doc["overview"]["bouncing-ball"]["crashing-double"]["outcome"] == "failed"
    assert "provenance" in doc and paths["csv"].endswith("suite.csv")


def test_a_scheme_that_is_another_on_the_scene_is_run_once(tmp_path, monkeypatch):
    # event-driven on a scene without a reference of its own is event-driven-generic: the
    # suite runs it once and gives both columns its row, each kept, the copy saying whose it is
    import moreau.suite.run as run_mod
    ran = []
    real = run_mod.simulate
    monkeypatch.setattr(run_mod, "simulate", lambda *a, **k: ran.append(a[4]) or real(*a, **k))
    schemes = ["event-driven", "event-driven-generic", "moreau-jean"]
    rep = run_suite(problems=["sliding-block"], schemes=schemes, quick=True,
                    cache_dir=str(tmp_path), progress=False)
    assert "event-driven" not in ran and {"event-driven-generic", "moreau-jean"} <= set(ran)
    rows = {(r["scheme"], r["setting"]): r for r in rep["rows"]}
    copies = [k for k in rows if k[0] == "event-driven"]
    assert copies and len(rows) == len(rep["rows"])
    for _, label in copies:
        copy, run = rows[("event-driven", label)], rows[("event-driven-generic", label)]
        assert copy["cause"] == "the same run as event-driven-generic (the same scheme on this scene)"
        assert {k: v for k, v in copy.items() if k not in ("scheme", "cause")} == \
            {k: v for k, v in run.items() if k not in ("scheme", "cause")}
        assert (tmp_path / "sliding-block" / "event-driven" / f"{label}.json").exists()
    assert rep["cells"]["computed"] == len(rep["rows"])


def test_cli_refuses_before_work(tmp_path, capsys):
    assert main(["suite", "--problems", "no-such", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "`problems` must name problems of the suite" in err and "bouncing-ball" in err
    (tmp_path / "file").write_text("x")
    assert main(["suite", "--out", str(tmp_path / "file")]) == 2
    assert "is a file" in capsys.readouterr().err


def test_registry_and_pending():
    names = problem_names()
    assert {"bouncing-ball", "painleve-rod", "ball-chain", "friction-drive", "sliding-block",
            "sliding-box", "stick-slip-motor"} <= set(names)
    assert "rocking-block" in PENDING or "rocking-block" in names
    with pytest.raises(InputError, match="`problems` must name"):
        get_problem("nope")
    assert crossing_time([0.0, 1.0], [1.0, 2.0], 0.0) is None


@pytest.mark.slow
def test_worker_pool_gives_the_same_table(tmp_path):
    kw = dict(problems=["sliding-block", "painleve-rod"], schemes=["moreau-jean", "event-driven"],
              quick=True, progress=False)
    one = run_suite(cache_dir=str(tmp_path / "a"), n_jobs=1, **kw)
    two = run_suite(cache_dir=str(tmp_path / "b"), n_jobs=2, **kw)
    assert [(r["problem"], r["scheme"], r["setting"], r["outcome"], r["max_error"])
            for r in one["rows"]] == [(r["problem"], r["scheme"], r["setting"], r["outcome"],
                                       r["max_error"]) for r in two["rows"]]


def test_compare_to_history_flags_first(tmp_path, capsys):
    hist = tmp_path / "history.json"
    args = ["suite", "--quick", "--problems", "sliding-block", "--schemes", "moreau-jean",
            "--no-plot", "--quiet", "--compare-to", str(hist)]
    assert main(args + ["--out", str(tmp_path / "a")]) == 0
    assert "0 flag(s)" in capsys.readouterr().out
    doc = json.loads(hist.read_text())
    (entry,) = doc["machines"].values()
    cells = entry["suite_runs"][-1]["cells"]
    assert cells["sliding-block/moreau-jean/N=1000"]["outcome"] == "ok"
    # a history in which the coarse cell was ok with a tiny error: now its outcome changed
    # and its error grew above the tolerance
    cells["sliding-block/moreau-jean/N=100"].update(outcome="ok", max_error=1e-6)
    hist.write_text(json.dumps(doc))
    assert main(args + ["--out", str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out
    assert out.index("FLAG outcome: sliding-block/moreau-jean/N=100: outcome ok -> "
                     "inaccurate") < out.index("| problem |")
    assert "FLAG error: sliding-block/moreau-jean/N=100: error 1e-06 -> 0.015" in out
    page = (tmp_path / "b" / "index.md").read_text()
    assert page.index("## Flags against the history") < page.index("| problem |")
    assert len(json.loads(hist.read_text())["machines"][next(iter(doc["machines"]))][
        "suite_runs"]) == 2


class _Interrupts(MoreauJean):
    """A test double: its second run is interrupted (Ctrl-C) at its first step."""

    runs = 0

    def __init__(self, scene, t0, q0, v0, t_bound, h=None):
        super().__init__(scene, t0, q0, v0, t_bound, h=h)
        type(self).runs += 1
        self.stop = type(self).runs == 3       # the warm-up run, the first cell, the second

    def _step_impl(self):
        if self.stop:
            raise KeyboardInterrupt
        super()._step_impl()


def test_an_interrupted_suite_keeps_its_cells_and_resumes(tmp_path, monkeypatch):
    monkeypatch.setitem(INTEGRATORS, "interrupting-double", _Interrupts)
    kw = dict(problems=["sliding-block"], schemes=["interrupting-double"], quick=True,
              cache_dir=str(tmp_path), progress=False)
    with pytest.raises(Interrupted, match="suite: 1 of 2 cells finished"):
        run_suite(**kw)
    assert [p.name for p in tmp_path.rglob("*.json")] == ["N=100.json"]
    rep = run_suite(**kw)
    assert rep["cells"] == {"total": 2, "cached": 1, "computed": 1}
    assert [r["outcome"] for r in rep["rows"]] == ["inaccurate", "ok"]


@pytest.mark.slow
@pytest.mark.skipif(not siconos_available(), reason="Siconos is not installed (/usr/bin/python3)")
def test_siconos_peer_column_on_the_friction_drive(tmp_path):
    rep = run_suite(problems=["friction-drive", "sliding-block"],
                    schemes=["siconos:MoreauJeanOSI"], cache_dir=str(tmp_path), progress=False)
    fd, block = rep["rows"]
    # Siconos's Moreau-Jean (theta 1/2, 1000 steps) from the same periodic state: measured
    # 9.2e-4 from the event-driven displacement per period
    assert fd["outcome"] == "ok" and fd["max_error"] < 2e-3 and fd["steps"] == 1000
    assert block["outcome"] == "refused" and "states no Siconos model" in block["cause"]
