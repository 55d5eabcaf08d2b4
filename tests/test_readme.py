"""The README and the guide's pages against the program: its tables, and every command they show."""

import json
import os
import pathlib
import re
import shlex
import subprocess
import sys

import pytest

import moreau
from moreau.cli import build_parser

ROOT = pathlib.Path(moreau.__file__).resolve().parent.parent
README = ROOT / "README.md"
#: the guide: the README (a user's guide), and the pages of docs/ that hold the details
#: it moved there (tutorial.md only includes the README)
GUIDE = [README] + sorted(p for p in (ROOT / "docs").glob("*.md")
                          if p.name not in ("index.md", "tutorial.md"))
MAX_README_LINES = 350


def _subparsers():
    (sub,) = [a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction"]
    return sub.choices


def test_the_readme_is_a_short_guide():
    lines = README.read_text().splitlines()
    assert len(lines) <= MAX_README_LINES, (
        f"README.md has {len(lines)} lines, at most {MAX_README_LINES}: details and "
        "measurements belong in docs/ (docs/benchmarks.md for the dated ones)")


def _table(heading):
    """The first column's backticked names of the table under the README's ``## heading``."""
    text = README.read_text()
    section = re.search(rf"^## {re.escape(heading)}\n(.*?)(?=^## |\Z)", text, flags=re.S | re.M)
    assert section, f"README.md has no section '## {heading}'"
    rows = [line for line in section.group(1).splitlines() if line.startswith("| `")]
    assert rows, f"no table under '## {heading}'"
    return [set(re.findall(r"`([^`]+)`", row.split("|")[1])) for row in rows]


def test_the_command_table_lists_exactly_the_cli_commands():
    # one row a command, in `moreau --help`'s set; a command added or removed shows up here
    rows = _table("The commands")
    assert all(len(names) == 1 for names in rows), rows
    names = [n for (n,) in rows]
    assert all(n.startswith("moreau ") for n in names), names
    assert sorted(n.split()[1] for n in names) == sorted(_subparsers())


def test_the_tour_shows_every_command():
    tour = [c for block in readme_blocks(README) for c in block]
    shown = {m for c in tour for m in re.findall(r"(?:^|&& )moreau (\w+)", c)}
    assert shown == set(_subparsers())


def test_the_scene_table_lists_every_registered_scene():
    from moreau.scenes import registry
    rows = _table("Scenes")
    listed = [n for names in rows for n in names]
    assert sorted(listed) == sorted(registry.scene_names()), (
        "README.md's scene table and the registry differ: add or remove a line")


def test_the_scheme_table_lists_every_registered_scheme():
    (steady,) = [p for n, p in _subparsers().items() if n == "steady"]
    (scheme,) = [a for a in steady._actions if "--scheme" in a.option_strings]
    listed = [n for names in _table("Schemes") for n in names]
    assert sorted(listed) == sorted(scheme.choices), (
        "README.md's scheme table and the CLI's --scheme choices differ: add or remove a line")


def test_every_benchmark_the_readme_names_exists():
    names = [n for names in _table("Benchmarks") for n in names]
    assert len(names) >= 8
    for name in names:
        assert (ROOT / "benchmarks" / name).is_file(), name


def test_every_guide_link_resolves():
    # a page the README or a guide page links to exists, and so does the heading it names
    for page in GUIDE:
        for target in re.findall(r"\]\(([^)\s]+\.md)(?:#([^)]+))?\)", page.read_text()):
            path = (page.parent / target[0]).resolve()
            assert path.is_file(), (page.name, target)
            if target[1]:
                slugs = {_slug(h) for h in re.findall(r"^#+ (.+)$", path.read_text(), flags=re.M)}
                assert target[1] in slugs, (page.name, target, sorted(slugs))


def _slug(heading):
    # GitHub's (and myst's) anchor of a heading: lower case, punctuation dropped, spaces to -
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_no_dated_measurement_is_left_in_the_readme():
    # the README's numbers with a date are only the headline ones, each pointing to the
    # page that has its machine and method
    for paragraph in re.split(r"\n\s*\n", README.read_text()):
        if re.search(r"20\d\d-\d\d-\d\d", paragraph):
            assert "docs/benchmarks.md" in paragraph, paragraph


README_TEST = 'python -m venv .venv && . .venv/bin/activate && pip install -e ".[test]" && python -m pytest -q'


def _ci_steps(tmp, pip_fails_on=None, uv_fails=False):
    """Run .ci/run with stand-ins for python, pip and uv that log what they are asked."""
    ci = tmp / ".ci"
    ci.mkdir()
    (ci / "run").write_text((ROOT / ".ci" / "run").read_text())
    bin_ = tmp / "bin"
    bin_.mkdir()
    log = tmp / "log"
    stub = {
        # python -m venv makes the folder with an activate script; anything else is logged
        "python": 'echo "python $*" >> LOG; if [ "$1 $2" = "-m venv" ]; then '
                  'mkdir -p "$3/bin"; : > "$3/bin/activate"; fi',
        "pip": f'echo "pip $*" >> LOG; [ "$*" != "{pip_fails_on}" ]',
        "uv": f'echo "uv $*" >> LOG; {"false" if uv_fails else "true"}',
    }
    for name, body in stub.items():
        (bin_ / name).write_text("#!/bin/sh\n" + body.replace("LOG", str(log)) + "\n")
        (bin_ / name).chmod(0o755)
    env = dict(os.environ, PATH=f"{bin_}:/usr/bin:/bin")
    done = subprocess.run(["bash", str(ci / "run")], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return log.read_text().splitlines(), done.stderr


def test_readme_test_command_is_the_one_ci_mirrors():
    assert README_TEST in [c for b in readme_blocks(README) for c in b]


@pytest.mark.parametrize("pip_fails_on, uv_fails", [(None, False), ("install -q uv", False),
                                                     (None, True)])
def test_ci_runs_the_readme_test_command(tmp_path, pip_fails_on, uv_fails):
    # .ci/run makes the README's environment, installs the package with its test extras
    # (through uv, or through pip as the README says when uv fails) and runs the README's
    # pytest command, as it is
    steps, stderr = _ci_steps(tmp_path, pip_fails_on, uv_fails)
    venv, _, _, pytest_ = README_TEST.split(" && ")
    assert steps[0] == venv
    assert steps[-1] == pytest_
    installs = [s for s in steps if '-e .[test]' in s]
    if pip_fails_on is None and not uv_fails:
        assert installs == ["uv pip install -q -e .[test]"] and stderr == ""
    else:
        # the README's install, with only the byte-compiling switched off
        assert installs[-1] == "pip install --no-compile -e .[test]"
        assert "installing with pip" in stderr


def test_every_command_that_takes_force_is_documented_with_it():
    takes = {name for name, p in _subparsers().items()
             if any("--force" in a.option_strings for a in p._actions)}
    assert takes == {"sweep", "atlas", "run", "reproduce", "bifurcation", "compare", "suite",
                     "animate"}
    paragraphs = [p for p in re.split(r"\n\s*\n", README.read_text()) if "`--force`" in p]
    documented = {name for name in takes for p in paragraphs
                  if re.search(rf"`moreau\s+{name}`", p)}
    assert documented == takes


# -- every command of the README, in a fresh process ----------------------------------
#
# Each README command maps to what runs here: the same command where it takes a few
# seconds, its quick variant where the README's own takes minutes (fewer points, fewer
# steps, one worker: the same code paths), or a reason to skip it (it installs
# packages or needs a cluster). A command added to the README without an entry here
# fails `test_the_table_covers_every_readme_command`. The commands of one README block
# run one after the other in one folder, as a user pasting the block would, so that
# a later command that would clash with an earlier one's files shows up.

SKIP_INSTALL = "installs packages"
SKIP_CLUSTER = "needs a Dask cluster (HEAD is a placeholder); --scheduler is tested in-process"

#: README command (comment stripped) -> (commands to run, files they must write) or a reason
COMMANDS = {
    # "moreau reproduce" after the install: the full run takes about an hour
    'python -m venv .venv && . .venv/bin/activate && pip install -e . && moreau reproduce':
        (["moreau reproduce --quick --jobs 1"],
         ["moreau-results/report.md", "moreau-results/data/frequency.csv",
          "moreau-results/data/phi0_2000Hz.json", "moreau-results/figures/mu_185Hz.png",
          "moreau-results/figures/mode_NP.png"]),
    'python -m venv .venv && . .venv/bin/activate && pip install -e ".[test]" && python -m pytest -q':
        "installs packages; the test suite is what runs this",
    'moreau sweep frequency 10 12500 --points 250 --scale log':
        (["moreau sweep frequency 10 12500 --points 3 --scale log --jobs 1"],
         ["out/sweep_frequency.csv", "out/sweep_frequency.json", "out/sweep_frequency.png"]),
    'moreau sweep mu 0.01 0.99 --points 99 --set frequency=185':
        (["moreau sweep mu 0.01 0.99 --points 2 --set frequency=185 --jobs 1"],
         ["out/sweep_mu_185Hz.csv", "out/sweep_mu_185Hz.json", "out/sweep_mu_185Hz.svg"]),
    'moreau sweep k 5e3 2e4 --points 40 --set frequency=185 --set mu=0.2':
        (["moreau sweep k 5e3 2e4 --points 2 --set frequency=185 --set mu=0.2 --jobs 1"],
         ["out/sweep_k_185Hz.csv", "out/sweep_k_185Hz.json"]),
    'moreau sweep mu --set frequency=185 --scheme moreau-jean --theta 0.5 --steps-per-period 2000':
        (["moreau sweep mu --set frequency=185 --scheme moreau-jean --theta 0.5 "
          "--steps-per-period 200 --points 2 --jobs 1"],
         ["out/sweep_mu_185Hz_mj_theta0.5_N200.csv", "out/sweep_mu_185Hz_mj_theta0.5_N200.json"]),
    'moreau characteristic --set frequency=185 --json':
        (["moreau characteristic --set frequency=185 --points 5 --json"],
         ["out/characteristic_friction-drive_185Hz_event-driven.csv",
          "out/characteristic_friction-drive_185Hz_event-driven.json",
          "out/characteristic_friction-drive_185Hz_event-driven.png"]),
    'moreau characteristic --efficiency-vs-frequency 20 185 2000':
        (["moreau characteristic --efficiency-vs-frequency 2000 --points 3 --json"],
         ["out/efficiency_friction-drive_2000-2000Hz_event-driven.csv",
          "out/efficiency_friction-drive_2000-2000Hz_event-driven.json",
          "out/efficiency_friction-drive_2000-2000Hz_event-driven.png"]),
    'moreau bifurcation frequency 1e4 5e4 --points 24 --set restitution=1':
        (["moreau bifurcation frequency 1e4 5e4 --points 2 --transient 5 --samples 3 "
          "--set restitution=1 --quiet"],
         ["out/bifurcation_friction-drive_frequency_event-driven.csv",
          "out/bifurcation_friction-drive_frequency_event-driven.json",
          "out/bifurcation_friction-drive_frequency_event-driven.png"]),
    'moreau atlas':
        (["moreau atlas --f-points 3 --y-points 2 --jobs 1"],
         ["out/atlas_f-mu.csv", "out/atlas_f-mu.json", "out/atlas_f-mu.png",
          "out/atlas_f-phi0.csv", "out/atlas_f-phi0.svg"]),
    'moreau atlas --plane f-phi0 --f-points 100 --y-points 50 --mu 0.2 --out out/mu0.2':
        (["moreau atlas --plane f-phi0 --f-points 3 --y-points 2 --mu 0.2 --out out/mu0.2 "
          "--jobs 1"],
         ["out/mu0.2/atlas_f-phi0.csv", "out/mu0.2/atlas_f-phi0.json"]),
    'moreau sweep load 0 0.1 --points 11 --scene stick-slip-motor --set frequency=1000':
        (["moreau sweep load 0 0.1 --points 2 --scene stick-slip-motor --set frequency=1000 "
          "--jobs 1"],
         ["out/sweep_stick-slip-motor_load_1000Hz_event-driven.csv",
          "out/sweep_stick-slip-motor_load_1000Hz_event-driven.json"]),
    'pip install -e ".[dask]"': SKIP_INSTALL,
    'dask scheduler': SKIP_CLUSTER,
    'dask worker tcp://HEAD:8786 --nworkers 8 --nthreads 1': SKIP_CLUSTER,
    'moreau atlas --scheduler tcp://HEAD:8786 --out /shared/atlas --cache /shared/moreau-cache':
        SKIP_CLUSTER,
    'moreau reproduce --scheduler tcp://HEAD:8786 --out /shared/results': SKIP_CLUSTER,
    'moreau steady --set frequency=185 --json': (["moreau steady --set frequency=185 --json"], []),
    'moreau steady --set frequency=2000 --set mu=0.5': (["moreau steady --set frequency=2000 --set mu=0.5"], []),
    'moreau steady --scene stick-slip-motor --set frequency=1000 --set drive=sine':
        (["moreau steady --scene stick-slip-motor --set frequency=1000 --set drive=sine"], []),
    'moreau run --set frequency=185 --periods 10':
        (["moreau run --set frequency=185 --periods 10"],
         ["out/history_friction-drive_frequency185_event-driven.csv",
          "out/history_friction-drive_frequency185_event-driven.json",
          "out/history_friction-drive_frequency185_event-driven.png"]),
    'moreau run --set frequency=185 --scheme moreau-jean --steps-per-period 2000':
        (["moreau run --set frequency=185 --scheme moreau-jean --steps-per-period 2000"],
         ["out/history_friction-drive_frequency185_moreau-jean_steps20000.csv",
          "out/history_friction-drive_frequency185_moreau-jean_steps20000.json"]),
    'moreau run --scene sliding-box --duration 0.5 --scheme moreau-jean --steps 5000 --theta 0.5':
        (["moreau run --scene sliding-box --duration 0.5 --scheme moreau-jean --steps 5000 "
          "--theta 0.5"],
         ["out/history_sliding-box_moreau-jean_steps5000_theta0.5.csv",
          "out/history_sliding-box_moreau-jean_steps5000_theta0.5.png"]),
    'moreau run --scene bouncing-ball --set restitution=0.9 --duration 2 --rtol 1e-12':
        (["moreau run --scene bouncing-ball --set restitution=0.9 --duration 2 --rtol 1e-12"],
         ["out/history_bouncing-ball_restitution0.9_event-driven_rtol1e-12.csv",
          "out/history_bouncing-ball_restitution0.9_event-driven_rtol1e-12.json"]),
    'moreau steady --set frequency=185 --scheme moreau-jean --steps-per-period 2000 --json':
        (["moreau steady --set frequency=185 --scheme moreau-jean --steps-per-period 2000 --json"],
         []),
    'moreau steady --scene bidirectional-drive --set frequency=185 --set x10_b=0':
        (["moreau steady --scene bidirectional-drive --set frequency=185 --set x10_b=0"], []),
    'moreau steady --scene bidirectional-drive --set frequency=185 --set x10_a=0':
        (["moreau steady --scene bidirectional-drive --set frequency=185 --set x10_a=0"], []),
    'moreau steady --scene bidirectional-drive --set frequency=185 --set phase=1.0 --scheme moreau-jean':
        (["moreau steady --scene bidirectional-drive --set frequency=185 --set phase=1.0 "
          "--scheme moreau-jean"], []),
    'python -m moreau.studies.bidirectional.direction_control out/':
        (["python -m moreau.studies.bidirectional.direction_control out/ --points 2"],
         ["out/direction_control.csv", "out/bidirectional_direction_control.png"]),
    'moreau sweep --scene bidirectional-drive phase 0 6.2832 --points 25 --set frequency=185':
        (["moreau sweep --scene bidirectional-drive phase 0 6.2832 --points 2 --set frequency=185 "
          "--jobs 1"],
         ["out/sweep_bidirectional_phase_185Hz.csv", "out/sweep_bidirectional_phase_185Hz.json"]),
    'moreau sweep --scene bidirectional-drive balance -1 1 --points 21 --set frequency=185 '
    '--scheme moreau-jean':
        (["moreau sweep --scene bidirectional-drive balance -1 1 --points 2 --set frequency=185 "
          "--scheme moreau-jean --jobs 1"],
         ["out/sweep_bidirectional_balance_185Hz_mj_theta1_N1000.csv",
          "out/sweep_bidirectional_balance_185Hz_mj_theta1_N1000.json"]),
    'pip install -e ".[bench]"': SKIP_INSTALL,
    # the benchmarks time for minutes (bench_lcp --quick: 22 s, tested in-process by
    # tests/test_bench_lcp_peer.py): here they only start and read their options
    'python benchmarks/bench_event_driven.py':
        (["python benchmarks/bench_event_driven.py --help"], []),
    'python benchmarks/bench_moreau_jean.py':
        (["python benchmarks/bench_moreau_jean.py --help"], []),
    'python benchmarks/bench_lcp.py --quick': (["python benchmarks/bench_lcp.py --help"], []),
    # about a minute: the four cases of one scene
    'python -m pytest benchmarks/test_regression.py -n 0':
        (["python -m pytest benchmarks/test_regression.py -n 0 -q -p no:cacheprovider "
          "-k ball"], []),
    'python -m pytest benchmarks/test_regression.py -n 0 --update-baselines':
        "rewrites the stored baselines of the checkout",
    'moreau scenes [--json]': (["moreau scenes", "moreau scenes --json"], []),
    'moreau compare --scene friction-drive --set frequency=185 [--out DIR] [--json] [--quick]':
        (["moreau compare --scene friction-drive --set frequency=185 --out cmp --json --quick"],
         ["cmp/compare_friction-drive_185Hz.csv", "cmp/compare_friction-drive_185Hz.json",
          "cmp/compare_friction-drive_185Hz.png"]),
    'moreau compare --scene NAME [--set NAME=VALUE ...]':
        (["moreau compare --scene painleve-rod --set mu=0.5 --quick"],
         ["out/compare_painleve-rod.csv", "out/compare_painleve-rod.json"]),
    'moreau compare --scene sliding-box --set speed=2 --set mu=0.3':
        (["moreau compare --scene sliding-box --set speed=2 --set mu=0.3 --quick"],
         ["out/compare_sliding-box.csv", "out/compare_sliding-box.png"]),
    # the map's first three columns: every other scheme's column on all 17 cases took 82 %
    # of the command's time (and grows with each new scheme) while nothing here reads the
    # rows; tests/test_stress.py holds every column's outcome, the default columns included
    'moreau compare --stress [--quick]':
        (["moreau compare --stress --quick --schemes event-driven,mj-1,mj-1/2"],
         ["out/stress.csv", "out/stress.json"]),
    # the suite's two smallest problems and two schemes (the quick suite takes minutes)
    'moreau suite --quick --out suite-results':
        (["moreau suite --quick --problems sliding-block,painleve-rod "
          "--schemes moreau-jean,event-driven --out suite-results"],
         ["suite-results/index.md", "suite-results/suite.csv", "suite-results/overview.png",
          "suite-results/wp_sliding-block.png"]),
    'moreau suite --quick --compare-to history.json --out suite-results':
        (["moreau suite --quick --problems sliding-block,painleve-rod "
          "--schemes moreau-jean,event-driven --compare-to history.json --out suite-results"],
         ["history.json"]),
    'moreau run --scene sliding-box --duration 0.5 --out run1':
        (["moreau run --scene sliding-box --duration 0.5 --out run1 --samples 50"],
         ["run1/history_sliding-box_event-driven.csv"]),
    'moreau animate run1 --out box.gif': (["moreau animate run1 --out box.gif --frames 5"],
                                          ["box.gif"]),
    'moreau compare --scene bouncing-ball --schemes compliant-radau,compliant-rk45':
        (["moreau compare --scene bouncing-ball --schemes compliant-radau,compliant-rk45 "
          "--quick"], ["out/compare_bouncing-ball.csv", "out/compare_bouncing-ball.json"]),
}


def readme_blocks(*pages):
    """The bash blocks of the guide (or of ``pages``), each a list of commands without comments."""
    text = "\n".join(p.read_text() for p in (pages or GUIDE))
    blocks = re.findall(r"```bash\n(.*?)```", text, flags=re.S)
    return [[line.split("  #")[0].strip() for line in b.splitlines()
             if line.strip() and not line.startswith("#")] for b in blocks]


def test_the_table_covers_every_readme_command():
    readme = [c for block in readme_blocks() for c in block]
    assert sorted(set(readme)) == sorted(COMMANDS)


def _argv(command):
    # `benchmarks/...` is the checkout's (the scripts find the test scenes beside them)
    words = [str(README.parent / w) if w.startswith("benchmarks/") else w
             for w in shlex.split(command)]
    if words[0] == "moreau":
        return [sys.executable, "-m", "moreau"] + words[1:]
    if words[0] == "python":
        return [sys.executable] + words[1:]
    raise AssertionError(f"no way to run {command!r}")


@pytest.mark.slow
@pytest.mark.parametrize("block", range(len(readme_blocks())))
def test_every_readme_command_runs_in_a_fresh_process(block, tmp_path):
    commands = readme_blocks()[block]
    runnable = [COMMANDS[c] for c in commands if not isinstance(COMMANDS[c], str)]
    if not runnable:
        pytest.skip("; ".join(sorted({COMMANDS[c] for c in commands})))
    root = README.parent
    # a user's shell, not an xdist worker's (pytest-benchmark turns itself off under one)
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_")}
    env["PYTHONPATH"] = os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")])
    for variants, files in runnable:
        for command in variants:
            done = subprocess.run(_argv(command), cwd=tmp_path, env=env, capture_output=True,
                                  text=True, timeout=300)
            assert done.returncode == 0, (command, done.stdout[-2000:], done.stderr[-2000:])
            assert "Traceback" not in done.stderr, (command, done.stderr[-2000:])
            if "--json" in command.split():
                assert json.loads(done.stdout), command
        for name in files:
            path = tmp_path / name
            assert path.is_file() and path.stat().st_size > 0, (commands, name)
