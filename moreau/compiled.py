"""The compiled form of a scene's model: how any scene gets the compiled Moreau–Jean loop.

A scene's Python methods (``mass``, ``forces``, ``gaps``, ...) define its
model. To run Moreau–Jean at compiled speed, a scene's ``compiled_model()``
also returns a :class:`CompiledModel`: the same equations as a few
``numba.njit`` functions and a float vector ``par`` of parameters. Each
scheme's compiled step loop takes these functions as arguments, so it is
compiled once for every model (``moreau.integrators._loops``) and kept in
numba's disk cache; a long run moves on to a loop compiled for the model
itself, kept on disk too when the functions live in an importable module.
Functions defined in ``__main__`` or a notebook work too; their own loop is
compiled again in each process.

Nothing in the package has to change for a new scene: the shipped scenes
use this same hook, each in its own module.

The functions and the layout of their outputs (the engine zero-fills every
output once; a function writes the same entries on every call and may
leave the structural zeros alone):

``mass(par, q, M)``
    the mass matrix into ``M`` (ndof, ndof).
``forces(par, q, v, t, D, need_jac)``
    ``D`` (ndof, 1 + 2 ndof): the forces ``h`` in column 0; when
    ``need_jac`` and the model ``has_jacobians``, ``K = dh/dq`` in columns
    ``1 .. ndof`` and ``C = dh/dv`` after them.
``contacts(par, q, t, G, need_gap, need_T)``
    row ``i`` of ``G`` (ncontacts, 3 + 2 ndof) is ``(g_i, wN_i, wT_i, WN_i,
    WT_i)``: the gap (only when ``need_gap``), the rheonomic terms ``wN``
    and ``wT``, the normal row ``WN_i`` and one tangential row ``WT_i`` per
    contact (only when ``need_T``). The engine reads a contact's tangential
    entries only where its ``mu > 0``.
``drift(par, q, v, t, Dr)``
    ``Dr`` (ncontacts, 2) = ``(wNbar_i, wTbar_i)``: the velocity-dependent
    parts of the contact accelerations (``d/dt (W v + w) = W a + wbar``).
    ``None`` where they are zero: rows ``W`` and terms ``w`` that do not
    change along the motion (a fixed flat obstacle in these coordinates).
``gaps(par, q, t, G)`` (optional)
    column 0 of ``G`` alone; without it the engine calls ``contacts`` with
    ``need_gap=True, need_T=False``.

``par`` belongs to the model: its functions may also keep values there from
one call to the next, as long as each output depends on the arguments alone
(the friction drive keeps the sines and cosines of its last angle and phase,
:func:`memo_sincos`).

:func:`check_compiled_model` (and :func:`moreau.check_scene`) hold every
function to the scene's Python methods.

Examples
--------
A ball of radius ``par[0]`` above the floor, under gravity:

>>> import numpy as np
>>> from numba import njit
>>> @njit
... def mass(par, q, M):
...     M[0, 0] = 1.0
>>> @njit
... def forces(par, q, v, t, D, need_jac):
...     D[0, 0] = -1.0
>>> @njit
... def contacts(par, q, t, G, need_gap, need_T):
...     if need_gap:
...         G[0, 0] = q[0] - par[0]
...     G[0, 3] = 1.0
>>> model = CompiledModel(mass, forces, contacts, None, par=[0.1], ndof=1, ncontacts=1,
...                       const_mass=True, has_jacobians=False)
>>> model.ndof, float(model.par[0])
(1, 0.1)

The floor's row is constant, so its drift terms are zero: ``drift=None``.
"""

import dataclasses
import math
from typing import Any, Optional

import numpy as np
from numba import njit

from . import _jit_cache
from .errors import InputError

__all__ = ["CompiledModel", "evaluate_compiled", "check_compiled_model", "MODEL_FUNCTIONS",
           "memo_sincos", "zero_drift"]

#: the function fields of a :class:`CompiledModel`, required ones first
MODEL_FUNCTIONS = ("mass", "forces", "contacts", "drift", "gaps")
_REQUIRED = ("mass", "forces", "contacts")


@njit(cache=True)
def zero_drift(par, q, v, t, Dr):
    """The drift of a model whose contact rows do not change: ``Dr = 0`` (``drift=None``).

    Examples
    --------
    >>> Dr = np.ones((2, 2))
    >>> zero_drift(np.zeros(1), np.zeros(1), np.zeros(1), 0.0, Dr)
    >>> Dr.tolist()
    [[0.0, 0.0], [0.0, 0.0]]
    """
    Dr[:, :] = 0.0


def _is_jitted(f):
    # a numba dispatcher (njit/jit); checked by its interface so that this
    # module does not import numba's internals
    return callable(f) and hasattr(f, "py_func") and hasattr(f, "signatures")


@dataclasses.dataclass(frozen=True, eq=False)
class CompiledModel:
    """A scene's equations as ``numba.njit`` functions, with their parameters.

    Parameters
    ----------
    mass, forces, contacts : numba dispatchers
        The model functions (see the module docstring for their signatures
        and output layouts).
    drift : numba dispatcher or None
        The drift terms; ``None`` where they are zero (constant contact rows):
        the model then takes :func:`zero_drift`.
    par : array_like of float
        Parameters passed to every function as a float64 vector.
    ndof, ncontacts : int
        Degrees of freedom (>= 1) and contacts (>= 0) of the scene.
    const_mass : bool
        ``M`` does not depend on ``q`` (it is evaluated once).
    has_jacobians : bool
        ``dh/dq`` or ``dh/dv`` is not identically zero (the implicit part of
        the θ-method reads them).
    gaps : numba dispatcher, optional
        The gaps alone (see the module docstring).
    """

    mass: Any
    forces: Any
    contacts: Any
    drift: Any
    par: Any
    ndof: int
    ncontacts: int
    const_mass: bool
    has_jacobians: bool
    gaps: Optional[Any] = None

    def __post_init__(self):
        if self.drift is None:
            object.__setattr__(self, "drift", zero_drift)
        for name in MODEL_FUNCTIONS:
            f = getattr(self, name)
            if f is None and name not in _REQUIRED:
                continue
            if not _is_jitted(f):
                raise InputError(f"`{name}` must be a numba.njit function, got "
                                 f"{type(f).__name__}")
        for name in ("ndof", "ncontacts"):
            val = getattr(self, name)
            if isinstance(val, bool) or not isinstance(val, (int, np.integer)):
                raise InputError(f"`{name}` must be an integer, got {val!r}")
        if self.ndof < 1:
            raise InputError(f"`ndof` must be >= 1, got {self.ndof}")
        if self.ncontacts < 0:
            raise InputError(f"`ncontacts` must be >= 0, got {self.ncontacts}")
        for name in ("const_mass", "has_jacobians"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise InputError(f"`{name}` must be True or False, got {getattr(self, name)!r}")
        par = np.asarray(self.par)
        if par.dtype.kind not in "fiu" or par.ndim > 1:
            raise InputError(f"`par` must be a vector of real numbers, got dtype {par.dtype} "
                             f"and shape {par.shape}")
        par = np.ascontiguousarray(par, dtype=np.float64).reshape(-1)
        if not np.all(np.isfinite(par)):
            raise InputError("`par` must be finite")
        if par.size == 0:
            # the engine passes par as float64[::1]: keep one slot so that every model
            # compiles to the same argument type
            par = np.zeros(1)
        object.__setattr__(self, "par", par)
        object.__setattr__(self, "ndof", int(self.ndof))
        object.__setattr__(self, "ncontacts", int(self.ncontacts))
        object.__setattr__(self, "const_mass", bool(self.const_mass))
        object.__setattr__(self, "has_jacobians", bool(self.has_jacobians))
        _bind_caches(self.functions().values())

    def functions(self):
        """``{name: function}`` of the functions given (``gaps`` only when set)."""
        return {k: getattr(self, k) for k in MODEL_FUNCTIONS if getattr(self, k) is not None}


def _bind_caches(functions):
    """Tie the disk cache of each model function to its sources before any use in this process.

    Whichever path uses a function first (a scene's Python methods, a compiled
    loop, a check), its cache entry then carries the same stamp
    (:func:`moreau._jit_cache.bind_cache_to_sources`): with the stamp set by
    some paths only, a process that came in by the other one found the entry
    stale, compiled the function again and overwrote it for the next.
    """
    for f in functions:
        if getattr(f, "_moreau_cache_bound", False) or getattr(f, "signatures", None):
            # bound already, or compiled (or loaded) in this process: its stamp is used
            continue
        _jit_cache.bind_cache_to_sources([f], _jit_cache.dependency_files([f]))
        try:
            f._moreau_cache_bound = True
        except AttributeError:
            pass


def evaluate_compiled(model, q, v, t):
    """Every output of ``model``'s functions at ``(q, v, t)``, as a dict of arrays.

    Each output is computed as the engine calls it (gaps, forces with their
    Jacobians, normal rows alone and full rows).
    """
    n, nc = model.ndof, model.ncontacts
    q = np.ascontiguousarray(q, dtype=float)
    v = np.ascontiguousarray(v, dtype=float)
    t = float(t)
    M = np.zeros((n, n))
    D = np.zeros((n, 1 + 2 * n))
    G = np.zeros((max(nc, 1), 3 + 2 * n))
    G2 = np.zeros_like(G)
    Dr = np.zeros((max(nc, 1), 2))
    par = model.par
    model.mass(par, q, M)
    model.forces(par, q, v, t, D, True)
    model.contacts(par, q, t, G, True, True)
    model.contacts(par, q, t, G2, False, False)
    model.drift(par, q, v, t, Dr)
    out = {"mass": M, "forces": D[:, 0], "K": D[:, 1:1 + n], "C": D[:, 1 + n:],
           "gaps": G[:nc, 0], "wN": G[:nc, 1], "wT": G[:nc, 2], "WN": G[:nc, 3:3 + n],
           "WT": G[:nc, 3 + n:], "WN_normal_only": G2[:nc, 3:3 + n],
           "wN_normal_only": G2[:nc, 1], "wNbar": Dr[:nc, 0], "wTbar": Dr[:nc, 1]}
    if model.gaps is not None:
        G3 = np.zeros_like(G)
        model.gaps(par, q, t, G3)
        out["gaps_alone"] = G3[:nc, 0]
    return out


def check_compiled_model(scene, q, v, t):
    """Largest difference between ``scene``'s compiled model and its Python methods at ``(q, v, t)``.

    Compares ``M``, ``h``, ``dh/dq``, ``dh/dv``, gaps, ``WN``, ``wN``, the
    tangential rows of the frictional contacts and the drift terms, each
    relative to ``max(1, |Python value|)``, and the optional ``gaps``
    function against the Python gaps.

    Returns
    -------
    float
        The largest scaled difference; the caller decides what is acceptable.

    Examples
    --------
    >>> from moreau.scenes import BouncingBall
    >>> ball = BouncingBall()
    >>> check_compiled_model(ball, [1.0], [-0.5], 0.3) <= 1e-12
    True
    """
    model = scene.compiled_model()
    c = evaluate_compiled(model, q, v, t)
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    fr = scene.frictional_index
    K, Cj = scene.force_jacobians(q, v, t)
    WN, wN, WT, wT = scene.contact_jacobians(q, t)
    wNb, wTb = scene.contact_drift(q, v, t)
    pairs = [(c["mass"], scene.mass(q)), (c["forces"], scene.forces(q, v, t)),
             (c["K"], K), (c["C"], Cj), (c["gaps"], scene.gaps(q, t)),
             (c["WN"], WN), (c["wN"], wN), (c["WN_normal_only"], WN),
             (c["wN_normal_only"], wN), (c["WT"][fr], WT), (c["wT"][fr], wT),
             (c["wNbar"], wNb), (c["wTbar"][fr], wTb)]
    if "gaps_alone" in c:
        pairs.append((c["gaps_alone"], scene.gaps(q, t)))
    worst = 0.0
    for a, b in pairs:
        b = np.asarray(b, dtype=float)
        a = np.asarray(a, dtype=float).reshape(b.shape)
        if b.size:
            worst = max(worst, float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b)))))
    return worst


@njit(cache=True)
def memo_sincos(par, j, x):
    """``(sin x, cos x)``, from ``par[j + 1], par[j + 2]`` when ``par[j]`` is ``x``, else computed and kept there.

    A scheme's step evaluates a model's functions several times at one time
    and one state (a Moreau–Jean step of a drive: three times at the angle it
    starts from, once at the one it ends at; the next step starts from that
    angle): a driven angle and a harmonic's phase are then the same from call
    to call, and their sines and cosines are computed once (LLVM fuses the two
    into one ``sincos``). The kept values are those the library returns for
    that argument, so every result is the same to the last bit; a zero hits
    only a zero of its own sign (``sin(-0.0)`` is ``-0.0``). The three slots
    start at ``(0, 0, 1)``, consistent.

    Examples
    --------
    >>> import numpy as np
    >>> par = np.array([0.0, 0.0, 1.0])
    >>> memo_sincos(par, 0, 0.5) == (np.sin(0.5), np.cos(0.5)), float(par[0])
    (True, 0.5)
    """
    key = par[j]
    if x == key and (x != 0.0 or math.copysign(1.0, x) == math.copysign(1.0, key)):
        return par[j + 1], par[j + 2]
    s = math.sin(x)
    c = math.cos(x)
    par[j] = x
    par[j + 1] = s
    par[j + 2] = c
    return s, c
