"""What a dmc task's physics steps cost, by how many linear solves each took (not a test).

    python benchmarks/dmc_steps.py walker-walk cheetah-run hopper-hop

Runs planarsim/dmc-<task>-v0 under uniformly random actions (seed 0) physics step by physics
step (Simulator.steps(1): a few microseconds of Python each), and prints the steps grouped by
their linear solves (step_info: "solves") and whether Lemke's method took part: how many,
their mean time [us] and their share of the run's time. The mode rounds' cost shows here
(kernels/step.py solve_modes); the observation's and reward's are not timed.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def step_costs(task: str, env_steps: int = 500, seed: int = 0) -> dict:
    """{(solves, lemke): [steps, seconds]} of env_steps env steps of `task`."""
    import gymnasium
    import planarsim.envs  # noqa: F401  (registers the environments)
    from planarsim.compiled import step_info
    from planarsim.envs.dmc import env_id
    env = gymnasium.make(env_id(task)).unwrapped
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    sim, groups = env.sim, {}
    sim.steps(1, env._u)                  # (compiled or loaded before the clock runs)
    env.reset(seed=seed)
    for _ in range(env_steps):
        env.load_commands(rng.uniform(env.action_space.low, env.action_space.high))
        for _ in range(env.frame_skip):
            t = time.perf_counter()
            sim.steps(1, env._u)
            dt = time.perf_counter() - t
            info = step_info(sim.ws)
            g = groups.setdefault((info["solves"], info["lcp_solves"] > 0), [0, 0.0])
            g[0] += 1
            g[1] += dt
        env._sync()
    return groups


def report(task: str, groups: dict, top: int = 8) -> str:
    n = sum(g[0] for g in groups.values())
    total = sum(g[1] for g in groups.values())
    solves = sum(k[0] * g[0] for k, g in groups.items())
    lines = [f"{task}: {n} physics steps, mean {total / n * 1e6:.1f} us, "
             f"{solves / n:.2f} linear solves a step, "
             f"{sum(g[0] for k, g in groups.items() if k[1])} steps with Lemke's method"]
    for (s, lemke), (c, t) in sorted(groups.items(), key=lambda kv: -kv[1][1])[:top]:
        lines.append(f"  {s:3d} solves{' + Lemke' if lemke else '        '}: {c:5d} steps "
                     f"({100 * c / n:4.1f} %), mean {t / c * 1e6:7.1f} us, "
                     f"{100 * t / total:4.1f} % of the time")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("tasks", nargs="*", default=["walker-walk", "hopper-hop", "cheetah-run"])
    ap.add_argument("--env-steps", type=int, default=500)
    args = ap.parse_args(argv)
    for task in args.tasks:
        print(report(task, step_costs(task, args.env_steps)), flush=True)


if __name__ == "__main__":
    main()
