"""Summarise a compile log written through ``benchmarks/ci_profile/sitecustomize.py``.

Prints the outermost compiles (a loop with the kernels it pulled in counts
once): their number and CPU seconds, how many were compiled in more than one
process (two xdist workers at once, or a child process before the cache was
written), and the tests that paid most.

    python benchmarks/ci_profile/summarize.py /tmp/clog [--all]
"""

import collections
import glob
import json
import os
import sys


def main(folder, show_all=False):
    recs = [json.loads(line) for path in glob.glob(os.path.join(folder, "*.jsonl"))
            for line in open(path)]
    waits = [r for r in recs if "lock_wait" in r]
    recs = [r for r in recs if "lock_wait" not in r]
    if waits:
        print(f"compile-lock waits: {len(waits)}, {sum(r['lock_wait'] for r in waits):.1f} s "
              f"of idle wall time (longest {max(r['lock_wait'] for r in waits):.1f} s)")
    top = [r for r in recs if r["depth"] == 0]
    print(f"compiles: {len(recs)} in all, {len(top)} outermost, "
          f"{sum(r['cpu'] for r in top):.0f} CPU s, {len({r['pid'] for r in recs})} processes")
    groups = collections.defaultdict(list)
    for r in top:
        groups[(r["fn"], r["args"])].append(r)
    again = {k: v for k, v in groups.items() if len({r["pid"] for r in v}) > 1}
    extra = sum(sum(r["cpu"] for r in v) - max(r["cpu"] for r in v) for v in again.values())
    print(f"distinct outermost: {len(groups)}; compiled in more than one process: "
          f"{len(again)} ({extra:.0f} CPU s beyond the first)")
    loops = [r for r in top if "_loop_" in r["fn"]]
    print(f"step loops compiled: {len(loops)} ({len({r['fn'] for r in loops})} distinct), "
          f"{sum(r['cpu'] for r in loops):.0f} CPU s")
    per_test = collections.Counter()
    for r in top:
        per_test[r["test"].split(" (")[0] or r["argv"]] += r["cpu"]
    print("\nCPU s of compiles per test:")
    for name, cpu in per_test.most_common(None if show_all else 25):
        print(f"{cpu:7.1f}  {name}")


if __name__ == "__main__":
    main(sys.argv[1], "--all" in sys.argv)
