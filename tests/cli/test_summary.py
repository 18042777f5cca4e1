"""Every walker's `planarsim run` summary has the same common keys, units in their names, whole-
step quantities that do not depend on where the run ends, wall time split into compile and
run, and only declared, explained extras."""
import json

import pytest

import walkers
from walkers.cli import main

COMMON = ("walker", "gait", "terrain", "duration_s", "params_changed", "time_s", "fell",
          "distance_m", "mean_speed_m_per_s", "steps", "whole_steps", "step_period_s",
          "step_length_m", "step_speed_m_per_s", "audit", "wall_time_s", "extras", "files")


def run_json(capsys, *argv):
    code = main(["run", *map(str, argv), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


@pytest.mark.parametrize("walker", sorted(walkers.WALKERS))
def test_every_walker_reports_the_common_keys(walker, capsys):
    s = run_json(capsys, walker, "--duration", "3")
    assert tuple(s) == COMMON
    assert set(s["wall_time_s"]) == {"compile", "run", "output"}
    assert s["terrain"] != "default"
    assert s["whole_steps"] >= 1 and s["steps"] == s["whole_steps"] + 1
    assert 0 < s["step_period_s"] < 3 and s["step_length_m"] > 0
    # every extra is declared with a unit-named key and an explanation
    spec = walkers.load(walker).SUMMARY_EXTRAS
    declared = {v[0] for v in spec.values() if v is not None}
    assert set(s["extras"]) <= declared
    assert all(doc for _, doc in (v for v in spec.values() if v is not None))


def test_whole_step_speed_does_not_depend_on_where_the_run_ends(capsys):
    """The Simple Biped starts walking at about 2 s: a run's mean speed depends on its length,
    the whole-step speed much less."""
    a = run_json(capsys, "simple-biped", "--duration", "6")
    b = run_json(capsys, "simple-biped", "--duration", "6.3")
    assert abs(a["step_speed_m_per_s"] - b["step_speed_m_per_s"]) < 0.05 * a["step_speed_m_per_s"]
    short = run_json(capsys, "simple-biped", "--duration", "3")
    assert short["mean_speed_m_per_s"] < 0.8 * a["mean_speed_m_per_s"]


def test_a_raw_key_nobody_declared_is_an_error(monkeypatch):
    from walkers.common.summary import walker_summary
    mod = walkers.load("simplest-walker")
    traj, raw, model = mod.simulate(2.0)
    raw = {**raw, "mystery": 1.0}
    with pytest.raises(KeyError, match="mystery"):
        walker_summary(mod, traj, model, raw, walker="simplest-walker", gait="passive",
                       terrain="slope", duration=2.0)


def test_the_walkers_page_explains_every_walker_extra():
    """docs/walkers.md names every key of every walker's summary extras, in its walker's line."""
    from pathlib import Path
    page = (Path(__file__).resolve().parents[2] / "docs" / "walkers.md").read_text()
    lines = {line.split(":")[0][2:]: line for line in page.splitlines() if line.startswith("- ")}
    missing = [(name, key) for name in sorted(walkers.WALKERS)
               for key, _ in (v for v in walkers.load(name).SUMMARY_EXTRAS.values() if v is not None)
               if f"`{key}`" not in lines.get(name, "")]
    assert not missing


def test_a_jump_is_one_landing(capsys):
    """Both feet of a jump land within MIN_AIR_S: the summary counts the walker's own jumps."""
    assert main(["run", "simple-biped", "--gait", "jump", "--duration", "6", "--json", "--no-animation"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["extras"]["jumps"] >= 2 and s["steps"] == s["extras"]["jumps"]
