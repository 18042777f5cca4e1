"""Step-level summaries over whole steps, touchdown to touchdown.

Quantities taken between the first and the last touchdown of a run do not depend on where
in a step the run happens to end (the end of a run cuts a step anywhere; a partial step
moves the centre of mass forward without the matching energy loss, or the reverse).
"""
from __future__ import annotations

import math

import numpy as np

from ..trajectory import Trajectory
from .events import step_events


def frame_from_state(model, state, ws=None):
    """A one-frame Trajectory of a State (the frame record_frame would write; contacts that
    are disabled get mode -1)."""
    s = state
    mode = np.where(np.asarray(s.contact_enabled) != 0, s.contact_mode, -1)[None, :].astype(np.int64)
    nc, na = model.n_contact, model.n_act
    imp = np.array(ws.contact_impulse)[None] if ws is not None else np.zeros((1, nc, 2))
    pt = np.array(ws.contact_point)[None] if ws is not None else np.zeros((1, nc, 2))
    nrm = np.array(ws.contact_normal)[None] if ws is not None else np.full((1, nc, 2), np.nan)
    act_u = np.array(ws.act_u)[None] if ws is not None else np.zeros((1, na))
    act_p = np.array(ws.act_power)[None] if ws is not None else np.zeros((1, na))
    return Trajectory(t=np.array([float(s.time[0])]), q=np.array(s.q)[None], v=np.array(s.v)[None],
                      contact_mode=mode, contact_impulse=imp, contact_point=pt, act_u=act_u,
                      act_power=act_p, contact_normal=nrm, body_names=model.body_names, contact_names=model.contact_names,
                      act_names=model.act_names)


def step_summary(traj, model, contacts=None, direction=None, feet=None, min_air=0.0,
                 together=0.0, min_stride=0.0) -> dict:
    """Whole-step summary of a recorded run, from its first to its last touchdown
    (planarsim.analysis.step_events of `contacts`, default all, or of `feet`: groups of
    contacts that touch down as one, with min_air, together and min_stride: see step_events).

    direction : unit vector of travel (default +x); a walker on a slope passes the slope's
        downhill tangent to measure distance along the slope.
    Returns whole_steps (touchdowns - 1), step_period [s], step_length [m] (centre-of-mass
    displacement along direction per step), speed [m/s], cost_of_transport [-] (energy spent
    per weight and distance: the mechanical energy lost plus the actuators' net work, over
    (total mass x |g| x distance); a passive walker on a slope gamma gives sin(gamma); the
    work each frame's act_power times the time since the frame before),
    energy_spent [J], first_touchdown, last_touchdown [s]. NaN where fewer than two
    touchdowns (or no forward motion for the cost of transport).
    """
    ev = step_events(traj, contacts, feet, min_air, together, min_stride, model)
    out = dict(whole_steps=0, step_period=math.nan, step_length=math.nan, speed=math.nan,
               cost_of_transport=math.nan, energy_spent=math.nan, first_touchdown=math.nan,
               last_touchdown=math.nan)
    if len(ev) < 2:
        return out
    u = np.array([1.0, 0.0]) if direction is None else np.asarray(direction, dtype=np.float64)
    u = u / np.hypot(*u)
    a, b = int(ev.frame[0]), int(ev.frame[-1])
    n = len(ev) - 1
    t = np.asarray(traj.t)
    com = traj.com(model)
    energy = traj.energy(model)["total"]
    dist = float((com[b] - com[a]) @ u)
    T = float(t[b] - t[a])
    work = 0.0
    if traj.act_power.shape[1]:
        # a frame's power is the mean over the steps since the frame before: the steps of
        # frames a+1..b (as measure.cost_of_transport sums it)
        power = np.sum(traj.act_power[a + 1:b + 1], axis=1)
        work = float(np.sum(power * np.diff(t[a:b + 1])))
    spent = float(energy[a] - energy[b]) + work
    weight = float(np.sum(model.arrays.body_mass) * np.hypot(*model.arrays.gravity))
    out.update(whole_steps=n, step_period=T / n, step_length=dist / n,
               speed=dist / T if T > 0 else math.nan,
               cost_of_transport=spent / (weight * dist) if dist > 0 else math.nan,
               energy_spent=spent, first_touchdown=float(t[a]), last_touchdown=float(t[b]))
    return out
