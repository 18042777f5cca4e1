"""Random planar MJCF trees against MuJoCo (not a test; tests/planarsim/test_mjcf_tree_parity.py
asserts on a few of the same trees).

    python -m benchmarks.tree_parity                   # 120 trees, seeds 0..119
    python -m benchmarks.tree_parity --trees 40 --first 500

Each tree: 2 to 4 bodies in a chain, each on a hinge (axis y) or a slide (an axis in the x-z
plane), the joint off the body's origin; each joint with or without armature (0.01-2), a
spring (1-50) and a damper (0.01-1), drawn independently; capsules of 0.1-3 kg; gravity on,
contacts off (MuJoCo's `<flag contact="disable"/>`, which planarsim honours). From joint
positions within 0.3 and rates within 2, no motor: the joint velocities after 0.2 s at dt 4e-3
and at dt / 8, against MuJoCo's RK4 at dt 1e-5. Prints, per tree, planarsim's error, how much
it fell at dt / 8 (first order: 8x) and its ratio to MuJoCo Euler's at dt; then the
percentiles. A tree flagged BAD fell less than 4x or erred above 10x MuJoCo Euler's.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

DT = 4e-3       # [s]
SPAN = 0.2      # [s]


def tree_xml(rng, dt=DT) -> tuple[str, int]:
    """(MJCF text of a random chain of 2-4 bodies, its number of joints)."""
    n = int(rng.integers(2, 5))
    parts = ['<mujoco model="tree">',
             f'<option timestep="{dt}" gravity="0 0 -9.81"><flag contact="disable"/></option>',
             "<worldbody>"]
    for k in range(n):
        kind = "hinge" if (k == 0 and rng.random() < 0.5) else str(rng.choice(["hinge", "slide"]))
        arm = rng.choice([0.0, rng.uniform(0.01, 2.0)])
        stiff = rng.choice([0.0, rng.uniform(1.0, 50.0)])
        damp = rng.choice([0.0, rng.uniform(0.01, 1.0)])
        pos = f'{rng.uniform(-.1, .1):.3f} 0 {rng.uniform(-.1, .1):.3f}'
        if kind == "hinge":
            axis = "0 1 0"
        else:
            a = rng.uniform(0, np.pi)
            axis = f"{np.cos(a):.4f} 0 {np.sin(a):.4f}"
        joint = (f'<joint name="j{k}" type="{kind}" axis="{axis}" pos="{pos}" armature="{arm:.4f}" '
                 f'stiffness="{stiff:.3f}" damping="{damp:.3f}"/>')
        length = rng.uniform(0.2, 0.6)
        geom = (f'<geom type="capsule" fromto="0 0 0 {length:.3f} 0 {-rng.uniform(0, 0.3):.3f}" '
                f'size="0.03" mass="{rng.uniform(0.1, 3):.3f}"/>')
        at = "0 0 0" if k == 0 else f"{rng.uniform(0.1, 0.5):.3f} 0 {rng.uniform(-0.2, 0.2):.3f}"
        parts.append(f'<body name="b{k}" pos="{at}">{joint}{geom}')
    parts += ["</body>"] * n + ["</worldbody>", "</mujoco>"]
    return "\n".join(parts), n


def case(seed: int):
    """(MJCF text, qpos, qvel) of tree `seed`."""
    rng = np.random.default_rng(seed)
    xml, n = tree_xml(rng)
    qv = rng.uniform(-2, 2, n)
    qp = rng.uniform(-0.3, 0.3, n)
    return xml, qp, qv


def errors(seed: int) -> tuple[float, float, float, int]:
    """(planarsim's error at DT, at DT / 8, MuJoCo Euler's at DT, the audit's count): the
    largest joint-velocity error after SPAN against MuJoCo RK4 at 1e-5."""
    import mujoco
    from mujoco_oracle import mujoco_qvel
    from planarsim.envs.core import PlanarMujocoEnv
    xml, qp, qv = case(seed)
    none = np.zeros(0)
    exact, _ = mujoco_qvel(mujoco, mujoco.MjModel.from_xml_string(xml), qp, qv, none, 1e-5,
                           mujoco.mjtIntegrator.mjINT_RK4, SPAN)
    euler, _ = mujoco_qvel(mujoco, mujoco.MjModel.from_xml_string(xml), qp, qv, none, DT,
                           mujoco.mjtIntegrator.mjINT_EULER, SPAN)
    ours, audits = [], 0
    for dt in (DT, DT / 8):
        env = PlanarMujocoEnv(xml.replace(f'timestep="{DT}"', f'timestep="{dt}"'), frame_skip=1)
        env.set_state(qp, qv)
        for _ in range(int(round(SPAN / dt))):
            env.do_simulation(none, 1)
        audits += int(env.sim.ws.audit.sum())
        ours.append(float(np.abs(env.data.qvel - exact).max()))
    return ours[0], ours[1], float(np.abs(euler - exact).max()), audits


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trees", type=int, default=120)
    ap.add_argument("--first", type=int, default=0, help="the first tree's seed")
    args = ap.parse_args(argv)
    ratios, falls, bad = [], [], 0
    print("tree   ours at dt   at dt/8   fell   MuJoCo Euler at dt   ratio  audit")
    for seed in range(args.first, args.first + args.trees):
        coarse, fine, euler, audits = errors(seed)
        fell, ratio = coarse / max(fine, 1e-300), coarse / max(euler, 1e-300)
        flag = fell < 4.0 or ratio > 10.0 or audits
        bad += bool(flag)
        ratios.append(ratio)
        falls.append(fell)
        print(f"{seed:4d}   {coarse:10.2e}  {fine:8.2e}  {fell:5.1f}x  {euler:19.2e}  {ratio:6.2f}  "
              f"{audits}{'  BAD' if flag else ''}", flush=True)
    r = np.sort(ratios)
    print(f"{len(r)} trees: ratio to MuJoCo Euler median {np.median(r):.2f}, 90th percentile "
          f"{r[int(0.9 * (len(r) - 1))]:.2f}, largest {r[-1]:.2f}; error fell at dt / 8 by "
          f"{min(falls):.1f}x at least (median {np.median(falls):.1f}x); {bad} BAD")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
