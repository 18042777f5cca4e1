"""Pixel stamps: text and small pictures drawn as cached bitmaps on a matplotlib figure.

matplotlib lays out and rasterises every glyph of every Text on every draw (about 2 ms for a
line of 25 characters); an animation's labels change little from frame to frame. A
``TextStamp`` renders its string once with Pillow (in matplotlib's own DejaVu font), keeps the
bitmap, and hands it to the renderer as an image: the same look, about 20x faster per frame.
``ImageStamp`` shows a fixed RGBA bitmap (a legend drawn once, say) at a place on the axes.
Both are ordinary matplotlib artists: they draw on Agg, on screen canvases, in SVG and PDF
(there as an embedded image) and take part in blitting.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from matplotlib import colors as mcolors
from matplotlib.artist import Artist

_HA = {"left": 0.0, "center": 0.5, "right": 1.0}
_VA = {"bottom": 0.0, "center": 0.5, "top": 1.0}


@lru_cache(maxsize=8)
def _font(family: str, size_px: int):
    from matplotlib import font_manager
    from PIL import ImageFont
    path = font_manager.findfont(font_manager.FontProperties(family=family))
    return ImageFont.truetype(path, size_px)


@lru_cache(maxsize=4096)
def _line_mask(line: str, size_px: int, family: str) -> np.ndarray:
    """Alpha (h, w) uint8 of one line of text, h = the font's ascent + descent."""
    from PIL import Image, ImageDraw
    font = _font(family, size_px)
    ascent, descent = font.getmetrics()
    mask = Image.new("L", (max(1, int(np.ceil(font.getlength(line)))), ascent + descent), 0)
    ImageDraw.Draw(mask).text((0, 0), line, font=font, fill=255)
    return np.asarray(mask)


@lru_cache(maxsize=1024)
def text_bitmap(text: str, size_px: int, rgba: tuple, family: str = "monospace",
                line_spacing: float = 1.25) -> np.ndarray:
    """(H, W, 4) uint8 RGBA bitmap of `text` (lines split at newlines) in `size_px` pixels;
    each line is rasterised once and kept (a label that changes one line redraws only it)."""
    size_px = max(1, int(size_px))
    masks = [_line_mask(line, size_px, family) for line in text.split("\n")]
    step = int(round(line_spacing * size_px))
    width = max(m.shape[1] for m in masks) + 2
    height = step * (len(masks) - 1) + masks[0].shape[0] + 2
    alpha = np.zeros((height, width), np.uint8)
    for i, m in enumerate(masks):
        alpha[1 + i * step:1 + i * step + m.shape[0], 1:1 + m.shape[1]] = m
    out = np.empty((height, width, 4), np.uint8)
    out[:, :, :3] = rgba[:3]
    out[:, :, 3] = alpha if rgba[3] == 255 else np.round(alpha * (rgba[3] / 255.0)).astype(np.uint8)
    return out


class Stamp(Artist):
    """A bitmap drawn with its anchor (ha, va) at (x, y) in `transform` coordinates."""

    def __init__(self, x=0.0, y=0.0, transform=None, ha="left", va="bottom", zorder=9):
        super().__init__()
        if ha not in _HA or va not in _VA:
            raise ValueError(f"ha={ha!r} must be one of {sorted(_HA)} and va={va!r} one of {sorted(_VA)}")
        self._xy = (float(x), float(y))
        self.ha, self.va = ha, va
        self.set_zorder(zorder)
        if transform is not None:
            self.set_transform(transform)

    def set_position(self, xy) -> None:
        self._xy = (float(xy[0]), float(xy[1]))
        self.stale = True

    def get_position(self) -> tuple:
        return self._xy

    def bitmap(self, dpi: float):
        """(H, W, 4) uint8 RGBA, top row first; None draws nothing."""
        raise NotImplementedError

    def window_box(self, dpi: float):
        """(x0, y0, width, height) in display pixels of the drawn bitmap, or None."""
        img = self.bitmap(dpi)
        if img is None:
            return None
        h, w = img.shape[:2]
        x, y = self.get_transform().transform(self._xy)
        return (round(x - _HA[self.ha] * w), round(y - _VA[self.va] * h), w, h)

    def draw(self, renderer):
        if not self.get_visible():
            return
        img = self.bitmap(renderer.dpi)
        if img is None:
            return
        x0, y0, _, _ = self.window_box(renderer.dpi)
        gc = renderer.new_gc()
        self._set_gc_clip(gc)          # clipped to the axes, as text is
        gc.set_alpha(1.0)
        renderer.draw_image(gc, x0, y0, img[::-1])     # renderers take the bottom row first
        gc.restore()
        self.stale = False


class TextStamp(Stamp):
    """Text drawn from a cached bitmap (see module docstring); fontsize in points."""

    def __init__(self, x=0.0, y=0.0, text="", transform=None, ha="left", va="bottom", fontsize=9.0,
                 color="black", family="monospace", zorder=9):
        super().__init__(x, y, transform, ha, va, zorder)
        self._text, self.fontsize, self.family = str(text), float(fontsize), family
        self.set_color(color)

    def set_text(self, text) -> None:
        text = str(text)
        if text != self._text:
            self._text = text
            self.stale = True

    def get_text(self) -> str:
        return self._text

    def set_color(self, color) -> None:
        self._rgba = tuple(int(round(255 * c)) for c in mcolors.to_rgba(color))
        self.stale = True

    def bitmap(self, dpi: float):
        if not self._text:
            return None
        return text_bitmap(self._text, int(round(self.fontsize * dpi / 72.0)), self._rgba, self.family)


class ImageStamp(Stamp):
    """A picture made once per dpi by `make(dpi) -> (H, W, 4) uint8` (top row first)."""

    def __init__(self, make, x=0.0, y=0.0, transform=None, ha="left", va="bottom", zorder=9):
        super().__init__(x, y, transform, ha, va, zorder)
        self._make, self._cache = make, {}

    def bitmap(self, dpi: float):
        key = round(float(dpi), 3)
        if key not in self._cache:
            self._cache[key] = self._make(dpi)
        return self._cache[key]


