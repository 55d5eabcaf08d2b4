"""Issue 34: SIGINT and SIGTERM stop every long command within about a second, with one line.

Each test starts a real ``moreau`` process, waits until it has spent a few seconds of CPU
time (the imports take about one: the command is then inside its computation), sends the
signal and checks the exit status (128 + the signal), the single line on stderr and what
was kept. Before, ``simulate`` turned the interrupt into a failed run (status -4) and the
command went on: ``steady --scene flexible-rod-drive`` ran 98 s after a SIGINT,
``characteristic`` ignored SIGTERM for minutes.
"""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

#: seconds of CPU time of the process before the signal: inside the computation
BUSY = 2.5
#: seconds from the signal to the end of the process (a second, with room for a busy host)
STOP_WITHIN = 10.0


def _cpu_seconds(pid):
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _signal_when_busy(argv, signum, cwd):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    # the command as a terminal starts it: Ctrl-C at its default (a test worker of the suite
    # may run with SIGINT ignored, which a child inherits and a command rightly keeps)
    p = subprocess.Popen([sys.executable, "-m", "moreau", *argv], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env, cwd=cwd,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 300
        while p.poll() is None and _cpu_seconds(p.pid) < BUSY and time.monotonic() < deadline:
            time.sleep(0.05)
        assert p.poll() is None, "the command ended before it could be interrupted"
        sent = time.monotonic()
        p.send_signal(signum)
        out, err = p.communicate(timeout=60)
        took = time.monotonic() - sent
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    return p.returncode, lines[0], took


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigint_stops_a_long_steady_state(tmp_path):
    # the flexible rod's no-load orbit takes about 35 s of CPU
    rc, line, took = _signal_when_busy(["steady", "--scene", "flexible-rod-drive"],
                                       signal.SIGINT, tmp_path)
    assert rc == 130 and line == "moreau: interrupted" and took < STOP_WITHIN


@pytest.mark.slow  # the same in process, interrupted by a stub: test_cli_edges.py
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigterm_stops_a_characteristic_and_keeps_its_finished_loads_as_partial(tmp_path):
    # 5000 grid loads, a steady state each: minutes
    rc, line, took = _signal_when_busy(["characteristic", "--points", "5000", "--out",
                                        str(tmp_path), "--no-plot"],
                                       signal.SIGTERM, tmp_path)
    assert rc == 143 and took < STOP_WITHIN
    stem = tmp_path / "characteristic_friction-drive_185Hz_event-driven"
    table = stem.with_name(stem.name + ".partial.csv")
    assert line == ("moreau: terminated (SIGTERM): characteristic: "
                    f"{len(table.read_text().splitlines()) - 1} loads finished, kept in {table}")
    side = json.loads(stem.with_name(stem.name + ".partial.json").read_text())
    assert side["partial"] is True and side["loads_finished"] >= 1
    # nothing under the names of a finished characteristic
    assert not stem.with_name(stem.name + ".csv").exists()
    assert not stem.with_name(stem.name + ".json").exists()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigterm_on_a_run_keeps_the_history_under_partial_names(tmp_path):
    # 1e5 drive periods: minutes of the event-driven walk
    rc, line, took = _signal_when_busy(["run", "--periods", "1e5", "--out", str(tmp_path),
                                        "--no-plot", "--quiet"], signal.SIGTERM, tmp_path)
    assert rc == 143 and took < STOP_WITHIN
    stem = tmp_path / "history_friction-drive_event-driven"
    table = stem.with_name(stem.name + ".partial.csv")
    rows = table.read_text().splitlines()
    assert line.startswith("moreau: terminated (SIGTERM): run: stopped at t = ")
    assert line.endswith(f"; the partial history ({len(rows) - 1} samples) is in {table}")
    side = json.loads(stem.with_name(stem.name + ".partial.json").read_text())
    assert side["partial"] is True and side["status"] == -4 and side["samples"] == len(rows) - 1
    assert not list(tmp_path.glob("*event-driven.csv")) and not list(
        tmp_path.glob("*event-driven.json"))
    # the kept samples end where the run stopped, before the requested end
    last = float(rows[-1].split(",")[0])
    assert 0.0 < last < 1e5 / 185.0


def test_an_interrupt_dropped_inside_a_ctypes_callback_is_sent_again():
    # CPython prints and drops an exception raised in a ctypes callback (numba's compiler
    # calls back into Python while it compiles): the command must still stop
    from types import SimpleNamespace

    from moreau.cli import _stop_on_sigterm

    previous, seen = _stop_on_sigterm()
    try:
        # SIGTERM: its handler is always the command's (SIGINT's only where it is not ignored)
        seen["signal"] = signal.SIGTERM
        with pytest.raises(KeyboardInterrupt):
            sys.unraisablehook(SimpleNamespace(exc_value=KeyboardInterrupt(), exc_type=KeyboardInterrupt,
                                               exc_traceback=None, err_msg=None, object=None))
            time.sleep(5.0)   # the signal sent again ends this wait
        assert seen["resend"] is not None
    finally:
        for signum, handler in previous.items():
            if signum == "unraisablehook":
                sys.unraisablehook = handler
            else:
                signal.signal(signum, handler)
