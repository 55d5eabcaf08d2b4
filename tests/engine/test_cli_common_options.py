"""Issue 21 (part): options several commands share are checked before any work, exit 2, one line."""

import pytest

from moreau.cli import main


@pytest.mark.parametrize("extra, message", [
    (["--jobs", "0"], "`--jobs` must be -1 (one per core) or a whole number from 1 to"),
    (["--jobs", "100000"], "`--jobs` must be -1"),
    (["--scheduler", "garbage://x"], "`--scheduler` must be a Dask scheduler address"),
    (["--cache", "/proc/x"], "`--cache` folder '/proc/x' is not writable"),
])
def test_shared_options_are_refused_before_work(extra, message, tmp_path, capsys):
    argv = ["sweep", "mu", "0.1", "0.2", "--points", "2", "--frequency", "185", "--out",
            str(tmp_path), "--quiet", "--no-plot"] + extra
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not list(tmp_path.glob("*.csv"))


def _no_work(monkeypatch):
    from moreau import cli
    from moreau.analysis import engine

    def no_work(*a, **k):
        raise AssertionError("work started before the folder was checked")

    monkeypatch.setattr(engine, "run_points", no_work)
    monkeypatch.setattr(cli, "run_history", no_work)


@pytest.mark.parametrize("command", [
    ["sweep", "mu", "0.1", "0.2", "--points", "2", "--frequency", "185"],
    ["atlas", "--quick"],
])
def test_a_cache_that_is_a_file_is_refused_in_one_line(command, tmp_path, capsys, monkeypatch):
    _no_work(monkeypatch)
    taken = tmp_path / "cache"
    taken.write_text("not a folder")
    argv = command + ["--out", str(tmp_path / "out"), "--cache", str(taken), "--quiet",
                      "--no-plot"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == (f"moreau: error: `--cache` folder {str(taken)!r} is not writable: it is a "
                   "file, not a folder\n")
    assert taken.read_text() == "not a folder"


@pytest.mark.parametrize("where, reason", [
    ("/proc/x", "No such file or directory"),
    ("FILE", "it is a file, not a folder"),
])
def test_run_refuses_an_out_it_cannot_write_in_one_line(where, reason, tmp_path, capsys,
                                                        monkeypatch):
    _no_work(monkeypatch)
    if where == "FILE":
        where = tmp_path / "taken"
        where.write_text("x")
    argv = ["run", "--frequency", "185", "--periods", "1", "--out", str(where), "--quiet"]
    assert main(argv) == 2
    assert capsys.readouterr().err == (f"moreau: error: `--out` folder {str(where)!r} is not "
                                       f"writable: {reason}\n")


def test_workers_are_capped_at_the_points_and_the_cores(monkeypatch):
    import os

    from moreau.analysis.engine import MAX_JOBS_PER_CORE, check_jobs

    monkeypatch.setattr(os, "cpu_count", lambda: 4)
    assert check_jobs(-1, 100) == 4 and check_jobs(-1, 2) == 2
    assert check_jobs(16, 100) == 16 == MAX_JOBS_PER_CORE * 4 and check_jobs(16, 3) == 3
    with pytest.raises(ValueError, match="from 1 to 16"):
        check_jobs(17, 100)


def test_reproduce_refuses_zero_jobs(tmp_path, capsys):
    assert main(["reproduce", "--quick", "--jobs", "0", "--out", str(tmp_path)]) == 2
    assert "`--jobs`" in capsys.readouterr().err


def test_run_refuses_an_out_folder_it_cannot_write(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["run", "--frequency", "185", "--out", str(f), "--quiet"]) == 2
    assert "`--out` folder" in capsys.readouterr().err


def test_wrong_types_in_the_api_are_refused_by_name():
    import math

    from moreau.analysis.steady_state import find_steady_state
    from moreau.errors import InputError
    from moreau.integrators import simulate
    from moreau.scenes.friction_drive import FrictionDrive

    with pytest.raises(InputError, match="`scene` must be a Scene instance, got str"):
        find_steady_state("hello")
    for bad in ("0.1", True):
        with pytest.raises(InputError, match="`mu` must be a real number"):
            FrictionDrive(mu=bad)
    sc = FrictionDrive()
    with pytest.raises(InputError, match="`h` must be a real number, got '0.01'"):
        simulate(sc, (0.0, 2 * math.pi), *sc.rest_state(), "moreau-jean", h="0.01")


def test_progress_bars_stay_out_of_logs(tmp_path):
    # stderr redirected to a file, as a log would be: no tqdm bar in it
    import subprocess
    import sys
    log = tmp_path / "log.txt"
    with open(log, "w") as fh:
        run = subprocess.run([sys.executable, "-m", "moreau", "compare", "--scene", "sliding-block",
                              "--quick", "--no-plot", "--out", str(tmp_path)], stdout=subprocess.PIPE,
                             stderr=fh, text=True)
    assert run.returncode == 0
    assert "it/s" not in log.read_text() and "run/s" not in log.read_text()
    assert "%|" not in log.read_text()


def _run_with_stderr(stderr, out):
    import subprocess
    import sys
    return subprocess.run([sys.executable, "-m", "moreau", "run", "--frequency", "185",
                           "--periods", "2", "--no-plot", "--out", str(out)],
                          stdout=subprocess.PIPE, stderr=stderr, text=True, timeout=600)


def test_run_shows_its_progress_bar_on_a_terminal_only(tmp_path):
    import fcntl
    import os
    import pty
    import struct
    import termios

    # stderr a terminal: the bar is drawn (so the check below can see one)
    leader, follower = pty.openpty()
    try:
        # a new pseudo-terminal is 0 columns wide, where tqdm draws nothing
        fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
        assert _run_with_stderr(follower, tmp_path / "tty").returncode == 0
        os.close(follower)
        drawn = b""
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:  # the terminal is closed once everything is read
                break
            if not chunk:
                break
            drawn += chunk
    finally:
        os.close(leader)
    assert b"%|" in drawn
    # stderr a file, as a log would be: no bar in it
    log = tmp_path / "log.txt"
    with open(log, "w") as fh:
        assert _run_with_stderr(fh, tmp_path / "log").returncode == 0
    assert "%|" not in log.read_text() and "t/s" not in log.read_text()


def _free_port():
    import socket
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_scheduler_that_does_not_answer_is_refused_before_work(tmp_path, capsys, monkeypatch):
    from moreau.analysis import engine

    monkeypatch.setattr(engine, "SCHEDULER_TIMEOUT_S", 1.0)
    addr = f"tcp://127.0.0.1:{_free_port()}"
    argv = ["sweep", "mu", "0.1", "0.2", "--points", "2", "--frequency", "185", "--out",
            str(tmp_path), "--quiet", "--no-plot", "--scheduler", addr]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"moreau: error: `--scheduler` {addr}: no Dask scheduler answered there "
                          "within 1 s") and err.count("\n") == 1
    assert not list(tmp_path.glob("*.csv"))


def test_a_scheduler_without_dask_names_the_extra(tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "distributed", None)  # as if Dask were not installed
    argv = ["reproduce", "--quick", "--scheduler", "tcp://127.0.0.1:8786", "--out", str(tmp_path)]
    assert main(argv) == 2
    assert capsys.readouterr().err == ("moreau: error: `--scheduler` needs Dask, which is not "
                                       "installed: pip install -e \".[dask]\"\n")
