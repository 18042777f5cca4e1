"""Gymnasium environment steps per second: planarsim's environments beside gymnasium's
MuJoCo environments of the same name, single and vectorised, in the same run
(`planarsim bench --parts envs`).

Each figure is env.step calls per second (one call = frame_skip physics steps, the
observation and the reward) under uniformly random actions from a fixed seed, resets
included where an episode ends. Single: one environment, `steps` calls. Vectorised:
PlanarVectorEnv (planarsim.envs.vector) with `copies` copies on `workers` processes, for both
engines (it makes any registered id: the same machinery, so the ratio is the engines'),
copies x calls per second. Repeats interleave the four figures of an environment so that a
shared machine's drift hits them alike; median and min-max are reported. Nothing here is
asserted by the tests.

The DeepMind Control Suite's tasks (planarsim/dmc-<domain>-<task>-v0, measure_dmc) go beside
dm_control's own environments (``suite.load``: MuJoCo's physics and dm_control's Python
observation and reward), one environment each, interleaved per task; they need dm_control.
"""
from __future__ import annotations

import os
import statistics
import sys
import time
import types

import numpy as np

NAMES = ("Hopper", "Walker2d", "HalfCheetah", "InvertedPendulum", "InvertedDoublePendulum",
         "Reacher", "Swimmer")


def _gym():
    try:
        import gymnasium
        import planarsim.envs  # noqa: F401  (registers planarsim/*-v0)
    except ImportError:
        return None
    return gymnasium


def _mujoco_available():
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    # gymnasium's MuJoCo environments import imageio for their video recorder only
    sys.modules.setdefault("imageio", types.ModuleType("imageio"))
    return True


def _single_rate(gym, env_id, steps, seed=0):
    env = gym.make(env_id)
    env.reset(seed=seed)
    actions = np.random.default_rng(seed).uniform(env.action_space.low, env.action_space.high,
                                                  size=(steps, *env.action_space.shape))
    t0 = time.perf_counter()
    for a in actions:
        _, _, term, trunc, _ = env.step(a)
        if term or trunc:
            env.reset()
    rate = steps / (time.perf_counter() - t0)
    env.close()
    return rate


def _vector_rate(envs, steps, seed=0):
    envs.reset(seed=seed)
    actions = np.random.default_rng(seed).uniform(-1.0, 1.0, size=(steps, *envs.action_space.shape))
    low, high = envs.action_space.low, envs.action_space.high
    actions = low + (actions + 1.0) / 2.0 * (high - low)
    t0 = time.perf_counter()
    for a in actions:
        envs.step(a)
    return steps * envs.num_envs / (time.perf_counter() - t0)


def measure_envs(repeats=3, steps=2000, copies=16, workers=2, names=NAMES):
    """Rows (dicts) of env steps/s per environment, engine and mode; [] without gymnasium."""
    gym = _gym()
    if gym is None:
        print("envs: gymnasium is not installed (pip install -e '.[gym]'); skipped\n")
        return []
    from planarsim.envs.vector import PlanarVectorEnv
    engines = {"planarsim": "planarsim/{}-v0"}
    if _mujoco_available():
        engines["mujoco"] = "{}-v5"
    else:
        print("envs: mujoco is not installed; gymnasium's MuJoCo environments are skipped")
    from benchmarks.walker_runs import machine_parallel_capacity
    capacity = machine_parallel_capacity(workers)
    rows = []
    vec_steps = max(1, steps // copies * 2)
    for name in names:
        ids = {e: f.format(name) for e, f in engines.items()}
        vectors = {e: PlanarVectorEnv(i, copies, workers=workers) for e, i in ids.items()}
        try:
            for e in engines:                                  # warm up: compile or cache load
                _single_rate(gym, ids[e], 20)
                _vector_rate(vectors[e], 5)
            rates = {(e, m): [] for e in engines for m in ("single", "vector")}
            for _ in range(repeats):
                for e in engines:
                    rates[(e, "single")].append(_single_rate(gym, ids[e], steps))
                    rates[(e, "vector")].append(_vector_rate(vectors[e], vec_steps))
        finally:
            for v in vectors.values():
                v.close()
        for (e, mode), r in rates.items():
            rows.append(dict(scene="envs", env=name, engine=e, env_id=ids[e], mode=mode,
                             copies=1 if mode == "single" else copies, machine_capacity=capacity,
                             workers=1 if mode == "single" else workers,
                             steps_per_s=statistics.median(r), steps_per_s_min=min(r),
                             steps_per_s_max=max(r)))
        print(f"  {name}: done", flush=True)
    return rows


def print_envs(rows):
    """The table: env steps/s, single and vectorised, per engine, and planarsim / MuJoCo."""
    if not rows:
        return
    r0 = next(r for r in rows if r["mode"] == "vector")
    print(f"gymnasium environments: env.step calls/s (random actions, resets included), "
          f"median (min-max); vector = PlanarVectorEnv, {r0['copies']} copies on "
          f"{r0['workers']} processes")
    by = {(r["env"], r["engine"], r["mode"]): r for r in rows}
    engines = sorted({r["engine"] for r in rows}, key=lambda e: e != "planarsim")
    head = f"{'environment':24s}"
    for e in engines:
        head += f" {e + ' single':>26s} {e + ' vector':>26s}"
    if len(engines) > 1:
        head += f" {'ratio single':>13s} {'ratio vector':>13s}"
    print(head)
    for env in dict.fromkeys(r["env"] for r in rows):
        line = f"{env:24s}"
        for e in engines:
            for mode in ("single", "vector"):
                r = by[(env, e, mode)]
                line += f" {r['steps_per_s']:10,.0f} ({r['steps_per_s_min']:,.0f}-{r['steps_per_s_max']:,.0f})".rjust(27)
        if len(engines) > 1:
            for mode in ("single", "vector"):
                ratio = by[(env, "planarsim", mode)]["steps_per_s"] / by[(env, engines[1], mode)]["steps_per_s"]
                line += f" {ratio:12.2f}x"
        print(line)
    print(f"machine check: {r0['workers']} independent Python processes ran "
          f"{r0['machine_capacity']:.2f}x the work of one in the same time ({r0['workers']:.1f}x = "
          f"that many free cores; load average now {os.getloadavg()[0]:.1f})")
    print("(ratio: planarsim / MuJoCo; planarsim's and MuJoCo's physics differ: hard contacts and "
          "its own integrator against MuJoCo's soft contacts and the files' integrators)", flush=True)
    print(flush=True)


# --- the DeepMind Control Suite's tasks (planarsim/dmc-*-v0) beside dm_control's own ---------

def _dm_control_suite():
    """dm_control.suite, or None (not installed)."""
    try:
        sys.modules.setdefault("imageio", types.ModuleType("imageio"))
        from dm_control import suite
    except ImportError:
        return None
    return suite


def _dmc_rate(gym, task, steps, seed=0):
    """planarsim's env.step calls/s on dmc task `task` (random actions, resets included)."""
    from planarsim.envs.dmc import env_id
    return _single_rate(gym, env_id(task), steps, seed)


def _dm_control_rate(suite, task, steps, seed=0):
    """dm_control's env.step calls/s on the same task (suite.load; random actions in its
    action_spec, resets included)."""
    domain, name = task.split("-", 1)
    env = suite.load(domain, name, task_kwargs={"random": seed})
    env.reset()
    spec = env.action_spec()
    actions = np.random.default_rng(seed).uniform(spec.minimum, spec.maximum,
                                                  size=(steps, *spec.shape))
    t0 = time.perf_counter()
    for a in actions:
        if env.step(a).last():
            env.reset()
    return steps / (time.perf_counter() - t0)


def measure_dmc(repeats=3, steps=1000, tasks=None):
    """Rows (dicts) of env steps/s of planarsim's dmc tasks and dm_control's, single
    environments, interleaved per task; [] without gymnasium or dm_control."""
    gym = _gym()
    suite = _dm_control_suite()
    if gym is None or suite is None:
        print("dmc: gymnasium or dm_control is not installed (pip install -e '.[gym]' "
              "dm_control); skipped\n")
        return []
    from planarsim.envs.dmc import TASKS
    rows = []
    for task in tasks or TASKS:
        _dmc_rate(gym, task, 20)                                # warm up: compile or load
        _dm_control_rate(suite, task, 20)
        rates = {"planarsim": [], "dm_control": []}
        for _ in range(repeats):
            rates["planarsim"].append(_dmc_rate(gym, task, steps))
            rates["dm_control"].append(_dm_control_rate(suite, task, steps))
        for engine, r in rates.items():
            rows.append(dict(scene="dmc", env=task, engine=engine, mode="single",
                             steps_per_s=statistics.median(r), steps_per_s_min=min(r),
                             steps_per_s_max=max(r)))
    return rows


def print_dmc(rows):
    """The table: env steps/s of each dmc task, planarsim's and dm_control's, and their ratio."""
    if not rows:
        return
    print("DeepMind Control Suite tasks: env.step calls/s, one environment (random actions, "
          "resets included), median (min-max)")
    print(f"{'task':24s} {'planarsim':>26s} {'dm_control':>26s} {'ratio':>8s}")
    by = {(r["env"], r["engine"]): r for r in rows}
    below = []
    for task in dict.fromkeys(r["env"] for r in rows):
        ours, theirs = by[(task, "planarsim")], by[(task, "dm_control")]
        ratio = ours["steps_per_s"] / theirs["steps_per_s"]
        if ratio < 1.0:
            below.append(task)
        cells = [f"{r['steps_per_s']:10,.0f} ({r['steps_per_s_min']:,.0f}-{r['steps_per_s_max']:,.0f})"
                 for r in (ours, theirs)]
        print(f"{task:24s} {cells[0]:>26s} {cells[1]:>26s} {ratio:7.2f}x")
    print(f"{len(below)} of {len(by) // 2} tasks below dm_control's env steps/s"
          + (f": {', '.join(below)}" if below else ""))
    print("(ratio: planarsim / dm_control; the motion differs: planarsim's hard contacts and "
          "integrator against MuJoCo's soft contacts, Euler or RK4)", flush=True)
    print(flush=True)
