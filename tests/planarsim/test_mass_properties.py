"""Mass, centre of mass and inertia from shapes and a density (planarsim.shapes.mass_properties,
add_body(density=...), add_shape(density=...)), against analytic answers."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import planarsim as ps
from planarsim import ModelError
from planarsim.shapes import mass_properties

RHO = 7.5   # [kg/m^2]


def test_disk():
    m, c, i = mass_properties([("circle", (0.3, -0.2), 0.1)], RHO)
    assert m == pytest.approx(RHO * math.pi * 0.01, rel=1e-15)
    assert c.tolist() == [0.3, -0.2]
    assert i == pytest.approx(m * 0.1 ** 2 / 2, rel=1e-15)


@pytest.mark.parametrize("angle", [0.0, 0.4, -2.0])
def test_box(angle):
    m, c, i = mass_properties([("box", (1.0, 2.0), 0.4, 0.1, angle)], RHO)
    assert m == pytest.approx(RHO * 0.04, rel=1e-15)
    assert c.tolist() == [1.0, 2.0]
    assert i == pytest.approx(m * (0.4 ** 2 + 0.1 ** 2) / 12, rel=1e-14)


def test_capsule():
    """A rectangle L x 2r plus two half disks; the half disks' second moment about the centre
    integrated directly: pi r^2 (L^2/4 + r^2/2) + 4 L r^3 / 3."""
    p0, p1, r = np.array([0.1, 0.2]), np.array([0.5, -0.1]), 0.07
    length = math.hypot(*(p1 - p0))
    m, c, i = mass_properties([("capsule", tuple(p0), tuple(p1), r)], RHO)
    assert m == pytest.approx(RHO * (2 * r * length + math.pi * r * r), rel=1e-15)
    assert c == pytest.approx(0.5 * (p0 + p1), abs=1e-16)
    j = (2 * r * length * (length ** 2 + 4 * r ** 2) / 12
         + math.pi * r ** 2 * (length ** 2 / 4 + r ** 2 / 2) + 4 * length * r ** 3 / 3)
    assert i == pytest.approx(RHO * j, rel=1e-14)
    # the same capsule as a polygon of 4000 vertices on its outline: O(n^-2) close
    n = 2000
    ang = math.atan2(*(p1 - p0)[::-1])
    a0 = ang + np.linspace(-math.pi / 2, math.pi / 2, n)
    a1 = ang + np.linspace(math.pi / 2, 3 * math.pi / 2, n)
    outline = np.vstack([p1 + r * np.c_[np.cos(a0), np.sin(a0)], p0 + r * np.c_[np.cos(a1), np.sin(a1)]])
    mp, cp, ip = mass_properties([("polygon", outline)], RHO)
    assert mp == pytest.approx(m, rel=1e-5) and ip == pytest.approx(i, rel=1e-5)
    assert cp == pytest.approx(c, abs=1e-9)


def test_triangle():
    """Polar moment about the centroid m (a^2 + b^2 + c^2) / 36 (a, b, c its sides)."""
    v = np.array([(0.0, 0.0), (0.9, 0.1), (0.2, 0.5)])
    m, c, i = mass_properties([("polygon", v)], RHO)
    sides2 = np.sum((v - np.roll(v, 1, axis=0)) ** 2)
    e1, e2 = v[1] - v[0], v[2] - v[0]
    area = 0.5 * abs(e1[0] * e2[1] - e1[1] * e2[0])
    assert m == pytest.approx(RHO * area, rel=1e-14)
    assert c == pytest.approx(v.mean(axis=0), abs=1e-15)
    assert i == pytest.approx(m * sides2 / 36, rel=1e-13)


def test_composite_by_the_parallel_axis_theorem():
    """A hammer: a 0.6 x 0.04 handle and a 0.1 x 0.2 head at its end, and a disk."""
    parts = [("box", (0.0, 0.0), 0.6, 0.04), ("box", (0.35, 0.0), 0.1, 0.2), ("circle", (-0.3, 0.1), 0.05)]
    m, c, i = mass_properties(parts, RHO)
    ms = [RHO * 0.6 * 0.04, RHO * 0.1 * 0.2, RHO * math.pi * 0.05 ** 2]
    cs = [np.array([0.0, 0.0]), np.array([0.35, 0.0]), np.array([-0.3, 0.1])]
    js = [ms[0] * (0.36 + 0.0016) / 12, ms[1] * (0.01 + 0.04) / 12, ms[2] * 0.05 ** 2 / 2]
    cm = sum(mk * ck for mk, ck in zip(ms, cs)) / sum(ms)
    assert m == pytest.approx(sum(ms), rel=1e-15)
    assert c == pytest.approx(cm, abs=1e-15)
    assert i == pytest.approx(sum(j + mk * np.sum((ck - cm) ** 2) for j, mk, ck in zip(js, ms, cs)),
                              rel=1e-14)
    # two boxes side by side are one box
    m2, c2, i2 = mass_properties([("box", (-0.1, 0.0), 0.2, 0.3), ("box", (0.2, 0.0), 0.4, 0.3)], RHO)
    assert (m2, *c2, i2) == pytest.approx((RHO * 0.18, 0.1, 0.0, RHO * 0.18 * (0.36 + 0.09) / 12),
                                          rel=1e-14, abs=1e-15)


def test_per_shape_densities():
    m, c, i = mass_properties([("circle", (0, 0), 0.1), ("circle", (1, 0), 0.1)], [1.0, 3.0])
    assert c == pytest.approx([0.75, 0.0], abs=1e-15)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_bad_density(bad):
    with pytest.raises(ModelError, match="density"):
        mass_properties([("circle", (0, 0), 0.1)], bad)


@st.composite
def convex_polygons(draw):
    n = draw(st.integers(3, 9))
    angles = sorted(draw(st.lists(st.floats(0.0, 2 * math.pi), min_size=n, max_size=n,
                                  unique=True)))
    gaps = np.diff(np.r_[angles, angles[0] + 2 * math.pi])
    if gaps.min() < 0.05 or gaps.max() > math.pi - 0.05:    # distinct, the centre inside
        angles = list(np.linspace(0.0, 2 * math.pi, n, endpoint=False) + angles[0])
    radius = draw(st.floats(0.05, 3.0))
    return radius * np.c_[np.cos(angles), np.sin(angles)] * [1.0, draw(st.floats(0.3, 1.0))]


@settings(max_examples=200, deadline=None)
@given(v=convex_polygons(), start=st.integers(0, 8), shift=st.tuples(st.floats(-20, 20), st.floats(-20, 20)),
       turn=st.floats(-math.pi, math.pi))
def test_a_polygons_mass_properties_do_not_depend_on_order_winding_or_place(v, start, shift, turn):
    m, c, i = mass_properties([("polygon", v)], RHO)
    assert m > 0 and i > 0
    for other in (np.roll(v, start, axis=0), v[::-1]):
        m2, c2, i2 = mass_properties([("polygon", other)], RHO)
        assert (m2, i2) == pytest.approx((m, i), rel=1e-12)
        assert c2 == pytest.approx(c, abs=1e-12 * (1 + np.abs(v).max()))
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    m3, c3, i3 = mass_properties([("polygon", v @ rot.T + shift)], RHO)
    assert (m3, i3) == pytest.approx((m, i), rel=1e-9)
    assert c3 == pytest.approx(rot @ c + shift, abs=1e-9)


# the builder ---------------------------------------------------------------------------------
def test_a_body_from_density_has_its_com_at_the_shapes_centroid_and_they_stay_put():
    """A hammer built at pos (1, 2) turned by 0.5 rad: q is the centroid's pose, mass and
    inertia are mass_properties', and the shapes are where they were put in the world."""
    parts = [("box", (0.0, 0.0), 0.6, 0.04), ("box", (0.35, 0.0), 0.1, 0.2)]
    th = 0.5
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    b = ps.ModelBuilder(ground=None)
    b.add_body("hammer", pos=(1.0, 2.0), angle=th, density=RHO, shapes=parts)
    model = b.compile()
    m, c, i = mass_properties(parts, RHO)
    assert model.arrays.body_mass[0] == pytest.approx(m, rel=1e-15)
    assert model.arrays.body_inertia[0] == pytest.approx(i, rel=1e-14)
    assert model.q0[0, :2] == pytest.approx(np.array([1.0, 2.0]) + rot @ c, abs=1e-15)
    assert model.q0[0, 2] == th
    for shape, part in zip(model.shapes, parts):
        world = model.q0[0, :2] + rot @ np.asarray(shape.params[0])
        assert world == pytest.approx(np.array([1.0, 2.0]) + rot @ np.asarray(part[1]), abs=1e-15)


def test_shapes_added_one_by_one_with_density_build_the_same_body():
    """Every kind moved with its body's frame: the same shapes, pose, mass and inertia."""
    parts = [("box", (0.0, 0.0), 0.6, 0.04), ("box", (0.35, 0.0), 0.1, 0.2), ("circle", (-0.3, 0.1), 0.05),
             ("capsule", (0.1, 0.2), (0.3, 0.25), 0.02),
             ("polygon", [(-0.2, -0.1), (-0.1, -0.1), (-0.15, 0.0)])]
    b = ps.ModelBuilder(ground=None)
    b.add_body("all", pos=(1.0, 2.0), angle=0.3, density=RHO, shapes=parts)
    b.add_body("one_by_one", pos=(1.0, 2.0), angle=0.3)
    for p in parts:
        b.add_shape("one_by_one", *p, density=RHO)
    model = b.compile()
    a = model.arrays
    assert a.body_mass[1] == pytest.approx(a.body_mass[0], rel=1e-14)
    assert a.body_inertia[1] == pytest.approx(a.body_inertia[0], rel=1e-13)
    assert model.q0[1] == pytest.approx(model.q0[0], abs=1e-14)
    assert len(model.shapes) == 2 * len(parts)
    for s0, s1 in zip(model.shapes[:len(parts)], model.shapes[len(parts):]):
        for p0, p1 in zip(s0.params, s1.params):
            assert np.asarray(p1, dtype=float) == pytest.approx(np.asarray(p0, dtype=float), abs=1e-14)
    # and where they were put in the world
    rot = np.array([[math.cos(0.3), -math.sin(0.3)], [math.sin(0.3), math.cos(0.3)]])
    placed = model.q0[1, :2] + np.asarray(model.shapes[-1].params[0]) @ rot.T
    assert placed == pytest.approx(np.array([1.0, 2.0]) + np.asarray(parts[-1][1]) @ rot.T, abs=1e-14)


def test_a_pendulum_built_from_density_swings_with_its_physical_period():
    """A 1 m x 0.05 m bar whose frame's origin (pos) is its end, pinned there by a local
    anchor (0, 0): small swings of period 2 pi sqrt(I_pivot / (m g d))."""
    h, L, w = 2e-4, 1.0, 0.05
    b = ps.ModelBuilder(dt=h, ground=None)
    bar = b.add_body("bar", pos=(0.0, 2.0), angle=-math.pi / 2 + 0.01, density=RHO,
                     shapes=[("box", (L / 2, 0.0), L, w)])
    b.add_pin("pivot", None, bar, anchor_b=(0.0, 0.0), anchor_a=(0.0, 2.0))
    model = b.compile()
    m = RHO * L * w
    assert model.arrays.pin_anchor[0, 1] == pytest.approx([-L / 2, 0.0], abs=1e-15)
    sim = ps.Simulator(model)
    traj = sim.run(n_steps=int(4.0 / h), record_every=1)
    th = traj.q[:, 0, 2] + math.pi / 2
    up = np.flatnonzero((th[:-1] < 0) & (th[1:] >= 0))
    t_up = traj.t[up] + h * -th[up] / (th[up + 1] - th[up])
    period = np.mean(np.diff(t_up))
    i_pivot = m * (L ** 2 + w ** 2) / 12 + m * (L / 2) ** 2
    assert period == pytest.approx(2 * math.pi * math.sqrt(i_pivot / (m * 9.81 * L / 2)), rel=2e-5)


@pytest.mark.parametrize("kw, words", [
    (dict(mass=1.0, inertia=0.1, density=RHO), r"body 'slab' \(1\): mass=1.0 and inertia=0.1 given "
                                              r"with density=7.5"),
    (dict(density=0.0), r"body 'slab' \(1\): density=0.0 must be finite and > 0"),
    (dict(density=-2.0), r"body 'slab' \(1\): density=-2.0 must be finite and > 0"),
    (dict(density=math.nan), r"body 'slab' \(1\): density=nan must be finite"),
])
def test_bad_body_densities_name_the_body(kw, words):
    b = ps.ModelBuilder()
    b.add_body("torso", 1.0, 1.0, pos=(0, 1))
    with pytest.raises(ModelError, match=words):
        b.add_body("slab", pos=(0.0, 1.0), shapes=[("box", (0, 0), 0.2, 0.1)], **kw)


def test_bad_shape_densities_name_the_shape_and_body():
    b = ps.ModelBuilder()
    b.add_body("torso", 1.0, 1.0, pos=(0, 1))
    b.add_body("slab", pos=(0.0, 1.0))
    with pytest.raises(ModelError, match=r"shape 'sole' \(box 0\) of body 'slab': density=-1.0 must be"):
        b.add_shape("slab", "box", (0, 0), 0.2, 0.1, density=-1.0, name="sole")
    with pytest.raises(ModelError, match=r"box shape \(0\) of body 'torso': density=2.0 on body "
                                         r"'torso', whose mass and inertia were given"):
        b.add_shape("torso", "box", (0, 0), 0.2, 0.1, density=2.0)
    with pytest.raises(ModelError, match=r"static box shape \(0\): density=2.0 on a static shape"):
        b.add_shape(None, "box", (0, 0), 0.2, 0.1, density=2.0)
    with pytest.raises(ModelError, match=r"body 'slab' \(1\): no mass"):
        b.compile()
    b.add_shape("slab", "box", (0, 0), 0.2, 0.1, density=2.0)
    b.add_pin("hip", "torso", "slab", anchor_world=(0.0, 1.0))
    with pytest.raises(ModelError, match=r"box shape \(1\) of body 'slab': density=2.0 would move "
                                         r"the centre of mass of body 'slab', which pin 'hip'"):
        b.add_shape("slab", "box", (0.3, 0), 0.2, 0.1, density=2.0)
    b.add_shape("slab", "box", (0.3, 0), 0.2, 0.1, collide=False)    # no density: no mass
    assert b.compile().arrays.body_mass[1] == pytest.approx(2.0 * 0.02, rel=1e-15)
