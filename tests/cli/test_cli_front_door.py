"""The command line's front door: what a new user meets first. A duration that cannot be
recorded, an interrupt at any moment, the first compile, progress in pipes, tuning budgets,
the gaits `list` shows and the summary's files: each answered in one clear way."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from walkers.cli import main

ROOT = Path(__file__).resolve().parents[2]


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# a duration that cannot fit in memory ----------------------------------------------------------
def test_a_duration_that_cannot_be_recorded_is_one_line_naming_the_option(capsys):
    code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "1e9", "--json")
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "--duration" in err and "GiB" in err and "memory" in err


# Ctrl-C at any moment ---------------------------------------------------------------------------
def _interrupt_after(delay, *argv):
    """Run `planarsim ARGV` as its own process, send it SIGINT after `delay` [s]; (exit code,
    stderr)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.Popen([sys.executable, "-m", "walkers.cli", *argv], cwd=ROOT, env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    return p.returncode, err


@pytest.mark.parametrize("delay", [0.2, 0.35, 0.6, 1.5])
def test_ctrl_c_at_any_moment_is_one_line_and_exit_130(delay):
    """From the imports (the first few tenths of a second), through loading or compiling the
    engine, to a long simulation: one line, exit code 130, no traceback."""
    code, err = _interrupt_after(delay, "run", "simple-biped", "--no-animation", "--duration", "3000")
    assert code == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.splitlines()[-1] == "planarsim run: interrupted"


def test_an_interrupt_before_the_command_is_known_is_one_line(monkeypatch, capsys):
    import walkers.cli as cli

    def interrupted():
        raise KeyboardInterrupt
    monkeypatch.setattr(cli, "make_parser", interrupted)
    try:
        code = main(["list"])
    except KeyboardInterrupt:
        pytest.fail("the interrupt escaped planarsim's main")
    assert code == 130
    out, err = capsys.readouterr()
    assert err == "planarsim list: interrupted\n"


# the summary file carries the files README promises ----------------------------------------------
def test_the_summary_file_lists_the_files_the_run_wrote(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.5", "--fps", "5")
    assert code == 0, err
    saved = json.loads((tmp_path / "out" / "simple-biped_summary.json").read_text())
    assert saved["files"] == ["out/simple-biped.gif", "out/simple-biped_summary.json"]
    assert all((tmp_path / f).exists() for f in saved["files"])


def test_a_10_s_walk_at_the_default_size_is_under_1_mb(tmp_path, monkeypatch, capsys):
    """docs/cli.md: 'out/WALKER.gif (640x360, 20 fps: a 10 s walk is under 1 MB)' (the Simple
    Biped's: 0.75 MB measured)."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, "run", "simple-biped")
    assert code == 0, err
    assert (tmp_path / "out" / "simple-biped.gif").stat().st_size < 1_000_000


# progress goes to a terminal only ---------------------------------------------------------------
def test_analyze_writes_no_progress_bar_into_a_pipe(capsys):
    code, out, err = run_cli(capsys, "analyze", "simplest-walker", "--param", "slope",
                             "--range", "0.009:0.0095", "--points", "2", "--workers", "1")
    assert code == 0, err
    assert "\r" not in err and "points" not in err
    assert "period-1 branch" in out


# tune: the budget is what is evaluated, and --help shows the defaults -----------------------------
def test_tune_evaluates_its_whole_budget_or_says_why_not(tmp_path, capsys):
    """simple-biped's generations hold 11 candidates: a budget of 14 is one generation and
    three candidates of the next, all evaluated."""
    out = tmp_path / "tuned.json"
    code, stdout, err = run_cli(capsys, "tune", "simple-biped", "--budget", "14", "--duration", "0.3",
                                "--workers", "1", "--out", out)
    assert code == 0, err
    result = json.loads(stdout)
    assert result["evaluations"] == 14 and result["stopped"] is None


def test_tune_help_shows_the_defaults(capsys):
    with pytest.raises(SystemExit) as done:
        main(["tune", "--help"])
    assert done.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for default in ("(default: 200)", "(default: 0.1)", "(default: 2)", "(default: tuned.json)"):
        assert default in text


# every gait `list` shows is explained -----------------------------------------------------------
def test_list_explains_every_gait_it_shows(capsys):
    import walkers
    code, out, err = run_cli(capsys, "list")
    assert code == 0, err
    lines = out.splitlines()
    for name in walkers.WALKERS:
        start = next(i for i, line in enumerate(lines) if line.split()[:1] == [name])
        block = []
        for line in lines[start + 1:]:
            if not line.startswith(" " * 19):
                break
            block.append(line.split(":", 1))
        explained = {gait.strip(): doc.strip() for gait, doc in block}
        for gait in walkers.load(name).GAITS:
            assert len(explained.get(gait, "")) > 10, (name, gait)
    assert "gui:" in out and "by hand" in out


# the terrain's parameters are recorded ------------------------------------------------------------
def test_custom_hills_are_recorded_with_their_coefficients(tmp_path, capsys):
    from planarsim import Trajectory, terrain
    spec = "hills:0.05,2.5,0.3;0.02,1.1"
    code, out, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.3", "--terrain", spec,
                             "--save", tmp_path / "run.npz", "--json")
    assert code == 0, err
    summary = json.loads(out)
    asked = terrain.parse(spec)
    assert summary["terrain"] != "hills"
    assert terrain.parse(summary["terrain"]).coef.tolist() == asked.coef.tolist()
    saved = Trajectory.load(tmp_path / "run.npz").terrain()
    assert saved.coef.tolist() == asked.coef.tolist()


# the first compile states what this machine measures ----------------------------------------------
def test_the_first_compile_message_states_what_this_machine_measured(tmp_path, monkeypatch, capsys):
    """A cold cache (pretended: no index files in a folder of the test's own): the note gives
    the figure of a quiet two-core machine and says none was measured here yet, the run then
    says what it measured and keeps it, and the next cold start quotes that figure."""
    import re

    import planarsim.compiled as compiled
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(compiled, "kernel_cache", lambda: (tmp_path, []))
    code, _, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.1", "--json")
    assert code == 0, err
    assert ("compiling the engine (first run only; about "
            f"{compiled.TYPICAL_COMPILE_S:.0f} s on a quiet two-core machine") in err
    assert "not yet measured on this machine)" in err
    said = re.search(r"first compile: measured (\d+) s on this machine", err)
    assert said, err
    assert compiled.measured_compile() is not None
    code, _, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.1", "--json")
    assert code == 0, err
    assert re.search(r"the last one measured on this machine took \d+ s", err), err
    code, out, _ = run_cli(capsys, "info")
    assert "cold: the first run compiles; the last one measured on this machine took" in out
