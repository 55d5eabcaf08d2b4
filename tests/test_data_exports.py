"""Results in the data structures of the Python science stack: pandas and xarray."""

import numpy as np
import pytest

from moreau.analysis.atlas import run_scene_atlas
from moreau.analysis.sweep import rows_to_xarray
from moreau.errors import InputError
from moreau.integrators import simulate
from moreau.model.registry import make_scene

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
    # the generic atlas on the friction drive: its steady states (the walker's) take 0.3 s
    # for the grid, against 6 s for the stick-slip motor's event-driven shooting; every cell
    # has a displacement of its own and the mu axis changes the mode (NP at 0.1, NS at 0.6),
    # so a cell read from the wrong row shows
    rows = run_scene_atlas("friction-drive", ("load", [-2e-4, -1e-4, 0.0]), ("mu", [0.1, 0.6]),
                           frequency=185.0, out=None, progress=False, plot=False,
                           n_jobs=1, log=lambda s: None)
    assert len({r["displacement_per_period_m"] for r in rows}) == 6
    assert {r["mode"] for r in rows} == {"NP", "NS"}
    ds = rows_to_xarray(rows, ["load [N]", "mu"])
    assert ds["displacement_per_period_m"].shape == (3, 2)
    assert ds["load"].attrs["units"] == "N" and ds["load"].values.tolist() == [-2e-4, -1e-4, 0.0]
    for r in rows:
        cell = ds.sel(load=r["load [N]"], mu=r["mu"])
        assert float(cell["displacement_per_period_m"]) == r["displacement_per_period_m"]
        assert str(cell["mode"].values) == r["mode"]


def test_a_column_that_is_not_there_is_refused():
    with pytest.raises(InputError, match="`dims` must name columns of the rows"):
        rows_to_xarray([{"a": 1.0, "b": 2.0}], ["c"])


# -- NetCDF (issue 21): `--netcdf` on sweep and atlas, units as attributes ------------------

import csv  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402

from moreau.analysis.sweep import netcdf_attrs, rows_to_netcdf  # noqa: E402
from moreau.cli import main  # noqa: E402


def _csv_rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _same(text, value):
    # a CSV cell against the NetCDF value at the same grid point
    try:
        x = float(text)
    except ValueError:
        return text == str(value)
    return (np.isnan(x) and np.isnan(float(value))) or x == float(value)


def test_a_sweep_s_netcdf_holds_the_csv_s_values_and_units(tmp_path, capsys):
    # two points: every column of every row is compared below (the motor's generic
    # event-driven steady states cost about a second each)
    argv = ["sweep", "frequency", "500", "2000", "--points", "2", "--scene", "stick-slip-motor",
            "--jobs", "1", "--quiet", "--no-plot", "--netcdf", "--out", str(tmp_path)]
    assert main(argv) == 0
    stem = tmp_path / "sweep_stick-slip-motor_frequency_event-driven"
    assert f"wrote {stem}.nc" in capsys.readouterr().out
    rows = _csv_rows(f"{stem}.csv")
    side = json.loads((stem.parent / (stem.name + ".json")).read_text())
    with xr.open_dataset(f"{stem}.nc") as ds:
        assert ds["frequency"].attrs["units"] == "Hz"
        assert ds["frequency"].values.tolist() == [float(r["frequency [Hz]"]) for r in rows]
        units = {"displacement_per_period_m": "m", "average_velocity_m_per_s": "m/s",
                 "min_normal_force_N": "N", "compute_time_s": "s", "stator_work_J": "J"}
        for name, unit in units.items():
            assert ds[name].attrs["units"] == unit, name
        assert "units" not in ds["mode"].attrs and "units" not in ds["periodic_residual"].attrs
        for k, r in enumerate(rows):
            for col, text in r.items():
                if col == "frequency [Hz]":
                    continue
                name = col.partition(" [")[0]
                assert _same(text, ds[name].values[k]), (col, text, ds[name].values[k])
        # the sidecar's record, provenance included, as global attributes
        assert ds.attrs["scene"] == "stick-slip-motor"
        assert json.loads(ds.attrs["provenance"]) == side["provenance"]
        assert json.loads(ds.attrs["settings"]) == side["settings"]


def test_an_atlas_s_netcdf_is_on_its_grid(tmp_path):
    argv = ["atlas", "--plane", "f-mu", "--fmin", "20", "--fmax", "40", "--f-points", "2",
            "--y-points", "3", "--jobs", "1", "--quiet", "--no-plot", "--netcdf", "--out",
            str(tmp_path)]
    assert main(argv) == 0
    rows = _csv_rows(tmp_path / "atlas_f-mu.csv")
    with xr.open_dataset(tmp_path / "atlas_f-mu.nc") as ds:
        assert ds["displacement_per_period_m"].dims == ("frequency_Hz", "mu")
        assert ds["displacement_per_period_m"].shape == (2, 3)
        assert ds["frequency_Hz"].attrs["units"] == "Hz" and ds["phi0_rad"].attrs["units"] == "rad"
        for r in rows:
            cell = ds.sel(frequency_Hz=float(r["frequency_Hz"]), mu=float(r["mu"]))
            for col in ("displacement_per_period_m", "min_normal_force_N", "mode", "status"):
                assert _same(r[col], cell[col].values), col
        assert ds.attrs["plane"] == "f-mu" and ds.attrs["grid"].tolist() == [2.0, 3.0]


def test_netcdf_attributes_are_legal_and_read_back(tmp_path):
    meta = {"points": 3, "big": 2**40, "range": [0.5, 1], "flag": True, "none": None,
            "nested": {"a": [1, "x"]}, "text": "Painlevé – 2 µm", "np": np.float64(2.5),
            "odd key [Hz]": 1.0}
    attrs = netcdf_attrs(meta)
    for v in attrs.values():
        assert isinstance(v, (str, int, float, np.ndarray)) and not isinstance(v, bool)
    path = rows_to_netcdf([{"x [s]": 1.0, "y_m": 2.0, "word": "ok"},
                           {"x [s]": 2.0, "y_m": np.nan, "word": "é"}], ["x [s]"],
                          tmp_path / "t.nc", meta)
    with xr.open_dataset(path) as ds:
        assert ds.attrs["points"] == 3 and json.loads(ds.attrs["big"]) == 2**40
        assert ds.attrs["range"].tolist() == [0.5, 1.0]
        assert json.loads(ds.attrs["flag"]) is True and json.loads(ds.attrs["none"]) is None
        assert json.loads(ds.attrs["nested"]) == {"a": [1, "x"]}
        assert ds.attrs["text"] == "Painlevé – 2 µm" and ds.attrs["odd_key__Hz_"] == 1.0
        assert ds["x"].attrs["units"] == "s" and ds["y_m"].attrs["units"] == "m"
        assert ds["word"].values.tolist() == ["ok", "é"]
        assert np.isnan(ds["y_m"].values[1])
    assert [p.name for p in tmp_path.iterdir()] == ["t.nc"]   # no temporary file left


def test_netcdf_without_xarray_names_the_extra(tmp_path, capsys, monkeypatch):
    from moreau.analysis import engine

    def no_work(*a, **k):
        raise AssertionError("work started before xarray was looked for")

    monkeypatch.setattr(engine, "run_points", no_work)
    monkeypatch.setitem(sys.modules, "xarray", None)   # as if the [data] extra were not installed
    for argv in (["sweep", "mu", "0.1", "0.2", "--points", "2", "--frequency", "185"],
                 ["atlas", "--quick"]):
        assert main(argv + ["--netcdf", "--quiet", "--no-plot", "--out", str(tmp_path)]) == 2
        assert capsys.readouterr().err == ("moreau: error: `--netcdf` needs xarray, which is "
                                           "not installed: pip install -e \".[data]\"\n")
    with pytest.raises(ImportError, match=r"`rows_to_netcdf` needs xarray.*\.\[data\]"):
        rows_to_netcdf([{"x": 1.0}], ["x"], tmp_path / "t.nc")
    assert not list(tmp_path.iterdir())
