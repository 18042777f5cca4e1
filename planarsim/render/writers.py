"""Video writers fed with RGB frames: GIF (Pillow), MP4 (ffmpeg), HTML (a player page).

Each writer splits its work in two: ``encode(rgb)`` turns one frame (H, W, 3) uint8 into what
the file needs (it may run in a worker process: it must not touch the file), and ``add``
appends that to the file in frame order; ``close`` finishes the file. All write to a staging
path given by the caller (animate.py moves it onto the target).
"""
from __future__ import annotations

import base64
import io

from PIL import Image

from .html import player_page
from .gif import FrameEncoder, GifStream, palette_from, quantize


class GifWriter:
    """Animated GIF with one palette of `colors` colours fitted to `samples` (RGB frames)."""

    def __init__(self, path, n_frames: int, fps: float, samples, colors: int = 64):
        self.encode = FrameEncoder(palette_from(samples, colors))
        self._file = open(path, "wb")
        self._stream = GifStream(self._file, n_frames, fps)

    def add(self, encoded) -> None:
        self._stream.add(encoded)

    def close(self) -> None:
        self._stream.close()
        self._file.close()

    def abort(self) -> None:
        self._file.close()


class Mp4Writer:
    """H.264 MP4 (yuv420p, plays everywhere) through the ffmpeg of imageio-ffmpeg."""

    def __init__(self, path, size: tuple, fps: float, bitrate=None):
        import imageio_ffmpeg
        kbit = f"{int(bitrate)}k" if bitrate else None
        self._gen = imageio_ffmpeg.write_frames(str(path), size, fps=fps, codec="libx264", bitrate=kbit,
                                                pix_fmt_in="rgb24", pix_fmt_out="yuv420p", macro_block_size=2,
                                                output_params=["-f", "mp4"], ffmpeg_log_level="error")
        self._gen.send(None)

    def encode(self, rgb):
        return rgb.tobytes()

    def add(self, encoded) -> None:
        self._gen.send(encoded)

    def close(self) -> None:
        self._gen.close()

    def abort(self) -> None:
        self._gen.close()


class HtmlWriter:
    """Frames as base64 PNG (palette of `colors` colours) for a player page (html.py); an
    error, not dropped frames, once they pass `limit_mb` megabytes."""

    def __init__(self, path, fps: float, samples, colors: int = 128, limit_mb: float = 200.0, page=None):
        self.path, self.fps, self.page = path, float(fps), page or {}
        self.palette = palette_from(samples, colors)
        n = len(self.palette) // 3 - 1
        self._png_palette = self.palette[:3 * n]
        self.limit = float(limit_mb) * 1024 * 1024
        self.frames, self.bytes = [], 0

    def encode(self, rgb):
        buf = io.BytesIO()
        img = Image.fromarray(quantize(rgb, self.palette), "P")
        img.putpalette(self._png_palette)
        img.save(buf, format="PNG", compress_level=6)
        return base64.b64encode(buf.getvalue()).decode("ascii")

    def add(self, encoded) -> None:
        self.bytes += len(encoded)
        if self.bytes >= self.limit:
            raise ValueError(f"HTML animation exceeds the {self.limit / 1024 / 1024:.0f} MB embed limit at "
                             f"frame {len(self.frames) + 1}: lower fps, size or dpi, or pass embed_limit_mb")
        self.frames.append(encoded)

    def close(self) -> None:
        with open(self.path, "w", encoding="utf-8") as f:
            f.write(player_page(self.frames, self.fps, **self.page))

    def abort(self) -> None:
        self.frames = []
