"""The interactive viewer and its frame timer (planarsim/render/viewer.py), headless with Agg."""

import math
import random

import numpy as np
import pytest
from matplotlib.backend_bases import KeyEvent, MouseEvent

import planarsim as ps
from planarsim.render import FrameTimer, Viewer
from tests.render.helpers import pendulum_model


class FakeClock:
    """Wall time that only moves when the loop renders or sleeps, with jitter: rendering takes
    5-9 ms, a sleep is rounded to whole milliseconds (GUI timers) and overshoots by 0-1 ms."""

    def __init__(self, seed=0, render=(0.005, 0.009), oversleep=(0.0, 0.001)):
        self.t = 1000.0
        self.rng = random.Random(seed)
        self.render_range, self.oversleep = render, oversleep

    def __call__(self):
        return self.t

    def render(self):
        self.t += self.rng.uniform(*self.render_range)

    def sleep(self, d):
        self.t += round(max(d, 0.0) * 1000) / 1000 + self.rng.uniform(*self.oversleep)


def run_timer(timer, clock, seconds=10.0):
    errors = []
    timer.start()
    while clock() - 1000.0 < seconds:
        clock.render()
        pause = timer.frame_done()
        errors.append(timer.last_error)
        clock.sleep(pause)
    return np.array(errors)


def key(viewer, k):
    c = viewer.fig.canvas
    c.callbacks.process("key_press_event", KeyEvent("key_press_event", c, k))


def click(viewer, ax, fx=0.5, fy=0.5):
    c = viewer.fig.canvas
    bb = ax.get_window_extent()
    x, y = bb.x0 + fx * bb.width, bb.y0 + fy * bb.height
    for name in ("button_press_event", "button_release_event"):
        c.callbacks.process(name, MouseEvent(name, c, x, y, button=1))


class GaitController:
    """Holds the pendulum at an angle set by the gait, with a PD gain from a slider."""
    TARGET = {"stand": 0.0, "walk": -0.5, "jump": 0.5}

    def __init__(self):
        self.gait, self.kp = "stand", 0.0

    def __call__(self, sim):
        th, w = sim.state.q[0, 2], sim.state.v[0, 2]
        return np.array([self.kp * (self.TARGET[self.gait] - th) - 0.2 * self.kp * w])


@pytest.fixture
def live():
    model = pendulum_model()
    sim = ps.Simulator(model)
    ctrl = GaitController()
    gains = {"kp": (0.0, 200.0, lambda: ctrl.kp, lambda v: setattr(ctrl, "kp", v))}
    clock = FakeClock(7)
    viewer = Viewer(sim, ctrl, fps=30, gains=gains, on_gait=lambda g: setattr(ctrl, "gait", g),
                    labels=lambda s: {"angle": round(float(s.state.q[0, 2]), 3)}, clock=clock,
                    overlay_labels=["gait", "angle"])
    return viewer, sim, ctrl, clock


@pytest.mark.parametrize("kw, error, said", [
    (dict(controller=5), TypeError, r"controller=5 must be a function controller\(sim\) -> u, or None"),
    (dict(labels="angle"), TypeError, r"labels='angle' must be a function labels\(sim\)"),
    (dict(camera=5), TypeError, r"camera=5 must be a planarsim.render.Camera"),
    (dict(on_gait="walk"), TypeError, r"on_gait='walk' must be a function on_gait\(name\)"),
    # control_every and fps: a string failed in a comparison ("'<' not supported between
    # instances of 'str' and 'int'"), True was one step, NaN fps built the viewer
    (dict(control_every="2"), ValueError, r"control_every='2' must be a whole number$"),
    (dict(control_every=True), ValueError, r"control_every=True must be a whole number \(not True"),
    (dict(control_every=1.5), ValueError, r"control_every=1.5 must be a whole number$"),
    (dict(control_every=0), ValueError, r"control_every=0 must be a whole number >= 1"),
    (dict(control_every=float("nan")), ValueError, r"control_every=nan must be a whole number"),
    (dict(fps="30"), ValueError, r"fps='30' must be a finite number > 0 \(frames per second\)"),
    (dict(fps=True), ValueError, r"fps=True must be a finite number > 0"),
    (dict(fps=float("nan")), ValueError, r"fps=nan must be a finite number > 0"),
    (dict(fps=0), ValueError, r"fps=0 must be a finite number > 0"),
    (dict(fps=-30.0), ValueError, r"fps=-30.0 must be a finite number > 0"),
    # speed: "fast" failed in float() ("could not convert string to float"), True was 1
    (dict(speed="fast"), ValueError, r"speed='fast' must be a finite number > 0 \(playback speed"),
    (dict(speed=True), ValueError, r"speed=True must be a finite number > 0"),
    (dict(speed=-1.0), ValueError, r"speed=-1.0 must be a finite number > 0"),
    # gains: a bare number failed in len(), string bounds passed the comparison and failed in
    # the slider, NaN bounds were refused as "min < max" without naming which
    (dict(gains={"kp": 5}), ValueError, r"gain 'kp': 5 must be \(min, max, getter, setter\)"),
    (dict(gains={"kp": ("a", "b", float, float)}), ValueError, r"gain 'kp': min='a' must be a finite number"),
    (dict(gains={"kp": (0.0, float("nan"), float, float)}), ValueError, r"gain 'kp': max=nan must be a finite"),
    (dict(gains={"kp": (1.0, 0.0, float, float)}), ValueError, r"gain 'kp': min=1 must be < max=0"),
    (dict(gains={"kp": (0.0, 1.0, 5, float)}), TypeError, r"gain 'kp': getter=5 must be a function"),
    (dict(gains=5), TypeError, r"gains=5 must be a dict"),
])
def test_viewer_names_arguments_of_the_wrong_kind(kw, error, said):
    """controller=5 and camera=5 failed at the first frame ("'int' object is not callable",
    "has no attribute 'update'")."""
    with pytest.raises(error, match=said):
        Viewer(ps.Simulator(pendulum_model()), clock=FakeClock(7), **kw)


def test_viewer_and_timer_name_bad_numbers_given_later():
    """FrameTimer's period and gains, and the viewer's set_gravity, set_speed and advance, name
    a bad number: a string failed in math.isfinite() or float(), NaN gravity or a NaN advance
    went into the simulation (int(nan) then failed raw)."""
    with pytest.raises(ValueError, match=r"FrameTimer: period='0.1' must be a finite number > 0"):
        FrameTimer("0.1", clock=FakeClock(7))
    with pytest.raises(ValueError, match=r"FrameTimer: kp=nan must be a finite number >= 0"):
        FrameTimer(0.1, kp=float("nan"), clock=FakeClock(7))
    with pytest.raises(ValueError, match=r"FrameTimer: max_lag=-1.0 must be a finite number >= 0"):
        FrameTimer(0.1, max_lag=-1.0, clock=FakeClock(7))
    with pytest.raises(TypeError, match=r"FrameTimer: clock=5 must be a function clock\(\)"):
        FrameTimer(0.1, clock=5)
    viewer = Viewer(ps.Simulator(pendulum_model()), clock=FakeClock(7))
    t = viewer.sim.t
    with pytest.raises(ValueError, match=r"set_gravity: magnitude=nan m/s\^2 must be a finite number >= 0"):
        viewer.set_gravity(float("nan"))
    with pytest.raises(ValueError, match=r"set_gravity: tilt_deg='x' deg must be a finite number"):
        viewer.set_gravity(9.81, "x")
    with pytest.raises(ValueError, match=r"speed=0.0 must be a finite number > 0"):
        viewer.set_speed(0.0)
    for bad in (float("nan"), -0.1, "0.1"):
        with pytest.raises(ValueError, match=r"advance: sim_seconds=.* s must be a finite number >= 0"):
            viewer.advance(bad)
    assert viewer.sim.t == t and viewer.speed == 1.0
    assert viewer.sim.model.arrays.gravity[1] == pytest.approx(-9.81)


@pytest.mark.parametrize("fps,seed", [(30, 0), (60, 1), (24, 2)])
def test_pi_timer_holds_playback_within_5_ms_of_wall_time(fps, seed):
    clock = FakeClock(seed)
    errors = run_timer(FrameTimer(1.0 / fps, clock=clock), clock)
    assert len(errors) >= 0.98 * 10 * fps
    assert np.abs(errors).max() < 0.005
    assert abs(errors[len(errors) // 2:].mean()) < 0.001     # no steady lag: the integral took it


def test_fixed_pause_timer_drifts_so_the_pi_terms_matter():
    clock = FakeClock(3)
    errors = run_timer(FrameTimer(1 / 30, kp=0.0, ki=0.0, max_lag=1e9, clock=clock), clock)
    assert errors.max() > 1.0      # 7.5 ms late per frame for 10 s
    clock = FakeClock(3)
    errors = run_timer(FrameTimer(1 / 30, kp=1.0, ki=0.0, clock=clock), clock)
    assert errors[30:].mean() > 0.005   # proportional only: a steady lag (render time + oversleep)


def test_timer_skips_frames_it_cannot_render_in_time():
    clock = FakeClock(4, render=(0.045, 0.055))    # rendering slower than a 30 fps frame
    timer = FrameTimer(1 / 30, clock=clock)
    errors = run_timer(timer, clock, seconds=5.0)
    assert timer.skipped > 0
    assert errors.max() <= timer.max_lag + 1e-12
    assert timer.playback_time == pytest.approx(timer.wall_time(), abs=timer.max_lag + 2 / 30)


def test_viewer_keys_play_pause_step_and_switch_gaits(live):
    viewer, sim, ctrl, clock = live
    assert not viewer.playing
    viewer.tick()
    assert sim.t == 0.0                       # paused: nothing moves
    key(viewer, "right")
    assert sim.t == pytest.approx(1 / 30, abs=1e-3)
    key(viewer, " ")
    assert viewer.playing
    for _ in range(3):
        viewer.tick()
    assert sim.t == pytest.approx(4 / 30, abs=1e-3)
    key(viewer, " ")
    t = sim.t
    viewer.tick()
    assert sim.t == t and not viewer.playing
    for k, gait in (("w", "walk"), ("j", "jump"), ("s", "stand")):
        key(viewer, k)
        assert ctrl.gait == gait and viewer.gait == gait
    assert "gait: stand" in viewer.scene.text.get_text() and "angle:" in viewer.scene.text.get_text()
    key(viewer, "i")
    assert not viewer.scene.show_impulses
    click(viewer, viewer.buttons["impulses"].ax)
    assert viewer.scene.show_impulses
    key(viewer, "r")
    assert sim.t == 0.0


def test_viewer_gain_slider_and_gait_key_change_the_motion(live):
    viewer, sim, ctrl, clock = live
    click(viewer, viewer.sliders["kp"].ax, fx=0.5)
    assert ctrl.kp == pytest.approx(100.0, abs=2.0)
    key(viewer, "w")
    viewer.advance(1.5)                 # 1.5 s with the PD holding -0.5 rad
    assert sim.state.q[0, 2] == pytest.approx(-0.5 - 9.81 * 0.5 / ctrl.kp, abs=0.05)   # PD + gravity sag
    key(viewer, "j")
    viewer.advance(1.5)
    assert sim.state.q[0, 2] == pytest.approx(0.5 - 9.81 * 0.5 * math.cos(0.5) / ctrl.kp, abs=0.05)


def test_viewer_gravity_slider_changes_the_simulation():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_point_mass("ball", 1.0, pos=(0.0, 5.0))
    sim = ps.Simulator(b.compile())
    viewer = Viewer(sim, None, fps=30, clock=FakeClock())
    slider = viewer.sliders["gravity [m/s2]"]
    click(viewer, slider.ax, fx=0.0)
    assert slider.val == pytest.approx(0.0, abs=0.05 * slider.valmax)
    g = np.hypot(*sim.model.arrays.gravity)
    assert g == pytest.approx(slider.val)
    viewer.step_frame()
    v0 = sim.state.v[0, 1]
    for _ in range(30):
        viewer.step_frame()
    assert sim.state.v[0, 1] - v0 == pytest.approx(-g * 1.0, abs=1e-9)   # falls at the new g
    click(viewer, viewer.sliders["tilt [deg]"].ax, fx=1.0)
    click(viewer, slider.ax, fx=0.5)
    gx, gy = sim.model.arrays.gravity
    assert math.degrees(math.atan2(gx, -gy)) == pytest.approx(viewer.sliders["tilt [deg]"].val)
    vx0 = sim.state.v[0, 0]
    viewer.step_frame()
    assert sim.state.v[0, 0] > vx0          # tilted gravity pushes along +x


def test_viewer_slow_motion_stays_on_time_with_the_pi_timer(live):
    viewer, sim, ctrl, clock = live
    click(viewer, viewer.sliders["speed [x]"].ax, fx=(0.25 - 0.05) / (4.0 - 0.05))
    speed = viewer.speed
    assert speed == pytest.approx(0.25, abs=0.02)
    key(viewer, " ")
    wall, shown = [], []
    start = None
    for _ in range(60):                 # 2 s of wall time at 30 fps
        clock.render()
        pause = viewer.tick()
        start = clock() if start is None else start
        wall.append(clock() - start)
        shown.append(sim.t)
        clock.sleep(pause)
    wall, shown = np.array(wall), np.array(shown)
    first = shown[0]
    # simulated time shown = speed x wall time, within the timer's 5 ms (scaled) and one step
    assert np.abs((shown - first) - speed * wall).max() < speed * 0.005 + sim.model.dt


def test_view_opens_and_returns_under_a_non_interactive_backend():
    """`view` is the on-screen entry point; under Agg plt.show() returns at once, so this checks
    that the window set-up (figure, GUI timer, key maps) runs without a display."""
    import matplotlib.pyplot as plt
    from planarsim.render import view
    sim = ps.Simulator(pendulum_model())
    viewer = view(sim, lambda s: np.zeros(1), fps=30)
    assert viewer.playing and " " not in plt.rcParams["keymap.fullscreen"]
    assert "s" not in plt.rcParams["keymap.save"]
    plt.close(viewer.fig)


def test_view_walker_uses_the_live_hook_and_names_a_walker_without_one():
    import types
    import matplotlib.pyplot as plt
    from planarsim.render import view_walker
    ctrl = GaitController()

    def live(gait="stand", terrain=None):
        ctrl.gait = gait
        return {"sim": ps.Simulator(pendulum_model()), "controller": ctrl,
                "on_gait": lambda g: setattr(ctrl, "gait", g)}

    walker = types.SimpleNamespace(__name__="walkers.fake", NAME="fake", live=live)
    viewer = view_walker(walker, gait="walk")
    assert ctrl.gait == "walk" and viewer.controller is ctrl
    key(viewer, "j")
    assert ctrl.gait == "jump"
    plt.close(viewer.fig)
    with pytest.raises(NotImplementedError, match="'fake' has no live"):
        view_walker(types.SimpleNamespace(__name__="walkers.fake", NAME="fake"))


def test_blitted_frames_equal_full_redraws():
    """The viewer redraws only the scene over a saved background; the picture must be the one a
    full redraw of the figure gives."""
    import copy
    sim = ps.Simulator(pendulum_model())
    fast = Viewer(sim, lambda s: np.zeros(1), clock=FakeClock())
    assert fast.blit
    key(fast, " ")
    for _ in range(5):
        fast.tick()
    slow = Viewer(sim, lambda s: np.zeros(1), clock=FakeClock(), blit=False)
    slow.camera = copy.deepcopy(fast.camera)
    slow._drawn_t = fast._drawn_t
    slow.draw()
    fast.draw()
    a = np.asarray(fast.fig.canvas.buffer_rgba())
    b = np.asarray(slow.fig.canvas.buffer_rgba())
    assert a.shape == b.shape
    assert np.count_nonzero(np.any(a != b, axis=2)) == 0
    assert np.count_nonzero(np.any(a[:, :, :3] < 200, axis=2)) > 1000    # and it is not blank


def test_viewer_pauses_with_a_message_when_the_simulation_diverges():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_point_mass("ball", 1.0, pos=(0.0, 0.0))            # no contacts: falls forever
    sim = ps.Simulator(b.compile(), ps.make_options(guard_limit=5.0))
    viewer = Viewer(sim, None, clock=FakeClock())
    key(viewer, " ")
    viewer.advance(2.0)
    assert not viewer.playing
    assert viewer.message.startswith("stopped: simulation diverged")
    viewer.draw()
    assert "stopped: simulation diverged" in viewer.scene.text.get_text()
    assert sim.t < 1.1                                        # |y| passed 5 m after ~1 s
