"""`moreau reproduce`: every file written, and the report's rows against the paper."""

import json
import math

import numpy as np
import pytest

from moreau.studies.paper.reproduce import run_jobs, study_grids
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
    # one process: the quick run's 60 points and 20 figures take 12 CPU s in one process and
    # 26 in a pool of two (each worker imports and loads the package again); the pool's
    # paths are checked by test_worker_pool (the points) and test_figure_jobs_run_on_a_pool
    rc = main(["reproduce", "--quick", "--out", str(out), "--quiet", "--jobs", "1"])
    assert rc == 0
    return out


def test_figure_jobs_run_on_a_pool():
    # reproduce's figures on local processes, in order, through the same call as a full run
    jobs = [(list, ("ab",)), (sorted, ("dc",)), (list, ("",)), (list, ("e",))]
    assert run_jobs(jobs, 2) == ["a", "b", "c", "d", "e"]
    assert run_jobs(jobs, 1) == ["a", "b", "c", "d", "e"]


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


# --- the claims of issue 19 (section 4) and the figures a new reader sees -------------------

def _quick_results(out):
    return {name: read_table(out / "data" / f"{name}.csv") for name in STUDIES}


def _report_row(out, claim):
    rows = [line for line in (out / "report.md").read_text().splitlines()
            if line.startswith("| ") and claim in line]
    assert len(rows) == 1, claim
    return rows[0]


@pytest.fixture(scope="module")
def quick_points(quick_run):
    from moreau.studies.paper.figures import mode_points
    return mode_points(_quick_results(quick_run), PAPER_DEFAULTS)


def test_stepping_claim_measures_the_velocity_ratio(quick_run, quick_points):
    from moreau.studies.paper.figures import steady_period
    from moreau.studies.paper.report import stepping_claim, velocity_ratio
    row = stepping_claim(quick_points)
    assert row["verdict"] == "differ" and row["paper"] == "stepping motion in each mode"
    assert set(quick_points) >= set(MODES)
    for mode, (p, f) in quick_points.items():
        r, ss = velocity_ratio(p, f)
        assert ss.mode == mode
        # independent: the rotor's velocity from differences of its sampled position
        _, res = steady_period(p, f, samples=6000)
        s = math.copysign(1.0, ss.displacement_per_period)
        dt = np.diff(res.t)
        keep = dt > 1e-9  # events add samples at the same time
        v = s * np.diff(res.q[:, 1])[keep] / dt[keep]
        assert v.min() / v.max() == pytest.approx(r, abs=5e-3), mode
        assert f"{mode} {r:+.2f} (f = {f:g} Hz" in row["ours"]
        if f == 2000.0:
            assert r > 0.85  # nearly uniform (NSP, SP; and NP where the quick run draws it there)
        else:
            assert r < 0  # runs back within each period
    assert "NSP" in row["note"] and "SP never stop" in row["note"]
    assert "NSP +0.91 (f = 2000 Hz" in _report_row(quick_run, "moves in steps in every")


def test_impact_claim_on_the_2000Hz_phi0_sweep(quick_run):
    from moreau.studies.paper.report import impact_claim
    from moreau.studies.paper.valid_range import lift_off_margin
    rows = read_table(quick_run / "data" / "phi0_2000Hz.csv")
    row = impact_claim(rows)
    imp = [r for r in rows if "!" in r["mode"]]
    edge = study_grids(quick=True)["phi0_2000Hz"][3]["inner_edges"][0]
    # the quick grid has one point past the contact loss, and only there are impacts
    assert [r["phi0_rad"] for r in imp] == [r["phi0_rad"] for r in rows if r["phi0_rad"] > edge]
    assert len(imp) == 1
    phi = imp[0]["phi0_rad"]
    margin = 1.0 - 0.1 * math.tan(phi)
    assert margin > 0.4
    assert f"still {margin:.3f} to {margin:.3f}" in row["ours"]
    # max D > 0 at the impact point, < 0 at every impact-free one
    assert lift_off_margin(PAPER_DEFAULTS.with_(phi0=phi), 2000.0) > 0
    assert all(lift_off_margin(PAPER_DEFAULTS.with_(phi0=r["phi0_rad"]), 2000.0) < 0
               for r in rows if "!" not in r["mode"])
    assert "all 7 impact-free points max D < 0" in row["ours"] and row["verdict"] == "differ"
    assert "1 of 8 points have impacts" in _report_row(quick_run, "Impacts avoided")


def test_sign_change_of_the_185Hz_phi0_sweep(quick_run):
    from moreau.analysis.steady_state import find_steady_state
    from moreau.scenes.friction_drive import FrictionDrive
    from moreau.studies.paper.report import sign_change, sign_change_claim
    rows = read_table(quick_run / "data" / "phi0_185Hz.csv")
    (x, below, above), = sign_change(rows, "phi0_rad", "phi0", PAPER_DEFAULTS, 185.0)
    assert below == above == "NP" and 1.16 < x < 1.17

    def d(phi):
        ss = find_steady_state(FrictionDrive(PAPER_DEFAULTS.with_(phi0=phi), 185.0))
        return ss.displacement_per_period, ss.mode

    # a direct steady state at the root moves the rotor by nothing; either side, opposite ways
    assert abs(d(x)[0]) < 1e-9 * max(abs(r["displacement_per_period_m"]) for r in rows) / 1e-3
    assert d(x - 1e-4)[0] < 0 < d(x + 1e-4)[0]
    assert d(x)[1] == "NP"
    row = sign_change_claim(rows, PAPER_DEFAULTS, 185.0)
    assert f"d changes sign at \u03c6\u2080 = {x:.4f} (NP below, NP above)" in row["ours"]
    assert row["verdict"] == "differ" and "inside one mode" in row["note"]
    assert f"{x:.4f}" in _report_row(quick_run, "Direction of motion along")


def test_frequency_figure_scales(quick_run):
    from moreau.studies.paper.figures import draw_sweep
    rows = read_table(quick_run / "data" / "frequency.csv")
    fig = draw_sweep(rows, "frequency", None, {})
    vax = fig.axes[1]
    assert vax.get_xscale() == "log" and vax.get_yscale() == "symlog"
    v = [r["average_velocity_m_per_s"] * 1e3 for r in rows]
    texts = [t.get_text() for t in vax.texts]
    assert f"minimum {min(v):.3g} mm/s at {rows[int(np.argmin(v))]['frequency_Hz']:.4g} Hz" in texts
    assert "slope one: v \u221d f" in texts
    _inside(fig)


def _inside(fig):
    """Every axis label and the figure's tight bbox lie inside the figure."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    box = fig.bbox
    for ax in fig.axes:
        for lab in (ax.yaxis.label, ax.xaxis.label):
            if lab.get_text():
                e = lab.get_window_extent(r)
                assert box.x0 <= e.x0 and e.x1 <= box.x1 and box.y0 <= e.y0 and e.y1 <= box.y1, \
                    lab.get_text()
    t = fig.get_tightbbox(r)
    w, h = fig.get_size_inches()
    assert t.x0 >= -1e-6 and t.y0 >= -1e-6 and t.x1 <= w + 1e-6 and t.y1 <= h + 1e-6


def test_phi0_2000Hz_figure_log_scale_and_impact_note(quick_run):
    from moreau.studies.paper.figures import draw_sweep
    rows = read_table(quick_run / "data" / "phi0_2000Hz.csv")
    extra = study_grids(quick=True)["phi0_2000Hz"][3]
    fig = draw_sweep(rows, "phi0", 2000.0, extra)
    # the two log panels, and the stability panel of every sweep figure
    assert len(fig.axes) == 3
    assert [ax.get_yscale() for ax in fig.axes[:2]] == ["log", "log"]
    assert "Floquet multiplier" in fig.axes[2].get_ylabel()
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert "F: flight, !: contact entered by an impact" in labels
    assert "NP" in labels and any("!" in m for m in labels[:-1])
    _inside(fig)


def test_phi0_185Hz_figure_zooms_on_the_negative_side():
    from moreau.studies.paper.figures import draw_sweep, zoom_side
    # the shape of the full sweep: a -6.8 um minimum, a sign change, a rise to +88 um
    phi = np.linspace(0.62, 1.46, 40)
    d = -6.8 + 6.8 * ((phi - 0.83) / (1.166 - 0.83)) ** 2
    d = np.where(phi > 1.166, 88.0 * ((phi - 1.166) / (1.46 - 1.166)) ** 2, d)
    rows = [{"phi0_rad": a, "displacement_per_period_m": b * 1e-6,
             "average_velocity_m_per_s": b * 1e-6 * 185.0, "mode": "NP", "status": "ok"}
            for a, b in zip(phi, d)]
    assert zoom_side(d) == -1 and zoom_side(-d) == 1 and zoom_side(d.clip(None, 20.0)) is None
    fig = draw_sweep(rows, "phi0", 185.0, {})
    assert len(fig.axes) == 3
    lo, hi = fig.axes[1].get_ylim()
    assert lo < d.min() < 0 < hi < 0.7 * -d.min()
    k = int(np.flatnonzero(d > 0)[0])
    xc = phi[k - 1] - d[k - 1] * (phi[k] - phi[k - 1]) / (d[k] - d[k - 1])
    assert f"sign change near {xc:.4g}" in [t.get_text() for t in fig.axes[1].texts]
    _inside(fig)


def _lab(color, alpha):
    """CIE L*a*b* of ``color`` laid with ``alpha`` over white."""
    from matplotlib.colors import to_rgb
    rgb = alpha * np.array(to_rgb(color)) + (1 - alpha)
    lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    xyz = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                    [0.0193, 0.1192, 0.9505]]) @ lin / np.array([0.9505, 1.0, 1.089])
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_mode_band_colours_are_told_apart():
    import itertools
    from moreau.studies.paper.figures import BAND_ALPHA, EXTRA_COLORS, MODE_COLORS
    cols = dict(MODE_COLORS, **{f"extra{i}": c for i, c in enumerate(EXTRA_COLORS[:4])})
    # the pair the issue found alike, and every other pair: at least 9 (CIE76) as drawn
    for (a, ca), (b, cb) in itertools.combinations(cols.items(), 2):
        assert np.linalg.norm(_lab(ca, BAND_ALPHA) - _lab(cb, BAND_ALPHA)) > 9.0, (a, b)


def test_mode_figures_at_round_frequencies(quick_run, quick_points):
    from moreau.studies.paper.figures import mode_figure_jobs
    jobs = mode_figure_jobs(_quick_results(quick_run), PAPER_DEFAULTS, quick_run, quick_points)
    assert [args[0] for _, args in jobs][:1] + [args[0] for _, args in jobs][-3:] == \
        ["NS", "NP", "NSP", "SP"]
    for _, (mode, p, f, _) in jobs:
        assert f == float(f"{f:.3g}"), (mode, f)
        assert p.mu == float(f"{p.mu:.2g}")
    assert {m: quick_points[m][1] for m in ("NS", "NSP", "SP")} == \
        {"NS": 20.0, "NSP": 2000.0, "SP": 2000.0}


def test_mode_figure_labels_inside_and_apart():
    from moreau.studies.paper.figures import REGIME_COLORS, draw_mode
    fig = draw_mode("NS", PAPER_DEFAULTS, 20.0)
    _inside(fig)
    # NSPS: the N->S->P transitions 0.07 apart share one label; the short stick gets a dot
    fig = draw_mode("NSPS", PAPER_DEFAULTS, 156.0)
    _inside(fig)
    r = fig.canvas.get_renderer()
    for ax in fig.axes:
        texts = [t for t in ax.texts]
        assert [t.get_text() for t in texts] == ["P\u2192S", "S\u2192N", "N\u2192S\u2192P"]
        boxes = [t.get_window_extent(r) for t in texts]
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                assert not boxes[i].overlaps(boxes[j])
        dots = [ln for ln in ax.lines if ln.get_marker() == "o"]
        assert len(dots) == 1 and dots[0].get_markerfacecolor() == REGIME_COLORS["S"]
