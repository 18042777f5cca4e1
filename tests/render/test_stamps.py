"""Text stamps (planarsim/render/stamps.py) drawn where they say."""

import numpy as np

from planarsim.render import make_figure
from planarsim.render.stamps import TextStamp              # noqa: E402
from tests.render.helpers import RED, mask


def test_text_stamp_draws_the_text_where_it_says():
    fig, ax = make_figure((3.0, 1.0), 100)
    stamp = TextStamp(0.5, 0.5, "Hi there", transform=ax.transAxes, ha="center", va="center", fontsize=14,
                      color="#ff0000")
    ax.add_artist(stamp)
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int)
    rows, cols = np.nonzero(mask(img, RED))
    assert len(rows) > 50
    assert abs(cols.mean() - 150) < 8 and abs(rows.mean() - 50) < 8
    x0, y0, w, h = stamp.window_box(fig.dpi)
    assert x0 <= cols.min() and cols.max() < x0 + w and 100 - (y0 + h) <= rows.min()
    stamp.set_text("")
    fig.canvas.draw()
    assert not mask(np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int), RED).any()
