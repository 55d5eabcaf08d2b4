"""Siconos's lexicographic Lemke timed per call: the peer of ``bench_lcp.py --siconos``.

Runs under the system interpreter (Debian ``python3-siconos``), not the
project's venv, and does not import ``moreau``. Reads one JSON object from
stdin, ``{"problems": [{"M": [[...]], "q": [...]}, ...], "rounds": R,
"budget": s, "max_iter": k}``, and prints one JSON object: ``{"available":
true, "version": ..., "results": [{"info": int, "z": [...], "times": [R
per-call CPU seconds]}, ...]}`` or ``{"available": false, "reason": ...}``.

A call is what a user with new data does: build ``sn.LCP(M, q)`` and run
``sn.lcp_lexicolemke`` (the options, ``SICONOS_LCP_LEMKE`` with the pivot
limit ``max_iter``, are built once). Each round times a batch of calls
lasting about ``budget`` CPU seconds (``time.process_time``) and reports the
mean; ``solve_s`` holds the same for the solve alone, the problem built
beforehand.
"""

import json
import sys
import time


def main():
    try:
        import numpy as np
        import siconos
        import siconos.numerics as sn
    except ImportError as exc:  # pragma: no cover - depends on the system
        print(json.dumps({"available": False, "reason": f"siconos not importable: {exc}"}))
        return
    job = json.load(sys.stdin)
    rounds = int(job.get("rounds", 5))
    budget = float(job.get("budget", 0.02))
    opts = sn.SolverOptions(sn.SICONOS_LCP_LEMKE)
    opts.iparam[0] = int(job.get("max_iter", 100000))
    clock = time.process_time
    out = []
    for prob in job["problems"]:
        M = np.ascontiguousarray(prob["M"], dtype=float)
        q = np.ascontiguousarray(prob["q"], dtype=float)
        n = len(q)
        z = np.zeros(n)
        w = np.zeros(n)

        def call():
            return sn.lcp_lexicolemke(sn.LCP(M, q), z, w, opts)

        p = sn.LCP(M, q)

        def solve_only():
            return sn.lcp_lexicolemke(p, z, w, opts)

        info = call()
        zres = z.tolist()
        times = {}
        for key, fn in (("times", call), ("solve_s", solve_only)):
            t0 = time.perf_counter()
            fn()
            dt = time.perf_counter() - t0
            num = max(1, min(20000, int(budget / max(dt, 1e-7))))
            samples = []
            for _ in range(rounds):
                t0 = clock()
                for _ in range(num):
                    fn()
                samples.append((clock() - t0) / num)
            times[key] = samples
        out.append({"info": int(info), "z": zres, **times})
    version = getattr(siconos, "__version__", "unknown")
    print(json.dumps({"available": True, "version": version, "results": out}))


if __name__ == "__main__":
    main()
