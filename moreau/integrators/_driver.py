"""The compiled driver of the fixed-step schemes: one loop, each scheme's step rule inside it.

:func:`drive` owns what every fixed-step scheme's loop repeated: the time
grid (:func:`grid_step`), the state and contact buffers, the step limit of a
call, the save countdown, the recording of the samples (and of the initial
state), the hand-back statuses (a step rule that returns a status other
than :data:`OK` stops the call at the start of that step) and the regimes
kept from one call to the next in the contact problem's control array.

A scheme's kernel module gives two functions under fixed names and builds its
loop template with :func:`loop_template`:

- ``step_workspace(n, nc, opts, lcp_ctl)``: its buffers, one tuple, allocated once a call
  (a :func:`spliced` helper: its arrays go to the step rule's names with no tuple between);
- ``step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn, NDOF, NCONTACTS,
  CONST_MASS, HAS_JAC, HAS_GAPS, lcp_step, ws, par, mu, e, opts, memo,
  lcp_ctl, stats, k, k0, tk, t1, hk, hn, record_initial, q, v, out)``,
  inlined (``numba.njit(inline="always")``): one step from ``(q, v)`` at
  ``tk`` to ``(q1, v1)`` at ``t1``, ``out`` being ``(q1, v1, pN, pT, slip,
  reg, G0, Gq)``. ``hn`` is the length of the step after this one (``h``
  where this one is the last): a scheme that solves a node one step ahead of
  the state it commits (Schatzman–Paoli) needs it. ``record_initial`` is
  true on the run's first step (its start state not yet recorded). It writes the impulses ``pN``, ``pT``, the slip velocities, the
  regimes, the contact rows at the start (``G0``, whose gap column the driver
  carries over from the step before) and the gaps at the end (``Gq``'s column
  0), and returns a status. ``opts`` is a
  tuple of the scheme's options and ``memo`` a tuple of the arrays it
  carries from one call to the next (Moreau–Jean's closed contacts).

A scheme that chooses its own step sizes (Studer's extrapolation) sets
``ADAPTIVE_STEPS = True`` in its module: the driver then has no grid, ``tk``
is where the step before ended (``t0`` for the first; ``h`` is not read),
and the step rule sets ``t1``, ``hk`` and ``last`` (the step's end, its
length and whether it is the call's last) instead of reading them; ``hn``
is not given.

The model comes first in the step rule's arguments, as the driver has it:
frozen globals in a model's own (specialised) loop, run-time arguments in the
scheme's shared loop (:mod:`moreau.integrators._loops` compiles the one
template both ways). :func:`loop_template` splices the step rule's source into
the driver's: its statements before the marker ``...`` run once a call, before
the loop, the rest once a step, so that the workspace is unpacked once.
"""

import ast
import functools
import inspect
import textwrap
import types

import numpy as np
from numba import njit
from numba.extending import overload

from ._contact_step import CTL_IA, OK, borrowed

__all__ = ["drive", "grid_step", "record_sample", "gap_of", "loop_template", "spliced",
           "STEP_FUNCTIONS"]

#: the names under which a scheme module gives its step (see the module docstring)
STEP_FUNCTIONS = ("step_workspace", "step_rule")


@njit(inline="always")
def grid_step(t0, k, h, t_bound):
    """``(t_k, t_{k+1}, step, last)`` of the fixed-step grid ``t0 + k h``, the last step cut at
    ``t_bound``: the compiled loops' twin of :func:`moreau.integrators.moreau_jean.next_time`."""
    tk = t0 + k * h
    t1 = t0 + (k + 1) * h
    if t1 >= t_bound - 1e-9 * h:
        return tk, t_bound, t_bound - tk, True
    return tk, t1, h, False


def gap_of(gaps, i):
    """The gap of contact ``i``: ``gaps[i]`` of a vector, ``gaps[i, 0]`` of a contact table.

    Examples
    --------
    >>> table, vector = np.array([[0.5, 1.0], [0.25, 1.0]]), np.array([0.5, 0.25])
    >>> float(gap_of(table, 1)), float(gap_of(vector, 1))
    (0.25, 0.25)
    """
    return gaps[i, 0] if gaps.ndim == 2 else gaps[i]


@overload(gap_of, inline="always")
def _gap_of(gaps, i):
    # chosen by the array's type when the caller compiles: the driver passes its contact
    # table itself, since a column view (G[:, 0]) made in the loop went with the sliding
    # box's shared loop 15-20 % slower (benchmarks/bench_moreau_jean.py)
    if gaps.ndim == 2:
        return lambda gaps, i: gaps[i, 0]
    return lambda gaps, i: gaps[i]


@njit(cache=True)
def record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, nrec, t, q, v,
                  reg, pN, pT, h, slip, gaps, nc):
    """Write sample ``nrec`` of a compiled loop and return ``nrec + 1``: time, state, and per
    contact the regime, the forces (impulse / step), the slip velocity and the gap
    (:func:`gap_of` ``gaps``: a vector, or a contact table whose column 0 holds the gaps)."""
    rec_t[nrec] = t
    for j in range(q.shape[0]):
        rec_q[nrec, j] = q[j]
    for j in range(v.shape[0]):
        rec_v[nrec, j] = v[j]
    for i in range(nc):
        rec_reg[nrec, i] = reg[i]
        rec_fN[nrec, i] = pN[i] / h
        rec_fT[nrec, i] = pT[i] / h
        rec_slip[nrec, i] = slip[i]
        rec_gap[nrec, i] = gap_of(gaps, i)
    return nrec + 1


def drive(par, mu, e, t0, h, t_bound, k0, nmax, q, v, opts, memo, save_every, record_initial,
          lcp_ctl, rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap, stats):
    """Run up to ``nmax`` steps of a scheme's step rule on a compiled model in one call.

    A template, not called as it stands (see the module docstring):
    :func:`moreau.integrators._loops.runner_for` compiles it for a scheme
    (:func:`loop_template`) with the model's functions ``mass_fn``,
    ``forces_fn``, ``contacts_fn``, ``gaps_fn`` and sizes ``NDOF``,
    ``NCONTACTS``, ``CONST_MASS``, ``HAS_JAC``, ``HAS_GAPS`` either frozen in
    or as leading arguments.

    Parameters
    ----------
    par : float64[:]
        The model's parameters.
    mu, e : float64[:]
        Friction and restitution of each contact.
    t0, h, t_bound : float
        Grid ``t0 + k h``; the step that reaches ``t_bound`` is cut there.
    k0 : int
        Index of the first step (``t_k0 = t0 + k0 h``).
    nmax : int
        Most steps to take in this call.
    q, v : float64[n]
        State at ``t_k0``; overwritten with the final state.
    opts : tuple
        The scheme's options (Moreau–Jean: ``(theta, projection)``).
    memo : tuple of arrays
        What the scheme carries from one call to the next (Moreau–Jean:
        ``(closed,)``, the contacts that carried a normal impulse in the step
        before); updated.
    save_every : int
        Record after every ``save_every``-th step (counted from ``t0``) and after the last.
    record_initial : bool
        Also record the state at ``t_k0`` (with the first step's regime and forces).
    lcp_ctl : int64[:]
        The contact problem's options, warm-start memory and the regimes of
        the step before
        (:func:`moreau.integrators._contact_step.new_lcp_control`), read and
        updated; the caller keeps the array from one call to the next.
    rec_* : arrays
        Sample buffers, ``rec_q``/``rec_v`` of shape (ns, n), the contact
        ones (ns, nc); long enough for this call's samples.
    stats : float64[:]
        Accumulated statistics, layout
        :data:`moreau.integrators._contact_step.STAT_NAMES`.

    Returns
    -------
    status : int
        ``OK`` or the step rule's status (``PAINLEVE``, ``NUMERICAL``,
        ``SINGULAR``: the state is the last good one; ``LCP_HANDBACK``: the
        start of the step the contact problem could not solve).
    k : int
        Index of the next step (steps taken: ``k - k0``).
    nrec : int
        Samples written.
    """
    n = NDOF  # noqa: F821  (the model's namespace, see above)
    nc = NCONTACTS  # noqa: F821
    ncm = max(nc, 1)
    ws = step_workspace(n, nc, opts, lcp_ctl)  # noqa: F821  (the scheme's module)
    q1 = np.empty(n)
    v1 = np.empty(n)
    pN = np.zeros(ncm)
    pT = np.zeros(ncm)
    slip = np.zeros(ncm)
    reg = np.zeros(ncm, dtype=np.int64)
    # contact rows (g, wN, wT, WN, WT) at (q_k, t_k) and the gaps at (q_k+1, t_k+1)
    G0 = np.zeros((ncm, 3 + 2 * n))
    Gq = np.zeros((ncm, 3 + 2 * n))
    # one argument for all: a call of more than thirty is passed as a tuple by CPython,
    # which numba cannot inline
    out = (q1, v1, pN, pT, slip, reg, G0, Gq)
    # the regime of each contact in the step before (a tangential impact stops a slip)
    roff = CTL_IA + 5 * ncm
    for i in range(nc):
        reg[i] = lcp_ctl[roff + i]
    # np.int64, not the literal: numba types the calls of record_sample once with the
    # literal 0 before the loop's increment widens it, and compiles it twice
    nrec = np.int64(0)
    k = k0
    status = OK
    # steps left until the next sample (k % save_every == 0 after the step): a
    # countdown, because an integer division per step costs as much as a sine
    to_save = save_every - k0 % save_every
    while k - k0 < nmax:
        tk, t1, hk, last = grid_step(t0, k, h, t_bound)
        if tk >= t_bound:
            break
        # the step after this one (the nominal one after the last): unused, it costs nothing
        hn = h if last else grid_step(t0, k + 1, h, t_bound)[2]
        status = step_rule(mass_fn, forces_fn, contacts_fn, gaps_fn,  # noqa: F821
                           NDOF, NCONTACTS, CONST_MASS, HAS_JAC, HAS_GAPS,  # noqa: F821
                           _lcp_step, ws, par, mu, e, opts, memo, lcp_ctl, stats,  # noqa: F821
                           k, k0, tk, t1, hk, hn, record_initial, q, v, out)
        if status != OK:
            break
        if record_initial:
            nrec = record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                                 nrec, tk, q, v, reg, pN, pT, hk, slip, G0, nc)
            record_initial = False
        for i in range(nc):
            G0[i, 0] = Gq[i, 0]
        for j in range(n):
            q[j] = q1[j]
            v[j] = v1[j]
        k += 1
        to_save -= 1
        if to_save == 0:
            to_save = save_every
        if to_save == save_every or last:
            nrec = record_sample(rec_t, rec_q, rec_v, rec_reg, rec_fN, rec_fT, rec_slip, rec_gap,
                                 nrec, t1, q, v, reg, pN, pT, hk, slip, Gq, nc)
        if last:
            break
    for i in range(nc):
        lcp_ctl[roff + i] = reg[i]
    return status, k, nrec


#: the attributes a loop template gives of the function it builds
_FUNCTION_ATTRS = frozenset(dir(types.FunctionType)) | {"__moreau_source__", "__moreau_sources__"}


class _Template:
    """A loop template that is spliced on first use (:func:`loop_template`).

    Splicing parses and rewrites the driver and the step rule, about a tenth
    of a CPU second a loop; built at import, it was paid by every process
    that imports :mod:`moreau.integrators`, which runs no loop in most of
    them. The name, module and docstring are known without building; any
    other attribute (``__code__``, ``__moreau_source__``, ...) and a call
    build the function once and are taken from it.
    """

    def __init__(self, name, namespace, scheme):
        self.__name__ = self.__qualname__ = name
        self.scheme = scheme
        self._namespace = namespace
        self._fn = None

    @property
    def __module__(self):
        return self._namespace["__name__"]

    @property
    def __doc__(self):
        return drive.__doc__

    @property
    def __signature__(self):
        # inspect.signature reads it; not __wrapped__, which inspect.unwrap follows and the
        # doctest finder calls on every module global
        return inspect.signature(self._built())

    def _built(self):
        if self._fn is None:
            self._fn = _splice_template(self.__name__, self._namespace)
        return self._fn

    def __getattr__(self, attr):
        # only what a spliced function has builds it: a probe such as hasattr(t, "py_func")
        # (the disk-cache binding looks for numba functions among a module's globals) must not
        if attr not in _FUNCTION_ATTRS:
            raise AttributeError(attr)
        return getattr(self._built(), attr)

    def __call__(self, *args):
        return self._built()(*args)

    def __repr__(self):
        return f"<loop template {self.__module__}.{self.__name__}>"


def loop_template(name, namespace, scheme):
    """The driver with the step rule of the scheme module whose globals are ``namespace`` spliced in.

    The module holds :data:`STEP_FUNCTIONS` and ``_lcp_step`` (a shared loop
    may take it as an argument, see
    :data:`moreau.integrators._contact_step.SHARED_INDIRECT`); the driver's
    own names are added to ``namespace`` where it lacks them.

    The step rule's source is spliced into the driver's, not called: its
    statements before the marker ``...`` (unpacking the workspace, the
    options and the memory) go before the loop, the rest into the loop, each
    ``return X`` becoming ``status = X`` and a break out of the step. Called
    (even inlined by numba), the step rule unpacked its workspace on every
    step, and the reference counts of its thirty arrays made a step of the
    friction drive about six times slower. Calls of :func:`spliced` helpers
    and of another scheme's step rule are spliced in the same way
    (:class:`_Splicer`). The template's qualified name is ``name`` (numba
    names a function's disk-cache files after it); its source is kept in
    ``__moreau_source__`` for the shared loop's rewrite, and the files
    spliced into it in ``__moreau_sources__``. It is built on first use
    (:class:`_Template`): an import splices nothing. ``scheme`` is the
    scheme's name in the notes of its compiles (``template.scheme``).
    """
    return _Template(name, namespace, scheme)


def _splice_template(name, namespace):
    # loop_template's work, done at the template's first use
    for own in ("np", "OK", "CTL_IA", "grid_step", "record_sample", "borrowed"):
        namespace.setdefault(own, globals()[own])
    tree = ast.parse(_source(drive))
    fdef = tree.body[0]
    fdef.name = name
    if namespace.get("ADAPTIVE_STEPS", False):
        _adaptive(fdef)
    step = namespace["step_rule"].py_func
    sdef = _function_def(step)
    setup, per_step = _split_at_marker(sdef.body)
    if per_step and isinstance(per_step[-1], ast.Return):
        per_step = per_step[:-1]       # the step's `return OK`
    splicer = _Splicer(namespace)
    setup = splicer.stmts(setup)
    per_step = splicer.stmts(per_step)
    # the setups of the step rules it calls run after its own, which gives them their workspace
    setup += splicer.setup
    per_step = _returns_to_breaks(per_step)
    loop_at = next(i for i, st in enumerate(fdef.body) if isinstance(st, ast.While))
    loop = fdef.body[loop_at]
    at = next(i for i, st in enumerate(loop.body) if isinstance(st, ast.Assign)
              and isinstance(st.value, ast.Call) and isinstance(st.value.func, ast.Name)
              and st.value.func.id == "step_rule")
    call = loop.body[at].value
    params = [a.arg for a in sdef.args.args]
    binds = [ast.Assign(targets=[ast.Name(id=p, ctx=ast.Store())], value=arg)
             for p, arg in zip(params, call.args)
             if not (isinstance(arg, ast.Name) and arg.id == p)]
    loop.body[at:at + 1] = _one_exit(per_step)
    fdef.body[loop_at:loop_at] = binds + setup
    _spliced_workspace(fdef.body, splicer)
    _borrow_model_arguments(fdef)
    ast.fix_missing_locations(tree)
    source = ast.unparse(tree)
    code = compile(source, drive.__code__.co_filename, "exec")
    scope = {}
    exec(code, namespace, scope)  # noqa: S102  (the package's own driver and step rule)
    fn = scope[name]
    fn.__qualname__ = name
    fn.__module__ = namespace["__name__"]
    fn.__doc__ = drive.__doc__
    fn.__moreau_source__ = source
    fn.__moreau_sources__ = tuple(sorted(splicer.files))
    return fn


#: the model's functions as a loop template names them (the shared loop's arguments)
MODEL_FUNCTIONS = ("mass_fn", "forces_fn", "contacts_fn", "gaps_fn")


def _borrow_model_arguments(fdef):
    """Every call of a model's function in ``fdef`` takes its lasting arrays as borrowed views.

    A model function with a branch (``if need_gap:``) kept numba's reference
    counts on its array arguments, which LLVM did not prune: atomic operations
    on every call, inlined into the model's own loop or called through a
    pointer by the shared one (the bouncing ball's step spent most of its time
    in them). On a view without memory info
    (:func:`moreau.integrators._contact_step.borrowed`) each is a test of a
    null pointer. A view owns nothing, so only a name that outlives the call is
    borrowed: the loop's arguments and the buffers made before its ``while``
    (and names that only alias them). A name the loop body assigns anew (an
    array made during a step, whose last use may be this call: numba frees it
    right after its last use, before the call would run) is passed as it is,
    and so are constants and expressions.
    """
    loop = next(st for st in fdef.body if isinstance(st, ast.While))
    fresh, aliases = set(), []
    for node in ast.walk(loop):
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                for name in ast.walk(target):
                    if isinstance(name, ast.Name) and isinstance(name.ctx, ast.Store):
                        if isinstance(node, ast.Assign) and isinstance(target, ast.Name) \
                                and isinstance(node.value, ast.Name):
                            aliases.append((name.id, node.value.id))
                        else:
                            fresh.add(name.id)
        elif isinstance(node, (ast.For, ast.comprehension)):
            fresh.update(n.id for n in ast.walk(node.target) if isinstance(n, ast.Name))
    changed = True
    while changed:       # an alias of a fresh name is fresh
        changed = False
        for name, source in aliases:
            if source in fresh and name not in fresh:
                fresh.add(name)
                changed = True
    for node in ast.walk(fdef):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id in MODEL_FUNCTIONS:
            node.args = [ast.Call(func=ast.Name(id="borrowed", ctx=ast.Load()), args=[a],
                                  keywords=[])
                         if isinstance(a, ast.Name) and a.id not in fresh else a
                         for a in node.args]


#: the helpers :func:`loop_template` splices in where a step rule calls them (their Python
#: functions), each with its ``step_returns``
_SPLICED = {}
#: the helpers whose rules (:func:`_check_spliced`) are checked
_CHECKED = set()


def spliced(fn=None, *, step_returns=False):
    """Decorator: a piece of step rule that :func:`loop_template` splices in at each call.

    The helper is written like a numba function; it is also compiled as one
    (``njit(inline="always")``) for a caller that is not spliced. At a call
    ``f(...)``, ``x = f(...)`` or ``a, b = f(...)`` in a step rule (or in
    another helper) its body replaces the call, its locals renamed apart
    and its parameters replaced by the arguments: no call, no arguments
    passed, so the arrays' reference counts cost nothing per step and the
    arithmetic is the caller's own, to the bit. Its parameters are never
    assigned, and its only ``return`` is its last statement, unless
    ``step_returns``: then its other ``return X`` return ``X`` from the step
    rule it is spliced into (a status; such a helper serves step rules only).
    A helper breaking these rules is refused here, or, for the package's own
    helpers, when a template first splices it: reading and parsing their
    sources at import cost every process that imports the schemes half its
    import time.
    """
    if fn is None:
        return functools.partial(spliced, step_returns=step_returns)
    if not fn.__module__.startswith(__package__.split(".")[0] + "."):
        _check_spliced(fn, step_returns)
    _SPLICED[fn] = step_returns
    return njit(inline="always", error_model="numpy")(fn)


def _check_spliced(fn, step_returns):
    """Refuse a :func:`spliced` helper that assigns a parameter or returns early (once a helper)."""
    if fn in _CHECKED:
        return
    fdef = _function_def(fn)
    params = {a.arg for a in fdef.args.args}
    stored = {n.id for n in ast.walk(fdef) if isinstance(n, ast.Name)
              and isinstance(n.ctx, ast.Store)}
    if stored & params:
        raise TypeError(f"spliced helper {fn.__name__} assigns its parameters "
                        f"{sorted(stored & params)}")
    returns = [n for n in ast.walk(fdef) if isinstance(n, ast.Return)]
    body = _strip_docstring(fdef.body)
    if returns and not step_returns and not (len(returns) == 1 and body
                                             and body[-1] is returns[0]):
        raise TypeError(f"spliced helper {fn.__name__} returns before its last statement")
    _CHECKED.add(fn)


def _adaptive(fdef):
    """The driver's loop without its grid: each step starts where the one before ended (``t1``),
    the step rule sets ``t1``, ``hk`` and ``last`` (see the module docstring)."""
    loop_at = next(i for i, st in enumerate(fdef.body) if isinstance(st, ast.While))
    loop = fdef.body[loop_at]

    def assigns(st, nm):
        return isinstance(st, ast.Assign) and any(
            isinstance(n, ast.Name) and n.id == nm for tg in st.targets for n in ast.walk(tg))
    grid = next(i for i, st in enumerate(loop.body) if assigns(st, "tk"))
    loop.body[grid] = ast.parse("tk = t1").body[0]
    loop.body = [st for st in loop.body if not assigns(st, "hn")]
    fdef.body[loop_at:loop_at] = ast.parse("t1 = t0\nhk = h\nlast = False").body


@functools.lru_cache(maxsize=None)
def _source(fn):
    # inspect.getsource tokenizes the file from the function on: importing the schemes splices
    # 54 functions 197 times, and the tokenizing was a fifth of the package's import time
    return textwrap.dedent(inspect.getsource(fn))


def _function_def(fn):
    # parsed afresh at each call: the splicer rewrites the tree it is given
    return ast.parse(_source(fn)).body[0]


@functools.lru_cache(maxsize=None)
def _names(py):
    """``(stored, all)``: the names ``py``'s source assigns, and all the names it holds."""
    nodes = [n for n in ast.walk(_function_def(py)) if isinstance(n, ast.Name)]
    return frozenset(n.id for n in nodes if isinstance(n.ctx, ast.Store)), \
        frozenset(n.id for n in nodes)


def _strip_docstring(body):
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        return body[1:]
    return body


def _marker_at(body):
    return next((i for i, st in enumerate(body) if isinstance(st, ast.Expr)
                 and isinstance(st.value, ast.Constant) and st.value.value is Ellipsis), None)


@functools.lru_cache(maxsize=None)
def _is_step_rule(py):
    """Whether the Python function ``py`` is a step rule (its body holds the marker ``...``)."""
    return _marker_at(_strip_docstring(_function_def(py).body)) is not None


def _split_at_marker(body):
    """A step rule's statements: ``(setup, per_step)``, before and after its ``...``."""
    body = _strip_docstring(body)
    mark = _marker_at(body)
    return body[:mark], body[mark + 1:]


class _Rename(ast.NodeTransformer):
    def __init__(self, names):
        self.names = names

    def visit_Name(self, node):
        if node.id in self.names:
            return ast.copy_location(ast.Name(id=self.names[node.id], ctx=node.ctx), node)
        return node


class _Splicer:
    """Splices the calls of :func:`spliced` helpers and of step rules into a step rule's source.

    A helper's body replaces its call, its last ``return X`` becoming an
    assignment to the call's target. A step rule called by another (the
    projected Moreau–Jean calls Moreau–Jean's) gives its statements before
    ``...`` to :attr:`setup` (they run once a call, after the caller's) and
    the rest replaces the call, its last ``return X`` assigned to the
    target and its other returns the caller's; an argument that is not a
    name is bound once, in :attr:`setup`, so it must not change from step to
    step. The globals a spliced body reads are added to the namespace, under
    another name where the namespace binds the name to something else, except
    the names in the namespace's ``SPLICE_SWITCHES``: compile-time switches of
    the spliced code that the caller's module sets to its own values (numba
    prunes the branches they guard).
    """

    def __init__(self, namespace):
        self.ns = namespace
        self.count = 0
        self.setup = []
        self.files = set()

    def _callee(self, node):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)):
            return None, None
        py = getattr(self.ns.get(node.func.id), "py_func", None)
        if py is None:
            return None, None
        if py in _SPLICED:
            _check_spliced(py, _SPLICED[py])
            return "helper", py
        if _is_step_rule(py):
            return "step", py
        return None, None

    def stmts(self, stmts):
        out = []
        for st in stmts:
            call, target = None, None
            if isinstance(st, ast.Expr):
                call = st.value
            elif isinstance(st, ast.Assign) and len(st.targets) == 1:
                call, target = st.value, st.targets[0]
            kind, py = self._callee(call)
            if kind is None:
                for field in ("body", "orelse"):
                    if isinstance(getattr(st, field, None), list):
                        setattr(st, field, self.stmts(getattr(st, field)))
                out.append(st)
            else:
                out.extend(self._expand(kind, py, call, target))
        return out

    def _expand(self, kind, py, call, target):
        if call.keywords:
            raise TypeError(f"a spliced call of {py.__name__} takes positional arguments only")
        self.count += 1
        tag = f"_{py.__name__.strip('_')}{self.count}_"
        fdef = _function_def(py)
        params = [a.arg for a in fdef.args.args]
        if len(params) != len(call.args):
            raise TypeError(f"{py.__name__} takes {len(params)} arguments, "
                            f"a spliced call gives {len(call.args)}")
        names, bind = {}, []
        for p, arg in zip(params, call.args):
            if isinstance(arg, ast.Name):
                names[p] = arg.id
            else:
                names[p] = tag + p
                bind.append(ast.Assign(targets=[ast.Name(id=tag + p, ctx=ast.Store())],
                                       value=arg))
        stored, read = _names(py)
        for nm in stored - set(params):
            names[nm] = tag + nm
        self._globals(py, read - set(params) - stored, names)
        self.files.add(py.__code__.co_filename)
        body = [_Rename(names).visit(st) for st in _strip_docstring(fdef.body)]
        if kind == "helper":
            setup, per_step = [], body
        else:
            setup, per_step = _split_at_marker(body)
            setup, bind = bind + setup, []
        if per_step and isinstance(per_step[-1], ast.Return):
            ret = per_step.pop()
            if target is not None:
                per_step.append(ast.Assign(targets=[target], value=ret.value))
        self.setup += self.stmts(setup)
        return bind + self.stmts(per_step)

    def _globals(self, py, free, names):
        """Bind the globals ``py``'s body reads (of the names ``free``) in the namespace
        (renamed where taken)."""
        switches = self.ns.get("SPLICE_SWITCHES", ())
        for nm in sorted(free):
            if nm not in py.__globals__:
                continue            # a builtin
            if nm in switches:
                continue            # a compile-time switch the caller's module sets itself
            val = py.__globals__[nm]
            have = self.ns.get(nm, val)
            if have is val or (type(have) is type(val) and isinstance(val, (int, float, bool))
                               and have == val):
                self.ns.setdefault(nm, val)
                continue
            alias = f"{nm}__{py.__module__.rsplit('.', 1)[-1]}"
            self.ns[alias] = val
            names[nm] = alias


def _one_exit(per_step):
    """The step's statements (returns made breaks) in a loop of one pass, left by one edge.

    numba releases every array the driver's loop holds (the workspace's
    fifty and more) on each edge that leaves the loop: one release of each
    per ``break``, a dozen breaks in a step rule. Breaking out of a loop of
    one pass instead, and out of the driver's loop once after it where the
    step did not run to its end, leaves the same steps taken and the same
    status (a ``return`` stops the call whatever its status, as before) and
    cuts the loop's unoptimised code by a tenth or more.
    """
    flag = "_step_done"
    tree = ast.parse(f"{flag} = False\nwhile True:\n    pass\nif not {flag}:\n    break")
    start, once, leave = tree.body
    once.body = per_step + ast.parse(f"{flag} = True\nbreak").body
    return [start, once, leave]


def _spliced_workspace(body, splicer):
    """Build the workspace in the loop's own code, straight into the names that use it.

    A scheme's ``step_workspace`` returns a tuple of fifty and more arrays
    (tuples in it, some), which the step rule unpacks: numba takes a
    reference to each array for the tuple, for the copy the unpacking makes
    and for each name, and drops them again, thousands of lines of
    unoptimised code in every loop. Spliced (where ``step_workspace`` is a
    :func:`spliced` helper) and forwarded (:func:`_forward_tuples`), the
    same arrays are allocated in the same order, with no tuple between.
    """
    while True:
        loop_at = next(i for i, st in enumerate(body) if isinstance(st, ast.While))
        count = splicer.count
        body[:loop_at] = splicer.stmts(body[:loop_at])
        if not _forward_tuples(body) and splicer.count == count:
            return


def _names_in(stmts):
    """Every name ``stmts`` (nodes) assign or read."""
    return {node.id for st in stmts for node in ast.walk(st) if isinstance(node, ast.Name)}


def _unpacked_later(body, i):
    """Where ``body[i]`` is ``x = (a, b, ...)`` whose one use is ``p, q, ... = x`` of as many
    names that the statements between neither assign nor read, nor ``a, b, ...`` read:
    that statement's index, else None."""
    st = body[i]
    if not (isinstance(st, ast.Assign) and len(st.targets) == 1
            and isinstance(st.targets[0], ast.Name) and isinstance(st.value, ast.Tuple)):
        return None
    x = st.targets[0].id
    uses = [j for j in range(len(body)) if j != i and x in _names_in([body[j]])]
    if len(uses) != 1 or uses[0] < i:
        return None
    j = uses[0]
    un = body[j]
    if not (isinstance(un, ast.Assign) and len(un.targets) == 1
            and isinstance(un.targets[0], ast.Tuple) and isinstance(un.value, ast.Name)
            and un.value.id == x and len(un.targets[0].elts) == len(st.value.elts)
            and all(isinstance(t, ast.Name) for t in un.targets[0].elts)):
        return None
    names = {t.id for t in un.targets[0].elts}
    if len(names) < len(un.targets[0].elts) \
            or names & (_names_in(body[i + 1:j]) | _names_in(st.value.elts)):
        return None
    return j


def _forward_tuples(body):
    """Make ``x = (a, b)`` ... ``p, q = x`` into ``p = a; q = b`` where that is the same program
    (:func:`_unpacked_later`); ``a`` a name assigned once before and read nowhere else is
    renamed ``p`` instead of copied. Returns whether it changed ``body``."""
    changed = False
    i = 0
    while i < len(body):
        j = _unpacked_later(body, i)
        if j is None:
            i += 1
            continue
        changed = True
        elts = body[i].value.elts
        targets = [t.id for t in body[j].targets[0].elts]
        del body[j]
        # the names after the tuple (the loop among them), walked once for all its elements:
        # the renames below change only the statements before it
        after = _names_in(body[i + 1:])
        new = []
        for k, (t, e) in enumerate(zip(targets, elts)):
            others = elts[:k] + elts[k + 1:]
            if not (isinstance(e, ast.Name) and e.id not in _names_in(others)
                    and _rename_once_assigned(body, i, e.id, t, after)):
                new.append(ast.Assign(targets=[ast.Name(id=t, ctx=ast.Store())], value=e))
        # the new assignments are looked at again: a tuple among them may be unpacked later
        body[i:i + 1] = new
    return changed


def _rename_once_assigned(body, i, name, to, after):
    """Rename ``name`` ``to`` in ``body[:i]`` where it is assigned once there and is not among
    ``after`` (the names of ``body[i + 1:]``), and ``to`` occurs nowhere before; whether it did."""
    before = body[:i]
    stores = [node for st in before for node in ast.walk(st)
              if isinstance(node, ast.Name) and node.id == name and isinstance(node.ctx, ast.Store)]
    if len(stores) != 1 or name in after or to in _names_in(before):
        return False
    renamer = _Rename({name: to})
    for k in range(i):
        body[k] = renamer.visit(body[k])
    return True


def _has_return(stmts):
    return any(isinstance(n, ast.Return) for st in stmts for n in ast.walk(st))


def _returns_to_breaks(stmts):
    """``return X`` -> ``status = X; break``, and after every loop that held one, a break on."""
    out = []
    for st in stmts:
        if isinstance(st, ast.Return):
            out.append(ast.Assign(targets=[ast.Name(id="status", ctx=ast.Store())],
                                  value=st.value))
            out.append(ast.Break())
        elif isinstance(st, (ast.For, ast.While)):
            had = _has_return(st.body)
            st.body = _returns_to_breaks(st.body)
            st.orelse = _returns_to_breaks(st.orelse)
            out.append(st)
            if had:
                out.append(ast.parse("if status != OK:\n    break").body[0])
        elif isinstance(st, ast.If):
            st.body = _returns_to_breaks(st.body)
            st.orelse = _returns_to_breaks(st.orelse)
            out.append(st)
        else:
            out.append(st)
    return out
