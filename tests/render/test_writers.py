"""The GIF, MP4 and HTML writers (planarsim/render/writers.py): an interrupted export leaves no
half-written file."""

import pytest

from planarsim.render import export_animation


@pytest.mark.parametrize("ext", ["gif", "mp4", "html"])
def test_interrupted_export_leaves_no_half_written_file(sliding_run, tmp_path, ext):
    model, traj = sliding_run
    target = tmp_path / f"run.{ext}"
    target.write_bytes(b"old contents")

    def interrupt(done, total):
        if done == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        export_animation(traj, model, target, fps=30, size=(1.6, 0.9), dpi=50, progress=interrupt)
    assert target.read_bytes() == b"old contents"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
