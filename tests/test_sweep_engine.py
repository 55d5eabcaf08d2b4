"""The sweep engine: disk cache, resume after an interrupt, failure status, Dask path."""

import math
import pickle
from dataclasses import asdict

import pytest

from moreau.analysis import engine
from moreau.analysis.engine import ED_REFERENCE, Scheme, check_output_dir, run_points
from moreau.errors import InputError
from moreau.scenes.friction_drive import PAPER_DEFAULTS

P = asdict(PAPER_DEFAULTS)
POINTS = [(P, 20.0), (P, 185.0), (P, 2000.0), (P, 5000.0)]


def test_cache_hits_give_the_same_rows(tmp_path):
    rows1, st1 = run_points(POINTS, cache_dir=tmp_path, n_jobs=1)
    assert st1 == {"cached": 0, "computed": 4}
    assert [r["mode"] for r in rows1] == ["NS", "NP", "NP", "NP"]
    # the 185 Hz value of the event-driven reference (tests/friction_drive)
    assert rows1[1]["displacement_per_period_m"] == pytest.approx(-6.639079e-6, rel=1e-6)
    rows2, st2 = run_points(POINTS, cache_dir=tmp_path, n_jobs=1)
    assert st2 == {"cached": 4, "computed": 0}
    assert rows2 == rows1
    # another scheme is another key
    _, st3 = run_points(POINTS[:1], Scheme.moreau_jean(1.0, 500), cache_dir=tmp_path, n_jobs=1)
    assert st3["computed"] == 1


def test_interrupted_run_resumes_without_recomputing(tmp_path, monkeypatch):
    calls = {"n": 0}
    real = engine._steady

    def steady(*a, **kw):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(*a, **kw)

    monkeypatch.setattr(engine, "_steady", steady)
    with pytest.raises(KeyboardInterrupt):
        run_points(POINTS, cache_dir=tmp_path, n_jobs=1)
    monkeypatch.setattr(engine, "_steady", real)
    rows, st = run_points(POINTS, cache_dir=tmp_path, n_jobs=1)
    assert st == {"cached": 2, "computed": 2}
    assert all(r["status"] == "ok" for r in rows)


def test_failing_point_becomes_a_status(monkeypatch):
    real = engine._steady

    def steady(params, frequency, scheme, **kw):
        if frequency == 2000.0:
            raise RuntimeError("numerical trouble\n on two lines")
        return real(params, frequency, scheme, **kw)

    monkeypatch.setattr(engine, "_steady", steady)
    pts = POINTS[:3] + [(asdict(PAPER_DEFAULTS.with_(phi0=1.5)), 185.0)]
    rows, _ = run_points(pts, checks=(Scheme.moreau_jean(1.0, 400),), n_jobs=1)
    assert [r["status"] for r in rows[:2]] == ["ok", "ok"]
    assert rows[2]["status"] == "RuntimeError: numerical trouble on two lines"
    assert math.isnan(rows[2]["displacement_per_period_m"]) and rows[2]["mode"] == ""
    assert rows[3]["status"].startswith("PainleveError")
    assert rows[3]["mj_theta1_status"].startswith("PainleveError")
    # the cross-check's relative error is measured against the reference
    r = rows[1]
    ref = r["displacement_per_period_m"]
    assert r["mj_theta1_relative_error"] == pytest.approx(
        (r["mj_theta1_displacement_per_period_m"] - ref) / abs(ref))
    assert abs(r["mj_theta1_relative_error"]) < 2e-2


def test_dask_local_cluster_shares_the_cache(tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        rows_d, st = run_points(POINTS[:3], cache_dir=tmp_path, scheduler=cluster.scheduler_address)
    assert st["computed"] == 3
    rows_l, st_l = run_points(POINTS[:3], cache_dir=tmp_path, n_jobs=1)
    assert st_l == {"cached": 3, "computed": 0}
    assert rows_l == rows_d


def test_scheme_settings_are_checked():
    with pytest.raises(InputError, match="`theta` must be in"):
        Scheme.moreau_jean(0.3, 1000)
    with pytest.raises(InputError, match="`theta` is not an option of scheme 'event-driven'"):
        Scheme("event-driven", theta=0.5)
    with pytest.raises(InputError, match="`method` must be one of .*'moreau-jean'"):
        Scheme("rk4")
    with pytest.raises(InputError, match="`steps_per_period` applies only to time-stepping"):
        Scheme("compliant-rk45", steps_per_period=100)
    with pytest.raises(InputError, match="`theta` is not an option of scheme 'compliant-rk45'"):
        Scheme("compliant-rk45", theta=1.0)
    # a setting the scheme does not take is refused when the settings are made, not in a worker
    with pytest.raises(InputError, match="`stiffnes` is not an option of scheme 'compliant-rk45'"):
        Scheme("compliant-rk45", options={"stiffnes": 1e6})
    with pytest.raises(InputError, match="`steps_per_period` must be an integer >= 8"):
        Scheme.moreau_jean(1.0, 7)
    assert ED_REFERENCE.label == "ed" and Scheme.moreau_jean(0.5, 100).label == "mj_theta0.5"
    assert Scheme("compliant-radau", options={"stiffness": 1e5}).label == \
        "compliant-radau_stiffness100000"
    # pickling (the workers get their settings this way) keeps every field
    s = Scheme("compliant-rk45", rtol=1e-6, options={"stiffness": 1e6})
    assert pickle.loads(pickle.dumps(s)) == s


def test_output_folder_is_checked_before_work(tmp_path, capsys, monkeypatch):
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    with pytest.raises(InputError, match="is not writable"):
        check_output_dir(blocker / "out")
    from moreau import cli

    def no_work(*a, **k):
        raise AssertionError("work started before the output folder was checked")

    monkeypatch.setattr(engine, "run_points", no_work)
    rc = cli.main(["reproduce", "--out", str(blocker / "out"), "--quick", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "`--out` folder" in err and "not writable" in err


def test_runaway_rotor_is_a_status_not_a_number(monkeypatch):
    # seen in the atlas at 2.2 kHz, mu = 0.88 (mode P) and phi0 = 1.44 (!PF): the shooting
    # "converged" on a rotor moving 1e9 m per period
    real = engine._steady

    def steady(params, frequency, scheme, **kw):
        scene, ss = real(params, frequency, scheme, **kw)
        ss.displacement_per_period = 1e9
        return scene, ss

    monkeypatch.setattr(engine, "_steady", steady)
    row = engine.evaluate_point(P, 2000.0, ED_REFERENCE, checks=(Scheme.moreau_jean(1.0, 400),))
    assert row["status"].startswith("ConvergenceError: no steady state: the rotor runs away")
    assert "runaway rotor" in row["status"] and "(mode 'NP'" in row["status"]
    assert row["mj_theta1_status"].startswith("ConvergenceError")
    assert math.isnan(row["displacement_per_period_m"])
    # with a load too (issue 16): a rotor always faster than the tip takes one-signed
    # friction, which balances a load only by coincidence; the reason names the stall
    scene, ss = steady(dict(P, load=1e-3), 2000.0, ED_REFERENCE)
    assert "past stall (load F_L = 0.001 N)" in engine._implausible(dict(P, load=1e-3), scene, ss)
    # a sound steady state passes: the rotor's average speed is below the tip's largest
    scene, ss = real(P, 2000.0, ED_REFERENCE)
    assert engine._implausible(P, scene, ss) is None
