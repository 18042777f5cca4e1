"""Frame times and drawing frames on several processes (planarsim/render/frames.py)."""

import numpy as np
import pytest

from planarsim.render import export_animation, frame_indices, frame_times


def test_playback_speed_samples_frames_from_the_trajectory_times(sliding_run):
    model, traj = sliding_run
    real = frame_times(traj, fps=30, speed=1.0)
    slow = frame_times(traj, fps=30, speed=0.25)
    fast = frame_times(traj, fps=30, speed=4.0)
    assert (len(real), len(slow), len(fast)) == (60, 240, 15)
    np.testing.assert_allclose(np.diff(slow), 0.25 / 30)
    np.testing.assert_allclose(np.diff(fast), 4.0 / 30)
    idx = frame_indices(traj, slow)
    assert np.abs(traj.t[idx] - slow).max() <= 0.5 * (traj.t[1] - traj.t[0]) + 1e-12
    window = frame_times(traj, fps=10, speed=0.5, start=0.5, duration=1.0)
    assert len(window) == 20 and window[0] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="outside the trajectory"):
        frame_times(traj, fps=30, start=1.5, duration=2.0)
    with pytest.raises(ValueError, match="speed"):
        frame_times(traj, fps=30, speed=0)


def test_frames_drawn_on_two_processes_equal_those_drawn_on_one(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    one = export_animation(traj, model, tmp_path / "one.gif", fps=30, size=(3.2, 1.8), progress=False, workers=1)
    two = export_animation(traj, model, tmp_path / "two.gif", fps=30, size=(3.2, 1.8), progress=False, workers=2)
    with Image.open(one) as a, Image.open(two) as b:
        assert a.n_frames == b.n_frames == 60
        for k in range(60):
            a.seek(k)
            b.seek(k)
            assert np.array_equal(np.asarray(a.convert("RGB")), np.asarray(b.convert("RGB"))), k


def test_a_frame_error_in_a_worker_reaches_the_caller_and_leaves_nothing(sliding_run, tmp_path, monkeypatch):
    from planarsim.render import frames
    model, traj = sliding_run
    real = frames.FrameRenderer.draw

    def broken(self, k):
        if k == 50:
            raise ValueError("frame 50 is broken")
        return real(self, k)

    monkeypatch.setattr(frames.FrameRenderer, "draw", broken)
    with pytest.raises(ValueError, match="frame 50 is broken"):
        export_animation(traj, model, tmp_path / "x.gif", fps=30, size=(1.6, 0.9), dpi=50, progress=False,
                         workers=2)
    assert list(tmp_path.iterdir()) == []
