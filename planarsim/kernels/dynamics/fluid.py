"""MuJoCo's inertia-box fluid model in the plane: drag on boxes moving through a still fluid.

Each fluid box k (model.fluid_body, model.fluid_coef) sits on a body at a local centre c, with
its first in-plane axis u1 at angle alpha in the body's frame (u2 the second; the third axis
is the plane's normal). Its centre moving at v (components v1, v2 along u1, u2) and turning at
omega feels, explicitly at the step's start (as MuJoCo's passive forces):
  force  F_i = -(3 pi d mu) v_i - (1/2 rho l_j l_n) |v_i| v_i   along u_i (j the other axis)
  torque T   = -(pi d^3 mu) omega - (rho l_n (l_1^4 + l_2^4) / 64) |omega| omega
with mu the fluid's viscosity [Pa s], rho its density [kg/m^3], (l_1, l_2, l_n) the box's full
sides [m] and d their mean (MuJoCo's mj_inertiaBoxFluidModel restricted to the plane; the
coefficients are precomputed: fluid_coef = (cx, cy, alpha, 3 pi d mu, pi d^3 mu,
rho l_2 l_n / 2, rho l_1 l_n / 2, rho l_n (l_1^4 + l_2^4) / 64)). The force acts at the
centre. It only takes energy out (each term opposes its own velocity component).
"""
import math

from ...compile import kernel
from ..math2d import cross2, rotate


@kernel
def apply_fluid(m, q, cs, v, f):
    """Add every fluid box's drag force and torque to f (n_body, 3) at (q, v)."""
    for k in range(m.fluid_body.shape[0]):
        b = m.fluid_body[k]
        c = cs[b, 0]
        s = cs[b, 1]
        rx, ry = rotate(c, s, m.fluid_coef[k, 0], m.fluid_coef[k, 1])
        vx = v[b, 0] - v[b, 2] * ry
        vy = v[b, 1] + v[b, 2] * rx
        ca = math.cos(q[b, 2] + m.fluid_coef[k, 2])
        sa = math.sin(q[b, 2] + m.fluid_coef[k, 2])
        v1 = ca * vx + sa * vy
        v2 = -sa * vx + ca * vy
        lin = m.fluid_coef[k, 3]
        f1 = -lin * v1 - m.fluid_coef[k, 5] * abs(v1) * v1
        f2 = -lin * v2 - m.fluid_coef[k, 6] * abs(v2) * v2
        fx = ca * f1 - sa * f2
        fy = sa * f1 + ca * f2
        w = v[b, 2]
        f[b, 0] += fx
        f[b, 1] += fy
        f[b, 2] += cross2(rx, ry, fx, fy) - m.fluid_coef[k, 4] * w - m.fluid_coef[k, 7] * abs(w) * w
