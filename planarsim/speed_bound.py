"""The speed bound a run is held to (StepOptions.speed_limit = -1, the default): 100 times the
fastest speed the model can explain, so that a run gone unphysical (a body at 1e5 m/s) stops
at once with the body named, long before the magnitude guard (1e10) would.

The speeds the model explains [m/s]:
  fall      sqrt(2 |g| (H + L)): a fall from the highest body's height above the ground H plus
            the model's size L (the span of its bodies and contact points, at least 1 m); a
            model without ground (ModelBuilder(ground=None)) under gravity has no bound (0)
  start     the fastest body's speed, or turning speed |omega| r_g, at the start
  actuators each actuator's largest force or torque acting for one second on the lightest
            body it moves: F / m, or tau / (m r_g) (r_g = sqrt(I / m))
  springs   each joint spring's energy at the start, k (x - rest)^2 / 2, all given to the
            lightest body it moves: sqrt(2 E / m) (as a speed, and as a turning speed
            |omega| r_g, sqrt(2 E / I) r_g alike)
A body's speed and its turning speed are both held to the bound (guards.check_speeds).
"""
from __future__ import annotations

import math

import numpy as np

from .energy import joint_position_rate

SPEED_MARGIN = 100.0
MIN_SPEED = 1.0      # [m/s] the smallest speed scale a model is given
MIN_SIZE = 1.0       # [m]


def _turning(model, v):
    """|omega| r_g of each body [m/s] at velocities v (n_body, 3)."""
    a = model.arrays
    return np.abs(v[:, 2]) * np.sqrt(a.body_inertia * a.body_inv_mass)


def speed_bound(model, v=None, q=None) -> float:
    """SPEED_MARGIN times the largest of the speeds the module docstring lists [m/s], for
    the model started at positions q and velocities v (default: the model's own)."""
    a = model.arrays
    q = model.q0 if q is None else np.asarray(q, dtype=float)
    v = model.v0 if v is None else np.asarray(v, dtype=float)
    points = [q[:, :2]]
    if model.n_contact:
        points.append(q[a.contact_body, :2] + np.abs(a.contact_local).max())
    points = np.vstack(points)
    size = max(MIN_SIZE, float(np.ptp(points[:, 0])) + float(np.ptp(points[:, 1])))
    g = float(np.hypot(*a.gravity))
    if model.terrain is None and g > 0.0:
        return 0.0          # no ground: a body falls without end, no speed bounds it
    height = 0.0 if model.terrain is None else max(0.0, float(np.max(q[:, 1] - model.terrain.height(q[:, 0]))))
    speeds = [MIN_SPEED, math.sqrt(2.0 * g * (height + size))]
    if len(v):
        speeds.append(float(np.max(np.hypot(v[:, 0], v[:, 1]))))
        speeds.append(float(np.max(_turning(model, v))))
    for k in range(model.n_act):
        push = float(np.max(np.abs(a.act_range[k])))
        if not math.isfinite(push):
            return 0.0      # an unsaturated actuator: no bound explains its speeds
        for body in a.act_body[k]:
            if body < 0:
                continue
            mass = float(a.body_mass[body])
            r_g = math.sqrt(float(a.body_inertia[body]) / mass)
            speeds.append(push / mass)
            if r_g > 0.0:
                speeds.append(push / (mass * r_g))
    for j in range(model.n_pin):
        k = float(a.pin_stiffness[j])
        bodies = [int(b) for b in a.pin_body[j] if b >= 0]
        if k > 0.0 and bodies:
            x = joint_position_rate(model, q, np.zeros_like(q), j)[0]
            stored = 0.5 * k * (float(x) - float(a.pin_rest[j])) ** 2
            speeds.append(math.sqrt(2.0 * stored / min(float(a.body_mass[b]) for b in bodies)))
    return SPEED_MARGIN * max(speeds)


def resolve_speed_limit(options, model, v=None, q=None):
    """options with speed_limit = -1 (from the model) replaced by speed_bound(model, v, q)."""
    if options.speed_limit != -1.0:
        return options
    return options._replace(speed_limit=speed_bound(model, v, q))
