"""`moreau reproduce`: every file written, and the report's rows against the paper."""

import json
import math

import numpy as np
import pytest

from moreau.studies.paper.reproduce import study_grids
from moreau.studies.paper.report import refine_extremum
from moreau.studies.paper.tables import read_table
from moreau.studies.paper.valid_range import lift_off_margin, phi0_valid_range
from moreau.cli import main
from moreau.scenes.friction_drive import PAPER_DEFAULTS

STUDIES = ["frequency", "mu_20Hz", "mu_185Hz", "mu_2000Hz", "phi0_20Hz", "phi0_185Hz",
           "phi0_2000Hz"]
MODES = ["NS", "NP", "NSP", "SP"]  # NSPS and NPS bands are too narrow for the quick grids


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    pytest.importorskip("matplotlib")
    out = tmp_path_factory.mktemp("repro")
    rc = main(["reproduce", "--quick", "--out", str(out), "--quiet"])
    assert rc == 0
    return out


def test_quick_run_writes_every_file(quick_run):
    out = quick_run
    for name in STUDIES:
        rows = read_table(out / "data" / f"{name}.csv")
        assert rows, name
        swept = {"frequency": "frequency_Hz", "mu": "mu", "phi0": "phi0_rad"}[name.split("_")[0]]
        assert list(rows[0])[0] == swept
        for col in ("displacement_per_period_m", "average_velocity_m_per_s", "mode",
                    "min_normal_force_N", "status", "mj_theta0.5_displacement_per_period_m",
                    "mj_theta1_relative_error", "mj_steps_per_period"):
            assert col in rows[0], (name, col)
        ok = [r for r in rows if r["status"] == "ok"]
        assert len(ok) == len(rows), name
        for r in ok:
            assert r["average_velocity_m_per_s"] == pytest.approx(
                r["displacement_per_period_m"] * r["frequency_Hz"])
        meta = json.loads((out / "data" / f"{name}.json").read_text())
        assert meta["package_version"] and meta["parameters_SI"]["k"] == 1e4
        assert meta["points"] == len(rows)
        for ext in ("png", "svg"):
            assert (out / "figures" / f"{name}.{ext}").stat().st_size > 5000
    for m in MODES:
        assert (out / "figures" / f"mode_{m}.png").exists(), m
    report = (out / "report.md").read_text()
    assert "| 180 Hz |" in report and "| 0.13 |" in report and "| 0.89 |" in report
    assert "| 1.42 |" in report and "| 0.84 |" in report
    assert "figures/frequency.png" in report and "Typos" in report
    # every row of a table has as many cells as its header (a bare "|" in "|d|" would split one)
    import re
    width = None
    for line in report.splitlines():
        if not line.startswith("|"):
            width = None
            continue
        n = len(re.findall(r"(?<!\\)\|", line))
        width = n if width is None else width
        assert n == width, line


def test_second_run_comes_from_the_cache(quick_run):
    from moreau.studies.paper.reproduce import reproduce
    logs = []
    res = reproduce(quick_run, quick=True, progress=False, figures=False, report=False,
                    log=logs.append)
    assert "0 computed" in logs[0]
    first = read_table(quick_run / "data" / "mu_2000Hz.csv")
    assert [r["displacement_per_period_m"] for r in res["mu_2000Hz"]] == \
        [r["displacement_per_period_m"] for r in first]


def test_a_full_run_into_a_quick_runs_folder_is_refused_before_any_work(quick_run, capsys):
    before = {p: p.stat().st_mtime_ns for p in quick_run.rglob("*") if p.is_file()}
    capsys.readouterr()
    assert main(["reproduce", "--out", str(quick_run), "--quiet", "--jobs", "1"]) == 2
    assert capsys.readouterr().err == (
        "moreau: error: `--out` already holds frequency.csv/.json from a run with other settings "
        "(mj_steps_per_period, points, quick): give `--force` to replace them, or another "
        "`--out`\n")
    # no point computed, no file touched
    assert {p: p.stat().st_mtime_ns for p in quick_run.rglob("*") if p.is_file()} == before
    meta = json.loads((quick_run / "data" / "mu_185Hz.json").read_text())
    assert meta["settings"] == {"quick": True, "points": 8, "frequency_Hz": 185.0,
                                "mj_steps_per_period": 200}


def test_force_replaces_the_files_of_a_run_with_other_settings(tmp_path):
    from moreau.errors import InputError
    from moreau.studies.paper.reproduce import reproduce
    (tmp_path / "data").mkdir()
    full = {"quick": False, "points": 99, "frequency_Hz": 185.0, "mj_steps_per_period": 2000}
    (tmp_path / "data" / "mu_185Hz.json").write_text(json.dumps({"settings": full}))
    (tmp_path / "data" / "mu_185Hz.csv").write_text("mu\n0.5\n")
    with pytest.raises(InputError, match=r"mu_185Hz.csv/.json from a run with other settings "
                                         r"\(mj_steps_per_period, points, quick\)"):
        reproduce(tmp_path, quick=True, n_jobs=1, progress=False, figures=False, report=False,
                  log=lambda msg: None)
    assert not (tmp_path / "cache").exists()
    reproduce(tmp_path, quick=True, n_jobs=1, progress=False, figures=False, report=False,
              log=lambda msg: None, force=True)
    assert len(read_table(tmp_path / "data" / "mu_185Hz.csv")) == 8
    assert json.loads((tmp_path / "data" / "mu_185Hz.json").read_text())["settings"]["quick"]


def test_grids_of_the_three_studies():
    g = study_grids()
    f = g["frequency"][1]
    assert len(f) >= 250 and f[0] == 10.0 and f[-1] == pytest.approx(12500.0)
    assert np.allclose(np.diff(np.log(f)), np.log(f[1] / f[0]))
    assert np.allclose(g["mu_185Hz"][1], np.arange(1, 100) / 100)
    for name in ("phi0_20Hz", "phi0_185Hz", "phi0_2000Hz"):
        _, values, _, edges = g[name]
        assert len(values) >= 99
        assert edges["lift_off_edge"] < values[0] and values[-1] < edges["painleve_edge"]
    # the lift-off edge at tau = 0 is arccos(sqrt(2/3)); the Painleve edge atan(1/mu)
    assert g["phi0_20Hz"][3]["lift_off_edge"] == pytest.approx(math.acos(math.sqrt(2 / 3)),
                                                                abs=1e-8)
    assert g["phi0_20Hz"][3]["painleve_edge"] == pytest.approx(math.atan(10.0))
    # at 2000 Hz contact is lost again near 1.37 (max D = 0 inside the range)
    inner = g["phi0_2000Hz"][3]["inner_edges"]
    assert len(inner) == 1 and 1.35 < inner[0] < 1.39
    assert lift_off_margin(PAPER_DEFAULTS.with_(phi0=inner[0]), 2000.0) == pytest.approx(0, abs=1e-8)
    # the frequency where the rod at phi0 = pi/4 lifts off lies just above the study
    assert 12500 < g["frequency"][3]["contact_loss_Hz"] < 13000


def _rows(parameter, xs, f=None):
    from dataclasses import asdict

    from moreau.analysis.engine import run_points
    from moreau.studies.paper.tables import SWEPT_COLUMN
    pts = [(asdict(PAPER_DEFAULTS), x) if parameter == "frequency"
           else (asdict(PAPER_DEFAULTS.with_(**{parameter: x})), f) for x in xs]
    rows, _ = run_points(pts, n_jobs=1)
    for r, x in zip(rows, xs):
        r[SWEPT_COLUMN[parameter]] = x
    return rows


@pytest.mark.parametrize("parameter, f, xs, kind, paper, agree", [
    ("frequency", None, [160.0, 175.0, 190.0, 205.0], "min", 180.0, 0.03 * 180),
    ("mu", 2000.0, [0.86, 0.88, 0.90, 0.92], "max", 0.89, 0.01),
    ("phi0", 20.0, [1.38, 1.41, 1.44, 1.46], "min", 1.42, 0.01),
    ("phi0", 185.0, [0.78, 0.82, 0.86, 0.90], "min", 0.84, 0.01),
])
def test_report_extrema_agree_with_the_paper(parameter, f, xs, kind, paper, agree):
    from moreau.studies.paper.tables import SWEPT_COLUMN
    rows = _rows(parameter, xs, f)
    x, _ = refine_extremum(rows, SWEPT_COLUMN[parameter], parameter, PAPER_DEFAULTS, f, kind)
    assert abs(x - paper) <= agree


def test_report_mu_minimum_at_185Hz_differs_from_the_paper():
    rows = _rows("mu", [0.08, 0.10, 0.12, 0.14], 185.0)
    x, d = refine_extremum(rows, "mu", "mu", PAPER_DEFAULTS, 185.0, "min")
    # ours: 0.105, not the paper's 0.13; the curve there is only ~3 % above the minimum
    assert 0.10 < x < 0.11
    at_paper = [r for r in _rows("mu", [0.13], 185.0)][0]["displacement_per_period_m"]
    assert 0.01 < at_paper / d - 1 < 0.05 or 0.01 < 1 - at_paper / d < 0.05


def test_valid_range_function():
    r = phi0_valid_range(PAPER_DEFAULTS.with_(mu=0.5), 185.0)
    assert r["painleve_edge"] == pytest.approx(math.atan(2.0))
