"""FCLib HDF5 interchange: exact round trip, FCLib's layout, one-line errors for bad files."""

import numpy as np
import pytest

h5py = pytest.importorskip("h5py")

from moreau.contact._sparse import check_problem, stacked_disks_problem  # noqa: E402
from moreau.contact.fclib import read_fclib, write_fclib  # noqa: E402
from moreau.contact.solvers.nsgs import solve_nsgs  # noqa: E402
from moreau.errors import InputError  # noqa: E402


@pytest.fixture
def problem():
    W, q, mu = stacked_disks_problem(3, 4, mu=0.4)
    return check_problem(W, q, mu)


def test_round_trip_is_exact(tmp_path, problem):
    W, q, mu = problem
    res = solve_nsgs(W, q, mu, tol=1e-10, max_sweeps=10**5)
    path = tmp_path / "stack.hdf5"
    write_fclib(path, W, q, mu, title="stack 3x4", description="one granular step",
                math_info="natural map", solution=(res.r, res.u), guesses=[(0 * q, q)])
    p = read_fclib(path)
    assert p.spacedim == 2
    for a, b in ((p.W.indptr, W.indptr), (p.W.indices, W.indices), (p.W.data, W.data),
                 (p.q, q), (p.mu, mu), (p.solution["r"], res.r), (p.solution["u"], res.u),
                 (p.guesses[0]["u"], q)):
        assert a.shape == b.shape and np.array_equal(a, b)
    assert p.info == {"title": "stack 3x4", "description": "one granular step",
                      "math_info": "natural map"}
    assert len(p.guesses) == 1
    again = solve_nsgs(p.W, p.q, p.mu, tol=1e-10, max_sweeps=10**5)
    assert np.array_equal(again.r, res.r)


def test_layout_is_fclibs(tmp_path, problem):
    # names and storage codes as FCLib's fclib.h writes them (fclib_write_local, write_matrix)
    W, q, mu = problem
    path = tmp_path / "p.hdf5"
    write_fclib(path, W, q, mu, title="t")
    with h5py.File(path, "r") as f:
        assert f["fclib_local/spacedim"][()].tolist() == [2]
        g = f["fclib_local/W"]
        assert [int(g[k][0]) for k in ("m", "n", "nz", "nzmax")] == [W.shape[0], W.shape[0], -2, W.nnz]
        assert g["p"].shape == (W.shape[0] + 1,) and g["p"].dtype == np.int32
        assert f["fclib_local/vectors/q"].shape == q.shape
        assert f["fclib_local/vectors/mu"].shape == mu.shape
        # a C string with its null, as H5LTmake_dataset_string stores it
        assert f["fclib_local/info/title"].dtype.itemsize == 2


def test_triplet_and_csc_storage_are_read(tmp_path, problem):
    W, q, mu = problem
    coo = W.tocoo()
    for nz, (p, i, x) in ((coo.nnz, (coo.row, coo.col, coo.data)),
                          (-1, (W.tocsc().indptr, W.tocsc().indices, W.tocsc().data))):
        path = tmp_path / f"w{nz}.hdf5"
        with h5py.File(path, "w") as f:
            f["fclib_local/spacedim"] = np.array([2], dtype=np.int32)
            for k, v in (("m", W.shape[0]), ("n", W.shape[0]), ("nz", nz), ("nzmax", len(x))):
                f[f"fclib_local/W/{k}"] = np.array([v], dtype=np.int32)
            f["fclib_local/W/p"] = p.astype(np.int32)
            f["fclib_local/W/i"] = i.astype(np.int32)
            f["fclib_local/W/x"] = x
            f["fclib_local/vectors/q"] = q
            f["fclib_local/vectors/mu"] = mu
        assert np.array_equal(read_fclib(path).W.toarray(), W.toarray())


def _edit(path, fn):
    with h5py.File(path, "a") as f:
        fn(f)


BAD = {
    "not an HDF5 file": None,
    "no /fclib_local group": lambda f: f.move("fclib_local", "other"),
    "space dimension 3": lambda f: f["fclib_local/spacedim"].write_direct(np.array([3], np.int32)),
    "/fclib_local/vectors/q is missing": lambda f: f["fclib_local/vectors"].pop("q"),
    "/fclib_local/vectors/mu has 1 entries, 21 expected":
        lambda f: (f["fclib_local/vectors"].pop("mu"),
                   f["fclib_local/vectors"].create_dataset("mu", data=[0.1])),
    "W's storage code nz = -7": lambda f: f["fclib_local/W/nz"].write_direct(np.array([-7], np.int32)),
    "W's indices i fall outside":
        lambda f: f["fclib_local/W/i"].write_direct(np.full(f["fclib_local/W/i"].shape, 99, np.int32)),
    "holds NaN or inf": lambda f: f["fclib_local/vectors/q"].write_direct(np.full(42, np.nan)),
    "a friction coefficient mu is negative":
        lambda f: f["fclib_local/vectors/mu"].write_direct(np.full(21, -1.0)),
}


@pytest.mark.parametrize("why", list(BAD))
def test_bad_files_give_one_line_input_errors(tmp_path, problem, why):
    path = tmp_path / "bad.hdf5"
    if BAD[why] is None:
        path.write_text("FCLib? no")
    else:
        write_fclib(path, *problem)
        _edit(path, BAD[why])
    with pytest.raises(InputError) as info:
        read_fclib(path)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith("`path` ") and why in msg


def test_writer_refuses_to_overwrite_and_checks_data(tmp_path, problem):
    path = tmp_path / "p.hdf5"
    write_fclib(path, *problem)
    with pytest.raises(InputError, match="exists"):
        write_fclib(path, *problem)
    with pytest.raises(InputError, match="`mu` must be >= 0"):
        write_fclib(tmp_path / "q.hdf5", problem[0], problem[1], -problem[2] - 1.0)
    assert not (tmp_path / "q.hdf5").exists()
    with pytest.raises(InputError, match="is not a file"):
        read_fclib(tmp_path / "none.hdf5")
