"""The joint limit's rows: inequalities on a pin's relative angle
ang = theta_b - theta_a - ref [rad]: ang - lower >= 0 (side 0, ROW_LIMIT_LO) and
upper - ang >= 0 (side 1, ROW_LIMIT_HI). A side has a row only while it is active
(State.limit_active; engaged and released by the mode rules, kernels/solver/modes.py)."""
import math

from ...compile import kernel
from ..codes import ROW_LIMIT_HI, ROW_LIMIT_LO
from ..dynamics.forces import pin_angle
from .joints import joint_position_rate
from .row_list import add_row


@kernel
def limit_side(kind):
    """0 for a lower-limit row, 1 for an upper (the column of State.limit_active)."""
    return 0 if kind == ROW_LIMIT_LO else 1


@kernel
def limit_row(m, q, o, a, b, side, J):
    """Jacobian blocks J (2, 3) and error [rad] (distance inside the limit) of pin o's limit
    row on `side`."""
    sign = 1.0 if side == 0 else -1.0
    ang = pin_angle(m, q, o)
    for k in range(3):
        J[0, k] = 0.0
        J[1, k] = 0.0
    if a >= 0:
        J[0, 2] = -sign
    J[1, 2] = sign
    if side == 0:
        return ang - m.pin_limit[o, 0]
    return m.pin_limit[o, 1] - ang


@kernel
def add_limit_rows(m, s, ws, n, j):
    """Append the rows of pin j's active limit sides at slot n; returns the next free slot."""
    if s.limit_active[j, 0]:
        n = add_row(ws, n, ROW_LIMIT_LO, j, m.pin_body[j, 0], m.pin_body[j, 1])
    if s.limit_active[j, 1]:
        n = add_row(ws, n, ROW_LIMIT_HI, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return n


@kernel
def limit_overshoot(m, q, cs, v, j):
    """How far [rad or m] joint j's coordinate lies outside its limit at q (cs its cos / sin;
    0 inside it, or without a limit): negative on neither side."""
    lo = m.pin_limit[j, 0]
    hi = m.pin_limit[j, 1]
    if lo == -math.inf and hi == math.inf:
        return 0.0
    x = joint_position_rate(m, q, cs, v, j)[0]
    return max(0.0, lo - x, x - hi)


@kernel
def add_violated_limit_rows(m, s, ws, n, j):
    """add_limit_rows, and a row for each side of pin j's limit that s.q lies outside of
    while inactive (a start outside the limit, or a released side the step's end crossed:
    the position projection puts the joint back onto it); returns the next free slot."""
    lo = m.pin_limit[j, 0]
    hi = m.pin_limit[j, 1]
    if lo == -math.inf and hi == math.inf:
        return n
    x = joint_position_rate(m, s.q, ws.body_cs, s.v, j)[0]
    if s.limit_active[j, 0] or x < lo:
        n = add_row(ws, n, ROW_LIMIT_LO, j, m.pin_body[j, 0], m.pin_body[j, 1])
    if s.limit_active[j, 1] or x > hi:
        n = add_row(ws, n, ROW_LIMIT_HI, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return n
