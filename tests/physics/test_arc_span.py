"""An arc sole's span test (kernels/geometry/contacts.sole_facing): a direction lies in the span
(a0, a1), ends included, exactly when its angle, taken within a turn after a0, is at most a1;
decided by the sides of the span's end directions, with no angle computed."""
import math

import numpy as np
from hypothesis import given, settings, strategies as st
from numba import njit

import planarsim as ps
from planarsim.compile import options as compile_options
from planarsim.kernels.geometry.contacts import sole_facing


@njit(**dict(compile_options(), cache=False))
def _facing(m, cs, nx, ny):
    return sole_facing(m, cs, 0, 0, nx, ny)[0]


@settings(max_examples=300, deadline=None)
@given(a0=st.floats(-10.0, 10.0), width=st.floats(1e-3, 7.0), angle=st.floats(-4.0, 4.0),
       tilt=st.floats(-4.0, 4.0))
def test_a_direction_is_in_an_arcs_span_as_its_angle_says(a0, width, angle, tilt):
    a1 = a0 + width
    b = ps.ModelBuilder(dt=1e-3)
    foot = b.add_body("foot", 1.0, 0.01, pos=(0.0, 1.0), angle=tilt)
    b.add_arc_contact("sole", foot, (0.0, 0.0), 0.1, span=(a0, a1))
    model = b.compile()
    # the ground's normal n such that -n, in the foot's frame, points at `angle`
    wx, wy = math.cos(angle + tilt), math.sin(angle + tilt)
    cs = np.array([[math.cos(tilt), math.sin(tilt), tilt]])
    # the reference: the angle within a turn after a0, against a1 (away from the ends, where
    # rounding decides either way)
    rel = (angle - a0) % (2.0 * math.pi)
    ends = min(rel, 2.0 * math.pi - rel, abs(rel - width) if width < 2.0 * math.pi else math.inf)
    if ends < 1e-9:
        return
    assert _facing(model.arrays, cs, -wx, -wy) == (width >= 2.0 * math.pi or rel <= width)
