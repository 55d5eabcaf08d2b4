"""Test-session settings, loaded by pytest before it collects anything.

The suite checks answers, not speed (speed is measured in ``benchmarks/``),
so numba compiles it at optimisation level 1 instead of 3: the compiles,
most of the suite's time, take about 30 % less (the Studer and
time-discontinuous Galerkin tests: 78 s at level 3, 55 s at level 1, on one
core). Level 1 changes no floating-point result: the kernels do not use
``fastmath``, so LLVM may not reorder their arithmetic at any level.
``moreau._jit_cache`` keys the disk cache on the level, so code compiled
here is never loaded by a run at the default level. A level set in the
environment wins.
"""

import os

os.environ.setdefault("NUMBA_OPT", "1")
