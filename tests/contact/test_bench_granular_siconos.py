"""benchmarks/bench_granular_siconos.py compares correct answers on the problem a run solves.

On a box of 100 disks fallen 110 steps (about 100 contacts): the benchmark's
step problem is the one :func:`simulate_disks` solves (its next step's
velocities come out bit for bit), the problem survives our FCLib writer and
reader bit for bit, and our answer and Siconos's (skipped where
``/usr/bin/python3`` has no Siconos with scipy) meet the tolerance in our
recomputed residual.
"""

import argparse
import pathlib
import runpy

import numpy as np
import pytest

from moreau.contact._sparse import problem_residual
from moreau.integrators.granular import simulate_disks

BENCH = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "bench_granular_siconos.py"
TOL = 1e-8


@pytest.fixture(scope="module")
def bench():
    return runpy.run_path(str(BENCH), run_name="bench_granular_siconos_under_test")


@pytest.fixture(scope="module")
def fallen(bench):
    system, x = bench["box"](100)
    res = simulate_disks(system, x, np.zeros((100, 3)), 110, bench["H"], theta=1.0, tol=1e-6)
    return system, res


def test_step_problem_is_the_runs_and_round_trips_through_fclib(bench, fallen, tmp_path):
    system, res = fallen
    x, v = res.x[-1], res.v[-1]
    act, r = res.impulses
    W, q, mu, r0, (Hm, v_free) = bench["step_problem"](system, x, v, act.key, r.reshape(-1, 2))
    assert 80 <= mu.size <= 160 and np.any(r0)
    nxt = simulate_disks(system, x, v, 1, bench["H"], theta=1.0, tol=TOL, max_sweeps=20_000,
                         warm=res.impulses, phi0=res.phi[-1])
    sol, _ = bench["solve_ours"](W, q, mu, r0, TOL, 20_000)
    v1 = v_free + system.inv_mass * (Hm.T @ sol.r)
    assert nxt.steps["contacts"][-1] == mu.size
    assert np.array_equal(v1.reshape(-1, 3), nxt.v[-1])
    Wr, qr, mur, r0r = bench["round_trip"](W, q, mu, r0, tmp_path / "step.hdf5")
    for a, b in ((Wr.indptr, W.indptr), (Wr.indices, W.indices), (Wr.data, W.data), (qr, q),
                 (mur, mu), (r0r, r0)):
        assert np.array_equal(a, b)
    assert problem_residual(W, q, mu, sol.r)[0] <= TOL


def test_both_answers_meet_the_tolerance_in_our_residual(bench, fallen, tmp_path):
    system, res = fallen
    act, r = res.impulses
    W, q, mu, r0, _ = bench["step_problem"](system, res.x[-1], res.v[-1], act.key, r.reshape(-1, 2))
    args = argparse.Namespace(tol=TOL, budget=20_000, repeat=1)
    rows, reason = bench["run_siconos"]({"p": (W, q, mu, r0)}, args, str(tmp_path))
    if rows is None:
        if "not importable" in reason or "did not run" in reason:
            pytest.skip(f"/usr/bin/python3 has no Siconos with scipy: {reason}")
        pytest.fail(reason)
    for row in rows:
        assert row["info"] == 0, row
        # Siconos's own error and our residual differ in normalisation, not by orders
        assert row["residual"] <= 10 * row["its_tol"], row
    for start in ("cold", "warm"):
        ladder = [row for row in rows if row["start"] == start]
        # down the ladder until an answer meets TOL in our residual, and no further
        assert 1 <= len(ladder) <= len(bench["LADDER"])
        assert ladder[-1]["residual"] <= TOL
        assert all(row["residual"] > TOL for row in ladder[:-1])
