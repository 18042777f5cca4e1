"""The benchmark runner on tiny settings, so that `planarsim bench` cannot silently
break; no timing is asserted. The peer checks run only for the peers that are installed
(`pip install planarsim[compare]`); the runner itself must work without them."""
import csv
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import planarsim as ps
from benchmarks import runner as bench
from benchmarks.metrics import accuracy, spec_from_model
from benchmarks.peers import PEER_MODULES, available_peers
from benchmarks.scenes import biped_collapse, chain

ROOT = Path(__file__).resolve().parents[2]
TINY = ["--repeats", "1", "--steps", "20", "--accuracy-seconds", "0.05"]


def test_scenes_and_peers_print_figures_and_write_csv(tmp_path, capsys):
    assert bench.main(["chain2", "rod_drop", "--parts", "scenes,peers", "--csv", str(tmp_path), *TINY]) == 0
    out = capsys.readouterr().out
    assert "planarsim scenes" in out and "benchmark targets" in out
    found, missing = available_peers()
    assert len(found) + len(missing) == len(PEER_MODULES)
    for name in found:
        assert f"chain2          {name}" in out
    for msg in missing:
        assert msg in out
    folder = tmp_path / bench.machine_name()
    rows = list(csv.DictReader(open(folder / "chain2.csv")))
    engines = [r["engine"] for r in rows]
    assert engines == ["planarsim", *found]
    # accuracy figures are physics, not timing: the engine's pins hold to README's 2e-12 m
    assert float(rows[0]["pin_error_m"]) <= 2e-12
    assert float(rows[0]["steps_per_s"]) > 0
    assert {"rod_drop.csv", "targets.csv"} <= {p.name for p in folder.iterdir()}


def test_missing_peer_is_named_and_skipped(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pymunk", None)  # import pymunk now raises ImportError
    assert bench.main(["chain2", "--parts", "peers", "--peers", "pymunk", *TINY]) == 0
    out = capsys.readouterr().out
    assert "peer pymunk: not installed" in out and "pip install planarsim[compare]" in out
    assert "peer comparison skipped" in out


def test_walkers_batch_and_warm_startup_parts(capsys):
    argv = ["--parts", "walkers,batch,startup", "--walkers", "simple-biped", "--walker-seconds", "0.05",
            "--batch-jobs", "2", "--batch-seconds", "0.05", "--no-cold", "--repeats", "1"]
    assert bench.main(argv) == 0
    out = capsys.readouterr().out
    assert "simple-biped     walk" in out
    assert "workers=1" in out and "workers=2" in out
    assert "warm numba cache" in out and "cold numba cache" not in out


def test_a_walker_that_fails_makes_the_run_fail(monkeypatch, capsys):
    """A walker that raised was printed as FAILED and the run exited 0, its figures missing."""
    import benchmarks.walker_runs as runs

    def broken(name, seconds, repeats):
        raise RuntimeError("broken on purpose")
    monkeypatch.setattr(runs, "measure_walker", broken)
    assert bench.main(["--parts", "walkers", "--walkers", "ranger", "--repeats", "1"]) == 1
    captured = capsys.readouterr()
    assert "walker ranger: FAILED with RuntimeError: broken on purpose" in captured.out
    assert "bench: 1 walker(s) failed: ranger (exit 1)" in captured.err


def test_scene_without_peer_version_runs_with_its_default_settings(capsys):
    assert bench.main(["boxes_on_hills", "--parts", "scenes,peers", "--repeats", "1", "--steps", "20"]) == 0
    assert "boxes_on_hills" in capsys.readouterr().out


def test_bad_arguments_name_the_culprit(capsys):
    """An unknown part exited with status 1 (not argparse's 2 for a usage error)."""
    with pytest.raises(SystemExit) as e:
        bench.main(["--parts", "scenes,nonsense"])
    assert e.value.code == 2
    assert ("--parts scenes,nonsense: unknown part(s) ['nonsense']; choose from ['scenes'"
            in capsys.readouterr().err)
    with pytest.raises(SystemExit):
        bench.main(["no_such_scene"])


@pytest.mark.parametrize("argv, said", [
    (["--batch-jobs", "0", "--parts", "batch"], "--batch-jobs 0 must be >= 1"),
    (["--walker-seconds", "-1", "--parts", "walkers"], "--walker-seconds -1.0 must be"),
    (["chain2", "--steps", "0"], "--steps 0 must be >= 1"),
    (["chain2", "--accuracy-seconds", "-1"], "--accuracy-seconds -1.0 must be"),
    (["--env-copies", "0", "--parts", "envs"], "--env-copies 0 must be >= 1"),
    (["--batch-seconds", "nan", "--parts", "batch"], "--batch-seconds nan must be"),
    (["--pareto-out", "/proc/no/such", "--parts", "pareto"], "--pareto-out /proc/no/such: cannot"),
])
def test_bad_values_are_refused_before_the_runs(argv, said, capsys):
    """Values a part would have failed on (a division by zero after the walks), ignored (0
    steps timed the scene's default) or met only after the header, each refused at once as a
    usage error naming its flag."""
    with pytest.raises(SystemExit) as e:
        bench.main(argv)
    assert e.value.code == 2
    assert said in capsys.readouterr().err


def test_benchmarks_run_py_is_the_same_command():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "run.py"), "chain2", "--parts", "scenes",
                           "--peers", "none", *TINY], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "chain2" in proc.stdout and "benchmark targets" in proc.stdout


@pytest.mark.parametrize("peer", sorted(PEER_MODULES))
@pytest.mark.parametrize("scene", ["chain2", "biped_collapse"])
def test_peer_builds_the_same_scene(peer, scene):
    """Each installed peer starts from the scene's exact pose, and the chain moves like
    planarsim's for 0.15 s (same masses, inertias, pins, gravity; the peers' joints are soft to
    a few mm). The biped is compared at the start only: Box2D's 1 cm polygon skin pushes the
    foot that starts 1 mm above the ground up at once."""
    found, _ = available_peers([peer])
    if peer not in found:
        # the test extra installs every peer: in CI a missing one fails instead of skipping
        if os.environ.get("CI"):
            pytest.fail(f"{peer} is not installed in CI (the test extra lists it)")
        pytest.skip(f"{peer} not installed (compare extra)")
    model = chain(2) if scene == "chain2" else biped_collapse()
    n = 150 if scene == "chain2" else 10
    spec = spec_from_model(scene, model, n * model.dt)
    q, v = found[peer].World(spec).record(n)
    assert np.allclose(q[0], model.q0, atol=1e-9)
    if scene == "chain2":
        traj = ps.Simulator(model).run(n_steps=n, record_every=1)
        assert np.allclose(q[-1], traj.q[-1], atol=1e-2)
    assert np.isfinite(accuracy(spec, q, v)["energy_drift"])


def test_box_columns_report_their_cost_growth_and_peer_ratio(capsys, tmp_path):
    """Two box columns give the log-log slope of their cost per step against N in the
    targets table, and each peer's raw ratio beside the engine's figures. The slopes are
    checked against the costs the run wrote (log(c10 / c5) / log 2, c = 1 / steps per s) and
    the target's verdict against its bound, 1.5; the timing itself is not asserted."""
    assert bench.main(["box_column5", "box_column10", "--parts", "scenes,peers", "--csv", str(tmp_path),
                       *TINY]) == 0
    out = capsys.readouterr().out
    folder = tmp_path / bench.machine_name()
    rows = {n: {r["engine"]: r for r in csv.DictReader(open(folder / f"box_column{n}.csv"))} for n in (5, 10)}
    slopes = {e: math.log(float(rows[5][e]["steps_per_s"]) / float(rows[10][e]["steps_per_s"])) / math.log(2.0)
              for e in rows[10]}
    line = next(x for x in out.splitlines() if "box columns: cost per step grows" in x)
    printed, verdict = re.search(r"slope (-?\d+\.\d+)\s+(met|NOT MET)\s*$", line).groups()
    assert float(printed) == pytest.approx(slopes["planarsim"], abs=0.0051), (line, slopes)
    assert verdict == ("met" if slopes["planarsim"] <= 1.5 else "NOT MET"), (line, slopes)
    fits = dict(re.findall(r"(\w+) (-?\d+\.\d+)", out.split("log-log fit over the box columns run):")[1].splitlines()[0]))
    assert set(fits) == set(slopes)
    for engine, slope in slopes.items():
        assert float(fits[engine]) == pytest.approx(slope, abs=0.0051), (engine, fits, slopes)
    # the engine's columns stand: no box moves (contacts that neither sink nor slide)
    for n in (5, 10):
        assert float(rows[n]["planarsim"]["stack_drift_m"]) <= 1e-9
    for name in available_peers()[0]:
        assert f"box_column10    {name}" in out


def test_stress_part_prints_every_stress_scene(capsys):
    """`planarsim bench --parts stress` on 5 steps: a row per stress scene, a column per peer."""
    from benchmarks.stress_scenes import STRESS_SCENES
    assert bench.main(["--parts", "stress", "--repeats", "1", "--steps", "5"]) == 0
    out = capsys.readouterr().out
    for name in STRESS_SCENES:
        assert f"\n{name} " in out, name
    for name in available_peers()[0]:
        assert f"{name} ms" in out


def test_md_writes_the_machines_results_page(tmp_path, capsys):
    """--md DIR writes DIR/<machine>.md (the documentation's benchmarks page shows
    benchmarks/results/*.md): the command line, the targets as a Markdown table with one row per
    target, and the figures the run printed."""
    argv = ["chain2", "--parts", "scenes", "--md", str(tmp_path), *TINY]
    assert bench.main(argv) == 0
    out = capsys.readouterr().out
    page = (tmp_path / f"{bench.machine_name()}.md").read_text()
    assert f"wrote {tmp_path / bench.machine_name()}.md" in out
    assert page.startswith(f"## Measured on `{bench.machine_name()}`")
    assert f"`planarsim bench {' '.join(argv)}`" in page
    commit = bench._git_commit()          # the checkout's commit, where there is one
    assert (f" at commit {commit} (" in page) if commit else ("at commit" not in page)
    table = [line for line in page.splitlines() if line.startswith("| ")]
    assert table[0] == "| benchmark target | measured | status |"
    targets = out[out.index("benchmark targets (measured in this run)"):].splitlines()[1:]
    assert len(table) - 1 == len([t for t in targets if t.startswith("  ")]) > 0
    assert any("(chain2)" in row and row.endswith(("| met |", "| NOT MET |")) for row in table)
    # the printed figures, verbatim, in a text block
    printed = page[page.index("```text\n") + 8:page.rindex("```")]
    assert "planarsim scenes" in printed and "chain2 " in printed
    assert printed.strip() in out


def test_worlds_growth_is_the_log_log_slope_of_the_median_step():
    """stress.growth: from the smallest world to the largest, log(t1 / t0) / log(n1 / n0) of
    the median steps; rows without a median (planarsim stopped) are left out."""
    from benchmarks.stress import growth
    from benchmarks.stress_scenes import WORLD_SCENES
    rows = [dict(bodies=10, median_ms=0.02), dict(bodies=1000, median_ms=2.0 * 100 ** 1.3 * 0.01),
            dict(bodies=100, median_ms=0.5), dict(bodies=5000)]
    k, (n0, t0), (n1, t1) = growth(rows)
    assert (n0, n1) == (10, 1000)
    assert k == pytest.approx(math.log(t1 / t0) / math.log(100.0))
    assert growth(rows[:1]) is None
    assert [s.n_body for s in WORLD_SCENES.values()] == [10, 100, 210, 400, 1035]
