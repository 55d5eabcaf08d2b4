"""Timing helpers shared by the benchmarks: medians over repeats, in-process baselines."""

import statistics
import time

import numpy as np


def median_time(fn, repeat=21, warmup=2):
    """Median wall time of ``fn()`` over ``repeat`` runs, after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def calibration():
    """A fixed numpy workload; timings divided by it are comparable across machines."""
    a = np.random.default_rng(0).standard_normal((120, 120))

    def work():
        for _ in range(20):
            np.linalg.solve(a, a[:, 0])

    return median_time(work, repeat=31)
