"""Key numba's on-disk cache of a module's functions on every source they compile in.

Numba validates a cached function against the modification time and size of
the one file that defines it (a documented limitation: "changes in symbols
defined in another file are not detected"). A stepper that inlines or links
compiled functions from other modules would therefore keep running stale
machine code after one of those modules is edited, and give silently wrong
answers. :func:`bind_cache_to_sources` adds a digest of the contents of all
the files the functions depend on to the stamp that numba stores in each
cache index and compares on load: when any of them changes, the index no
longer matches, numba compiles again and overwrites the stale entry.

Nothing is written or removed here, so a read-only install is unaffected. If
numba's cache internals are not what this module expects (another numba
version), the functions fall back to compiling in memory each process:
slower, never stale.

Examples
--------
A function bound to its module's sources has no machine code until its
first call (:func:`bind_cache_to_sources`, :func:`has_cached_code`):

>>> from numba import njit
>>> @njit
... def f(x):
...     return x + 1
>>> bind_cache_to_sources([f], [__file__]) in ("bound", "memory")
True
>>> has_cached_code(f), f(1), has_cached_code(f)
(False, 2, True)

Processes that may compile one function together hold :func:`compile_lock`
while they do (without a disk cache, it holds nothing):

>>> with compile_lock(f):
...     f(2)
3
"""

import contextlib
import hashlib
import os
import types

try:
    import fcntl
except ImportError:  # Windows: the compile lock is skipped
    fcntl = None

try:
    # numba's internal cache classes: another numba version may not have this one
    from numba.core.caching import NullCache
except ImportError:
    NullCache = None

__all__ = ["sources_digest", "bind_cache_to_sources", "has_cached_code", "dependency_files",
           "compile_lock", "try_lock"]


def sources_digest(paths):
    """SHA-256 of the contents of ``paths``, in order (unreadable files count as missing).

    Examples
    --------
    >>> import moreau._jit_cache as jc
    >>> len(sources_digest([jc.__file__]))
    64
    """
    hasher = hashlib.sha256()
    for path in paths:
        hasher.update(os.path.basename(path).encode())
        try:
            with open(path, "rb") as fh:
                hasher.update(fh.read())
        except OSError:
            hasher.update(b"<missing>")
    return hasher.hexdigest()


def bind_cache_to_sources(dispatchers, paths):
    """Make the on-disk cache of ``dispatchers`` valid only for the current ``paths``.

    Parameters
    ----------
    dispatchers : iterable of numba dispatchers
        Functions compiled with ``cache=True``, before their first call.
    paths : sequence of str
        Every source file whose compiled code ends up in them (their own
        module included).

    Returns
    -------
    str
        ``"bound"`` when the cache stamps carry the digest, ``"memory"`` when
        caching had to be turned off for at least one function.

    Examples
    --------
    See the module's docstring.
    """
    digest = sources_digest(paths)
    mode = "bound"
    for disp in dispatchers:
        cache = getattr(disp, "_cache", None)
        cache_file = getattr(cache, "_cache_file", None)
        if cache_file is None:
            # not cached on disk (cache=False or a null cache): nothing can go stale
            continue
        stamp = getattr(cache_file, "_source_stamp", None)
        if stamp is None:
            _disable_disk_cache(disp)
            mode = "memory"
            continue
        if isinstance(stamp, tuple) and len(stamp) == 2 and stamp[0] == "moreau-deps":
            # bound already (module reloaded): rebind to the current digest
            stamp = stamp[1][0]
        cache_file._source_stamp = ("moreau-deps", (stamp, digest))
    return mode


def has_cached_code(dispatcher):
    """Whether the first call of ``dispatcher`` will load machine code instead of compiling.

    True when the function has been compiled in this process, or when
    numba's disk cache holds an entry that is fresh for the current sources
    (:func:`bind_cache_to_sources`) and was built for this CPU. False
    otherwise, including when numba's cache internals are not the expected
    ones: the answer only decides whether to tell the user that a compile is
    starting.

    Examples
    --------
    See the module's docstring.
    """
    if getattr(dispatcher, "signatures", None):
        return True
    try:
        index = dispatcher._cache._cache_file._load_index()
        magic = dispatcher.targetctx.codegen().magic_tuple()
        return any(key[1] == magic for key in index)
    except Exception:
        # a null cache, another numba version: nothing known to be on disk
        return False


@contextlib.contextmanager
def compile_lock(dispatcher):
    """Hold a lock file next to ``dispatcher``'s disk cache while it compiles.

    Processes that start together (pytest-xdist workers, a sweep's workers)
    would each compile the same function; with the lock the later ones
    wait and then load the first one's machine code from the cache. Without
    a writable cache folder or ``fcntl`` (Windows) it holds nothing.

    Examples
    --------
    See the module's docstring.
    """
    # no lock to be had (read-only install, no fcntl, other numba internals, a function
    # without a disk cache): compiling twice is slower, never wrong
    fh = _locked(dispatcher, "lock", fcntl.LOCK_EX if fcntl is not None else 0)
    try:
        yield
    finally:
        if fh is not None:
            fh.close()


def _locked(dispatcher, purpose, mode):
    """The lock file ``<function>.moreau-<purpose>`` beside ``dispatcher``'s disk cache, opened
    and locked with ``fcntl.flock(mode)``; None where that fails (or would block, with
    ``LOCK_NB``)."""
    fh = None
    try:
        folder = dispatcher._cache._cache_path
        name = dispatcher.py_func.__qualname__
        fh = open(os.path.join(folder, f"{name}.moreau-{purpose}"), "a")
        fcntl.flock(fh, mode)
        return fh
    except Exception:
        if fh is not None:
            fh.close()
        return None


def try_lock(dispatcher, purpose):
    """An exclusive lock file next to ``dispatcher``'s disk cache, or None if another holds it.

    Does not wait: the caller that gets None leaves to the holder what the
    lock is for (``purpose`` names the file, beside :func:`compile_lock`'s).
    Release it by closing the returned file. None too where there is no lock
    to be had (no writable cache folder, no ``fcntl``).

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import _mass
    >>> first = try_lock(_mass, "example")
    >>> second = try_lock(_mass, "example")      # held by the first (or no lock to be had)
    >>> second is None
    True
    >>> if first is not None:
    ...     first.close()
    """
    return _locked(dispatcher, purpose,
                   fcntl.LOCK_EX | fcntl.LOCK_NB if fcntl is not None else 0)


def dependency_files(functions):
    """Source files of ``functions`` and of every compiled function they call by name.

    Follows globals (``helper(...)``) and module attributes (``mod.helper(...)``)
    that are numba functions, recursively.

    Examples
    --------
    >>> from moreau.scenes.bouncing_ball import _mass
    >>> [p.rsplit("/", 1)[-1] for p in dependency_files([_mass])]
    ['bouncing_ball.py']
    """
    files, seen, todo = [], set(), list(functions)
    while todo:
        f = todo.pop()
        if id(f) in seen:
            continue
        seen.add(id(f))
        py = getattr(f, "py_func", None)
        if py is None:
            continue
        path = py.__code__.co_filename
        if path not in files:
            files.append(path)
        names, codes = set(), [py.__code__]
        while codes:
            code = codes.pop()
            names.update(code.co_names)
            codes.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
        for name in names:
            val = py.__globals__.get(name)
            if isinstance(val, types.ModuleType):
                todo.extend(getattr(val, n) for n in names
                            if hasattr(getattr(val, n, None), "py_func"))
            elif hasattr(val, "py_func"):
                todo.append(val)
    return sorted(files)


def _disable_disk_cache(disp):
    try:
        disp._cache = NullCache() if NullCache is not None else _NoCache()
    except Exception:
        # last resort: a dispatcher without a usable cache object compiles in memory
        disp._cache = _NoCache()


class _NoCache:
    def load_overload(self, sig, target_context):
        return None

    def save_overload(self, sig, data):
        pass

    def flush(self):
        pass
