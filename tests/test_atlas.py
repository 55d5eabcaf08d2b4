"""`moreau atlas`: mode maps over (f, mu) and (f, phi0), boundaries, cache, Dask path."""

import csv
import math

import numpy as np
import pytest

from moreau import cli
from moreau.analysis import engine
from moreau.studies.paper.atlas import compute_atlas, point_label
from moreau.errors import InputError

SMALL = dict(f_range=(20.0, 2000.0), f_points=3, y_points=4)


def test_mu_plane_modes_and_boundaries(tmp_path):
    a = compute_atlas("f-mu", y_range=(0.1, 0.98), cache_dir=tmp_path, n_jobs=1, **SMALL)
    assert a["label"].shape == (3, 4)
    # the paper's mu studies: NS throughout at 20 Hz, NP then SP at 2000 Hz
    assert list(a["label"][0]) == ["NS"] * 4
    assert a["label"][2, 0] == "NP" and a["label"][2, -1] == "SP"
    # the 185 Hz-like column (200 Hz here) runs negative, the 2000 Hz one positive
    assert np.all(a["displacement_per_period_m"][0] < 0)
    assert np.all(a["displacement_per_period_m"][2] > 0)
    # boundary fields: max D does not depend on mu; Painleve margin 1 - mu tan(pi/4) = 1 - mu
    assert np.allclose(a["lift_off_field"], a["lift_off_field"][:, :1])
    assert np.all(a["lift_off_field"] < 0)
    assert a["painleve_field"][0] == pytest.approx(1.0 - a["y"])
    assert np.all(a["contact_loss_field"] == -1.0)


def test_phi0_plane_marks_ill_posed_and_flight(tmp_path):
    a = compute_atlas("f-phi0", f_range=(185.0, 2000.0), f_points=2, y_range=(0.8, 1.48),
                      y_points=3, cache_dir=tmp_path, n_jobs=1)
    # phi0 = 1.48 > atan(1/0.1) = 1.4711: ill-posed, before any integration
    assert list(a["label"][:, 2]) == ["ill-posed (Painlev\u00e9)"] * 2
    assert np.all(a["painleve_field"][:, 2] < 0) and np.all(a["painleve_field"][:, :2] > 0)
    assert math.isnan(a["contact_loss_field"][0, 2])
    # at 2000 Hz, phi0 = 1.14: still in contact (the contact-loss edge is at 1.367)
    assert a["label"][1, 1] == "NP" and a["contact_loss_field"][1, 1] == -1.0
    assert point_label({"status": "ConvergenceError: the rod does not touch the rotor in 50 "
                                  "periods after the shooting's last state"}) == "no contact"
    assert point_label({"status": "ConvergenceError: shooting did not converge"}) == "failed"


def test_dask_local_cluster_gives_the_same_atlas(tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        a = compute_atlas("f-mu", cache_dir=tmp_path, scheduler=cluster.scheduler_address,
                          **SMALL)
    assert a["stats"] == {"cached": 0, "computed": 12}
    b = compute_atlas("f-mu", cache_dir=tmp_path, n_jobs=1, **SMALL)
    assert b["stats"] == {"cached": 12, "computed": 0}
    assert np.array_equal(a["label"], b["label"])
    assert np.array_equal(a["displacement_per_period_m"], b["displacement_per_period_m"])


def test_atlas_command_files_and_checks(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    rc = cli.main(["atlas", "--plane", "f-mu", "--f-points", "2", "--y-points", "2",
                   "--fmin", "20", "--fmax", "2000", "--out", str(out), "--quiet", "--jobs", "1"])
    assert rc == 0
    for suffix in (".csv", ".json", ".png", ".svg"):
        assert (out / f"atlas_f-mu{suffix}").is_file()
    with open(out / "atlas_f-mu.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 4 and {"frequency_Hz", "mu", "phi0_rad", "displacement_per_period_m",
                               "mode", "status", "min_normal_force_N"} <= set(rows[0])

    def no_work(*a, **k):
        raise AssertionError("work started before the checks")

    monkeypatch.setattr(engine, "run_points", no_work)
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    capsys.readouterr()
    assert cli.main(["atlas", "--out", str(blocker / "x"), "--quiet"]) == 2
    assert "not writable" in capsys.readouterr().err
    assert cli.main(["atlas", "--theta", "0.5", "--out", str(tmp_path), "--quiet"]) == 2
    assert "`--theta` does not act with `--scheme event-driven`" in capsys.readouterr().err
    with pytest.raises(InputError, match="`plane` must be one of"):
        compute_atlas("mu-phi0")
