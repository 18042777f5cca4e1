"""A dm_control task's env step as one compiled call: the action's commands, frame_skip physics
steps, MuJoCo's qpos / qvel, the readings (readout.read: the observation and the reward's
values) and the reward (dmc_rewards.task_reward).

An environment's own arrays (its joint map, drives, control, readings' table and reward
parameters) are one registered NamedTuple, ``DMCArrays``, handed to compiled code as one
pointer (compile/refs.py) beside the simulator's StepArgs handle. ``dmc_observe`` is the
readings and reward of the current state (a reset, an observation, a batched step's copy);
``dmc_step`` the whole env step (the fast compile mode only: elsewhere it would compile the
physics step into itself, and the env steps with Simulator.steps, then dmc_observe).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..compile import register
from ..compiled import jit
from ..link.step import run_steps
from .core import joint_values, set_commands
from .dmc_rewards import task_reward
from .readout import read

# dmc_step's code for an action of the wrong length or with a NaN or infinite entry (nothing
# changed); the guard codes (kernels/checks/guards.py) lie between -2 and 10
ACTION_REFUSED = -100


@register
class DMCArrays(NamedTuple):
    """An environment's arrays for dmc_observe / dmc_step."""
    q0: np.ndarray           # (n_body, 3) the file's pose [m, rad]
    qpos: np.ndarray         # (nq,) MuJoCo's qpos, written (env.data.qpos)
    qvel: np.ndarray         # (nq,) MuJoCo's qvel, written (env.data.qvel)
    cs: np.ndarray           # (n_body, 3) joint_values' buffer of cos / sin
    pins: np.ndarray         # (nq,) each MJCF joint's pin (int64)
    sign: np.ndarray         # (nq,) and its sign
    ref: np.ndarray          # (nq,) and its ref
    ctrl: np.ndarray         # (nu,) the last action as given
    lo: np.ndarray           # (nu,) ctrlrange's lower ends
    hi: np.ndarray           # (nu,) and upper
    entry: np.ndarray        # (drives,) each drive's action entry (int64)
    act_id: np.ndarray       # (drives,) its planarsim actuator (int64)
    gain: np.ndarray         # (drives,) its gear * coef
    u: np.ndarray            # (n_act,) the actuators' commands, written
    ops_i: np.ndarray        # the readings' table (readout.Readout.tables)
    ops_f: np.ndarray
    ids: np.ndarray
    weights: np.ndarray
    values: np.ndarray       # (n_obs + values,) the readings, written
    reward_p: np.ndarray     # the reward's parameters (dmc_rewards.reward_params)
    scratch: np.ndarray      # the reward's room
    n_obs: int               # the observation's entries (first in values)
    reward_code: int         # the domain's code (dmc_rewards)


@jit
def dmc_observe(args, e):
    """qpos, qvel and the readings of the state of StepArgs args into DMCArrays e; returns
    the reward."""
    m, s, ws = args.m, args.s, args.ws
    joint_values(m, s.q, s.v, e.cs, e.pins, e.sign, e.ref, e.qpos, e.qvel)
    read(s.q, s.v, e.q0, e.qpos, e.qvel, e.ctrl, s.last_contact_impulse, m.contact_kind,
         m.contact_body, m.contact_local, m.contact_radius, ws.contact_bodies, ws.contact_refpt,
         e.ops_i, e.ops_f, e.ids, e.weights, e.values)
    return task_reward(e.reward_code, e.values[e.n_obs:], e.reward_p, e.ctrl, e.scratch)


@jit
def dmc_step(args, e, action, n):
    """One env step of DMCArrays e on StepArgs args: the commands of `action` (clamped to
    ctrlrange, each drive's gain), n physics steps (run_steps), then e.ctrl = action and
    dmc_observe. Returns (code, steps completed, reward): code 0, or a guard code of the
    physics (e.ctrl and the readings left as they were), or ACTION_REFUSED (nothing
    changed: an action of another length than ctrl's, or not finite)."""
    if action.shape[0] != e.ctrl.shape[0]:
        return ACTION_REFUSED, 0, 0.0
    if not set_commands(action, e.lo, e.hi, e.entry, e.act_id, e.gain, e.u):
        return ACTION_REFUSED, 0, 0.0
    code, done = run_steps(args, e.u, n)
    if code != 0:
        return code, done, 0.0
    for k in range(action.shape[0]):
        e.ctrl[k] = action[k]
    return 0, n, dmc_observe(args, e)
