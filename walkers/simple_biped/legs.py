"""Leg-level control laws of the Simple Biped (compiled), shared by every state.

Conventions: leg i joins the hip to foot i; d = foot - hip; leg length l = |d|; leg angle
phi = atan2(d_x, -d_y) [rad] (0 with the foot straight below the hip, positive with the foot
ahead, increasing counter-clockwise). Axial command u_i [N] pushes hip and foot apart. The hip
torque command u_2 [N m] turns leg 1 counter-clockwise relative to leg 0, so a torque tau on
leg i is u_2 = (2 i - 1) tau: left/right symmetry is this sign, not a second copy of the code.
"""
import math

from planarsim.compiled import jit

from walkers.common.pd import clamp

ACT_HIP = 2


@jit
def leg_state(q, v, i):
    """Leg i (foot body i + 1, hip body 0): d_x, d_y [m], l [m], l_dot [m/s], phi [rad], phi_dot [rad/s]."""
    dx = q[i + 1, 0] - q[0, 0]
    dy = q[i + 1, 1] - q[0, 1]
    wx = v[i + 1, 0] - v[0, 0]
    wy = v[i + 1, 1] - v[0, 1]
    l = math.sqrt(dx * dx + dy * dy)
    if l < 1e-9:
        return dx, dy, 1e-9, 0.0, 0.0, 0.0
    return dx, dy, l, (dx * wx + dy * wy) / l, math.atan2(dx, -dy), (dx * wy - dy * wx) / (l * l)


@jit
def push_hip(q, fx, fy, fmax, u):
    """Double stance: axial forces u[0], u[1] >= 0 with u_0 e_0 + u_1 e_1 = (fx, fy) on the hip,
    e_i = unit(hip - foot_i). Legs only push, so the vertical force has priority: fy is kept
    (>= 0) and fx is limited to the range that two pushing legs can give with that fy (the
    cone between the legs), then the 2x2 system is solved by Cramer's rule."""
    ex0 = q[0, 0] - q[1, 0]
    ey0 = q[0, 1] - q[1, 1]
    ex1 = q[0, 0] - q[2, 0]
    ey1 = q[0, 1] - q[2, 1]
    n0 = math.sqrt(ex0 * ex0 + ey0 * ey0)
    n1 = math.sqrt(ex1 * ex1 + ey1 * ey1)
    ex0 /= n0
    ey0 /= n0
    ex1 /= n1
    ey1 /= n1
    u[0] = 0.0
    u[1] = 0.0
    u[ACT_HIP] = 0.0
    det = ex0 * ey1 - ey0 * ex1
    if fy <= 0.0 or ey0 < 1e-6 or ey1 < 1e-6:
        return
    # horizontal force with all the load on leg 0 or on leg 1
    h0 = fy * ex0 / ey0
    h1 = fy * ex1 / ey1
    fx = clamp(fx, min(h0, h1), max(h0, h1))
    if abs(det) < 1e-6:
        u[0] = clamp(0.5 * fy / ey0, 0.0, fmax)
        u[1] = clamp(0.5 * fy / ey1, 0.0, fmax)
        return
    u[0] = clamp((fx * ey1 - fy * ex1) / det, 0.0, fmax)
    u[1] = clamp((ex0 * fy - ey0 * fx) / det, 0.0, fmax)


@jit
def push_hip_pendulum(q, front, f_n, f_t, f_front_min, f_rear_max, u):
    """Double stance with priority to the front leg's normal force (eq. 1): the hip force
    f_n n + f_t t [N] (n = unit(hip - front foot), t = (-n_y, n_x)) from u_f n + u_r e_r.
    The rear leg delivers f_t (u_r = f_t / (e_r . t)), limited to [0, f_rear_max] and so that
    it does not unload the front leg below f_front_min (a floor that binds only when
    f_n >= f_front_min); the front leg takes the rest of f_n, within [f_front_min, f_rear_max]."""
    rear = 1 - front
    nx = q[0, 0] - q[front + 1, 0]
    ny = q[0, 1] - q[front + 1, 1]
    ln = math.sqrt(nx * nx + ny * ny)
    nx /= ln
    ny /= ln
    ex = q[0, 0] - q[rear + 1, 0]
    ey = q[0, 1] - q[rear + 1, 1]
    le = math.sqrt(ex * ex + ey * ey)
    a = (-ny * ex + nx * ey) / le   # e_r . t
    b = (nx * ex + ny * ey) / le    # e_r . n
    f_front_min = min(f_front_min, max(f_n, 0.0))
    u_r = 0.0
    if abs(a) > 1e-3:
        hi = f_rear_max
        if b > 1e-9:
            hi = min(hi, (f_n - f_front_min) / b)
        u_r = clamp(f_t / a, 0.0, max(hi, 0.0))
    u[front] = clamp(f_n - u_r * b, f_front_min, f_rear_max)
    u[rear] = u_r
    u[ACT_HIP] = 0.0


@jit
def hold_stance(q, v, i, length, kp, kd, mass, gx, gy, fmax, u):
    """Single stance: axial force on leg i holding the hip at `length` [m] from the foot, as an
    inverted pendulum of `mass` [kg]: u = mass (kp (L - l) - kd l_dot - l phi_dot^2 - g.n),
    n = unit(hip - foot); saturated to [0, fmax] (a stance leg cannot pull on the ground)."""
    dx, dy, l, ldot, phi, phidot = leg_state(q, v, i)
    g_n = -(gx * dx + gy * dy) / l
    a = kp * (length - l) - kd * ldot - l * phidot * phidot
    u[i] = clamp(mass * (a - g_n), 0.0, fmax)


@jit
def track_foot(q, v, i, tx, ty, tvx, tvy, kp, kd, mass, gx, gy, lmax, fmax, tmax, u):
    """Virtual leg (Kelly 2014, 4.2): PD on leg i's length and angle toward the virtual leg from
    the hip to the target (tx, ty) [m] moving at (tvx, tvy) [m/s], plus the static force that
    holds the foot's weight (gravity compensation). The virtual leg is at most lmax [m] long.
    Writes u[i] and the hip torque u[2]."""
    dx, dy, l, ldot, phi, phidot = leg_state(q, v, i)
    # virtual leg and its rates relative to the hip
    vx = tx - q[0, 0]
    vy = ty - q[0, 1]
    wx = tvx - v[0, 0]
    wy = tvy - v[0, 1]
    lv = max(math.sqrt(vx * vx + vy * vy), 1e-6)
    lv_dot = (vx * wx + vy * wy) / lv
    if lv > lmax:
        lv = lmax
        lv_dot = 0.0
    phiv = math.atan2(vx, -vy)
    phiv_dot = (vx * wy - vy * wx) / (lv * lv)
    # foot weight: axial part and moment about the hip of the force -mass g
    u_g = -mass * (gx * dx + gy * dy) / l
    tau_g = -mass * (dx * gy - dy * gx)
    dphi = phiv - phi
    if dphi > math.pi:
        dphi -= 2.0 * math.pi
    elif dphi < -math.pi:
        dphi += 2.0 * math.pi
    u[i] = clamp(mass * (kp * (lv - l) + kd * (lv_dot - ldot)) + u_g, -fmax, fmax)
    tau = mass * l * l * (kp * dphi + kd * (phiv_dot - phidot)) + tau_g
    u[ACT_HIP] = clamp((2.0 * i - 1.0) * tau, -tmax, tmax)


@jit
def limit_hip_torque(q, stance, mu, foot_weight, u):
    """Saturate the hip torque u[2] so that the stance foot is not pushed out of a friction
    cone of coefficient mu about the world vertical: the force of both actuators on the stance
    foot, F = u_st (foot - hip)/l + s u_2 (-d_y, d_x)/l^2 (s = +1 on leg 1, -1 on leg 0), must
    satisfy |F_x| <= mu (-F_y + foot_weight). Both conditions are linear in u_2. The torque is
    only reduced toward 0, never increased or reversed."""
    dx = q[stance + 1, 0] - q[0, 0]
    dy = q[stance + 1, 1] - q[0, 1]
    l2 = dx * dx + dy * dy
    l = math.sqrt(l2)
    s = 2.0 * stance - 1.0
    ax = u[stance] * dx / l
    ay = u[stance] * dy / l
    bx = -s * dy / l2
    by = s * dx / l2
    lo = -math.inf
    hi = math.inf
    # sign * F_x - mu (-F_y + w) <= 0  ->  c0 + c1 u_2 <= 0
    for sign in (-1.0, 1.0):
        c0 = sign * ax + mu * ay - mu * foot_weight
        c1 = sign * bx + mu * by
        if c1 > 1e-12:
            hi = min(hi, -c0 / c1)
        elif c1 < -1e-12:
            lo = max(lo, -c0 / c1)
        elif c0 > 0.0:
            lo = 0.0
            hi = 0.0
    # saturation only: the result lies between 0 and the asked torque
    tau = u[ACT_HIP]
    if lo > hi:
        u[ACT_HIP] = 0.0
    else:
        u[ACT_HIP] = clamp(clamp(tau, lo, hi), min(tau, 0.0), max(tau, 0.0))
