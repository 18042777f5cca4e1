"""Mechanical energy of a state: kinetic (bodies and joint armatures), gravitational
potential, joint springs [J]."""
from __future__ import annotations

import numpy as np

from .kernels.codes import JOINT_SLIDE_BIT


def joint_position_rate(model, q, v, j):
    """Joint j's coordinate and rate at q, v of shape (..., n_body, 3): a hinge's angle
    theta_b - theta_a - ref [rad] and rate [rad/s]; a slider's slide s = d.(p_b - p_a) [m] and
    ds/dt [m/s] (kernels/constraints/slider.py)."""
    a = model.arrays
    q = np.asarray(q)
    v = np.asarray(v)
    ba, bb = a.pin_body[j]
    if not a.pin_kind[j] & JOINT_SLIDE_BIT:
        ang = q[..., bb, 2] - a.pin_ref[j] - (q[..., ba, 2] if ba >= 0 else 0.0)
        rate = v[..., bb, 2] - (v[..., ba, 2] if ba >= 0 else 0.0)
        return ang, rate

    def point(body, loc):
        if body < 0:
            return loc[0] + 0.0 * q[..., 0, 0], loc[1] + 0.0 * q[..., 0, 0]
        c, s = np.cos(q[..., body, 2]), np.sin(q[..., body, 2])
        return q[..., body, 0] + c * loc[0] - s * loc[1], q[..., body, 1] + s * loc[0] + c * loc[1]

    ux, uy = a.pin_axis[j]
    if ba >= 0:
        c, s = np.cos(q[..., ba, 2]), np.sin(q[..., ba, 2])
        dx, dy = c * ux - s * uy, s * ux + c * uy
    else:
        dx, dy = ux, uy
    ax, ay = point(ba, a.pin_anchor[j, 0])
    bx, by = point(bb, a.pin_anchor[j, 1])
    slide = dx * (bx - ax) + dy * (by - ay)

    def velocity_at(body):   # velocity of the point of `body` at anchor b
        if body < 0:
            return 0.0, 0.0
        return (v[..., body, 0] - v[..., body, 2] * (by - q[..., body, 1]),
                v[..., body, 1] + v[..., body, 2] * (bx - q[..., body, 0]))

    vbx, vby = velocity_at(bb)
    vax, vay = velocity_at(ba)
    return slide, dx * (vbx - vax) + dy * (vby - vay)


def _body_frames(model, x, name, who):
    """x as an array of shape (..., n_body, 3), or a ValueError naming `who` and `name` (a
    state of another model's bodies was broadcast against this one's masses silently)."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {name}={x!r} must be numbers of shape (..., {model.n_body}, 3)") from None
    if arr.shape[-2:] != (model.n_body, 3):
        raise ValueError(f"{who}: {name} has shape {arr.shape}; it must be (..., {model.n_body}, 3): "
                         f"one row per body of the model ({list(model.body_names)})")
    return arr


def _scalar_or_array(x):
    return float(x) if np.ndim(x) == 0 else x


def kinetic_energy(model, q, v):
    """sum 1/2 m |v|^2 + 1/2 I w^2, plus each joint armature's 1/2 a rate^2 [J]; q, v of
    shape (..., n_body, 3)."""
    a = model.arrays
    q = _body_frames(model, q, "q", "kinetic_energy")
    v = _body_frames(model, v, "v", "kinetic_energy")
    ke = 0.5 * np.sum(a.body_mass * (v[..., 0] ** 2 + v[..., 1] ** 2) + a.body_inertia * v[..., 2] ** 2, axis=-1)
    for j in range(model.n_pin):
        if a.pin_armature[j] > 0.0:
            ke = ke + 0.5 * a.pin_armature[j] * joint_position_rate(model, q, v, j)[1] ** 2
    return _scalar_or_array(ke)


def potential_energy(model, q, v=None):
    """-sum m g.x plus joint-spring energy 1/2 k (coordinate - rest)^2 [J]."""
    a = model.arrays
    q = _body_frames(model, q, "q", "potential_energy")
    pe = -np.sum(a.body_mass * (a.gravity[0] * q[..., 0] + a.gravity[1] * q[..., 1]), axis=-1)
    for j in range(model.n_pin):
        k = a.pin_stiffness[j]
        if k:
            ang = joint_position_rate(model, q, np.zeros_like(q), j)[0]
            pe = pe + 0.5 * k * (ang - a.pin_rest[j]) ** 2
    return _scalar_or_array(pe)


def total_energy(model, q, v):
    return kinetic_energy(model, q, v) + potential_energy(model, q)
