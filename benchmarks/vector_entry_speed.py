"""Vector steps per second of gymnasium.make_vec on Hopper: planarsim's vector entry point
(BatchedVectorEnv: the copies' physics in one compiled call, observations and rewards per
copy in Python) beside gymnasium's SyncVectorEnv of the same planarsim environment and of
MuJoCo's own Hopper-v5, for 1, 8 and 64 copies, all in this one process.

A vector step is one envs.step call (every copy steps once: frame_skip physics steps, the
observation, the reward, autoresets where an episode ended) under uniformly random actions
from a fixed seed. Repeats interleave the three vectorisations; median and min-max are
printed, with env steps/s (copies x vector steps/s) and the share of the vector entry
point's step spent in its compiled physics call. Nothing here is asserted by the tests.

    python -m benchmarks.vector_entry_speed [--repeats 3] [--copies 1 8 64]
"""
from __future__ import annotations

import argparse
import statistics
import time

from benchmarks.env_speed import _gym, _mujoco_available, _vector_rate

PLANAR_ID, MUJOCO_ID = "planarsim/Hopper-v0", "Hopper-v5"


def _vectorisations(gym, copies):
    """label -> VectorEnv of `copies` Hopper copies."""
    envs = {"planarsim entry point": gym.make_vec(PLANAR_ID, num_envs=copies,
                                                  vectorization_mode="vector_entry_point"),
            "planarsim sync": gym.make_vec(PLANAR_ID, num_envs=copies, vectorization_mode="sync")}
    if _mujoco_available():
        envs["mujoco sync"] = gym.make_vec(MUJOCO_ID, num_envs=copies, vectorization_mode="sync")
    return envs


def _physics_share(envs, steps):
    """Fraction of the entry point's vector step time spent in its batched physics phase."""
    inner = envs._advance_physics
    spent = [0.0]

    def timed():
        t0 = time.perf_counter()
        inner()
        spent[0] += time.perf_counter() - t0

    envs._advance_physics = timed
    try:
        t0 = time.perf_counter()
        _vector_rate(envs, steps)
        return spent[0] / (time.perf_counter() - t0)
    finally:
        del envs._advance_physics


def measure(copies_list=(1, 8, 64), repeats=3, env_steps=4000):
    """Rows (dicts): vector steps/s per copies and vectorisation."""
    gym = _gym()
    if gym is None:
        print("gymnasium is not installed (pip install -e '.[gym]')")
        return []
    rows = []
    for copies in copies_list:
        steps = max(20, env_steps // copies)
        envs = _vectorisations(gym, copies)
        try:
            for e in envs.values():
                _vector_rate(e, 5)                     # warm up: compile or cache load
            rates = {label: [] for label in envs}
            for _ in range(repeats):
                for label, e in envs.items():
                    rates[label].append(_vector_rate(e, steps) / copies)
            share = _physics_share(envs["planarsim entry point"], steps)
        finally:
            for e in envs.values():
                e.close()
        for label, r in rates.items():
            rows.append(dict(copies=copies, vectorisation=label, vector_steps=steps,
                             per_s=statistics.median(r), per_s_min=min(r), per_s_max=max(r),
                             physics_share=share if label == "planarsim entry point" else None))
    return rows


def print_rows(rows):
    """The table, and the entry point's speed-up over the sync vectorisations."""
    print("Hopper: vector steps/s (envs.step calls/s; random actions, autoresets included), "
          "median (min-max), one process")
    print(f"{'copies':>6s}  {'vectorisation':22s} {'vector steps/s':>28s} {'env steps/s':>12s}"
          f"  notes")
    by = {(r["copies"], r["vectorisation"]): r for r in rows}
    for r in rows:
        note = ""
        if r["physics_share"] is not None:
            note = f"compiled physics {100 * r['physics_share']:.0f}% of the step"
        else:
            entry = by[(r["copies"], "planarsim entry point")]["per_s"]
            note = f"entry point / this: {entry / r['per_s']:.2f}x"
        figure = f"{r['per_s']:,.0f} ({r['per_s_min']:,.0f}-{r['per_s_max']:,.0f})"
        print(f"{r['copies']:6d}  {r['vectorisation']:22s} {figure:>28s} "
              f"{r['per_s'] * r['copies']:12,.0f}  {note}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--copies", type=int, nargs="+", default=[1, 8, 64])
    p.add_argument("--env-steps", type=int, default=4000,
                   help="env steps per measurement (vector steps = this / copies, at least 20)")
    a = p.parse_args(argv)
    print_rows(measure(a.copies, a.repeats, a.env_steps))


if __name__ == "__main__":
    main()
