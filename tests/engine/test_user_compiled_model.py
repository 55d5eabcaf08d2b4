"""A user's scene gets the compiled Moreau–Jean loop through ``moreau.compiled``, no package edit."""

import glob
import json
import os
import subprocess
import sys
import textwrap
import uuid

import numpy as np
import pytest
from numba import njit

from moreau.compiled import CompiledModel, check_compiled_model, zero_drift
from moreau.errors import InputError
from moreau.integrators import _loops, _sp_kernels, simulate
from moreau.integrators.moreau_jean import MoreauJean

from belt_scene import (BeltBlock, CompiledBeltBlock, belt_contacts, belt_drift, belt_forces,
                        belt_mass, local_belt_block)

HERE = os.path.dirname(os.path.abspath(__file__))


def test_the_compiled_model_equals_the_python_methods():
    rng = np.random.default_rng(3)
    sc = CompiledBeltBlock(k=3.0, vb=0.7, mu=0.4)
    for _ in range(20):
        q, v = rng.normal(size=2), rng.normal(size=2)
        assert check_compiled_model(sc, q, v, rng.uniform(0, 5)) <= 1e-12


def test_a_wrong_compiled_model_is_caught_by_the_check():
    @njit
    def wrong_forces(par, q, v, t, D, need_jac):
        D[0, 0] = -par[0] * q[0]
        D[1, 0] = -2.0      # gravity doubled: not the Python model

    class Wrong(CompiledBeltBlock):
        def compiled_model(self):
            m = super().compiled_model()
            return CompiledModel(m.mass, wrong_forces, m.contacts, m.drift, m.par, 2, 1, True, True)

    assert check_compiled_model(Wrong(), [0.1, 0.0], [0.0, 0.0], 0.0) == pytest.approx(1.0)


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_the_compiled_loop_runs_the_generic_step_to_rounding(theta):
    sc = CompiledBeltBlock()
    q0, v0 = sc.initial_state()
    fast = MoreauJean(sc, 0.0, q0, v0, 6.0, h=0.01, theta=theta, fast=True)
    assert fast._fast
    while fast.status == "running":
        fast.step()
    slow = simulate(sc, (0.0, 6.0), q0, v0, "moreau-jean", h=0.01, theta=theta, fast=False)
    res = fast.result()
    assert res.success and slow.success
    np.testing.assert_allclose(res.q, slow.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.v, slow.v, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(res.regime, slow.regime)
    # the block sticks, slips and sticks again: both regimes are exercised
    assert len(np.unique(res.regime)) >= 2


def test_functions_defined_in_a_function_run_compiled_in_memory(monkeypatch):
    # a notebook's or script's functions cannot be imported again by name: the loop is
    # compiled for this process only, and still runs the model's equations. Compiled in
    # every run of the suite: Schatzman-Paoli's loop, the quickest to compile (15 s
    # against Moreau-Jean's 27 s), held to its generic step
    Local, mass = local_belt_block()

    model = Local().compiled_model()
    assert _loops._import_path(mass) is None
    # the model's own loop is what this test is about (the shared one needs no compile)
    monkeypatch.setenv(_loops.SPECIALISE_ENV, "1")
    # one contact, Lemke not forced: the variant with the LCP step's stand-in runs
    run = _loops.runner_for(model, _sp_kernels.sp_loop, specialise=True, stub=True)
    assert type(run._cache).__name__ == "NullCache"
    sc = Local()
    q0, v0 = sc.initial_state()
    a = simulate(sc, (0.0, 3.0), q0, v0, "schatzman-paoli", h=0.01, fast=True)
    assert run.signatures                     # the in-memory loop ran
    b = simulate(CompiledBeltBlock(), (0.0, 3.0), q0, v0, "schatzman-paoli", h=0.01, fast=False)
    assert a.success and b.success
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.v, b.v, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.regime, b.regime)
    # the block sticks, slips and sticks again: both regimes are exercised
    assert len(np.unique(a.regime)) >= 2


def test_a_models_own_loop_is_built_in_a_fresh_process_with_every_name_it_reads():
    # a model's own loop runs in a copy of its scheme module's globals, to which splicing the
    # template adds the driver's and the spliced helpers' names: in a fresh process, where no
    # shared loop spliced it first, every global the loop reads must still be there (built,
    # not compiled: a missing name is numba's NameError at the loop's first compile)
    script = textwrap.dedent("""
        import builtins, dis, sys
        sys.path.insert(0, sys.argv[1])
        from belt_scene import local_belt_block
        from moreau.integrators import _loops, _mj_kernels, _sp_kernels
        Local, _ = local_belt_block()
        for template in (_sp_kernels.sp_loop, _mj_kernels.mj_loop):
            fn = _loops._build(Local().compiled_model(), template).py_func
            names = {i.argval for i in dis.get_instructions(fn.__code__)
                     if i.opname == "LOAD_GLOBAL"}
            print(template.__name__, sorted(n for n in names
                                            if n not in fn.__globals__ and not hasattr(builtins, n)))
    """)
    out = subprocess.run([sys.executable, "-c", script, HERE], capture_output=True, text=True,
                         check=True).stdout
    assert out.split("\n")[:2] == ["sp_loop []", "mj_loop []"]
    assert "CTL_IA" in _sp_kernels.sp_loop.__globals__ and "S_PEN" in _sp_kernels.sp_loop.__globals__


def test_an_importable_model_is_cached_and_an_edit_recompiles(tmp_path):
    # a user's model module, run in fresh processes: the second loads the compiled loop
    # from numba's disk cache; after an edit of the model, the third compiles again and
    # runs the edited model (never the stale machine code). Every scheme's loop is built
    # and cached by the same `runner_for`; Schatzman-Paoli's is the quickest to compile.
    # The module's name is new on every run, so that its loop is too (a first run always
    # compiles it), while the loop's shared kernels come from the checkout's cache like any
    # user's (a private NUMBA_CACHE_DIR would compile all of them again: 40 s of CI)
    module = f"user_belt_{uuid.uuid4().hex[:12]}"
    src = open(os.path.join(HERE, "belt_scene.py")).read()
    (tmp_path / f"{module}.py").write_text(src)
    script = textwrap.dedent(f"""
        import json, sys
        import numpy as np
        from moreau.integrators import simulate, _loops, _sp_kernels
        from {module} import CompiledBeltBlock
        sc = CompiledBeltBlock()
        q0, v0 = sc.initial_state()
        r = simulate(sc, (0.0, 2.0), q0, v0, "schatzman-paoli", h=0.01, fast=True)
        run = _loops.runner_for(sc.compiled_model(), _sp_kernels.sp_loop, specialise=True,
                                stub=True)
        print(json.dumps({{"hits": sum(run.stats.cache_hits.values()),
                          "misses": sum(run.stats.cache_misses.values()),
                          "x": float(r.q[-1, 0]), "name": run.__qualname__,
                          "cache": getattr(run._cache, "_cache_path", None)}}))
    """)
    env = dict(os.environ, PYTHONPATH=str(tmp_path) + os.pathsep + os.environ.get("PYTHONPATH", ""),
               **{_loops.SPECIALISE_ENV: "1"})

    def run():
        out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                             text=True, timeout=600, cwd=tmp_path)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = run()
    try:
        second = run()
        assert first["misses"] == 1 and first["hits"] == 0
        assert second["hits"] == 1 and second["misses"] == 0
        assert second["x"] == first["x"]
        # the spring twice as stiff, in the compiled model only: the edited code must run
        (tmp_path / f"{module}.py").write_text(src.replace("D[0, 0] = -par[0] * q[0]",
                                                           "D[0, 0] = -2.0 * par[0] * q[0]"))
        third = run()
        assert third["name"] == first["name"]
        assert third["misses"] == 1
        assert third["x"] != first["x"]
    finally:
        # this run's loop is of no use to a later one (its module name is new each time)
        if first["cache"]:
            for path in glob.glob(os.path.join(glob.escape(first["cache"]),
                                               f"*.{first['name']}-*")):
                os.remove(path)


def test_bad_compiled_models_are_refused_by_name():
    def plain(par, q, M):
        M[0, 0] = 1.0

    with pytest.raises(InputError, match=r"`mass` must be a numba.njit function"):
        CompiledModel(plain, belt_forces, belt_contacts, belt_drift, [1.0], 2, 1, True, True)
    with pytest.raises(InputError, match=r"`ndof` must be >= 1"):
        CompiledModel(belt_mass, belt_forces, belt_contacts, belt_drift, [1.0], 0, 1, True, True)
    with pytest.raises(InputError, match=r"`par` must be finite"):
        CompiledModel(belt_mass, belt_forces, belt_contacts, belt_drift, [np.nan], 2, 1, True, True)
    with pytest.raises(InputError, match=r"`const_mass` must be True or False"):
        CompiledModel(belt_mass, belt_forces, belt_contacts, belt_drift, [1.0], 2, 1, "yes", True)


def test_a_model_without_a_drift_function_has_zero_drift_terms():
    class NoDrift(CompiledBeltBlock):
        def compiled_model(self):
            return CompiledModel(belt_mass, belt_forces, belt_contacts, None, [self.k, self.vb],
                                 2, 1, True, True)

    sc = NoDrift(k=3.0, vb=0.7, mu=0.4)
    assert sc.compiled_model().drift is zero_drift
    assert check_compiled_model(sc, np.array([0.3, 0.0]), np.array([-0.2, 0.1]), 0.5) < 1e-12
    Dr = np.full((3, 2), np.nan)
    zero_drift(np.zeros(1), np.zeros(2), np.zeros(2), 0.0, Dr)
    np.testing.assert_array_equal(Dr, 0.0)
    with pytest.raises(InputError, match=r"`drift` must be a numba.njit function"):
        CompiledModel(belt_mass, belt_forces, belt_contacts, belt_drift.py_func, [1.0], 2, 1,
                      True, True)


def test_a_model_of_other_sizes_than_its_scene_is_refused():
    class Mismatch(BeltBlock):
        def compiled_model(self):
            return CompiledModel(belt_mass, belt_forces, belt_contacts, belt_drift, [4.0, 0.5],
                                 3, 1, True, True)

    with pytest.raises(InputError, match=r"describes 3 dof"):
        MoreauJean(Mismatch(), 0.0, np.zeros(2), np.zeros(2), 1.0, h=0.01, fast=True)
