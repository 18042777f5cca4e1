"""Interactive viewer: a live Simulator drawn in real time or slow motion.

Kelly 2014, sections 2.2-2.3: a GUI panel adjusts the gravity vector, the playback speed and the
controller's gains and shows/hides the contact impulses; playback is held on time by a
proportional-integral (PI) controller on the pause between frames, because a plain fixed
pause drifts by the render time and the operating system's sleep error every frame.

``FrameTimer`` (the PI law, with an injectable clock so tests drive it with a fake one):
after frame k is on screen, its lateness e_k = (wall time - scheduled time k T) [s] gives the
pause before the next frame

    pause_k = T - kp e_k - ki sum_{i<=k} e_i      (clamped at >= 0; no windup while clamped)

so the integral absorbs the steady render time and oversleep, the proportional term the
jitter. The integral starts from the time the first frame took to prepare. When a frame is
more than ``max_lag`` late (rendering slower than the frame rate), the schedule skips whole
frames instead of trying to catch up, and the simulation jumps by the skipped time.

``Viewer`` steps ``sim`` with ``controller(sim) -> u`` (the Python path) by ``speed * T`` of
simulated time per frame. Keys: space play/pause, right or '.' step one frame, 'i' impulses,
'c' centre of mass, 'r' reset, and the gait keys (default w walk, s stand, j jump) which call
``on_gait(name)``. Sliders: gravity [m/s^2], gravity tilt [deg], playback speed and one per
entry of ``gains = {name: (min, max, getter, setter)}``. It runs headless (Agg canvas, events
sent by a test) or on screen with :func:`view`.
"""
from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from ..checks import callable_or_none, finite_number, positive, whole
from ..errors import SimulationDiverged
from .camera import camera_or_default
from .draw import Scene

DEFAULT_GAIT_KEYS = {"w": "walk", "s": "stand", "j": "jump"}


class FrameTimer:
    """PI-corrected frame timer (see module docstring).

    period : frame interval T [s]; kp, ki : proportional and integral gains [-];
    clock : callable returning seconds (default time.perf_counter); max_lag : lateness [s]
    beyond which frames are skipped (default 2 T).
    """

    def __init__(self, period: float, kp: float = 0.7, ki: float = 0.2, clock=time.perf_counter,
                 max_lag=None):
        self.period = positive("FrameTimer: period", period, "the frame interval [s]")
        self.kp = finite_number("FrameTimer: kp", kp, 0.0)
        self.ki = finite_number("FrameTimer: ki", ki, 0.0)
        callable_or_none("FrameTimer: clock", clock, "a function clock() -> seconds")
        if clock is None:
            raise TypeError("FrameTimer: clock=None must be a function clock() -> seconds")
        self.clock = clock
        self.max_lag = (2.0 * self.period if max_lag is None
                        else finite_number("FrameTimer: max_lag", max_lag, 0.0))
        self.start()

    def start(self) -> None:
        """(Re)start the schedule: playback time 0 is the moment the next frame is on screen.
        The time that first frame takes to prepare seeds the integral (warm start), so the
        first pauses already leave room for the per-frame work."""
        self.wall0 = None
        self._started = self.clock()
        self.playback_time = 0.0      # scheduled time of the current frame [s]
        self.integral = 0.0           # sum of lateness [s]
        self.last_error = 0.0
        self.frames = 0
        self.skipped = 0

    def wall_time(self) -> float:
        """Seconds of wall time since start()."""
        return 0.0 if self.wall0 is None else self.clock() - self.wall0

    def frame_done(self) -> float:
        """Call when the current frame is on screen. Returns the pause [s] before the next frame
        and advances the schedule by one period (or more, when frames must be skipped)."""
        if self.wall0 is None:
            self.wall0 = self.clock()
            if self.ki > 0:
                self.integral = min(self.wall0 - self._started, self.period) / self.ki
        e = self.wall_time() - self.playback_time
        if e > self.max_lag:
            skip = int(e // self.period)
            self.playback_time += skip * self.period
            self.skipped += skip
            e -= skip * self.period
        self.last_error = e
        integral = self.integral + e
        pause = self.period - self.kp * e - self.ki * integral
        if pause >= 0.0:
            self.integral = integral   # no windup while the pause is clamped
        pause = max(0.0, pause)
        self.playback_time += self.period
        self.frames += 1
        return pause


class Viewer:
    """Live view of a Simulator with play/pause, stepping, sliders and gait keys.

    Parameters
    ----------
    sim : Simulator (stepped in place)
    controller : callable(sim) -> u (n_act,) or None (no commands)
    fps : frames per second on screen; speed : simulated seconds per wall second
    control_every : steps between controller calls
    gains : {name: (min, max, getter, setter)} sliders for controller gains
    gait_keys : {key: gait name}; on_gait : callable(name) called on those keys
    labels : callable(sim) -> dict shown in the overlay (e.g. {'gait': 1})
    fig : a matplotlib Figure to draw into (default: a headless Agg figure)
    clock : time source for the FrameTimer (tests pass a fake one)
    blit : redraw only the scene over a saved background (default: where the canvas can);
        a full redraw of the figure with its widgets costs several times more per frame
    scene_kw : options of Scene (view_width, tick_spacing, label_names, style, ...)
    """

    def __init__(self, sim, controller=None, fps: float = 30.0, speed: float = 1.0, control_every: int = 1,
                 gains=None, gait_keys=None, on_gait=None, labels=None, fig=None, camera=None,
                 clock=time.perf_counter, blit=None, **scene_kw):
        callable_or_none("controller", controller, "a function controller(sim) -> u")
        callable_or_none("labels", labels, "a function labels(sim) -> dict of scalars")
        callable_or_none("on_gait", on_gait, "a function on_gait(name)")
        # (a string here failed in a comparison, True was 1 step, NaN fps built the viewer)
        self.control_every = whole("control_every", control_every, least=1)
        fps = positive("fps", fps, "frames per second")
        self.sim, self.controller, self.labels = sim, controller, labels
        self.speed = _check_speed(speed)
        self.gains = _check_gains(gains)
        self.gait_keys = dict(DEFAULT_GAIT_KEYS if gait_keys is None else gait_keys)
        self.on_gait = on_gait
        self.gait = None
        self.playing = False
        self.message = ""
        self.timer = FrameTimer(1.0 / fps, clock=clock)
        self.camera = camera_or_default(camera)
        self._carry = 0.0
        self._due = self.timer.period
        self._drawn_t = sim.t
        self._initial = sim.snapshot()
        g = np.asarray(sim.model.arrays.gravity, float)
        self.gravity = float(np.hypot(*g))
        self.tilt_deg = float(np.degrees(np.arctan2(g[0], -g[1]))) if self.gravity > 0 else 0.0
        self.fig = fig if fig is not None else _headless_figure(6.4, 3.6 + 0.3 * (3 + len(self.gains)))
        self._layout(scene_kw)
        self._setup_blit(blit)
        self.draw()

    # layout -----------------------------------------------------------------------------------
    def _layout(self, scene_kw):
        from matplotlib.widgets import Button, Slider
        fig = self.fig
        n_sliders = 3 + len(self.gains)
        h_in = fig.get_figheight()
        row = 0.3 / h_in                       # slider row height as a figure fraction
        panel = row * (n_sliders + 1.5)
        self.ax = fig.add_axes((0.0, panel, 1.0, 1.0 - panel))
        self.ax.set_axis_off()
        self.scene = Scene(self.sim.model, self.ax, **scene_kw)
        self.scene.step_length = self.sim.dt
        self.sliders = {}

        def slider(i, label, lo, hi, val, fn):
            sax = fig.add_axes((0.25, panel - row * (i + 1.2), 0.6, row * 0.7))
            s = Slider(sax, label, lo, hi, valinit=val)
            s.on_changed(fn)
            self.sliders[label] = s
            return s

        slider(0, "gravity [m/s2]", 0.0, max(20.0, 1.5 * self.gravity), self.gravity,
               lambda v: self.set_gravity(v, self.tilt_deg))
        slider(1, "tilt [deg]", -20.0, 20.0, self.tilt_deg, lambda v: self.set_gravity(self.gravity, v))
        slider(2, "speed [x]", 0.05, 4.0, self.speed, self.set_speed)
        for i, (name, (lo, hi, get, set_)) in enumerate(self.gains.items()):
            slider(3 + i, name, lo, hi, float(get()), set_)
        y = panel - row * (n_sliders + 1.2)
        self.buttons = {}
        for j, (label, fn) in enumerate((("play/pause", self.toggle), ("step", self.step_frame),
                                         ("impulses", self.toggle_impulses), ("reset", self.reset))):
            bax = fig.add_axes((0.02 + 0.245 * j, max(0.0, y), 0.225, row * 0.8))
            b = Button(bax, label)
            b.on_clicked(lambda event, fn=fn: fn())
            self.buttons[label] = b
        self._cid = fig.canvas.mpl_connect("key_press_event", self.on_key)

    # actions ----------------------------------------------------------------------------------
    def on_key(self, event) -> None:
        key = event.key
        if key == " ":
            self.toggle()
        elif key in ("right", "."):
            self.step_frame()
        elif key == "i":
            self.toggle_impulses()
        elif key == "c":
            self.scene.show_com = not self.scene.show_com
            self.draw()
        elif key == "r":
            self.reset()
        elif key in self.gait_keys:
            self.set_gait(self.gait_keys[key])

    def set_gait(self, name: str) -> None:
        self.gait = name
        if self.on_gait is not None:
            self.on_gait(name)
        self.draw()

    def toggle(self) -> None:
        self.playing = not self.playing
        if self.playing:
            self.timer.start()
            self._due = self.timer.period

    def toggle_impulses(self) -> None:
        self.scene.show_impulses = not self.scene.show_impulses
        self.draw()

    def set_speed(self, speed) -> None:
        self.speed = _check_speed(speed)

    def set_gravity(self, magnitude, tilt_deg=0.0) -> None:
        """Gravity of `magnitude` [m/s^2] (finite, >= 0) tilted by `tilt_deg` (finite) from
        straight down (+: toward +x)."""
        self.gravity = finite_number("set_gravity: magnitude", magnitude, 0.0, unit=" m/s^2")
        self.tilt_deg = finite_number("set_gravity: tilt_deg", tilt_deg, unit=" deg")
        a = math.radians(self.tilt_deg)
        g = np.array([self.gravity * math.sin(a), -self.gravity * math.cos(a)])
        g.setflags(write=False)
        m = self.sim.model
        self.sim.model = dataclasses.replace(m, arrays=m.arrays._replace(gravity=g))

    def reset(self) -> None:
        """Back to the state the viewer started from (gravity and sliders kept)."""
        self.sim.restore(self._initial)
        self.camera.position = None
        self._drawn_t = self.sim.t
        self._carry = 0.0
        self.message = ""
        self.draw()

    def step_frame(self) -> None:
        """Advance one frame (speed x frame period of simulated time) and draw it."""
        self.advance(self.timer.period * self.speed)
        self.draw()

    def advance(self, sim_seconds: float) -> int:
        """Step the simulation by `sim_seconds` [s] (whole steps; the remainder carries over).
        Returns the number of steps taken. A diverged simulation pauses with a message;
        `sim_seconds` must be a finite number >= 0 (ValueError naming it)."""
        sim_seconds = finite_number("advance: sim_seconds", sim_seconds, 0.0, unit=" s")
        dt = self.sim.dt
        want = self._carry + sim_seconds / dt
        n = int(math.floor(want + 1e-9))
        self._carry = want - n
        done = 0
        try:
            while done < n:
                chunk = min(self.control_every, n - done)
                u = self.controller(self.sim) if self.controller is not None else None
                if chunk == 1:
                    self.sim.step(u)
                else:
                    self.sim.steps(chunk, u)
                done += chunk
        except SimulationDiverged as e:
            self.playing = False
            self.message = f"stopped: {e}"
        return done

    # drawing and the clock --------------------------------------------------------------------
    def draw(self):
        sim = self.sim
        q = sim.state.q
        com = self.scene.com_of(q)
        # the camera moves in simulated time, like the exported animations
        mass = sim.model.arrays.body_mass
        com_v = mass @ sim.state.v[:, :2] / mass.sum()
        center = self.camera.update(com, max(0.0, sim.t - self._drawn_t), com_v)
        self._drawn_t = sim.t
        labels = dict(self.labels(sim)) if self.labels is not None else {}
        if self.gait is not None:
            labels.setdefault("gait", self.gait)
        speed = float(com_v[0])
        arts = self.scene.draw_state(q, center=center, t=sim.t, contact_point=sim.ws.contact_point,
                                     contact_impulse=sim.ws.contact_impulse, labels=labels, speed=speed,
                                     contact_normal=sim.ws.contact_normal)
        if self.message:
            self.scene.text.set_text(self.scene.text.get_text() + "\n" + self.message[:120])
        self._present()
        return arts

    # blitting: the widgets stay in a saved background, only the scene's artists are redrawn
    def _setup_blit(self, blit):
        canvas = self.fig.canvas
        self.blit = bool(canvas.supports_blit) if blit is None else bool(blit)
        self._background = None
        if self.blit:
            for art in self.scene.artists:
                art.set_animated(True)
            canvas.mpl_connect("draw_event", self._on_full_draw)

    def _on_full_draw(self, event=None):
        """After any full redraw (first frame, a slider moved, a resize): keep the background and
        put the scene on top of it."""
        self._background = self.fig.canvas.copy_from_bbox(self.ax.bbox)
        for art in self.scene.artists:
            self.ax.draw_artist(art)

    def _present(self):
        canvas = self.fig.canvas
        if not self.blit:
            canvas.draw_idle()
        elif self._background is None:
            canvas.draw()                      # the draw_event saves the background
        else:
            canvas.restore_region(self._background)
            for art in self.scene.artists:
                self.ax.draw_artist(art)
            canvas.blit(self.ax.bbox)

    def tick(self) -> float:
        """One frame of playback: advance (when playing), draw, and return the PI-corrected pause
        [s] before the next frame."""
        if not self.playing:
            self.draw()
            return self.timer.period
        self.advance(self._due * self.speed)
        self.draw()
        before = self.timer.playback_time
        pause = self.timer.frame_done()
        # the next frame shows the simulation one period later (more if the timer skipped frames)
        self._due = self.timer.playback_time - before
        return pause

    def show(self) -> None:
        """Run on screen (needs an interactive matplotlib backend; use :func:`view`)."""
        import matplotlib.pyplot as plt
        ours = {" ", "right", ".", "i", "c", "r", *self.gait_keys}
        for key in [k for k in plt.rcParams if k.startswith("keymap.")]:
            plt.rcParams[key] = [k for k in plt.rcParams[key] if k not in ours]
        timer = self.fig.canvas.new_timer(interval=int(1000 * self.timer.period))
        timer.single_shot = True

        def on_timer():
            pause = self.tick()
            timer.interval = max(1, int(round(1000 * pause)))
            timer.start()

        timer.add_callback(on_timer)
        self._gui_timer = timer
        if not self.playing:
            self.toggle()
        timer.start()
        plt.show()


def view(sim, controller=None, **kw) -> Viewer:
    """Open the interactive viewer on screen for `sim` driven by `controller(sim) -> u`."""
    import matplotlib.pyplot as plt
    n_gains = len(kw.get("gains") or {})
    fig = plt.figure(figsize=(8.0, 4.5 + 0.35 * (3 + n_gains)))
    viewer = Viewer(sim, controller, fig=fig, **kw)
    viewer.show()
    return viewer


def view_walker(module, gait=None, terrain=None, **kw) -> Viewer:
    """Open the viewer on a walker package that offers the live-view hook

        module.live(gait=..., terrain=...) -> dict(sim=Simulator, controller=callable(sim) -> u,
            on_gait=callable(name), gains={name: (min, max, getter, setter)},
            labels=callable(sim) -> dict, label_names={label: {value: name}})

    (only ``sim`` and ``controller`` are required). This is what ``planarsim view WALKER`` runs."""
    live = getattr(module, "live", None)
    if live is None:
        name = getattr(module, "NAME", getattr(module, "__name__", repr(module)))
        raise NotImplementedError(f"walker {name!r} has no live(gait, terrain) hook for the interactive "
                                  f"viewer (see planarsim.render.viewer.view_walker)")
    args = {k: v for k, v in (("gait", gait), ("terrain", terrain)) if v is not None}
    spec = dict(live(**args))
    missing = [k for k in ("sim", "controller") if k not in spec]
    if missing:
        raise ValueError(f"{module.__name__}.live() must return sim and controller; missing {missing}")
    sim, controller = spec.pop("sim"), spec.pop("controller")
    allowed = {"on_gait", "gains", "labels", "label_names", "gait_keys", "control_every"}
    unknown = sorted(set(spec) - allowed)
    if unknown:
        raise ValueError(f"{module.__name__}.live() returned unknown keys {unknown}; allowed: {sorted(allowed)}")
    spec.update(kw)
    return view(sim, controller, **spec)


def _check_speed(speed) -> float:
    """The playback speed as a float (finite, > 0; a string failed in float(), True was 1)."""
    return positive("speed", speed, "playback speed: 1 real time, < 1 slow motion")


def _check_gains(gains) -> dict:
    """gains as a dict {name: (min, max, getter, setter)}: a ValueError (TypeError for what
    is no dict or no function) naming the gain and what is wrong (a string min failed in a
    comparison, NaN or inf bounds built a slider that could not be drawn)."""
    try:
        gains = dict(gains or {})
    except (TypeError, ValueError):
        raise TypeError(f"gains={gains!r} must be a dict {{name: (min, max, getter, setter)}}") from None
    out = {}
    for name, spec in gains.items():
        if not isinstance(spec, (tuple, list)) or len(spec) != 4:
            raise ValueError(f"gain {name!r}: {spec!r} must be (min, max, getter, setter)")
        lo = finite_number(f"gain {name!r}: min", spec[0])
        hi = finite_number(f"gain {name!r}: max", spec[1])
        if not lo < hi:
            raise ValueError(f"gain {name!r}: min={lo:g} must be < max={hi:g}")
        for which, f in (("getter", spec[2]), ("setter", spec[3])):
            if not callable(f):
                raise TypeError(f"gain {name!r}: {which}={f!r} must be a function")
        out[name] = (lo, hi, spec[2], spec[3])
    return out


def _headless_figure(w, h):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(w, h), dpi=100)
    FigureCanvasAgg(fig)
    return fig
