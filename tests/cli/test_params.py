"""Walker parameters from the command line: `planarsim params`, `run --set / --params`, and
tune-then-run for every walker that has a tuning objective."""
import json
from dataclasses import fields

import pytest

import walkers
from walkers.cli import main

TUNABLE = ("quadruped", "ranger", "simbicon", "simple-biped")


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("walker", sorted(walkers.WALKERS))
def test_params_lists_every_field_with_unit_bounds_and_default(walker, capsys):
    code, out, err = run_cli(capsys, "params", walker, "--json")
    assert code == 0, err
    rows = json.loads(out)
    cls = walkers.load(walker).Params
    assert [r["name"] for r in rows] == [f.name for f in fields(cls)]
    for r in rows:
        assert r["unit"] and r["doc"]
        assert r["lower"] <= r["default"] <= r["upper"]
    # the walkers that can be tuned have tunable fields, the passive ones none
    assert any(r["tunable"] for r in rows) == (walker in TUNABLE)


def test_list_says_which_walkers_can_be_tuned(capsys):
    code, out, _ = run_cli(capsys, "list")
    assert code == 0
    lines = {ln.split()[0]: ln for ln in out.splitlines() if ln.startswith("  ") and ln.split()[0] in walkers.WALKERS}
    assert {w for w, ln in lines.items() if "[tunable]" in ln} == set(TUNABLE)


def test_set_changes_the_physics_and_is_reported(capsys):
    base = json.loads(run_cli(capsys, "run", "simple-biped", "--duration", "3", "--json")[1])
    code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "3", "--json",
                             "--set", "hip_mass=14", "--set", "mu=0.9")
    assert code == 0, err
    heavy = json.loads(out)
    assert heavy["params_changed"] == {"hip_mass": 14.0}    # mu=0.9 is the default
    assert base["params_changed"] == {}
    assert heavy["extras"]["positive_work_J"] != base["extras"]["positive_work_J"]


def test_params_file_then_set_later_wins(tmp_path, capsys):
    f = tmp_path / "p.json"
    f.write_text(json.dumps({"slope": 0.01, "leg_length": 1.0}))
    code, out, err = run_cli(capsys, "run", "simplest-walker", "--duration", "1", "--json",
                             "--params", f, "--set", "slope=0.012")
    assert code == 0, err
    assert json.loads(out)["params_changed"] == {"slope": 0.012}


@pytest.mark.parametrize("argv, fragment", [
    (["--set", "bogus=1"], "has no parameter 'bogus'"),
    (["--set", "speed"], "write NAME=VALUE"),
    (["--set", "speed=fast"], "'fast' is not a number"),
    (["--set", "speed=9"], "speed=9.0 outside its bounds"),
    (["--params", "/no/such/file.json"], "cannot read it"),
])
def test_bad_parameters_exit_2_naming_the_culprit(argv, fragment, capsys):
    code, out, err = run_cli(capsys, "run", "simple-biped", "--json", *argv)
    assert code == 2
    assert fragment in err and len(err.strip().splitlines()) == 1
    assert out == ""


def test_a_params_file_of_another_walker_is_refused(tmp_path, capsys):
    f = tmp_path / "ranger.json"
    f.write_text(json.dumps({"best_params": {"push_gain": 5.0}, "walker": "ranger"}))
    code, _, err = run_cli(capsys, "run", "simple-biped", "--json", "--params", f)
    assert code == 2 and "has no parameter(s) ['push_gain']" in err


def test_tune_refuses_a_walker_without_an_objective(capsys):
    code, _, err = run_cli(capsys, "tune", "rimless-wheel", "--budget", "4")
    assert code == 2 and "no tuning objective" in err and "simple-biped" in err


@pytest.mark.parametrize("walker", TUNABLE)
def test_tune_then_run_with_the_result(walker, tmp_path, capsys):
    out = tmp_path / "tuned.json"
    code, text, err = run_cli(capsys, "tune", walker, "--budget", "4", "--popsize", "4",
                              "--duration", "1", "--workers", "1", "--seed", "3", "--out", out)
    assert code == 0, err
    result = json.loads(out.read_text())
    assert result["walker"] == walker and result["evaluations"] == 4
    assert result["best_score"] >= result["start_score"]
    # the tuned parameters score what the tuner says, on the tuning objective, in this process
    objective = walkers.objective(walker)
    best = objective.Params(**result["best_params"])
    settings = dict(result["settings"])
    assert objective.evaluate(best, settings)["score"] == pytest.approx(result["best_score"], rel=1e-12)
    assert objective.evaluate(objective.Params(), settings)["score"] <= result["best_score"]
    code, text, err = run_cli(capsys, "run", walker, "--duration", "1", "--json", "--params", out)
    assert code == 0, err
    changed = json.loads(text)["params_changed"]
    defaults = objective.Params().as_dict()
    assert changed == {k: v for k, v in result["best_params"].items() if v != defaults[k]}


def test_a_count_takes_whole_numbers(capsys):
    code, out, err = run_cli(capsys, "run", "rimless-wheel", "--duration", "1", "--json",
                             "--set", "n_spokes=10")
    assert code == 0, err
    assert json.loads(out)["params_changed"] == {"n_spokes": 10}
    code, out, err = run_cli(capsys, "run", "rimless-wheel", "--json", "--set", "n_spokes=7.5")
    assert code == 2 and "must be a whole number" in err and len(err.strip().splitlines()) == 1


def test_slope_set_twice_is_refused(capsys):
    code, _, err = run_cli(capsys, "run", "simplest-walker", "--json", "--set", "slope=0.01",
                           "--terrain", "slope:-1")
    assert code == 2 and "--set slope and --terrain" in err


def test_bad_parameters_make_no_output_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    code, _, _ = run_cli(capsys, "run", "simple-biped", "--set", "bogus=1")
    assert code == 2 and not (tmp_path / "out").exists()
