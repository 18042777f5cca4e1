"""Helpers for step-to-step maps of actuated walkers (used by walkers/*/gait_map.py).

A map evaluation restores the complete simulation (State, the workspace arrays the controller
reads, controller memory), applies a perturbation of the section coordinates, runs a compiled
rollout to the next section event and reads the coordinates back. These helpers copy the
simulation snapshots and turn a perturbation of body angles / angular rates into body poses and
velocities that keep every pin of the model closed (kinematic chain from a root body).
"""
from __future__ import annotations

import math

import numpy as np


def copy_tuple(nt):
    """Deep copy of a NamedTuple of arrays (nested NamedTuples too)."""
    return type(nt)(*(copy_tuple(a) if isinstance(a, tuple) else np.array(a, copy=True) for a in nt))


def restore_tuple(dst, src) -> None:
    """Overwrite the arrays of NamedTuple `dst` in place with those of `src` (bit for bit)."""
    for a, b in zip(dst, src):
        if isinstance(a, tuple):
            restore_tuple(a, b)
        else:
            a[...] = b


def _rot(th, r):
    c, s = math.cos(th), math.sin(th)
    return np.array([c * r[0] - s * r[1], s * r[0] + c * r[1]])


def _cross_w(w, r):
    """omega x r for a planar rate w [rad/s] and lever r [m]."""
    return np.array([-w * r[1], w * r[0]])


def chain_poses(model, angles, root: int, root_pos) -> np.ndarray:
    """Body positions (n_body, 2) [m] with the given body angles [rad] such that every pin of the
    model joins its two anchors, body `root` at `root_pos`. Raises ValueError if a body is not
    reachable from the root through pins."""
    a = model.arrays
    nb = model.n_body
    pos = np.full((nb, 2), np.nan)
    pos[root] = root_pos
    done = {root}
    changed = True
    while changed:
        changed = False
        for j in range(model.n_pin):
            ba, bb = int(a.pin_body[j, 0]), int(a.pin_body[j, 1])
            la, lb = a.pin_anchor[j, 0], a.pin_anchor[j, 1]
            if ba < 0 or bb < 0:
                continue
            if ba in done and bb not in done:
                pos[bb] = pos[ba] + _rot(angles[ba], la) - _rot(angles[bb], lb)
                done.add(bb)
                changed = True
            elif bb in done and ba not in done:
                pos[ba] = pos[bb] + _rot(angles[bb], lb) - _rot(angles[ba], la)
                done.add(ba)
                changed = True
    if len(done) != nb:
        missing = [model.body_names[b] for b in range(nb) if b not in done]
        raise ValueError(f"bodies {missing} are not joined by pins to root body {model.body_names[root]!r}")
    return pos


def chain_velocities(model, q, rates, root: int, root_vel) -> np.ndarray:
    """Body velocities (n_body, 3) [m/s, rad/s] with angular rates `rates` [rad/s] that keep every
    pin closed at configuration q (n_body, 3), body `root` moving at root_vel (2,)."""
    a = model.arrays
    nb = model.n_body
    vel = np.full((nb, 2), np.nan)
    vel[root] = root_vel
    done = {root}
    changed = True
    while changed:
        changed = False
        for j in range(model.n_pin):
            ba, bb = int(a.pin_body[j, 0]), int(a.pin_body[j, 1])
            if ba < 0 or bb < 0:
                continue
            ra = _rot(q[ba, 2], a.pin_anchor[j, 0])
            rb = _rot(q[bb, 2], a.pin_anchor[j, 1])
            if ba in done and bb not in done:
                vel[bb] = vel[ba] + _cross_w(rates[ba], ra) - _cross_w(rates[bb], rb)
                done.add(bb)
                changed = True
            elif bb in done and ba not in done:
                vel[ba] = vel[bb] + _cross_w(rates[bb], rb) - _cross_w(rates[ba], ra)
                done.add(ba)
                changed = True
    if len(done) != nb:
        raise ValueError(f"bodies not joined by pins to root body {model.body_names[root]!r}")
    return np.c_[vel, rates]


class GaitMapMixin:
    """Shared analysis of a walker's gait map (the class supplies x0, names, step_map(); its
    section state, taken after the walker has settled, is the candidate fixed point)."""

    def residual(self) -> float:
        """|P(x0) - x0|_inf: how far the settled section state is from a fixed point."""
        return float(np.max(np.abs(self.step_map()(self.x0) - self.x0)))

    def jacobian(self, eps) -> np.ndarray:
        """Central finite-difference Jacobian (d, d) of the map at x0, step eps."""
        from planarsim.analysis import jacobian
        return jacobian(self.step_map(), self.x0, eps, central=True)

    def multipliers(self, eps) -> np.ndarray:
        """Floquet multipliers (eigenvalues of the Jacobian at x0), largest modulus first."""
        from planarsim.analysis import sort_multipliers
        return sort_multipliers(np.linalg.eigvals(self.jacobian(eps)))
