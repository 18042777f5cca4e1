"""GIF encoding (planarsim/render/gif.py): size of a ten-second walk, exact background and ground
colours."""

import numpy as np
import pytest

from planarsim.render import Style, export_animation


def test_ten_second_walk_gif_is_at_most_one_megabyte(tmp_path):
    """The command line's default animation (640x360, 20 fps) of a 10 s Simple Biped walk."""
    import walkers
    from PIL import Image
    from walkers.gallery import gait_names
    mod = walkers.load("simple-biped")
    traj, _, model = mod.simulate(duration=10.0)
    out = export_animation(traj, model, tmp_path / "walk.gif", fps=20, progress=False,
                           label_names=gait_names(mod))
    assert out.stat().st_size <= 1_000_000
    with Image.open(out) as im:
        assert im.n_frames == 200 and im.size == (640, 360)
        im.seek(150)
        frame = np.asarray(im.convert("RGB")).astype(int)
    assert np.count_nonzero(np.any(frame < 200, axis=2)) > 2000        # a picture, not a blank


def test_gif_keeps_the_background_and_ground_colours_exact(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.gif", fps=10, size=(3.2, 1.8), progress=False)
    style = Style()
    with Image.open(out) as im:
        im.seek(5)
        rgb = np.asarray(im.convert("RGB"))
    colours = {tuple(int(c) for c in px) for px in rgb.reshape(-1, 3)}
    assert (255, 255, 255) in colours                                     # white stays white
    ground = tuple(int(style.ground_fill[i:i + 2], 16) for i in (1, 3, 5))
    assert ground in colours


@pytest.mark.parametrize("flags, text", [(["--width", "0"], "--width 0"),
                                         (["--duration", "0"], "--duration 0"),
                                         (["--fps", "-1"], "--fps -1"),
                                         (["--fps", "60"], "--fps 60 frames/s is too fast for a GIF")])
def test_gallery_refuses_sizes_and_times_before_any_run(flags, text, tmp_path, capsys):
    """--width 0 wrote a 2 x 2 pixel GIF and --duration 0 exited 0; --fps -1 failed after
    simulating."""
    from walkers.gallery import main
    with pytest.raises(SystemExit) as e:
        main([str(tmp_path), "--walker", "rimless-wheel", *flags])
    assert e.value.code == 2 and text in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
