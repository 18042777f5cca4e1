"""A joint's coordinate, whatever its kind (the pin table's model.pin_kind): a hinge's angle
theta_b - theta_a - ref [rad], a slider's slide s = d.(p_b - p_a) [m] (slider.py). The one
dispatch on a joint's kind, for what acts on its coordinate: limits (limit.py, modes.py),
springs, dampers and armature (soft.py)."""
from ..compile import kernel
from .codes import JOINT_SLIDER
from .forces import pin_angle_rate
from .slider import slide_position_rate, slide_row


@kernel
def is_slider(m, j):
    """Joint j is a slider (prismatic), not a hinge."""
    return m.pin_kind[j] == JOINT_SLIDER


@kernel
def joint_position_rate(m, q, cs, v, j):
    """Joint j's coordinate [rad or m] and its rate [rad/s or m/s] at (q, v) (cs: cos / sin
    of the angles at q)."""
    if m.pin_kind[j] == JOINT_SLIDER:
        return slide_position_rate(m, q, cs, v, j)
    return pin_angle_rate(m, q, v, j)


@kernel
def joint_rate_row(m, q, cs, j, J):
    """J (2, 3): the Jacobian blocks (bodies a, b) of joint j's rate, dx/dt = J v; returns its
    coordinate x [rad or m]."""
    a = m.pin_body[j, 0]
    b = m.pin_body[j, 1]
    if m.pin_kind[j] == JOINT_SLIDER:
        return slide_row(m, q, cs, j, a, b, J)
    for k in range(3):
        J[0, k] = 0.0
        J[1, k] = 0.0
    ang = q[b, 2] - m.pin_ref[j]
    if a >= 0:
        ang -= q[a, 2]
        J[0, 2] = -1.0
    J[1, 2] = 1.0
    return ang

