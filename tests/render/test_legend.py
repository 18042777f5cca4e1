"""The legend (planarsim/render/legend.py): sides, force and COM, on every frame."""

import numpy as np

import planarsim as ps
from planarsim.render import Scene, Style, make_figure
from tests.render.helpers import _legged_model


def test_legend_names_sides_force_and_com_and_is_on_every_frame(tmp_path):
    model = _legged_model()
    traj = ps.Simulator(model).run(0.5, record_every=10)
    fig, ax = make_figure()
    scene = Scene(model, ax)
    assert [e[0] for e in scene.legend_entries()] == ["left leg", "right leg", "centre of mass"]
    from planarsim.render.animate import FrameRenderer
    r = FrameRenderer(traj, model, fps=20, size=(4.0, 2.25))
    box = None
    for k in range(len(r)):
        img = r.rgb(k).astype(int)
        x0, y0, w, h = r.scene.legend.window_box(r.fig.dpi)
        assert r.scene.legend.get_visible()
        height = img.shape[0]
        patch = img[height - (y0 + h):height - y0, x0:x0 + w]
        side0 = np.array(tuple(int(Style().side_colors[0][i:i + 2], 16) for i in (1, 3, 5)))
        assert np.any(np.all(np.abs(patch - side0) < 8, axis=2))          # the legend's left-leg patch
        assert box is None or box == (x0, y0, w, h)                        # in the same place
        box = (x0, y0, w, h)
        assert r.scene.text.get_text().startswith(f"t = {r.shown_times[k]:7.3f} s")
    assert r.shown_times[0] == 0.0
