"""Log every numba compile of every Python process, for profiling the test suite's cold start.

Not part of the package: put this folder first on ``PYTHONPATH`` and name a log folder::

    PYTHONPATH=benchmarks/ci_profile MOREAU_COMPILE_LOG=/tmp/clog bash .ci/run
    python benchmarks/ci_profile/summarize.py /tmp/clog

Python imports ``sitecustomize`` at start-up, so the xdist workers and the
processes the tests start (README commands, notebooks) are all logged. One JSON
line per compile (a disk-cache load is not a compile), written at once into
``<pid>.jsonl``: the function, its argument types, wall and CPU seconds, the
nesting depth and the test running (``PYTEST_CURRENT_TEST``, which child
processes inherit). A wait of more than 50 ms for an exclusive ``fcntl.flock``
(the compile lock of :mod:`moreau.integrators._loops`: another worker compiles
the same kernel) is logged as a line with ``"lock_wait"`` seconds: wall time
that worker spent idle.
"""

import json
import os
import sys
import time

LOG_DIR = os.environ.get("MOREAU_COMPILE_LOG")

if LOG_DIR:
    from numba.core import event

    class CompileLog(event.Listener):
        def __init__(self):
            self.started = []

        def on_start(self, ev):
            self.started.append((time.perf_counter(), time.process_time()))

        def on_end(self, ev):
            wall0, cpu0 = self.started.pop()
            data = ev.data or {}
            py = getattr(data.get("dispatcher"), "py_func", None)
            rec = {"pid": os.getpid(), "test": os.environ.get("PYTEST_CURRENT_TEST", ""),
                   "argv": " ".join(sys.argv[:4])[:200],
                   "fn": f"{getattr(py, '__module__', '?')}:{getattr(py, '__qualname__', '?')}",
                   "args": str(data.get("args"))[:300], "wall": time.perf_counter() - wall0,
                   "cpu": time.process_time() - cpu0, "depth": len(self.started),
                   "t": time.time()}
            with open(os.path.join(LOG_DIR, f"{os.getpid()}.jsonl"), "a") as fh:
                fh.write(json.dumps(rec) + "\n")

    event.register("numba:compile", CompileLog())

    import fcntl

    _flock = fcntl.flock

    def _timed_flock(fd, op):
        if not op & fcntl.LOCK_EX or op & fcntl.LOCK_NB:
            return _flock(fd, op)
        t0 = time.perf_counter()
        out = _flock(fd, op)
        wait = time.perf_counter() - t0
        if wait > 0.05:
            rec = {"pid": os.getpid(), "test": os.environ.get("PYTEST_CURRENT_TEST", ""),
                   "lock": getattr(fd, "name", str(fd))[-120:], "lock_wait": wait,
                   "t": time.time()}
            with open(os.path.join(LOG_DIR, f"{os.getpid()}.jsonl"), "a") as fh:
                fh.write(json.dumps(rec) + "\n")
        return out

    fcntl.flock = _timed_flock
