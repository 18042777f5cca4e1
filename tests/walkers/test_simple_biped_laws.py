"""Property tests of the Simple Biped's control laws and the shared Bezier/PD helpers."""
import math

import numpy as np
from hypothesis import given, settings, strategies as st

from walkers.common.bezier import bezier3, rectangle_bezier
from walkers.common.pd import clamp, pd
from walkers.simple_biped.legs import leg_state, limit_hip_torque, push_hip, push_hip_pendulum

finite = dict(allow_nan=False, allow_infinity=False)


def standing_q(x0, x1, hip_x, hip_y):
    """Positions (hip, foot0, foot1) with feet on y = 0."""
    q = np.zeros((3, 3))
    q[0, :2] = hip_x, hip_y
    q[1, :2] = x0, 0.0
    q[2, :2] = x1, 0.0
    return q


def leg_force_on_hip(q, u):
    """Force [N] of the two axial actuators on the hip."""
    f = np.zeros(2)
    for i in range(2):
        e = q[0, :2] - q[i + 1, :2]
        f += u[i] * e / np.linalg.norm(e)
    return f


@settings(max_examples=200, deadline=None)
@given(x0=st.floats(-0.6, -0.05), x1=st.floats(0.05, 0.6), hip_x=st.floats(-0.3, 0.3),
       hip_y=st.floats(0.6, 1.1), fx=st.floats(-300, 300), fy=st.floats(-100, 600))
def test_double_stance_split_only_pushes_and_keeps_the_vertical_force(x0, x1, hip_x, hip_y, fx, fy):
    q = standing_q(x0, x1, hip_x, hip_y)
    u = np.zeros(3)
    push_hip(q, fx, fy, 1e6, u)
    assert u[0] >= 0.0 and u[1] >= 0.0 and u[2] == 0.0
    f = leg_force_on_hip(q, u)
    if fy <= 0.0:
        assert u[0] == 0.0 and u[1] == 0.0
        return
    assert abs(f[1] - fy) <= 1e-9 * max(1.0, fy)
    # the horizontal force is the asked one, or the nearest one two pushing legs can give
    h = sorted(fy * (q[0, 0] - q[i + 1, 0]) / (q[0, 1] - q[i + 1, 1]) for i in range(2))
    assert abs(f[0] - min(max(fx, h[0]), h[1])) <= 1e-9 * max(1.0, abs(fx), fy)


@settings(max_examples=200, deadline=None)
@given(rear=st.floats(-0.8, -0.1), front=st.floats(0.05, 0.6), hip_x=st.floats(-0.1, 0.3),
       hip_y=st.floats(0.8, 1.0), f_n=st.floats(0.0, 400), f_t=st.floats(-300, 300))
def test_walking_double_stance_forces_stay_in_their_limits(rear, front, hip_x, hip_y, f_n, f_t):
    q = standing_q(rear, front, hip_x, hip_y)
    u = np.zeros(3)
    floor, cap = 30.0, 500.0
    push_hip_pendulum(q, 1, f_n, f_t, floor, cap, u)
    assert 0.0 <= u[0] <= cap and min(floor, f_n) - 1e-9 <= u[1] <= cap
    n = (q[0, :2] - q[2, :2]) / np.linalg.norm(q[0, :2] - q[2, :2])
    f = leg_force_on_hip(q, u)
    if u[0] == 0.0:  # rear leg idle: the front leg delivers the normal force alone
        assert abs(f @ n - min(f_n, cap)) < 1e-9 * max(1.0, f_n)


@settings(max_examples=200, deadline=None)
@given(sx=st.floats(-0.5, 0.5), hip_y=st.floats(0.7, 1.1), u_st=st.floats(0.0, 400),
       tau=st.floats(-300, 300), stance=st.integers(0, 1), mu=st.floats(0.1, 1.5))
def test_hip_torque_limit_keeps_the_stance_foot_in_its_friction_cone(sx, hip_y, u_st, tau, stance, mu):
    q = np.zeros((3, 3))
    q[0, :2] = 0.0, hip_y
    q[stance + 1, :2] = sx, 0.0
    q[2 - stance, :2] = -sx, 0.3
    u = np.zeros(3)
    u[stance] = u_st
    u[2] = tau
    w = 9.81
    limit_hip_torque(q, stance, mu, w, u)
    assert abs(u[2]) <= abs(tau) + 1e-12 and u[2] * tau >= 0.0
    # force of the actuators on the stance foot, as the engine applies it
    d = q[stance + 1, :2] - q[0, :2]
    s = 2.0 * stance - 1.0

    def excess(torque):
        """How far the foot force is outside the friction cone [N] (<= 0 inside)."""
        F = u_st * d / np.linalg.norm(d) + s * torque * np.array([-d[1], d[0]]) / (d @ d)
        return abs(F[0]) - mu * (-F[1] + w)

    # the kept torque never pushes the foot further out than the leg force alone does
    assert excess(u[2]) <= max(0.0, excess(0.0)) + 1e-9 * (1.0 + u_st + abs(tau))


@settings(deadline=None)
@given(x=st.floats(-0.5, 0.5, **finite), y=st.floats(-1.2, -0.3, **finite))
def test_leg_state_angle_convention(x, y):
    q = np.zeros((3, 3))
    v = np.zeros((3, 3))
    q[1, :2] = x, y
    v[1, :2] = -y, x  # counter-clockwise about the hip at 1 rad/s
    dx, dy, l, ldot, phi, phidot = leg_state(q, v, 0)
    assert math.isclose(l, math.hypot(x, y))
    assert math.isclose(phi, math.atan2(x, -y))
    assert abs(ldot) < 1e-12 and math.isclose(phidot, 1.0)


@settings(deadline=None)
@given(p=st.lists(st.floats(-10, 10, **finite), min_size=4, max_size=4), s=st.floats(0, 1))
def test_bezier_ends_and_derivative(p, s):
    b0, _ = bezier3(*p, 0.0)
    b1, _ = bezier3(*p, 1.0)
    assert math.isclose(b0, p[0], abs_tol=1e-12) and math.isclose(b1, p[3], abs_tol=1e-12)
    h = 1e-6
    lo, hi = max(0.0, s - h), min(1.0, s + h)
    num = (bezier3(*p, hi)[0] - bezier3(*p, lo)[0]) / (hi - lo)
    assert abs(bezier3(*p, s)[1] - num) < 1e-4 * (1 + max(abs(x) for x in p))


def test_rectangle_bezier_clears_by_three_quarters_of_its_top_edge():
    clearance = 0.08
    x, y, dx, dy = rectangle_bezier(0.0, 0.0, 0.6, 0.0, 4.0 / 3.0 * clearance, 0.5)
    assert math.isclose(y, clearance) and math.isclose(x, 0.3) and abs(dy) < 1e-12
    # it starts straight up and ends straight down
    assert rectangle_bezier(0.0, 0.0, 0.6, 0.0, 0.1, 0.0)[2] == 0.0
    assert rectangle_bezier(0.0, 0.0, 0.6, 0.0, 0.1, 1.0)[2] == 0.0


def test_pd_and_clamp():
    assert pd(2.0, 3.0, 1.0, 0.5, 0.0, 1.0) == 2.0 * 0.5 - 3.0
    assert clamp(5.0, -1.0, 1.0) == 1.0 and clamp(-5.0, -1.0, 1.0) == -1.0 and clamp(0.2, -1, 1) == 0.2
