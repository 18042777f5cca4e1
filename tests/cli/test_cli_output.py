"""What `planarsim run` shows while it works and what its files say: progress bars only on a
terminal and never with --json, the HTML page's title and summary, the CSV's units."""
import csv
import io
import re

import pytest

import planarsim.progress as progress
from walkers.cli import main
from planarsim.progress import Elapsed, TextProgress


def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def terminal(monkeypatch):
    monkeypatch.setattr(progress, "stderr_is_terminal", lambda: True)


def test_run_on_a_terminal_shows_the_frame_bar(tmp_path, capsys, terminal):
    out = tmp_path / "walk.gif"
    code, _, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.5", "--fps", "10",
                           "--out", str(out))
    assert code == 0, err
    assert "5/5 frames -> walk.gif" in err and "#" * 30 in err


def test_run_with_json_is_quiet_even_on_a_terminal(tmp_path, capsys, terminal):
    out = tmp_path / "walk.gif"
    code, stdout, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.5", "--fps", "10",
                                "--out", str(out), "--json")
    assert code == 0
    assert err == ""
    assert stdout.count("\n") == 1 and out.exists()


def test_run_not_on_a_terminal_shows_no_bars(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(progress, "stderr_is_terminal", lambda: False)
    code, _, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.5", "--fps", "10",
                           "--out", str(tmp_path / "walk.gif"))
    assert code == 0
    assert "frames" not in err and "\r" not in err


def test_elapsed_shows_only_after_its_delay():
    import time
    quick = io.StringIO()
    with Elapsed("simulating", stream=quick, delay=0.5, every=0.02):
        time.sleep(0.05)
    assert quick.getvalue() == ""
    slow = io.StringIO()
    with Elapsed("simulating", stream=slow, delay=0.05, every=0.02):
        time.sleep(0.3)
    text = slow.getvalue()
    assert text.startswith("\rsimulating ... ") and text.endswith(" s\n")
    last = float(re.findall(r"([0-9.]+) s", text)[-1])
    assert 0.25 <= last < 5.0
    off = io.StringIO()
    with Elapsed("simulating", enabled=False, stream=off, delay=0.0):
        time.sleep(0.05)
    assert off.getvalue() == ""


def test_text_progress_ends_its_line_at_the_total():
    buf = io.StringIO()
    bar = TextProgress(4, "frames", stream=buf, width=8)
    for k in range(1, 5):
        bar(k)
    assert buf.getvalue().endswith("\r[########] 4/4 frames\n")


def test_html_page_is_titled_with_the_walker_and_holds_the_summary(tmp_path, capsys):
    out = tmp_path / "walk.html"
    code, _, err = run_cli(capsys, "run", "simple-biped", "--duration", "0.5", "--fps", "10",
                           "--out", str(out), "--terrain", "flat")
    assert code == 0, err
    page = out.read_text()
    assert "<title>simple-biped (walk gait) on flat terrain - planarsim</title>" in page
    assert "<h1>simple-biped (walk gait) on flat terrain</h1>" in page
    assert '<table class="planarsim-summary">' in page and "<th>mean_speed_m_per_s</th>" in page
    assert "play_animation(); }" in page              # plays when opened


def test_csv_header_has_units_commands_torques_and_impulses(tmp_path, capsys):
    path = tmp_path / "run.csv"
    code, _, err = run_cli(capsys, "run", "ranger", "--duration", "0.3", "--csv", str(path), "--json")
    assert code == 0, err
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, first = rows[0], rows[1]
    assert header[0] == "t_s"
    assert "outer_leg.x_m" in header and "outer_leg.theta_rad" in header and "outer_leg.omega_rad_per_s" in header
    assert "hip_motor.torque_Nm" in header and "hip_motor.power_W" in header
    assert "outer_sole.impulse_n_Ns" in header and "outer_sole.impulse_t_Ns" in header
    assert "outer_sole.point_x_m" in header and "outer_sole.mode" in header
    assert len(first) == len(header)
    assert all(re.fullmatch(r"[A-Za-z0-9_./]+", h) for h in header)   # no spaces or brackets


def test_csv_names_axial_efforts_as_forces_and_without_a_model_as_u(tmp_path):
    import walkers
    traj, _, model = walkers.load("simple-biped").simulate(duration=0.1)
    with_model = traj.to_csv(tmp_path / "a.csv", model).read_text().splitlines()[0].split(",")
    assert "leg0.force_N" in with_model and "hip.torque_Nm" in with_model
    bare = traj.to_csv(tmp_path / "b.csv").read_text().splitlines()[0].split(",")
    assert "leg0.u" in bare and "foot0.impulse_n_Ns" in bare
    import numpy as np
    table = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)
    col = with_model.index("foot0.impulse_n_Ns")
    np.testing.assert_allclose(table[:, col], traj.contact_impulse[:, 0, 0], rtol=1e-9)   # 10 digits
    with pytest.raises(ValueError, match="wrong model"):
        traj.to_csv(tmp_path / "c.csv", walkers.load("ranger").simulate(duration=0.02)[2])


def test_plot_is_titled_with_walker_gait_and_terrain(tmp_path, capsys, monkeypatch):
    import planarsim.render.plots as plots
    seen = {}
    real = plots.plot_summary

    def spy(traj, model, path=None, **kw):
        seen["fig"] = real(traj, model, path, **kw)
        return seen["fig"]

    monkeypatch.setattr(plots, "plot_summary", spy)
    import planarsim.render
    monkeypatch.setattr(planarsim.render, "plot_summary", spy)
    code, _, err = run_cli(capsys, "run", "ranger", "--duration", "0.3", "--plot", str(tmp_path / "p.png"),
                           "--terrain", "flat", "--json")
    assert code == 0, err
    assert seen["fig"]._suptitle.get_text() == "ranger (walk gait) on flat terrain"
