"""The slider (prismatic) joint's rows: two equalities and the slide coordinate.

A slider j (model.pin_kind[j] == JOINT_SLIDER) between body a (-1: the world) and body b has
an axis d0 fixed in a's frame (model.pin_axis; world if a < 0) and anchors p_a, p_b (model.
pin_anchor). With d = R(theta_a) d0 the axis in the world and n = (-d_y, d_x) its normal:
  ROW_SLIDE_PERP   n.(p_b - p_a) = 0 [m]: anchor b on the axis line through anchor a;
  ROW_SLIDE_ANGLE  theta_b - theta_a - ref = 0 [rad]: no relative rotation;
  slide            s = d.(p_b - p_a) [m], the joint's coordinate (limits, springs, motor).
Both n and d turn with body a: d/dt (n.e) = n.(v_pb - v_pa) - omega_a d.e (e = p_b - p_a),
which is the row of a pin along n with a's point taken at p_b (the point of a that p_b is
passing): J_a = -(n, (p_b - x_a) x n), J_b = (n, (p_b - x_b) x n). Likewise the slide's rate
is J_s v with J_a = -(d, (p_b - x_a) x d), J_b = (d, (p_b - x_b) x d), exact at any q.
Its limit rows (ROW_LIMIT_LO / HI, limit.py's kinds) are s - lower >= 0 and upper - s >= 0.
"""
import math

from ...compile import kernel
from ..codes import JOINT_SLIDE_BIT, ROW_SLIDE_ANGLE, ROW_SLIDE_PERP
from ..math2d import set_dir, world_point
from .row_list import add_row


@kernel
def slider_frame(m, q, cs, o, a, b):
    """Slider o's world axis (dx, dy) and its anchors (ax, ay), (bx, by) [m] at q."""
    ux = m.pin_axis[o, 0]
    uy = m.pin_axis[o, 1]
    if a >= 0:
        c = cs[a, 0]
        s = cs[a, 1]
        dx = c * ux - s * uy
        dy = s * ux + c * uy
    else:
        dx = ux
        dy = uy
    ax, ay = world_point(q, cs, a, m.pin_anchor[o, 0, 0], m.pin_anchor[o, 0, 1])
    bx, by = world_point(q, cs, b, m.pin_anchor[o, 1, 0], m.pin_anchor[o, 1, 1])
    return dx, dy, ax, ay, bx, by


@kernel
def slider_dir_row(q, a, b, bx, by, dx, dy, J):
    """J (2, 3) of d/dt [u.(p_b - p_a)] for a direction u = (dx, dy) turning with body a:
    both blocks act at the point p_b (see the module's docstring)."""
    set_dir(q, a, bx, by, dx, dy, -1.0, J[0])
    set_dir(q, b, bx, by, dx, dy, 1.0, J[1])


@kernel
def slider_perp_row(m, q, cs, o, a, b, J):
    """Jacobian blocks J (2, 3) and error [m] of slider o's perpendicular row: n.(p_b - p_a)."""
    dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, o, a, b)
    slider_dir_row(q, a, b, bx, by, -dy, dx, J)
    return -dy * (bx - ax) + dx * (by - ay)


@kernel
def slider_angle_row(m, q, o, a, b, J):
    """Jacobian blocks J (2, 3) and error [rad] of slider o's angle row:
    theta_b - theta_a - ref (also a hinge's coordinate row, joints.joint_rate_row)."""
    for k in range(3):
        J[0, k] = 0.0
        J[1, k] = 0.0
    ang = q[b, 2] - m.pin_ref[o]
    if a >= 0:
        ang -= q[a, 2]
        J[0, 2] = -1.0
    J[1, 2] = 1.0
    return ang


@kernel
def slide_row(m, q, cs, o, a, b, J):
    """Jacobian blocks J (2, 3) of slider o's slide rate and the slide s = d.(p_b - p_a) [m]."""
    dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, o, a, b)
    slider_dir_row(q, a, b, bx, by, dx, dy, J)
    return dx * (bx - ax) + dy * (by - ay)


@kernel
def slide_position_rate(m, q, cs, v, o):
    """Slider o's slide s [m] and its rate ds/dt [m/s] at (q, v)."""
    a = m.pin_body[o, 0]
    b = m.pin_body[o, 1]
    dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, o, a, b)
    s = dx * (bx - ax) + dy * (by - ay)
    # J_s v with both blocks at p_b
    rate = dx * (v[b, 0] - v[b, 2] * (by - q[b, 1])) + dy * (v[b, 1] + v[b, 2] * (bx - q[b, 0]))
    if a >= 0:
        rate -= (dx * (v[a, 0] - v[a, 2] * (by - q[a, 1]))
                 + dy * (v[a, 1] + v[a, 2] * (bx - q[a, 0])))
    return s, rate


@kernel
def slider_gap(m, q, cs, o):
    """How far slider o is off [m]: anchor b's distance from the axis line (the audit's
    pin_gap; its angle row is held by the position correction, not audited)."""
    a = m.pin_body[o, 0]
    b = m.pin_body[o, 1]
    dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, o, a, b)
    return abs(-dy * (bx - ax) + dx * (by - ay))


@kernel
def slider_lever(m, o, e):
    """|x| + |y| [m] bound of the lever of slider o's perpendicular row on body slot e, where
    its error is linear in a point (body a the world, the axis fixed: anchor b's); inf where
    the axis turns with body a."""
    if m.pin_body[o, 0] >= 0:
        return math.inf
    return abs(m.pin_anchor[o, e, 0]) + abs(m.pin_anchor[o, e, 1])


@kernel
def add_slider_rows(m, ws, n, j):
    """Append slider j's perpendicular and angle rows at slot n; returns the next free slot."""
    n = add_row(ws, n, ROW_SLIDE_PERP, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return add_row(ws, n, ROW_SLIDE_ANGLE, j, m.pin_body[j, 0], m.pin_body[j, 1])


@kernel
def _rotor_blocks(q, v, a, b, dx, dy, bx, by):
    """For a slide rate phi = g(q) v (module docstring: both blocks at anchor b, axis d turning
    with body a): (phi [m/s], g's blocks, the blocks of its time derivative g' = D_q g [v],
    grad_q phi at v), each 6-tuple ordered body a (x, y, theta), body b (x, y, theta)."""
    wa = v[a, 2] if a >= 0 else 0.0
    wb = v[b, 2]
    rbx = bx - q[b, 0]
    rby = by - q[b, 1]
    rax = bx - q[a, 0] if a >= 0 else 0.0
    ray = by - q[a, 1] if a >= 0 else 0.0
    vax = v[a, 0] if a >= 0 else 0.0
    vay = v[a, 1] if a >= 0 else 0.0
    # the axis turns with a; r_b = p_b - x_b with b; r_a = p_b - x_a as p_b and x_a move
    ddx = -wa * dy
    ddy = wa * dx
    drbx = -wb * rby
    drby = wb * rbx
    drax = v[b, 0] + drbx - vax
    dray = v[b, 1] + drby - vay
    ca = rax * dy - ray * dx           # cross(r_a, d)
    cb = rbx * dy - rby * dx           # cross(r_b, d)
    g = (-dx, -dy, -ca, dx, dy, cb)
    gd = (-ddx, -ddy, -(drax * dy - dray * dx + rax * ddy - ray * ddx),
          ddx, ddy, drbx * dy - drby * dx + rbx * ddy - rby * ddx)
    # grad_q phi: x_a and x_b through r_a, theta_a through d, theta_b through r_b and r_a
    nx = -dy
    ny = dx
    grad = (wa * dy, -wa * dx,
            (nx * (v[b, 0] - vax) + ny * (v[b, 1] - vay) + wb * (rbx * ny - rby * nx)
             - wa * (rax * ny - ray * nx)),
            -wa * dy, wa * dx, (wb - wa) * (-rby * dy - rbx * dx))
    phi = dx * (v[b, 0] - vax) + dy * (v[b, 1] - vay) + wb * cb - wa * ca
    return phi, g, gd, grad


@kernel
def add_rotor_forces(m, q, cs, v, f):
    """Add to f [N, N m] the velocity-product forces of each slider's rotor (armature a on its
    slide s): its kinetic energy a (g v)^2 / 2 has a row g that depends on q (the axis turns
    with body a, the anchor with body b), so Lagrange's equations give, besides the inertia
    a g^T g the velocity solve holds (soft.py),

        -a ((g' v) g^T + (g v) (g'^T - grad_q (g v))),     g' = D_q g [v],

    which keep the energy of the bodies and the rotor together: their power on the bodies,
    -a (g v)(g' v), is minus the rotor's energy change that the turning of its row makes. A
    hinge's rate w_b - w_a has a constant row: none. Without them a rotor on a slider whose
    rail turns gained energy at any step (a cart on a spinning rail: 0.47 J -> 1.34 J in
    2 s, and the same 1.34 J at a sixteenth of the step)."""
    for j in range(m.pin_armature.shape[0]):
        arm = m.pin_armature[j]
        if arm == 0.0 or (m.pin_kind[j] & JOINT_SLIDE_BIT) == 0:
            continue
        a = m.pin_body[j, 0]
        b = m.pin_body[j, 1]
        dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, j, a, b)
        phi, g, gd, grad = _rotor_blocks(q, v, a, b, dx, dy, bx, by)
        psi = 0.0
        for e in range(2):
            body = a if e == 0 else b
            if body >= 0:
                for k in range(3):
                    psi += gd[3 * e + k] * v[body, k]
        for e in range(2):
            body = a if e == 0 else b
            if body >= 0:
                for k in range(3):
                    i = 3 * e + k
                    f[body, k] -= arm * (psi * g[i] + phi * (gd[i] - grad[i]))
