"""Tiny 2D helpers: cross products, rotation, world points."""
import math

from ..compile import kernel


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
    """cs[i] = (cos, sin, angle) of body i's angle: computed once per configuration, and only
    for bodies whose angle changed (the same float, sign of zero included) since the last call:
    point masses and bodies at rest skip sin and cos."""
    for i in range(q.shape[0]):
        th = q[i, 2]
        if th == cs[i, 2] and math.copysign(1.0, th) == math.copysign(1.0, cs[i, 2]):
            continue
        cs[i, 0] = math.cos(th)
        cs[i, 1] = math.sin(th)
        cs[i, 2] = th


@kernel
def world_point(q, cs, body, lx, ly):
    """World position [m] of the point (lx, ly) fixed in `body` (cs: cached cos/sin of the
    body angles at q); body < 0 is the world frame."""
    if body < 0:
        return lx, ly
    rx, ry = rotate(cs[body, 0], cs[body, 1], lx, ly)
    return q[body, 0] + rx, q[body, 1] + ry


@kernel
def set_dir(q, body, px, py, dx, dy, sign, out):
    """out = sign * (dx, dy, (p - x_body) x d): the Jacobian block of a row along the unit
    direction d at world point p of `body` (zeros for the world, body < 0)."""
    if body < 0:
        out[0] = 0.0
        out[1] = 0.0
        out[2] = 0.0
        return
    out[0] = sign * dx
    out[1] = sign * dy
    out[2] = sign * cross2(px - q[body, 0], py - q[body, 1], dx, dy)
