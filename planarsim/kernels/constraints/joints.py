"""A joint's coordinate, whatever its kind (the pin table's model.pin_kind): a hinge's angle
theta_b - theta_a - ref [rad], a slider's slide s = d.(p_b - p_a) [m] (slider.py). The one
dispatch on a joint's kind, for what acts on its coordinate: limits (limit.py, modes.py),
springs, dampers and armature (soft.py). A free body's coordinate (codes.JOINT_FREE_BIT) is
measured the same way but holds nothing: it has no constraint rows."""
from ...compile import kernel
from ..codes import JOINT_FREE_BIT, JOINT_SLIDE_BIT
from ..dynamics.forces import pin_angle_rate
from .slider import slide_position_rate, slide_row, slider_angle_row


@kernel
def is_slider(m, j):
    """Joint j's coordinate is a slide [m] (a slider, or a free body's slide), not an angle."""
    return (m.pin_kind[j] & JOINT_SLIDE_BIT) != 0


@kernel
def is_free_joint(m, j):
    """Joint j only measures a free body's coordinate: no constraint rows, no gap."""
    return (m.pin_kind[j] & JOINT_FREE_BIT) != 0


@kernel
def joint_position_rate(m, q, cs, v, j):
    """Joint j's coordinate [rad or m] and its rate [rad/s or m/s] at (q, v) (cs: cos / sin
    of the angles at q)."""
    if is_slider(m, j):
        return slide_position_rate(m, q, cs, v, j)
    return pin_angle_rate(m, q, v, j)


@kernel
def joint_rate_row(m, q, cs, j, J):
    """J (2, 3): the Jacobian blocks (bodies a, b) of joint j's rate, dx/dt = J v; returns its
    coordinate x [rad or m]."""
    a = m.pin_body[j, 0]
    b = m.pin_body[j, 1]
    if is_slider(m, j):
        return slide_row(m, q, cs, j, a, b, J)
    return slider_angle_row(m, q, j, a, b, J)     # the same relative angle as a hinge's


@kernel
def rate_along(bodies, J, v):
    """g v [rad/s or m/s] of a row g with blocks J (2, 3) on bodies (2,) at velocities v
    (a joint's rate along its soft or friction row)."""
    rate = 0.0
    for e in range(2):
        b = bodies[e]
        if b < 0:
            continue
        for k in range(3):
            rate += J[e, k] * v[b, k]
    return rate
