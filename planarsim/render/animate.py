"""Animation export of a recorded Trajectory: GIF (Pillow), MP4 (ffmpeg), self-contained HTML.

Frames are sampled from the trajectory's times: video frame k (k = 0 .. n-1) shows the
recorded frame nearest to simulated time t_start + k * speed / fps, with
n = round(duration * fps / speed); a trajectory recorded every h seconds with frames at
t_1 .. t_K lasts t_K - t_1 + h. So ``speed=1`` is real time, ``speed=0.25`` slow motion
(4x longer video) and ``speed=4`` four times faster than real time; a 2 s run at 30 fps gives
60 frames. The camera (camera.py) follows the COM in simulated time, so the picture is the
same at every playback speed.

MP4 uses the ffmpeg binary shipped by the ``imageio-ffmpeg`` wheel (a dependency of
planarsim; no system install). Every file is written to a temporary file and moved onto
the target at the end (planarsim.files): an error, Ctrl-C or SIGKILL leaves no half-written
file at or beside the target. Unknown extensions and unwritable folders are rejected before any frame is drawn.
"""
from __future__ import annotations

import math
import os
import re
import sys
import tempfile
from pathlib import Path

import numpy as np
from matplotlib import animation

from ..files import discard, publish, staging_file
from .camera import Camera
from .draw import Scene, make_figure

VIDEO_FORMATS = {".gif": "gif", ".mp4": "mp4", ".html": "html", ".htm": "html"}


# frame sampling ------------------------------------------------------------------------------
def frame_times(traj, fps: float = 30.0, speed: float = 1.0, start=None, duration=None) -> np.ndarray:
    """Simulated times [s] shown by the video frames (see module docstring)."""
    fps, speed = float(fps), float(speed)
    if not (math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps={fps} must be finite and > 0 frames per second")
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed={speed} must be finite and > 0 (1 real time, <1 slow motion, >1 faster)")
    if len(traj.t) == 0:
        raise ValueError("the trajectory has no frames to animate")
    # each recorded frame stands for one recording interval h: frames at h, 2h, .. T cover T
    h = float(np.median(np.diff(traj.t))) if len(traj.t) > 1 else 0.0
    t0 = float(traj.t[0]) if start is None else float(start)
    t_end = float(traj.t[-1]) + h
    if duration is None:
        duration = t_end - t0
    duration = float(duration)
    if not (math.isfinite(duration) and duration >= 0):
        raise ValueError(f"duration={duration} must be finite and >= 0 s")
    if t0 < float(traj.t[0]) - 1e-9 or t0 + duration > t_end + 1e-6 * max(1.0, abs(t_end)):
        raise ValueError(f"start={t0:g} s, duration={duration:g} s lies outside the trajectory "
                         f"({traj.t[0]:g} .. {traj.t[-1]:g} s, recorded every {h:g} s)")
    n = max(1, int(round(duration * fps / speed)))
    return t0 + np.arange(n) * (speed / fps)


def frame_indices(traj, times) -> np.ndarray:
    """Index of the recorded frame nearest to each time."""
    t = np.asarray(traj.t)
    i = np.clip(np.searchsorted(t, times), 1, max(1, len(t) - 1))
    if len(t) == 1:
        return np.zeros(len(times), dtype=int)
    left = t[i - 1]
    right = t[i]
    return np.where(np.abs(np.asarray(times) - left) <= np.abs(right - np.asarray(times)), i - 1, i)


# progress ------------------------------------------------------------------------------------
class TextProgress:
    """A one-line text progress bar on stderr: ``[#####.....] 30/60 frames``."""

    def __init__(self, total: int, label: str = "frames", stream=None, width: int = 30):
        self.total, self.label, self.width = int(total), label, width
        self.stream = stream if stream is not None else sys.stderr
        self._last = -1

    def __call__(self, done: int) -> None:
        filled = int(self.width * done / max(1, self.total))
        if filled == self._last and done < self.total:
            return
        self._last = filled
        bar = "#" * filled + "." * (self.width - filled)
        end = "\n" if done >= self.total else ""
        self.stream.write(f"\r[{bar}] {done}/{self.total} {self.label}{end}")
        self.stream.flush()


def _progress(progress, total, label):
    if progress is True:
        return TextProgress(total, label)
    if callable(progress):
        return lambda done: progress(done, total)
    return lambda done: None


# file checks ---------------------------------------------------------------------------------
def check_output_path(path, formats=VIDEO_FORMATS) -> tuple[Path, str]:
    """(path, format) or a clear error for an unknown extension or an unwritable folder."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in formats:
        raise ValueError(f"cannot write animation {str(path)!r}: extension {ext or '(none)'!r} unknown; "
                         f"use one of {', '.join(sorted(formats))}")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise OSError(f"cannot write {str(path)!r}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK):
        raise OSError(f"cannot write {str(path)!r}: folder {str(parent)!r} is not writable")
    if path.is_dir():
        raise OSError(f"cannot write {str(path)!r}: it is a folder")
    return path, formats[ext]


def ffmpeg_exe() -> str:
    """Path of the ffmpeg binary shipped by the imageio-ffmpeg wheel (set for matplotlib too)."""
    import matplotlib
    try:
        import imageio_ffmpeg
    except ImportError as e:  # pragma: no cover - a dependency of planarsim
        raise RuntimeError("MP4 export needs the imageio-ffmpeg package (pip install imageio-ffmpeg)") from e
    exe = imageio_ffmpeg.get_ffmpeg_exe()
    matplotlib.rcParams["animation.ffmpeg_path"] = exe
    return exe


def _writer(fmt, fps, bitrate=None, embed_limit_mb=200.0):
    if fmt == "gif":
        return _GifWriter(fps=fps)
    if fmt == "mp4":
        ffmpeg_exe()
        return animation.FFMpegWriter(fps=fps, codec="libx264", bitrate=bitrate,
                                      extra_args=["-pix_fmt", "yuv420p"])
    if fmt == "html":
        return animation.HTMLWriter(fps=fps, embed_frames=True, default_mode="loop",
                                    embed_limit=embed_limit_mb)
    raise ValueError(fmt)


def _gif_durations(n: int, fps: float) -> list:
    """Frame delays [ms] in the GIF's 10 ms units whose running sum stays on the fps clock
    (30 fps: 30, 40, 30, 30, 40, ... ms rather than 30 ms every frame, which runs 11% fast)."""
    cs = np.round(np.arange(n + 1) * 100.0 / fps)
    return [int(d) for d in np.maximum(np.diff(cs), 1) * 10]


class _GifWriter(animation.PillowWriter):
    """matplotlib's PillowWriter with per-frame delays that keep the GIF on time."""

    def finish(self):
        self._frames[0].save(self.outfile, save_all=True, append_images=self._frames[1:],
                             duration=_gif_durations(len(self._frames), self.fps), loop=0)


# the exporter --------------------------------------------------------------------------------
class FrameRenderer:
    """Draws the sampled frames of a trajectory with a Scene and a tracking Camera."""

    def __init__(self, traj, model, fps=30.0, speed=1.0, start=None, duration=None, size=(6.4, 3.6),
                 dpi=100, camera: Camera | None = None, **scene_kw):
        if traj.q.shape[1:] != (model.n_body, 3):
            raise ValueError(f"trajectory has {traj.q.shape[1]} bodies per frame but the model has "
                             f"{model.n_body} ({list(model.body_names)}): wrong model for this trajectory?")
        self.traj, self.model = traj, model
        self.times = frame_times(traj, fps, speed, start, duration)
        self.index = frame_indices(traj, self.times)
        # even pixel sizes: H.264 with yuv420p needs them
        w_px, h_px = (max(2, int(round(float(v) * dpi)) // 2 * 2) for v in size)
        self.fig, self.ax = make_figure((w_px / dpi, h_px / dpi), dpi)
        self.scene = Scene(model, self.ax, **scene_kw)
        cam = camera if camera is not None else Camera()
        self.centers = cam.track(self.times, traj.com(model)[self.index], traj.com_velocity(model)[self.index])

    def __len__(self):
        return len(self.times)

    def draw(self, k: int):
        return self.scene.draw_frame(self.traj, int(self.index[k]), center=self.centers[k])


def export_animation(traj, model, path, fps: float = 30.0, speed: float = 1.0, start=None, duration=None,
                     size=(6.4, 3.6), dpi: int = 100, camera: Camera | None = None, progress=True,
                     bitrate=None, embed_limit_mb: float = 200.0, **scene_kw) -> Path:
    """Write an animation of `traj` to `path` (.gif, .mp4 or .html, by extension).

    fps : video frames per second; speed : simulated seconds per video second (1 real time,
    0.25 slow motion, 4 faster); start, duration : simulated time window [s] (default: all);
    size : figure size [inch] at `dpi`; camera : a Camera (default Camera()); progress :
    True for a text bar on stderr, a callable(done, total), or False; bitrate : MP4 bitrate
    [kbit/s] (None: ffmpeg's default quality); embed_limit_mb : size cap of an HTML page (an
    error, not silently dropped frames, when exceeded); scene_kw : options of
    Scene (view_width, tick_spacing, show_impulses, show_com, label_names, style, ...).
    Returns the path written.
    """
    path, fmt = check_output_path(path)
    renderer = FrameRenderer(traj, model, fps, speed, start, duration, size, dpi, camera, **scene_kw)
    writer = _writer(fmt, fps, bitrate, embed_limit_mb)
    report = _progress(progress, len(renderer), f"frames -> {path.name}")
    suffix = ".html" if fmt == "html" else path.suffix
    tmp = staging_file(path, suffix)
    try:
        with writer.saving(renderer.fig, tmp, dpi):
            for k in range(len(renderer)):
                renderer.draw(k)
                writer.grab_frame()
                if getattr(writer, "_hit_limit", False):   # matplotlib would drop the rest silently
                    raise ValueError(f"HTML animation {str(path)!r} exceeds the {writer._bytes_limit / 1e6:.0f} MB "
                                     f"embed limit at frame {k + 1} of {len(renderer)}: lower fps, size or "
                                     f"dpi, or pass embed_limit_mb")
                report(k + 1)
        if fmt == "html":
            _wrap_html_page(tmp, title=path.stem)
        publish(tmp, path)
    except BaseException:
        discard(tmp)
        raise
    return path


# matplotlib's player draws its buttons with Font Awesome icons from a CDN; the page must work
# offline, so the stylesheet link goes and each icon becomes a plain character
_ICONS = {"fa-minus": "&minus;", "fa-fast-backward": "|&#9664;&#9664;", "fa-step-backward": "|&#9664;",
          "fa-play fa-flip-horizontal": "&#9664;", "fa-pause": "&#10074;&#10074;", "fa-play": "&#9654;",
          "fa-step-forward": "&#9654;|", "fa-fast-forward": "&#9654;&#9654;|", "fa-plus": "+"}


def self_contained(fragment: str) -> str:
    """matplotlib's HTML animation without its external stylesheet (icons as characters)."""
    fragment = re.sub(r'<link rel="stylesheet"\s+href="[^"]*font-awesome[^"]*">', "", fragment)
    for cls, text in _ICONS.items():
        fragment = fragment.replace(f'<i class="fa {cls}"></i>', text)
    return fragment


def _wrap_html_page(tmp, title):
    """Turn matplotlib's HTML fragment into a complete, offline page (doctype, head, body)."""
    body = self_contained(Path(tmp).read_text(encoding="utf-8"))
    page = ("<!DOCTYPE html>\n<html>\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{title} - planarsim</title>\n</head>\n<body>\n{body}\n</body>\n</html>\n")
    Path(tmp).write_text(page, encoding="utf-8")


def animation_html(traj, model, fps: float = 30.0, speed: float = 1.0, progress=False, **kw) -> str:
    """The animation as an HTML fragment (frames embedded as base64 PNG, with play/pause and a
    frame slider): what a Jupyter notebook shows inline."""
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "animation.html"
        export_animation(traj, model, out, fps=fps, speed=speed, progress=progress, **kw)
        page = out.read_text(encoding="utf-8")
    start, end = page.index("<body>") + len("<body>"), page.rindex("</body>")
    return page[start:end].strip()


def show_inline(traj, model, fps: float = 30.0, speed: float = 1.0, **kw):
    """Inline animation for Jupyter: an ``IPython.display.HTML`` object (the HTML string when
    IPython is not installed)."""
    html = animation_html(traj, model, fps=fps, speed=speed, **kw)
    try:
        from IPython.display import HTML
    except ImportError:
        return html
    return HTML(html)
