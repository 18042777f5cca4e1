"""The command line (planarsim = walkers.cli.main). Runs in-process through main."""
import json
import os

import numpy as np
import pytest

from walkers.cli import main
from planarsim.trajectory import Trajectory
import walkers


def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("walker", sorted(walkers.WALKERS))
def test_run_each_walker_writes_the_files_asked_for(walker, tmp_path, capsys):
    files = dict(out=tmp_path / "a.gif", plot=tmp_path / "p.png", save=tmp_path / "t.npz",
                 csv=tmp_path / "t.csv")
    code, out, err = run_cli(capsys, "run", walker, "--duration", "0.3", "--fps", "10",
                             "--out", str(files["out"]), "--plot", str(files["plot"]),
                             "--save", str(files["save"]), "--csv", str(files["csv"]), "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["walker"] == walker
    for p in files.values():
        assert p.exists() and p.stat().st_size > 0
    traj = Trajectory.load(files["save"])
    assert abs(traj.t[-1] - 0.3) < 0.02
    assert np.all(np.isfinite(traj.q))


@pytest.mark.parametrize("argv, fragment", [
    (["run", "no-such-walker"], "unknown walker 'no-such-walker'"),
    (["run", "simple-biped", "--terrain", "bumpy"], "terrain spec 'bumpy' not understood"),
    (["run", "simple-biped", "--out", "/no/such/folder/x.gif"], "does not exist"),
    (["run", "simple-biped", "--out", "x.avi"], "extension must be one of"),
    (["run", "simple-biped", "--gait", "fly"], "has no gait 'fly'"),
])
def test_user_errors_exit_2_with_one_line(argv, fragment, capsys):
    code, out, err = run_cli(capsys, *argv)
    assert code == 2
    assert fragment in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err


def test_negative_duration_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as e:
        main(["run", "simple-biped", "--duration", "-1"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "--duration" in err
    assert len(err.strip().splitlines()) == 1, err    # one line, not the usage first


def test_view_without_a_display_says_so_and_exits_2(monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    code, out, err = run_cli(capsys, "view", "ranger")
    assert code == 2
    assert "no display" in err and "planarsim run ranger" in err


def test_tune_refuses_a_budget_below_one_generation(tmp_path, capsys):
    out = tmp_path / "tuned.json"
    code, _, err = run_cli(capsys, "tune", "simbicon", "--budget", "3", "--out", str(out))
    assert code == 2
    assert "budget 3 is smaller than one generation" in err
    assert not out.exists()


def test_unwritable_output_path(tmp_path, capsys):
    import os
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        # root may write anywhere except where the kernel says no (/proc/1 on Linux)
        folder = locked if not os.access(locked, os.W_OK) else "/proc/1"
        if os.access(folder, os.W_OK):
            pytest.skip("no unwritable folder available to this user")
        code, out, err = run_cli(capsys, "run", "simple-biped", "--out", f"{folder}/x.gif")
        assert code == 2 and "not writable" in err
    finally:
        locked.chmod(0o700)


@pytest.mark.parametrize("flag, path, said", [
    # root passes os.access in /proc; the run took its 10 s, then the export failed
    ("--out", "/proc/x.gif", "--out '/proc/x.gif': not writable"),
    ("--plot", "/proc/x.png", "--plot '/proc/x.png': not writable"),
    ("--csv", "adir.csv", "--csv 'adir.csv': is a folder"),
    ("--out", "adir.gif", "--out 'adir.gif': is a folder"),
])
def test_outputs_that_cannot_be_written_are_refused_before_the_run(flag, path, said, tmp_path,
                                                                   monkeypatch, capsys):
    if path.startswith("/proc") and not os.path.isdir("/proc"):
        pytest.skip("no /proc")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "adir.csv").mkdir()
    (tmp_path / "adir.gif").mkdir()
    monkeypatch.setattr(walkers.load("simple-biped"), "Run",
                        lambda *a, **k: pytest.fail("the walker was run"))
    code, _, err = run_cli(capsys, "run", "simple-biped", flag, path, "--json")
    assert code == 2 and said in err, err


def test_a_default_summary_path_that_is_a_folder_is_refused_before_the_run(tmp_path, monkeypatch,
                                                                           capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out" / "simple-biped_summary.json").mkdir(parents=True)
    monkeypatch.setattr(walkers.load("simple-biped"), "Run",
                        lambda *a, **k: pytest.fail("the walker was run"))
    code, _, err = run_cli(capsys, "run", "simple-biped")
    assert code == 2 and "the summary 'out/simple-biped_summary.json': is a folder" in err, err


@pytest.mark.parametrize("out", [None, "walk.gif"])
def test_a_gif_faster_than_50_fps_is_refused_before_the_run(out, tmp_path, monkeypatch, capsys):
    """--fps 60 wrote a GIF, after the run, that most viewers play at about a third of its speed
    (every other delay of 1/100 s shown as 1/10 s)."""
    monkeypatch.chdir(tmp_path)
    mod = walkers.load("simple-biped")
    monkeypatch.setattr(mod, "Run", lambda *a, **k: pytest.fail("the walker was run"))
    code, _, err = run_cli(capsys, "run", "simple-biped", "--fps", "60",
                           *(["--out", out] if out else []))
    assert code == 2
    assert "--fps 60 frames/s is too fast for a GIF" in err and "give at most 50 fps" in err


@pytest.mark.parametrize("sub", ["list", "run", "view", "bench", "tune", "info"])
def test_help_of_every_subcommand(sub, capsys):
    with pytest.raises(SystemExit) as e:
        main([sub, "--help"])
    assert e.value.code == 0
    assert "usage" in capsys.readouterr().out.lower()


def test_list_and_info(capsys):
    code, out, err = run_cli(capsys, "list")
    assert code == 0 and "simple-biped" in out and "slope:DEG" in out
    code, out, err = run_cli(capsys, "info")
    assert code == 0 and "numba" in out


def test_json_alone_renders_nothing(tmp_path, monkeypatch, capsys):
    """--json without --out is for scripts: the summary only, no default animation written."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.2", "--json")
    assert code == 0, err
    assert json.loads(out)["files"] == []
    assert not (tmp_path / "out").exists()


def test_list_marks_each_walkers_default_gait(capsys):
    code, out, _ = run_cli(capsys, "list")
    assert code == 0
    assert "stand, walk (default), jump" in out      # the Simple Biped walks by default


def test_a_reader_that_stops_early_is_not_an_error(tmp_path, monkeypatch, capsys):
    """planarsim params ranger | head -1: the closed pipe is the reader's choice, exit 0 and
    no message (an OSError handler used to catch it first: exit 2, 'Broken pipe')."""
    sink = open(tmp_path / "sink", "w")

    class ClosedPipe:
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            pass

        def fileno(self):
            return sink.fileno()
    monkeypatch.setattr("sys.stdout", ClosedPipe())
    code = main(["params", "ranger"])
    err = capsys.readouterr().err
    assert code == 0 and "Broken pipe" not in err, err


def test_a_reader_that_leaves_does_not_stop_the_files(tmp_path, monkeypatch, capsys):
    """planarsim analyze ... --csv d.csv --plot d.png | head -1: the printing stops, the command
    goes on and writes what it was asked for."""
    sink = open(tmp_path / "sink", "w")

    class ClosedPipe:
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            pass

        def fileno(self):
            return sink.fileno()
    monkeypatch.setattr("sys.stdout", ClosedPipe())
    csv_path, png = tmp_path / "d.csv", tmp_path / "d.png"
    code = main(["analyze", "simplest-walker", "--param", "slope", "--range", "0.009:0.010",
                 "--points", "6", "--diagram", "--transient", "1", "--keep", "2", "--csv",
                 str(csv_path), "--plot", str(png), "--workers", "1"])
    assert code == 0, capsys.readouterr().err
    assert csv_path.stat().st_size > 0 and png.stat().st_size > 0


@pytest.mark.parametrize("argv, fragment", [
    (["tune", "simple-biped", "--start", "/nonexistent.json"],
     "--start /nonexistent.json: no such file"),
    (["bench", "--parts", "nosuch"], "--parts nosuch: unknown part(s) ['nosuch']; choose from"),
    (["run", "simple-biped", "--dt", "-1e-3"], "argument --dt: -1e-3 must be a finite number > 0"),
    (["run", "simple-biped", "--dt", "0"], "argument --dt: 0 must be a finite number > 0"),
    (["run", "simple-biped", "--dt", "2.0"], "--dt 2 s is too large; use a step of at most 0.01 s"),
    (["analyze", "simplest-walker", "--param", "slope", "--range", "0.01:0.02", "--dt", "0.05"],
     "--dt 0.05 s is too large"),
    # numpy's own words, naming no flag: "error: expected non-negative integer"
    (["run", "simple-biped", "--seed", "-5", "--json"], "argument --seed: -5 must be a whole number >= 0"),
    # a run of no step exited 0 with the summary of a walker that never moved
    (["run", "simple-biped", "--duration", "1e-6", "--json"],
     "--duration 1e-06 s is less than half a step (dt=0.001 s): the run would take no step"),
])
def test_bad_flags_exit_2_naming_the_flag(argv, fragment, capsys):
    """--start of a missing file said only "[Errno 2] No such file or directory"; an unknown
    --parts exited 1; --dt -1e-3 read as an option ("expected one argument")."""
    try:
        code = main(argv)
    except SystemExit as e:          # argparse's own usage errors
        code = e.code
    err = capsys.readouterr().err
    assert code == 2
    assert fragment in err, err
    assert "Traceback" not in err


def test_a_step_so_small_the_run_would_not_end_is_refused_naming_dt_and_duration(capsys,
                                                                                monkeypatch):
    """Where its recording fits in memory (here any: 5e8 steps at --dt 1e-8 for 5 s need 18 GB),
    a run at a tiny --dt ran for hours."""
    import planarsim.memory
    monkeypatch.setattr(planarsim.memory, "machine_memory", lambda: 2 ** 50)
    monkeypatch.setattr(walkers.load("simple-biped").Run, "advance",
                        lambda *a: pytest.fail("the walker was run"))
    code, _, err = run_cli(capsys, "run", "simple-biped", "--dt", "1e-9", "--json")
    assert code == 2
    assert ("--duration 10 s at dt=1e-09 s would take 10,000,000,000 steps, more than 100,000,000 "
            "(a run that long would take practically forever); give a larger --dt or a shorter "
            "--duration") in err, err


def test_default_animation_in_an_unwritable_folder(tmp_path, monkeypatch, capsys):
    """A run from a folder where out/ cannot be made said only "[Errno 2] No such file or
    directory: 'out'" (in /proc)."""
    import os
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        folder = locked if not os.access(locked, os.W_OK) else "/proc/1"
        if not os.path.isdir(folder) or os.access(folder, os.W_OK):
            pytest.skip("no unwritable folder available to this user")
        monkeypatch.chdir(folder)
        code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "1")
        assert code == 2
        assert "cannot write the default animation 'out/simple-biped.gif'" in err
        assert "--out FILE.gif, or --no-animation" in err
    finally:
        locked.chmod(0o700)


def test_tune_start_file_that_is_not_a_result(tmp_path, capsys):
    """A --start JSON without the result's fields stopped with a KeyError traceback."""
    start = tmp_path / "start.json"
    start.write_text('{"format_version": 1}')
    code, _, err = run_cli(capsys, "tune", "simple-biped", "--start", str(start), "--budget", "1")
    assert code == 2
    assert "start.json: not a tuning result: missing ['walker', 'best_params'" in err
    assert "Traceback" not in err
