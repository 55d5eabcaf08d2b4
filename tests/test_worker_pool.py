"""A parallel command ends its worker pool: no loky resource-tracker warning at exit."""

import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).parents[1]


def test_a_parallel_sweep_leaves_no_leaked_semaphores(tmp_path):
    # in a fresh process, as a user runs it: the warning is printed by loky's resource
    # tracker when the interpreter exits with the pool still alive
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_")}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    done = subprocess.run([sys.executable, "-W", "default", "-m", "moreau", "sweep", "mu", "0.1",
                           "0.2", "--points", "3", "--frequency", "185", "--jobs", "2", "--no-plot",
                           "--quiet", "--out", str(tmp_path / "out")],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert (tmp_path / "out" / "sweep_mu_185Hz.csv").is_file()
    for word in ("leaked", "resource_tracker", "Traceback"):
        assert word not in done.stderr, done.stderr[-2000:]


def test_the_pool_is_shut_down_after_a_parallel_run():
    from joblib.externals.loky import get_reusable_executor

    from moreau.analysis.engine import end_worker_pool

    pool = get_reusable_executor(max_workers=1)
    assert pool.submit(abs, -3).result() == 3
    end_worker_pool()
    # the next request gets a new pool: the old one is shut down
    assert get_reusable_executor(reuse=True) is not pool
    end_worker_pool()


# -- workers end with their parent on an error and on a time limit (issue 21) ---------------

import os  # noqa: E402
import signal  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402

import pytest  # noqa: E402

# a test dependency ([test] extra): a missing psutil must fail here, not skip the module
import psutil  # noqa: E402


def _workers(pid=None):
    """The loky worker processes under ``pid`` (this process by default)."""
    out = []
    for k in psutil.Process(pid).children(recursive=True):
        try:
            if "popen_loky" in " ".join(k.cmdline()):
                out.append(k)
        except psutil.NoSuchProcess:
            pass
    return out


def _alive(procs):
    alive = []
    for k in procs:
        try:
            if k.is_running() and k.status() != psutil.STATUS_ZOMBIE:
                alive.append(k)
        except psutil.NoSuchProcess:
            pass
    return alive


def _points(n):
    from dataclasses import asdict

    from moreau.scenes.friction_drive import PAPER_DEFAULTS
    return [(asdict(PAPER_DEFAULTS), float(f)) for f in (20.0 + 10 * k for k in range(n))]


def test_an_error_in_the_parent_ends_the_workers_at_once(tmp_path, monkeypatch, capfd):
    from moreau.analysis import engine

    real = engine._entry_matches
    calls = {"n": 0}

    def fails_on_the_second_row(*a):
        calls["n"] += 1
        if calls["n"] == 2:
            raise RuntimeError("a defect in the parent")
        return real(*a)

    monkeypatch.setattr(engine, "_entry_matches", fails_on_the_second_row)
    with pytest.raises(RuntimeError, match="a defect in the parent"):
        engine.run_points(_points(12), cache_dir=tmp_path / "cache", n_jobs=2)
    assert _workers() == []
    err = capfd.readouterr().err
    # joblib was told to stop: no task handed to the closed pool, reported one by one
    assert "exception calling callback" not in err and "Traceback" not in err


def test_a_killed_worker_ends_the_run_with_one_line_and_no_pool(tmp_path, capsys):
    from moreau.cli import main

    def kill_a_worker():
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            busy = _workers()
            if len(busy) == 2:
                os.kill(busy[0].pid, signal.SIGKILL)   # as the kernel's out-of-memory killer does
                return
            time.sleep(0.05)

    killer = threading.Thread(target=kill_a_worker, daemon=True)
    killer.start()
    argv = ["sweep", "frequency", "20", "2000", "--points", "60", "--jobs", "2", "--quiet",
            "--no-plot", "--out", str(tmp_path)]
    assert main(argv) == 1
    killer.join(timeout=5)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("moreau: failed: WorkerError: sweep frequency: a worker process ended "
                          "unexpectedly (exit codes {SIGKILL(-9)}; killed, or out of memory?): ")
    assert err.endswith(f"of 60 points finished, kept in {tmp_path / 'cache'}; run the same "
                        "command again to resume\n")
    assert _workers() == []


@pytest.mark.parametrize("how", ["kill PID", pytest.param("timeout", marks=pytest.mark.slow),
                                 "SIGKILL"])
def test_workers_end_with_a_parent_stopped_by_a_time_limit(how, tmp_path):
    # the engine has no time limit of its own: a run is ended from outside. `kill PID` and a
    # batch system's limit send SIGTERM to the parent; coreutils `timeout` sends it to the
    # whole process group; `timeout -s KILL` kills the parent outright. The workers' points
    # (the first one is the parent's) are underway when the signal comes
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_")}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    p = subprocess.Popen([sys.executable, "-m", "moreau", "sweep", "frequency", "10", "12500",
                          "--points", "4000", "--scale", "log", "--jobs", "2", "--quiet",
                          "--no-plot", "--out", str(tmp_path)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                         start_new_session=True)
    workers = []
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and p.poll() is None and (
                len(workers) < 2 or sum(1 for _ in (tmp_path / "cache").rglob("output.pkl")) < 2):
            workers = _workers(p.pid) if len(workers) < 2 else workers
            time.sleep(0.2)
        assert len(workers) == 2 and p.poll() is None
        if how == "kill PID":
            os.kill(p.pid, signal.SIGTERM)
        elif how == "timeout":
            os.killpg(p.pid, signal.SIGTERM)
        else:
            os.kill(p.pid, signal.SIGKILL)
        out, err = p.communicate(timeout=60)
        for _ in range(100):  # a killed parent's workers get their parent-death signal
            if not _alive(workers):
                break
            time.sleep(0.1)
        assert _alive(workers) == []
        if how == "SIGKILL":
            assert p.returncode == -signal.SIGKILL
            return
        assert p.returncode == 143 and "Traceback" not in err
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith(
            "moreau: terminated (SIGTERM): sweep frequency: ")
        assert lines[0].endswith(f"of 4000 points finished, kept in {tmp_path / 'cache'}; run "
                                 "the same command again to resume")
    finally:
        for k in _alive(workers) + ([psutil.Process(p.pid)] if p.poll() is None else []):
            k.kill()
