"""The driver's splicer: a helper's body replaces its call, with its own rules checked first."""

import ast

import pytest

from moreau.integrators import (_contact_step, _driver, _sp_kernels, _step_parts,
                                moreau_jean_projected)
from moreau.integrators._driver import spliced


def test_a_helper_that_assigns_its_parameter_is_refused():
    def bump(x):
        x = x + 1
        return x
    with pytest.raises(TypeError, match=r"assigns its parameters \['x'\]"):
        spliced(bump)


def test_a_helper_that_returns_before_its_end_is_refused():
    def early(x):
        if x > 0:
            return 1
        return 0
    with pytest.raises(TypeError, match="returns before its last statement"):
        spliced(early)


def test_the_package_s_own_helper_is_checked_when_it_is_first_spliced():
    # the package's helpers are read and parsed when a template splices them, not at import
    def bump(x):
        x = x + 1
        return x
    bump.__module__ = "moreau.integrators._fake_kernels"
    helper = spliced(bump)                     # accepted for now: nothing parsed yet
    with pytest.raises(TypeError, match=r"assigns its parameters \['x'\]"):
        _driver._Splicer({"bump": helper}).stmts(ast.parse("y = bump(z)").body)


def _calls(source):
    return {n.func.id for n in ast.walk(ast.parse(source))
            if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}


def test_the_step_rules_and_their_helpers_are_spliced_not_called():
    # Schatzman–Paoli's loop calls no helper of _step_parts nor a step rule; the projected
    # Moreau–Jean's holds Moreau–Jean's step, its locals renamed apart from its own
    for loop in (_sp_kernels.sp_loop, moreau_jean_projected.mjp_loop):
        called = _calls(loop.__moreau_source__)
        assert not called & {"step_rule", "_mj_step", "invert", "gaps_at", "index_set",
                             "gather_rows", "contact_block", "solve_one", "record_contacts"}
        assert any(f.endswith("_step_parts.py") for f in loop.__moreau_sources__)
    src = moreau_jean_projected.mjp_loop.__moreau_source__
    # Moreau-Jean's options, a tuple built in the call, given to its renamed names directly
    assert "_step_rule1_th = opts[0]" in src and "_step_rule1_projection = False" in src


def test_a_tuple_unpacked_once_goes_to_its_names_directly():
    body = ast.parse("c = n + 1\nws = (np.zeros(n), b, c)\nk = 1\nx, y, z = ws\n"
                     "while k:\n    k = x[0] + y + z").body
    assert _driver._forward_tuples(body)
    out = ast.unparse(ast.fix_missing_locations(ast.Module(body, [])))
    # the element named once before is renamed, not copied; the others are assigned
    assert "ws" not in out and "x = np.zeros(n)" in out and "y = b" in out
    assert "z = n + 1" in out and "c" not in out.split()
    # a name the unpacking assigns is used between the two: the tuple stays
    body = ast.parse("ws = (a, b)\nx = 3\nx, y = ws\nwhile k:\n    pass").body
    assert not _driver._forward_tuples(body) and len(body) == 4


def test_no_scheme_s_loop_unpacks_its_workspace_tuple():
    for loop in (_sp_kernels.sp_loop, moreau_jean_projected.mjp_loop):
        lines = [ln.strip() for ln in loop.__moreau_source__.splitlines()]
        assert not [ln for ln in lines if ln.endswith(("= ws", "= mws", "= pws"))]
        assert "ws = step_workspace(n, nc, opts, lcp_ctl)" not in lines


def test_a_global_of_a_helper_that_the_namespace_binds_otherwise_is_renamed():
    ns = {"record_contacts": _step_parts.record_contacts, "S_PEN": -1}
    out = ast.unparse(ast.Module(_driver._Splicer(ns).stmts(
        ast.parse("record_contacts(G, nc, pN, pT, mu, reg, stats)").body), []))
    assert "record_contacts(" not in out and "stats[S_PEN___step_parts]" in out
    assert ns["S_PEN___step_parts"] == _contact_step.S_PEN and ns["S_PEN"] == -1
    # the helper's locals are renamed apart, its parameters replaced by the arguments
    assert "for _record_contacts1_i in range(nc)" in out


def test_a_part_with_step_returns_ends_the_step_with_its_status():
    def part(x, out):
        if x < 0.0:
            return 7
        out[0] = x
    helper = spliced(part, step_returns=True)
    stmts = _driver._Splicer({"part": helper}).stmts(ast.parse("part(y, buf)").body)
    out = ast.unparse(ast.fix_missing_locations(
        ast.Module(_driver._returns_to_breaks(stmts), [])))
    assert "part(" not in out and "buf[0] = y" in out
    assert "if y < 0.0:\n    status = 7\n    break" in out


def test_the_schemes_parts_are_spliced_into_their_loops():
    from moreau.integrators import _mj_kernels, _nsga_kernels, _studer_kernels, _tdg_kernels
    parts = {_mj_kernels.mj_loop: {"free_velocity", "start_contacts", "one_contact",
                                   "sparse_delassus", "several_contacts", "lemke_solve",
                                   "project_positions"},
             _nsga_kernels.nsga_loop: {"smooth_stage", "impulse_stage", "correct_positions",
                                       "dense_delassus", "one_row_impulse", "lemke_solve"},
             _tdg_kernels.tdg_loop: {"start_contacts", "impulse_at_start", "total_impulses",
                                     "project_held"},
             _studer_kernels.studer_loop: {"sequence", "midpoint_velocity", "extrapolated",
                                           "switch_error", "project_held", "times_ht",
                                           "add_impulse", "gather_rows"}}
    for loop, names in parts.items():
        src = loop.__moreau_source__
        assert not _calls(src) & names
        # each part's locals, renamed apart, are in the loop's source
        assert all(f"_{name}" in src for name in names)


def test_a_scheme_that_sizes_its_steps_runs_the_driver_without_its_grid():
    # Studer's macro steps (ADAPTIVE_STEPS): each starts where the one before ended, the step
    # rule sets its end; a fixed-step scheme's loop keeps the grid
    from moreau.integrators import _studer_kernels, _tdg_kernels
    src = _studer_kernels.studer_loop.__moreau_source__
    names = {n.id for n in ast.walk(ast.parse(src)) if isinstance(n, ast.Name)}
    assert "grid_step" not in _calls(src) and "hn" not in names
    assert "t1 = t0" in src and "tk = t1" in src
    assert "grid_step" in _calls(_tdg_kernels.tdg_loop.__moreau_source__)
