"""``moreau run`` on every registered scene, with the reference and with Moreau–Jean."""

import csv
import json

import pytest

from moreau.cli import main
from moreau.scenes import registry


def _span(name):
    scene = registry.make_scene(name)
    return (["--periods", "1"] if getattr(scene, "period", None) is not None
            else ["--duration", str(0.2 * (scene.time_unit_s or 1.0))])


#: (scene, scheme) pairs with the long checks: the event-driven reference on the masonry arch
#: searches the modes of its ten frictional contacts, all closed at once, at every event (about
#: 4 s of CPU over the 0.2 time units, more than the arch's other default-run tests together)
SLOW = {("masonry-arch", "event-driven")}


@pytest.mark.parametrize("scheme, name", [
    pytest.param(s, n, marks=pytest.mark.slow) if (n, s) in SLOW else (s, n)
    for s in ["event-driven", "moreau-jean"] for n in registry.scene_names()])
def test_run_writes_a_history_with_units_for_every_scene(name, scheme, tmp_path, capsys):
    argv = ["run", "--scene", name, "--scheme", scheme, "--out", str(tmp_path), "--quiet",
            "--no-plot", "--samples", "50"] + _span(name)
    if scheme == "moreau-jean":
        argv += ["--steps", "400"]
    scene = registry.make_scene(name)
    if scheme == "event-driven" and getattr(scene, "spatial", False):
        # the event-driven reference steps no spatial scene: refused by name
        assert main(argv) == 2
        assert "steps no spatial scene" in capsys.readouterr().err
        return
    assert main(argv) == 0
    (path,) = tmp_path.glob("*.csv")
    assert path.name.startswith(f"history_{name}_{scheme}")
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    header = list(rows[0])
    # every scene shipped has SI units: time in seconds, no unitless column but the regimes
    assert header[0] == "t [s]"
    assert all("[" in h for h in header if not h.startswith("regime"))
    assert float(rows[0]["t [s]"]) == 0.0 and float(rows[-1]["t [s]"]) > 0.0
    regimes = [h for h in header if h.startswith("regime")]
    # (a scene without contacts has no regime)
    assert (regimes or scene.ncontacts == 0) and all(r[h] in {"stick", "positive", "negative",
                                                               "flight"}
                           for r in rows for h in regimes)
    side = json.loads(path.with_suffix(".json").read_text())
    assert side["scene"] == name and side["scheme"] == scheme and side["status"] == 0
    assert [c["name"] for c in side["columns"]] == [h.split(" [")[0] for h in header]


def test_a_scene_without_a_drive_needs_a_duration_and_periods_need_a_drive(tmp_path, capsys):
    assert main(["run", "--scene", "sliding-block", "--periods", "2", "--out", str(tmp_path)]) == 2
    assert "`periods` needs a scene with a periodic drive" in capsys.readouterr().err
