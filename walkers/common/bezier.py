"""Cubic Bezier curves in the plane (compiled), for swing-foot trajectories.

B(s) = (1-s)^3 P0 + 3 (1-s)^2 s P1 + 3 (1-s) s^2 P2 + s^3 P3,   0 <= s <= 1
dB/ds = 3 (1-s)^2 (P1-P0) + 6 (1-s) s (P2-P1) + 3 s^2 (P3-P2)

With the control points at the corners of a rectangle of height H (P1, P2 directly above P0,
P3), the curve's top is at (3/4) H: a top edge at (4/3) c gives a clearance c (Kelly 2014, 4.2).
Points are given as scalars [m]; s is dimensionless.
"""
from planarsim.compiled import jit


@jit
def bezier3(p0, p1, p2, p3, s):
    """One coordinate of the cubic Bezier curve and its derivative d/ds at s."""
    r = 1.0 - s
    b = r * r * r * p0 + 3.0 * r * r * s * p1 + 3.0 * r * s * s * p2 + s * s * s * p3
    db = 3.0 * r * r * (p1 - p0) + 6.0 * r * s * (p2 - p1) + 3.0 * s * s * (p3 - p2)
    return b, db


@jit
def rectangle_bezier(x0, y0, x1, y1, top, s):
    """Point (x, y) and tangent (dx/ds, dy/ds) of the rectangle Bezier from (x0, y0) to
    (x1, y1) with control points (x0, top), (x1, top) [m]."""
    x, dx = bezier3(x0, x0, x1, x1, s)
    y, dy = bezier3(y0, top, top, y1, s)
    return x, y, dx, dy
