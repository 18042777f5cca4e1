"""The rod's row: one equality, |p_b - p_a| - L = 0, between anchor points fixed in bodies a
and b (a massless rigid link of length L [m]); its row acts along the unit vector a -> b."""
import math

from ...compile import kernel
from ..codes import ROW_ROD
from ..math2d import set_dir, world_point
from .row_list import add_row


@kernel
def rod_row(m, q, cs, o, a, b, J):
    """Jacobian blocks J (2, 3) and error [m] (length minus rest length) of rod o."""
    ax, ay = world_point(q, cs, a, m.rod_anchor[o, 0, 0], m.rod_anchor[o, 0, 1])
    bx, by = world_point(q, cs, b, m.rod_anchor[o, 1, 0], m.rod_anchor[o, 1, 1])
    ex = bx - ax
    ey = by - ay
    L = math.sqrt(ex * ex + ey * ey)
    ex /= L
    ey /= L
    set_dir(q, a, ax, ay, ex, ey, -1.0, J[0])
    set_dir(q, b, bx, by, ex, ey, 1.0, J[1])
    return L - m.rod_length[o]


@kernel
def add_rod_row(m, ws, n, j):
    """Append rod j's row at slot n; returns the next free slot."""
    return add_row(ws, n, ROW_ROD, j, m.rod_body[j, 0], m.rod_body[j, 1])
