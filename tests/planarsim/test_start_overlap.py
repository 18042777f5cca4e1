"""Two colliding shapes may not start inside each other (planarsim.start_check): a ModelError
naming both shapes and the depth, unless allow_overlap=True (then a warning says so)."""
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import planarsim as ps
from planarsim import ModelError
from planarsim.shapes import box_vertices
from planarsim.start_check import START_TOLERANCE, shape_gap


def circle_in_box(dx=0.05, **shape_kw):
    """A disk 'heel' (r = 0.1 m) of body 'shin_L' whose centre is 0.05 m inside the left side of
    a 0.2 m box of body 'crate': they overlap by 0.15 m (the disk leaves by moving 0.15 m left)."""
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("shin_L", 1.0, 0.01, pos=(0.0, 1.0),
               shapes=[("circle", (0.0, 0.0), 0.1, {"name": "heel", **shape_kw})])
    b.add_body("crate", 1.0, 0.01, pos=(dx, 1.0), shapes=[("box", (0.0, 0.0), 0.2, 0.2)])
    return b


def test_an_overlapping_start_names_both_shapes_and_the_depth():
    with pytest.raises(ModelError) as err:
        ps.Simulator(circle_in_box().compile())
    said = str(err.value)
    assert "shape 'heel' (circle 0) of body 'shin_L'" in said
    assert "box shape (1) of body 'crate'" in said
    assert "overlapping by 0.15 m" in said
    assert "allow_overlap=True" in said


def test_an_allowed_overlap_starts_and_says_so():
    model = circle_in_box().compile()
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        sim = ps.Simulator(model, allow_overlap=True)
    words = [str(w.message) for w in said]
    assert any("'heel'" in w and "'crate'" in w and "0.15 m" in w for w in words), words
    sim.steps(5)
    assert np.all(np.isfinite(sim.state.q))


def test_shapes_that_do_not_collide_may_start_inside_each_other():
    # filtered out by their bits
    ps.Simulator(circle_in_box(mask=0).compile())
    # bodies of one mechanism
    b = circle_in_box()
    b.add_pin("hinge", "shin_L", "crate", anchor_world=(0.0, 1.0))
    ps.Simulator(b.compile())


@pytest.mark.parametrize("sink", [0.0, 0.5 * START_TOLERANCE, -1e-3])
def test_a_box_resting_on_a_box_starts(sink):
    """Touching (or within the start tolerance, or apart): no error."""
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("lower", 1.0, 1.0 / 6, pos=(0.0, 0.5), shapes=[("box", (0, 0), 1.0, 1.0)])
    b.add_body("upper", 1.0, 1.0 / 6, pos=(0.3, 1.5 - sink), shapes=[("box", (0, 0), 1.0, 1.0)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ps.Simulator(b.compile()).steps(3)


def test_a_body_sunk_into_a_static_wall_is_refused():
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("ball", 1.0, 0.004, pos=(0.98, 0.5), shapes=[("circle", (0, 0), 0.1)])
    b.add_shape(None, "box", (1.5, 0.5), 1.0, 1.0, name="wall")
    with pytest.raises(ModelError, match=r"circle shape \(0\) of body 'ball' and static shape "
                                         r"'wall' \(box 1\) start overlapping by 0.08 m"):
        ps.Simulator(b.compile())


# the depth against analytic answers ---------------------------------------------------------
def test_shape_gap_analytic():
    c = np.array([[0.0, 0.0]])
    assert shape_gap(c, 0.1, c + [0.5, 0.0], 0.2) == pytest.approx(0.2, abs=1e-15)   # disks apart
    assert shape_gap(c, 0.3, c + [0.3, 0.4], 0.5) == pytest.approx(-0.3, abs=1e-15)  # disks in
    box = box_vertices((0.0, 0.0), 2.0, 1.0)
    # a disk beyond a corner: its distance to the corner
    assert shape_gap(box, 0.0, c + [1.3, 0.9], 0.1) == pytest.approx(0.5 - 0.1, abs=1e-15)
    # a disk whose centre is inside: the nearest side
    assert shape_gap(box, 0.0, c + [0.8, 0.1], 0.05) == pytest.approx(-0.25, abs=1e-15)
    # a capsule across a box, centre line 0.1 m below its top: out through the top
    seg = np.array([[-3.0, 0.4], [3.0, 0.4]])
    assert shape_gap(box, 0.0, seg, 0.05) == pytest.approx(-0.15, abs=1e-15)
    # two crossing segments (an X): the shortest way out is along one's normal
    x1 = np.array([[-1.0, -1.0], [1.0, 1.0]])
    x2 = np.array([[-1.0, 1.0], [1.0, -1.0]])
    assert shape_gap(x1, 0.0, x2, 0.0) == pytest.approx(-math.sqrt(2.0), rel=1e-12)
    # a segment in line with another, beyond its end (the direction separates them)
    assert shape_gap(seg, 0.0, seg + [7.0, 0.0], 0.0) == pytest.approx(1.0, abs=1e-12)
    # boxes overlapping by 0.05 m on x and 0.3 m on y: the smaller
    assert shape_gap(box, 0.0, box + [1.95, 0.7], 0.0) == pytest.approx(-0.05, abs=1e-12)


def _polygon(n, radius, phase):
    a = phase + 2.0 * math.pi * np.arange(n) / n
    return radius * np.stack([np.cos(a), np.sin(a)], axis=1)


@settings(max_examples=300, deadline=None)
@given(n=st.integers(1, 7), m=st.integers(1, 7), phase=st.floats(0, 6.3), turn=st.floats(0, 6.3),
       dx=st.floats(-2, 2), dy=st.floats(-2, 2), ra=st.floats(0, 0.3), rb=st.floats(0, 0.3),
       shift=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_shape_gap_is_symmetric_moves_with_the_shapes_and_is_exact_for_disks(
        n, m, phase, turn, dx, dy, ra, rb, shift):
    a = _polygon(n, 0.5, phase)
    b = _polygon(m, 0.7, phase + 1.0) + [dx, dy]
    gap = shape_gap(a, ra, b, rb)
    assert shape_gap(b, rb, a, ra) == pytest.approx(gap, abs=1e-12)
    assert shape_gap(a + shift, ra, b + shift, rb) == pytest.approx(gap, abs=1e-9)
    c, s = math.cos(turn), math.sin(turn)
    rot = np.array([[c, s], [-s, c]])
    assert shape_gap(a @ rot, ra, b @ rot, rb) == pytest.approx(gap, abs=1e-12)
    if n == m == 1:
        assert gap == pytest.approx(math.hypot(*(b[0] - a[0])) - ra - rb, abs=1e-12)
