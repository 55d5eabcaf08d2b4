"""The Siconos peer of bench_contact_solvers.py gets the problem right: on the struck chain
its NSGS returns the exact block result (so W, the interleaving and q reach Siconos as meant).

Skipped where the system interpreter has no Siconos with scipy (the peer's requirements);
under ``-m slow`` (3.5 s, most of it Siconos's import).
"""

import json
import pathlib
import subprocess

import numpy as np
import pytest

from moreau.contact._sparse import chain_impact_problem, problem_residual, stacked_disks_problem

PEER = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "siconos_fc2d_peer.py"


def _peer_available():
    try:
        done = subprocess.run(["/usr/bin/python3", "-c", "import siconos.numerics, scipy.sparse"],
                              capture_output=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done.returncode == 0


@pytest.mark.slow
def test_peer_solves_the_chain_and_a_stack(tmp_path):
    if not _peer_available():
        pytest.skip("/usr/bin/python3 has no siconos with scipy")
    W, q, mu, r_exact = chain_impact_problem(10, e=1.0)
    Ws, qs, mus = stacked_disks_problem(2, 3, mu=0.5)
    for name, (A, b, m) in (("chain", (W, q, mu)), ("stack", (Ws, qs, mus))):
        np.savez(tmp_path / f"{name}.npz", indptr=A.indptr, indices=A.indices, data=A.data, q=b, mu=m)
    job = {"problems": [{"name": n, "file": str(tmp_path / f"{n}.npz")} for n in ("chain", "stack")],
           "runs": [{"tol": 1e-13, "max_iter": 100_000}], "rounds": 1, "budget": 1e-3,
           "out": str(tmp_path)}
    done = subprocess.run(["/usr/bin/python3", str(PEER)], input=json.dumps(job), text=True,
                          capture_output=True, timeout=300)
    answer = json.loads(done.stdout.strip().splitlines()[-1])
    assert answer["available"], answer
    chain, stack = answer["results"]
    assert chain["info"] == 0 and stack["info"] == 0
    r = np.load(chain["r_file"])
    assert np.max(np.abs(r - r_exact)) <= 1e-8
    assert problem_residual(Ws, qs, mus, np.load(stack["r_file"]))[0] <= 1e-10
