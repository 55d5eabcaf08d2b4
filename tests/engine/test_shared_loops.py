"""One compiled loop per scheme serves every model; a long run moves to the model's own loop.

:mod:`moreau.integrators._loops` runs a model in its scheme's *shared* loop
(the model's functions called through pointers, compiled once for all
scenes) until the time spent there passes ``TIER_UP_SECONDS``, then in the
model's *specialised* loop (the same source, the model compiled in). The
two must give the same numbers to the last bit, so that where a run
switches never shows in its answer.
"""

import numpy as np
import pytest

from moreau.integrators import _blocks, _loops, simulate
from moreau.model.registry import make_scene

from belt_scene import local_belt_block


def _run(scene, t_end, h):
    q0, v0 = scene.initial_state()
    return simulate(scene, (0.0, t_end), q0, v0, "moreau-jean", h=h, fast=True)


# the two-rod drive: two frictional contacts, Lemke's pivoting, the warm start and the
# closed-form single-contact solve all run; the friction drive: one contact, whose own
# loop is the variant with the stand-in for the LCP step (no Lemke compiled), the one
# production runs take. The cost is the specialised loop's compile (13-16 CPU s each; the
# runs take 0.1 s): the friction drive's variant runs by default, the two-rod drive's
# with the long checks (-m slow)
@pytest.mark.parametrize("name, t_end, h, stub", [
    pytest.param("bidirectional-drive", 40.0, 2e-3, False, marks=pytest.mark.slow),
    ("friction-drive", 40.0, 2e-3, True)])
def test_a_run_that_moves_to_the_specialised_loop_gives_the_same_bits(monkeypatch, name, t_end, h,
                                                                      stub):
    # small blocks so that the switch falls inside the run, after the first block
    monkeypatch.setattr(_blocks, "FAST_BLOCK", 2000)
    monkeypatch.setattr(_loops, "_CHOSEN", {})
    # start in the shared loop even where an earlier run left the specialised one on disk
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: False)
    monkeypatch.setattr(_loops, "TIER_UP_SECONDS", float("inf"))
    shared = _run(make_scene(name), t_end, h)
    runner = _loops.runner_for(make_scene(name).compiled_model())
    assert isinstance(runner, _loops.SharedRunner) and runner._special is None

    monkeypatch.setattr(_loops, "_CHOSEN", {})
    monkeypatch.setattr(_loops, "TIER_UP_SECONDS", 0.0)
    tiered = _run(make_scene(name), t_end, h)
    runner = _loops.runner_for(make_scene(name).compiled_model())
    assert list(runner._specials) == [stub]             # it did move, to the right variant
    assert len(runner._special.signatures) == 1        # compiled once
    assert shared.success and tiered.success
    assert shared.stats["steps"] == tiered.stats["steps"] > 3 * 2000
    for field in ("t", "q", "v", "regime", "force_N", "force_T", "slip_velocity", "gap"):
        np.testing.assert_array_equal(getattr(tiered, field), getattr(shared, field), field)
    # the run crosses regimes: stick or slip changes and, on the two-rod drive, both rods
    assert len(np.unique(shared.regime)) >= 2


def test_a_scene_defined_in_a_function_needs_no_loop_compile(monkeypatch):
    # a notebook's model: its functions compile on their own (small), the loop is the
    # scheme's shared one, already compiled for the other scenes
    monkeypatch.setattr(_loops, "_CHOSEN", {})

    Local, mass = local_belt_block()

    a = _run(Local(), 3.0, 0.01)
    runner = _loops.runner_for(Local().compiled_model())
    assert isinstance(runner, _loops.SharedRunner)
    specialised = _loops._RUNNERS[next(k for k in _loops._RUNNERS if k[1] == "mj_loop"
                                       and dict(k[2])["mass"] is mass)]
    assert not specialised.signatures                 # the model's own loop never compiled
    q0, v0 = Local().initial_state()
    b = simulate(Local(), (0.0, 3.0), q0, v0, "moreau-jean", h=0.01, fast=False)
    assert a.success and b.success
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.regime, b.regime)


def test_the_specialise_setting_is_read_from_the_environment(monkeypatch):
    monkeypatch.delenv(_loops.SPECIALISE_ENV, raising=False)
    assert _loops.specialise_default() is None
    for value, expected in (("1", True), ("yes", True), ("0", False), ("off", False),
                            ("", None), ("auto", None)):
        monkeypatch.setenv(_loops.SPECIALISE_ENV, value)
        assert _loops.specialise_default() is expected


def test_specialise_false_keeps_the_shared_loop_even_when_the_model_s_own_is_cached(monkeypatch):
    monkeypatch.setattr(_loops, "_CHOSEN", {})
    monkeypatch.delenv(_loops.SPECIALISE_ENV, raising=False)
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: True)
    model = make_scene("bouncing-ball").compiled_model()
    auto = _loops.runner_for(model)
    assert auto.mode == "auto" and auto._wants_own(True)       # cached: its own, at once
    shared = _loops.runner_for(model, specialise=False)
    assert shared.mode == "shared" and not shared.tier_up and not shared._wants_own(True)
    monkeypatch.setenv(_loops.SPECIALISE_ENV, "1")
    assert _loops.runner_for(model).mode == "specialised"


def test_a_single_contact_run_passes_a_stand_in_for_lemke_unless_lemke_is_forced(monkeypatch):
    from moreau.integrators import _mj_kernels as mk

    monkeypatch.setattr(_loops, "_CHOSEN", {})
    monkeypatch.setenv(_loops.SPECIALISE_ENV, "0")
    one = _loops.runner_for(make_scene("friction-drive").compiled_model())
    two = _loops.runner_for(make_scene("bidirectional-drive").compiled_model())
    names = list(__import__("inspect").signature(mk.mj_loop).parameters)
    args = [0.0] * len(names)
    slot = names.index("lcp_ctl")
    for runner, nc, force, expected in ((one, 1, False, mk._lcp_step_unused),
                                        (one, 1, True, mk._lcp_step),
                                        (two, 2, False, mk._lcp_step)):
        args[slot] = mk.new_lcp_control(nc, force_lemke=force)
        assert runner._prefix_for(args)[-1] is expected
    # forced Lemke on one contact runs the real pivoting, and agrees with the closed form
    sc = make_scene("friction-drive")
    q0, v0 = sc.initial_state()
    closed = simulate(sc, (0.0, 6.3), q0, v0, "moreau-jean", h=6.3e-3, fast=True)
    lemke = simulate(sc, (0.0, 6.3), q0, v0, "moreau-jean", h=6.3e-3, fast=True,
                     lcp_method="lemke")
    assert closed.stats["direct_solves"] > 0 and lemke.stats["direct_solves"] == 0
    assert lemke.stats["pivots"] > 0 and lemke.stats["fallbacks"] == 0
    np.testing.assert_allclose(lemke.q, closed.q, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(lemke.regime, closed.regime)


def test_specialised_loops_holds_for_its_block_and_leaves_a_user_setting_alone(monkeypatch):
    from moreau.integrators import specialised_loops

    monkeypatch.delenv(_loops.SPECIALISE_ENV, raising=False)
    with specialised_loops():
        assert _loops.specialise_default() is True
        assert _loops.runner_for(make_scene("bouncing-ball").compiled_model()).mode == "specialised"
    assert _loops.SPECIALISE_ENV not in __import__("os").environ
    monkeypatch.setenv(_loops.SPECIALISE_ENV, "0")
    with specialised_loops():
        assert _loops.specialise_default() is False
    assert __import__("os").environ[_loops.SPECIALISE_ENV] == "0"


def test_a_one_contact_run_takes_the_lean_shared_loop_with_the_full_loop_s_bits(monkeypatch):
    # the friction drive (one contact, no projection) runs the lean form of the shared loop,
    # compiled without the several-contact LCP and the projection; the full form, forced,
    # gives the same arrays to the last bit (a projection run takes the full form)
    monkeypatch.setattr(_loops, "_CHOSEN", {})
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: False)
    monkeypatch.setattr(_loops, "TIER_UP_SECONDS", float("inf"))
    scene = make_scene("friction-drive")
    lean = _run(scene, 2.0, 2e-3)
    runner = _loops.runner_for(scene.compiled_model())
    assert list(runner._cores) == [True] and runner._special is None
    assert runner._cores[True].py_func.__name__ == "mj_loop_lean_shared"

    monkeypatch.setattr(_loops, "_CHOSEN", {})
    monkeypatch.setattr(_loops.SharedRunner, "_lean_for", lambda self, args, stub: False)
    full = _run(scene, 2.0, 2e-3)
    runner = _loops.runner_for(scene.compiled_model())
    assert list(runner._cores) == [False]
    assert lean.success and full.success and lean.stats["steps"] == full.stats["steps"] == 1000
    for field in ("t", "q", "v", "regime", "force_N", "force_T", "slip_velocity", "gap"):
        np.testing.assert_array_equal(getattr(lean, field), getattr(full, field), field)

    monkeypatch.undo()
    monkeypatch.setattr(_loops, "_CHOSEN", {})
    monkeypatch.setattr(_loops._jit_cache, "has_cached_code", lambda disp: False)
    q0, v0 = scene.initial_state()
    simulate(scene, (0.0, 0.2), q0, v0, "moreau-jean", h=2e-3, projection=True)
    assert list(_loops.runner_for(scene.compiled_model())._cores) == [False]


@pytest.mark.parametrize("module", ["_mj_kernels", "_sp_kernels", "_nsga_kernels", "_tdg_kernels",
                                    "_studer_kernels", "moreau_jean_projected"])
def test_every_scheme_s_loop_calls_the_lcp_step_through_its_argument(module):
    # through the argument, the shared loop gets Lemke as a pointer (not linked in and optimised
    # again with the loop) and a one-contact run the stand-in; a kernel that called the global
    # _lcp_step (as TDG's stage problem did) linked Lemke into TDG's and Studer's loops
    import importlib

    mod = importlib.import_module(f"moreau.integrators.{module}")
    assert "_lcp_step" in mod.SHARED_INDIRECT
    callers = [name for name, f in vars(mod).items()
               if getattr(getattr(f, "py_func", None), "__module__", None) == mod.__name__
               and "_lcp_step" in f.py_func.__code__.co_names]
    assert callers == []
