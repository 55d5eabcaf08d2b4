"""Bifurcation diagrams: section samples, periods, Lyapunov exponents, marks, the command."""

import json
import math

import numpy as np
import pytest

from moreau.analysis.bifurcation import (bifurcation_diagram, bifurcation_marks,
                                         classify_motion, section_samples, sequence_period)
from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.errors import InputError
from moreau.model.registry import make_scene

from periodic_scenes import DampedOscillator


def test_the_lyapunov_exponent_of_a_linear_oscillator_is_its_floquet_exponent():
    # x'' + 2 zeta w0 x' + w0^2 x = cos t: the period map is affine with multipliers
    # exp(T w0 (-zeta +- i sqrt(1 - zeta^2))) and the rotor's exp(-2 pi c); the largest
    # modulus gives the exponent -zeta w0 2 pi = -0.8168 a period
    sc = DampedOscillator(w0=1.3, zeta=0.1, c=0.2)
    exact = math.log(max(abs(m) for m in sc.multipliers()))
    q0, v0 = sc.initial_state()
    rows, q, v, flight, lyap, bound = section_samples(sc, "event-driven", q0, v0, {}, 40, 20,
                                                      1, True)
    assert not bound and flight      # its one contact never closes
    # the oscillator block is not a rotation in these coordinates: its per-period growth
    # oscillates about |mu|, and 20 periods average it to a few per cent (measured 0.07 %;
    # 0.5 % over 60 periods, at twice the cost)
    assert lyap == pytest.approx(exact, rel=0.05)
    # after 40 periods (a factor 1e-14) the section repeats: period 1
    data = np.array([[x for _, _, x in r] for r in rows])
    assert sequence_period(data) == 1


def test_sequence_period_finds_the_smallest_repeat_and_refuses_bad_input():
    x = np.tile([[1.0, 5.0], [2.0, 5.0], [3.0, 5.0]], (4, 1))
    assert sequence_period(x) == 3
    assert sequence_period(x + 1e-9 * np.arange(12)[:, None], rtol=1e-6) == 3
    assert sequence_period(x + 1e-3 * np.arange(12)[:, None], rtol=1e-6) == 0
    with pytest.raises(InputError, match="`samples` must have shape"):
        sequence_period(np.zeros(5))


def test_motion_names_and_marks():
    assert classify_motion(1, -0.5) == "period-1"
    assert classify_motion(0, 0.2) == "chaotic"
    assert classify_motion(0, -0.02) == "converging"
    pts = [{"value": v, "period": k, "flight": f, "status": "ok"}
           for v, k, f in ((1.0, 1, False), (2.0, 2, False), (3.0, 4, True), (4.0, 0, True))]
    pts.append({"value": 5.0, "period": 1, "flight": True, "status": "PainleveError: x"})
    marks = bifurcation_marks(pts, "a")
    assert [(m["kind"], m["between"]) for m in marks] == [
        ("period doubling", [1.0, 2.0]), ("period doubling", [2.0, 3.0]),
        ("grazing", [2.0, 3.0]), ("period change", [3.0, 4.0])]


@pytest.mark.slow
def test_each_point_samples_the_steady_state_it_continues_to():
    # the stick-slip motor is period 1 at every load: its sampled displacement per period
    # is the steady state's, found independently by shooting
    d = bifurcation_diagram("stick-slip-motor", "load", [0.0, 0.05], frequency=1000.0,
                            transient=10, samples=6, out=None, progress=False)
    for p in d["points"]:
        assert p["status"] == "ok" and p["period"] == 1 and p["motion"] == "period-1"
        sc = make_scene("stick-slip-motor", frequency=1000.0, load=p["value"])
        ref = sc.displacement_to_si(find_steady_state(sc).displacement_per_period)
        assert np.allclose(p["samples"]["displacement_per_period"], ref, rtol=1e-9, atol=0)
    assert d["marks"] == []


def test_the_drive_above_lift_off_with_elastic_impacts_is_chaotic():
    # e = 1 at 17.1 kHz: the rod bounces on the stator; measured exponent 0.35 a period
    d = bifurcation_diagram("friction-drive", "frequency", [17099.8], fixed={"restitution": 1.0},
                            transient=50, samples=20, out=None, progress=False)
    p = d["points"][0]
    assert p["flight"] and p["period"] == 0
    assert p["lyapunov_per_period"] > 0.05 and p["motion"] == "chaotic"


def test_the_command_writes_table_sidecar_and_figure(tmp_path, capsys):
    # the command's files on the friction drive (0.3 CPU s against 5 s for the stick-slip
    # motor's event-driven runs; the motor's diagram is the module's docstring example)
    out = tmp_path / "b"
    rc = main(["bifurcation", "k", "1e4", "2e4", "--scene", "friction-drive",
               "--frequency", "185", "--points", "2", "--transient", "5", "--samples", "4",
               "--out", str(out), "--json", "--quiet"])
    assert rc == 0
    rep = json.loads(capsys.readouterr().out)
    assert [p["motion"] for p in rep["points"]] == ["period-1", "period-1"]
    stem = out / "bifurcation_friction-drive_k_185Hz_event-driven"
    header = stem.with_suffix(".csv").read_text().splitlines()[0].split(",")
    assert header[:2] == ["k [N/m]", "sample"] and "displacement_per_period [m]" in header
    assert len(stem.with_suffix(".csv").read_text().splitlines()) == 1 + 2 * 4
    meta = json.loads(stem.with_suffix(".json").read_text())
    assert meta["transient_periods"] == 5 and "provenance" in meta
    assert stem.with_suffix(".png").stat().st_size > 0


@pytest.mark.parametrize("extra, message", [
    (["--samples", "1"], "`samples` must be >= 2"),
    (["--rtol", "1e-6"], "`--rtol` does not act in `moreau bifurcation`"),
    (["--set", "nope=1"], "`nope` is not a parameter of scene 'stick-slip-motor'"),
    (["--steps-per-period", "100"], "`steps_per_period` applies to time-stepping schemes"),
])
def test_bad_settings_are_refused_before_any_work(tmp_path, capsys, extra, message):
    rc = main(["bifurcation", "load", "0", "0.05", "--scene", "stick-slip-motor",
               "--frequency", "1000", "--points", "2", "--out", str(tmp_path / "b"),
               "--quiet"] + extra)
    assert rc == 2 and message in capsys.readouterr().err
    assert not (tmp_path / "b").exists() or not any((tmp_path / "b").iterdir())
