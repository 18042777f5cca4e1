"""Exporting an animation (planarsim/render/animate.py): frame counts, playback speed, errors,
progress, interrupted exports."""

import os
import re
import subprocess
from pathlib import Path

import pytest

import planarsim as ps
from planarsim.render import Camera, animation_html, export_animation
from tests.render.helpers import box_model, default_file_mode, _two_body_model


def count_mp4_frames(path):
    import imageio_ffmpeg
    gen = imageio_ffmpeg.read_frames(str(path))
    meta = next(gen)
    n = sum(1 for _ in gen)
    return n, meta


def test_gif_and_mp4_of_two_seconds_at_30_fps_have_60_frames(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    gif = export_animation(traj, model, tmp_path / "run.gif", fps=30, size=(3.2, 1.8), progress=False)
    mp4 = export_animation(traj, model, tmp_path / "run.mp4", fps=30, size=(3.2, 1.8), progress=False)
    with Image.open(gif) as im:
        assert im.n_frames == 60
        delays = []
        for k in range(im.n_frames):
            im.seek(k)
            delays.append(im.info["duration"])
    assert set(delays) <= {30, 40} and sum(delays) == 2000    # GIF counts in 10 ms: kept on time
    n, meta = count_mp4_frames(mp4)
    assert n == 60
    assert meta["fps"] == pytest.approx(30)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.gif", "run.mp4"]   # no leftovers
    assert gif.stat().st_mode & 0o777 == mp4.stat().st_mode & 0o777 == default_file_mode()


def test_slow_motion_gif_has_four_times_the_frames(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "slow.gif", fps=20, speed=0.25, duration=0.5,
                           size=(1.6, 0.9), dpi=50, progress=False)
    with Image.open(out) as im:
        assert im.n_frames == 40


def test_unknown_extension_and_unwritable_path_give_clear_errors(sliding_run, tmp_path):
    model, traj = sliding_run
    with pytest.raises(ValueError, match=r"'\.avi' unknown.*\.gif.*\.mp4"):
        export_animation(traj, model, tmp_path / "x.avi", progress=False)
    with pytest.raises(OSError, match="does not exist"):
        export_animation(traj, model, tmp_path / "missing" / "x.gif", progress=False)
    (tmp_path / "adir.gif").mkdir()
    with pytest.raises(OSError, match="is a folder"):
        export_animation(traj, model, tmp_path / "adir.gif", progress=False)
    if os.geteuid() != 0:   # root may write anywhere
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o500)
        with pytest.raises(OSError, match="not writable"):
            export_animation(traj, model, ro / "x.gif", progress=False)
    with pytest.raises(ValueError, match="wrong model"):
        export_animation(traj, _two_body_model(), tmp_path / "y.gif", progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir.gif"]


@pytest.mark.parametrize("kw, said", [
    (dict(dpi=0), r"dpi=0 must be finite and > 0"),                     # was ZeroDivisionError
    (dict(dpi=float("nan")), r"dpi=nan must be finite and > 0"),        # was int() of NaN
    (dict(size=(-6.4, -3.6)), r"size=\(-6.4, -3.6\) must be two finite numbers > 0"),  # was 2 px
    (dict(size=(6.4, 3.6, 1.0)), r"size=\(6.4, 3.6, 1.0\) must be \(width, height\)"),
    (dict(start=float("nan")), r"start=nan must be finite"),           # was named duration=nan
    (dict(start="abc"), r"start='abc' must be a number of seconds"),
    (dict(bitrate=-5), r"bitrate=-5 must be None .* or a number >= 1"),  # was ffmpeg's broken pipe
])
def test_bad_picture_settings_are_named_before_any_frame(sliding_run, tmp_path, kw, said):
    model, traj = sliding_run
    with pytest.raises(ValueError, match=said):
        export_animation(traj, model, tmp_path / "x.mp4", progress=False, workers=1, **kw)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("camera", [5, "follow", Camera])
def test_a_camera_that_is_no_camera_is_named(sliding_run, tmp_path, camera):
    """camera=5 failed at the first frame with "'int' object has no attribute 'track'"."""
    model, traj = sliding_run
    said = rf"camera={re.escape(repr(camera))} must be a planarsim.render.Camera"
    with pytest.raises(TypeError, match=said):
        export_animation(traj, model, tmp_path / "x.gif", progress=False, workers=1, camera=camera)
    with pytest.raises(TypeError, match=said):
        animation_html(traj, model, camera=camera)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="/proc")
def test_a_folder_no_file_can_be_made_in_is_refused_before_any_frame(sliding_run):
    """Root passes os.access in /proc: every frame was drawn, then the file could not be put
    there."""
    model, traj = sliding_run
    drawn = []
    with pytest.raises(OSError, match=r"cannot write '/proc/x.gif': folder '/proc' is not writable"):
        export_animation(traj, model, "/proc/x.gif", workers=1,
                         progress=lambda done, total: drawn.append(done))
    assert drawn == []


def test_a_gif_faster_than_50_fps_is_refused_naming_fps(sliding_run, tmp_path):
    """A GIF at 100 fps has 1/100 s delays, which most viewers show as 1/10 s: it played at a
    tenth of its speed. An MP4 keeps any rate."""
    model, traj = sliding_run
    with pytest.raises(ValueError, match=r"fps=60 frames/s is too fast for a GIF: .* give at most "
                                         r"50 fps, or write an \.mp4"):
        export_animation(traj, model, tmp_path / "x.gif", fps=60, progress=False, workers=1)
    assert list(tmp_path.iterdir()) == []
    kw = dict(duration=0.1, size=(1.6, 0.9), dpi=50, progress=False, workers=1)
    export_animation(traj, model, tmp_path / "x.gif", fps=50, **kw)
    assert count_mp4_frames(export_animation(traj, model, tmp_path / "x.mp4", fps=120, **kw))[0] == 12


def test_progress_bar_counts_every_frame(sliding_run, tmp_path, capsys, monkeypatch):
    model, traj = sliding_run
    seen = []
    export_animation(traj, model, tmp_path / "a.gif", fps=10, duration=1.0, size=(1.6, 0.9), dpi=50,
                     progress=lambda done, total: seen.append((done, total)))
    assert seen == [(k, 10) for k in range(1, 11)]
    import planarsim.progress
    monkeypatch.setattr(planarsim.progress, "stderr_is_terminal", lambda: True)  # the bar: terminals only
    export_animation(traj, model, tmp_path / "b.gif", fps=10, duration=1.0, size=(1.6, 0.9), dpi=50)
    err = capsys.readouterr().err
    assert "10/10 frames" in err and "#" * 30 in err


KILLED_EXPORTER = """
import multiprocessing, sys
import numpy as np
import planarsim as ps
from planarsim.render import export_animation
b = ps.ModelBuilder(dt=1e-3)
box = b.add_body("box", mass=2.0, inertia=0.1, pos=(0.0, 0.1), vel=(1.0, 0.0))
b.add_box_contacts("corner", box, (0.0, 0.0), 0.8, 0.2, mu=0.3)
model = b.compile()
traj = ps.Simulator(model).run(2.0, record_every=10)

def progress(done, total):
    if done == 5:
        pids = [p.pid for p in multiprocessing.active_children()]
        print("exporting", *pids, flush=True)
        import time
        time.sleep(60)

export_animation(traj, model, sys.argv[1], fps=50, progress=progress, workers=2)
"""


def _gone(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            return "\nState:\tZ" in f.read()      # a zombie has ended
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not hasattr(os, "fork") or not Path("/proc").is_dir(), reason="fork, /proc")
def test_sigkill_mid_export_leaves_nothing_and_no_drawing_processes(tmp_path):
    import signal
    import sys
    import tempfile
    import time
    target = tmp_path / "run.gif"
    proc = subprocess.Popen([sys.executable, "-c", KILLED_EXPORTER, str(target)], stdout=subprocess.PIPE, text=True)
    words = proc.stdout.readline().split()
    assert words[:1] == ["exporting"], words
    workers = [int(w) for w in words[1:]]
    assert len(workers) == 2
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert os.listdir(tmp_path) == []
    deadline = time.monotonic() + 20
    while not all(_gone(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert all(_gone(pid) for pid in workers)        # the workers ended with their parent
    traj, model = _tiny_run()
    export_animation(traj, model, target, fps=5, progress=False)       # the next write cleans up
    left = [n for n in os.listdir(tempfile.gettempdir()) if n.startswith(f"planarsim-{proc.pid}-")]
    assert left == [] and sorted(os.listdir(tmp_path)) == ["run.gif"]


def _tiny_run():
    model = box_model()
    return ps.Simulator(model).run(0.5, record_every=10), model


def test_an_error_while_writing_ends_the_drawing_processes_at_once(sliding_run, tmp_path):
    import multiprocessing
    model, traj = sliding_run
    with pytest.raises(ValueError, match="embed limit") as caught:
        export_animation(traj, model, tmp_path / "big.html", fps=30, size=(1.6, 0.9), dpi=50,
                         progress=False, embed_limit_mb=0.01, workers=2)
    assert caught.value is not None                    # the traceback is still held here
    assert multiprocessing.active_children() == []
    assert list(tmp_path.iterdir()) == []
