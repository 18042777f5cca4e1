"""Shapes that collide: stacks held exactly, impacts, restitution, no tunnelling, filtering,
and the builder's checks of shapes."""
import math

import numpy as np
import pytest
from numba import njit

import planarsim as ps
from planarsim.compile import options as compile_options
from planarsim.compiled import audit_counts
from planarsim.errors import ModelError
from planarsim.kernels.codes import CONTACT_EDGE
from planarsim.kernels.geometry.contacts import edge_deepest
from planarsim.kernels.math2d import update_trig

W, H = 0.4, 0.2     # box width, height [m]


def box_inertia(mass, w, h):
    return mass * (w * w + h * h) / 12.0


def column(masses, dt=1e-3, gap=0.0, mu=0.6, x_offsets=None):
    """Boxes W x H stacked on flat ground, bottom first, `gap` [m] apart."""
    b = ps.ModelBuilder(dt=dt)
    for k, mass in enumerate(masses):
        x = 0.0 if x_offsets is None else x_offsets[k]
        b.add_body(f"box{k}", mass, box_inertia(mass, W, H), pos=(x, H / 2 + k * (H + gap)),
                   shapes=[("box", (0.0, 0.0), W, H, {"mu": mu})])
    return b.compile()


def assert_clean(sim):
    counts = audit_counts(sim.ws)
    assert all(v == 0 for v in counts.values()), counts


@pytest.mark.parametrize("masses", [[1.0] * 10, [1.0, 100.0] * 5, [1.0] * 9 + [100.0]],
                         ids=["equal", "alternating_1_100", "heavy_on_top"])
def test_column_of_ten_boxes_stands_exactly(masses):
    model = column(masses)
    sim = ps.Simulator(model)
    q0 = sim.state.q.copy()
    sim.steps(10000)     # 10 s
    assert_clean(sim)    # no overlap deeper than 1e-8 m at the end of any step, no pull, no work
    drift = np.abs(sim.state.q - q0).max()
    assert drift <= 1e-9, drift
    # every box rests on the one below: tops at (k + 1) H
    tops = sim.state.q[:, 1] + H / 2
    np.testing.assert_allclose(tops, H * np.arange(1, len(masses) + 1), atol=1e-9)


def test_pyramid_of_twenty_boxes_stands():
    b = ps.ModelBuilder(dt=1e-3)
    rows = [6, 5, 4, 3, 2]
    k = 0
    for level, n in enumerate(rows):
        for j in range(n):
            x = (j - (n - 1) / 2) * (W + 0.02)
            b.add_body(f"box{k}", 1.0, box_inertia(1.0, W, H), pos=(x, H / 2 + level * H),
                       shapes=[("box", (0.0, 0.0), W, H)])
            k += 1
    model = b.compile()
    assert model.n_body == 20
    sim = ps.Simulator(model)
    q0 = sim.state.q.copy()
    sim.steps(10000)
    assert_clean(sim)
    assert np.abs(sim.state.q - q0).max() <= 1e-9


@pytest.mark.parametrize("strategy", ["alternating", "all"])
def test_two_boxes_dropped_stack_at_the_right_height(strategy):
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("low", 2.0, box_inertia(2.0, W, H), pos=(0.0, 0.5), shapes=[("box", (0, 0), W, H)])
    b.add_body("high", 1.0, box_inertia(1.0, 0.2, 0.1), pos=(0.05, 1.2),
               shapes=[("box", (0, 0), 0.2, 0.1)])
    sim = ps.Simulator(b.compile(), ps.make_options(strategy))
    sim.steps(3000)
    assert_clean(sim)
    q = sim.state.q
    assert abs(q[0, 1] - H / 2) < 1e-8
    assert abs(q[1, 1] - (H + 0.05)) < 1e-8
    assert abs(q[0, 2]) < 1e-6 and abs(q[1, 2]) < 1e-6
    assert np.abs(sim.state.v).max() < 1e-6


def test_box_sliding_down_a_tilted_plank_stops_against_a_box():
    slope = math.radians(25.0)
    L, T = 4.0, 0.1                      # a static plank, tilted down to the right
    origin = np.array([0.0, 1.0])
    t = np.array([math.cos(slope), -math.sin(slope)])     # down the plank
    n = np.array([math.sin(slope), math.cos(slope)])      # its upper face's normal

    def on_plank(u, half_height):
        return tuple(origin + u * t + (T / 2 + half_height) * n)

    b = ps.ModelBuilder(dt=1e-3)
    b.add_shape(None, "box", tuple(origin), L, T, -slope, mu=1.0)
    # the stop holds by friction (pair mu 1 > tan 25 deg); the slider slides (0.2 < 0.47)
    b.add_body("stop", 50.0, box_inertia(50.0, 0.3, 0.5), pos=on_plank(1.0, 0.25),
               angle=-slope, shapes=[("box", (0, 0), 0.3, 0.5, {"mu": 1.0})])
    b.add_body("slider", 1.0, box_inertia(1.0, 0.2, 0.2), pos=on_plank(-1.0, 0.1),
               angle=-slope, shapes=[("box", (0, 0), 0.2, 0.2, {"mu": 0.04})])
    model = b.compile()
    sim = ps.Simulator(model)
    sim.steps(4000)
    assert_clean(sim)
    assert np.abs(sim.state.v).max() < 1e-6        # everything at rest
    slider = sim.state.q[model.body("slider"), :2]
    stop = sim.state.q[model.body("stop"), :2]
    # the slider rests against the stop's uphill face: centres 0.15 + 0.1 m apart along t
    assert abs((stop - slider) @ t - 0.25) < 1e-8
    assert abs((slider - origin) @ n - (T / 2 + 0.1)) < 1e-8     # on the plank, not in it


@pytest.mark.parametrize("e", [0.3, 0.5, 0.8])
def test_disk_rebounds_to_e_squared_of_its_height(e):
    h0 = 1.0
    r = 0.1
    b = ps.ModelBuilder(dt=1e-4)
    b.add_body("disk", 1.0, 0.5 * r * r, pos=(0.0, r + h0),
               shapes=[("circle", (0, 0), r, {"restitution": e})])
    sim = ps.Simulator(b.compile())
    t_fall = math.sqrt(2 * h0 / 9.81)
    sim.steps(int(t_fall / 1e-4) + 50)
    assert sim.state.v[0, 1] > 0          # on its way up
    best = 0.0
    for _ in range(int(1.5 * t_fall / 1e-4)):
        sim.step()
        best = max(best, sim.state.q[0, 1] - r)
    assert abs(best - e * e * h0) <= 0.01 * e * e * h0, best
    assert_clean(sim)


def test_fast_box_does_not_pass_through_a_thin_plank():
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    b.add_shape(None, "box", (0.0, 0.0), 1.0, 0.05)
    b.add_body("box", 1.0, box_inertia(1.0, 0.1, 0.1), pos=(0.0, 0.5), vel=(0.0, -20.0),
               shapes=[("box", (0, 0), 0.1, 0.1)])
    sim = ps.Simulator(b.compile())
    sim.steps(200)
    assert_clean(sim)
    assert sim.state.q[0, 1] >= 0.025 + 0.05 - 1e-8


def test_pinned_bodies_do_not_collide_unless_enabled():
    def build(enable):
        b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
        a = b.add_body("a", 1.0, 0.1, pos=(0.0, 1.0), shapes=[("box", (0, 0), 0.4, 0.4)])
        c = b.add_body("c", 1.0, 0.1, pos=(0.3, 1.0), shapes=[("box", (0, 0), 0.4, 0.4)])
        b.add_pin("p", a, c, anchor_world=(0.15, 1.0))
        if enable:
            b.enable_collision("a", "c")
        return b.compile()
    assert not any("|" in n for n in build(False).contact_names)
    assert sum("|" in n for n in build(True).contact_names) == 2


def test_category_and_mask_filter_pairs():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("a", 1.0, 0.1, pos=(0.0, 1.0), shapes=[("circle", (0, 0), 0.1, {"category": 2})])
    b.add_body("c", 1.0, 0.1, pos=(0.0, 2.0), shapes=[("circle", (0, 0), 0.1, {"mask": 1})])
    b.add_body("d", 1.0, 0.1, pos=(0.0, 3.0), shapes=[("circle", (0, 0), 0.1)])
    names = b.compile().contact_names
    pairs = {n.split("/")[0] for n in names if "|" in n}
    assert pairs == {"a.circle0|d.circle2", "c.circle1|d.circle2"}


def test_shape_drawn_only_has_no_contacts():
    b = ps.ModelBuilder()
    b.add_body("a", 1.0, 0.1, shapes=[("box", (0, 0), 0.4, 0.4, {"collide": False})])
    assert b.compile().n_contact == 0


@pytest.mark.parametrize("kind,params,words", [
    ("box", ((0, 0), 0.0, 1.0), "width=0.0 must be > 0"),
    ("box", ((0, 0), 1.0, -1.0), "height=-1.0 must be > 0"),
    ("circle", ((0, 0), 0.0), "radius=0.0 must be > 0"),
    ("capsule", ((0, 0), (1, 0), -0.1), "radius=-0.1 must be >= 0"),
    ("polygon", ([(0, 0), (1, 0)],), "at least 3 vertices"),
    ("polygon", ([(0, 0), (2, 0), (1, 0.2), (1, 1)],), "not convex"),
    ("polygon", ([(0, 0), (1, 0), (2, 0), (1, 1)],), "on the line"),
])
def test_bad_shapes_are_model_errors(kind, params, words):
    b = ps.ModelBuilder()
    b.add_body("a", 1.0, 0.1)
    with pytest.raises(ModelError, match=words):
        b.add_shape("a", kind, *params)


def test_shape_on_a_missing_body_and_bad_mask():
    b = ps.ModelBuilder()
    b.add_body("a", 1.0, 0.1)
    with pytest.raises(ModelError, match="names no body"):
        b.add_shape("nobody", "circle", (0, 0), 0.1)
    with pytest.raises(ModelError, match="not a body id"):
        b.add_shape(7, "circle", (0, 0), 0.1)
    with pytest.raises(ModelError, match="mask=1.5 must be a non-negative integer"):
        b.add_shape("a", "circle", (0, 0), 0.1, mask=1.5)
    with pytest.raises(ModelError, match="restitution=2.0"):
        b.add_shape("a", "circle", (0, 0), 0.1, restitution=2.0)


def test_clockwise_polygon_is_accepted_and_collides():
    b = ps.ModelBuilder(dt=1e-3)
    tri = [(-0.2, -0.1), (0.0, 0.2), (0.2, -0.1)]     # clockwise
    b.add_body("tri", 1.0, 0.01, pos=(0.0, 0.5), shapes=[("polygon", tri)])
    sim = ps.Simulator(b.compile())
    sim.steps(2000)
    assert_clean(sim)
    assert abs(sim.state.q[0, 1] - 0.1) < 1e-8       # rests on its flat side


@pytest.mark.parametrize("kind,params", [("box", ((0, 0), 1.0, 0.1)),
                                         ("capsule", ((-0.5, 0), (0.5, 0), 0.05))])
def test_long_shape_rests_on_a_crest_without_sinking_into_it(kind, params):
    """A 1 m long box or capsule dropped flat onto the crest of a hill (radius of curvature
    1.3 m): its corners or end circles hang in the air, the middle of its lower side carries it."""
    from planarsim import terrain
    from planarsim.kernels.checks.audit import DEPTH_TOL
    ground = terrain.hills([0.3], [4.0], [math.pi / 2])      # crest at x = 0, height 0.3
    b = ps.ModelBuilder(dt=1e-3, terrain=ground)
    b.add_body("plank", 2.0, 2.0 / 12, pos=(0.0, 0.42), shapes=[(kind, *params)])
    model = b.compile()
    sim = ps.Simulator(model)
    sim.steps(3000)
    assert_clean(sim)
    x, y, th = sim.state.q[0]
    # the lowest point of the lower side over the crest is 0.05 m below the body's centre
    xs = np.linspace(-0.5, 0.5, 2001)
    c, s = math.cos(th), math.sin(th)
    px = x + c * xs + s * 0.05
    py = y + s * xs - c * 0.05
    clearance = py - np.array([ground.height(v) for v in px])
    assert clearance.min() > -DEPTH_TOL            # nowhere inside the hill
    assert clearance.min() < 1e-6                   # resting on it, not hovering
    assert abs(x) < 0.05 and abs(th) < 0.05         # balanced on the crest


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("ratio", [1.0, 7.0, 1000.0])
def test_head_on_disks_follow_newtons_law_of_restitution(e, ratio):
    """Two disks in free space meet head on: momentum is kept and the separation speed is e
    times the approach speed (1-D impact law), for mass ratios to 1000."""
    m1, m2 = 1.0, ratio
    v1, v2 = 3.0, -1.0
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    # 1 m up: in free space, clear of the ground (at y = 0 they started half inside it)
    b.add_body("a", m1, 0.5 * m1 * 0.01, pos=(-0.5, 1.0), vel=(v1, 0.0),
               shapes=[("circle", (0, 0), 0.1, {"restitution": e, "mu": 0.0})])
    b.add_body("b", m2, 0.5 * m2 * 0.01, pos=(0.5, 1.0), vel=(v2, 0.0),
               shapes=[("circle", (0, 0), 0.1, {"restitution": e, "mu": 0.0})])
    sim = ps.Simulator(b.compile())
    sim.steps(500)
    assert_clean(sim)
    u1, u2 = sim.state.v[0, 0], sim.state.v[1, 0]
    p = m1 * v1 + m2 * v2
    assert abs(m1 * u1 + m2 * u2 - p) <= 1e-9 * (abs(p) + m2)
    assert abs((u2 - u1) - e * (v1 - v2)) <= 1e-9 * abs(v1 - v2)
    assert np.abs(sim.state.v[:, 1:]).max() < 1e-12          # nothing off the line


def test_a_pile_resumes_bit_for_bit_from_a_snapshot():
    """A falling pile: snapshot mid-way, run on, restore, run again: the same bits (the shape
    pairs' features are part of the State)."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from benchmarks.scenes import box_drop
    model = box_drop()
    sim = ps.Simulator(model)
    sim.steps(400)
    snap = sim.state.copy()
    sim.steps(400)
    first = sim.state.copy()
    sim.state.restore(snap)
    sim.steps(400)
    for a, b in zip(first, sim.state):
        assert np.array_equal(a, b)


def test_shape_contacts_are_recorded_with_their_normals_and_drawn_along_them():
    """A box slides into another sideways (no gravity): the pair's contacts are recorded with a
    horizontal normal and impulse, and the picture's arrows are horizontal too."""
    import matplotlib
    matplotlib.use("Agg")
    from planarsim.render import make_figure
    from planarsim.render.draw import Scene
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0))
    b.add_body("left", 1.0, 0.05, pos=(0.0, 1.0), vel=(2.0, 0.0), shapes=[("box", (0, 0), 0.4, 0.4)])
    b.add_body("right", 1.0, 0.05, pos=(1.0, 1.0), shapes=[("box", (0, 0), 0.4, 0.4)])
    model = b.compile()
    traj = ps.Simulator(model).run(0.5, record_every=1)
    pair = [i for i, n in enumerate(model.contact_names) if "|" in n]
    hit = [(k, i) for k in range(len(traj.t)) for i in pair if traj.contact_impulse[k, i, 0] > 0]
    assert hit                                   # the boxes met
    for k, i in hit:
        assert abs(abs(traj.contact_normal[k, i, 0]) - 1.0) < 1e-12
        assert abs(traj.contact_normal[k, i, 1]) < 1e-12
    fig, ax = make_figure()
    scene = Scene(model, ax)
    k = hit[0][0]
    segs = scene.impulse_segments(traj.contact_point[k], traj.contact_impulse[k],
                                  normals=traj.contact_normal[k])
    shaft = segs[0]
    assert abs(shaft[1, 1] - shaft[0, 1]) < 1e-9 * abs(shaft[1, 0] - shaft[0, 0])
    # momentum is kept through the plastic impact: they move on together at 1 m/s
    np.testing.assert_allclose(traj.v[-1, :, 0], [1.0, 1.0], atol=1e-9)


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_disk_rolls_on_a_box_at_constant_speed_without_slipping(dt):
    """A disk (r = 0.1 m, 1 kg, I = m r^2 / 2) rolling at 1 m/s on a box's flat top: rolling
    without slipping is motion at constant v and omega = -v / r, so after 1 s it has rolled
    1 m. The pair's tangent row holds the material points that touched at the step's start:
    a roll of phi = h omega per step leaves r (phi - sin phi) <= r phi^3 / 6 of slip for the
    correction to take back, so the disk ends within n r phi^3 / 6 of 1 m (a row holding the
    surface point instead pulled it back by r phi every step, and lifted it)."""
    r, speed = 0.1, 1.0
    b = ps.ModelBuilder(dt=dt)
    b.add_body("disk", 1.0, 0.5 * r * r, pos=(0.0, 0.5 + r), vel=(speed, 0.0), omega=-speed / r)
    b.add_shape("disk", "circle", (0.0, 0.0), r, mu=1.0)
    b.add_shape(None, "box", (0.0, 0.25), 20.0, 0.5, mu=1.0)
    model = b.compile()
    sim = ps.Simulator(model)
    steps = int(round(1.0 / dt))
    sim.run(n_steps=steps, record_every=steps)
    q, v = sim.state.q[0], sim.state.v[0]
    phi = dt * speed / r
    assert abs(q[0] - speed * steps * dt) <= steps * r * phi ** 3 / 6.0, q
    assert abs(q[1] - (0.5 + r)) < 1e-9, q
    # taking r phi^3 / 6 back over a step changes the speed by v phi^2 / 6
    assert abs(v[0] - speed) <= speed * phi ** 2 / 6.0, v
    assert abs(v[2] + speed / r) <= speed / r * phi ** 2 / 6.0, v
    assert sum(audit_counts(sim.ws).values()) == 0


def test_a_disk_rolling_on_a_box_does_not_slip_at_any_step():
    """The rolling bound above is loose: the sticking contact's tangent row counts the arc
    the disk's round side rolled (pair.pair_row), so the disk's centre travels exactly r
    times its turn, to rounding, at every step from 10 ms to 1 ms, as on the ground. Its row
    held the material point that touched at the step's start before: a step that turned the
    disk by phi moved its centre by the chord r sin(phi) while the rim unrolled the arc
    r phi, a slip of n r (phi - sin phi) after n steps (1.7e-3 m in 1 s at 10 ms), which
    the correction turned into velocity (a disk rolling down a static incline spun faster
    than it rolled and gained energy)."""
    r, speed = 0.1, 1.0
    for dt in (1e-2, 5e-3, 2.5e-3, 1.25e-3, 1e-3):
        b = ps.ModelBuilder(dt=dt)
        b.add_body("disk", 1.0, 0.5 * r * r, pos=(0.0, 0.5 + r), vel=(speed, 0.0), omega=-speed / r)
        b.add_shape("disk", "circle", (0.0, 0.0), r, mu=1.0)
        b.add_shape(None, "box", (0.0, 0.25), 20.0, 0.5, mu=1.0)
        sim = ps.Simulator(b.compile())
        steps = int(round(1.0 / dt))
        sim.run(n_steps=steps, record_every=steps)
        x, turn = sim.state.q[0, 0], sim.state.q[0, 2]
        assert abs(x + r * turn) <= 1e-12, (dt, x + r * turn)   # the centre's travel less the arc
        assert abs(sim.state.v[0, 0] - speed) <= 1e-12 and abs(sim.state.v[0, 2] + speed / r) <= 1e-11
        assert sum(audit_counts(sim.ws).values()) == 0


@pytest.mark.parametrize("n", [3, 12, 30])
def test_a_flush_box_column_settles_with_linear_solves_and_keeps_its_corner_names(n):
    """N boxes of one width stacked flush: their corners sit on the side lines of the faces
    below, where rounding could clip or keep them. Their contacts keep their names (feature
    ids) from step to step, and the column settles engaging one level per linear solve,
    never needing the complementarity solve; it stays put to 1e-9 m with no audit count."""
    from benchmarks.scenes import box_column
    from planarsim.compiled import step_info
    model = box_column(n)
    sim = ps.Simulator(model)
    lcp_steps = 0
    features = None
    for k in range(300):
        sim.step()
        lcp_steps += step_info(sim.ws)["lcp_solves"] > 0
        if k == 5:
            features = sim.state.contact_feature.copy()
    assert lcp_steps == 0
    assert np.array_equal(sim.state.contact_feature, features)
    assert np.max(np.abs(sim.state.q - model.q0)) <= 1e-9
    assert sum(audit_counts(sim.ws).values()) == 0


@njit(**dict(compile_options(), cache=False))
def _edge_deepest(m, q, cs, i):
    update_trig(q, cs)
    return edge_deepest(m, q, cs, i)


def test_a_capsules_side_finds_its_deepest_point_where_the_curvature_at_its_foot_turns(
        monkeypatch):
    """Stress corpus shape_hills seed 35 at its extreme ranges: a 43 kg capsule (r = 7.3 cm)
    sliding over hills at 26 m/s, at the configuration of its step 651. Its side's clearance
    dips to -9.5e-8 m at 0.9 of its core from one end, between a rise and its end. Near an
    inflection the dip is where the curvature at the foot of the side's normal turns, up to
    r sin(slope) aside of the core; the rate search cut the side under the core and missed it,
    the sampled search missed it next to the end, and one step had left the side inside the
    hill with nothing counted. The edge contact now finds the dip, to 1e-12 m of the lowest
    clearance sampled every 17 um apart from the engine."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    import benchmarks.contact_stress as corpus
    for key, value in corpus.EXTREME_SHAPE_RANGES.items():
        monkeypatch.setitem(corpus.SHAPE_RANGES, key, value)
    model, _, q0, _ = corpus.build("shape_hills", 35)
    a = model.arrays
    q = q0.copy()
    q[0] = (0.297554234060498, 0.13338907063268585, -8.932737903186709)
    edge = [i for i in range(model.n_contact)
            if a.contact_body[i] == 0 and a.contact_kind[i] == CONTACT_EDGE]
    assert len(edge) == 1 and a.contact_radius[edge[0]] > 0.0       # the capsule's side
    inside, px, py = _edge_deepest(a, q, np.full((q.shape[0], 3), np.nan), edge[0])
    r = a.shape_radius[0]
    core = a.core_vert[a.shape_vert_adr[0]:a.shape_vert_adr[0] + 2]
    local = core[0] + (core[1] - core[0]) * np.linspace(0.0, 1.0, 20001)[:, None]
    x, y, th = q[0]
    wx = x + math.cos(th) * local[:, 0] - math.sin(th) * local[:, 1]
    wy = y + math.sin(th) * local[:, 0] + math.cos(th) * local[:, 1]
    sampled = corpus.ground_distance(model.terrain, wx, wy) - r
    assert sampled.min() < -5e-8                                     # the dip is there
    found = corpus.ground_distance(model.terrain, np.array([px]), np.array([py]))[0] - r
    assert inside and found <= sampled.min() + 1e-12, (inside, found, sampled.min())
