"""Where and how a result was computed: recorded in every JSON output and sidecar.

Timings without the machine that took them cannot be compared, and a number
without the code that produced it cannot be checked again. :func:`provenance`
gathers what identifies a run: the package and code versions, the versions of
numpy, scipy and numba, the CPU, the number of threads, the time and the
command line.

Examples
--------
>>> p = provenance()
>>> sorted(p)[:4]
['code_version', 'command', 'cpu', 'cpu_count']
>>> p["moreau_version"] == __import__("moreau").__version__
True
>>> p["code_version"].startswith(p["moreau_version"] + "+")
True
"""

import datetime
import hashlib
import importlib.metadata
import os
import pathlib
import platform
import sys

from . import __version__

__all__ = ["provenance", "machine", "code_version"]


def _version(dist):
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def _cpu_name():
    # platform.processor() is empty on many Linux systems; /proc/cpuinfo names the model
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _threads():
    # the BLAS and numba thread counts decide how a timing can be compared
    out = {"numba": None, "omp": os.environ.get("OMP_NUM_THREADS")}
    numba = sys.modules.get("numba")
    if numba is not None:
        out["numba"] = int(numba.config.NUMBA_NUM_THREADS)
    return out


def machine():
    """What identifies the machine that takes a timing, without its host name.

    Two runs on the same hardware give the same dict (a timing history is
    kept per machine: :mod:`moreau.analysis.regression`); the host name is
    left out, so that a rebuilt container or a renamed host keeps its history.

    Returns
    -------
    dict
        ``cpu`` (model name), ``cpu_count``, ``architecture`` (``x86_64``,
        ``arm64`` ...) and ``system`` (``Linux`` ...).

    Examples
    --------
    >>> sorted(machine())
    ['architecture', 'cpu', 'cpu_count', 'system']
    """
    return {"cpu": _cpu_name(), "cpu_count": os.cpu_count(),
            "architecture": platform.machine(), "system": platform.system()}


#: modules that only present results (files, figures, text); editing them keeps the cache
_PRESENTATION = {"cli.py", "provenance.py", "analysis/summary.py",
                 "studies/paper/figures.py", "studies/paper/report.py",
                 "studies/paper/reproduce.py", "studies/paper/atlas.py", "studies/paper/sweeps.py",
                 "analysis/history.py", "studies/paper/tables.py"}


def code_version():
    """Package version plus a hash of the source files that compute results.

    Used as part of the cache key (:mod:`moreau.analysis.engine`): any edit
    of the computing code gives new keys. Modules that only write files,
    figures or text are left out. It hashes the installed files, so it
    identifies the code also outside a git checkout (about 10 ms).

    Examples
    --------
    >>> v = code_version()
    >>> v.startswith("0.") and len(v.split("+")[1]) == 16
    True
    """
    root = pathlib.Path(__file__).resolve().parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        if path.relative_to(root).as_posix() in _PRESENTATION:
            continue
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return f"{__version__}+{h.hexdigest()[:16]}"


#: :func:`provenance`'s argument of that name shadows the function
_code_version = code_version


def provenance(code_version=None):
    """A JSON-ready dict identifying this run.

    Parameters
    ----------
    code_version : str, optional
        The package version and a hash of the computing sources
        (:func:`code_version`); computed here where not given, so that no
        output leaves it out.

    Returns
    -------
    dict
        ``moreau_version``, ``code_version``, ``numpy_version``,
        ``scipy_version``, ``numba_version``, ``python_version``, ``platform``,
        ``cpu``, ``cpu_count``, ``threads``, ``time_utc`` (ISO 8601) and
        ``command`` (the command line).
    """
    if code_version is None:
        code_version = _code_version()
    return {
        "moreau_version": __version__,
        "code_version": code_version,
        "numpy_version": _version("numpy"),
        "scipy_version": _version("scipy"),
        "numba_version": _version("numba"),
        "python_version": platform.python_version(),
        "platform": platform.platform(),
        "cpu": _cpu_name(),
        "cpu_count": os.cpu_count(),
        "threads": _threads(),
        "time_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": " ".join([os.path.basename(sys.argv[0])] + sys.argv[1:]) if sys.argv else "",
    }
