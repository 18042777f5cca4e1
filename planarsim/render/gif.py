"""Animated GIF written frame by frame, with one palette for the whole animation.

Each frame is quantised to a shared palette (nearest colour, no dithering: flat colours
compress well); ``FrameEncoder`` keeps only the rectangle that changed since its previous
frame, with unchanged pixels transparent, and LZW-encodes it (it can run in another process,
one encoder per run of frames); ``GifStream`` writes the header once and appends each encoded
frame with its delay, so frames need not be held in memory. The palette comes from a few
sample frames (``palette_from``); its last entry is kept for transparency. Frame delays are
kept on the fps clock in the GIF's 10 ms units.
"""
from __future__ import annotations

import io
import struct

import numpy as np
from PIL import Image

from ..checks import to_float


def palette_from(samples, colors: int = 64, exact: int = 8) -> bytes:
    """RGB bytes of a palette of `colors` entries fitted to RGB arrays (H, W, 3): median cut,
    then the `exact` most frequent colours (background, ground, ...) put in exactly, in place
    of their nearest entries (a median-cut box averages white with the light edges around
    it) and of every entry within 4 levels of them (Pillow maps a colour to the entry nearest
    to its 4-level box, so white would still come out as 253); the last entry is left free
    (transparency)."""
    if not 3 <= int(colors) <= 256:
        raise ValueError(f"colors={colors} must be between 3 and 256")
    strip = np.concatenate([np.asarray(s, np.uint8)[:, :, :3] for s in samples], axis=0)
    fitted = Image.fromarray(np.ascontiguousarray(strip), "RGB").quantize(int(colors) - 1,
                                                                          method=Image.Quantize.MEDIANCUT)
    used = int(np.asarray(fitted).max()) + 1
    pal = np.array(fitted.getpalette()[:3 * used], dtype=np.int64).reshape(-1, 3)
    packed = strip.reshape(-1, 3).astype(np.int64) @ np.array([65536, 256, 1])
    values, counts = np.unique(packed, return_counts=True)
    taken = set()
    for v in values[np.argsort(counts)[::-1][:exact]]:
        rgb = np.array([v >> 16, (v >> 8) & 255, v & 255])
        order = np.argsort(((pal - rgb) ** 2).sum(axis=1))
        slot = next((int(i) for i in order if int(i) not in taken), None)
        if slot is not None:
            near = np.flatnonzero(np.abs(pal - rgb).max(axis=1) <= 4)
            pal[near] = rgb
            pal[slot] = rgb
            taken.update(int(i) for i in near)
            taken.add(slot)
    return bytes(pal.astype(np.uint8).ravel()) + bytes(3 * (int(colors) - used))


def _palette_image(palette: bytes, used: int) -> Image.Image:
    img = Image.new("P", (1, 1))
    img.putpalette(palette[:3 * used])
    return img


def quantize(rgb, palette: bytes) -> np.ndarray:
    """Palette indices (H, W) uint8 of an RGB image or array (H, W, 3): the nearest of the
    palette's colours but its last, no dithering."""
    n = len(palette) // 3
    ref = _palette_image(palette, n - 1)
    img = rgb if isinstance(rgb, Image.Image) else Image.fromarray(np.ascontiguousarray(rgb, np.uint8), "RGB")
    out = np.asarray(img.quantize(palette=ref, dither=Image.Dither.NONE))
    if out.max(initial=0) >= n - 1:       # pragma: no cover - Pillow maps to the given entries only
        raise RuntimeError("palette quantisation returned an index outside the palette")
    return out


def _blocks(data: bytes) -> tuple:
    """(header + logical screen descriptor + global colour table, image descriptor and data)
    of a one-frame GIF."""
    flags = data[10]
    pos = 13 + (3 << ((flags & 7) + 1) if flags & 0x80 else 0)
    head = data[:pos]
    while data[pos] == 0x21:                  # extensions: label, then sub-blocks to a 0 byte
        pos += 2
        while data[pos]:
            pos += data[pos] + 1
        pos += 1
    if data[pos] != 0x2C:
        raise ValueError("unexpected GIF block from the encoder")
    end = len(data) - 1 if data[-1] == 0x3B else len(data)
    return head, data[pos:end]


def _encode(indices: np.ndarray, palette: bytes) -> tuple:
    img = Image.fromarray(np.ascontiguousarray(indices), "P")
    img.putpalette(palette)
    buf = io.BytesIO()
    img.save(buf, format="GIF", optimize=False)
    return _blocks(buf.getvalue())


class FrameEncoder:
    """Encodes the frames of one run in order: the first in full, each later one as the
    rectangle that changed since the one before, unchanged pixels transparent."""

    def __init__(self, palette: bytes):
        self.palette, self.clear = palette, len(palette) // 3 - 1
        self._prev = None

    def __call__(self, rgb) -> tuple:
        """(head, body, clear): the GIF header with the colour table, the image descriptor
        with its LZW data, and the transparent palette index (None: the frame has none)."""
        idx = quantize(rgb, self.palette)
        prev, self._prev = self._prev, idx
        if prev is None or prev.shape != idx.shape:
            return (*_encode(idx, self.palette), None)
        changed = idx != prev
        rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
        if len(rows) == 0:                          # nothing moved: one transparent pixel
            y0 = y1 = x0 = x1 = 0
        else:
            y0, y1, x0, x1 = rows[0], rows[-1], cols[0], cols[-1]
        part = idx[y0:y1 + 1, x0:x1 + 1].copy()
        part[~changed[y0:y1 + 1, x0:x1 + 1]] = self.clear
        head, body = _encode(part, self.palette)
        body = body[:1] + struct.pack("<HH", x0, y0) + body[5:]     # place the rectangle
        return head, body, self.clear


# [frames/s] the fastest GIF that plays on time: its delays are whole 1/100 s, and most
# viewers (browsers among them) show a delay below 2/100 s as 1/10 s, so 100 fps played at
# a tenth of its speed
MAX_GIF_FPS = 50.0


def check_gif_fps(fps, flag: str = "fps=") -> None:
    """ValueError naming fps [frames/s] (as `flag` and its value: "fps=60", "--fps 60") where a
    GIF at that rate would play slow (above MAX_GIF_FPS); an MP4 or HTML animation has no such
    bound. What is no number is left to frame_times to refuse."""
    x = to_float(fps)
    if x is not None and x > MAX_GIF_FPS:
        raise ValueError(f"{flag}{x:g} frames/s is too fast for a GIF: its frame delays are whole "
                         f"1/100 s and most viewers slow those below 2/100 s to 1/10 s; give at "
                         f"most {MAX_GIF_FPS:g} fps, or write an .mp4")


def gif_delays(n: int, fps: float) -> list:
    """Frame delays [ms] in the GIF's 10 ms units whose running sum stays on the fps clock
    (30 fps: 30, 40, 30, 30, 40, ... ms rather than 30 ms every frame, which runs 11% fast)."""
    cs = np.round(np.arange(n + 1) * 100.0 / fps)
    return [int(d) for d in np.maximum(np.diff(cs), 1) * 10]


class GifStream:
    """Writes frames encoded by FrameEncoder to a binary file, in order; the GIF loops forever."""

    def __init__(self, fileobj, n_frames: int, fps: float):
        self.f, self.delays, self.k = fileobj, gif_delays(n_frames, fps), 0
        self._head = None

    def add(self, encoded: tuple) -> None:
        head, body, clear = encoded
        if self._head is None:
            self._head = head
            self.f.write(b"GIF89a" + head[6:])     # 89a: the delays and loop are extensions
            self.f.write(b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00")      # loop forever
        elif head[10:] != self._head[10:]:
            raise ValueError("GIF frames with different palettes cannot share one colour table")
        delay_cs = self.delays[min(self.k, len(self.delays) - 1)] // 10
        flags = (1 << 2) | int(clear is not None)     # keep the frame below; transparency on/off
        self.f.write(b"\x21\xf9\x04" + struct.pack("<BHB", flags, delay_cs, clear or 0) + b"\x00")
        self.f.write(body)
        self.k += 1

    def close(self) -> None:
        self.f.write(b"\x3b")
