"""Tiny 2D helpers: cross products, rotation, world points."""
import math

from ._jit import jit


@jit
def cross2(ax, ay, bx, by):
    """z component of a x b."""
    return ax * by - ay * bx


@jit
def rotate(c, s, x, y):
    """Rotate the local vector (x, y) by the angle with cosine c and sine s."""
    return c * x - s * y, s * x + c * y


@jit
def world_point(q, body, lx, ly):
    """World position [m] of the point (lx, ly) fixed in `body`; body < 0 is the world frame."""
    if body < 0:
        return lx, ly
    c = math.cos(q[body, 2])
    s = math.sin(q[body, 2])
    rx, ry = rotate(c, s, lx, ly)
    return q[body, 0] + rx, q[body, 1] + ry
