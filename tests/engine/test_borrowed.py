"""``borrowed`` views: the same data, no reference counting where an inlined helper takes them."""

import numpy as np
from numba import njit

from moreau.integrators._contact_step import borrowed


@njit
def _double(a, b, n):
    for i in range(n):
        b[i] = 2.0 * a[i]


@njit(inline="always")
def _scaled_sum(a, b, n):
    # returns from within its loop, as _regime_solve does: references that LLVM's pruning
    # cannot pair across the exits
    acc = 0.0
    for i in range(n):
        if a[i] < 0.0:
            return -1.0
        acc += a[i]
    _double(a, b, n)
    return 2.0 * acc


@njit
def _owned(a, b, steps):
    acc = 0.0
    for k in range(steps):
        if k > 0:
            acc += _scaled_sum(a, b, a.shape[0])
    return acc


@njit
def _viewed(a, b, steps):
    acc = 0.0
    for k in range(steps):
        if k > 0:
            acc += _scaled_sum(borrowed(a), borrowed(b), a.shape[0])
    return acc


def _refcount_calls(dispatcher):
    (ir,) = dispatcher.inspect_llvm().values()
    return ir.count("call void @NRT_incref"), ir.count("call void @NRT_decref")


def test_a_borrowed_view_reads_and_writes_the_array_s_own_data():
    a = np.arange(5.0)
    b = np.zeros(5)
    # two of the three steps call the helper
    assert _viewed(a, b, 3) == _owned(a, b.copy(), 3) == 2 * 2.0 * a.sum()
    np.testing.assert_array_equal(b, 2.0 * a)


def test_an_inlined_helper_on_borrowed_views_takes_fewer_references():
    a, b = np.ones(4), np.zeros(4)
    _owned(a, b, 1)
    _viewed(a, b, 1)
    # owned arrays: numba takes a reference for each of the helper's names and drops it at
    # each of its exits (atomic operations, every step); views: none there (what is left,
    # the loop function's own arguments, both have)
    owned, viewed = _refcount_calls(_owned), _refcount_calls(_viewed)
    assert viewed[0] < owned[0] and viewed[1] < owned[1], (owned, viewed)


@njit
def _write_through_tuple(group):
    a, (b, c) = borrowed(group)
    a[0] = 1.0
    b[0] = 2.0
    c[0] = 3
    return a.shape[0] + b.shape[0] + c.shape[0]


def test_a_tuple_of_arrays_gives_the_tuple_of_their_views():
    a, b, c = np.zeros(2), np.zeros(3), np.zeros(4, dtype=np.int64)
    assert _write_through_tuple((a, (b, c))) == 9
    assert (a[0], b[0], c[0]) == (1.0, 2.0, 3)


def _model_call_arguments(tree):
    import ast

    from moreau.integrators._driver import MODEL_FUNCTIONS
    wrapped, plain = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id in MODEL_FUNCTIONS:
            for arg in node.args:
                if isinstance(arg, ast.Call) and arg.func.id == "borrowed":
                    wrapped.add(ast.unparse(arg.args[0]))
                elif isinstance(arg, ast.Name):
                    plain.add(arg.id)
    return wrapped, plain


def test_every_driver_loop_passes_its_buffers_to_the_model_as_borrowed_views():
    # a model function with a branch keeps numba's counts on its arrays: every array a
    # loop hands to one is borrowed; what a step assigns anew (here only times) is not
    import ast
    import importlib
    for module, name in (("_mj_kernels", "mj_loop"), ("_sp_kernels", "sp_loop"),
                         ("_nsga_kernels", "nsga_loop"), ("_tdg_kernels", "tdg_loop"),
                         ("_studer_kernels", "studer_loop"),
                         ("moreau_jean_projected", "mjp_loop")):
        mod = importlib.import_module(f"moreau.integrators.{module}")
        wrapped, plain = _model_call_arguments(ast.parse(getattr(mod, name).__moreau_source__))
        assert {"par", "q", "M"} <= wrapped, name
        assert all(p == "t" or p.startswith(("t", "_gaps_at", "_sequence")) for p in plain), \
            (name, plain)


def test_an_array_made_during_a_step_is_not_borrowed():
    # numba frees an array right after its last use: a view of a step's temporary, made
    # for the call that is its last use, would point at freed memory during the call
    import ast
    import textwrap

    from moreau.integrators._driver import _borrow_model_arguments
    tree = ast.parse(textwrap.dedent("""
        def loop(par, q, v, n):
            G = np.zeros((2, 5))
            keep = G
            k = 0
            while k < n:
                q_th = q + 0.5 * v
                alias = q_th
                contacts_fn(par, q_th, 0.0, keep, True, False)
                gaps_fn(par, alias, 0.0, G)
                k += 1
    """))
    _borrow_model_arguments(tree.body[0])
    wrapped, plain = _model_call_arguments(tree)
    assert wrapped == {"par", "keep", "G"}
    assert plain == {"q_th", "alias"}
