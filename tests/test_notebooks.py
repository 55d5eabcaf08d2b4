"""Every notebook runs top to bottom in a Jupyter kernel (nbclient), outputs not committed."""

import json
import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))

#: checks run after a notebook, in its kernel (its variables are there)
AFTER = {
    "friction_drive_steady_states.ipynb": """
assert ss.periodic_residual < 1e-9
# the recorded period starts on the fixed point: it closes with the steady displacement
assert abs(res.q[-1, 1] - res.q[0, 1] - ss.displacement_per_period) <= 1e-9 * abs(ss.displacement_per_period)
assert abs(res.v[-1, 1] - res.v[0, 1]) <= 1e-9 * abs(res.v[0, 1])
""",
    "friction_drive_tour.ipynb": """
assert len(rows) == 15 and all(r["status"] == "ok" for r in rows)
assert atlas["label"].shape == (14, 8)
assert not out.exists()     # the tour removed its temporary folder
""",
    "granular_column.ipynb": """
# (a step whose solve ended above tol is reported, status 1: measured one of 250, 3.7e-5)
assert run.status in (0, 1) and run.unconverged.size <= 5 and len(run.t) == 11
assert free.n_disks == 40
# the column spread beyond its base (measured: front at 8.96 d, L0 = 4 d), to the right only
assert front > 1.5 * L0 and np.all(run.x[-1][:, 0] > 0.0)
# every solver met 1e-12 on the step's problem, its certified residual recomputed
assert all(s.converged and s.residual <= 1e-12 for s in solves.values())
# the residual history is the solver's: its last entry is the residual returned
assert all(abs(s.history[-1, 1] - s.residual) <= 1e-3 * s.residual for s in solves.values())
# the problem rebuilt from the step's contacts is the step's: its impulses give its velocity
assert np.max(np.abs(v_nsgs - one.v[-1].ravel())) <= 1e-9
""",
    "pendulum_on_a_stop.ipynb": """
assert report.ok and scene.ndof == 3 and scene.n_joint_rows == 2
assert all(r.status == 0 for r in runs.values()) and ref.status == 0
# the drift plotted is the result's: its largest value is constraint_drift
assert abs(np.max(drift(runs[1.0])) - runs[1.0].constraint_drift * scene.length) <= 1e-15
# theta = 1/2 holds the pin better than theta = 1 by more than an order of magnitude
assert runs[0.5].constraint_drift < 0.1 * runs[1.0].constraint_drift
assert ref.constraint_drift < 1e-10
# the reference's first rebound: the energy and Newton's law, e omega
assert abs(after - e * omega) <= 1e-8 * omega
# at rest on the stop: the angle and the force of statics (N = m g / 2)
for r in runs.values():
    si = scene.to_si(r)
    assert np.all(np.abs(si["v"][-10:]) < 1e-9)
    assert abs(si["force_N"][-1, 0] - mass * g / 2) <= 1e-9 * mass * g
err = {theta: abs(scene.to_si(r)["q"][-1, 2] - theta_rest) for theta, r in runs.items()}
assert err[0.5] < 1e-4 and err[1.0] < 1e-2 and err[0.5] < 0.1 * err[1.0]
""",
    "puck_facets.ipynb": """
assert all(r.status == 0 for r in runs.values()) and len(t) == 201
# the exact cone lies on the closed-form path to the step's error; the facets' error falls with d
# (measured: 312, 101, 11.0 mm at d = 4, 8, 32, the exact cone 2.64 mm)
assert errors["exact"] < 4e-3 and errors["exact"] < 0.5 * errors[32] < errors[8] < errors[4]
assert errors[4] > 0.2 and errors[32] < 0.02
assert abs(si["exact"]["q"][-1, 1] - exact_path[-1, 1]) < 3e-3
assert 1.3 < order < 1.9

""",
    "scheme_comparison.ipynb": """
assert {r["scheme"] for r in report["rows"]} == {"event-driven", "moreau-jean"}
# the time histories: every scheme on the same t_eval, within a small distance of the reference
assert len(runs) >= 4 and all(r.status == 0 and np.array_equal(r.t, t_eval) for r in runs.values())
assert all(np.max(np.abs(r.q[:, 1] - ref.q[:, 1])) < 1e-3 for r in runs.values())
""",
    "your_own_scene.ipynb": """
assert report.ok and not moreau.check_scene(Broken()).ok
# written once: the Python methods are the compiled functions, and WT is held to slip_positions
assert isinstance(scene, CompiledScene) and report.errors["compiled model"] == 0.0
assert report.errors["slip rates (WT, wT)"] < 1e-6
assert any("gap rates" in p for p in moreau.check_scene(Broken()).problems)
assert abs(ref.events[0].t - 0.3) < 1e-8
assert all(r["status"] == 0 for r in rep["rows"])
orders = {o["theta"]: o["order"] for o in rep["orders"]}
assert 0.8 < orders[1.0] < 1.3 and orders[0.5] > 0.8
assert np.max(np.abs(same.q - slow_run.q)) <= 1e-12 and np.max(np.abs(same.v - slow_run.v)) <= 1e-12
assert fast_run.success and fast_run.stats["steps"] == 200000
""",
}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path, monkeypatch, tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(path, as_version=4)
    # committed without outputs, so that the repository holds no generated results
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert not cell.outputs and cell.execution_count is None, f"{path.name}: strip outputs"
            # a notebook shows figures drawn from returned data, not pictures saved on disk
            assert "Image(" not in cell.source and ".png" not in cell.source, path.name
        # every cell has an id (nbformat 4.5; a missing one is a warning today, an error later)
        assert cell.get("id"), f"{path.name}: a cell without an id"
    if path.name in AFTER:
        nb.cells.append(nbformat.v4.new_code_cell(AFTER[path.name]))
    # the kernel imports the package from this checkout even where it is not installed
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_code_cell_follows_prose(path):
    """Each code cell comes after a markdown cell that says what it does (issue 21)."""
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    bare = []
    for i, cell in enumerate(cells):
        if cell["cell_type"] != "code":
            continue
        before = cells[i - 1] if i > 0 else None
        if not (before and before["cell_type"] == "markdown" and "".join(before["source"]).strip()):
            bare.append(f"cell {i} ({cell.get('id')}): " + "".join(cell["source"]).split("\n")[0])
    assert not bare, f"{path.name}: code cells with no markdown cell before them: {bare}"


def test_every_notebook_has_its_checks():
    assert {p.name for p in NOTEBOOKS} == set(AFTER)
