"""`moreau compare` on the two-contact scenes: the sliding box and the bidirectional drive."""

import contextlib
import io
import json

import pytest

from moreau.analysis.compare import compare, fit_order, make_case
from moreau.cli import main
from moreau.errors import InputError

ROW_KEYS = {"scheme", "theta", "lcp", "steps_per_period", "rtol", "time_s", "error",
            "trajectory_error", "switching_error", "status"}


def by_series(rep):
    out = {}
    for r in rep["rows"]:
        if r["scheme"] == "moreau-jean":
            out.setdefault((r["theta"], r["lcp"]), {})[r["steps_per_period"]] = r
    return out


def test_sliding_box_cli_json_and_orders(tmp_path):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["compare", "--scene", "sliding-box", "--json", "--quick", "--quiet",
                     "--out", str(tmp_path)])
    assert code == 0
    rep = json.loads(buf.getvalue())
    assert rep["scene"] == "sliding-box" and rep["reference"]["scheme"] == "exact"
    assert rep["rows"][0]["scheme"] == "exact" and rep["rows"][0]["error"] == 0.0
    for r in rep["rows"]:
        assert ROW_KEYS <= set(r) and r["status"] == 0, r["message"]
        assert (r["rtol"] is None) != (r["steps_per_period"] is None) or r["scheme"] == "exact"
    s = by_series(rep)
    assert set(s) == {(0.5, None), (1.0, None), (1.0, "lemke"), (1.0, "qp")}
    assert max(s[(1.0, None)]) / min(s[(1.0, None)]) >= 100           # two decades
    orders = {(o["theta"], o["lcp"]): o["order"] for o in rep["orders"]}
    # theta = 1: first order (measured 1.00)
    assert 0.95 <= orders[(1.0, None)] <= 1.1
    # theta = 1/2 integrates the constant deceleration exactly; only the step in
    # which the box stops errs, by O(h^2) times a factor set by where t* = 2.5
    # falls in it: second order along N = 50, 500, 5000 (t*/h = 33.3, 333.3, ...)
    # and exact where t* is a grid time (N = 150, 1500)
    half = s[(0.5, None)]
    assert fit_order([50, 500, 5000], [half[n]["error"] for n in (50, 500, 5000)]) == \
        pytest.approx(2.0, abs=0.02)
    assert half[150]["error"] < 1e-12 and half[1500]["error"] < 1e-11
    for n, r in s[(1.0, "lemke")].items():
        # forced Lemke = the scheme's own two-contact solve = the QP path
        assert r["error"] == pytest.approx(s[(1.0, None)].get(n, r)["error"], rel=1e-9)
        assert abs(r["error"] - s[(1.0, "qp")][n]["error"]) < 1e-6
        assert abs(r["trajectory_error"] - s[(1.0, "qp")][n]["trajectory_error"]) < 1e-6
    window = rep["parameters"]["window"]
    for series in s.values():
        for n, r in series.items():
            # each corner stops within a step of the exact t* = v0 / mu
            assert r["switching_error"] is not None and r["switching_error"] <= window / n
    for f in ("csv", "json", "png"):
        assert (tmp_path / f"compare_sliding-box.{f}").stat().st_size > 0


@pytest.fixture(scope="module")
def bidir():
    return compare("bidirectional-drive", steps=[50, 200, 1000, 5000], lcp_steps=[50],
                   repeat=1, progress=False)


def test_bidirectional_drive_rows_and_reference(bidir):
    rep = bidir
    json.dumps(rep)                                   # one JSON object, no NaN objects
    assert rep["parameters"]["x10_b"] == 1e-6 and rep["reference"]["rtol"] == 1e-12
    for r in rep["rows"]:
        assert ROW_KEYS <= set(r) and r["status"] == 0, r["message"]
    ed = {r["rtol"]: r for r in rep["rows"] if r["scheme"] == "event-driven"}
    assert set(ed) == {1e-4, 1e-6, 1e-8, 1e-10}
    # the generic event-driven reference converges to the tight one
    assert ed[1e-8]["error"] < 1e-9 and ed[1e-8]["switching_error"] < 1e-8
    # the issue-10 value: -4.053673e-3 l per period (x10_b = x10_a / 2, 185 Hz)
    assert rep["reference"]["headline_value"] == pytest.approx(-4.053673e-3, rel=1e-6)


def test_bidirectional_drive_moreau_jean_is_first_order(bidir):
    s = by_series(bidir)
    orders = {(o["theta"], o["lcp"]): o["order"] for o in bidir["orders"]}
    assert 0.8 <= orders[(1.0, None)] <= 1.3              # measured 1.02
    assert 0.8 <= orders[(0.5, None)] <= 1.3              # measured 0.92
    assert s[(1.0, None)][5000]["error"] < 1e-3           # measured 6.1e-4
    assert s[(0.5, None)][5000]["error"] < 1e-4           # measured 6.2e-5
    for n in (50,):
        lem, qp = s[(1.0, "lemke")][n], s[(1.0, "qp")][n]
        assert abs(lem["error"] - qp["error"]) < 1e-6
        assert abs(lem["trajectory_error"] - qp["trajectory_error"]) < 1e-6
    # the forced-Lemke period from the reference's state has the same trajectory
    # as the compiled scheme's period from there
    assert s[(1.0, "lemke")][50]["trajectory_error"] == pytest.approx(
        s[(1.0, None)][50]["trajectory_error"], rel=1e-6)
    # both contacts' switching times converge with the step
    sw = [s[(1.0, None)][n]["switching_error"] for n in (200, 1000, 5000)]
    assert None not in sw and sw[2] < sw[1] < sw[0] and sw[2] <= 2 * 6.3e-3 / 5


def test_two_contact_scenes_refuse_bad_input():
    with pytest.raises(InputError, match="`x10` is not a parameter of scene 'bidirectional-drive'"):
        make_case("bidirectional-drive", x10=1e-6)
    with pytest.raises(InputError, match="`mu` \\* half_height must be < half_width"):
        make_case("sliding-box", mu=3.0)
    with pytest.raises(InputError, match="`x10_b` must be < length"):
        make_case("bidirectional-drive", x10_b=1e-3)


@pytest.mark.parametrize("frequency", [185.0, 2000.0])
def test_rod_b_unexcited_moreau_jean_equals_the_single_rod(frequency):
    # the 2000 Hz Moreau-Jean errors of the two-rod compare are the single rod's
    # grid plateaus (moreau.analysis.compare, "Plateaus"), not a two-contact effect
    from moreau.analysis.steady_state import find_steady_state
    from moreau.scenes.bidirectional_drive import BidirectionalDrive, BidirectionalDriveParams
    from moreau.scenes.friction_drive import FrictionDrive

    two = BidirectionalDrive(BidirectionalDriveParams(x10_b=0.0), frequency)
    one = FrictionDrive(frequency=frequency)
    for theta in (0.5, 1.0):
        d2 = find_steady_state(two, "moreau-jean", steps_per_period=500, theta=theta)
        d1 = find_steady_state(one, "moreau-jean", steps_per_period=500, theta=theta)
        assert d2.displacement_per_period == pytest.approx(d1.displacement_per_period, rel=1e-12)
