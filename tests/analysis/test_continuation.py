"""Continuation along atlas lines and the classification of points without a periodic orbit."""

import csv
import math
from dataclasses import asdict

import numpy as np
import pytest

from periodic_scenes import TableBall

from moreau import cli
from moreau.analysis.classify import classification_columns, classify_long_run
from moreau.analysis.continuation import continue_point, midpoint, solve_line
from moreau.analysis.engine import ED_REFERENCE, evaluate_points
from moreau.analysis.scheme_settings import Scheme, steady_of
from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.errors import ConvergenceError, InputError
from moreau.scenes.friction_drive import PAPER_DEFAULTS, FrictionDrive
from moreau.model.registry import make_scene
from moreau.scenes.stick_slip_motor.exact import stick_slip_steady_state
from moreau.studies.paper.atlas import compute_atlas, point_label
from moreau.studies.paper.tables import read_table


def test_continued_atlas_equals_the_cold_one(tmp_path):
    # a small f-mu atlas across NS, NP and SP: every point found either way, same mode,
    # displacements equal to the shooting's tolerance (measured: 5.1e-10 relative at most)
    kw = dict(f_range=(185.0, 3000.0), f_points=3, y_range=(0.1, 0.9), y_points=6, n_jobs=1,
              classify=0)
    cold = compute_atlas("f-mu", continuation=False, **kw)
    cont = compute_atlas("f-mu", continuation=True, **kw)
    assert np.array_equal(cold["label"], cont["label"])
    d0, d1 = cold["displacement_per_period_m"], cont["displacement_per_period_m"]
    assert np.all(np.isfinite(d0))
    assert np.max(np.abs(d1 / d0 - 1.0)) < 1e-8
    # the column: each line of constant frequency starts cold and continues from there
    assert set(cold["start"].ravel()) == {"cold"}
    assert list(cont["start"][0]) == ["cold"] + ["continued"] * 5
    assert set(cont["start"][:, 1:].ravel()) == {"continued"}


def test_a_failed_or_ill_posed_neighbour_means_a_cold_start():
    # phi0 = 1.48 is ill-posed (1 - mu tan phi0 < 0): the point after it has no orbit to
    # continue from
    pts = [(asdict(PAPER_DEFAULTS.with_(phi0=p)), 2000.0) for p in (1.0, 1.05, 1.48, 1.1)]
    rows = evaluate_points(pts, ED_REFERENCE, classify=0)
    assert [r["start"] for r in rows] == ["cold", "continued", "cold", "cold"]
    assert [r["continuation_solves"] for r in rows] == [0, 1, 0, 0]
    assert rows[2]["status"].startswith("PainleveError")
    assert rows[3]["status"] == "ok"


def test_step_halving_then_cold_fallback():
    calls = []

    def solve(point, guess):
        calls.append((point[1], guess))
        # a direct step of more than 1.5 fails; halved steps succeed
        if guess is not None and abs(point[1] - guess) > 1.5:
            raise ConvergenceError("too far")
        return point[1]

    ss, n = continue_point(solve, ({}, 0.0), 0.0, ({}, 2.0), max_halvings=1)
    assert ss == 2.0 and n == 2
    # midpoints of a frequency are geometric
    assert midpoint(({"mu": 0.1}, 100.0), ({"mu": 0.3}, 400.0)) == ({"mu": 0.2}, 200.0)
    # four units in one step need two halvings: with one, the line falls back to a cold start
    out = solve_line([({}, 1.0), ({}, 5.0)], solve, max_halvings=1)
    assert [o["start"] for o in out] == ["cold", "cold-fallback"]
    assert out[1]["steady"] == 5.0 and out[1]["solves"] == 0


def test_guess_must_be_a_period_one_orbit():
    sc = FrictionDrive(frequency=185.0)
    ss = find_steady_state(sc)
    ss.period = 2
    with pytest.raises(InputError, match="`guess` must be the period-1 SteadyState"):
        find_steady_state(sc, guess=ss)


@pytest.mark.slow
def test_classifies_a_period_two_orbit():
    # the table ball past its flip (Gamma 1.6 > 1.527, e = 1/2): the period-1 orbit is
    # unstable (multiplier < -1), the period-2 one attracts (multipliers of P^2 |0.25|).
    # Its state at its section, from find_steady_state(max_period=8) as in test_floquet
    # (61 s, so written out here); the plain run from it repeats every second period
    sc = TableBall(gamma=1.6, e=0.5)
    q, v = np.array([4.57392410, 0.0]), np.array([3.95683054e-02, 0.0])
    got = classify_long_run(sc, "event-driven-generic", start=(q, v),
                            section_tau=3.9988698950943915, budget=17)
    assert got["classification"] == "period-2" and got["periods"] == 17
    assert got["displacement_per_period"] == pytest.approx(0.0, abs=1e-30)


def test_classifies_a_non_periodic_flight_case():
    # the light-rotor flight case of the statistical tests (15 kHz, e = 1): no orbit; its
    # long-run mean 7.77e-3 a period (every scheme within 7.62e-3 .. 7.92e-3)
    sc = FrictionDrive(PAPER_DEFAULTS.with_(restitution=1.0, m2=2e-8), 15000.0)
    got = classify_long_run(sc, "moreau-jean", {"steps_per_period": 2000, "theta": 0.5},
                            budget=400)
    assert got["classification"] == "non-periodic"
    assert 7.5e-3 < got["displacement_per_period"] < 8.1e-3


def test_classification_columns_of_rows():
    p = asdict(PAPER_DEFAULTS)
    ok = {"status": "ok", "mode": "NS", "displacement_per_period_m": -1e-6}
    cols = classification_columns(ok, p, 20.0, ED_REFERENCE, "friction-drive")
    assert cols["classification"] == "period-1" and cols["classified_half_width_m"] == 0.0
    bad = {"status": "PainleveError: 1 - mu*tan(phi0) = -0.4 <= 0", "mode": ""}
    assert classification_columns(bad, p, 20.0, ED_REFERENCE,
                                  "friction-drive")["classification"] == "ill-posed"
    # a failed shooting at a point with a stable orbit: the run finds it (period 1)
    failed = {"status": "ConvergenceError: shooting did not converge", "mode": ""}
    cols = classification_columns(failed, asdict(PAPER_DEFAULTS.with_(restitution=1.0,
                                                                      m2=2e-8)), 185.0,
                                  Scheme.moreau_jean(1.0, 200), "friction-drive", budget=100)
    assert cols["classification"] == "period-1"
    assert "shooting did not converge" in cols["classification_detail"]
    assert point_label({"status": failed["status"], "classification": "period-2"}) == "period-2"
    assert point_label({"status": failed["status"], "classification": "failed"}) == "failed"


def test_atlas_command_cold_and_classify_options(tmp_path):
    args = ["atlas", "--plane", "f-mu", "--f-points", "2", "--y-points", "2", "--fmin", "185",
            "--fmax", "2000", "--no-plot", "--quiet", "--jobs", "1", "--out", str(tmp_path)]
    assert cli.main(args + ["--cold", "--classify-periods", "0"]) in (0, None)
    rows = read_table(tmp_path / "atlas_f-mu.csv")
    assert [r["start"] for r in rows] == ["cold"] * 4
    assert {r["classification"] for r in rows} == {"period-1"}
    # other settings: refused without --force, the rule named
    assert cli.main(args) == 2
    assert cli.main(args + ["--force"]) in (0, None)
    # each line of constant frequency (mu 0.01 and 0.99) starts cold; its second point is
    # continued, or at 2000 Hz, where NP turns SP over that step, falls back to a cold start
    starts = [r["start"] for r in read_table(tmp_path / "atlas_f-mu.csv")]
    assert starts[0::2] == ["cold", "cold"] and starts[1] == "continued"
    assert starts[3] in ("continued", "cold-fallback")
    assert cli.main(args + ["--classify-periods", "-1", "--force"]) == 2


@pytest.mark.parametrize("scene, parameter, values, fixed", [
    # the paper's drive through its own study sweep (moreau sweep mu)
    ("friction-drive", "mu", (0.1, 0.3, 7), None),
    # any registered periodic scene through the generic sweep
    ("stick-slip-motor", "load", (0.0, 0.1, 3), None),
])
def test_a_continued_sweep_equals_the_cold_one(tmp_path, monkeypatch, scene, parameter, values,
                                              fixed):
    def run(out, *extra):
        argv = ["sweep", parameter, str(values[0]), str(values[1]), "--points", str(values[2]),
                "--scene", scene, "--set", "frequency=185", "--out", str(tmp_path / out),
                "--quiet", "--no-plot", "--jobs", "1"] + list(extra)
        if scene == "stick-slip-motor":
            argv[argv.index("frequency=185")] = "frequency=1000"
        assert main(argv) == 0
        (path,) = (tmp_path / out).glob("*.csv")
        return list(csv.DictReader(open(path)))

    warm = run("warm")
    # one task of neighbours with one worker (two tasks per worker: ceil(n / 2) points each)
    n = values[2]
    assert [r["start"] for r in warm] == [
        "cold" if i % math.ceil(n / 2) == 0 else "continued" for i in range(n)]
    assert all(int(r["continuation_solves"]) >= 1 for r in warm if r["start"] == "continued")
    if scene == "friction-drive":
        cold = run("cold", "--cold")
        assert {r["start"] for r in cold} == {"cold"}
    else:
        # the generic sweep's `--cold` reaches run_scene_sweep as continuation=False (the
        # engine's cold chunks are the ones the friction drive's case runs above); its
        # cold-started points are those of the warm run (points 0 and 2 here, the same
        # deterministic call), so the continued one is checked against the motor's
        # closed-form steady state (1 ms; a cold shooting agrees with it to 7e-15) instead
        # of a second sweep of 3 (3 of 6 CPU s)
        seen = {}
        with monkeypatch.context() as m:
            m.setattr(cli, "run_scene_sweep", lambda *a, **kw: seen.update(kw))
            run_args = ["sweep", parameter, "0", "1", "--points", "3", "--scene", scene,
                        "--out", str(tmp_path / "plumbing"), "--quiet", "--jobs", "1"]
            assert main(run_args + ["--cold"]) == 0 and seen["continuation"] is False
            assert main(run_args) == 0 and seen["continuation"] is True
        cold = []
        for w in warm:
            if w["start"] == "cold":
                cold.append(w)
                continue
            motor = make_scene(scene, frequency=1000.0, **{parameter: float(w["load [N]"])})
            ss = stick_slip_steady_state(motor)
            cold.append({"mode": ss.mode, "status": "ok", "displacement_per_period_m":
                         motor.displacement_to_si(ss.displacement_per_period)})
    for w, c in zip(warm, cold):
        assert w["mode"] == c["mode"] and w["status"] == c["status"] == "ok"
        assert float(w["displacement_per_period_m"]) == pytest.approx(
            float(c["displacement_per_period_m"]), rel=1e-8, abs=1e-15)


def test_the_secant_predictor_saves_shootings_and_lands_on_the_same_orbits():
    # one 1 kHz line of the f-mu atlas: the prediction from the two previous orbits starts
    # each shooting one order closer than the neighbour's orbit does
    pts = [(asdict(PAPER_DEFAULTS.with_(mu=m)), 1000.0) for m in np.linspace(0.3, 0.5, 12)]

    def solve(point, guess):
        p, f = point
        return steady_of(make_scene("friction-drive", frequency=f, **p), ED_REFERENCE,
                         guess=guess)

    a = solve_line(pts, solve, predict=True)
    b = solve_line(pts, solve, predict=False)
    assert [r["start"] for r in a] == ["cold"] + ["continued"] * 11
    its = [sum(r["steady"].iterations for r in x[1:]) for x in (a, b)]
    assert its[0] < its[1]
    for ra, rb in zip(a, b):
        assert ra["steady"].mode == rb["steady"].mode
        assert ra["steady"].displacement_per_period == pytest.approx(
            rb["steady"].displacement_per_period, rel=1e-8)

