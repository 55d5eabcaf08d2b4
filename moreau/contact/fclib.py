"""FCLib's HDF5 files of frictional contact problems: write and read the local problem.

FCLib (Frictional Contact Library; Acary, Brémond, Dubois, Huber et al.) is
the field's collection of contact problems. Its local problem is the one of
:mod:`moreau.contact._sparse`: ``u = W r + q``, Coulomb's cones ``mu``,
``spacedim`` 2 or 3. The layout below is the one FCLib's reference
implementation (``src/fclib.h`` of the FrictionalContactLibrary/fclib
repository: ``fclib_write_local``, ``write_matrix``,
``write_local_vectors``, ``write_problem_info``, ``write_solution``) writes
and reads; this module writes it with h5py (the optional extra
``moreau[fclib]``) and reads it back::

    /fclib_local/spacedim            int[1]   2 (or 3)
    /fclib_local/W/{m, n, nz, nzmax} int[1]   nz = -2: CSR, -1: CSC, >= 0: triplet
    /fclib_local/W/p                 int      row (CSR) / column (CSC) pointers; triplet: rows
    /fclib_local/W/i                 int      column (CSR) / row (CSC) indices; triplet: columns
    /fclib_local/W/x                 double   values
    /fclib_local/vectors/q           double[m]
    /fclib_local/vectors/mu          double[m / spacedim]
    /fclib_local/info/{title, description, math_info}   strings (optional)
    /solution/{u, r}                 double[m] (optional)
    /guesses/number_of_guesses       int[1], /guesses/1, /guesses/2, ...: {u, r} (optional)

The ``V``, ``R``, ``s`` of FCLib's local problem with equality constraints
are not read (a file that has them is refused). Rows are interleaved per
contact, ``[N, T]`` in 2D, as :mod:`moreau.contact._sparse` has them.
Writing stores ``W`` as CSR (``nz = -2``); reading accepts the three forms.
The round trip returns the same arrays, bit for bit.
"""

import os
from typing import NamedTuple

import numpy as np
import scipy.sparse as sps

from moreau._validate import finite_array
from moreau.contact._sparse import check_problem
from moreau.errors import InputError

__all__ = ["FCLibProblem", "write_fclib", "read_fclib"]

_INFO = ("title", "description", "math_info")


class FCLibProblem(NamedTuple):
    """An FCLib local problem as read: ``W`` (CSR), ``q``, ``mu``, ``spacedim``, extras."""

    W: sps.csr_array
    q: np.ndarray
    mu: np.ndarray
    spacedim: int
    info: dict
    solution: dict | None
    guesses: list


def _h5py():
    try:
        import h5py
    except ImportError:  # pragma: no cover - depends on the install
        raise InputError("FCLib files need h5py: install the extra `moreau[fclib]`") from None
    return h5py


def _int1(group, name, value):
    group.create_dataset(name, data=np.array([value], dtype=np.int32))


def _string(group, name, text):
    # H5LTmake_dataset_string stores a scalar C string with its terminating null: C readers
    # allocate the stored size and rely on the null
    group.create_dataset(name, data=np.bytes_(text.encode("utf-8") + b"\0"))


def write_fclib(path, W, q, mu, *, title=None, description=None, math_info=None, solution=None,
                guesses=()):
    """Write a 2D local frictional contact problem to an FCLib HDF5 file.

    Parameters
    ----------
    path : str or os.PathLike
        The file; an existing file is refused (FCLib does not overwrite).
    W, q, mu : FCLib-form data (``W`` ``2 nc x 2 nc``, dense or sparse).
    title, description, math_info : str, optional
        FCLib's ``info`` strings.
    solution : (r, u), optional
        A solution to store under ``/solution``.
    guesses : sequence of (r, u)
        Initial guesses, stored under ``/guesses/1``, ``/guesses/2``, ...

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "one.hdf5")
    >>> write_fclib(path, [[1.0, 0.0], [0.0, 1.0]], [-1.0, 1.0], [0.5], title="block")
    >>> p = read_fclib(path)
    >>> p.W.toarray().tolist(), p.q.tolist(), p.mu.tolist(), p.info["title"]
    ([[1.0, 0.0], [0.0, 1.0]], [-1.0, 1.0], [0.5], 'block')
    """
    W, q, mu = check_problem(W, q, mu)
    n = q.shape[0]
    pairs = []
    for name, pair in ([("solution", solution)] if solution is not None else []) + \
            [(f"guesses[{k}]", g) for k, g in enumerate(guesses)]:
        if len(pair) != 2:
            raise InputError(f"`{name}` must be a pair (r, u)")
        pairs.append((finite_array(f"{name}.r", pair[0], shape=(n,)),
                      finite_array(f"{name}.u", pair[1], shape=(n,))))
    for key, text in zip(_INFO, (title, description, math_info)):
        if text is not None and not isinstance(text, str):
            raise InputError(f"`{key}` must be a string, got {type(text).__name__}")
    path = os.fspath(path)
    if os.path.exists(path):
        raise InputError(f"`path` {path!r} exists: FCLib files are written once, not overwritten")
    h5py = _h5py()
    with h5py.File(path, "w") as f:
        root = f.create_group("fclib_local")
        _int1(root, "spacedim", 2)
        g = root.create_group("W")
        _int1(g, "m", n)
        _int1(g, "n", n)
        _int1(g, "nz", -2)
        _int1(g, "nzmax", W.nnz)
        g.create_dataset("p", data=W.indptr.astype(np.int32))
        g.create_dataset("i", data=W.indices.astype(np.int32))
        g.create_dataset("x", data=W.data.astype(np.float64))
        v = root.create_group("vectors")
        v.create_dataset("q", data=q)
        v.create_dataset("mu", data=mu)
        if any(t is not None for t in (title, description, math_info)):
            info = root.create_group("info")
            for key, text in zip(_INFO, (title, description, math_info)):
                if text is not None:
                    _string(info, key, text)
        if solution is not None:
            r, u = pairs.pop(0)
            s = f.create_group("solution")
            s.create_dataset("u", data=u)
            s.create_dataset("r", data=r)
        if pairs:
            gs = f.create_group("guesses")
            _int1(gs, "number_of_guesses", len(pairs))
            for k, (r, u) in enumerate(pairs, start=1):
                s = gs.create_group(str(k))
                s.create_dataset("u", data=u)
                s.create_dataset("r", data=r)


def _bad(path, why):
    return InputError(f"`path` {path!r} is not a readable FCLib local problem: {why}")


def _array(path, group, name, dtype, shape=None):
    if name not in group:
        raise _bad(path, f"{group.name}/{name} is missing")
    obj = group[name]
    if not hasattr(obj, "shape"):
        raise _bad(path, f"{group.name}/{name} is not a dataset")
    try:
        a = np.asarray(obj[()], dtype=dtype)
    except (TypeError, ValueError):
        raise _bad(path, f"{group.name}/{name} does not hold {np.dtype(dtype).name} data") from None
    a = a.reshape(-1) if a.ndim else a.reshape(1)
    if shape is not None and a.shape != (shape,):
        raise _bad(path, f"{group.name}/{name} has {a.size} entries, {shape} expected")
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        raise _bad(path, f"{group.name}/{name} holds NaN or inf")
    return a


def _scalar(path, group, name):
    return int(_array(path, group, name, np.int64, 1)[0])


def _text(obj):
    raw = obj[()]
    if isinstance(raw, np.ndarray):
        raw = raw.tobytes()
    if isinstance(raw, bytes):
        raw = raw.split(b"\0", 1)[0].decode("utf-8", errors="replace")
    return str(raw)


def _matrix(path, g):
    m, n, nz, nzmax = (_scalar(path, g, k) for k in ("m", "n", "nz", "nzmax"))
    if m != n or m <= 0:
        raise _bad(path, f"W is {m} x {n}, a nonempty square matrix expected")
    if nz == -2 or nz == -1:
        p = _array(path, g, "p", np.int64, m + 1)
        i = _array(path, g, "i", np.int64)
        x = _array(path, g, "x", np.float64)
        used = int(p[-1]) if p.size else 0
        if p[0] != 0 or np.any(np.diff(p) < 0) or used > min(i.size, x.size) or used > nzmax:
            raise _bad(path, "W's pointers p are not a compressed-storage index")
        i, x = i[:used], x[:used]
        if i.size and (i.min() < 0 or i.max() >= m):
            raise _bad(path, "W's indices i fall outside the matrix")
        cls = sps.csr_array if nz == -2 else sps.csc_array
        W = cls((x, i, p), shape=(m, n))
    elif nz >= 0:
        rows = _array(path, g, "p", np.int64, nz)
        cols = _array(path, g, "i", np.int64, nz)
        x = _array(path, g, "x", np.float64)
        if x.size < nz:
            raise _bad(path, f"W has {x.size} values for {nz} triplets")
        if nz and (min(rows.min(), cols.min()) < 0 or max(rows.max(), cols.max()) >= m):
            raise _bad(path, "W's triplet indices fall outside the matrix")
        W = sps.coo_array((x[:nz], (rows, cols)), shape=(m, n))
    else:
        raise _bad(path, f"W's storage code nz = {nz} is none of FCLib's (-2, -1, >= 0)")
    return sps.csr_array(W)


def _pair(path, g, n):
    return {"r": _array(path, g, "r", np.float64, n), "u": _array(path, g, "u", np.float64, n)}


def read_fclib(path):
    """Read an FCLib local problem of space dimension 2.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    FCLibProblem
        ``W`` as CSR, ``q``, ``mu``, ``spacedim``, ``info`` (the strings
        present), ``solution`` (``{"r", "u"}`` or None), ``guesses`` (list
        of such dicts).

    Raises
    ------
    InputError
        One line naming the file and what is wrong: no such file, not HDF5,
        no ``/fclib_local``, a missing or malformed dataset, a space
        dimension other than 2, constraints ``V``, ``R`` not supported.

    Examples
    --------
    >>> import os, tempfile
    >>> bad = os.path.join(tempfile.mkdtemp(), "bad.hdf5")
    >>> _ = open(bad, "w").write("not HDF5")
    >>> read_fclib(bad)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `path` '...bad.hdf5' is not a readable FCLib local problem: not an HDF5 file
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise InputError(f"`path` {path!r} is not a file")
    h5py = _h5py()
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise _bad(path, "not an HDF5 file") from None
    with f:
        if "fclib_local" not in f:
            what = "a global problem (/fclib_global)" if "fclib_global" in f else "no /fclib_local group"
            raise _bad(path, what)
        root = f["fclib_local"]
        d = _scalar(path, root, "spacedim")
        if d != 2:
            raise _bad(path, f"space dimension {d}; only 2D problems (spacedim 2) are read")
        if "V" in root or "R" in root:
            raise _bad(path, "it has equality constraints (V, R), which are not supported")
        if "W" not in root or "vectors" not in root:
            raise _bad(path, "/fclib_local/W or /fclib_local/vectors is missing")
        W = _matrix(path, root["W"])
        n = W.shape[0]
        if n % d:
            raise _bad(path, f"W has {n} rows, not a multiple of spacedim {d}")
        q = _array(path, root["vectors"], "q", np.float64, n)
        mu = _array(path, root["vectors"], "mu", np.float64, n // d)
        if np.any(mu < 0.0):
            raise _bad(path, "a friction coefficient mu is negative")
        info = {}
        if "info" in root:
            for key in _INFO:
                if key in root["info"]:
                    info[key] = _text(root["info"][key])
        solution = _pair(path, f["solution"], n) if "solution" in f else None
        guesses = []
        if "guesses" in f:
            k = _scalar(path, f["guesses"], "number_of_guesses")
            for j in range(1, k + 1):
                if str(j) not in f["guesses"]:
                    raise _bad(path, f"/guesses/{j} is missing")
                guesses.append(_pair(path, f["guesses"][str(j)], n))
    return FCLibProblem(W, q, mu, d, info, solution, guesses)
