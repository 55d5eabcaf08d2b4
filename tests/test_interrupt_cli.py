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

    def stop_at_third(*a, **k):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(*a, **k)

    argv = ["sweep", "frequency", "20", "40", "--points", "5", "--out", str(tmp_path), "--jobs",
            "1", "--quiet", "--no-plot"]
    monkeypatch.setattr(engine, "_checked_steady", stop_at_third)
    assert main(argv) == 130
    err = capsys.readouterr().err
    assert err.strip() == (f"moreau: interrupted: sweep frequency: 2 of 5 points finished, kept in "
                           f"{tmp_path / 'cache'}; run the same command again to resume")
    assert not list(tmp_path.glob("*.csv"))
    monkeypatch.setattr(engine, "_checked_steady", real)
    assert main(argv) == 0
    assert "(5 points: 3 computed, 2 from the cache)" in capsys.readouterr().out


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
