"""The frames of an animation: which recorded frame each video frame shows, and its pixels.

Frames are sampled from the trajectory's times: video frame k (k = 0 .. n-1) shows the
recorded frame nearest to simulated time t_start + k * speed / fps, with
n = round(duration * fps / speed); a trajectory with frames at t_0 .. t_K (frame 0: the state
the run started from) lasts t_K - t_0. So ``speed=1`` is real time, ``speed=0.25`` slow motion
(4x longer video) and ``speed=4`` four times faster than real time; a 2 s run at 30 fps gives
60 frames. The camera (camera.py) follows the COM in simulated time, so the picture is the
same at every playback speed. The time printed on frame k is t_start + k * speed / fps minus
the trajectory's first time: the first frame of a whole run says 0.

``FrameRenderer`` owns one figure and one Scene and moves their artists per frame;
``map_frames`` runs a per-frame function on forked worker processes (each with its own copy
of the figure and a contiguous run of frames) and hands the results back in order.
"""
from __future__ import annotations

import math
import os
import pickle

import numpy as np

from ..checks import pair, to_float
from ..errors import plain
from ..trajectory import check_recorded_by
from .camera import Camera, camera_or_default
from .draw import Scene, make_figure


def frame_times(traj, fps: float = 30.0, speed: float = 1.0, start=None, duration=None) -> np.ndarray:
    """Simulated times [s] shown by the video frames (see module docstring)."""
    fps, speed = float(fps), float(speed)
    if not (math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps={fps} must be finite and > 0 frames per second")
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed={speed} must be finite and > 0 (1 real time, <1 slow motion, >1 faster)")
    if len(traj.t) == 0:
        raise ValueError("the trajectory has no frames to animate")
    # frame 0 is the run's start: frames at 0, h, .. T cover T
    h = float(np.median(np.diff(traj.t))) if len(traj.t) > 1 else 0.0
    if start is None:
        t0 = float(traj.t[0])
    else:
        try:
            t0 = float(start)
        except (TypeError, ValueError):
            raise ValueError(f"start={start!r} must be a number of seconds") from None
        if not math.isfinite(t0):
            raise ValueError(f"start={t0} must be finite [s]")
    t_end = float(traj.t[-1])
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


def figure_size(size, dpi) -> tuple:
    """((width, height) [inch], dpi) as floats, or a ValueError naming them: two finite
    numbers > 0 and a finite dpi > 0 (dpi 0 divided by zero, a NaN one failed in int(), a
    negative size was drawn 2 pixels wide)."""
    w, h = pair("size", size, "(width, height) [inch], two numbers")
    if not (math.isfinite(w) and math.isfinite(h) and w > 0 and h > 0):
        raise ValueError(f"size=({w:g}, {h:g}) must be two finite numbers > 0 [inch]")
    x = to_float(dpi)
    if x is None:
        raise ValueError(f"dpi={plain(dpi)!r} must be a number (pixels per inch)")
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"dpi={x:g} must be finite and > 0 (pixels per inch)")
    return (w, h), x


def frame_indices(traj, times) -> np.ndarray:
    """Index of the recorded frame nearest to each time."""
    t = np.asarray(traj.t)
    i = np.clip(np.searchsorted(t, times), 1, max(1, len(t) - 1))
    if len(t) == 1:
        return np.zeros(len(times), dtype=int)
    left = t[i - 1]
    right = t[i]
    return np.where(np.abs(np.asarray(times) - left) <= np.abs(right - np.asarray(times)), i - 1, i)


class FrameRenderer:
    """Draws the sampled frames of a trajectory with a Scene and a tracking Camera.

    size : figure size [inch] at `dpi` (rounded to even pixel counts, as H.264 needs);
    scene_kw : options of Scene.
    """

    def __init__(self, traj, model, fps=30.0, speed=1.0, start=None, duration=None, size=(6.4, 3.6),
                 dpi=100, camera: Camera | None = None, **scene_kw):
        check_recorded_by(traj, model, type(self).__name__)
        cam = camera_or_default(camera)
        self.traj, self.model = traj, model
        self.times = frame_times(traj, fps, speed, start, duration)
        self.index = frame_indices(traj, self.times)
        self.shown_times = self.times - float(traj.t[0])
        size, dpi = figure_size(size, dpi)
        w_px, h_px = (max(2, int(round(float(v) * dpi)) // 2 * 2) for v in size)
        self.fig, self.ax = make_figure((w_px / dpi, h_px / dpi), dpi)
        self.scene = Scene(model, self.ax, **scene_kw)
        self.centers = cam.track(self.times, traj.com(model)[self.index], traj.com_velocity(model)[self.index])

    def __len__(self):
        return len(self.times)

    @property
    def pixel_size(self) -> tuple:
        """(width, height) of a frame in pixels."""
        return self.fig.canvas.get_width_height()

    def draw(self, k: int):
        """Move the artists to video frame k; returns them."""
        return self.scene.draw_frame(self.traj, int(self.index[k]), center=self.centers[k],
                                     t=self.shown_times[k])

    def image(self, k: int):
        """Video frame k as a Pillow RGB image."""
        from PIL import Image
        self.draw(k)
        canvas = self.fig.canvas
        canvas.draw()
        return Image.frombuffer("RGBA", self.pixel_size, canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")

    def rgb(self, k: int) -> np.ndarray:
        """Video frame k as an (height, width, 3) uint8 array."""
        return np.asarray(self.image(k))


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:      # pragma: no cover - not Linux
        return os.cpu_count() or 1


def map_frames(work, n: int, workers: int = 1, received=None):
    """Yield work(k) for k = 0 .. n-1 in order. With workers > 1 (and a platform that can fork)
    each of `workers` forked processes computes one contiguous run of frames, in order (so a
    stateful `work`, a GIF delta say, sees its previous frame); results are kept until their
    turn. received(count) is called as results arrive (for a progress bar)."""
    import multiprocessing as mp
    from multiprocessing.connection import wait
    received = received or (lambda count: None)
    if workers <= 1 or n < 2 or "fork" not in mp.get_all_start_methods():
        for k in range(n):
            value = work(k)
            received(k + 1)
            yield value
        return
    workers = min(int(workers), n)
    bounds = [i * n // workers for i in range(workers + 1)]
    ctx = mp.get_context("fork")
    procs, conns, owner = [], [], {}
    try:
        for i in range(workers):
            recv, send = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_serve, args=(work, range(bounds[i], bounds[i + 1]), send, conns + [recv]),
                               daemon=True, name=f"planarsim-frames-{i}")
            proc.start()
            send.close()
            procs.append(proc)
            conns.append(recv)
            owner[recv] = i
        results, count, nxt = {}, 0, list(bounds[:-1])
        for k in range(n):
            while k not in results:
                for conn in wait([c for c in conns if nxt[owner[c]] < bounds[owner[c] + 1]]):
                    i = owner[conn]
                    try:
                        ok, value = conn.recv()
                    except EOFError:
                        raise RuntimeError(f"the process drawing frames {bounds[i]}..{bounds[i + 1] - 1} "
                                           f"stopped unexpectedly") from None
                    if not ok:
                        raise value
                    results[nxt[i]] = value
                    nxt[i] += 1
                    count += 1
                    received(count)
            yield results.pop(k)
    finally:
        for proc in procs:
            if proc.is_alive():
                proc.terminate()
            proc.join()
        for c in conns:
            c.close()


def _serve(work, frames, send, others):
    """Worker: send (True, work(k)) for each frame, or (False, error) and stop. Exits at once
    when the parent is gone (its end of the pipe closed)."""
    for c in others:
        c.close()
    try:
        for k in frames:
            try:
                item = (True, work(k))
            except Exception as e:   # handed to the parent, which raises it
                item = (False, e)
            try:
                send.send(item)
            except (pickle.PicklingError, TypeError, AttributeError, ValueError) as e:   # does not pickle
                item = (False, RuntimeError(f"drawing frame {k} failed: {item[1]!r} ({e})"))
                send.send(item)
            if not item[0]:
                break
    except (BrokenPipeError, ConnectionResetError, KeyboardInterrupt):
        pass
    finally:
        send.close()
        os._exit(0)
