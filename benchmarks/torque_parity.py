"""gymnasium's planar models under constant motor commands against MuJoCo (not a test;
tests/planarsim/test_envs_under_torque.py asserts on hypothesis-drawn states).

    python -m benchmarks.torque_parity                  # 250 states per model
    python -m benchmarks.torque_parity --states 40 --models Hopper,Reacher

From random states drawn as the test draws them (each limited joint within the middle 40 % of
its range, hinges offset within 0.5 rad, rates within 1, the walkers' roots lifted 1 m) and
constant controls 0.3 or 1.0 with random signs, the joint velocities after 0.02 s at the
file's dt are compared with MuJoCo's RK4 at dt 1e-5 (the exact motion); states where MuJoCo
meets a contact or a limit, or planarsim a contact or a joint limit, are left out. Prints, per
model, our error over MuJoCo Euler's at the same dt: median, 90th percentile, largest, and how
many states exceed 3.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

MODELS = ("Hopper", "Walker2d", "HalfCheetah", "InvertedPendulum", "InvertedDoublePendulum",
          "Reacher", "Swimmer")
WALKERS = ("Hopper", "Walker2d", "HalfCheetah")
SPAN = 0.02     # [s]


def start_state(ref, fractions, speeds, lift):
    """(qpos, qvel) of gymnasium env `ref` (its MuJoCo model): each limited joint at
    `fractions` of its range, each free hinge offset by fractions - 0.5 rad; qvel = speeds
    [rad/s or m/s]; the root raised by lift [m]."""
    import mujoco
    m = ref.model
    qp = ref.init_qpos.copy()
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        if m.jnt_limited[j]:
            lo, hi = m.jnt_range[j]
            qp[a] = lo + fractions[j] * (hi - lo)
        elif m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            qp[a] += fractions[j] - 0.5
    qp[1] += lift
    return qp, np.asarray(speeds[:m.nv], float)


def our_qvel(name, qp, qv, u, dt):
    """(planarsim's joint velocities after SPAN at step dt from (qp, qv) under commands u,
    whether a contact or a joint limit acted at any of its steps, the audit's count)."""
    import gymnasium as gym
    import planarsim.envs  # noqa: F401  (registers the environments)
    from planarsim.kernels.codes import MODE_FREE
    env = gym.make(f"planarsim/{name}-v0", dt=dt, frame_skip=1).unwrapped
    env.reset(seed=0)
    env.set_state(qp, qv)
    touched = False
    for _ in range(int(round(SPAN / dt))):
        env.do_simulation(u, 1)
        state = env.sim.state
        touched |= bool(state.limit_active.any() or (state.contact_mode != MODE_FREE).any())
    return env.data.qvel.copy(), touched, int(env.sim.ws.audit.sum())


def ratios(name, states, seed=0):
    """Our error over MuJoCo Euler's on `states` random states of gymnasium's `name` file."""
    import gymnasium as gym
    import mujoco
    from mujoco_oracle import mujoco_qvel

    ref = gym.make(f"{name}-v5").unwrapped
    m, dt = ref.model, float(ref.model.opt.timestep)
    rng = np.random.default_rng([seed, sum(map(ord, name))])
    out = []
    for _ in range(states):
        fractions, speeds = rng.uniform(0.3, 0.7, 12), rng.uniform(-1.0, 1.0, 12)
        level, signs = rng.choice([0.3, 1.0]), rng.choice([-1.0, 1.0], 6)
        qp, qv = start_state(ref, fractions, speeds, 1.0 if name in WALKERS else 0.0)
        u = level * signs[:m.nu]
        exact, rows = mujoco_qvel(mujoco, m, qp, qv, u, 1e-5, mujoco.mjtIntegrator.mjINT_RK4,
                                  SPAN, data=ref.data)
        euler, more = mujoco_qvel(mujoco, m, qp, qv, u, dt, mujoco.mjtIntegrator.mjINT_EULER,
                                  SPAN, data=ref.data)
        ours, touched, _ = our_qvel(name, qp, qv, u, dt)
        if rows + more or touched:
            continue
        out.append(np.abs(ours - exact).max() / np.abs(euler - exact).max())
    return np.array(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=250)
    ap.add_argument("--models", default=",".join(MODELS))
    args = ap.parse_args(argv)
    print(f"{'model':24s} {'states':>6s} {'median':>7s} {'90th':>6s} {'largest':>8s} {'above 3':>8s}")
    for name in args.models.split(","):
        r = ratios(name, args.states)
        print(f"{name:24s} {r.size:6d} {np.median(r):7.2f} {np.percentile(r, 90):6.2f} "
              f"{r.max():8.2f} {int((r > 3).sum()):8d}")
    print("ours / MuJoCo Euler's error of the joint velocities after 0.02 s at the file's dt, "
          "both against MuJoCo RK4 at dt 1e-5")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
