"""Drawing a state (planarsim/render/draw.py): shapes, ticks, arrows, overlay text and side
colours where the geometry says."""

import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import terrain
from planarsim.render import Scene, Style, make_figure
from tests.render.helpers import RED, BLUE, box_model, red_style, render, to_pixels, mask, _legged_model


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
