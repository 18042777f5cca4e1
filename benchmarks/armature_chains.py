"""Random planar chains with rotors (armature), dampers, springs and motors against MuJoCo (not
a test; tests/physics/test_armature_chains.py asserts on a slice of it).

    python benchmarks/armature_chains.py                 # seeds 0-99
    python benchmarks/armature_chains.py --seeds 40 --first 200 --all

Each seed draws a chain of 1-6 capsule links (lengths 3 cm - 1 m, radii 1-20 % of them,
densities 10-10^4 kg/m^3: masses and inertias over six decades), hinged end to end to the
world (the first joint a slide in 30 % of chains), each joint with armature 10^U(-5, 0) (in
80 %), damping 10^U(-3, 0) (50 %), stiffness 10^U(-1, 2) (30 %) and a motor of gear
10^U(-2, 1) under a constant control in [-1, 1]; dt 10^U(-3.5, -2) s; a random start (joint
offsets within 0.5, rates within 1). The joint velocities after 0.02 s are compared with
MuJoCo's RK4 at dt 1e-5 (the exact motion): planarsim's error at dt beside MuJoCo's Euler's,
and planarsim's at dt / 10. A run that planarsim refuses (a motor that would turn its link
by more than the step resolves: SimulationDiverged before step 0, naming it) is counted
apart. Prints each flagged seed (ratio > 3, or the error not 5x smaller at dt / 10) and the
ratio's quantiles.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim.envs.core import GeneralizedCoords  # noqa: E402
from planarsim.mjcf import load_mjcf  # noqa: E402

SPAN = 0.02         # [s] simulated
EXACT_DT = 1e-5     # [s] MuJoCo RK4's step for the exact motion


def chain_xml(rng):
    """(MJCF text, links, dt [s]) of a random chain (module docstring)."""
    n = int(rng.integers(1, 7))
    dt = float(10 ** rng.uniform(-3.5, -2))
    body, close, acts, prev = "", "", "", 0.0
    for k in range(n):
        length = float(10 ** rng.uniform(-1.5, 0))
        radius = length * float(10 ** rng.uniform(-2, -0.7))
        density = float(10 ** rng.uniform(1, 4))
        armature = float(10 ** rng.uniform(-5, 0)) if rng.random() < 0.8 else 0.0
        damping = float(10 ** rng.uniform(-3, 0)) if rng.random() < 0.5 else 0.0
        stiffness = float(10 ** rng.uniform(-1, 2)) if rng.random() < 0.3 else 0.0
        kind = "slide" if (k == 0 and rng.random() < 0.3) else "hinge"
        axis = "1 0 0" if kind == "slide" else "0 1 0"
        body += (f'<body name="b{k}" pos="{prev} 0 0"><joint name="j{k}" type="{kind}" '
                 f'axis="{axis}" armature="{armature}" damping="{damping}" '
                 f'stiffness="{stiffness}"/><geom type="capsule" fromto="0 0 0 {length} 0 0" '
                 f'size="{radius}" density="{density}" contype="0" conaffinity="0"/>')
        close += "</body>"
        gear = float(10 ** rng.uniform(-2, 1))
        acts += f'<motor joint="j{k}" gear="{gear}" ctrlrange="-1 1" ctrllimited="true"/>'
        prev = length
    return (f'<mujoco><option timestep="{dt}" gravity="0 0 -9.81"/><worldbody>{body}{close}'
            f'</worldbody><actuator>{acts}</actuator></mujoco>'), n, dt


def case(seed):
    """(MJCF text, links, dt, qpos, qvel, ctrl) of seed's chain and start."""
    import mujoco
    rng = np.random.default_rng(seed)
    xml, n, dt = chain_xml(rng)
    m = mujoco.MjModel.from_xml_string(xml)
    qpos = 0.5 * rng.uniform(-1, 1, m.nq)
    qvel = rng.uniform(-1, 1, m.nv)
    ctrl = rng.uniform(-1, 1, m.nu)
    return xml, n, dt, qpos, qvel, ctrl


def mujoco_qvel(xml, qpos, qvel, ctrl, dt, rk4):
    """MuJoCo's joint velocities after SPAN at step dt (RK4 or Euler)."""
    import mujoco
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    m.opt.timestep = dt
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4 if rk4 else mujoco.mjtIntegrator.mjINT_EULER
    d.qpos[:], d.qvel[:], d.ctrl[:] = qpos, qvel, ctrl
    for _ in range(int(round(SPAN / dt))):
        mujoco.mj_step(m, d)
    return d.qvel.copy()


def our_qvel(xml, qpos, qvel, ctrl, dt):
    """(planarsim's joint velocities after SPAN at step dt, the audit's count)."""
    loaded = load_mjcf(xml, dt=dt)
    model = loaded.compile()
    coords = GeneralizedCoords(loaded, model)
    q, v = coords.to_maximal(qpos, qvel)
    sim = ps.Simulator(model, None, ps.make_state(model, q, v))
    command = np.zeros(model.n_act)
    for k, act in enumerate(loaded.actuator.values()):
        command[act.id] = act.gear * np.clip(ctrl[k], *act.ctrlrange)
    sim.steps(int(round(SPAN / dt)), command)
    return coords.values(sim.state.q, sim.state.v)[1], int(sim.ws.audit.sum())


def measure(seed):
    """{seed, links, dt, mujoco (MuJoCo Euler's error at dt), ours (at dt), finer (at dt / 10),
    audit} or {seed, refused: the error's first line}."""
    xml, n, dt, qpos, qvel, ctrl = case(seed)
    exact = mujoco_qvel(xml, qpos, qvel, ctrl, min(EXACT_DT, dt / 10), True)
    euler = mujoco_qvel(xml, qpos, qvel, ctrl, dt, False)
    try:
        coarse, audit = our_qvel(xml, qpos, qvel, ctrl, dt)
        fine, more = our_qvel(xml, qpos, qvel, ctrl, dt / 10)
    except ps.SimulationDiverged as exc:
        return {"seed": seed, "refused": str(exc).splitlines()[0]}
    return {"seed": seed, "links": n, "dt": dt, "mujoco": float(np.abs(euler - exact).max()),
            "ours": float(np.abs(coarse - exact).max()), "finer": float(np.abs(fine - exact).max()),
            "audit": audit + more}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=100)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--all", action="store_true", help="print every seed, not only flagged ones")
    a = ap.parse_args(argv)
    ratios, refused = [], 0
    for seed in range(a.first, a.first + a.seeds):
        r = measure(seed)
        if "refused" in r:
            refused += 1
            continue
        ratio = r["ours"] / r["mujoco"]
        ratios.append(ratio)
        gain = max(r["ours"], r["mujoco"]) / max(r["finer"], 1e-300)
        if a.all or ratio > 3 or gain < 5 or r["audit"]:
            print(f"seed {seed:4d} links {r['links']} dt {r['dt']:.1e}  MuJoCo Euler {r['mujoco']:.2e}"
                  f"  ours {r['ours']:.2e} ({ratio:.2f}x)  ours at dt/10 {r['finer']:.2e}"
                  f" ({gain:.1f}x less)  audit {r['audit']}")
    q = np.quantile(ratios, [0.5, 0.75, 0.9, 1.0])
    print(f"{len(ratios)} chains run, {refused} refused before their first step; ours / MuJoCo "
          f"Euler's error: median {q[0]:.2f}, 75th percentile {q[1]:.2f}, 90th {q[2]:.2f}, "
          f"largest {q[3]:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
