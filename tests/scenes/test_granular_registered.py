"""The registered granular scenes: every pair a candidate contact, the run `moreau run` takes."""

import json

import numpy as np
import pytest

from moreau.analysis.history import default_run
from moreau.cli import main
from moreau.errors import InputError
from moreau.integrators.base import simulate
from moreau.integrators.granular import simulate_disks
from moreau.model.granular import EVERY_PAIR_MAX, DiskScene
from moreau.scenes.granular_column import granular_column
from moreau.scenes.silo import silo


def test_the_registered_column_collapses_as_the_broad_phase_steps_it():
    sc = granular_column(width=0.0125, aspect=1.5)
    n = sc.system.n_disks
    # every pair of disks, every disk with the floor and the wall
    assert (n, sc.ncontacts) == (12, n * (n - 1) // 2 + 2 * n)
    q0, v0 = sc.initial_state()
    x0 = q0.reshape(-1, 3)[:, :2]
    scheme, options = default_run(sc)
    assert (scheme, options) == ("moreau-jean", {"lcp_method": "nsgs"})
    res = simulate(sc, (0.0, 4.0), q0, v0, scheme, h=0.04, lcp_tol=1e-10, **options)
    assert res.success
    # the same Moreau-Jean step with the contacts found by the broad phase every step
    # (an independent assembly: moreau.integrators.granular) gives the same motion
    ref = simulate_disks(sc.system, x0, np.zeros((n, 3)), 100, 0.04, theta=1.0, tol=1e-10,
                         max_sweeps=10_000)
    got = res.q[-1].reshape(-1, 3)
    assert np.max(np.abs(got[:, :2] - ref.x[-1])) < 1e-8
    assert np.max(np.abs(got[:, 2] - ref.phi[-1])) < 1e-8
    # an animation draws the touching candidates, and no point for those the scene marks open
    q_si = res.q[-1].copy()
    q_si[0::3] *= sc.length
    q_si[1::3] *= sc.length
    drawn = [s for s in sc.shapes(q_si) if s["kind"] == "contact"]
    assert [s["open"] for s in drawn] == (sc.gaps(res.q[-1], 0.0) > 0.01).tolist()
    assert n <= sum(not s["open"] for s in drawn) < sc.ncontacts // 2
    # a contact closed that was not within half a diameter at the start: a scene with the
    # start's contacts only stops there (status -6), naming its valid region
    start = sc.system.contacts(x0, 0.5)
    assert not np.all(np.isin(sc.system.contacts(got[:, :2], 0.0).key, start.key))
    fixed = DiskScene(sc.system, x0, margin=0.5, length=sc.length, time=sc.time, force=sc.force)
    stopped = simulate(fixed, (0.0, 4.0), q0, v0, scheme, h=0.04, **options)
    assert stopped.status == -6 and "candidate contact of the start" in stopped.message


def test_the_registered_scenes_refuse_more_disks_than_every_pair_takes():
    with pytest.raises(InputError, match="`width` = 0.05 m and `aspect` = 1.0 .* at most 64"):
        granular_column(width=0.05)
    with pytest.raises(InputError, match="`per_pour` must be at most 64"):
        silo(per_pour=EVERY_PAIR_MAX + 1)
    sc = silo(per_pour=EVERY_PAIR_MAX + 1 - 1)
    assert sc.ncontacts == 64 * 63 // 2 + 3 * 64


def test_moreau_run_takes_the_scenes_own_default(tmp_path):
    assert main(["run", "--scene", "silo", "--duration", "0.005", "--steps", "20", "--samples",
                 "5", "--out", str(tmp_path), "--no-plot", "--quiet"]) == 0
    (side,) = tmp_path.glob("*.json")
    doc = json.loads(side.read_text())
    assert doc["scheme"] == "moreau-jean" and doc["options"]["lcp_method"] == "nsgs"
    assert doc["status"] == 0
