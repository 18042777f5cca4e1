"""Measurements of a recorded run (a Trajectory) of any model: joint angles and rates, centre of
mass, energy, cost of transport, step events and whole-step summaries, in one place.

    from planarsim import measure
    angles = measure.joint_angles(traj, model)        # {pin name: (angle [rad], rate [rad/s])}
    x_com = measure.centre_of_mass(traj, model)        # (K, 2) [m]
    e = measure.energy(traj, model)["total"]           # (K,) [J]
    inst, avg = measure.cost_of_transport(traj, model) # positive actuator work per weight and distance
    s = measure.summary(traj, model)                   # whole steps: period, length, speed, CoT

For a controller (one state, not a recording): measure.pin_angle_rate(model, q, v, "hip"), or
planarsim.compiled.pin_angle_rate in compiled code.
"""
from __future__ import annotations

import math

import numpy as np

from .analysis import StepEvents, foot_groups, step_events, step_summary
from .checks import finite_number
from .energy import joint_position_rate
from .model import ACT_AXIAL
from .state import _body_rows
from .trajectory import check_recorded_by

__all__ = ["centre_of_mass", "centre_of_mass_velocity", "energy", "pin_angle_rate", "summary",
           "joint_angles", "cost_of_transport", "step_events", "step_summary", "StepEvents"]


def centre_of_mass(traj, model) -> np.ndarray:
    """(K, 2) centre of mass [m] per frame."""
    check_recorded_by(traj, model, "measure.centre_of_mass")
    return traj.com(model)


def centre_of_mass_velocity(traj, model) -> np.ndarray:
    """(K, 2) centre-of-mass velocity [m/s] per frame."""
    check_recorded_by(traj, model, "measure.centre_of_mass_velocity")
    return traj.com_velocity(model)


def energy(traj, model) -> dict:
    """{"kinetic", "potential", "total"}: (K,) [J] per frame."""
    check_recorded_by(traj, model, "measure.energy")
    return traj.energy(model)


def pin_angle_rate(model, q, v, pin) -> tuple:
    """Angle theta_b - theta_a - ref [rad] and rate [rad/s] of pin `pin` (name or index) at one
    state (q, v: (n_body, 3), e.g. sim.state.q, sim.state.v); a slider's slide [m] and its
    rate [m/s]."""
    names = list(model.pin_names)
    if isinstance(pin, str):
        if pin not in names:
            raise KeyError(f"no pin named {pin!r}; pins: {names}")
        pin = names.index(pin)
    elif not 0 <= int(pin) < len(names):
        raise IndexError(f"pin index {pin} out of range 0..{len(names) - 1}; pins: {names}")
    # one state, one row per body: a trajectory's (K, n_body, 3) frames or a transposed array
    # would be read as other bodies' numbers (or fail inside numpy)
    q = _body_rows("measure.pin_angle_rate: q", q, model.n_body)
    v = _body_rows("measure.pin_angle_rate: v", v, model.n_body)
    ang, rate = joint_position_rate(model, q, v, int(pin))
    return float(ang), float(rate)


MIN_STRIDE = 0.02   # [m] a landing is a step when the foot lands this far from where it lifted
MIN_TRANSPORT = 0.1     # [m] the least distance a cost of transport is reported for


def summary(traj, model, feet=None, min_air=0.05, together=0.05, min_stride=MIN_STRIDE) -> dict:
    """Whole-step summary of any recorded run (planarsim.analysis.step_summary): feet default
    to the contacts grouped by name (a box foot's corners are one foot); a landing is a step
    when the foot was off the ground at least min_air [s] and lands at least min_stride [m]
    from where it lifted (a model that stands, rocks or hops in place makes none); feet
    landing within `together` [s] of each other land once. Adds distance [m] and mean_speed
    [m/s] of the centre of mass over the whole recording."""
    check_recorded_by(traj, model, "measure.summary")
    feet = foot_groups(traj.contact_names) if feet is None else feet
    out = step_summary(traj, model, feet=feet, min_air=min_air, together=together,
                       min_stride=min_stride)
    com = traj.com(model)
    t = np.asarray(traj.t)
    dist = float(com[-1, 0] - com[0, 0]) if len(com) else 0.0
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    out.update(distance=dist, mean_speed=dist / span if span > 0 else math.nan)
    return out


def joint_angles(traj, model) -> dict:
    """{name: (angle (K,) [rad], rate (K,) [rad/s])} for every pin (a slider: slide [m], rate
    [m/s]), else for every rod and
    axial actuator segment (angle from the downward vertical)."""
    check_recorded_by(traj, model, "measure.joint_angles")
    a = model.arrays
    out = {}
    q, v = traj.q, traj.v
    for j, name in enumerate(model.pin_names):
        out[name] = joint_position_rate(model, q, v, j)
    if out:
        return out
    segs = [(n, a.rod_body[j], a.rod_anchor[j]) for j, n in enumerate(model.rod_names)]
    segs += [(model.act_names[j], a.act_body[j, :2], a.act_anchor[j])
             for j in range(model.n_act) if a.act_kind[j] == ACT_AXIAL]
    for name, bodies, anchors in segs:
        p, pv = [], []
        for side in range(2):
            b, loc = bodies[side], anchors[side]
            if b < 0:
                p.append(np.broadcast_to(loc, (len(q), 2)))
                pv.append(np.zeros((len(q), 2)))
                continue
            c, s = np.cos(q[:, b, 2]), np.sin(q[:, b, 2])
            r = np.column_stack([c * loc[0] - s * loc[1], s * loc[0] + c * loc[1]])
            p.append(q[:, b, :2] + r)
            pv.append(v[:, b, :2] + v[:, b, 2:3] * np.column_stack([-r[:, 1], r[:, 0]]))
        d, dv = p[1] - p[0], pv[1] - pv[0]
        ang = np.arctan2(d[:, 0], -d[:, 1])
        rate = (d[:, 0] * dv[:, 1] - d[:, 1] * dv[:, 0]) / np.maximum((d * d).sum(axis=1), 1e-300)
        out[name] = (np.unwrap(ang), rate)
    return out


def cost_of_transport(traj, model, power=None, min_distance=MIN_TRANSPORT):
    """(instantaneous CoT (K,) [-], averaged CoT [-]) from positive actuator power, or from
    `power` (K,) [W]. The average is work / (m g |x_end - x_start|), nan where the COM moved
    less than min_distance [m] (default MIN_TRANSPORT, 0.1 m, as the walkers' summaries: a
    gait in place that drifted 3 mm while its motors did 39 J reported a CoT of 117); the
    work each frame's power times the time since the frame before (a frame's power is the
    mean over the steps since that frame: exact however sparse the frames)."""
    check_recorded_by(traj, model, "measure.cost_of_transport")
    finite_number("measure.cost_of_transport: min_distance", min_distance, 0.0, unit=" m")
    if power is None:
        power = np.clip(traj.act_power, 0.0, None).sum(axis=1) if traj.act_power.size else np.zeros(len(traj.t))
    power = np.asarray(power, float)
    weight = model.total_mass * float(np.hypot(*model.arrays.gravity))
    speed = traj.com_velocity(model)[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        inst = power / (weight * np.abs(speed))
    inst[~np.isfinite(inst)] = np.nan
    com = traj.com(model)
    dist = abs(com[-1, 0] - com[0, 0]) if len(com) else 0.0
    work = float(np.sum(power[1:] * np.diff(traj.t))) if len(traj.t) > 1 else 0.0
    avg = work / (weight * dist) if dist >= max(min_distance, 1e-12) and weight > 0 else math.nan
    return inst, avg
