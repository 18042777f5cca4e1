"""Tiny 2D helpers: cross products, rotation, world points."""
import math

from ._jit import kernel


@kernel
def cross2(ax, ay, bx, by):
    """z component of a x b."""
    return ax * by - ay * bx


@kernel
def rotate(c, s, x, y):
    """Rotate the local vector (x, y) by the angle with cosine c and sine s."""
    return c * x - s * y, s * x + c * y


@kernel
def update_trig(q, cs):
    """cs[i] = (cos, sin) of body i's angle: computed once per configuration."""
    for i in range(q.shape[0]):
        cs[i, 0] = math.cos(q[i, 2])
        cs[i, 1] = math.sin(q[i, 2])


@kernel
def world_point(q, cs, body, lx, ly):
    """World position [m] of the point (lx, ly) fixed in `body` (cs: cached cos/sin of the
    body angles at q); body < 0 is the world frame."""
    if body < 0:
        return lx, ly
    rx, ry = rotate(cs[body, 0], cs[body, 1], lx, ly)
    return q[body, 0] + rx, q[body, 1] + ry
