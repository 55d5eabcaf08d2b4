"""Steady states of any periodically driven scene over one of its parameters.

The generic ``moreau sweep``: the points go through the sweep engine
(:func:`moreau.analysis.engine.run_points`: cached, in parallel, a failed
point kept as its ``status``) in segments of neighbours, each point's
shooting started from the previous one's orbit (continuation, with a cold
start where that fails; the ``start`` column), for any registered scene with a periodic
drive (:func:`moreau.analysis.engine.periodic_scene_names`) and any of its
numeric parameters. A scene whose study has its own sweep (the paper's
friction drive, with its valid-range marks) names it in its registry entry
(``SceneEntry.sweep``); ``moreau sweep`` then runs that one.

Outputs: ``OUT/sweep_SCENE_PARAM[_FREQ]_SCHEME.csv`` (tidy: the swept value,
the fixed parameters, the steady state, its energy audit
(:data:`moreau.analysis.energy.ENERGY_COLUMNS`, joules per period), units in
the column names), a JSON
sidecar (scene, parameters, scheme, engine statistics, provenance) and a
figure of the displacement per period and the operation mode.

Examples
--------
>>> rows = run_scene_sweep("stick-slip-motor", "load", [0.0, 0.1], frequency=1000.0,
...                        out=None, progress=False, plot=False, n_jobs=1, log=lambda s: None)
>>> [r["status"] for r in rows], rows[0]["displacement_per_period_m"] > rows[1]["displacement_per_period_m"]
(['ok', 'ok'], True)
"""

import json
import math
import os
import pathlib

import numpy as np

from .._validate import finite_scalar, positive, positive_int
from ..errors import InputError
from ..integrators.base import SchemeOptions
from ..outputs import claim_outputs, write_csv
from ..provenance import provenance
from ..model import registry
from . import engine
from .energy import ENERGY_COLUMNS
from .engine import ED_REFERENCE, check_output_dir, periodic_scene_names
from .scheme_settings import make_scheme

__all__ = ["run_scene_sweep", "plan_points", "sweep_tag", "sweep_values", "VALUE_COLUMNS",
           "MAX_POINTS", "rows_to_xarray", "rows_to_netcdf", "netcdf_attrs", "require_xarray",
           "write_netcdf_beside", "write_points_sidecar", "UNIT_SUFFIXES", "stability_panel"]

#: bound on the points of one sweep (each a steady state: about 1e5 s of CPU at the limit)
MAX_POINTS = 10**5

#: the steady-state columns of a sweep row (SI units in the names)
VALUE_COLUMNS = ("mode", "displacement_per_period_m", "average_velocity_m_per_s",
                 "min_normal_force_N", "periodic_residual", "shooting_iterations",
                 "max_multiplier", "stable", "status", "compute_time_s")


def sweep_values(start, stop, points, scale="linear", names=("START", "STOP", "points")):
    """``points`` values from ``start`` to ``stop``, linear or log-spaced, checked.

    ``names`` are the option names an error message gives; ``START`` and
    ``STOP`` must differ when there are several points (equal ones would
    compute one point several times).

    Examples
    --------
    >>> sweep_values(10, 1000, 3, "log").tolist()
    [10.0, 100.0, 1000.0]
    >>> sweep_values(0.1, 0.1, 2)
    Traceback (most recent call last):
    ...
    moreau.errors.InputError: `START` and `STOP` must differ when `points` > 1, got 0.1 twice
    """
    start = finite_scalar(names[0], start)
    stop = finite_scalar(names[1], stop)
    points = positive_int(names[2], points)
    if points > 1 and start == stop:
        raise InputError(f"`{names[0]}` and `{names[1]}` must differ when `{names[2]}` > 1, "
                         f"got {start:g} twice")
    if points > MAX_POINTS:
        raise InputError(f"`points` = {points:.3g} is more than the limit {MAX_POINTS:.0e} of one "
                         "sweep")
    if scale not in ("linear", "log"):
        raise InputError(f"`scale` must be 'linear' or 'log', got {scale!r}")
    if scale == "log":
        if start <= 0 or stop <= 0:
            raise InputError(f"`{names[0]}` and `{names[1]}` must be > 0 for a log-spaced sweep")
        return np.geomspace(start, stop, points)
    return np.linspace(start, stop, points)


def _column(p):
    return f"{p.name} [{p.unit}]" if p.unit and p.unit != "choice" else p.name


def sweep_tag(scene, parameter, frequency, scheme):
    """File stem of a sweep: scene, parameter, the frequency when fixed, and the scheme's settings.

    Examples
    --------
    >>> sweep_tag("stick-slip-motor", "load", 1000.0, ED_REFERENCE)
    'sweep_stick-slip-motor_load_1000Hz_event-driven'
    """
    parts = [f"sweep_{scene}", parameter]
    if parameter != "frequency":
        parts.append(f"{frequency:g}Hz")
    parts.append(scheme.name)
    if scheme.theta is not None:
        parts.append(f"theta{scheme.theta:g}")
    if scheme.steps_per_period is not None:
        parts.append(f"N{scheme.steps_per_period}")
    parts += [f"{k}{v:g}" if isinstance(v, float) else f"{k}{v}" for k, v in scheme[4]]
    if scheme.rtol is not None and scheme.rtol != ED_REFERENCE.rtol:
        parts.append(f"rtol{scheme.rtol:g}")
    return "_".join(parts)


def plan_points(scene, swept, values, fixed=None, frequency=None):
    """Check a sweep's or an atlas's settings before any work, and say how to make its points.

    Parameters
    ----------
    scene : str
        A registered scene with a periodic drive.
    swept : tuple of str
        The varied parameters (numeric parameters of the scene, or ``"frequency"``).
    values : tuple of array_like
        Their values (SI units), one array per swept parameter.
    fixed, frequency
        As in :func:`run_scene_sweep`.

    Returns
    -------
    entry : SceneEntry
    columns : dict
        Parameter name -> CSV column name (with its unit).
    point : callable
        ``point({name: value})`` -> ``(params, frequency)`` of one engine point.
    frequency : float or None
        The fixed drive frequency (None when it is swept).
    """
    entry = registry.get_entry(scene)
    if entry.name not in periodic_scene_names():
        raise InputError(f"`--scene` must be a periodically driven scene, one of "
                         f"{periodic_scene_names()}; got {scene!r}")
    params = {p.name: p for p in entry.parameters}
    numeric = [n for n, p in params.items() if p.unit != "choice"]
    for name in swept:
        if name not in numeric:
            raise InputError(f"`PARAM` must be a numeric parameter of scene {entry.name!r}, one "
                             f"of {numeric}; got {name!r}")
    fixed = dict(fixed or {})
    for key in fixed:
        if key not in params:
            raise InputError(f"`{key}` is not a parameter of scene {entry.name!r}; its "
                             f"parameters: {', '.join(params)}")
    for name in swept:
        if name in fixed:
            raise InputError(f"`{name}` is swept; do not fix it too")
    for name, vals in zip(swept, values):
        vals = np.asarray(vals, dtype=float).reshape(-1)
        if vals.size == 0 or not np.all(np.isfinite(vals)):
            raise InputError(f"the values of `{name}` must be finite numbers, at least one")
    if "frequency" in swept:
        if frequency is not None or "frequency" in fixed:
            raise InputError("`--frequency` is the swept parameter here; leave it out")
    elif frequency is None:
        frequency = fixed.pop("frequency", None)
        if frequency is None:
            raise InputError(f"`--frequency` is required for a sweep of {', '.join(swept)} "
                             "(drive frequency in Hz)")
    if frequency is not None:
        frequency = positive("frequency", frequency)
    defaults = {k: v for k, v in entry.defaults().items() if k != "frequency"}

    def point(at):
        p = dict(defaults, **fixed)
        f = float(at["frequency"]) if "frequency" in at else frequency
        p.update({k: float(v) for k, v in at.items() if k != "frequency"})
        return p, f

    # every corner of the range must make a valid scene before any work starts
    extremes = [(float(np.min(v)), float(np.max(v))) for v in values]
    for corner in np.array(np.meshgrid(*extremes)).reshape(len(swept), -1).T:
        p, f = point(dict(zip(swept, corner)))
        registry.make_scene(entry.name, frequency=f, **p)
    columns = {n: _column(p) for n, p in params.items()}
    columns["frequency"] = "frequency [Hz]"
    return entry, columns, point, frequency


def run_scene_sweep(scene, parameter, values, fixed=None, frequency=None, scheme=ED_REFERENCE,
                    out="out", cache_dir=None, n_jobs=-1, scheduler=None, progress=True,
                    plot=True, log=print, force=False, continuation=True, netcdf=False):
    """Steady states of the registered scene ``scene`` over ``values`` of ``parameter``.

    Parameters
    ----------
    scene : str
        A registered scene with a periodic drive.
    parameter : str
        One of the scene's numeric parameters, or ``"frequency"``.
    values : array_like
        The swept values, in the parameter's SI unit.
    fixed : dict, optional
        Other parameters of the scene (SI units); the rest keep their defaults.
    frequency : float, optional
        Drive frequency [Hz]; required unless ``parameter`` is ``"frequency"``.
    scheme : moreau.analysis.engine.Scheme or SchemeOptions
        The settings of each point's steady state; a scheme's options object
        (``MoreauJean.Options(theta=0.5)``) takes the default steps per period
        and tolerance of :func:`~moreau.analysis.scheme_settings.make_scheme`.
    out : path-like or None
        Output folder, checked writable before any work; None writes nothing.
    cache_dir : path-like, optional
        The engine's cache (default ``OUT/cache``; none without ``out``).
    force : bool
        Replace the files of an earlier sweep with other settings
        (:func:`moreau.outputs.claim_outputs`); refused otherwise, before any work.
    continuation : bool
        True (default): the values are neighbours, and each point's shooting
        starts from the previous point's orbit (:mod:`moreau.analysis.continuation`:
        a halved step, then a cold start where that fails), in segments of
        :func:`moreau.analysis.engine.line_chunk` points; False: every point
        starts cold. The ``start`` column says which it was.

    netcdf : bool
        Also write the table as ``STEM.nc`` (:func:`write_netcdf_beside`;
        needs xarray, the ``[data]`` extra, checked before any work).

    Returns
    -------
    list of dict
        One tidy row per value.
    """
    if isinstance(scheme, SchemeOptions):
        scheme = make_scheme(scheme)
    values = np.asarray(values, dtype=float).reshape(-1)
    if netcdf:
        if out is None:
            raise InputError("`netcdf` writes a file next to the CSV: give `out`")
        require_xarray("`netcdf`")
    entry, columns, point, frequency = plan_points(scene, (parameter,), (values,), fixed,
                                                   frequency)
    points = [point({parameter: x}) for x in values]
    if out is not None:
        out = check_output_dir(out)
        cache_dir = out / "cache" if cache_dir is None else cache_dir
        stem = out / sweep_tag(entry.name, parameter, frequency, scheme)
        settings = claim_outputs(stem, {
            "scene": entry.name, "parameter": parameter, "values": values.tolist(),
            "frequency_Hz": frequency,
            "fixed": {k: v for k, v in points[0][0].items() if k != parameter},
            "scheme": [scheme.name, scheme.theta, scheme.steps_per_period, scheme.rtol,
                       scheme.options], "continuation": bool(continuation)}, force)
    rows, stats = engine.run_points(points, scheme, cache_dir=cache_dir, n_jobs=n_jobs,
                                    scheduler=scheduler, progress=progress,
                                    desc=f"sweep {parameter}", scene=entry.name, energy=True,
                                    chunk=engine.line_chunk(len(points), n_jobs, continuation),
                                    continuation=bool(continuation))
    swept = columns[parameter]
    table = []
    for x, (p, f), row in zip(values, points, rows):
        r = {swept: float(x), "scene": entry.name, "scheme": scheme.name}
        if parameter != "frequency":
            r[columns["frequency"]] = f
        for name, val in p.items():
            if name != parameter:
                r[columns[name]] = val
        for c in VALUE_COLUMNS:
            r[c] = row.get(c, "" if c in ("mode", "status", "stable") else math.nan)
        r.update(engine.line_columns(row))
        for c in ENERGY_COLUMNS:
            r[c] = row.get(c, "" if c == "energy_status" else math.nan)
        table.append(r)
    if out is None:
        return table
    csv_path = stem.with_name(stem.name + ".csv")
    write_csv(csv_path, table)
    meta = {"scene": entry.name, "swept_parameter": swept, "points": int(values.size),
            "range": [float(values.min()), float(values.max())], "frequency_Hz": frequency,
            "fixed_parameters": {k: v for k, v in points[0][0].items() if k != parameter},
            "scheme": scheme.record,
            "continuation": bool(continuation),
            "engine": stats, "provenance": provenance(engine.code_version()),
            "settings": settings}
    write_points_sidecar(stem, meta, csv_path, len(table), stats, log)
    if netcdf:
        write_netcdf_beside(stem, table, [swept], log)
    if plot:
        fig_path = stem.with_name(stem.name + ".png")
        _figure(table, swept, entry.name, fig_path)
        log(f"wrote {fig_path}")
    return table


def _figure(table, swept, scene, path):
    import matplotlib  # noqa: PLC0415  (figures only)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    x = np.array([r[swept] for r in table])
    d = np.array([r["displacement_per_period_m"] for r in table], dtype=float)
    modes = [r["mode"] if r["status"] == "ok" else "failed" for r in table]
    fig, (ax, sax) = plt.subplots(2, 1, figsize=(7, 6), sharex=True,
                                  gridspec_kw={"height_ratios": [1.6, 1.0]})
    stability_panel(sax, x, table)
    ax.plot(x, d * 1e6, "k-", lw=0.8)
    for m in sorted(set(modes)):
        sel = np.array([mm == m for mm in modes])
        ax.plot(x[sel], np.where(np.isfinite(d[sel]), d[sel] * 1e6, 0.0), "o", ms=4, label=m)
    ax.axhline(0.0, color="0.7", lw=0.5)
    sax.set_xlabel(swept)
    ax.set_ylabel("displacement per period [um]")
    ax.set_title(f"{scene}: steady state")
    ax.legend(title="mode", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def stability_panel(ax, x, rows):
    """Draw the largest Floquet multiplier's modulus of every point against ``x`` on ``ax``.

    The unit circle is the line at 1: a point above it is unstable (drawn
    red), the distance below it the stability margin. Points without
    multipliers are left out.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> rows = [{"max_multiplier": m, "stable": m < 1} for m in (0.05, 0.99, 1.2)]
    >>> stability_panel(ax, np.array([1.0, 2.0, 3.0]), rows)
    2
    >>> plt.close(fig)
    """
    m = np.array([r.get("max_multiplier", math.nan) for r in rows], dtype=float)
    stable = np.array([r.get("stable") is True or r.get("stable") == "True" for r in rows])
    ok = np.isfinite(m)
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="|λ| = 1 (unit circle)")
    ax.plot(x[ok], m[ok], "-", color="0.6", lw=0.8)
    ax.plot(x[ok & stable], m[ok & stable], "o", ms=3, color="#0077bb", label="stable")
    ax.plot(x[ok & ~stable], m[ok & ~stable], "o", ms=3, color="#cc3311", label="unstable")
    ax.set_ylabel("largest |Floquet multiplier|")
    ax.set_ylim(0.0, max(1.1, float(np.nanmax(m)) * 1.05) if ok.any() else 1.1)
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3, lw=0.5)
    return int(np.count_nonzero(ok & stable))


#: units of the columns named with their unit at the end (``displacement_per_period_m``)
UNIT_SUFFIXES = (("_m_per_s", "m/s"), ("_Hz", "Hz"), ("_rad", "rad"), ("_N", "N"),
                 ("_J", "J"), ("_W", "W"), ("_s", "s"), ("_m", "m"))


def _split_unit(column):
    """``(name, unit)`` of a column: ``"load [N]"`` -> ``("load", "N")``,
    ``"min_normal_force_N"`` -> ``("min_normal_force_N", "N")``, ``"mu"`` -> ``("mu", "")``."""
    name, _, unit = column.partition(" [")
    if unit.endswith("]"):
        return name, unit[:-1]
    for suffix, unit in UNIT_SUFFIXES:
        if column.endswith(suffix):
            return column, unit
    return column, ""


def require_xarray(what="`rows_to_netcdf`"):
    """The xarray module, or an ImportError naming ``what`` and the extra that installs it.

    Raises
    ------
    ImportError
        xarray is not installed (the command line turns it into a refusal
        of its option before any work).
    """
    try:
        import xarray  # noqa: PLC0415  (optional: the [data] extra)
    except ImportError:
        raise ImportError(f"{what} needs xarray, which is not installed: "
                          "pip install -e \".[data]\"") from None
    return xarray


def netcdf_attrs(meta):
    """``meta`` (a sidecar's dict) as attributes a NetCDF file can hold.

    NetCDF attributes are text, numbers or flat numeric arrays (in the
    classic format that scipy writes: no 64-bit integers, no booleans, no
    None). Text, floats and 32-bit integers stay; a list of numbers becomes
    a float array; anything else (dicts, None, booleans, mixed lists, large
    integers) becomes its JSON text, which :func:`json.loads` reads back.
    Names are kept to letters, digits and ``_.@+-``.

    Examples
    --------
    >>> netcdf_attrs({"points": 3, "range": [1, 2], "stable": True, "fixed": {"mu": 0.1},
    ...               "rtol": None, "scene": "friction-drive", "bad key": 2**40})
    {'points': 3, 'range': array([1., 2.]), 'stable': 'true', 'fixed': '{"mu": 0.1}', 'rtol': 'null', 'scene': 'friction-drive', 'bad_key': '1099511627776'}
    """
    out = {}
    for key, val in meta.items():
        name = "".join(c if c.isalnum() or c in "_.@+-" else "_" for c in str(key))
        if isinstance(val, (bool, np.bool_)) or val is None:
            out[name] = json.dumps(bool(val) if val is not None else None)
        elif isinstance(val, str):
            out[name] = val
        elif isinstance(val, (int, np.integer)):
            out[name] = int(val) if -2**31 <= val < 2**31 else json.dumps(int(val))
        elif isinstance(val, (float, np.floating)):
            out[name] = float(val)
        elif isinstance(val, (list, tuple)) and val and all(
                isinstance(v, (int, float, np.number)) and not isinstance(v, (bool, np.bool_))
                for v in val):
            out[name] = np.asarray(val, dtype=float)
        else:
            out[name] = json.dumps(val, default=str)
    return out


def rows_to_netcdf(rows, dims, path, attrs=None):
    """Write a sweep's or an atlas's rows as a NetCDF file (xarray, the ``[data]`` extra).

    Parameters
    ----------
    rows, dims
        As in :func:`rows_to_xarray`: the swept columns become coordinates,
        every other column a variable with its ``units`` attribute.
    path : path-like
        The file, replaced as a whole (written to a temporary name first).
    attrs : dict, optional
        Global attributes, e.g. the JSON sidecar's content (scene, scheme,
        settings, provenance), made NetCDF-legal by :func:`netcdf_attrs`.

    Returns
    -------
    pathlib.Path

    Notes
    -----
    xarray picks its engine: netCDF4 or h5netcdf where installed, else
    scipy's writer of the classic format (NetCDF 3), which needs no other
    package. Text columns are written as UTF-8 characters.

    Examples
    --------
    >>> import pathlib, tempfile, xarray
    >>> rows = [{"frequency [Hz]": f, "displacement_per_period_m": 2e-6 * f, "mode": "NP"}
    ...         for f in (10.0, 20.0)]
    >>> p = rows_to_netcdf(rows, ["frequency [Hz]"], pathlib.Path(tempfile.mkdtemp()) / "s.nc",
    ...                    {"scene": "friction-drive", "points": 2})
    >>> with xarray.open_dataset(p) as ds:
    ...     ds["displacement_per_period_m"].attrs["units"], ds.attrs["scene"], str(ds["mode"][1].values)
    ('m', 'friction-drive', 'NP')
    """
    require_xarray("`rows_to_netcdf`")
    ds = rows_to_xarray(rows, dims)
    for name in list(ds.data_vars):
        var = ds[name]
        if var.dtype == object:
            # text columns may hold True/False (``stable``) next to "": all written as text
            text = np.vectorize(str, otypes=[object])(var.values)
            ds[name] = var.copy(data=text)
    ds.attrs = netcdf_attrs(attrs or {})
    path = pathlib.Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        ds.to_netcdf(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def write_points_sidecar(stem, meta, csv_path, points, stats, log=print):
    """Write ``meta`` as ``STEM.json``, the sidecar of the table at ``csv_path`` (a sweep's, an
    atlas's), and log both with the table's ``points`` and the engine's ``stats`` (computed,
    from the cache). Returns the sidecar's path."""
    json_path = pathlib.Path(stem).with_name(pathlib.Path(stem).name + ".json")
    json_path.write_text(json.dumps(meta, indent=1, default=str))
    log(f"wrote {csv_path} ({points} points: {stats['computed']} computed, "
        f"{stats['cached']} from the cache) and {json_path.name}")
    return json_path


def write_netcdf_beside(stem, rows, dims, log=print):
    """Write ``STEM.nc`` from a table's rows, ``STEM.json``'s content as its global attributes.

    The NetCDF twin of a command's CSV (``--netcdf``): the same rows on the
    grid of ``dims`` (:func:`rows_to_netcdf`), with the sidecar's scene,
    scheme, settings and provenance. Returns the path.
    """
    stem = pathlib.Path(stem)
    side = stem.with_name(stem.name + ".json")
    attrs = json.loads(side.read_text()) if side.exists() else {}
    path = rows_to_netcdf(rows, dims, stem.with_name(stem.name + ".nc"), attrs)
    log(f"wrote {path}")
    return path


def rows_to_xarray(rows, dims):
    """A sweep's or an atlas's tidy rows as an :class:`xarray.Dataset` (xarray is optional).

    Parameters
    ----------
    rows : list of dict
        Rows as written to the CSV (``"name [unit]"`` column names).
    dims : list of str
        The swept columns (one for a sweep, two for an atlas), as named in
        the rows; they become the dataset's coordinates, sorted.

    Returns
    -------
    xarray.Dataset
        One variable per other column on the grid of ``dims`` (NaN, or an
        empty string, where a combination has no row), named without the
        unit, which goes to the variable's ``units`` attribute; a column
        named with its unit at the end (``min_normal_force_N``,
        :data:`UNIT_SUFFIXES`) keeps its name and gets the attribute too.

    Examples
    --------
    >>> rows = [{"mu": 0.1, "frequency [Hz]": f, "displacement_per_period_m": 2 * f,
    ...          "mode": "NP"} for f in (10.0, 20.0)]
    >>> ds = rows_to_xarray(rows, ["frequency [Hz]"])
    >>> ds["displacement_per_period_m"].values.tolist(), ds["frequency"].attrs["units"]
    ([20.0, 40.0], 'Hz')
    """
    xr = require_xarray("`rows_to_xarray`")
    if not rows:
        raise InputError("`rows` must hold at least one row")
    for d in dims:
        if d not in rows[0]:
            raise InputError(f"`dims` must name columns of the rows; {d!r} is not one of "
                             f"{list(rows[0])}")
    axes = [sorted({float(r[d]) for r in rows}) for d in dims]
    index = [{v: k for k, v in enumerate(ax)} for ax in axes]
    shape = tuple(len(ax) for ax in axes)
    names = [_split_unit(d)[0] for d in dims]
    coords = {}
    for d, name, ax in zip(dims, names, axes):
        unit = _split_unit(d)[1]
        coords[name] = xr.Variable(name, np.array(ax), attrs={"units": unit} if unit else {})
    data = {}
    for col in rows[0]:
        if col in dims:
            continue
        numeric = all(isinstance(r.get(col), (int, float, np.number)) and
                      not isinstance(r.get(col), bool) for r in rows)
        arr = np.full(shape, np.nan) if numeric else np.full(shape, "", dtype=object)
        for r in rows:
            arr[tuple(ix[float(r[d])] for ix, d in zip(index, dims))] = r.get(col)
        name, unit = _split_unit(col)
        data[name] = xr.Variable(names, arr, attrs={"units": unit} if unit else {})
    return xr.Dataset(data, coords=coords)
