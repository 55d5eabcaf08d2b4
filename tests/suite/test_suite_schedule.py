"""The quick suite's schedule: a problem's kernel-sharing schemes in one task, animations on the
cells' pool."""

import pytest
from PIL import Image

from moreau.suite.report import animation_tasks, write_report
from moreau.suite.run import _pairs, plan_cells, run_suite


def test_a_problems_schemes_that_share_compiled_code_are_one_task():
    schemes = ["compliant-radau", "compliant-rk45", "event-driven", "event-driven-generic",
               "moreau-jean", "moreau-jean-projected", "schatzman-paoli"]
    _, _, plan = plan_cells(["bouncing-ball", "sliding-block"], schemes, quick=True, peers=False)
    tasks = _pairs(plan, list(range(len(plan))))
    grouped = [(p, [s for s, _ in by]) for p, by in tasks]
    # the first task of each family first (the ball's), then the block's in the plan's order
    assert grouped == [
        ("bouncing-ball", ["compliant-radau", "compliant-rk45"]),
        ("bouncing-ball", ["event-driven", "event-driven-generic"]),
        ("bouncing-ball", ["moreau-jean", "moreau-jean-projected"]),
        ("bouncing-ball", ["schatzman-paoli"]),
        ("sliding-block", ["compliant-radau", "compliant-rk45"]),
        ("sliding-block", ["event-driven", "event-driven-generic"]),
        ("sliding-block", ["moreau-jean", "moreau-jean-projected"]),
        ("sliding-block", ["schatzman-paoli"])]
    # every cell once, with its own index, label and options
    cells = sorted(i for _, by in tasks for _, c in by for i, _, _ in c)
    assert cells == list(range(len(plan)))
    for _, by in tasks:
        for s, c in by:
            assert all(plan[i][1:] == (s, label, opts) for i, label, opts in c)


def test_further_tasks_run_after_the_cells_and_come_back_by_key():
    rep = run_suite(problems=["sliding-block"], schemes=["stick-slip-exact"], quick=True,
                    progress=False, n_jobs=1, tasks=[("a", divmod, (7, 2)), ("b", max, (1, 3))])
    assert rep["tasks"] == {"a": (3, 1), "b": 3}


@pytest.mark.slow
def test_the_pool_draws_the_animations_the_page_embeds(tmp_path):
    out = str(tmp_path)
    rep = run_suite(problems=["sliding-block", "bouncing-ball"], schemes=["moreau-jean"],
                    quick=True, progress=False, n_jobs=2,
                    tasks=animation_tasks(["sliding-block", "bouncing-ball"], out, 3))
    assert rep["jobs"] == 2 and set(rep["tasks"]) == {"sliding-block", "bouncing-ball"}
    paths = write_report(rep, out, settings={"quick": True}, animations=rep["tasks"],
                         animation_frames=3)
    page = open(paths["page"]).read()
    for name in ("sliding-block", "bouncing-ball"):
        assert rep["tasks"][name] == (paths[f"gif_{name}"], None)
        assert f"anim_{name}.gif" in page and f"wp_{name}.png" in page
        with Image.open(paths[f"gif_{name}"]) as im:
            assert im.n_frames == 3
