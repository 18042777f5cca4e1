"""Animation export of a recorded Trajectory: GIF (Pillow), MP4 (ffmpeg), self-contained HTML.

Frame sampling and playback speed: see frames.py. One figure is drawn per export and its
artists are moved from frame to frame (nothing is re-created); the frames are drawn on both
cores (forked workers, frames.map_frames) when the machine has them, and handed as RGB pixels
to the writer (writers.py): a GIF with one palette for the whole animation (64 colours: a
10 s walk at 640x360 and 20 fps is well under 1 MB), an H.264 MP4 from the ffmpeg binary
shipped by the ``imageio-ffmpeg`` wheel (no system install), or an HTML page with a player.

Every file is written to a temporary file and moved onto the target at the end
(planarsim.files): an error, Ctrl-C or SIGKILL leaves no half-written file at or beside the
target. Unknown extensions and unwritable folders are rejected before any frame is drawn.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..checks import finite_number
from ..files import discard, folder_refuses, publish, staging_file
from ..progress import TextProgress, progress_for  # noqa: F401  (TextProgress: public here too)
from .camera import Camera
from .frames import FrameRenderer, frame_indices, frame_times, map_frames, usable_cores  # noqa: F401
from .gif import check_gif_fps
from .html import player_fragment, self_contained  # noqa: F401
from .writers import GifWriter, HtmlWriter, Mp4Writer

VIDEO_FORMATS = {".gif": "gif", ".mp4": "mp4", ".html": "html", ".htm": "html"}
PARALLEL_MIN_FRAMES = 40    # fewer frames: forking costs more than it saves


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
    if path.is_dir():
        raise OSError(f"cannot write {str(path)!r}: it is a folder")
    refused = "" if os.access(parent, os.W_OK) else "permission denied"
    refused = refused or folder_refuses(path)
    if refused:
        raise OSError(f"cannot write {str(path)!r}: folder {str(parent)!r} is not writable "
                      f"({refused.lower()})")
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


def _samples(renderer, n: int = 5) -> list:
    """n frames spread over the animation, every other pixel (RGB arrays to fit a palette to)."""
    ks = np.unique(np.linspace(0, len(renderer) - 1, min(n, len(renderer))).round().astype(int))
    return [renderer.rgb(int(k))[::2, ::2].copy() for k in ks]


def _make_writer(fmt, tmp, renderer, fps, bitrate, embed_limit_mb, colors, page):
    if fmt == "gif":
        return GifWriter(tmp, len(renderer), fps, _samples(renderer), colors)
    if fmt == "mp4":
        ffmpeg_exe()
        return Mp4Writer(tmp, renderer.pixel_size, fps, bitrate)
    return HtmlWriter(tmp, fps, _samples(renderer), max(colors, 128), embed_limit_mb, page)


def _default_workers(n_frames: int) -> int:
    """2 on a machine with 2 or more usable cores for 40 frames or more; 1 where threads other
    than this one run (a notebook kernel's, say): forking a threaded process is unsafe."""
    import threading
    if n_frames < PARALLEL_MIN_FRAMES or threading.active_count() > 1:
        return 1
    return min(2, usable_cores())


def _pump(renderer, writer, workers, report) -> None:
    """Draw every frame (on `workers` processes), encode it and add it to `writer` in order."""
    frames = map_frames(lambda k: writer.encode(renderer.image(k)), len(renderer), workers, report)
    try:
        for encoded in frames:
            writer.add(encoded)
    finally:
        frames.close()          # ends the drawing processes now, not when the traceback goes


def export_animation(traj, model, path, fps: float = 30.0, speed: float = 1.0, start=None, duration=None,
                     size=(6.4, 3.6), dpi: int = 100, camera: Camera | None = None, progress=True,
                     bitrate=None, embed_limit_mb: float = 200.0, colors: int = 64, workers=None,
                     title=None, summary=None, **scene_kw) -> Path:
    """Write an animation of `traj` to `path` (.gif, .mp4 or .html, by extension).

    fps : video frames per second (a GIF's at most 50: gif.MAX_GIF_FPS); speed : simulated
    seconds per video second (1 real time, 0.25 slow motion, 4 faster); start, duration :
    simulated time window [s] (default: all);
    size : figure size [inch] at `dpi`; camera : a Camera (default Camera()); progress :
    True for a text bar on stderr when stderr is a terminal (nothing in a pipe or a log), a
    callable(done, total), or False; bitrate : MP4 bitrate
    [kbit/s] (None: ffmpeg's default quality); embed_limit_mb : size cap of an HTML page (an
    error, not silently dropped frames, when exceeded); colors : GIF palette size (2..256);
    workers : processes drawing frames (default: the usable cores, at most 2, for 40 frames
    or more); title, summary : the HTML page's heading and the table beside the player;
    scene_kw : options of Scene (view_width, tick_spacing, show_impulses, show_com, sides,
    label_names, style, ...). Returns the path written.
    """
    path, fmt = check_output_path(path)
    if fmt == "gif":
        check_gif_fps(fps)
    if bitrate is not None:
        # ffmpeg refused it only once started: a broken pipe and its whole command line
        finite_number("bitrate", bitrate, least=1.0,
                      expected="None (ffmpeg's default quality) or a number >= 1 [kbit/s]")
    renderer = FrameRenderer(traj, model, fps, speed, start, duration, size, dpi, camera, **scene_kw)
    report = progress_for(progress, len(renderer), f"frames -> {path.name}")
    tmp = staging_file(path, ".html" if fmt == "html" else path.suffix)
    writer = None
    try:
        page = {"title": title or path.stem, "summary": summary}
        writer = _make_writer(fmt, tmp, renderer, fps, bitrate, embed_limit_mb, colors, page)
        _pump(renderer, writer, _default_workers(len(renderer)) if workers is None else workers, report)
        writer.close()
        publish(tmp, path)
    except BaseException:
        if writer is not None:
            writer.abort()
        discard(tmp)
        raise
    return path


def animation_html(traj, model, fps: float = 30.0, speed: float = 1.0, progress=False, autoplay=False,
                   start=None, duration=None, size=(6.4, 3.6), dpi: int = 100, camera: Camera | None = None,
                   workers=None, colors: int = 128, **scene_kw) -> str:
    """The animation as an HTML fragment (frames embedded as base64 PNG, with play/pause and a
    frame slider): what a Jupyter notebook shows inline. Arguments as export_animation."""
    import tempfile

    renderer = FrameRenderer(traj, model, fps, speed, start, duration, size, dpi, camera, **scene_kw)
    report = progress_for(progress, len(renderer), "frames")
    with tempfile.TemporaryDirectory() as d:
        writer = HtmlWriter(Path(d) / "unused.html", fps, _samples(renderer), colors)
        _pump(renderer, writer, _default_workers(len(renderer)) if workers is None else workers, report)
    return player_fragment(writer.frames, fps, autoplay=autoplay)


def show_inline(traj, model, fps: float = 30.0, speed: float = 1.0, **kw):
    """Inline animation for Jupyter: an ``IPython.display.HTML`` object (the HTML string when
    IPython is not installed)."""
    html = animation_html(traj, model, fps=fps, speed=speed, **kw)
    try:
        from IPython.display import HTML
    except ImportError:
        return html
    return HTML(html)
