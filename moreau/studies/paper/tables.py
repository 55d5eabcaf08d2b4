"""Tidy tables of the friction-drive studies: columns with units, rows, CSV files, JSON sidecars.

Shared by ``moreau reproduce`` (:mod:`~moreau.studies.paper.reproduce`),
``moreau sweep`` (:mod:`~moreau.studies.paper.sweeps`), the atlases, the
figures and the report, so that each of them reads and writes the same
columns. It sits below all of them and imports none of them.
"""

import csv
import json
import math
import sys
from dataclasses import asdict

from ... import __version__
from ...analysis.energy import ENERGY_COLUMNS
from ...analysis.engine import ED_REFERENCE, code_version, mj_check_columns
from ...provenance import provenance
from .valid_range import lift_off_margin

__all__ = ["SWEPT_COLUMN", "PARAM_COLUMNS", "VALUE_COLUMNS", "sweep_point", "tidy_rows",
           "write_table", "read_table", "write_sidecar", "run_columns"]

SWEPT_COLUMN = {"frequency": "frequency_Hz", "mu": "mu", "phi0": "phi0_rad"}
PARAM_COLUMNS = {"frequency": "frequency_Hz", "m": "m_kg", "m2": "m2_kg", "k": "k_N_per_m",
                 "length": "length_m", "phi0": "phi0_rad", "mu": "mu", "x10": "x10_m",
                 "load": "load_N", "restitution": "restitution",
                 # the bidirectional drive's own parameters (moreau.studies.bidirectional.bidirectional_sweep)
                 "x10_a": "x10_a_m", "x10_b": "x10_b_m", "phase": "phase_rad",
                 "balance": "balance"}
VALUE_COLUMNS = ["mode", "displacement_per_period_m", "average_velocity_m_per_s",
                 "min_normal_force_N", "painleve_margin", "lift_off_margin", "periodic_residual",
                 "shooting_iterations", "max_multiplier", "stable", "status"]


def sweep_point(params, parameter, value, frequency):
    """The engine's ``(params dict, frequency)`` of one sweep value (validated by ``with_``).

    Examples
    --------
    >>> from moreau.scenes.friction_drive import PAPER_DEFAULTS
    >>> p, f = sweep_point(PAPER_DEFAULTS, "mu", 0.2, 185.0)
    >>> p["mu"], f
    (0.2, 185.0)
    """
    if parameter == "frequency":
        return asdict(params), float(value)
    return asdict(params.with_(**{parameter: float(value)})), float(frequency)


def tidy_rows(parameter, values, frequency, params, rows, checks, steps=None):
    """Rows of a tidy CSV: the swept value and the fixed parameters first, with units."""
    out = []
    for x, row in zip(values, rows):
        p_dict, f = sweep_point(params, parameter, x, frequency)
        p = params.with_(**{k: v for k, v in p_dict.items()})
        r = {SWEPT_COLUMN.get(parameter, PARAM_COLUMNS.get(parameter, parameter)): float(x)}
        for name in ("frequency", "mu", "phi0"):
            col = PARAM_COLUMNS[name]
            if col not in r:
                r[col] = f if name == "frequency" else p_dict[name]
        r["painleve_margin"] = 1.0 - p.mu * math.tan(p.phi0)
        r["lift_off_margin"] = lift_off_margin(p, f)
        for c in VALUE_COLUMNS:
            if c not in r:
                r[c] = row.get(c, "" if c in ("mode", "stable") else math.nan)
        if checks:
            r["mj_steps_per_period"] = steps
            for chk in checks:
                for c in mj_check_columns(chk):
                    r[c] = row.get(c, math.nan)
        out.append(run_columns(r, row))
    return out


def run_columns(r, row):
    """``r`` with the energy audit's columns of ``row``, where it was computed with the audit
    (moreau sweep), and its compute time (NaN where it has none).

    Examples
    --------
    >>> run_columns({"mu": 0.2}, {"compute_time_s": 1.5})
    {'mu': 0.2, 'compute_time_s': 1.5}
    """
    for c in ENERGY_COLUMNS:
        if c in row:
            r[c] = row[c]
    r["compute_time_s"] = row.get("compute_time_s", math.nan)
    return r


def write_table(rows, path):
    """Write tidy rows as CSV (floats in full precision)."""
    cols = list(rows[0]) if rows else []
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols, restval="")
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})


def read_table(path):
    """Read a tidy CSV back: numbers as floats, text as text."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k, v in r.items():
            try:
                r[k] = float(v)
            except ValueError:
                pass
    return rows


def write_sidecar(path, params, name, parameter, values, frequency, extra, checks, steps, stats,
                  scheme=ED_REFERENCE, settings=None):
    """Write the JSON sidecar of one study's CSV: what was swept, how, and by which code.

    ``settings`` (from :func:`moreau.outputs.claim_outputs`) is stored so that a
    later run with other settings does not replace the files silently.
    """
    meta = {
        "study": name,
        "swept_parameter": SWEPT_COLUMN.get(parameter, parameter),
        "points": int(len(values)),
        "range": [float(values[0]), float(values[-1])],
        "frequency_Hz": frequency,
        "parameters_SI": asdict(params),
        "reference_scheme": scheme.record,
        "cross_checks": [{"name": c.name, "theta": c.theta, "steps_per_period": c.steps_per_period}
                         for c in checks],
        "valid_range": {k: v for k, v in extra.items()},
        "package_version": __version__,
        "code_version": code_version(),
        "python": sys.version.split()[0],
        "engine": stats,
        "provenance": provenance(code_version()),
    }
    if settings is not None:
        meta["settings"] = settings
    path.write_text(json.dumps(meta, indent=2))
