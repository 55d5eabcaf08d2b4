"""The compiled kernel's on-disk cache follows every source compiled into it."""

import os
import pathlib
import subprocess
import sys
import textwrap

import pytest

import moreau
from moreau import _jit_cache

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(moreau.__file__)))

KERNEL = textwrap.dedent("""
    import os
    from numba import njit
    from toypkg import dep

    @njit(cache=True)
    def f(x):
        return dep.g(x)

    if os.environ.get("TOY_BIND") == "1":
        from moreau._jit_cache import bind_cache_to_sources
        MODE = bind_cache_to_sources([f], [__file__, dep.__file__])
    """)

DEP = "from numba import njit\n\n\n@njit(cache=True, inline='always')\ndef g(x):\n    return x + {}.0\n"


def _toy(tmp_path, name):
    pkg = tmp_path / name / "toypkg"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "kern.py").write_text(KERNEL)
    (pkg / "dep.py").write_text(DEP.format(1))
    return pkg


def _run(pkg, bind):
    env = dict(os.environ)
    env.pop("NUMBA_CACHE_DIR", None)
    env["PYTHONPATH"] = os.pathsep.join([str(pkg.parent), ROOT])
    env["TOY_BIND"] = "1" if bind else "0"
    out = subprocess.run([sys.executable, "-c", "from toypkg import kern; print(kern.f(1.0))"],
                         env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return float(out.stdout.split()[-1])


def _edit_dep(pkg):
    # same size, same file for the kernel: only the dependency's content changes
    st = os.stat(pkg / "kern.py")
    (pkg / "dep.py").write_text(DEP.format(2))
    os.utime(pkg / "kern.py", ns=(st.st_atime_ns, st.st_mtime_ns))


def test_unbound_cache_goes_stale(tmp_path):
    # the hazard itself, so that the next test proves something: numba alone
    # keeps the old machine code after the dependency changes
    pkg = _toy(tmp_path, "plain")
    assert _run(pkg, bind=False) == 2.0
    _edit_dep(pkg)
    assert _run(pkg, bind=False) == 2.0


def test_bound_cache_recompiles_when_a_dependency_changes(tmp_path):
    pkg = _toy(tmp_path, "bound")
    assert _run(pkg, bind=True) == 2.0
    assert any(p.suffix == ".nbi" for p in (pkg / "__pycache__").iterdir())
    assert _run(pkg, bind=True) == 2.0
    _edit_dep(pkg)
    assert _run(pkg, bind=True) == 3.0
    assert _run(pkg, bind=True) == 3.0


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0,
                    reason="root ignores read-only permissions")
def test_read_only_install_still_runs(tmp_path):
    pkg = _toy(tmp_path, "readonly")
    assert _run(pkg, bind=True) == 2.0
    _edit_dep(pkg)
    for p in [pkg, pkg / "__pycache__"]:
        os.chmod(p, 0o555)
    try:
        assert _run(pkg, bind=True) == 3.0
    finally:
        for p in [pkg, pkg / "__pycache__"]:
            os.chmod(p, 0o755)


def test_kernel_stamps_carry_the_digest_of_all_kernel_sources():
    from moreau.integrators import _mj_kernels as mk
    from moreau.lcp import lemke

    names = {os.path.basename(p) for p in mk.KERNEL_SOURCES}
    assert {"_mj_kernels.py", "lemke.py", "certify.py", "_certified.py"} <= names
    assert mk.CACHE_MODE == "bound"
    from moreau.integrators import _contact_step as cs

    # the contact step's kernels on their module's sources (Lemke's among them), the
    # loop's on those and the driver's as well
    assert set(cs.KERNEL_SOURCES) <= set(mk.KERNEL_SOURCES)
    # the one-contact closed form lives on the contact floor (numba's own cache checks it
    # against its file); the kernels that call it are bound to that file too
    assert {"_contact_step.py", "_one_contact.py", "lemke.py", "certify.py", "_certified.py"} <= {
        os.path.basename(p) for p in cs.KERNEL_SOURCES}
    for module, disps in ((cs, (cs._lcp_step, cs._regime_solve)), (mk, (mk.no_gaps,))):
        digest = _jit_cache.sources_digest(module.KERNEL_SOURCES)
        for disp in disps:
            stamp = disp._cache._cache_file._source_stamp
            assert stamp[0] == "moreau-deps" and stamp[1][1] == digest
    assert lemke.lemke_core._cache._cache_file._source_stamp[0] == "moreau-deps"


def _tail(path):
    """The last two parts of ``path`` ("package/module.py")."""
    return "/".join(pathlib.PurePath(path).parts[-2:])


def test_a_scene_runner_is_tied_to_its_model_and_kernel_sources(monkeypatch):
    from moreau.integrators import _loops
    from moreau.integrators import _mj_kernels as mk
    from moreau.scenes.friction_drive import scene as friction_drive

    model = friction_drive.FrictionDrive(frequency=185.0).compiled_model()
    monkeypatch.setattr(_loops, "_RUNNERS", {})
    monkeypatch.setattr(_loops, "_CHOSEN", {})
    run = _loops.runner_for(model, specialise=True)
    deps = _loops.dependency_files(list(model.functions().values()))
    # the model's module and the rod pieces it calls (another file) are both tracked
    assert {"friction_drive/scene.py", "friction_drive/rod.py"} <= {_tail(p) for p in deps}
    digest = _jit_cache.sources_digest(list(mk.KERNEL_SOURCES) + deps)
    stamp = run._cache._cache_file._source_stamp
    assert stamp[0] == "moreau-deps" and stamp[1][1] == digest


def test_the_shared_loop_is_tied_to_the_kernels_and_each_model_function_to_its_files(monkeypatch):
    import numba

    from moreau.integrators import _loops
    from moreau.integrators import _mj_kernels as mk
    from moreau.scenes.friction_drive import scene as friction_drive

    monkeypatch.setattr(_loops, "_CORES", {})
    core = _loops.shared_core(mk.mj_loop, (numba.int64,))   # built, never compiled here
    stamp = core._cache._cache_file._source_stamp
    assert stamp[0] == "moreau-deps"
    assert stamp[1][1] == _jit_cache.sources_digest(list(mk.KERNEL_SOURCES))
    # a model function called through a pointer is compiled on its own: its cache must
    # follow the rod pieces it calls in another file, which numba alone would not see
    src = friction_drive._forces.py_func.__code__.co_filename
    fresh = numba.njit(cache=True)(friction_drive._forces.py_func)   # not compiled yet
    monkeypatch.setattr(friction_drive, "_forces", fresh)
    model = friction_drive.FrictionDrive(frequency=185.0).compiled_model()
    assert model.forces is fresh
    _loops._model_prefix(model)
    deps = _loops.dependency_files([fresh])
    assert src in deps and "friction_drive/rod.py" in {_tail(p) for p in deps}
    assert fresh._cache._cache_file._source_stamp[1][1] == _jit_cache.sources_digest(deps)


def test_a_loop_is_tied_to_the_kernels_of_other_schemes_it_calls():
    # Studer's loop calls the TDG module's stage solve: an edit there must compile it again
    from moreau.integrators import _loops, _studer_kernels

    names = [os.path.basename(p) for p in _loops._template_sources(_studer_kernels.studer_loop)]
    assert {"_studer_kernels.py", "_tdg_kernels.py", "_mj_kernels.py", "lemke.py"} <= set(names)
    core = _loops.shared_core(_studer_kernels.studer_loop, ())      # built, never compiled here
    digest = _jit_cache.sources_digest(_loops._template_sources(_studer_kernels.studer_loop))
    assert core._cache._cache_file._source_stamp[1][1] == digest


FIRST_USE = textwrap.dedent("""
    import sys
    import numpy as np
    from moreau.integrators import _loops
    from moreau.scenes import BouncingBall
    ball = BouncingBall()
    q, v = ball.initial_state()
    model = ball.compiled_model()
    if sys.argv[1] == "loop":
        _loops._model_prefix(model)            # what a compiled loop does first
        model.mass(model.par, np.asarray(q, float), np.zeros((1, 1)))
    else:
        ball.mass(q)                           # the scene's Python method
    print(sum(model.mass.stats.cache_hits.values()))
    """)


def test_a_model_function_cached_by_one_path_is_loaded_by_the_other(tmp_path):
    # the stamp of a model function's cache entry must not depend on the path that used
    # it first in a process: else each process that comes in by the other path compiles
    # it again and overwrites the entry for the next
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path),
               PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    hits = []
    for first in ("loop", "method", "loop"):
        out = subprocess.run([sys.executable, "-c", FIRST_USE, first], capture_output=True,
                             text=True, env=env, cwd=ROOT, timeout=600)
        assert out.returncode == 0, out.stderr
        hits.append(int(out.stdout.split()[-1]))
    assert hits == [0, 1, 1]
