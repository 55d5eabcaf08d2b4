"""Issue 16, parts 5 and 6: no steady state past stall, and no unbounded work from one argument."""

import math

import numpy as np
import pytest

from moreau.analysis.steady_state import find_steady_state
from moreau.cli import main
from moreau.errors import InputError, RunawayError
from moreau.integrators import simulate
from moreau.scenes.friction_drive import FrictionDrive


@pytest.mark.parametrize("load", [0.01, 1.0, 1e3, 1e9])
@pytest.mark.parametrize("scheme", ["event-driven", "moreau-jean"])
def test_past_stall_there_is_no_steady_state(load, scheme, capsys):
    # the rotor runs away; rounding hid every change a period made, so the
    # periodic residual read 0 and a "steady state" at -4e14 m/s came back
    argv = ["steady", "--frequency", "185", "--load", str(load), "--scheme", scheme]
    if scheme == "moreau-jean":
        argv += ["--steps-per-period", "200"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "RunawayError" in err and f"past stall (load F_L = {load:g} N)" in err
    assert "runs away backwards" in err


def test_the_one_entry_point_refuses_it_for_every_caller():
    with pytest.raises(RunawayError, match="past stall"):
        find_steady_state(FrictionDrive(frequency=185.0, load=0.01))
    # below stall a loaded drive keeps its steady state, slower than unloaded
    free = find_steady_state(FrictionDrive(frequency=185.0))
    loaded = find_steady_state(FrictionDrive(frequency=185.0, load=-1e-4))
    assert loaded.periodic_residual < 1e-9
    assert abs(loaded.displacement_per_period) < abs(free.displacement_per_period)


def test_a_sweep_across_stall_marks_the_runaway_point(tmp_path):
    import csv
    assert main(["sweep", "load", "0", "0.02", "--points", "5", "--frequency", "185", "--out",
                 str(tmp_path), "--quiet", "--no-plot", "--jobs", "1"]) == 0
    (path,) = tmp_path.glob("*.csv")
    rows = list(csv.DictReader(open(path)))
    assert rows[0]["status"] == "ok"
    assert [r["status"] for r in rows[1:]].count("ok") == 0
    assert rows[2]["status"].startswith("RunawayError")


@pytest.mark.parametrize("argv, message", [
    (["steady", "--frequency", "185", "--scheme", "moreau-jean", "--steps-per-period",
      "100000000"], "`steps_per_period` = 1e+08 is more than the limit 1e+07"),
    (["steady", "--frequency", "185", "--scheme", "moreau-jean", "--steps-per-period", "1e12"],
     "invalid int value"),
    (["run", "--frequency", "185", "--periods", "1e12"], "more than the limit 1e+07"),
    (["sweep", "mu", "0.1", "0.2", "--points", "1000000000000", "--frequency", "185"],
     "`points` = 1e+12 is more than the limit 1e+05"),
])
def test_unbounded_work_is_refused_before_it_starts(argv, message, capsys, tmp_path):
    if argv[0] in ("run", "sweep"):
        argv = argv + ["--out", str(tmp_path), "--quiet"]
    with pytest.raises(SystemExit) if "invalid int" in message else _no_exit():
        assert main(argv) == 2
    assert message in capsys.readouterr().err


class _no_exit:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


@pytest.mark.parametrize("h", [1e-9, 1e-300])
def test_a_tiny_step_is_refused_before_it_fills_memory(h):
    sc = FrictionDrive()
    q0, v0 = sc.rest_state()
    with pytest.raises(InputError, match="more than `max_steps` = 1e\\+09"):
        simulate(sc, (0.0, 2 * math.pi), q0, v0, "moreau-jean", h=h)
    # within the step budget, recording every step is bounded too
    with pytest.raises(InputError, match="raise `save_every`"):
        simulate(sc, (0.0, 2 * math.pi), q0, v0, "moreau-jean", h=1e-8, max_steps=10**10)
    res = simulate(sc, (0.0, 2 * math.pi), q0, v0, "moreau-jean", h=2 * math.pi / 1000)
    assert res.success and len(res.t) == 1001
