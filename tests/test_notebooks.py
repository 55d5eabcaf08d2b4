"""The notebooks run top to bottom (figures to the Agg backend)."""

import json
import pathlib

import pytest

NOTEBOOKS = sorted((pathlib.Path(__file__).parents[1] / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    nb = json.loads(path.read_text())
    ns = {}
    for cell in nb["cells"]:
        if cell["cell_type"] == "code":
            exec(compile("".join(cell["source"]), f"{path.name}", "exec"), ns)
    if "ss" in ns:
        assert ns["ss"].periodic_residual < 1e-9
    if "ss" in ns and "res" in ns:
        # the recorded period starts on the fixed point: it closes with the steady displacement
        res, ss = ns["res"], ns["ss"]
        assert res.q[-1, 1] - res.q[0, 1] == pytest.approx(ss.displacement_per_period, rel=1e-9)
        assert res.v[-1, 1] == pytest.approx(res.v[0, 1], rel=1e-9)


def test_there_is_a_notebook():
    assert NOTEBOOKS
