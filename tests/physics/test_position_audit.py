"""The end-of-step position audit leaves out the ground query of a contact whose normal row
the position correction held, where that row bounds the contact's depth
(audit.held_row_is_depth). For an arc contact that rests on a lemma: with every fallback
vertex inside the circle (audit.vertices_within_arc), no part of the foot is lower than the
circle's lowest point, on flat or sloped ground, in any pose. It also leaves out the query of
a contact surely clear of the ground (audit.surely_clear): for an arc foot, its gap at the
step's start minus |dx| + |dy| + |dtheta| times the foot's farthest point from the COM
(audit.foot_radius) never exceeds its gap at the end, in any two poses."""
import math

import numpy as np
from hypothesis import HealthCheck, given, settings, strategies as st
from numba import njit

import planarsim as ps
from planarsim import terrain
from planarsim.kernels.checks.audit import contact_gap, foot_radius, vertices_within_arc
from planarsim.kernels.math2d import update_trig, world_point
from planarsim.kernels.geometry.terrain import ground_point


def _trig():
    """A body's (cos, sin, angle) cache as the workspace holds it (state.py: NaN angle, so
    update_trig computes it; a (1, 2) array here once let update_trig write past its end)."""
    return np.full((1, 3), np.nan)


@njit(cache=False)   # a test helper: compiled per run, never a stale cache entry
def _gaps(m, q, cs):
    """(the foot's gap as the audit measures it, the circle's gap, vertices_within_arc)."""
    update_trig(q, cs)
    cx, cy = world_point(q, cs, 0, m.contact_local[0, 0], m.contact_local[0, 1])
    circle = ground_point(m.terrain_coef, cx, cy)[4] - m.contact_radius[0]
    return contact_gap(m, q, cs, 0), circle, vertices_within_arc(m, 0)


def _foot(slope_deg, vertices):
    b = ps.ModelBuilder(dt=1e-3, terrain=terrain.slope(slope_deg))
    foot = b.add_body("foot", 1.0, 0.01, pos=(0.0, 0.5))
    b.add_arc_contact("sole", foot, (-0.03, 0.16), 0.2, span=(-2.2, -0.9), vertices=vertices)
    return b.compile()


_INSIDE = [(-0.06, -0.017), (0.0, 0.04)]      # Ranger's heel and toe: inside the circle
_OUTSIDE = [(-0.06, -0.017), (0.25, 0.0)]     # a toe that sticks out of it


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(slope_deg=st.sampled_from([0.0, 9.0, -20.0]),
       x=st.floats(-1.0, 1.0), y=st.floats(-0.5, 0.5), angle=st.floats(-math.pi, math.pi))
def test_foot_is_never_lower_than_its_circle_when_vertices_lie_inside(slope_deg, x, y, angle):
    model = _foot(slope_deg, _INSIDE)
    m = model.arrays
    q = np.array([[x, y, angle]])
    gap, circle, inside = _gaps(m, q, _trig())
    assert inside
    assert gap >= circle - 1e-12


def test_a_vertex_outside_the_circle_is_recognised_and_can_be_lower():
    """The lemma's condition is not vacuous: a toe outside the circle is flagged, and some
    pose puts it below the circle's lowest point."""
    model = _foot(0.0, _OUTSIDE)
    m = model.arrays
    lower = 0
    for angle in np.linspace(-math.pi, math.pi, 73):
        gap, circle, inside = _gaps(m, np.array([[0.0, 0.3, angle]]), _trig())
        assert not inside
        lower += gap < circle - 1e-6
    assert lower > 0


@njit(cache=False)
def _gap_and_radius(m, q, cs):
    """(contact 0's gap as the audit measures it at q, its foot_radius)."""
    update_trig(q, cs)
    return contact_gap(m, q, cs, 0), foot_radius(m, 0)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(slope_deg=st.sampled_from([0.0, 9.0, -20.0]), outside=st.booleans(),
       full=st.booleans(),
       start=st.tuples(st.floats(-1.0, 1.0), st.floats(-0.5, 0.6), st.floats(-math.pi, math.pi)),
       move=st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), st.floats(-3.0, 3.0)))
def test_an_arc_foot_moves_no_closer_to_the_ground_than_its_reach(slope_deg, outside, full,
                                                                  start, move):
    b = ps.ModelBuilder(dt=1e-3, terrain=terrain.slope(slope_deg))
    foot = b.add_body("foot", 1.0, 0.01, pos=(0.0, 0.5))
    span = (-math.pi, math.pi) if full else (-2.2, -0.9)
    b.add_arc_contact("sole", foot, (-0.03, 0.16), 0.2, span=span,
                      vertices=_OUTSIDE if outside else _INSIDE)
    m = b.compile().arrays
    q0 = np.array([start])
    q1 = q0 + np.array([move])
    before, radius = _gap_and_radius(m, q0, _trig())
    after, _ = _gap_and_radius(m, q1, _trig())
    reach = abs(move[0]) + abs(move[1]) + abs(move[2]) * radius
    assert after >= before - reach - 1e-12, (before, after, reach)
