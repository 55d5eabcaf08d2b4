"""Output files that never silently replace the results of a run with other settings.

A command that writes ``STEM.csv`` and its sidecar ``STEM.json`` records in
the sidecar the settings that decide the file's content (``settings``). A
later run that would write the same names with other settings is refused
before any work, naming what differs, unless it is given ``force``; a rerun
with the same settings (a resumed run) replaces the files, which it computes
anew with the same content.
"""

import csv
import json
import pathlib

from .errors import InputError

__all__ = ["claim_outputs", "write_csv"]


def _normal(settings):
    # the form the sidecar stores: JSON types, keys sorted
    return json.loads(json.dumps(settings, sort_keys=True, default=str))


def claim_outputs(stem, settings, force=False):
    """Check that ``STEM.csv``/``STEM.json`` may be written by a run with ``settings``.

    Parameters
    ----------
    stem : path-like
        Output path without its suffix.
    settings : dict
        What decides the content (parameters, ranges, scheme, ...), not how it
        is computed (workers, cache, scheduler).
    force : bool
        Replace files of a run with other settings.

    Returns
    -------
    dict
        ``settings`` in the JSON form to store in the sidecar under ``"settings"``.

    Raises
    ------
    InputError
        The files exist from a run with other settings (or of unknown
        settings) and ``force`` is false.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> stem = pathlib.Path(tempfile.mkdtemp()) / "sweep_mu"
    >>> claim_outputs(stem, {"points": 5})
    {'points': 5}
    >>> _ = stem.with_name("sweep_mu.json").write_text('{"settings": {"points": 9}}')
    >>> claim_outputs(stem, {"points": 5})
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `--out` already holds sweep_mu.csv/.json from a run with other settings (points): give `--force` to replace them, or another `--out`
    """
    stem = pathlib.Path(stem)
    new = _normal(settings)
    side = stem.with_name(stem.name + ".json")
    table = stem.with_name(stem.name + ".csv")
    if force or not (side.exists() or table.exists()):
        return new
    try:
        old = json.loads(side.read_text()).get("settings")
    except (OSError, ValueError, AttributeError):
        old = None
    if old == new:
        return new
    if isinstance(old, dict):
        differ = ", ".join(sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k)))
    else:
        differ = "not recorded"
    raise InputError(f"`--out` already holds {stem.name}.csv/.json from a run with other "
                     f"settings ({differ}): give `--force` to replace them, or another `--out`")


def write_csv(path, rows, fields=None, **options):
    """Write the dicts ``rows`` to the CSV file ``path``, a header first.

    ``fields`` are the columns (default: the first row's keys); ``options``
    go to :class:`csv.DictWriter` (``extrasaction``, ``restval``).

    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "t.csv")
    >>> write_csv(p, [{"a": 1, "b": 2.5}]) == p, open(p).read().split()
    (True, ['a,b', '1,2.5'])
    """
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0] if fields is None else fields), **options)
        w.writeheader()
        w.writerows(rows)
    return path
