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


# [rad] a body's angle that changed by at most this since its (cos, sin) were computed has
# them turned by the change's series (turn_trig): cos d - (1 - d^2/2 + d^4/24) and
# sin d - d (1 - d^2/6 + d^4/120) are below d^6/720 ~ 1e-21 there, far below rounding
SERIES_TURN = 1e-3


@kernel
def turn_trig(q, cs):
    """update_trig for angles that moved by a correction (a few nanoradians): (cos, sin) of a
    body whose angle changed by d with |d| <= SERIES_TURN turned by d's series, exact to
    rounding, instead of computed afresh; others as update_trig. Each call turns the last
    (cos, sin) again, so it is for a few corrections after a fresh update_trig, not for a
    run of steps (rounding would add up)."""
    for i in range(q.shape[0]):
        th = q[i, 2]
        d = th - cs[i, 2]
        if d == 0.0 and math.copysign(1.0, th) == math.copysign(1.0, cs[i, 2]):
            continue
        if abs(d) <= SERIES_TURN:
            d2 = d * d
            cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0))
            sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)))
            c = cs[i, 0]
            s = cs[i, 1]
            cs[i, 0] = c * cd - s * sd
            cs[i, 1] = s * cd + c * sd
        else:
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
