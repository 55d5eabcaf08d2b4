"""Per-call cost of the contact-problem object against the function it replaced (issues 35, 36).

Times, in one process and interleaved round by round, on the same problems:

* ``old``: ``solve_contact_problem`` as it was before the object (loaded
  from git at ``--old-rev``, default the commit before the package), the
  function the Python schemes called;
* ``shim``: today's ``moreau.integrators.contact_problem.solve_contact_problem``,
  a thin call into the object (what the schemes call now);
* ``object``: ``moreau.contact.solve(ContactProblem(...))``, the data checked
  and copied (what a user calls);
* ``trusted``: ``solve(ContactProblem.trusted(...))``, no checks.

Problems: one frictional contact (closed form), one frictionless contact,
two and four frictional contacts (the friction LCP by Lemke), and, for the
object alone, the mixed LCP: one and two bilateral rows with one and three
contacts (eliminated equality block, then closed form or Lemke).

Each figure is the median over rounds of the CPU time per call
(``time.process_time`` over a batch, so that other work on a shared machine
counts less); the impulses of old and new are checked equal bit for bit.
Nothing is written to disk.

Usage::

    python benchmarks/bench_contact_problem.py            # about a minute
    python benchmarks/bench_contact_problem.py --quick
"""

import argparse
import importlib.util
import os
import statistics
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, ROOT)

from moreau.contact import ContactProblem, solve  # noqa: E402
from moreau.integrators.contact_problem import (new_contact_counters,  # noqa: E402
                                                solve_contact_problem)

OLD_REV = "e09dfb8"


def load_old(rev):
    """The old module, compiled from git's copy inside the package (its relative imports hold)."""
    src = subprocess.run(["git", "-C", ROOT, "show", f"{rev}:moreau/integrators/contact_problem.py"],
                         check=True, capture_output=True, text=True).stdout
    spec = importlib.util.spec_from_loader("moreau.integrators._old_contact_problem", loader=None)
    mod = importlib.util.module_from_spec(spec)
    mod.__package__ = "moreau.integrators"
    exec(compile(src, f"{rev}:contact_problem.py", "exec"), mod.__dict__)
    return mod


def problem(rng, nc, frictional=True, n_eq=0):
    mu = np.full(nc, 0.5 if frictional else 0.0)
    m = n_eq + nc + (nc if frictional else 0)
    ndof = m + 1
    J = rng.standard_normal((m, ndof))
    W = J @ J.T / ndof
    u = rng.standard_normal(m)
    u[n_eq:n_eq + nc] = -np.abs(u[n_eq:n_eq + nc])        # every contact pressing
    return W, u, mu, np.zeros(nc), u[n_eq:n_eq + nc].copy(), n_eq


def per_call(fn, batch):
    t0 = time.process_time()
    for _ in range(batch):
        fn()
    return (time.process_time() - t0) / batch


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--old-rev", default=OLD_REV)
    args = ap.parse_args()
    rounds, batch = (5, 200) if args.quick else (15, 1000)
    old = load_old(args.old_rev)
    rng = np.random.default_rng(0)
    cases = [("1 contact, mu > 0", problem(rng, 1)), ("1 contact, mu = 0", problem(rng, 1, False)),
             ("2 contacts, mu > 0", problem(rng, 2)), ("4 contacts, mu > 0", problem(rng, 4)),
             ("1 joint row + 1 contact", problem(rng, 1, n_eq=1)),
             ("2 joint rows + 3 contacts", problem(rng, 3, n_eq=2))]
    print(f"{'problem':28s} {'old':>9s} {'shim':>9s} {'object':>9s} {'trusted':>9s}  "
          f"{'shim/old':>8s}  residual   (microseconds per call)")
    for name, (W, u, mu, e, vN, k) in cases:
        fns = {}
        if k == 0:
            p_old = old.solve_contact_problem(W, u, mu, e, vN)[0]
            p_new = solve_contact_problem(W, u, mu, e, vN)[0]
            assert np.array_equal(p_old, p_new), name
            c_old, c_new = old.new_contact_counters(), new_contact_counters()
            fns["old"] = lambda: old.solve_contact_problem(W, u, mu, e, vN, counters=c_old)
            fns["shim"] = lambda: solve_contact_problem(W, u, mu, e, vN, counters=c_new)
        fns["object"] = lambda: solve(ContactProblem(W, u, mu, e, vN, n_eq=k))
        fns["trusted"] = lambda: solve(ContactProblem.trusted(W, u, mu, e, vN, n_eq=k))
        sol = fns["object"]()
        assert sol.success, (name, sol.message)
        times = {key: [] for key in fns}
        for _ in range(rounds):
            for key, fn in fns.items():
                times[key].append(per_call(fn, batch))
        med = {key: statistics.median(v) * 1e6 for key, v in times.items()}
        cell = lambda key: f"{med[key]:9.1f}" if key in med else f"{'-':>9s}"  # noqa: E731
        ratio = f"{med['shim'] / med['old']:8.2f}" if "old" in med else f"{'-':>8s}"
        print(f"{name:28s} {cell('old')} {cell('shim')} {cell('object')} {cell('trusted')}  "
              f"{ratio}  {sol.residual:.1e}")


if __name__ == "__main__":
    main()
