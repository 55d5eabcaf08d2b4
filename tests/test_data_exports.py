"""Results in the data structures of the Python science stack: pandas and xarray."""

import numpy as np
import pytest

from moreau.analysis.atlas import run_scene_atlas
from moreau.analysis.sweep import rows_to_xarray
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.scenes.registry import make_scene

pd = pytest.importorskip("pandas")
xr = pytest.importorskip("xarray")


def test_a_history_as_a_dataframe_in_si_units():
    sc = make_scene("friction-drive", frequency=185.0)
    q0, v0 = sc.initial_state()
    res = simulate(sc, (0.0, 4 * np.pi), q0, v0, "event-driven")
    df = res.to_dataframe(sc)
    si = sc.to_si(res)
    assert len(df) == len(res.t)
    np.testing.assert_array_equal(df["t"], si["t"])
    np.testing.assert_array_equal(df["q_1"], si["q"][:, 1])
    np.testing.assert_array_equal(df["force_N_0"], si["force_N"][:, 0])
    assert df.attrs["units"]["q_0"] == "rad" and df.attrs["units"]["q_1"] == "m"
    assert df.attrs["units"]["force_N_0"] == "N" and df.attrs["scheme"] == res.scheme
    assert set(df["regime_0"]) <= {"stick", "positive", "negative", "flight"}
    assert "negative" in set(df["regime_0"])


def test_a_history_without_a_scene_keeps_its_own_units():
    sc = make_scene("bouncing-ball")
    res = simulate(sc, (0.0, 1.0), *sc.initial_state(), "moreau-jean", h=0.01)
    df = res.to_dataframe()
    np.testing.assert_array_equal(df["q_0"], res.q[:, 0])
    np.testing.assert_array_equal(df["gap_0"], res.gap[:, 0])
    assert set(df.attrs["units"].values()) == {""}


def test_an_atlas_as_an_xarray_dataset_on_its_grid():
    rows = run_scene_atlas("stick-slip-motor", ("load", [0.0, 0.05, 0.1]), ("mu", [0.2, 0.3]),
                           frequency=1000.0, out=None, progress=False, plot=False,
                           log=lambda s: None)
    ds = rows_to_xarray(rows, ["load [N]", "mu"])
    assert ds["displacement_per_period_m"].shape == (3, 2)
    assert ds["load"].attrs["units"] == "N" and ds["load"].values.tolist() == [0.0, 0.05, 0.1]
    for r in rows:
        cell = ds.sel(load=r["load [N]"], mu=r["mu"])
        assert float(cell["displacement_per_period_m"]) == r["displacement_per_period_m"]
        assert str(cell["mode"].values) == r["mode"]


def test_a_column_that_is_not_there_is_refused():
    with pytest.raises(InputError, match="`dims` must name columns of the rows"):
        rows_to_xarray([{"a": 1.0, "b": 2.0}], ["c"])
