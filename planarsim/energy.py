"""Mechanical energy of a state: kinetic, gravitational potential, pin springs [J]."""
from __future__ import annotations

import numpy as np


def _scalar_or_array(x):
    return float(x) if np.ndim(x) == 0 else x


def kinetic_energy(model, q, v):
    """sum 1/2 m |v|^2 + 1/2 I w^2 [J]; q, v of shape (..., n_body, 3)."""
    a = model.arrays
    v = np.asarray(v)
    ke = 0.5 * np.sum(a.body_mass * (v[..., 0] ** 2 + v[..., 1] ** 2) + a.body_inertia * v[..., 2] ** 2, axis=-1)
    return _scalar_or_array(ke)


def potential_energy(model, q, v=None):
    """-sum m g.x plus pin-spring energy 1/2 k (angle - rest)^2 [J]."""
    a = model.arrays
    q = np.asarray(q)
    pe = -np.sum(a.body_mass * (a.gravity[0] * q[..., 0] + a.gravity[1] * q[..., 1]), axis=-1)
    for j in range(model.n_pin):
        k = a.pin_stiffness[j]
        if k:
            ba, bb = a.pin_body[j]
            ang = q[..., bb, 2] - a.pin_ref[j] - (q[..., ba, 2] if ba >= 0 else 0.0)
            pe = pe + 0.5 * k * (ang - a.pin_rest[j]) ** 2
    return _scalar_or_array(pe)


def total_energy(model, q, v):
    return kinetic_energy(model, q, v) + potential_energy(model, q)
