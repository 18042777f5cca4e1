"""The pin joint's rows: two equalities, p_b - p_a = 0 along x (ROW_PIN_X) and y (ROW_PIN_Y),
for the anchor points fixed in bodies a and b (a < 0: the world). A pin's x row is always
followed by its y row, so both come from one evaluation of the anchors (pin_rows).
"""
from ...compile import kernel
from ..codes import ROW_PIN_X, ROW_PIN_Y
from ..math2d import set_dir, world_point
from .row_list import add_row


@kernel
def pin_row(m, q, cs, o, a, b, axis, J):
    """Jacobian blocks J (2, 3) and error [m] of pin o's row along axis 0 (x) or 1 (y)."""
    ax, ay = world_point(q, cs, a, m.pin_anchor[o, 0, 0], m.pin_anchor[o, 0, 1])
    bx, by = world_point(q, cs, b, m.pin_anchor[o, 1, 0], m.pin_anchor[o, 1, 1])
    dx = 1.0 if axis == 0 else 0.0
    dy = 1.0 - dx
    set_dir(q, a, ax, ay, dx, dy, -1.0, J[0])
    set_dir(q, b, bx, by, dx, dy, 1.0, J[1])
    return (bx - ax) * dx + (by - ay) * dy


@kernel
def pin_rows(q, cs, anchor, o, a, b, J, c, r):
    """Rows r (x) and r + 1 (y) of pin o between bodies a and b: both from one evaluation of
    the two anchor points (the same arithmetic as pin_row, half the work)."""
    ax, ay = world_point(q, cs, a, anchor[o, 0, 0], anchor[o, 0, 1])
    bx, by = world_point(q, cs, b, anchor[o, 1, 0], anchor[o, 1, 1])
    set_dir(q, a, ax, ay, 1.0, 0.0, -1.0, J[r, 0])
    set_dir(q, b, bx, by, 1.0, 0.0, 1.0, J[r, 1])
    c[r] = (bx - ax) * 1.0 + (by - ay) * 0.0
    set_dir(q, a, ax, ay, 0.0, 1.0, -1.0, J[r + 1, 0])
    set_dir(q, b, bx, by, 0.0, 1.0, 1.0, J[r + 1, 1])
    c[r + 1] = (bx - ax) * 0.0 + (by - ay) * 1.0


@kernel(inline="always")
def pin_gap(q, cs, anchor, o, a, b):
    """(x, y) [m] of pin o's gap p_b - p_a between bodies a and b: its rows' errors (pin_rows'
    c, without their Jacobian blocks)."""
    ax, ay = world_point(q, cs, a, anchor[o, 0, 0], anchor[o, 0, 1])
    bx, by = world_point(q, cs, b, anchor[o, 1, 0], anchor[o, 1, 1])
    return bx - ax, by - ay


@kernel
def pin_axis(kind):
    """0 for a pin's x row, 1 for its y row (its impulse's slot in State.last_pin_impulse)."""
    return 0 if kind == ROW_PIN_X else 1


@kernel
def pin_lever(m, o, e):
    """|x| + |y| [m] of pin o's anchor on its body slot e (0: a, 1: b), from that body's COM."""
    return abs(m.pin_anchor[o, e, 0]) + abs(m.pin_anchor[o, e, 1])


@kernel
def add_pin_rows(m, ws, n, j):
    """Append pin j's x and y rows at slot n; returns the next free slot."""
    n = add_row(ws, n, ROW_PIN_X, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return add_row(ws, n, ROW_PIN_Y, j, m.pin_body[j, 0], m.pin_body[j, 1])
