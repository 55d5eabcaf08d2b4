"""A several-contact run's first call compiles Lemke's step in a child process beside the loop.

:meth:`moreau.integrators._loops.SharedRunner._kernels_aside` starts a child
that compiles the kernels a shared loop takes as arguments into numba's disk
cache, under the compile lock, while the parent compiles the loop; the parent
then takes the lock and loads them. These tests hold each piece to what it
must do: the child's entry writes a cache entry the parent loads, the
decision leaves the child out where it cannot help, a child still running is
killed and reaped, and (``-m slow``: two cold compiles, about 22 CPU s) a cold
first call through the child gives the arrays of a run in this process.
"""

import inspect
import io
import json
import os
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from moreau.integrators import _loops
from moreau.model.registry import make_scene

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

PROBE = textwrap.dedent("""
    from numba import njit
    from numba.core import types

    @njit(cache=True)
    def kern(x):
        return x + 1.0

    SHARED_INDIRECT = {"kern": (types.float64(types.float64), None, None, None)}
""")


def test_the_child_s_entry_leaves_machine_code_the_parent_loads(tmp_path, monkeypatch):
    (tmp_path / "aside_probe.py").write_text(PROBE)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.pathsep.join(
        [str(tmp_path), ROOT, os.environ.get("PYTHONPATH", "")]))
    code = ("import sys\nfrom moreau.integrators._loops import compile_indirect\n"
            "compile_indirect(sys.argv[1])")
    out = subprocess.run([sys.executable, "-c", code, "aside_probe"], capture_output=True,
                         text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    check = ("import aside_probe as p\nfrom moreau import _jit_cache\n"
             "before = _jit_cache.has_cached_code(p.kern)\n"
             "p.kern.compile(p.SHARED_INDIRECT['kern'][0])\n"
             "print(before, sum(p.kern.stats.cache_hits.values()), p.kern(2.0))")
    out = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True, env=env,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "1", "3.0"]


def test_no_child_where_it_cannot_help(monkeypatch):
    from moreau.integrators._contact_step import LCP_STEP_SIGNATURE, _lcp_step
    scene = make_scene("bidirectional-drive")
    runner = _loops.SharedRunner(scene.compiled_model(), _loops._mj_kernels.mj_loop)
    started = []
    monkeypatch.setattr(_loops.subprocess, "Popen", lambda *a, **k: started.append(a))
    names = list(inspect.signature(_loops._mj_kernels.mj_loop).parameters)
    args = [0.0] * len(names)
    args[names.index("lcp_ctl")] = _loops._mj_kernels.new_lcp_control(2)
    # as in a fresh process, whatever the tests before compiled here; each case below
    # departs from the favourable state in one condition only
    monkeypatch.setattr(_lcp_step, "overloads", {})
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: False)
    monkeypatch.setattr(_loops, "_spare_cpus", lambda: 1)
    # one CPU: the child would only take turns with this process
    monkeypatch.setattr(_loops, "_spare_cpus", lambda: 0)
    assert runner._kernels_aside(args, False) is None
    monkeypatch.setattr(_loops, "_spare_cpus", lambda: 1)
    # an embedded interpreter without an executable to start a child with
    executable = sys.executable
    monkeypatch.setattr(_loops.sys, "executable", "")
    assert runner._kernels_aside(args, False) is None
    monkeypatch.setattr(_loops.sys, "executable", executable)
    # the loop is compiled or on disk: no compile to overlap
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: True)
    assert runner._kernels_aside(args, False) is None
    # the kernel is on disk
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: disp is _lcp_step)
    assert runner._kernels_aside(args, False) is None
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: False)
    # the kernel is compiled in this process already
    monkeypatch.setattr(_lcp_step, "overloads", {LCP_STEP_SIGNATURE.args: None})
    assert runner._kernels_aside(args, False) is None
    monkeypatch.setattr(_lcp_step, "overloads", {})
    # no cache folder that the child could write to (numba's cache turned off): no lock
    from numba.core.caching import NullCache
    cache = _lcp_step._cache
    monkeypatch.setattr(_lcp_step, "_cache", NullCache())
    assert runner._kernels_aside(args, False) is None
    monkeypatch.setattr(_lcp_step, "_cache", cache)
    # another process's child compiles them already (a sweep's workers starting together):
    # this one waits on the compile lock instead of starting a second child
    monkeypatch.setattr(_loops._jit_cache, "try_lock", lambda disp, purpose: None)
    assert runner._kernels_aside(args, False) is None
    assert started == []
    # and with every condition as it should be, one child, holding the lock
    lock = io.StringIO()
    monkeypatch.setattr(_loops._jit_cache, "try_lock", lambda disp, purpose: lock)
    child = _FakeChild()
    monkeypatch.setattr(_loops.subprocess, "Popen",
                        lambda cmd, **kw: started.append(cmd) or child)
    assert runner._kernels_aside(args, False) is child
    assert started[0][-1] == "moreau.integrators._mj_kernels"
    assert child.moreau_aside_lock is lock
    _loops._end_aside(child)
    assert lock.closed


class _FakeChild:
    def poll(self):
        return 0

    def wait(self):
        return 0


def test_a_child_still_running_is_killed_and_reaped_and_its_lock_released(tmp_path):
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    child.moreau_aside_lock = held = open(tmp_path / "lock", "a")
    t0 = time.monotonic()
    _loops._end_aside(child)
    assert child.returncode is not None and child.returncode < 0
    assert time.monotonic() - t0 < 30
    assert held.closed
    _loops._end_aside(None)     # no child: nothing to do


def test_the_aside_lock_is_had_by_one_holder_at_a_time():
    from moreau.integrators._contact_step import _lcp_step
    first = _loops._jit_cache.try_lock(_lcp_step, "aside-probe")
    if first is None:
        pytest.skip("no writable cache folder or no fcntl: no lock to be had")
    try:
        assert _loops._jit_cache.try_lock(_lcp_step, "aside-probe") is None
    finally:
        first.close()
    again = _loops._jit_cache.try_lock(_lcp_step, "aside-probe")
    assert again is not None
    again.close()


FIRST_CALL = textwrap.dedent("""
    import json, logging, sys
    import numpy as np
    logging.basicConfig(level=logging.INFO, stream=sys.stderr)
    from moreau.integrators import simulate
    from moreau.integrators import _contact_step
    from moreau.model.registry import make_scene
    sc = make_scene("bidirectional-drive")
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 0.5), q0, v0, "moreau-jean", h=2e-3, fast=True)
    hits = sum(_contact_step._lcp_step.stats.cache_hits.values())
    print(json.dumps({"hits": hits, "q": res.q.tolist(), "pivots": res.stats["pivots"]}))
""")


@pytest.mark.slow
def test_a_cold_first_call_loads_lemke_from_the_child_and_gives_the_same_bits(tmp_path):
    if _loops._spare_cpus() < 1:
        pytest.skip("one CPU: no child is started")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               MOREAU_PLANAR_CACHE=str(tmp_path / "planar"),
               PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", FIRST_CALL], capture_output=True, text=True,
                         env=env, timeout=900)
    assert out.returncode == 0, out.stderr
    assert "alongside, in another process" in out.stderr
    got = json.loads(out.stdout.strip().splitlines()[-1])
    # the parent loaded Lemke's step from the cache the child wrote
    assert got["hits"] == 1 and got["pivots"] > 0
    sc = make_scene("bidirectional-drive")
    q0, v0 = sc.initial_state()
    from moreau.integrators import simulate
    here = simulate(sc, (0.0, 0.5), q0, v0, "moreau-jean", h=2e-3, fast=True)
    np.testing.assert_array_equal(np.array(got["q"]), here.q)
