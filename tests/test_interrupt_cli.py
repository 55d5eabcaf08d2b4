"""Issue 21: Ctrl-C during a long command ends with one line saying what was kept and how to resume."""

import os
import signal
import subprocess
import sys
import time

from moreau.analysis import engine
from moreau.cli import main


def test_an_interrupt_says_what_was_kept_and_a_rerun_resumes(tmp_path, capsys, monkeypatch):
    real = engine._checked_steady
    calls = {"n": 0}

    def stop_at_fourth(*a, **k):
        # the sweep's 5 neighbours are two continued segments (3 and 2 points, one worker);
        # the cache keeps whole segments: call 4 is the first point of the second
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return real(*a, **k)

    argv = ["sweep", "frequency", "20", "40", "--points", "5", "--out", str(tmp_path), "--jobs",
            "1", "--quiet", "--no-plot"]
    monkeypatch.setattr(engine, "_checked_steady", stop_at_fourth)
    assert main(argv) == 130
    err = capsys.readouterr().err
    assert err.strip() == (f"moreau: interrupted: sweep frequency: 3 of 5 points finished, kept in "
                           f"{tmp_path / 'cache'}; run the same command again to resume")
    assert not list(tmp_path.glob("*.csv"))
    monkeypatch.setattr(engine, "_checked_steady", real)
    assert main(argv) == 0
    assert "(5 points: 2 computed, 3 from the cache)" in capsys.readouterr().out


def test_ctrl_c_on_a_parallel_run_leaves_no_traceback_and_no_worker(tmp_path):
    # a real SIGINT to the whole process group, as a terminal's Ctrl-C sends it
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen([sys.executable, "-m", "moreau", "sweep", "frequency", "10", "12500",
                          "--points", "4000", "--scale", "log", "--jobs", "2", "--out", str(tmp_path),
                          "--no-plot"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=env, start_new_session=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    cache = tmp_path / "cache"
    # interrupt once the workers have finished some points
    while time.monotonic() < deadline and p.poll() is None and \
            sum(1 for _ in cache.rglob("output.pkl")) < 5:
        time.sleep(0.2)
    os.killpg(p.pid, signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 130
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.startswith("moreau:")]
    assert len(lines) == 1 and lines[0].startswith("moreau: interrupted: sweep frequency: ")
    assert lines[0].endswith(f"of 4000 points finished, kept in {cache}; run the same command "
                             "again to resume")
    left = None
    for _ in range(50):  # the resource trackers end when they see the parent gone
        left = subprocess.run(["ps", "-o", "pid=,cmd=", "-g", str(p.pid)], capture_output=True,
                              text=True).stdout
        if not left.strip():
            break
        time.sleep(0.1)
    assert left.strip() == ""


def _interrupt_when(monkeypatch, stop):
    # Ctrl-C in the middle of a point's steady state, where `stop(params, frequency)` says
    real = engine._checked_steady
    calls = {"n": 0}

    def steady(params, frequency, *a, **k):
        calls["n"] += 1
        if stop(calls["n"], params, frequency):
            raise KeyboardInterrupt
        return real(params, frequency, *a, **k)

    monkeypatch.setattr(engine, "_checked_steady", steady)
    return real


def _one_line(err):
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    return lines[0]


def test_ctrl_c_on_reproduce_says_what_was_kept(tmp_path, capsys, monkeypatch):
    # every point runs the reference and two Moreau-Jean cross-checks: call 7 is point 3's first
    _interrupt_when(monkeypatch, lambda n, p, f: n == 7)
    argv = ["reproduce", "--quick", "--jobs", "1", "--quiet", "--out", str(tmp_path)]
    assert main(argv) == 130
    line = _one_line(capsys.readouterr().err)
    assert line == (f"moreau: interrupted: reproduce: 2 of 60 points finished, kept in "
                    f"{tmp_path / 'cache'}; run the same command again to resume")
    # the two finished points are the cache's entries, and no table claims to be complete
    assert sum(1 for _ in (tmp_path / "cache").rglob("output.pkl")) == 2
    assert not list((tmp_path / "data").glob("*.csv"))


def test_ctrl_c_on_the_scene_s_own_atlas_says_what_was_kept(tmp_path, capsys, monkeypatch):
    # the first point of the second line of constant frequency
    _interrupt_when(monkeypatch, lambda n, p, f: f > 30.0)
    argv = ["atlas", "--plane", "f-mu", "--fmin", "20", "--fmax", "40", "--f-points", "2",
            "--y-points", "3", "--jobs", "1", "--quiet", "--no-plot", "--out", str(tmp_path)]
    assert main(argv) == 130
    line = _one_line(capsys.readouterr().err)
    assert line == (f"moreau: interrupted: atlas f-mu: 3 of 6 points finished, kept in "
                    f"{tmp_path / 'cache'}; run the same command again to resume")
    assert not list(tmp_path.glob("*.csv"))


def test_ctrl_c_on_an_atlas_says_what_was_kept_and_a_rerun_resumes(tmp_path, capsys,
                                                                     monkeypatch):
    # the first point of the second grid line (mu = 0.2)
    real = _interrupt_when(monkeypatch, lambda n, p, f: p["mu"] > 0.15)
    argv = ["atlas", "--x", "frequency", "20", "40", "--x-points", "3", "--y", "mu", "0.1",
            "0.2", "--y-points", "2", "--jobs", "1", "--quiet", "--no-plot", "--out",
            str(tmp_path)]
    assert main(argv) == 130
    line = _one_line(capsys.readouterr().err)
    assert line == (f"moreau: interrupted: atlas frequency-mu: 3 of 6 points finished, kept in "
                    f"{tmp_path / 'cache'}; run the same command again to resume")
    monkeypatch.setattr(engine, "_checked_steady", real)
    assert main(argv) == 0
    assert "(6 points: 3 computed, 3 from the cache)" in capsys.readouterr().out


def test_ctrl_c_while_reproduce_draws_says_the_tables_are_written(tmp_path, capsys, monkeypatch):
    from moreau.studies.paper import reproduce

    real_grids = reproduce.study_grids

    def two_points_each(params=None, quick=False):
        # the quick studies cut to two points each: the points stage takes seconds
        return {name: (par, values[:2], f, extra)
                for name, (par, values, f, extra) in real_grids(params, quick).items()}

    def ctrl_c(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(reproduce, "study_grids", two_points_each)
    monkeypatch.setattr(reproduce, "sweep_figure", ctrl_c)
    argv = ["reproduce", "--quick", "--jobs", "1", "--quiet", "--out", str(tmp_path)]
    assert main(argv) == 130
    line = _one_line(capsys.readouterr().err)
    assert line == (f"moreau: interrupted: reproduce (tables written to {tmp_path / 'data'}, "
                    f"figures unfinished): 14 of 14 points finished, kept in "
                    f"{tmp_path / 'cache'}; run the same command again to resume")
    assert len(list((tmp_path / "data").glob("*.csv"))) == 7


def test_ctrl_c_inside_a_batch_run_stops_the_batch_and_keeps_its_rows():
    # moreau compare --stress went on to its next case after Ctrl-C: simulate() returned the
    # interrupted run as status -4 and the catalogue continued; collect_rows (compare's and
    # the catalogue's loop) now lets the interrupt through and keeps the finished rows
    from moreau.analysis.compare import collect_rows
    from moreau.integrators import simulate
    from moreau.scenes.bouncing_ball import BouncingBall

    class Interrupting(BouncingBall):
        def forces(self, q, v, t):
            if t > 0.05:
                raise KeyboardInterrupt
            return super().forces(q, v, t)

    ran = []

    def run(item):
        ran.append(item)
        scene = Interrupting() if item == "b" else BouncingBall()
        res = simulate(scene, (0.0, 0.1), [1.0], [0.0], "moreau-jean", h=0.01, fast=False)
        return [{"item": item, "status": res.status}]

    rows = []
    assert collect_rows(["a", "b", "c"], run, rows) is True
    assert ran == ["a", "b"] and rows == [{"item": "a", "status": 0}]
    # a lone simulate still returns what it had, with the interrupted status
    res = simulate(Interrupting(), (0.0, 0.1), [1.0], [0.0], "moreau-jean", h=0.01, fast=False)
    assert res.status == -4 and res.t[-1] > 0.0


def test_ctrl_c_on_the_stress_catalogue_keeps_its_cells_and_a_rerun_resumes(tmp_path, capsys,
                                                                            monkeypatch):
    # moreau compare --stress ran > 35 min and kept nothing when interrupted: every finished
    # (case, scheme) cell is now kept in OUT/cache as it finishes, and a rerun reads it
    import json

    import moreau.studies.paper.stress as st
    monkeypatch.setattr(st, "CASES", {k: st.CASES[k] for k in ("mu-zero", "painleve-mu1.2")})
    real = st._guard
    computed = []

    def counted(stop_at=None):
        def guard(case, scheme, fn):
            # every computed cell of these cases runs through _guard once
            computed.append((case, scheme))
            if len(computed) == stop_at:
                raise KeyboardInterrupt
            return real(case, scheme, fn)
        return guard

    def argv(out):
        return ["compare", "--stress", "--quick", "--schemes", "event-driven,mj-1,mj-1/2",
                "--quiet", "--no-plot", "--json", "--out", str(out)]

    # Ctrl-C inside the second case, after its reference: the cells finished so far are kept
    monkeypatch.setattr(st, "_guard", counted(stop_at=5))
    assert main(argv(tmp_path / "a")) == 130
    line = _one_line(capsys.readouterr().err)
    assert line == (f"moreau: interrupted: stress catalogue: 4 of 6 cells finished, kept in "
                    f"{tmp_path / 'a' / 'cache'}; run the same command again to resume")
    assert not list((tmp_path / "a").glob("stress.*"))
    # the rerun computes the two missing cells only and reads the four others
    computed.clear()
    monkeypatch.setattr(st, "_guard", counted())
    assert main(argv(tmp_path / "a")) == 0
    resumed = json.loads(capsys.readouterr().out)
    assert computed == [("painleve-mu1.2", "mj-1"), ("painleve-mu1.2", "mj-1/2")]
    assert resumed["cells"]["computed"] == 2 and resumed["cells"]["cached"] == 4
    assert not resumed["interrupted"]
    # the resumed table is an uninterrupted run's (the run times aside)
    computed.clear()
    assert main(argv(tmp_path / "b")) == 0
    whole = json.loads(capsys.readouterr().out)
    assert len(computed) == 6

    def cells(rep):
        return [{k: v for k, v in r.items() if k != "time_s"} for r in rep["rows"]]

    assert cells(resumed) == cells(whole) and len(whole["rows"]) == 6
    assert (tmp_path / "a" / "stress.csv").read_text().count("\n") == 7
