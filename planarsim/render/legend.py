"""The legend of a Scene, drawn once into a bitmap (shown by a stamps.ImageStamp)."""
from __future__ import annotations

import math

import numpy as np


def legend_bitmap(entries, dpi: float, style) -> np.ndarray | None:
    """RGBA bitmap (H, W, 4), top row first, of a legend with entries [(label, kind, colour)]
    (kind: "side" a filled patch, "arrow" a force arrow, "com" the centre-of-mass mark)."""
    if not entries:
        return None
    import matplotlib.figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    handles = []
    for label, kind, color in entries:
        if kind == "side":
            handles.append(Patch(facecolor=color, edgecolor=style.edge_color, lw=0.8))
        elif kind == "arrow":
            handles.append(Line2D([], [], color=color, lw=1.6, marker=">", ms=5, markevery=[1]))
        else:   # the scene's mark: a ring with a cross
            handles.append(Line2D([], [], ls="none", marker=com_marker(), ms=8, mfc="white", mec=color, mew=1.2))
    labels = [label for label, _, _ in entries]
    fig = matplotlib.figure.Figure(figsize=(4, 2), dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    fig.patch.set_alpha(0.0)
    leg = fig.legend(handles, labels, loc="upper right", fontsize=0.85 * style.font_size, frameon=True,
                     framealpha=0.85, edgecolor="#cccccc", handlelength=1.4, borderpad=0.4, labelspacing=0.3)
    canvas.draw()
    img = np.asarray(canvas.buffer_rgba())
    box = leg.get_window_extent()
    h = img.shape[0]
    x0, x1 = int(math.floor(box.x0)), int(math.ceil(box.x1))
    y0, y1 = h - int(math.ceil(box.y1)), h - int(math.floor(box.y0))
    return np.ascontiguousarray(img[max(0, y0):y1, max(0, x0):x1])


def com_marker():
    """The centre-of-mass mark: a ring with a cross through it (one marker path)."""
    from matplotlib.path import Path
    cross = Path([(-1, 0), (1, 0), (0, -1), (0, 1)], [Path.MOVETO, Path.LINETO, Path.MOVETO, Path.LINETO])
    return Path.make_compound_path(Path.unit_circle(), cross)
