"""MuJoCo as the oracle of the motion tests: its joint velocities after a span of constant
controls (tests/planarsim/test_envs_under_torque.py, test_mjcf_tendons.py,
tests/physics/test_joint_friction.py)."""
from __future__ import annotations


def mujoco_qvel(mujoco, mm, qp, qv, ctrl, dt, integrator, span, data=None, count="nefc"):
    """MuJoCo's qvel after `span` [s] of steps dt [s] with `integrator`, from qpos qp and qvel
    qv under constant ctrl; and the sum over the steps of data.<count> (constraint rows
    "nefc" or contacts "ncon") met on the way. `data`: an MjData to reuse (reset first)."""
    mm.opt.timestep, mm.opt.integrator = dt, integrator
    if data is None:
        data = mujoco.MjData(mm)
    else:
        mujoco.mj_resetData(mm, data)
    data.qpos[:], data.qvel[:], data.ctrl[:] = qp, qv, ctrl
    met = 0
    for _ in range(int(round(span / dt))):
        mujoco.mj_step(mm, data)
        met += getattr(data, count)
    return data.qvel.copy(), met
