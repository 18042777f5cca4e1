"""Velocities at an instant and velocities over a step.

The step is symplectic Euler with SHAKE constraints:
    v_{n+1} = v_n + h M^-1 (f(q_n) + J(q_n)^T lambda),   q_{n+1} = q_n + h v_{n+1},
    c(q_{n+1}) = 0,
so the velocity a State carries is the velocity over the step just taken. Read as the
leapfrog's half-step velocity v_{n+1/2}, the positions are those of Stoermer-Verlet / SHAKE,
second order in h. A velocity known at an instant t_n (a section state, a measured start)
that is put in as v_n, or a State's velocity read out as the velocity at t_n, is off by half a
kick, h/2 M^-1 f = O(h): the one first-order error of a stride between located events (a
step-to-step map of the simplest walker: map error 5.5e-3 -> 4.9e-6 at dt 1e-3 s with both
ends converted, then second order).

to_step_velocity    v(t_n) -> the velocity the next step expects, v - h/2 M^-1 f. The
                    constraint reactions' half kick lies along M^-1 J(q_n)^T, which the next
                    step's impulses set anyway (for rods, pins and contacts that stay held).
to_instant_velocity the velocity over the last step -> v(t_n): v + h/2 M^-1 f, projected onto
                    the constraints at q_n (project_velocities), which removes the reactions'
                    half kick.
Applied forces: gravity, pushes (State.ext_force), actuator commands u (saturated), a slider
rotor's velocity-product forces and the springs a step of h takes as forces, as the step
applies them (kernels/dynamics/forces.apply_forces); the joint springs and dampers it solves
implicitly are not included.
"""
from __future__ import annotations

import math

import numpy as np

from . import dense
from .errors import ModelError
from .compile import jit
from .kernels.codes import JOINT_FREE_BIT, JOINT_SLIDER
from .kernels.dynamics.forces import kick as forces_kick


@jit
def kick(m, s, ws, u, h, step):
    """s.v += h M^-1 f [m/s, rad/s] with f the applied forces at s that a step of `step` [s]
    applies (kernels/dynamics/forces.kick), callable from Python."""
    forces_kick(m, s, ws, u, h, step)


def _commands(model, u):
    u = np.zeros(model.n_act) if u is None else np.ascontiguousarray(u, dtype=np.float64)
    if u.shape != (model.n_act,):
        raise ValueError(f"u has shape {u.shape}; the model has {model.n_act} actuators")
    return u


def _no_sliders(model, who):
    a = model.arrays
    for j in range(model.n_pin):
        if a.pin_kind[j] == JOINT_SLIDER:
            raise ModelError(f"{who}: slider joint {j} ({model.pin_names[j]!r}) is not supported "
                             "(rods, hinge pins and pinned contacts only)")


def _no_rotors(model, who):
    """ModelError naming the first joint with a rotor (armature): the half kick and the
    projection weigh the bodies alone, without the rotor's inertia on the joint's rate (a
    flywheel with a rotor of its own inertia ended 2 % short of its exact angle)."""
    a = model.arrays
    for j in range(model.n_pin):
        if a.pin_armature[j] != 0.0:
            raise ModelError(f"{who}: joint {j} ({model.pin_names[j]!r}) has a rotor (armature "
                             f"{a.pin_armature[j]:g}), which is not supported (joints without "
                             "armature only)")


def to_step_velocity(model, state, ws, h: float, u=None) -> None:
    """State's velocity known at its instant -> the velocity the next step of h [s] expects
    (in place): v - h/2 M^-1 f (module docstring). Joints with a rotor (armature) are refused
    (ModelError)."""
    _no_rotors(model, "to_step_velocity")
    kick(model.arrays, state, ws, _commands(model, u), -0.5 * float(h), float(h))


def to_instant_velocity(model, state, ws, h: float, u=None, pinned=()) -> None:
    """State's velocity over the last step of h [s] -> its velocity at its instant (in place):
    v + h/2 M^-1 f, projected onto the rods, pins and the contacts in `pinned` at its q.
    Sliders and joints with a rotor (armature) are refused (ModelError)."""
    _no_sliders(model, "to_instant_velocity")
    _no_rotors(model, "to_instant_velocity")
    kick(model.arrays, state, ws, _commands(model, u), 0.5 * float(h), float(h))
    state.v[...] = project_velocities(model, state.q, state.v, pinned)


def _point_rows(q, b, local):
    """World lever arm of a body-fixed point and the (2, 3) rows mapping the body velocity
    (vx, vy, omega) to the point velocity."""
    c, sn = math.cos(q[b, 2]), math.sin(q[b, 2])
    rx, ry = c * local[0] - sn * local[1], sn * local[0] + c * local[1]
    return np.array([[1.0, 0.0, -ry], [0.0, 1.0, rx]]), np.array([q[b, 0] + rx, q[b, 1] + ry])


def project_velocities(model, q, v, pinned=()) -> np.ndarray:
    """Velocities (n_body, 3) made consistent with the model's rods and hinge pins and with the
    contacts in `pinned` (their points at rest) at configuration q, by the mass-weighted
    projection v - W J^T (J W J^T)^+ J v (the smallest kinetic-energy change).

    The step leaves velocities tangent to the constraints of the START of the step, O(h) off
    those at its end; a state read at its instant, or a shorter step taken from it, needs them
    consistent with its own configuration. Slider joints and joints with a rotor (armature)
    are refused (ModelError)."""
    _no_sliders(model, "project_velocities")
    _no_rotors(model, "project_velocities")
    a = model.arrays
    nb = model.n_body
    w = np.c_[a.body_inv_mass, a.body_inv_mass, a.body_inv_inertia].ravel()
    rows = []

    def point(b, local):
        Jb, p = _point_rows(q, b, local)
        full = np.zeros((2, 3 * nb))
        full[:, 3 * b:3 * b + 3] = Jb
        return full, p

    for j in range(model.n_rod):
        (ba, bb), (la, lb) = a.rod_body[j], a.rod_anchor[j]
        Ja, pa = point(ba, la) if ba >= 0 else (np.zeros((2, 3 * nb)), la)
        Jb, pb = point(bb, lb) if bb >= 0 else (np.zeros((2, 3 * nb)), lb)
        e = (pb - pa) / np.hypot(*(pb - pa))
        rows.append(dense.matmul((Jb - Ja).T, e))
    for j in range(model.n_pin):
        if a.pin_kind[j] & JOINT_FREE_BIT:
            continue        # a free body's coordinate: measured, holds nothing
        (ba, bb), (la, lb) = a.pin_body[j], a.pin_anchor[j]
        Ja = point(ba, la)[0] if ba >= 0 else np.zeros((2, 3 * nb))
        Jb = point(bb, lb)[0] if bb >= 0 else np.zeros((2, 3 * nb))
        rows.extend(Jb - Ja)
    for c in pinned:
        rows.extend(point(a.contact_body[c], a.contact_local[c])[0])
    if not rows:
        return v.copy()
    J = np.array(rows)
    x = v.ravel()
    # (planarsim.dense: the same bits on every CPU, where numpy's BLAS kernels differ)
    A = dense.matmul(J * w, J.T)
    mu = dense.solve_psd(A, dense.matmul(J, x), 1e-12)
    return (x - w * dense.matmul(J.T, mu)).reshape(nb, 3)
