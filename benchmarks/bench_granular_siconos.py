"""One granular step's 2D contact problem, 1e3 and 1e4 contacts: our NSGS against Siconos's NSGS.

Two problems, each the contact problem of one Moreau–Jean step of a run:

``pile-RxC``
    the triangular packing of ``bench_granular.py`` (unit disks, ``R``
    rows of ``C``, in a box, ``mu = 0.5``) at rest under gravity after ten
    steps: a settled, hyperstatic pile, whose warm start is nearly its answer;
``box-N``
    ``N`` disks of radii uniform in ``[0.4, 0.5]`` (mass proportional to
    the area, ``g = 1``) in a box (a rough floor and two walls, ``mu =
    0.5``), filled by :func:`moreau.model.granular.random_fill` (about twice
    as wide as tall) and let fall by
    :func:`moreau.integrators.granular.simulate_disks` (``theta = 1``, ``h =
    1e-2``, NSGS to ``1e-6``) for ``--fall`` steps: a pile still compacting.
    The state after those steps, with the last step's impulses, is kept in a
    temporary directory (never in the repository), so that a second run does
    not let it fall again.

The problem timed is the *next* step's, built as :func:`simulate_disks`
builds it (:func:`step_problem`: the broad phase, the active set, ``W = H
M^-1 H^T`` in CSR, ``q = H v_free`` with the impact law): FCLib's local 2D
problem ``(W, q, mu)``, with the warm start ``r0`` the run would use (the
last step's impulses, matched by pair).

Interchange. The problem is written by :func:`moreau.contact.fclib.write_fclib`
(``r0`` as FCLib's first guess) and read back by
:func:`~moreau.contact.fclib.read_fclib`; the round trip is checked bit for
bit and both solvers take the arrays as read. Siconos takes them as arrays:
Debian's ``python3-siconos`` (4.4) has no FCLib reader in
``siconos.numerics`` (it is built without FCLib) and the system interpreter
has no h5py. ``W`` reaches Siconos as its sparse block matrix (2 x 2 blocks),
through ``benchmarks/siconos_fc2d_peer.py`` under ``/usr/bin/python3``.

The solvers.

``ours``
    the path :func:`simulate_disks` takes: :func:`~moreau.contact.solvers.nsgs.solve_nsgs`
    (plain Gauss–Seidel, a full residual every 4 sweeps) from ``r0``, and
    from zero again when the warm start ends above ``tol``;
``siconos``
    ``SICONOS_FRICTION_2D_NSGS`` (``fc2d_driver`` on the sparse block
    matrix) from the same start, its own tolerance set to ``tol``, and
    then lower (``tol / 3``, ``/ 10``, ``/ 30``, ``/ 100``) until its answer
    meets ``tol`` in our residual (its error is not our residual):
    ``siconos @ equal`` is that run, at the largest of its tolerances whose
    answer has our residual at most ``tol``.

Every answer's residual is recomputed here with ONE measure, the natural map
of the De Saxcé complementarity over ``1 + ||q||``
(:func:`moreau.contact._sparse.problem_residual`, compensated sums), the one
our solvers report. Cold runs start from zero, warm runs from ``r0``. Times:
median over ``--repeat`` solves (after one untimed) of the CPU time
(``time.process_time``; the machine is shared) and of the wall time.

Run: ``python benchmarks/bench_granular_siconos.py [--quick] [--tol 1e-6]
[--problems pile-10x42,pile-10x420,box-850]``; prints the table, writes
nothing to the repository. The falling box at 1e4 contacts is
``--problems box-8000 --tol 1e-5`` (its fall takes about 20 minutes once):
plain NSGS stalls on that step's problem at a residual of 1.8e-6 (cold) to
4e-6 (warm) over 20 000 sweeps, so it is compared at 1e-5.
"""

import os

# one BLAS thread: every solver here, and Siconos, runs on one core
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from types import SimpleNamespace  # noqa: E402

import numpy as np  # noqa: E402

from moreau.contact._sparse import problem_residual  # noqa: E402
from moreau.contact.fclib import read_fclib, write_fclib  # noqa: E402
from moreau.contact.solvers.nsgs import solve_nsgs  # noqa: E402
from moreau.integrators.granular import simulate_disks  # noqa: E402
from moreau.model.granular import DiskSystem, HalfPlane, random_fill  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
PEER = os.path.join(HERE, "siconos_fc2d_peer.py")
H = 1e-2
#: Siconos's tolerance as a fraction of ours, largest first
LADDER = (1.0, 1 / 3, 1 / 10, 1 / 30, 1 / 100)
#: where the fallen piles are kept between runs (a temporary directory, never the repository)
CACHE = os.path.join(tempfile.gettempdir(), "moreau_bench_granular_siconos")


def box(n_disks, seed=1):
    """The box and the loose fill: ``(system, x)``, about twice as wide as tall."""
    width = 2.04 * math.sqrt(n_disks) + 0.01
    radii, x = random_fill(n_disks, width, 0.4, 0.5, seed=seed)
    walls = [HalfPlane((0.0, 0.0), (0.0, 1.0)), HalfPlane((0.0, 0.0), (1.0, 0.0)),
             HalfPlane((width, 0.0), (-1.0, 0.0))]
    return DiskSystem(radii, (radii / 0.45) ** 2, walls=walls, mu=0.5), x


def fallen(n_disks, steps, *, seed=1, cache=CACHE, log=print):
    """The box after ``steps`` steps from the fill: ``(system, x, v, keys, r)``.

    ``keys, r``: the last step's contacts (pair keys) and impulses, ``(nc, 2)``.
    Kept in ``cache`` (``None``: not kept); a fall kept for fewer steps is continued."""
    system, x = box(n_disks, seed)
    v = np.zeros((n_disks, 3))
    phi, warm = None, None
    done = 0
    path = None
    if cache is not None:
        path = os.path.join(cache, f"box_{n_disks}_{steps}_{seed}.npz")
        kept = [(int(f.split("_")[2]), f) for f in os.listdir(cache)
                if f.startswith(f"box_{n_disks}_") and f.endswith(f"_{seed}.npz")] \
            if os.path.isdir(cache) else []
        kept = [(k, f) for k, f in kept if k <= steps]
        if kept:
            done, name = max(kept)
            d = np.load(os.path.join(cache, name))
            if done == steps:
                return system, d["x"], d["v"], d["keys"], d["r"]
            # simulate_disks's warm start reads only the pair keys of the contact set
            x, v, warm = d["x"], d["v"], (SimpleNamespace(key=d["keys"]), d["r"])
    t0 = time.perf_counter()
    while done < steps:
        k = min(50, steps - done)
        res = simulate_disks(system, x, v, k, H, theta=1.0, tol=1e-6, max_sweeps=2000, phi0=phi,
                             warm=warm, t0=done * H)
        x, v, phi, warm = res.x[-1], res.v[-1], res.phi[-1], res.impulses
        done += k
        log(f"  falling {n_disks} disks: {done}/{steps} steps, {int(res.steps['contacts'][-1])} "
            f"contacts, {time.perf_counter() - t0:.0f} s", flush=True)
    keys, r = warm[0].key, warm[1].reshape(-1, 2)
    if path is not None:
        os.makedirs(cache, exist_ok=True)
        np.savez(path, x=x, v=v, keys=keys, r=r)
    return system, x, v, keys, r


def pile(rows, cols, warmup=10):
    """``bench_granular.py``'s packing after ``warmup`` steps: ``(system, x, v, keys, r)``."""
    spec = importlib.util.spec_from_file_location("_bench_granular",
                                                  os.path.join(HERE, "bench_granular.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    system, x = mod.packing(rows, cols)
    res = simulate_disks(system, x, np.zeros((system.n_disks, 3)), warmup, H, theta=1.0, tol=1e-6,
                         max_sweeps=2000)
    return system, res.x[-1], res.v[-1], res.impulses[0].key, res.impulses[1].reshape(-1, 2)


def step_problem(system, x, v, prev_keys, prev_r, h=H):
    """The contact problem of the step from ``(x, v)``, as :func:`simulate_disks` builds it.

    Returns ``W`` (CSR), ``q``, ``mu``, the warm start ``r0`` (the last
    step's impulses ``prev_r`` of the pairs ``prev_keys``, zero for a new
    pair), and ``(H, v_free)``, so that ``v_{k+1} = v_free + M^-1 H^T r``.
    """
    N = system.n_disks
    rmin = float(np.min(system.radii))
    margin = 2.0 * h * float(np.max(np.hypot(v[:, 0], v[:, 1]), initial=0.0)) + 0.05 * rmin
    cs = system.contacts(x, margin)
    vb = v[cs.b, :2]
    va = np.where((cs.a >= 0)[:, None], v[np.maximum(cs.a, 0), :2], 0.0)
    uN = np.einsum("ij,ij->i", cs.normal, vb - va)
    if system.n_walls:
        uN += system.contact_offsets(cs)[0::2]
    closed = prev_keys[prev_r[:, 0] > 0.0]
    ia = np.flatnonzero((cs.gap + 0.5 * h * uN <= 0.0) | np.isin(cs.key, closed))
    act = type(cs)(*(f[ia] for f in cs))
    v_free = v.ravel() + np.tile(np.array([system.gravity[0], system.gravity[1], 0.0]) * h, N)
    Hm = system.jacobian(act)
    W = system.delassus(Hm)
    q = Hm @ v_free + system.contact_offsets(act)
    q[0::2] += act.e * np.minimum(uN[ia], 0.0)
    r0 = np.zeros((ia.size, 2))
    if prev_keys.size:
        order = np.argsort(prev_keys)
        pos = np.minimum(np.searchsorted(prev_keys, act.key, sorter=order), prev_keys.size - 1)
        hit = prev_keys[order[pos]] == act.key
        r0[hit] = prev_r[order[pos[hit]]]
    return W, q, act.mu, r0.ravel(), (Hm, v_free)


def solve_ours(W, q, mu, r0, tol, budget):
    """:func:`simulate_disks`'s solve: NSGS from ``r0``, from zero again if that ends above ``tol``.

    Returns ``(IterativeResult, sweeps of both)``."""
    sol = solve_nsgs(W, q, mu, r0=r0, tol=tol, max_sweeps=budget, check_every=4)
    sweeps = sol.iterations
    if not sol.converged and r0 is not None and np.any(r0):
        cold = solve_nsgs(W, q, mu, tol=tol, max_sweeps=budget, check_every=4)
        sweeps += cold.iterations
        if cold.converged:
            sol = cold
    return sol, sweeps


def round_trip(W, q, mu, r0, path):
    """Write ``(W, q, mu)`` (``r0`` the first guess) to FCLib, read it back, check it bit for bit.

    Returns the problem as read: ``(W, q, mu, r0)``."""
    write_fclib(path, W, q, mu, title="granular box step", guesses=[(r0, W @ r0 + q)],
                description="moreau benchmarks/bench_granular_siconos.py")
    p = read_fclib(path)
    same = (p.spacedim == 2 and np.array_equal(p.W.indptr, W.indptr)
            and np.array_equal(p.W.indices, W.indices) and np.array_equal(p.W.data, W.data)
            and np.array_equal(p.q, q) and np.array_equal(p.mu, mu)
            and np.array_equal(p.guesses[0]["r"], r0))
    if not same:
        raise RuntimeError(f"the FCLib round trip of {path} changed the problem")
    return p.W, p.q, p.mu, p.guesses[0]["r"]


def timed(fn, repeat):
    """``(median CPU s, median wall s, last result)`` over ``repeat`` calls after one untimed."""
    out = fn()
    cpu, wall = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - t0)
    return statistics.median(cpu), statistics.median(wall), out


def _peer(job):
    """Run the peer on ``job``: ``(answer, None)`` or ``(None, why not)``."""
    try:
        proc = subprocess.run(["/usr/bin/python3", PEER], input=json.dumps(job), text=True,
                              capture_output=True, timeout=7200)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return None, f"peer did not run: {exc}"
    try:
        answer = json.loads(proc.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        return None, f"peer failed: {proc.stderr.strip()[-300:]}"
    if not answer.get("available"):
        return None, answer.get("reason")
    return answer, None


def run_siconos(problems, args, tmp):
    """Siconos's NSGS on ``problems`` ({name: (W, q, mu, r0)}), cold and warm, down the ladder.

    Each problem and start goes down :data:`LADDER` until an answer meets
    ``args.tol`` in our residual (one peer run a rung). Returns ``(rows,
    version)`` or ``(None, why not)``."""
    rows = []
    for name, (W, q, mu, r0) in problems.items():
        path = os.path.join(tmp, f"{name}.npz")
        np.savez(path, indptr=W.indptr, indices=W.indices, data=W.data, q=q, mu=mu, r0=r0)
        pending = [False, True]
        for f in LADDER:
            if not pending:
                break
            runs = [{"tol": args.tol * f, "max_iter": args.budget, "warm": w} for w in pending]
            answer, why = _peer({"problems": [{"name": name, "file": path}], "runs": runs,
                                 "repeat": args.repeat, "out": tmp})
            if answer is None:
                return None, why
            for res in answer["results"]:
                run = runs[res["run"]]
                ours = problem_residual(W, q, mu, np.load(res["r_file"]))[0]
                rows.append({"problem": name, "start": "warm" if run["warm"] else "cold",
                             "solver": "siconos", "its_tol": run["tol"],
                             "sweeps": res["iterations"], "cpu": statistics.median(res["seconds"]),
                             "wall": statistics.median(res["wall"]), "residual": ours,
                             "its_error": res["error"], "info": res["info"]})
                if ours <= args.tol:
                    pending.remove(run["warm"])
    try:
        version = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "python3-siconos"],
                                 capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        version = ""
    return rows, version or answer.get("version")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the 1e3-contact problems only")
    ap.add_argument("--no-siconos", action="store_true")
    ap.add_argument("--problems", default="pile-10x42,pile-10x420,box-850",
                    help="comma-separated: pile-RxC (bench_granular.py's packing at rest, R rows "
                         "of C disks) or box-N (N disks fallen --fall steps)")
    ap.add_argument("--fall", type=int, default=400,
                    help="steps the fill of a box falls before the step timed")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--budget", type=int, default=20_000, help="sweeps of a solve, both solvers")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    names = args.problems.split(",")
    if args.quick:
        names = [n for n in names if n in ("pile-10x42", "box-850")]
    W, q, mu, r0, _ = step_problem(*fallen(20, 100, cache=None, log=lambda *a, **k: None))
    solve_ours(W, q, mu, r0, args.tol, 10)          # the compile, out of the timings
    problems, rows = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            kind, size = name.split("-")
            if kind == "pile":
                state = pile(*(int(k) for k in size.split("x")))
            elif kind == "box":
                state = fallen(int(size), args.fall)
            else:
                raise SystemExit(f"unknown problem {name!r}: pile-RxC or box-N")
            W, q, mu, r0, _ = step_problem(*state)
            W, q, mu, r0 = round_trip(W, q, mu, r0, os.path.join(tmp, f"{name}.hdf5"))
            problems[name] = (W, q, mu, r0)
            print(f"{name}: {mu.size} contacts, {W.nnz} nonzeros in W, FCLib round trip exact",
                  flush=True)
            for start, guess in (("cold", None), ("warm", r0)):
                cpu, wall, (sol, sweeps) = timed(
                    lambda: solve_ours(W, q, mu, guess, args.tol, args.budget), args.repeat)
                res = problem_residual(W, q, mu, sol.r)[0]
                rows.append({"problem": name, "start": start, "solver": "ours", "its_tol": args.tol,
                             "sweeps": sweeps, "cpu": cpu, "wall": wall, "residual": res,
                             "its_error": sol.residual, "info": 0 if sol.converged else 1})
                print(f"  ours    {start}: {cpu:.3e} s CPU, {sweeps} sweeps, residual {res:.2e}",
                      flush=True)
        version = None
        if not args.no_siconos:
            sic, version = run_siconos(problems, args, tmp)
            if sic is None:
                print(f"siconos left out: {version}")
            else:
                rows += sic
    contacts = {name: p[2].size for name, p in problems.items()}
    print(f"\ntol {args.tol:g} on our residual (natural map / (1 + ||q||)), budget {args.budget} "
          f"sweeps, median of {args.repeat} solves; Siconos {version}")
    head = ("problem", "contacts", "start", "solver", "its tol", "sweeps", "CPU ms", "wall ms",
            "our residual", "its error", "x ours")
    print(" | ".join(head))
    for name in problems:
        for start in ("cold", "warm"):
            mine = [r for r in rows if (r["problem"], r["start"], r["solver"]) ==
                    (name, start, "ours")]
            sic = [r for r in rows if (r["problem"], r["start"], r["solver"]) ==
                   (name, start, "siconos")]
            equal = next((r for r in sic if r["residual"] <= args.tol), None)
            for r in mine + sic:
                label = r["solver"] + (" @ equal" if r is equal else "")
                ratio = r["cpu"] / mine[0]["cpu"] if mine else math.nan
                print(" | ".join([name, str(contacts[name]), start, label, f"{r['its_tol']:.1e}",
                                  str(r["sweeps"]), f"{1e3 * r['cpu']:.2f}",
                                  f"{1e3 * r['wall']:.2f}",
                                  f"{r['residual']:.2e}", f"{r['its_error']:.2e}", f"{ratio:.2f}"]))


if __name__ == "__main__":
    main()
