"""The broad phase (sweep and prune): it never skips a pair the exact bounding-circle test
keeps, at any scale, speed or step; a pair that leaves it is cleared; a state put in from
outside does not keep a pair's contact its positions no longer have."""
import math

import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

import planarsim as ps
from planarsim.compiled import audit_counts
from planarsim.compile import options as compile_options
from planarsim.kernels.geometry.broad_phase import sweep_pairs
from planarsim.kernels.codes import CONTACT_PAIR, MODE_FREE
from planarsim.kernels.math2d import update_trig
from planarsim.kernels.geometry.pair import SPECULATIVE_FACTOR, place_shapes
from planarsim.state import make_workspace
from strategies import decades, matrices, reals, vectors

jit = njit(**dict(compile_options(), cache=False))


@jit
def _place_and_sweep(m, q, v, ws, margin, h, out):
    update_trig(q, ws.body_cs)
    place_shapes(m, q, ws.body_cs, v, v, ws)
    return sweep_pairs(ws, margin, h, out)


SHAPE_KINDS = ("box", "circle", "capsule", "polygon")


@st.composite
def scattered_shapes(draw):
    """(model, v): 2 to 30 bodies with a shape each (box, circle, capsule or triangle; sizes
    over two decades of a scale of 1 mm to 10 m), positions drawn over a square of 6 scale
    [m] near the origin or 2 km from it, angles in [-3, 3] rad, and velocities [m/s, rad/s]
    of up to 3 times a speed of 0 to 200 m/s (the 3 sigma of a normal draw)."""
    n = draw(st.integers(2, 30))
    scale = draw(st.sampled_from([1e-3, 0.1, 1.0, 10.0]))
    offset = np.array([1e3, -2e3]) if draw(st.booleans()) else np.zeros(2)
    speed = draw(st.sampled_from([0.0, 1.0, 30.0, 200.0]))
    b = ps.ModelBuilder(dt=1e-3)
    for k in range(n):
        size = scale * draw(decades(-1.0, 1.0))
        kind = draw(st.sampled_from(SHAPE_KINDS))
        if kind == "box":
            shape = ("box", (0.0, 0.0), size, 0.5 * size)
        elif kind == "circle":
            shape = ("circle", (0.0, 0.0), 0.5 * size)
        elif kind == "capsule":
            shape = ("capsule", (-0.5 * size, 0.0), (0.5 * size, 0.0), 0.2 * size)
        else:
            shape = ("polygon", [(0.0, 0.0), (size, 0.0), (0.3 * size, 0.8 * size)])
        pos = offset + 6 * scale * draw(vectors(2, 0.0, 1.0))
        b.add_body(f"b{k}", 1.0, 0.1, pos=tuple(pos), angle=draw(reals(-3.0, 3.0)), shapes=[shape])
    return b.compile(), speed * draw(matrices(n, 3, -3.0, 3.0))


@settings(max_examples=60, deadline=None)
@given(scene=scattered_shapes(), margin=st.sampled_from([0.0, 1e-6, 1e-4]),
       h=st.sampled_from([0.0, 1e-4, 1e-3, 1e-2]))
def test_sweep_keeps_every_pair_the_exact_test_keeps(scene, margin, h):
    model, v = scene
    arr = model.arrays
    ws = make_workspace(model)
    q = model.q0.copy()
    out = np.zeros(arr.n_shape_pair + 1, np.int64)
    count = _place_and_sweep(arr, q, v, ws, margin, h, out)
    listed = out[:count]
    assert np.all(np.diff(listed) > 0), "ascending, each pair once"
    reach = ws.shape_reach
    for i in np.flatnonzero((arr.contact_kind == CONTACT_PAIR) & (arr.contact_pair[:, 2] == 0)):
        a, b = arr.contact_pair[i, 0], arr.contact_pair[i, 1]
        d = math.hypot(reach[b, 0] - reach[a, 0], reach[b, 1] - reach[a, 1])
        need = reach[a, 2] + reach[b, 2] + margin + SPECULATIVE_FACTOR * h * (reach[a, 3] + reach[b, 3])
        if d <= need:
            assert i in listed, (i, d, need)


def _pair_slots(model):
    return np.flatnonzero(model.arrays.contact_kind == CONTACT_PAIR)


def two_boxes(gap):
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("low", 1.0, 0.01, pos=(0.0, 0.1), shapes=[("box", (0.0, 0.0), 0.4, 0.2)])
    b.add_body("high", 1.0, 0.01, pos=(0.0, 0.3 + gap), shapes=[("box", (0.0, 0.0), 0.4, 0.2)])
    return b.compile()


def test_a_state_put_in_keeps_no_contact_of_a_pair_now_apart():
    """A state whose pair contacts hold (taken from a stack at rest) with the top box moved
    1 m away, put into a simulator whose bodies were already apart (the pair out of its
    broad phase): the pair's contacts are free after a step, with no impulse."""
    model = two_boxes(0.0)
    stack = ps.Simulator(model)
    stack.steps(200)
    slots = _pair_slots(model)
    snap = stack.snapshot()
    assert np.any(snap.contact_mode[slots] != MODE_FREE)
    snap.q[1, 0] += 1.0
    apart = ps.Simulator(two_boxes(1.0))
    apart.steps(5)
    apart.state = snap
    apart.steps(1)
    assert np.all(apart.state.contact_mode[slots] == MODE_FREE)
    assert np.all(apart.state.last_contact_impulse[slots] == 0.0)


def test_a_pair_that_leaves_the_broad_phase_is_cleared():
    """The top box of a stack thrown upwards: once the boxes are apart, the pair's contacts
    are free, without features or impulses, and the audit stays clean."""
    model = two_boxes(0.0)
    sim = ps.Simulator(model)
    sim.steps(100)
    slots = _pair_slots(model)
    assert np.any(sim.state.contact_mode[slots] != MODE_FREE)
    sim.state.v[1, 1] = 5.0
    sim.steps(100)
    assert sim.state.q[1, 1] > 0.5
    assert np.all(sim.state.contact_mode[slots] == MODE_FREE)
    assert np.all(sim.state.contact_feature[slots] == -1)
    assert np.all(sim.ws.contact_impulse[slots] == 0.0)
    assert all(v == 0 for v in audit_counts(sim.ws).values())
