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
