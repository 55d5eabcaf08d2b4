"""An interrupted long run keeps what it had finished."""

import math

import numpy as np

from moreau.studies.paper import sweeps
from moreau.integrators import simulate
from moreau.scenes.friction_drive.walker import EventDriven
from moreau.scenes.friction_drive import FrictionDrive


def test_interrupted_simulation_returns_partial_result(monkeypatch):
    calls = {"n": 0}
    real_step = EventDriven._step_impl

    def step(self):
        calls["n"] += 1
        if calls["n"] == 6:
            raise KeyboardInterrupt
        real_step(self)

    monkeypatch.setattr(EventDriven, "_step_impl", step)
    sc = FrictionDrive(frequency=185.0)
    q0, v0 = sc.rest_state()
    res = simulate(sc, (0.0, 100 * 2 * math.pi), q0, v0, "event-driven", progress=True)
    assert res.status == -4 and not res.success and "interrupted" in res.message
    assert len(res.events) == 5 and 0.0 < res.t[-1] < 100 * 2 * math.pi
    assert np.all(np.isfinite(res.q))


def test_interrupted_sweep_keeps_finished_points(monkeypatch):
    from moreau.analysis import steady_state

    calls = {"n": 0}
    orig = steady_state.find_steady_state

    def fss(*a, **k):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return orig(*a, **k)

    monkeypatch.setattr(steady_state, "find_steady_state", fss)
    rows = sweeps.sweep("frequency", [20.0, 185.0, 2000.0, 5000.0])
    assert [r["mode"] for r in rows] == ["NS", "NP"]
