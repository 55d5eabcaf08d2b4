"""Siconos's 2D NSGS (``SICONOS_FRICTION_2D_NSGS``) timed per solve: the peer of
``bench_contact_solvers.py``.

Runs under the system interpreter (Debian's ``python3-siconos``, which needs
``python3-scipy`` to take a sparse matrix), not the project's venv, and does
not import ``moreau``. Reads one JSON object from stdin::

    {"problems": [{"name": str, "file": "p.npz"}, ...],   # CSR W (indptr, indices, data), q, mu
     "runs": [{"tol": float, "max_iter": int}, ...],      # one timing per problem and run
     "rounds": int, "budget": seconds, "out": "dir",
     "repeat": int}                                       # optional: see below

and prints one JSON object ``{"available": true, "version": ..., "results":
[{"name", "run", "info", "iterations", "error", "seconds": [per round],
"r_file"}, ...]}`` or ``{"available": false, "reason": ...}``.

The problem is handed over as FCLib's local form: ``W`` (``2 nc x 2 nc``,
``[N, T]`` per contact), ``q``, ``mu``. ``W`` goes in as Siconos's sparse
block matrix (2 x 2 blocks, ``SBM_from_csparse``), the storage its
``fc2d_nsgs_sbm`` sweeps; it is built once per problem, outside the timing.
A solve starts from zero impulses, as ours do. ``tol`` is Siconos's own
tolerance (``SICONOS_DPARAM_TOL``), ``max_iter`` its sweep budget; with
``tol = 0`` the solve runs exactly ``max_iter`` sweeps (the per-sweep cost).
Each round times solves for about ``budget`` CPU seconds (``time.process_time``)
and reports the mean; the impulses of the last solve are saved for the caller,
which computes its own residual on them. With ``"repeat": k`` in the job, each
run instead times ``k`` single solves (after one untimed), CPU and wall time
each (``"seconds"`` and ``"wall"``). A run with ``"warm": true`` starts from
the problem file's ``r0`` (a time-stepping run's warm start) instead of zero.
"""

import json
import os
import sys
import time


def main():
    try:
        import numpy as np
        import scipy.sparse as sp
        import siconos
        import siconos.numerics as sn
    except ImportError as exc:  # pragma: no cover - depends on the system
        print(json.dumps({"available": False, "reason": f"siconos or scipy not importable: {exc}"}))
        return
    job = json.load(sys.stdin)
    rounds = int(job.get("rounds", 3))
    budget = float(job.get("budget", 0.2))
    out = []
    for prob in job["problems"]:
        data = np.load(prob["file"])
        n = data["q"].shape[0]
        nc = n // 2
        W = sp.csr_matrix((data["data"], data["indices"], data["indptr"]), shape=(n, n)).tocsc()
        W.indices = W.indices.astype(np.int64)
        W.indptr = W.indptr.astype(np.int64)
        q = np.ascontiguousarray(data["q"], dtype=float)
        mu = np.ascontiguousarray(data["mu"], dtype=float)
        sparse_problem = sn.FrictionContactProblem(2, nc, W, q, mu)
        info, sbm = sn.SBM_from_csparse(2, sn.NM_csc(sparse_problem.M))
        M = sn.NM_create(sn.NM_SPARSE_BLOCK, n, n)
        M.matrix1 = sbm
        problem = sn.FrictionContactProblem(2, nc, M, q, mu)
        for k, run in enumerate(job["runs"]):
            opts = sn.SolverOptions(sn.SICONOS_FRICTION_2D_NSGS)
            opts.dparam[sn.SICONOS_DPARAM_TOL] = float(run["tol"])
            opts.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(run["max_iter"])
            r = np.zeros(n)
            u = np.zeros(n)
            start = np.zeros(n)
            if run.get("warm"):
                start = np.ascontiguousarray(data["r0"], dtype=float)

            def solve():
                r[:] = start
                u[:] = 0.0
                return sn.fc2d_driver(problem, r, u, opts)

            t0 = time.perf_counter()
            status = solve()
            dt = time.perf_counter() - t0
            wall = []
            if "repeat" in job:
                samples = []
                for _ in range(int(job["repeat"])):
                    t0, c0 = time.perf_counter(), time.process_time()
                    status = solve()
                    samples.append(time.process_time() - c0)
                    wall.append(time.perf_counter() - t0)
            else:
                num = max(1, min(1000, int(budget / max(dt, 1e-7))))
                samples = [dt] if dt > 5 * budget else []
                for _ in range(0 if samples else rounds):
                    t0 = time.process_time()
                    for _ in range(num):
                        status = solve()
                    samples.append((time.process_time() - t0) / num)
            r_file = os.path.join(job["out"], f"siconos_{prob['name']}_{k}.npy")
            np.save(r_file, r)
            out.append({"name": prob["name"], "run": k, "info": int(status),
                        "iterations": int(opts.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
                        "error": float(opts.dparam[sn.SICONOS_DPARAM_RESIDU]),
                        "seconds": samples, "wall": wall, "r_file": r_file})
    version = getattr(siconos, "__version__", "unknown")
    print(json.dumps({"available": True, "version": version, "results": out}))


if __name__ == "__main__":
    main()
