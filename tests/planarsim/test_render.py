"""Rendering, camera, animation export, plots and the interactive viewer.

Everything runs headless with Agg; test models are built inline (a box, a pendulum, a point
mass) so these tests do not depend on any walker package.
"""
import math
import os
import random
import re
import shutil
import subprocess
from pathlib import Path

import matplotlib
matplotlib.use("Agg")

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from matplotlib.backend_bases import KeyEvent, MouseEvent

import planarsim as ps
from planarsim import terrain
from planarsim.render import (Camera, FrameTimer, Scene, Style, Viewer, cost_of_transport, export_animation,
                              frame_indices, frame_times, joint_series, make_figure, plot_summary,
                              save_figure, show_inline, step_overshoot)

RED = (1.0, 0.0, 0.0)
BLUE = (0.0, 0.0, 1.0)


# models ----------------------------------------------------------------------------------------
def box_model(pos=(0.0, 0.1), vel=(0.0, 0.0), mu=0.8, width=0.8, height=0.2, push=False):
    b = ps.ModelBuilder(dt=1e-3)
    box = b.add_body("box", mass=2.0, inertia=2.0 * (width ** 2 + height ** 2) / 12, pos=pos, vel=vel)
    b.add_box_contacts("corner", box, (0.0, 0.0), width, height, mu=mu)
    if push:
        b.add_body_force("push", box, direction=(1.0, 0.0))
    return b.compile()


def pendulum_model(length=1.0, pivot=(0.0, 1.5), motor=True):
    b = ps.ModelBuilder(dt=1e-3)
    rod = b.add_body("rod", mass=1.0, inertia=length ** 2 / 12, pos=(pivot[0] + length / 2, pivot[1]),
                     shapes=[("capsule", (-length / 2, 0.0), (length / 2, 0.0), 0.03)])
    b.add_pin("pivot", None, rod, anchor_world=pivot)
    if motor:
        b.add_pin_motor("motor", "pivot", limit=(-100.0, 100.0))
    return b.compile()


def red_style(**kw):
    return Style(body_colors=("#ff0000",), edge_color="#ff0000", body_alpha=1.0, tick_color="#0000ff",
                 terrain_color="#00ff00", ground_fill="#ffffff", **kw)


def render(model, q, center, view_width=4.0, size=(6.4, 3.6), dpi=100, **kw):
    fig, ax = make_figure(size, dpi)
    # geometry only: the legend's force arrow is red too
    scene = Scene(model, ax, view_width=view_width, show_com=False, show_text=False, show_legend=False,
                  style=red_style(), **kw)
    scene.draw_state(q, center=center)
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int)
    return img, scene


def to_pixels(scene, xy):
    """Data -> image pixel (column, row from the top)."""
    x0, x1 = scene.ax.get_xlim()
    y0, y1 = scene.ax.get_ylim()
    fig = scene.ax.figure
    w, h = fig.canvas.get_width_height()
    xy = np.asarray(xy, float).reshape(-1, 2)
    return np.column_stack([(xy[:, 0] - x0) / (x1 - x0) * w, (y1 - xy[:, 1]) / (y1 - y0) * h])


def default_file_mode():
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def mask(img, rgb):
    target = np.array(rgb) * 255
    return np.all(np.abs(img - target) < 60, axis=2)


# camera ---------------------------------------------------------------------------------------
def analytic_step(t, wn, z, amplitude):
    wd = wn * math.sqrt(1 - z * z)
    return amplitude * (1 - np.exp(-z * wn * t) * (np.cos(wd * t) + z / math.sqrt(1 - z * z) * np.sin(wd * t)))


@settings(max_examples=25, deadline=None)
@given(z=st.floats(0.1, 0.95), wn=st.floats(0.5, 20.0), amplitude=st.floats(-5.0, 5.0).filter(lambda a: abs(a) > 1e-3),
       seed=st.integers(0, 10 ** 6))
def test_camera_step_response_is_the_damped_oscillator(z, wn, amplitude, seed):
    """Uneven frame intervals: the camera samples the continuous step response exactly, so its
    overshoot never exceeds exp(-zeta pi / sqrt(1 - zeta^2)) of the step."""
    rng = np.random.default_rng(seed)
    dts = rng.uniform(0.2, 1.0, 400) * min(0.05, 0.5 / wn)
    times = np.r_[0.0, np.cumsum(dts)]
    cam = Camera(natural_frequency=wn, damping_ratio=z, position=(0.0, 0.0))
    path = cam.track(times, np.tile([amplitude, -amplitude], (len(times), 1)))
    np.testing.assert_allclose(path[:, 0], analytic_step(times, wn, z, amplitude), atol=1e-9 * abs(amplitude))
    np.testing.assert_allclose(path[:, 1], -path[:, 0], atol=1e-12)
    overshoot = path[:, 0].max() / amplitude - 1 if amplitude > 0 else path[:, 0].min() / amplitude - 1
    assert overshoot <= step_overshoot(z) + 1e-9


@pytest.mark.parametrize("z", [0.3, 0.7])
def test_camera_overshoot_matches_its_damping_ratio_at_fine_frames(z):
    """At 1000 fps the sampled peak reaches the theory (so the camera really rings as zeta says)."""
    wn = 4.0
    times = np.arange(0, 5.0, 1e-3)
    cam = Camera(wn, z, position=(0.0, 0.0))
    x = cam.track(times, np.tile([1.0, 0.0], (len(times), 1)))[:, 0]
    assert x.max() - 1 == pytest.approx(step_overshoot(z), rel=1e-4)
    t_peak = times[np.argmax(x)]
    assert t_peak == pytest.approx(math.pi / (wn * math.sqrt(1 - z * z)), abs=1.5e-3)


@settings(max_examples=25, deadline=None)
@given(z=st.floats(1.0, 3.0), wn=st.floats(0.5, 20.0), fps=st.floats(5, 240))
def test_camera_without_overshoot_when_critically_or_over_damped(z, wn, fps):
    times = np.arange(0, 20.0 / wn + 1.0, 1.0 / fps)
    cam = Camera(wn, z, position=(0.0, 0.0))
    x = cam.track(times, np.tile([2.0, 0.0], (len(times), 1)))[:, 0]
    assert x.max() <= 2.0 + 1e-12
    assert np.all(np.diff(x) >= -1e-12)           # monotone approach
    assert x[-1] > 1.9                             # it does get there


def test_camera_is_smoother_than_the_com_it_tracks():
    """A walking COM whose speed jumps at every heel strike (1 +- 0.3 m/s, twice a second): a
    camera locked on it would change speed by 0.6 m/s in one frame; the tracking camera's
    velocity stays continuous, and with the COM velocity fed in it does not lag behind."""
    fps = 60
    t = np.arange(0, 6, 1 / fps)
    v = 1.0 + 0.3 * np.sign(np.sin(2 * np.pi * 2 * t + 0.1))
    x = np.r_[0.0, np.cumsum(v[:-1]) / fps]
    com, com_v = np.column_stack([x, np.zeros_like(t)]), np.column_stack([v, np.zeros_like(t)])
    for cam, max_error in ((Camera(3.0, 0.9), 0.2), (Camera(3.0, 0.9), None)):
        cx = cam.track(t, com, com_v if max_error else None)[:, 0]
        cam_dv = np.abs(np.diff(np.gradient(cx, t)[1:-1])).max()
        assert cam_dv < 0.15 * np.abs(np.diff(v)).max()
        if max_error:
            assert np.abs(cx - x).max() < max_error
        else:   # form (1) lags a ramp by 2 zeta v / wn
            assert (x - cx)[-fps:].mean() == pytest.approx(2 * 0.9 * 1.0 / 3.0, rel=0.05)


def test_camera_rejects_bad_parameters():
    with pytest.raises(ValueError, match="natural_frequency"):
        Camera(natural_frequency=0.0)
    with pytest.raises(ValueError, match="damping_ratio"):
        Camera(damping_ratio=float("nan"))


# drawing --------------------------------------------------------------------------------------
@pytest.mark.parametrize("angle", [0.0, 0.5])
def test_box_pixels_are_where_the_geometry_says(angle):
    model = box_model(width=0.8, height=0.4)
    q = np.array([[0.3, 0.8, angle]])
    img, scene = render(model, q, center=(0.0, 0.5))
    corners = np.array([[-0.4, -0.2], [0.4, -0.2], [0.4, 0.2], [-0.4, 0.2]])
    c, s = math.cos(angle), math.sin(angle)
    world = corners @ np.array([[c, -s], [s, c]]).T + q[0, :2]
    expect = to_pixels(scene, world)
    rows, cols = np.nonzero(mask(img, RED))
    assert len(rows) > 1000
    got = np.array([cols.min(), rows.min(), cols.max() + 1, rows.max() + 1])
    want = np.array([expect[:, 0].min(), expect[:, 1].min(), expect[:, 0].max(), expect[:, 1].max()])
    np.testing.assert_allclose(got, want, atol=2.0)   # edge line width and anti-aliasing
    # the ground line at y = 0 is drawn on the right row
    g_rows = np.nonzero(mask(img, (0.0, 1.0, 0.0)).any(axis=1))[0]
    assert abs(g_rows.mean() - to_pixels(scene, [0.0, 0.0])[0, 1]) < 2.0


def test_rotation_sense_of_an_asymmetric_shape():
    """A capsule from the COM to +0.5 m local x, turned +30 deg, points up and to the right."""
    b = ps.ModelBuilder()
    b.add_body("arm", mass=1.0, inertia=0.1, pos=(0.0, 1.0), angle=math.radians(30),
               shapes=[("capsule", (0.0, 0.0), (0.5, 0.0), 0.02)])
    model = b.compile()
    img, scene = render(model, model.q0, center=(0.0, 1.0))
    rows, cols = np.nonzero(mask(img, RED))
    tip = to_pixels(scene, [0.5 * math.cos(math.radians(30)), 1.0 + 0.5 * math.sin(math.radians(30))])[0]
    base = to_pixels(scene, [0.0, 1.0])[0]
    assert abs(cols.max() - tip[0]) < 5 and abs(rows.min() - tip[1]) < 5
    assert abs(cols.min() - base[0]) < 5 and abs(rows.max() - base[1]) < 5


def tick_columns(img, scene):
    """Pixel columns of the tick marks (blue) found in the image, sorted."""
    cols = np.nonzero(mask(img, BLUE).any(axis=0))[0]
    cols = cols[(cols > 2) & (cols < img.shape[1] - 3)]     # ticks cut by the frame edge
    groups = np.split(cols, np.flatnonzero(np.diff(cols) > 2) + 1)
    return np.array([g.mean() for g in groups if len(g)])


def test_tick_marks_move_in_the_image_when_the_body_moves():
    """The view follows the COM: the box stays put in the picture, the ticks slide backwards."""
    model = box_model()
    spacing = 0.5
    images = []
    for x in (0.0, 0.2):
        q = np.array([[x, 0.1, 0.0]])
        img, scene = render(model, q, center=None, tick_spacing=spacing)   # centred on the COM
        images.append((img, scene, x))
    (img0, sc0, _), (img1, sc1, _) = images
    t0, t1 = tick_columns(img0, sc0), tick_columns(img1, sc1)
    px_per_m = img0.shape[1] / 4.0
    # found ticks are where the spacing puts them
    x_left = 0.0 - 2.0
    want0 = (spacing * np.arange(math.ceil(x_left / spacing), math.floor(2.0 / spacing) + 1) - x_left) * px_per_m
    want0 = want0[(want0 > 3) & (want0 < img0.shape[1] - 3)]
    np.testing.assert_allclose(t0, want0, atol=1.5)
    # moved 0.2 m: every tick shifted 0.2 m to the left in the image (mod the spacing)
    shift = (t1[:, None] - t0[None, :]).ravel()
    assert np.any(np.abs(shift + 0.2 * px_per_m) < 1.5)
    assert not np.any(np.abs(shift) < 1.0)        # no tick stayed where it was
    # while the box itself stayed at the centre of the picture
    c0 = np.nonzero(mask(img0, RED))[1].mean()
    c1 = np.nonzero(mask(img1, RED))[1].mean()
    assert abs(c0 - c1) < 1.0


def test_impulse_arrows_follow_the_toggle_and_point_along_the_ground_normal():
    model = box_model()
    sim = ps.Simulator(model)
    sim.run(0.3)
    q, pts, imp = sim.state.q.copy(), sim.ws.contact_point.copy(), sim.ws.contact_impulse.copy()
    assert imp[:, 0].sum() > 0
    fig, ax = make_figure()
    scene = Scene(model, ax, view_width=3.0, style=red_style(impulse_color="#ff00ff"), show_com=False)
    scene.draw_state(q, contact_point=pts, contact_impulse=imp)
    segs = scene.impulses.get_segments()
    n_loaded = int((np.abs(imp).sum(axis=1) > 0).sum())
    assert len(segs) == 3 * n_loaded
    for shaft in segs[::3]:
        d = shaft[1] - shaft[0]
        assert d[1] > 0 and abs(d[0]) < 1e-9 * abs(d[1]) + 1e-12   # flat ground, box at rest: straight up
    # total arrow length is the weight times the scale (the impulses carry the weight)
    total = sum(np.hypot(*(s[1] - s[0])) for s in segs[::3])
    assert total == pytest.approx(model.total_mass * 9.81 * scene.impulse_scale, rel=1e-3)
    scene.show_impulses = False
    scene.draw_state(q, contact_point=pts, contact_impulse=imp)
    assert not scene.impulses.get_visible() and len(scene.impulses.get_segments()) == 0


def test_every_shape_kind_and_rods_pins_actuators_are_drawn():
    b = ps.ModelBuilder(terrain=terrain.hills([0.1], [3.0]))
    hip = b.add_point_mass("hip", mass=5.0, pos=(0.0, 1.0))
    foot = b.add_point_mass("foot", mass=0.5, pos=(0.0, 0.2))
    b.add_axial("leg", hip, foot)
    shin = b.add_body("shin", mass=1.0, inertia=0.05, pos=(0.5, 0.6), shapes=[("box", (0, 0), 0.1, 0.5, 0.2)])
    b.add_arc_contact("sole", shin, center=(0.0, -0.1), radius=0.2, span=(-2.5, -0.6),
                      vertices=[(-0.15, -0.25), (0.15, -0.25)])
    b.add_rod("rod", hip, shin, anchor_a=(0, 0), anchor_b=(0, 0.25))
    b.add_pin("p", None, shin, anchor_world=(0.5, 0.85))
    model = b.compile()
    kinds = sorted(s.kind for s in model.shapes)
    assert kinds == ["arc", "box", "circle", "circle"]
    fig, ax = make_figure()
    scene = Scene(model, ax)
    scene.draw_state(model.q0)
    assert len(scene.bodies.get_paths()) == 4
    assert len(scene.rods.get_segments()) == 1 and len(scene.actuators.get_segments()) == 1
    np.testing.assert_allclose(scene.pins.get_xydata(), [[0.5, 0.85]], atol=1e-12)
    np.testing.assert_allclose(scene.rods.get_segments()[0], [[0.0, 1.0], [0.5, 0.85]], atol=1e-12)
    # the terrain curve is the model's terrain
    x, y = scene.terrain_line.get_data()
    np.testing.assert_allclose(y, model.terrain.height(x), atol=1e-12)


def test_overlay_text_names_labels_and_picks_the_important_ones():
    model = box_model()
    fig, ax = make_figure()
    scene = Scene(model, ax, label_names={"gait": {0: "STAND", 1: "WALK"}})
    labels = {"phase": 0.123456, "gait": 1.0, "steps": 4.0, "state": 2.0}
    text = scene.overlay_text(t=1.5, speed=0.75, labels=labels)
    assert text.splitlines() == ["t =   1.500 s   v = +0.75 m/s", "gait: WALK", "state: 2"]
    scene.overlay_labels = "all"
    assert "phase: 0.123" in scene.overlay_text(labels=labels)
    scene.overlay_labels = ["steps"]
    assert scene.overlay_text(labels=labels) == "steps: 4"


# export ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def sliding_run():
    model = box_model(pos=(0.0, 0.1), vel=(1.5, 0.0), mu=0.3)
    traj = ps.Simulator(model).run(2.0, record_every=10)
    return model, traj


def count_mp4_frames(path):
    import imageio_ffmpeg
    gen = imageio_ffmpeg.read_frames(str(path))
    meta = next(gen)
    n = sum(1 for _ in gen)
    return n, meta


def test_gif_and_mp4_of_two_seconds_at_30_fps_have_60_frames(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    gif = export_animation(traj, model, tmp_path / "run.gif", fps=30, size=(3.2, 1.8), progress=False)
    mp4 = export_animation(traj, model, tmp_path / "run.mp4", fps=30, size=(3.2, 1.8), progress=False)
    with Image.open(gif) as im:
        assert im.n_frames == 60
        delays = []
        for k in range(im.n_frames):
            im.seek(k)
            delays.append(im.info["duration"])
    assert set(delays) <= {30, 40} and sum(delays) == 2000    # GIF counts in 10 ms: kept on time
    n, meta = count_mp4_frames(mp4)
    assert n == 60
    assert meta["fps"] == pytest.approx(30)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.gif", "run.mp4"]   # no leftovers
    assert gif.stat().st_mode & 0o777 == mp4.stat().st_mode & 0o777 == default_file_mode()


def test_playback_speed_samples_frames_from_the_trajectory_times(sliding_run):
    model, traj = sliding_run
    real = frame_times(traj, fps=30, speed=1.0)
    slow = frame_times(traj, fps=30, speed=0.25)
    fast = frame_times(traj, fps=30, speed=4.0)
    assert (len(real), len(slow), len(fast)) == (60, 240, 15)
    np.testing.assert_allclose(np.diff(slow), 0.25 / 30)
    np.testing.assert_allclose(np.diff(fast), 4.0 / 30)
    idx = frame_indices(traj, slow)
    assert np.abs(traj.t[idx] - slow).max() <= 0.5 * (traj.t[1] - traj.t[0]) + 1e-12
    window = frame_times(traj, fps=10, speed=0.5, start=0.5, duration=1.0)
    assert len(window) == 20 and window[0] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="outside the trajectory"):
        frame_times(traj, fps=30, start=1.5, duration=2.0)
    with pytest.raises(ValueError, match="speed"):
        frame_times(traj, fps=30, speed=0)


def test_slow_motion_gif_has_four_times_the_frames(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "slow.gif", fps=20, speed=0.25, duration=0.5,
                           size=(1.6, 0.9), dpi=50, progress=False)
    with Image.open(out) as im:
        assert im.n_frames == 40


def test_unknown_extension_and_unwritable_path_give_clear_errors(sliding_run, tmp_path):
    model, traj = sliding_run
    with pytest.raises(ValueError, match=r"'\.avi' unknown.*\.gif.*\.mp4"):
        export_animation(traj, model, tmp_path / "x.avi", progress=False)
    with pytest.raises(OSError, match="does not exist"):
        export_animation(traj, model, tmp_path / "missing" / "x.gif", progress=False)
    (tmp_path / "adir.gif").mkdir()
    with pytest.raises(OSError, match="is a folder"):
        export_animation(traj, model, tmp_path / "adir.gif", progress=False)
    if os.geteuid() != 0:   # root may write anywhere
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o500)
        with pytest.raises(OSError, match="not writable"):
            export_animation(traj, model, ro / "x.gif", progress=False)
    with pytest.raises(ValueError, match="wrong model"):
        export_animation(traj, _two_body_model(), tmp_path / "y.gif", progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir.gif"]


def _two_body_model():
    b = ps.ModelBuilder()
    b.add_point_mass("a", 1.0, pos=(0, 1))
    b.add_point_mass("b", 1.0, pos=(1, 1))
    return b.compile()


@pytest.mark.parametrize("ext", ["gif", "mp4", "html"])
def test_interrupted_export_leaves_no_half_written_file(sliding_run, tmp_path, ext):
    model, traj = sliding_run
    target = tmp_path / f"run.{ext}"
    target.write_bytes(b"old contents")

    def interrupt(done, total):
        if done == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        export_animation(traj, model, target, fps=30, size=(1.6, 0.9), dpi=50, progress=interrupt)
    assert target.read_bytes() == b"old contents"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]


def test_progress_bar_counts_every_frame(sliding_run, tmp_path, capsys, monkeypatch):
    model, traj = sliding_run
    seen = []
    export_animation(traj, model, tmp_path / "a.gif", fps=10, duration=1.0, size=(1.6, 0.9), dpi=50,
                     progress=lambda done, total: seen.append((done, total)))
    assert seen == [(k, 10) for k in range(1, 11)]
    import planarsim.progress
    monkeypatch.setattr(planarsim.progress, "stderr_is_terminal", lambda: True)  # the bar: terminals only
    export_animation(traj, model, tmp_path / "b.gif", fps=10, duration=1.0, size=(1.6, 0.9), dpi=50)
    err = capsys.readouterr().err
    assert "10/10 frames" in err and "#" * 30 in err


# html -----------------------------------------------------------------------------------------
def test_html_export_is_a_self_contained_player(sliding_run, tmp_path):
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.html", fps=15, size=(1.6, 0.9), dpi=50, progress=False)
    page = out.read_text()
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert page.count("data:image/png;base64,") == 30          # frames embedded
    assert "play_animation()" in page and 'type="range"' in page  # play button and frame slider
    assert "http://" not in page and "https://" not in page      # nothing fetched from the net
    frag = show_inline(traj, model, fps=5, size=(1.6, 0.9), dpi=50)
    html = frag.data if hasattr(frag, "data") else frag
    try:
        import IPython  # noqa: F401
        assert type(frag).__name__ == "HTML"
    except ImportError:
        assert isinstance(frag, str)  # without IPython, the HTML string itself
    assert html.count("data:image/png;base64,") == 10
    assert "<html>" not in html


def test_html_export_over_its_size_cap_is_an_error_not_a_short_page(sliding_run, tmp_path):
    model, traj = sliding_run
    with pytest.raises(ValueError, match="embed limit"):
        export_animation(traj, model, tmp_path / "big.html", fps=10, size=(1.6, 0.9), dpi=50,
                         progress=False, embed_limit_mb=0.01)
    assert list(tmp_path.iterdir()) == []


NODE_DOM_STUB = r"""
const fs = require('fs'); const vm = require('vm');
const html = fs.readFileSync(process.argv[2], 'utf8');
const els = {};
function el(id) { if (!els[id]) els[id] = {id, value: 0, max: 0, src: '', getAttribute: () => null,
                                          setAttribute: () => {}}; return els[id]; }
const sandbox = {navigator: {userAgent: 'node'}, Image: function() { this.src = ''; },
  setTimeout, setInterval, clearInterval, console,
  document: {getElementById: el}};
const form = html.match(/name="(_anim_loop_select\w+)"/)[1];
sandbox.document[form] = {state: [{value: 'once', checked: false}, {value: 'loop', checked: true},
                                   {value: 'reflect', checked: false}]};
vm.createContext(sandbox);
const scripts = [...html.matchAll(/<script[^>]*>([\s\S]*?)<\/script>/g)].map(m => m[1]);
for (const s of scripts) vm.runInContext(s, sandbox);
setTimeout(() => {
  const slider = html.match(/id="(_anim_slider\w+)"/)[1];
  const button = (title) => html.match(new RegExp(`title="${title}" aria-label="${title}" onclick="([^"]+)"`))[1];
  const autoplayed = el(slider).value;                 // nobody pressed Play: the page plays by itself
  vm.runInContext(button('Pause'), sandbox);
  const paused = el(slider).value;
  setTimeout(() => {
    const still = el(slider).value;
    vm.runInContext(button('Play'), sandbox);
    setTimeout(() => { console.log(JSON.stringify({autoplayed, paused, still, after: el(slider).value,
                                                   max: el(slider).max}));
                       process.exit(0); }, 300);
  }, 200);
}, 400);
"""


def test_html_player_script_runs_plays_by_itself_and_pauses(sliding_run, tmp_path):
    """The page's own JavaScript run in node (V8) against a minimal DOM: no script error, the
    page starts playing on its own, Pause holds the frame and Play moves it on. (Not a browser:
    see the chromium test.)"""
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed: cannot run the player's JavaScript")
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.html", fps=30, size=(1.6, 0.9), dpi=50, progress=False)
    (tmp_path / "stub.js").write_text(NODE_DOM_STUB)
    res = subprocess.run([node, str(tmp_path / "stub.js"), str(out)], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    import json
    state = json.loads(res.stdout.strip().splitlines()[-1])
    assert state["max"] == 59
    assert 3 <= state["autoplayed"] <= 59      # 33 ms per frame for 400 ms: about 12 frames
    assert state["still"] == state["paused"]
    assert state["after"] != state["paused"]


CHROMIUM_PROBE = """<script>
window.__errors = [];
window.addEventListener('error', function (e) { window.__errors.push(String(e.message)); });
</script>"""
CHROMIUM_DRIVER = """<script>
setTimeout(function () {
  var slider = document.querySelector('input.anim-slider');
  var before = slider.value;
  document.querySelector('button[title="Pause"]').click();
  setTimeout(function () {
    var out = document.createElement('pre'); out.id = 'result';
    out.textContent = 'RESULT ' + before + ' ' + slider.value + ' ERRORS ' + window.__errors.length + ' '
                      + window.__errors.join('|');
    document.body.appendChild(out);
  }, 1000);
}, 300);
</script>"""


CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "chrome")


def _find_chromium():
    return next((shutil.which(n) for n in CHROMIUM_NAMES if shutil.which(n)), None)


def chromium_or_skip():
    """Debian's chromium: found on PATH, else installed with apt-get when the test runs as root
    on Debian (the CI machines), else the test is skipped saying why."""
    exe = _find_chromium()
    if exe is not None:
        return exe
    apt = shutil.which("apt-get")
    if apt is None or not hasattr(os, "geteuid") or os.geteuid() != 0:
        pytest.skip("chromium is not installed and cannot be installed here (needs root and apt-get: "
                    "`apt-get install chromium`): the in-browser check of the HTML export did not run")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    install = [apt, "install", "-y", "-q", "--no-install-recommends", "chromium"]
    log = ""
    for cmds in ([install], [[apt, "update", "-q"], install]):
        try:
            for cmd in cmds:
                res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
                log = res.stdout[-500:] + res.stderr[-1500:]
        except (OSError, subprocess.TimeoutExpired) as exc:
            log = str(exc)
        exe = _find_chromium()
        if exe is not None:
            return exe
    pytest.skip(f"chromium could not be installed with apt-get ({log.strip()[-300:]}): the in-browser "
                "check of the HTML export did not run")


def test_html_export_plays_in_headless_chromium(sliding_run, tmp_path):
    """The exported page in a real browser (Debian's chromium, headless): it loads without a
    script error, plays by itself (the frame slider has moved before anyone presses a button)
    and Pause holds the frame."""
    exe = chromium_or_skip()
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.html", fps=30, size=(1.6, 0.9), dpi=50, progress=False)
    page = out.read_text().replace("<head>", "<head>" + CHROMIUM_PROBE, 1).replace("</body>", CHROMIUM_DRIVER + "</body>")
    out.write_text(page)
    res = subprocess.run([exe, "--headless", "--disable-gpu", "--no-sandbox", "--virtual-time-budget=5000",
                          "--dump-dom", out.as_uri()], capture_output=True, text=True, timeout=120)
    # the page's DOM after 5 s of virtual time; the driver's script text is in it too
    found = re.search(r'<pre id="result">RESULT (\S+) (\S+) ERRORS (\d+) ?([^<]*)</pre>', res.stdout)
    assert found is not None, (res.stdout[-1000:], res.stderr[-2000:])
    before, after, n_err = int(found[1]), int(found[2]), int(found[3])
    assert n_err == 0, found[4]
    assert before > 0 and after == before


# plots ----------------------------------------------------------------------------------------
def test_joint_rates_are_the_derivative_of_the_angles():
    model = pendulum_model(motor=False)
    traj = ps.Simulator(model).run(1.0, record_every=1)
    (ang, rate), = joint_series(traj, model).values()
    fd = np.gradient(ang, traj.t)
    np.testing.assert_allclose(rate[5:-5], fd[5:-5], atol=0.02 * np.abs(rate).max())
    assert np.ptp(ang) > 1.0   # it swung

    # a point-mass leg (axial actuator): segment angle from the vertical and its rate
    b = ps.ModelBuilder(gravity=(0.0, 0.0))
    hip = b.add_point_mass("hip", 1.0, pos=(0.0, 1.0), vel=(1.0, 0.0))
    foot = b.add_point_mass("foot", 1.0, pos=(0.0, 0.0))
    b.add_axial("leg", hip, foot)
    m2 = b.compile()
    tr2 = ps.Simulator(m2).run(0.5, record_every=1)
    (ang, rate), = joint_series(tr2, m2).values()
    # hip moving right over a resting foot: the leg hip->foot turns from straight down to behind
    d = tr2.q[:, 1, :2] - tr2.q[:, 0, :2]
    np.testing.assert_allclose(ang, np.arctan2(d[:, 0], -d[:, 1]), atol=1e-12)
    assert ang[-1] < -0.3
    np.testing.assert_allclose(rate[2:-2], np.gradient(ang, tr2.t)[2:-2], rtol=1e-3, atol=1e-6)


def test_cost_of_transport_of_a_box_dragged_at_constant_speed_is_mu():
    """Pushing a sliding box with F = mu m g keeps its speed; P = F v, so CoT = mu."""
    mu = 0.4
    model = box_model(pos=(0.0, 0.1), vel=(1.0, 0.0), mu=mu, push=True)
    sim = ps.Simulator(model)
    force = mu * model.total_mass * 9.81
    sim.run(0.3, u=np.array([force]))                      # settle the contact modes
    traj = sim.run(2.0, u=np.array([force]), record_every=5)
    speed = traj.com_velocity(model)[:, 0]
    assert np.ptp(speed) < 0.02 and speed.mean() > 0.5   # really dragged at constant speed
    inst, avg = cost_of_transport(traj, model)
    assert avg == pytest.approx(mu, rel=0.01)
    assert np.nanmedian(inst) == pytest.approx(mu, rel=0.01)


def test_summary_plots_save_by_extension(sliding_run, tmp_path):
    model, traj = sliding_run
    fig = plot_summary(traj, model)
    for ext, magic in (("png", b"\x89PNG"), ("svg", b"<?xml"), ("pdf", b"%PDF")):
        out = save_figure(fig, tmp_path / f"summary.{ext}")
        assert out.read_bytes()[:len(magic)] == magic
        assert out.stat().st_mode & 0o777 == default_file_mode()   # not mkstemp's owner-only mode
    # the energy panel plots the trajectory's own energies
    energy_ax = next(a for a in fig.axes if a.get_title() == "mechanical energy")
    total = next(l for l in energy_ax.get_lines() if l.get_label() == "total")
    np.testing.assert_allclose(total.get_ydata(), traj.energy(model)["total"])
    # the contact timeline covers exactly the frames in contact
    modes_ax = next(a for a in fig.axes if a.get_title() == "contact modes")
    dt_frame = traj.t[1] - traj.t[0]
    covered = sum(p.get_extents().width for coll in modes_ax.collections for p in coll.get_paths())
    assert covered == pytest.approx(dt_frame * np.count_nonzero(traj.contact_mode != 0), rel=1e-6)


def test_figure_with_unknown_extension_is_refused(sliding_run, tmp_path):
    model, traj = sliding_run
    with pytest.raises(ValueError, match=r"'\.jpeg' unknown.*\.png"):
        plot_summary(traj, model, tmp_path / "x.jpeg")
    fig = plot_summary(traj, model)
    with pytest.raises(ValueError, match="unknown"):
        save_figure(fig, tmp_path / "x")
    assert list(tmp_path.iterdir()) == []


# frame timer ----------------------------------------------------------------------------------
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


# viewer ---------------------------------------------------------------------------------------
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


# reading at a glance ---------------------------------------------------------------------------
from planarsim.render.sides import model_sides, side_of   # noqa: E402
from planarsim.render.stamps import TextStamp              # noqa: E402


@pytest.mark.parametrize("name, side", [
    ("left_thigh", "left"), ("right_shin", "right"), ("l_foot", "left"), ("r_knee", "right"),
    ("FL_calf", "left"), ("RR_thigh", "right"), ("HL_hip_motor", "left"), ("outer_leg", "outer"),
    ("inner_foot", "inner"), ("foot0", "leg 0"), ("leg1", "leg 1"), ("foot_a", "leg a"), ("leg_b", "leg b"),
    ("right_sole/2", "right"), ("hip", None), ("torso", None), ("base", None), ("spoke3", None),
    ("hub", None), ("hip_motor", None)])
def test_side_of_reads_the_leg_from_the_name(name, side):
    assert side_of(name) == side


def test_every_walker_has_its_two_legs_on_two_sides():
    import walkers
    for name in walkers.WALKERS:
        _, _, model = walkers.load(name).simulate(0.02)
        sides = {s for group in model_sides(model).values() for s in group} - {None}
        if name == "rimless-wheel":
            assert sides == set()                 # one rigid body: no legs to tell apart
        else:
            assert len(sides) == 2, (name, sides)


def _legged_model():
    b = ps.ModelBuilder(dt=1e-3)
    hip = b.add_point_mass("hip", 5.0, pos=(0.0, 1.0), radius=0.05)
    f0 = b.add_point_mass("foot_left", 0.5, pos=(-0.2, 0.05), radius=0.04)
    f1 = b.add_point_mass("foot_right", 0.5, pos=(0.2, 0.05), radius=0.04)
    b.add_axial("leg_left", hip, f0)
    b.add_axial("leg_right", hip, f1)
    return b.compile()


def test_left_and_right_legs_are_drawn_in_the_two_side_colours():
    model = _legged_model()
    fig, ax = make_figure()
    style = Style(side_colors=("#0000ff", "#ff0000"), trunk_color="#00ff00")
    scene = Scene(model, ax, view_width=2.0, style=style, show_legend=False, show_text=False, show_com=False)
    scene.draw_state(model.q0, center=(0.0, 0.5))
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int)
    blue, red = np.nonzero(mask(img, BLUE)), np.nonzero(mask(img, RED))
    mid = to_pixels(scene, [0.0, 0.5])[0, 0]
    assert len(blue[1]) > 100 and len(red[1]) > 100
    assert np.median(blue[1]) < mid < np.median(red[1])    # the left leg left, the right one right
    hip = to_pixels(scene, [0.0, 1.0])[0].round().astype(int)
    assert mask(img, (0.0, 1.0, 0.0))[hip[1], hip[0]]       # the trunk in the trunk colour
    # the override: both legs one side
    scene2 = Scene(model, make_figure()[1], sides={"foot_right": "left", "leg_right": "left"})
    assert scene2.sides["body"] == [None, "left", "left"] and scene2.side_labels == ["left"]
    with pytest.raises(ValueError, match="sides=.*'up'"):
        Scene(model, make_figure()[1], sides={"hip": "up"})


def test_ground_ticks_carry_distance_labels_at_their_places(sliding_run):
    model, traj = sliding_run
    fig, ax = make_figure()
    scene = Scene(model, ax, view_width=4.0, tick_spacing=0.5)
    assert scene.label_spacing == 1.0
    scene.draw_state(traj.q[0], center=(0.3, 0.5))
    shown = [lab for lab in scene.tick_labels if lab.get_visible()]
    texts = [lab.get_text() for lab in shown]
    assert texts == ["-1 m", "0 m", "1 m", "2 m"]      # view -1.7 .. 2.3 m; none cut by its edge
    for lab in shown:
        x = float(lab.get_text().split()[0])
        assert lab.get_position()[0] == pytest.approx(x) and lab.get_position()[1] < 0   # under the ground
    fig.canvas.draw()
    for lab in shown:                        # each label whole on the picture
        x0, y0, w, h = lab.window_box(fig.dpi)
        assert 0 <= x0 and x0 + w <= fig.canvas.get_width_height()[0] and y0 >= 0


def test_legend_names_sides_force_and_com_and_is_on_every_frame(tmp_path):
    model = _legged_model()
    traj = ps.Simulator(model).run(0.5, record_every=10)
    fig, ax = make_figure()
    scene = Scene(model, ax)
    assert [e[0] for e in scene.legend_entries()] == ["left leg", "right leg", "centre of mass"]
    from planarsim.render.animate import FrameRenderer
    r = FrameRenderer(traj, model, fps=20, size=(4.0, 2.25))
    box = None
    for k in range(len(r)):
        img = r.rgb(k).astype(int)
        x0, y0, w, h = r.scene.legend.window_box(r.fig.dpi)
        assert r.scene.legend.get_visible()
        height = img.shape[0]
        patch = img[height - (y0 + h):height - y0, x0:x0 + w]
        side0 = np.array(tuple(int(Style().side_colors[0][i:i + 2], 16) for i in (1, 3, 5)))
        assert np.any(np.all(np.abs(patch - side0) < 8, axis=2))          # the legend's left-leg patch
        assert box is None or box == (x0, y0, w, h)                        # in the same place
        box = (x0, y0, w, h)
        assert r.scene.text.get_text().startswith(f"t = {r.shown_times[k]:7.3f} s")
    assert r.shown_times[0] == 0.0


def test_artists_are_reused_from_frame_to_frame(sliding_run):
    model, traj = sliding_run
    from planarsim.render.animate import FrameRenderer
    from matplotlib.artist import Artist
    made = []
    real_init = Artist.__init__

    def counting_init(self, *a, **kw):
        made.append(type(self).__name__)
        real_init(self, *a, **kw)

    r = FrameRenderer(traj, model, fps=30)
    r.rgb(0)
    children = list(r.ax.get_children())
    Artist.__init__ = counting_init
    try:
        for k in range(1, len(r)):
            r.rgb(k)
    finally:
        Artist.__init__ = real_init
    assert made == [] and len(r) == 60
    assert r.ax.get_children() == children


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


def test_ten_second_walk_gif_is_at_most_one_megabyte(tmp_path):
    """The command line's default animation (640x360, 20 fps) of a 10 s Simple Biped walk."""
    import walkers
    from PIL import Image
    from walkers.gallery import gait_names
    mod = walkers.load("simple-biped")
    traj, _, model = mod.simulate(duration=10.0)
    out = export_animation(traj, model, tmp_path / "walk.gif", fps=20, progress=False,
                           label_names=gait_names(mod))
    assert out.stat().st_size <= 1_000_000
    with Image.open(out) as im:
        assert im.n_frames == 200 and im.size == (640, 360)
        im.seek(150)
        frame = np.asarray(im.convert("RGB")).astype(int)
    assert np.count_nonzero(np.any(frame < 200, axis=2)) > 2000        # a picture, not a blank


def test_frames_drawn_on_two_processes_equal_those_drawn_on_one(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    one = export_animation(traj, model, tmp_path / "one.gif", fps=30, size=(3.2, 1.8), progress=False, workers=1)
    two = export_animation(traj, model, tmp_path / "two.gif", fps=30, size=(3.2, 1.8), progress=False, workers=2)
    with Image.open(one) as a, Image.open(two) as b:
        assert a.n_frames == b.n_frames == 60
        for k in range(60):
            a.seek(k)
            b.seek(k)
            assert np.array_equal(np.asarray(a.convert("RGB")), np.asarray(b.convert("RGB"))), k


def test_a_frame_error_in_a_worker_reaches_the_caller_and_leaves_nothing(sliding_run, tmp_path, monkeypatch):
    from planarsim.render import frames
    model, traj = sliding_run
    real = frames.FrameRenderer.draw

    def broken(self, k):
        if k == 50:
            raise ValueError("frame 50 is broken")
        return real(self, k)

    monkeypatch.setattr(frames.FrameRenderer, "draw", broken)
    with pytest.raises(ValueError, match="frame 50 is broken"):
        export_animation(traj, model, tmp_path / "x.gif", fps=30, size=(1.6, 0.9), dpi=50, progress=False,
                         workers=2)
    assert list(tmp_path.iterdir()) == []


def test_summary_plot_has_title_position_and_speed(sliding_run):
    import dataclasses
    model, traj = sliding_run
    traj = dataclasses.replace(traj, info={**traj.info, "walker": "box"})
    fig = plot_summary(traj, model)
    assert fig._suptitle.get_text() == "box on flat terrain"
    speed_ax = next(a for a in fig.axes if a.get_title() == "centre of mass: forward speed")
    line = speed_ax.get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), traj.com_velocity(model)[:, 0])
    pos_ax = next(a for a in fig.axes if a.get_title() == "centre of mass: position")
    dist = pos_ax.get_lines()[0].get_ydata()
    # slid from 1.5 m/s to rest at mu g: v^2 / (2 mu g) = 0.38 m from its start (frame 0)
    assert dist[0] == 0.0 and dist[-1] == pytest.approx(1.5 ** 2 / (2 * 0.3 * 9.81), abs=2e-3)
    assert "slope:3" in plot_summary(traj, model, title="box on slope:3 terrain")._suptitle.get_text()


def test_gif_keeps_the_background_and_ground_colours_exact(sliding_run, tmp_path):
    from PIL import Image
    model, traj = sliding_run
    out = export_animation(traj, model, tmp_path / "run.gif", fps=10, size=(3.2, 1.8), progress=False)
    style = Style()
    with Image.open(out) as im:
        im.seek(5)
        rgb = np.asarray(im.convert("RGB"))
    colours = {tuple(int(c) for c in px) for px in rgb.reshape(-1, 3)}
    assert (255, 255, 255) in colours                                     # white stays white
    ground = tuple(int(style.ground_fill[i:i + 2], 16) for i in (1, 3, 5))
    assert ground in colours


KILLED_EXPORTER = """
import multiprocessing, sys
import numpy as np
import planarsim as ps
from planarsim.render import export_animation
b = ps.ModelBuilder(dt=1e-3)
box = b.add_body("box", mass=2.0, inertia=0.1, pos=(0.0, 0.1), vel=(1.0, 0.0))
b.add_box_contacts("corner", box, (0.0, 0.0), 0.8, 0.2, mu=0.3)
model = b.compile()
traj = ps.Simulator(model).run(2.0, record_every=10)

def progress(done, total):
    if done == 5:
        pids = [p.pid for p in multiprocessing.active_children()]
        print("exporting", *pids, flush=True)
        import time
        time.sleep(60)

export_animation(traj, model, sys.argv[1], fps=100, progress=progress, workers=2)
"""


def _gone(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            return "\nState:\tZ" in f.read()      # a zombie has ended
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not hasattr(os, "fork") or not Path("/proc").is_dir(), reason="fork, /proc")
def test_sigkill_mid_export_leaves_nothing_and_no_drawing_processes(tmp_path):
    import signal
    import sys
    import tempfile
    import time
    target = tmp_path / "run.gif"
    proc = subprocess.Popen([sys.executable, "-c", KILLED_EXPORTER, str(target)], stdout=subprocess.PIPE, text=True)
    words = proc.stdout.readline().split()
    assert words[:1] == ["exporting"], words
    workers = [int(w) for w in words[1:]]
    assert len(workers) == 2
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert os.listdir(tmp_path) == []
    deadline = time.monotonic() + 20
    while not all(_gone(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert all(_gone(pid) for pid in workers)        # the workers ended with their parent
    traj, model = _tiny_run()
    export_animation(traj, model, target, fps=5, progress=False)       # the next write cleans up
    left = [n for n in os.listdir(tempfile.gettempdir()) if n.startswith(f"planarsim-{proc.pid}-")]
    assert left == [] and sorted(os.listdir(tmp_path)) == ["run.gif"]


def _tiny_run():
    model = box_model()
    return ps.Simulator(model).run(0.5, record_every=10), model


def test_an_error_while_writing_ends_the_drawing_processes_at_once(sliding_run, tmp_path):
    import multiprocessing
    model, traj = sliding_run
    with pytest.raises(ValueError, match="embed limit") as caught:
        export_animation(traj, model, tmp_path / "big.html", fps=30, size=(1.6, 0.9), dpi=50,
                         progress=False, embed_limit_mb=0.01, workers=2)
    assert caught.value is not None                    # the traceback is still held here
    assert multiprocessing.active_children() == []
    assert list(tmp_path.iterdir()) == []
